/* Shared by the FMI 3.0 C test FMUs of the master's tests (fmi3_*.c), written against the
 * standard's headers (the tests pass their folder with -I): fmi3GetVersion and the helpers
 * that are the same in each. Each .c file is one shared library and includes this header
 * once. After its instance's struct (a `Type` with members `fmi3InstanceEnvironment env`
 * and `fmi3LogMessageCallback log`), a file writes FMI3_TEST_FAIL(Type) for its `fail`; an
 * Event Mode only Co-Simulation FMU FMI3_TEST_EVENT_MODE_INSTANCE, FMI3_TEST_EVENT_MODE_STEPS
 * and FMI3_TEST_RESET for its lifecycle, a Scheduled Execution FMU
 * FMI3_TEST_SCHEDULED_INSTANCE, a Model Exchange FMU FMI3_TEST_MODEL_EXCHANGE_INSTANCE (and
 * FMI3_TEST_NO_CONTINUOUS_STATES or FMI3_TEST_NO_STEP_EVENTS where they say what it does);
 * FMI3_TEST_GET and FMI3_TEST_SET give typed gets and sets from a table of the variables'
 * addresses, FMI3_TEST_OUTPUT_CLOCK the read of a single output clock,
 * FMI3_TEST_ONE_INTERVAL the interval of a single clock, FMI3_TEST_INPUT_CLOCK the ticks of a
 * single input clock, FMI3_TEST_CONSTANT_CLOCK the interval and shift of a single constant
 * clock, FMI3_TEST_CONTINUOUS_STATES Model Exchange's states. */
#ifndef FMI3_TEST_H
#define FMI3_TEST_H

#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"

const char *fmi3GetVersion(void) { return fmi3Version; }

/* `fail(instance, message)`: fmi3Error, with `message` logged (category logStatusError)
 * through the instance's callback when there are both. */
#define FMI3_TEST_FAIL(Type)                                                               \
    static fmi3Status fail(Type *instance, const char *message) {                          \
        if (instance && instance->log)                                                     \
            instance->log(instance->env, fmi3Error, "logStatusError", message);            \
        return fmi3Error;                                                                  \
    }

/* The body of an fmi3Instantiate* of a `Type` (members `env` and `log`; `token`, `env` and
 * `log` the function's parameters): when `refused` (an expression), NULL with `reason` logged
 * through `log` when there is one; else the zeroed instance `c` with env and log set, on which
 * `then` (statements of `c`) runs before it is returned. */
#define FMI3_TEST_NEW(Type, refused, reason, then)                                                 \
    if (refused) {                                                                                 \
        if (log) log(env, fmi3Error, "logStatusError", reason);                                    \
        return NULL;                                                                               \
    }                                                                                              \
    Type *c = calloc(1, sizeof(Type));                                                             \
    if (!c) return NULL;                                                                           \
    c->env = env;                                                                                  \
    c->log = log;                                                                                  \
    then;                                                                                          \
    return c;

/* The lifecycle of a Co-Simulation `Type` (members `env` and `log`) that runs in Event Mode
 * only: fmi3InstantiateCoSimulation refuses (NULL, logged) another instantiation token than
 * `token_text` and eventModeUsed false, else calls `start(Type *)` on the zeroed instance;
 * fmi3FreeInstance frees it; fmi3SetDebugLogging accepts anything. */
#define FMI3_TEST_EVENT_MODE_INSTANCE(Type, token_text, start)                                  \
    fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, \
        fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean eventMode, fmi3Boolean earlyReturnAllowed, \
        const fmi3ValueReference req[], size_t nReq, fmi3InstanceEnvironment env,                  \
        fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {                       \
        FMI3_TEST_NEW(Type, !token || strcmp(token, token_text) != 0 || !eventMode,               \
            "wrong instantiationToken or no eventModeUsed", start(c))                              \
    }                                                                                              \
    void fmi3FreeInstance(fmi3Instance instance) { free(instance); }                               \
    fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) { return fmi3OK; }

/* The end of an fmi3DoStep that reached `time` with no event, no end and no early return. */
static inline fmi3Status step_reached(fmi3Float64 time, fmi3Boolean *eventHandlingNeeded,
    fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    *eventHandlingNeeded = 0;
    *terminateSimulation = 0;
    *earlyReturn = 0;
    *lastSuccessfulTime = time;
    return fmi3OK;
}

/* The steps of an Event Mode only Co-Simulation `Type` (members `double time` and
 * `int in_event_mode`): fmi3EnterEventMode enters it; fmi3DoStep is refused in Event Mode,
 * else advances the time to t + h with no event; fmi3Terminate does nothing. */
#define FMI3_TEST_EVENT_MODE_STEPS(Type)                                                           \
    fmi3Status fmi3EnterEventMode(fmi3Instance instance) {                                         \
        ((Type *)instance)->in_event_mode = 1;                                                     \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior, \
        fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, \
        fmi3Float64 *lastSuccessfulTime) {                                                         \
        Type *c = instance;                                                                        \
        if (c->in_event_mode) return fail(c, "fmi3DoStep in Event Mode");                          \
        c->time = t + h;                                                                           \
        return step_reached(c->time, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime); \
    }                                                                                              \
    fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

