/* An FMI 3.0 Model Exchange test FMU whose periodic input clock resets a continuous state:
 * x' = 1, and each tick of `sample` sets x to 0 (in fmi3SetClock), which the following
 * fmi3UpdateDiscreteStates reports with valuesOfContinuousStatesChanged. So x is the time
 * since the last tick: a sawtooth. Value references as in fmi3_sawtooth.xml:
 *   1 sample  input clock, constant: interval 0.25 s, shift 0
 *   2 x       Float64 continuous state, output (start 0)
 *   3 der(x)  Float64, 1
 *   4 resets  Int32 output: the ticks so far
 * No event indicators; no time events of its own. */
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    double time, x, dx;
    int resets, reset_pending, in_event_mode;
} Sawtooth;

FMI3_TEST_FAIL(Sawtooth)

static void start(Sawtooth *s) { s->dx = 1.0; }

FMI3_TEST_MODEL_EXCHANGE_INSTANCE(Sawtooth, "{fmi3-sawtooth}", start)
void fmi3FreeInstance(fmi3Instance instance) { free(instance); }
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
    fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((Sawtooth *)instance)->time = startTime;
    return fmi3OK;
}
/* after initialization the instance is in Event Mode (FMI 3.0 Model Exchange) */
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ((Sawtooth *)instance)->in_event_mode = 1;
    return fmi3OK;
}
fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    ((Sawtooth *)instance)->in_event_mode = 1;
    return fmi3OK;
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    ((Sawtooth *)instance)->in_event_mode = 0;
    return fmi3OK;
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Sawtooth *)instance)->time = time;
    return fmi3OK;
}
FMI3_TEST_NO_STEP_EVENTS

FMI3_TEST_INPUT_CLOCK(Sawtooth, 1, {
    c->x = 0.0;
    c->resets++;
    c->reset_pending = 1;
})
FMI3_TEST_CONSTANT_CLOCK(Sawtooth, 1, 0.25)

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    Sawtooth *s = instance;
    if (!s->in_event_mode) return fail(s, "fmi3UpdateDiscreteStates outside Event Mode");
    updated_discrete_states(needUpdate, terminate, nominalsChanged, valuesChanged, nextDefined, next);
    *valuesChanged = s->reset_pending;
    s->reset_pending = 0;
    return fmi3OK;
}

FMI3_TEST_CONTINUOUS_STATES(Sawtooth, 1, &c->x)
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) {
    Sawtooth *s = instance;
    if (n != 1) return fail(s, "fmi3GetContinuousStateDerivatives: n != 1");
    dx[0] = s->dx;
    return fmi3OK;
}

FMI3_TEST_GET(Float64, fmi3Float64, Sawtooth, [0] = &c->time, [2] = &c->x, [3] = &c->dx)
FMI3_TEST_SET(Float64, fmi3Float64, Sawtooth, "not settable", [2] = &c->x)
FMI3_TEST_GET(Int32, fmi3Int32, Sawtooth, [4] = &c->resets)
