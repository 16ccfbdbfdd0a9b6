/* An FMI 3.0 Co-Simulation test FMU with a structural parameter, written against the
 * standard's headers (fmi3Functions.h; the test passes their folder with -I).
 *
 * Variables (value references as the test's description has them):
 *   0 time (independent)
 *   1 n  UInt64 structural parameter (fixed, start 2): the size of k and y; set in
 *        Configuration Mode only (fmi3Error elsewhere)
 *   2 k  Float64[n] parameter (start 1 for every element)
 *   3 u  Float64 input (start 1)
 *   4 y  Float64[n] output: y[i] = k[i] u t after each step (0 before the first)
 * The arrays are sized when the FMU leaves Configuration Mode (before initialization, or in
 * Reconfiguration Mode from Step Mode or Event Mode: k all 1 and y all 0 again); every get
 * and set of k and y must pass exactly n values (fmi3Error otherwise), so a master that gets
 * the size wrong fails. Model Exchange: no states, y = k u t at the time set (fmi3SetTime).
 * The functions a Co-Simulation or Model Exchange run calls exist; the others are absent. */
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    int configuring, model_exchange;
    unsigned long long n;
    double time, u, *k, *y;
} Sized;

FMI3_TEST_FAIL(Sized)

/* k all 1 and y all 0, for the current n */
static int size_arrays(Sized *s) {
    free(s->k);
    free(s->y);
    s->k = calloc(s->n ? s->n : 1, sizeof(double));
    s->y = calloc(s->n ? s->n : 1, sizeof(double));
    if (!s->k || !s->y) return 0;
    for (unsigned long long i = 0; i < s->n; i++) s->k[i] = 1.0;
    return 1;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean eventMode, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference req[], size_t nReq, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
    if (!token || strcmp(token, "{fmi3-sized}") != 0) return NULL;
    Sized *s = calloc(1, sizeof(Sized));
    if (!s) return NULL;
    s->env = env;
    s->log = log;
    s->n = 2;
    s->u = 1.0;
    if (!size_arrays(s)) return NULL;
    return s;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    Sized *s = fmi3InstantiateCoSimulation(name, token, resources, visible, logging, 0, 0, NULL, 0, env, log, NULL);
    if (s) s->model_exchange = 1;
    return s;
}

/* Model Exchange: y follows the time set */
static void compute_me(Sized *s) {
    if (s->model_exchange)
        for (unsigned long long i = 0; i < s->n; i++) s->y[i] = s->k[i] * s->u * s->time;
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Sized *)instance)->time = time;
    compute_me(instance);
    return fmi3OK;
}
fmi3Status fmi3EnterEventMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    compute_me(instance);
    *needUpdate = *terminate = *nominalsChanged = *valuesChanged = *nextDefined = 0;
    *next = 0;
    return fmi3OK;
}
FMI3_TEST_NO_CONTINUOUS_STATES

void fmi3FreeInstance(fmi3Instance instance) {
    Sized *s = instance;
    free(s->k);
    free(s->y);
    free(s);
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    ((Sized *)instance)->configuring = 1;
    return fmi3OK;
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    Sized *s = instance;
    s->configuring = 0;
    return size_arrays(s) ? fmi3OK : fail(s, "out of memory");
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((Sized *)instance)->time = startTime;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
    fmi3Boolean *event, fmi3Boolean *terminate, fmi3Boolean *early, fmi3Float64 *reached) {
    Sized *s = instance;
    s->time = t + h;
    for (unsigned long long i = 0; i < s->n; i++) s->y[i] = s->k[i] * s->u * s->time;
    return step_reached(s->time, event, terminate, early, reached);
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3Float64 values[], size_t nValues) {
    Sized *s = instance;
    size_t j = 0;
    for (size_t i = 0; i < nvr; i++) {
        const double *array = vr[i] == 2 ? s->k : vr[i] == 4 ? s->y : NULL;
        if (array) {
            if (nValues - j < s->n) return fail(s, "fmi3GetFloat64: fewer values than the array has");
            for (unsigned long long e = 0; e < s->n; e++) values[j++] = array[e];
        } else if (vr[i] == 0 && j < nValues) {
            values[j++] = s->time;
        } else if (vr[i] == 3 && j < nValues) {
            values[j++] = s->u;
        } else {
            return fail(s, "fmi3GetFloat64: unknown value reference");
        }
    }
    return j == nValues ? fmi3OK : fail(s, "fmi3GetFloat64: nValues is not the number of values");
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3Float64 values[], size_t nValues) {
    Sized *s = instance;
    size_t j = 0;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == 2) {
            if (nValues - j < s->n) return fail(s, "fmi3SetFloat64: fewer values than k has");
            for (unsigned long long e = 0; e < s->n; e++) s->k[e] = values[j++];
        } else if (vr[i] == 3 && j < nValues) {
            s->u = values[j++];
            compute_me(s);
        } else {
            return fail(s, "fmi3SetFloat64: not a settable value reference");
        }
    }
    return j == nValues ? fmi3OK : fail(s, "fmi3SetFloat64: nValues is not the number of values");
}

fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3UInt64 values[], size_t nValues) {
    Sized *s = instance;
    if (nvr != 1 || nValues != 1 || vr[0] != 1) return fail(s, "fmi3GetUInt64: only n");
    values[0] = s->n;
    return fmi3OK;
}

fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3UInt64 values[], size_t nValues) {
    Sized *s = instance;
    if (nvr != 1 || nValues != 1 || vr[0] != 1) return fail(s, "fmi3SetUInt64: only n");
    if (!s->configuring) return fail(s, "fmi3SetUInt64: n is set in Configuration Mode only");
    s->n = values[0];
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    Sized *s = instance;
    s->n = 2;
    s->u = 1.0;
    s->time = 0.0;
    return size_arrays(s) ? fmi3OK : fail(s, "out of memory");
}
