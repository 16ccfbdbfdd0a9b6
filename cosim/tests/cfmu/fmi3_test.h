/* Shared by the FMI 3.0 C test FMUs of the master's tests (fmi3_clocks.c, fmi3_counter.c,
 * fmi3_partitions.c, fmi3_sized.c), written against the standard's headers (the tests pass
 * their folder with -I; fmi3_clocked_exchange.c too): fmi3GetVersion and the helpers that are the same in each. Each .c
 * file is one shared library and includes this header once. After its instance's struct (a
 * `Type` with members `fmi3InstanceEnvironment env` and `fmi3LogMessageCallback log`), a
 * file writes FMI3_TEST_FAIL(Type) for its `fail`, and an Event Mode only Co-Simulation
 * FMU FMI3_TEST_EVENT_MODE_INSTANCE for its lifecycle. */
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

/* The lifecycle of a Co-Simulation `Type` (members `env` and `log`) that runs in Event Mode
 * only: fmi3InstantiateCoSimulation refuses (NULL, logged) another instantiation token than
 * `token_text` and eventModeUsed false, else calls `start(Type *)` on the zeroed instance;
 * fmi3FreeInstance frees it; fmi3SetDebugLogging accepts anything. */
#define FMI3_TEST_EVENT_MODE_INSTANCE(Type, token_text, start)                                  \
    fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, \
        fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean eventMode, fmi3Boolean earlyReturnAllowed, \
        const fmi3ValueReference req[], size_t nReq, fmi3InstanceEnvironment env,                  \
        fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {                       \
        if (!token || strcmp(token, token_text) != 0 || !eventMode) {                              \
            if (log) log(env, fmi3Error, "logStatusError", "wrong instantiationToken or no eventModeUsed"); \
            return NULL;                                                                           \
        }                                                                                          \
        Type *c = calloc(1, sizeof(Type));                                                         \
        if (!c) return NULL;                                                                       \
        c->env = env;                                                                              \
        c->log = log;                                                                              \
        start(c);                                                                                  \
        return c;                                                                                  \
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

/* Model Exchange without continuous states or event indicators: the counts 0, the state
 * and indicator calls accept their empty arrays, no integrator step asks for an event. */
#define FMI3_TEST_NO_CONTINUOUS_STATES                                                             \
    fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {                 \
        *n = 0;                                                                                    \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {                  \
        *n = 0;                                                                                    \
        return fmi3OK;                                                                             \
    }                                                                                              \
    fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) { return fmi3OK; } \
    fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetPrior,          \
        fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {                           \
        *enterEventMode = 0;                                                                       \
        *terminateSimulation = 0;                                                                  \
        return fmi3OK;                                                                             \
    }

#endif
