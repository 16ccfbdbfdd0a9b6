/* An FMI 3.0 Scheduled Execution test FMU for systems of several instances, written
 * against the standard's headers.
 *
 * Clocks (value references as the test's descriptions have them; priorities there):
 *   1 sample   input, fixed: its interval is the parameter period (fmi3GetIntervalDecimal),
 *              whatever the description says. Counts; w = v; y = n_sample; ticks the
 *              output clock done (clockUpdate).
 *   2 trigger  input, triggered: counts; z = u (u is clocked by trigger).
 *   3 done     output clock, ticked by every sample activation.
 *   4 rate     input, tunable, 0.5 s: counts; at its 2nd activation its interval becomes
 *              0.75 s (fmi3IntervalChanged, clockUpdate).
 * Variables: 10 period Float64 parameter (fixed), 11 u Float64 input clocked by trigger,
 *   12 v Float64 input, 13 y, 14 z, 15 w Float64 outputs (y, w clocked by sample, z by
 *   trigger), 20 n_sample, 21 n_trigger, 22 n_rate Int32 outputs (activations). */
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3ClockUpdateCallback update;
    double period, u, v, y, z, w, rate_interval;
    int n[3], done, sample_fresh, rate_fresh, initialized;
} Node;

FMI3_TEST_FAIL(Node)

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
    fmi3ClockUpdateCallback update, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    if (!token || strcmp(token, "{fmi3-se-node}") != 0 || !update) return NULL;
    Node *p = calloc(1, sizeof(Node));
    if (!p) return NULL;
    p->env = env;
    p->log = log;
    p->update = update;
    p->period = 0.5; /* the start of the description's period */
    p->rate_interval = 0.5;
    p->sample_fresh = 1;
    p->rate_fresh = 1;
    return p;
}

void fmi3FreeInstance(fmi3Instance instance) { free(instance); }
fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ((Node *)instance)->initialized = 1;
    return fmi3OK;
}
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock, fmi3Float64 time) {
    Node *p = instance;
    switch (clock) {
    case 1:
        p->n[0]++;
        p->w = p->v;
        p->y = p->n[0];
        p->done = 1;
        p->update(p->env);
        return fmi3OK;
    case 2:
        p->n[1]++;
        p->z = p->u;
        return fmi3OK;
    case 4:
        p->n[2]++;
        if (p->n[2] == 2) {
            p->rate_interval = 0.75;
            p->rate_fresh = 1;
            p->update(p->env);
        }
        return fmi3OK;
    default:
        return fail(p, "fmi3ActivateModelPartition: not an input clock");
    }
}

/* The fixed clock's interval is known after initialization only (the period set before). */
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    Node *p = instance;
    if (!p->initialized) return fail(p, "fmi3GetIntervalDecimal: before fmi3ExitInitializationMode");
    for (size_t i = 0; i < n; i++) {
        int *fresh;
        if (vr[i] == 1) {
            intervals[i] = p->period;
            fresh = &p->sample_fresh;
        } else if (vr[i] == 4) {
            intervals[i] = p->rate_interval;
            fresh = &p->rate_fresh;
        } else {
            return fail(p, "fmi3GetIntervalDecimal: only the clocks sample and rate");
        }
        qualifiers[i] = *fresh ? fmi3IntervalChanged : fmi3IntervalUnchanged;
        *fresh = 0;
    }
    return fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Clock values[]) {
    Node *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 3) return fail(p, "fmi3GetClock: only the output clock done");
        values[i] = p->done != 0;
        p->done = 0;
    }
    return fmi3OK;
}

static double *float64(Node *p, fmi3ValueReference vr) {
    switch (vr) {
    case 10: return &p->period;
    case 11: return &p->u;
    case 12: return &p->v;
    case 13: return &p->y;
    case 14: return &p->z;
    case 15: return &p->w;
    default: return NULL;
    }
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Float64 values[], size_t nValues) {
    Node *p = instance;
    for (size_t i = 0; i < n; i++) {
        double *x = float64(p, vr[i]);
        if (!x) return fail(p, "fmi3GetFloat64: unknown value reference");
        values[i] = *x;
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    const fmi3Float64 values[], size_t nValues) {
    Node *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 10 && p->initialized) return fail(p, "fmi3SetFloat64: period is fixed after initialization");
        if (vr[i] != 10 && vr[i] != 11 && vr[i] != 12) return fail(p, "fmi3SetFloat64: only period, u and v");
        *float64(p, vr[i]) = values[i];
    }
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Int32 values[], size_t nValues) {
    Node *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] < 20 || vr[i] > 22) return fail(p, "fmi3GetInt32: unknown value reference");
        values[i] = p->n[vr[i] - 20];
    }
    return fmi3OK;
}