/* fmi3Reset of a `Type` of FMI3_TEST_EVENT_MODE_INSTANCE: zeroed but for env and log, then
 * `start(Type *)` as at instantiation. */
#define FMI3_TEST_RESET(Type, start)                                                               \
    fmi3Status fmi3Reset(fmi3Instance instance) {                                                  \
        Type *c = instance;                                                                        \
        fmi3InstanceEnvironment env = c->env;                                                      \
        fmi3LogMessageCallback log = c->log;                                                       \
        memset(c, 0, sizeof(Type));                                                                \
        c->env = env;                                                                              \
        c->log = log;                                                                              \
        start(c);                                                                                  \
        return fmi3OK;                                                                             \
    }

/* The lifecycle of a Scheduled Execution `Type` (members `env`, `log` and `update`):
 * fmi3InstantiateScheduledExecution refuses (NULL, logged) another instantiation token than
 * `token_text` or no clockUpdate callback, else calls `start(Type *, lock, unlock)` on the
 * zeroed instance with env, log and update set; fmi3FreeInstance frees it; terminating does
 * nothing. */
#define FMI3_TEST_SCHEDULED_INSTANCE(Type, token_text, start)                                      \
    fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token,             \
        fmi3String resources, fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, \
        fmi3LogMessageCallback log, fmi3ClockUpdateCallback update, fmi3LockPreemptionCallback lock, \
        fmi3UnlockPreemptionCallback unlock) {                                                     \
        FMI3_TEST_NEW(Type, !token || strcmp(token, token_text) != 0 || !update,                  \
            "wrong instantiationToken or no clockUpdate", c->update = update; start(c, lock, unlock))     \
    }                                                                                              \
    void fmi3FreeInstance(fmi3Instance instance) { free(instance); }                               \
    fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

/* fmi3EnterInitializationMode of an FMU that has nothing to do there. */
#define FMI3_TEST_NOTHING_TO_INITIALIZE                                                            \
    fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,    \
        fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) { \
        return fmi3OK;                                                                             \
    }

/* fmi3InstantiateModelExchange of a `Type` (members `env` and `log`): refuses (NULL, logged)
 * another instantiation token than `token_text`, else calls `start(Type *)` on the zeroed
 * instance with env and log set. */
#define FMI3_TEST_MODEL_EXCHANGE_INSTANCE(Type, token_text, start)                                 \
    fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources, \
        fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) { \
        FMI3_TEST_NEW(Type, !token || strcmp(token, token_text) != 0, "wrong instantiationToken", start(c)) \
    }

/* fmi3Get<Kind> (values of C type `CType`) of a `Type`: `...` the addresses of its scalar
 * variables as designated initializers `[vr] = &c->member` (`c` the instance); another value
 * reference is no such variable, and nValues other than the number of value references
 * wrong, fmi3Error. */
#define FMI3_TEST_GET(Kind, CType, Type, ...)                                                      \
    fmi3Status fmi3Get##Kind(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,      \
        CType values[], size_t nValues) {                                                          \
        Type *c = instance;                                                                        \
        if (nValues != n) return fail(c, "fmi3Get" #Kind ": nValues is not nValueReferences");    \
        CType *slots[] = {__VA_ARGS__};                                                            \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] >= sizeof slots / sizeof *slots || !slots[vr[k]])                            \
                return fail(c, "fmi3Get" #Kind ": no such variable");                              \
            values[k] = *slots[vr[k]];                                                             \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }

/* fmi3Set<Kind> (values of C type `CType`) of a `Type`: `...` the addresses of the variables
 * that may be set now, as FMI3_TEST_GET's (an address may be an expression giving NULL:
 * not now); another value reference is refused (fmi3Error, logged as `refusal`), as is
 * nValues other than the number of value references. */
#define FMI3_TEST_SET(Kind, CType, Type, refusal, ...)                                             \
    fmi3Status fmi3Set##Kind(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,      \
        const CType values[], size_t nValues) {                                                    \
        Type *c = instance;                                                                        \
        if (nValues != n) return fail(c, "fmi3Set" #Kind ": nValues is not nValueReferences");    \
        CType *slots[] = {__VA_ARGS__};                                                            \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] >= sizeof slots / sizeof *slots || !slots[vr[k]])                            \
                return fail(c, "fmi3Set" #Kind ": " refusal);                                      \
            *slots[vr[k]] = values[k];                                                             \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }

/* fmi3GetIntervalDecimal of a `Type` with one clock whose interval the FMU gives, value
 * reference `clock`: `interval` (an expression of `c`, the instance), fmi3IntervalChanged
 * when the int member `changed` is set (the read clears it), else fmi3IntervalUnchanged. */
#define FMI3_TEST_ONE_INTERVAL(Type, clock, interval, changed)                                     \
    fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, \
        fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {                             \
        Type *c = instance;                                                                        \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] != clock) return fail(c, "fmi3GetIntervalDecimal: not the clock of the FMU's intervals"); \
            intervals[k] = interval;                                                               \
            qualifiers[k] = c->changed ? fmi3IntervalChanged : fmi3IntervalUnchanged;              \
            c->changed = 0;                                                                        \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }

