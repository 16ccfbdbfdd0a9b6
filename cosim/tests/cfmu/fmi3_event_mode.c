/* FMI 3.0 Co-Simulation test FMU with Event Mode (hasEventMode) and no clocks: x integrates
 * a rate of 1, which becomes 2 at the state event x = 0.55 (t = 0.55 s from x(0) = 0).
 * Instantiated with eventModeUsed, the step in which x crosses 0.55 ends at its end with
 * eventHandlingNeeded, and the rate changes in the Event Mode that follows (at that
 * communication point); without it, the FMU handles the event inside fmi3DoStep at the
 * crossing itself, as an FMU without Event Mode does (FMI 3.0 section 4.1.2). Outputs: x,
 * event_mode_used (eventModeUsed as instantiated), events (the events handled).
 * Without eventModeUsed but with earlyReturnAllowed, its first fmi3DoStep returns early at
 * its start time with eventHandlingNeeded, the initial event handled inside (as Dymola 2025x
 * CoupledClutches with Dassl does); the next fmi3DoStep from there steps on.
 * An instance named "...refuses..." refuses eventModeUsed = true (as the Reference FMUs'
 * Roberts does although it declares hasEventMode). */
#include <stdio.h>
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3Float64 time, x, rate;
    fmi3Boolean event_mode_used;
    fmi3Int32 events;
    int in_event_mode, pending, early_allowed, announced;
} EventModel;

FMI3_TEST_FAIL(EventModel)

/* the state event: x reaches this value */
#define X_EVENT 0.55

static void start(EventModel *c) {
    c->x = 0.0;
    c->rate = 1.0;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean eventMode, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference req[], size_t nReq, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
    if (!token || strcmp(token, "{fmi3-event-mode}") != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiationToken");
        return NULL;
    }
    FMI3_TEST_NEW(EventModel, eventMode && name && strstr(name, "refuses"), "eventModeUsed is not supported",
        c->event_mode_used = eventMode; c->early_allowed = earlyReturnAllowed; start(c))
}
void fmi3FreeInstance(fmi3Instance instance) { free(instance); }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) { return fmi3OK; }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((EventModel *)instance)->time = startTime;
    return fmi3OK;
}
/* with eventModeUsed the instance is in Event Mode after initialization */
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    EventModel *c = instance;
    c->in_event_mode = c->event_mode_used;
    return fmi3OK;
}
fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    EventModel *c = instance;
    if (!c->event_mode_used) return fail(c, "fmi3EnterEventMode: instantiated with eventModeUsed = false");
    c->in_event_mode = 1;
    return fmi3OK;
}
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    EventModel *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3UpdateDiscreteStates: not in Event Mode");
    if (c->pending) {
        c->rate = 2.0;
        c->events += 1;
        c->pending = 0;
    }
    return updated_discrete_states(needUpdate, terminate, nominalsChanged, valuesChanged, nextDefined, next);
}
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    EventModel *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3EnterStepMode: not in Event Mode");
    c->in_event_mode = 0;
    return fmi3OK;
}
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
    fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
    fmi3Float64 *lastSuccessfulTime) {
    EventModel *c = instance;
    if (c->in_event_mode) return fail(c, "fmi3DoStep: Illegal call sequence: in Event Mode (fmi3EnterStepMode first)");
    if (c->pending) return fail(c, "fmi3DoStep: the event of the last step was not handled in Event Mode");
    if (!c->event_mode_used && c->early_allowed && !c->announced) {
        /* the initial event, handled inside: an early return at t, no progress */
        c->announced = 1;
        step_reached(t, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime);
        *eventHandlingNeeded = 1;
        *earlyReturn = 1;
        return fmi3OK;
    }
    double end = t + h;
    double x_end = c->x + c->rate * h;
    int crosses = c->events == 0 && c->x < X_EVENT && x_end >= X_EVENT;
    if (crosses && c->event_mode_used) {
        /* the event is the importer's: the rate changes in Event Mode at the step's end */
        c->x = x_end;
        c->pending = 1;
        c->time = end;
        step_reached(end, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime);
        *eventHandlingNeeded = 1;
        return fmi3OK;
    }
    if (crosses) {
        /* handled here, at the crossing: rate 1 up to x = 0.55, then rate 2 to the step's end */
        double t_event = t + (X_EVENT - c->x) / c->rate;
        c->rate = 2.0;
        c->events += 1;
        c->x = X_EVENT + c->rate * (end - t_event);
    } else {
        c->x = x_end;
    }
    c->time = end;
    return step_reached(end, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime);
}
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

FMI3_TEST_GET(Float64, fmi3Float64, EventModel, [0] = &c->time, [1] = &c->x)
FMI3_TEST_GET(Boolean, fmi3Boolean, EventModel, [2] = &c->event_mode_used)
FMI3_TEST_GET(Int32, fmi3Int32, EventModel, [3] = &c->events)
