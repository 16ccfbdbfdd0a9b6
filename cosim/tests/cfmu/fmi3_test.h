/* Shared by the FMI 3.0 C test FMUs of the master's tests (fmi3_clocks.c, fmi3_counter.c,
 * fmi3_partitions.c, fmi3_sized.c), written against the standard's headers (the tests pass
 * their folder with -I): fmi3GetVersion and the helpers that are the same in each. Each .c
 * file is one shared library and includes this header once. After its instance's struct (a
 * `Type` with members `fmi3InstanceEnvironment env` and `fmi3LogMessageCallback log`), a
 * file writes FMI3_TEST_FAIL(Type) for its `fail`. */
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

/* The end of an fmi3DoStep that reached `time` with no event, no end and no early return. */
static inline fmi3Status step_reached(fmi3Float64 time, fmi3Boolean *eventHandlingNeeded,
    fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    *eventHandlingNeeded = 0;
    *terminateSimulation = 0;
    *earlyReturn = 0;
    *lastSuccessfulTime = time;
    return fmi3OK;
}

#endif