/* The partition activated first at the latest activation time: at an activation of `clock`
 * at `time` later than `*last_time`, `*first` becomes the clock and `*last_time` the time. */
static inline void note_first_partition(int *first, double *last_time, fmi3ValueReference clock, fmi3Float64 time) {
    if (time != *last_time) {
        *first = (int)clock;
        *last_time = time;
    }
}

/* fmi3GetClock of a `Type` with one output clock, value reference `clock`: whether it ticked
 * (the int member `ticked` nonzero), which the read clears. */
#define FMI3_TEST_OUTPUT_CLOCK(Type, clock, ticked)                                                \
    fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,       \
        fmi3Clock values[]) {                                                                      \
        Type *c = instance;                                                                        \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] != clock) return fail(c, "fmi3GetClock: not the output clock");              \
            values[k] = c->ticked != 0;                                                            \
            c->ticked = 0;                                                                         \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }

/* The end of an fmi3UpdateDiscreteStates that asks for nothing more: no further update, no
 * end, nothing changed, no next event time. */
static inline fmi3Status updated_discrete_states(fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    *needUpdate = 0;
    *terminate = 0;
    *nominalsChanged = 0;
    *valuesChanged = 0;
    *nextDefined = 0;
    *next = 0;
    return fmi3OK;
}

/* Model Exchange whose integrator steps ask for no event and no end. */
#define FMI3_TEST_NO_STEP_EVENTS                                                                   \
    fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetPrior,          \
        fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {                           \
        *enterEventMode = 0;                                                                       \
        *terminateSimulation = 0;                                                                  \
        return fmi3OK;                                                                             \
    }

/* Model Exchange's counts of a test FMU without event indicators: `count` continuous states,
 * no event indicators (their call accepts the empty array). */
#define FMI3_TEST_STATE_COUNTS(count)                                                              \
    fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {                 \
        *n = count;                                                                                \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {                  \
        *n = 0;                                                                                    \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) { return fmi3OK; }

/* Model Exchange without continuous states or event indicators: the counts 0, the state
 * and indicator calls accept their empty arrays, no integrator step asks for an event. */
#define FMI3_TEST_NO_CONTINUOUS_STATES                                                             \
    FMI3_TEST_STATE_COUNTS(0)                                                                      \
    fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) { return fmi3OK; } \
    FMI3_TEST_NO_STEP_EVENTS

/* fmi3SetClock of a single input clock, value reference `clock`, in Event Mode only (the
 * instance's int member in_event_mode): each tick runs `on_tick` (statements on `c`, the
 * instance). */
#define FMI3_TEST_INPUT_CLOCK(Type, clock, on_tick)                                                \
    fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[]) { \
        Type *c = instance;                                                                        \
        if (!c->in_event_mode) return fail(c, "fmi3SetClock outside Event Mode");                  \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] != clock) return fail(c, "fmi3SetClock: not an input clock");                \
            if (!v[k]) continue;                                                                   \
            on_tick                                                                                \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }

/* A single clock of constant interval: fmi3GetIntervalDecimal gives `interval` for value
 * reference `clock` (fmi3IntervalUnchanged), fmi3GetShiftDecimal a shift of 0. */
#define FMI3_TEST_CONSTANT_CLOCK(Type, clock, interval)                                            \
    fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, \
        fmi3Float64 v[], fmi3IntervalQualifier q[]) {                                              \
        for (size_t k = 0; k < n; k++) {                                                           \
            if (vr[k] != clock) return fail((Type *)instance, "fmi3GetIntervalDecimal: no interval"); \
            v[k] = interval;                                                                       \
            q[k] = fmi3IntervalUnchanged;                                                          \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, \
        fmi3Float64 v[]) {                                                                         \
        for (size_t k = 0; k < n; k++) v[k] = 0.0;                                                 \
        return fmi3OK;                                                                             \
    }

/* Model Exchange's continuous states of a test FMU without event indicators: `count` states,
 * the doubles at the addresses listed (expressions of `c`, the instance), read and written in
 * that order, each of nominal 1. */
#define FMI3_TEST_CONTINUOUS_STATES(Type, count, ...)                                              \
    FMI3_TEST_STATE_COUNTS(count)                                                                  \
    fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {         \
        Type *c = instance;                                                                        \
        double *states[] = {__VA_ARGS__};                                                          \
        if (n != count) return fail(c, "fmi3GetContinuousStates: n != " #count);                   \
        for (size_t i = 0; i < n; i++) x[i] = *states[i];                                          \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) {   \
        Type *c = instance;                                                                        \
        double *states[] = {__VA_ARGS__};                                                          \
        if (n != count) return fail(c, "fmi3SetContinuousStates: n != " #count);                   \
        for (size_t i = 0; i < n; i++) *states[i] = x[i];                                          \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) { \
        for (size_t i = 0; i < n; i++) x[i] = 1.0;                                                 \
        return fmi3OK;                                                                             \
    }


#endif
