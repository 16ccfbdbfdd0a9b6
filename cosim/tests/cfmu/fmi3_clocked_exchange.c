/* An FMI 3.0 test FMU (Co-Simulation with Event Mode only, Model Exchange, Scheduled
 * Execution) whose clocked variables may be accessed only while their clock is active, as
 * FMI 3.0 says: in Initialization Mode; set in Event Mode between fmi3SetClock of `tick` and
 * fmi3UpdateDiscreteStates, read in the Event Mode in which `tick` ticked (Co-Simulation and
 * Model Exchange: no states, no event indicators); in Scheduled Execution set once before
 * each fmi3ActivateModelPartition of `tick` (a second set before it is refused) and read
 * right after it (before the next set). Any other get or set of them is an error naming
 * the variable. Value references as in
 * fmi3_clocked_exchange.xml:
 *   1 tick   input clock, constant: interval 0.25 s, shift 0
 *   2 u      Float64 input clocked by tick (start 0)
 *   3 y      Float64 output clocked by tick (start -1): at the k-th tick (k = 1, 2, ...)
 *            y = 10 u + k, u as set in that activation (recomputed by a set of u in it)
 *   4 t_now  Float64 output, not clocked: the time
 * fmi3DoStep advances the time and never asks for an event. */
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    double time, u, y;
    int ticks, initializing, in_event_mode, active, ticked, scheduled, u_set;
} Exchange;

FMI3_TEST_FAIL(Exchange)

static void start(Exchange *c) {
    c->time = 0;
    c->u = 0;
    c->y = -1;
    c->ticks = 0;
    c->initializing = c->in_event_mode = c->active = c->ticked = c->u_set = 0;
}

FMI3_TEST_EVENT_MODE_INSTANCE(Exchange, "{fmi3-clocked-exchange}", start)

FMI3_TEST_MODEL_EXCHANGE_INSTANCE(Exchange, "{fmi3-clocked-exchange}", start)

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
    fmi3ClockUpdateCallback update, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    Exchange *c = fmi3InstantiateModelExchange(name, token, resources, visible, logging, env, log);
    if (c) c->scheduled = 1;
    return c;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Exchange *c = instance;
    c->time = startTime;
    c->initializing = 1;
    return fmi3OK;
}
/* after initialization the instance is in Event Mode (eventModeUsed), no clock active */
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Exchange *c = instance;
    c->initializing = 0;
    c->in_event_mode = !c->scheduled;
    return fmi3OK;
}
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Exchange *c = instance;
    if (c->active) return fail(c, "fmi3EnterStepMode: tick is still active");
    c->in_event_mode = 0;
    c->ticked = 0;
    return fmi3OK;
}
/* Model Exchange: no states, no event indicators; the time the importer sets */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { return fmi3EnterStepMode(instance); }
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Exchange *)instance)->time = time;
    return fmi3OK;
}
FMI3_TEST_NO_CONTINUOUS_STATES

/* Scheduled Execution: the activation of tick at `time` (u as set before it) */
fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock, fmi3Float64 time) {
    Exchange *c = instance;
    if (clock != 1) return fail(c, "fmi3ActivateModelPartition: not an input clock");
    c->time = time;
    c->ticks++;
    c->y = 10 * c->u + c->ticks;
    c->ticked = 1;
    c->u_set = 0;
    return fmi3OK;
}

FMI3_TEST_EVENT_MODE_STEPS(Exchange)
/* the scheduled flag (the instance's interface) stays */
fmi3Status fmi3Reset(fmi3Instance instance) {
    start(instance);
    return fmi3OK;
}

FMI3_TEST_INPUT_CLOCK(Exchange, 1, {
    c->active = c->ticked = 1;
    c->ticks++;
    c->y = 10 * c->u + c->ticks;
})

FMI3_TEST_CONSTANT_CLOCK(Exchange, 1, 0.25)

/* the end of the clock's activation */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    Exchange *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3UpdateDiscreteStates outside Event Mode");
    c->active = 0;
    return updated_discrete_states(needUpdate, terminate, nominalsChanged, valuesChanged, nextDefined, next);
}

/* whether a clocked variable may be set now: while tick is active (Scheduled Execution:
 * once before its activation) */
static int clocked_open(Exchange *c) {
    return c->initializing || (c->scheduled ? !c->u_set : c->in_event_mode && c->active);
}
/* whether it may be read now: in the Event Mode in which tick ticked (the values its
 * activation left, also after fmi3UpdateDiscreteStates; Scheduled Execution: right after
 * the activation) */
static int clocked_readable(Exchange *c) {
    return c->initializing || ((c->scheduled || c->in_event_mode) && c->ticked);
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3Float64 values[], size_t nValues) {
    Exchange *c = instance;
    for (size_t k = 0; k < nvr; k++) {
        switch (vr[k]) {
        case 0: values[k] = c->time; break;
        case 4: values[k] = c->time; break;
        case 2:
        case 3:
            if (!clocked_readable(c))
                return fail(c, vr[k] == 2 ? "fmi3GetFloat64: u is a clocked variable of tick, which is not active"
                                          : "fmi3GetFloat64: y is a clocked variable of tick, which is not active");
            values[k] = vr[k] == 2 ? c->u : c->y;
            break;
        default: return fail(c, "fmi3GetFloat64: no such variable");
        }
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3Float64 values[], size_t nValues) {
    Exchange *c = instance;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] != 2) return fail(c, "fmi3SetFloat64: not an input");
        if (!clocked_open(c)) return fail(c, "fmi3SetFloat64: u is a clocked variable of tick, which is not active");
        c->u = values[k];
        if (c->scheduled && !c->initializing) {
            c->u_set = 1;
            c->ticked = 0;
        }
        if (c->active) c->y = 10 * c->u + c->ticks;
    }
    return fmi3OK;
}
