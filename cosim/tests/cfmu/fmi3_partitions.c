/* An FMI 3.0 Scheduled Execution test FMU, written against the standard's headers.
 *
 * Clocks (value references as the test's description has them):
 *   1 fast   input, every 0.25 s, priority 1: adds u * 0.25 to x; counts; every 4th
 *            activation ticks the output clock out (clockUpdate). Locks preemption around
 *            its update (fmi3Error when the importer gave no lock callbacks).
 *   2 slow   input, every 1 s from 0.5 s, priority 0: counts; sets the countdown clock
 *            later to 0.125 s (clockUpdate)
 *   3 later  input, countdown, priority 2: counts; t_later = its activation time
 *   5 kick   input, triggered, priority 3: counts
 *   4 out    output clock
 * Variables: 10 u Float64 input (1), 11 x Float64 output, 12 t_later Float64 output,
 *   20 n_fast, 21 n_slow, 22 n_later, 23 n_kick Int32 outputs (activations), 24 first Int32
 *   output: the clock (value reference) of the first partition activated at the latest
 *   activation time. */
#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3ClockUpdateCallback update;
    fmi3LockPreemptionCallback lock;
    fmi3UnlockPreemptionCallback unlock;
    double u, x, t_later, last_time;
    int n[4], first, out, later_changed;
} Partitions;

static fmi3Status fail(Partitions *p, const char *message) {
    if (p->log) p->log(p->env, fmi3Error, "logStatusError", message);
    return fmi3Error;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
    fmi3ClockUpdateCallback update, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    if (!token || strcmp(token, "{fmi3-partitions}") != 0 || !update) return NULL;
    Partitions *p = calloc(1, sizeof(Partitions));
    if (!p) return NULL;
    p->env = env;
    p->log = log;
    p->update = update;
    p->lock = lock;
    p->unlock = unlock;
    p->u = 1.0;
    p->last_time = -1.0;
    return p;
}

void fmi3FreeInstance(fmi3Instance instance) { free(instance); }
fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock, fmi3Float64 time) {
    Partitions *p = instance;
    if (time != p->last_time) {
        p->first = (int)clock;
        p->last_time = time;
    }
    switch (clock) {
    case 1:
        if (!p->lock || !p->unlock) return fail(p, "fast: no lockPreemption/unlockPreemption");
        p->lock();
        p->x += p->u * 0.25;
        p->n[0]++;
        p->unlock();
        if (p->n[0] % 4 == 0) {
            p->out = 1;
            p->update(p->env);
        }
        return fmi3OK;
    case 2:
        p->n[1]++;
        p->later_changed = 1;
        p->update(p->env);
        return fmi3OK;
    case 3:
        p->n[2]++;
        p->t_later = time;
        return fmi3OK;
    case 5:
        p->n[3]++;
        return fmi3OK;
    default:
        return fail(p, "fmi3ActivateModelPartition: not an input clock");
    }
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    Partitions *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 3) return fail(p, "fmi3GetIntervalDecimal: only the countdown clock later");
        qualifiers[i] = p->later_changed ? fmi3IntervalChanged : fmi3IntervalUnchanged;
        intervals[i] = 0.125;
        p->later_changed = 0;
    }
    return fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Clock values[]) {
    Partitions *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 4) return fail(p, "fmi3GetClock: only the output clock out");
        values[i] = p->out != 0;
        p->out = 0;
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Float64 values[], size_t nValues) {
    Partitions *p = instance;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 10: values[i] = p->u; break;
        case 11: values[i] = p->x; break;
        case 12: values[i] = p->t_later; break;
        default: return fail(p, "fmi3GetFloat64: unknown value reference");
        }
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    const fmi3Float64 values[], size_t nValues) {
    Partitions *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 10) return fail(p, "fmi3SetFloat64: only u");
        p->u = values[i];
    }
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Int32 values[], size_t nValues) {
    Partitions *p = instance;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= 20 && vr[i] <= 23) values[i] = p->n[vr[i] - 20];
        else if (vr[i] == 24) values[i] = p->first;
        else return fail(p, "fmi3GetInt32: unknown value reference");
    }
    return fmi3OK;
}
