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

static void start(Node *p, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    p->period = 0.5; /* the start of the description's period */
    p->rate_interval = 0.5;
    p->sample_fresh = 1;
    p->rate_fresh = 1;
}

FMI3_TEST_SCHEDULED_INSTANCE(Node, "{fmi3-se-node}", start)
FMI3_TEST_NOTHING_TO_INITIALIZE
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ((Node *)instance)->initialized = 1;
    return fmi3OK;
}

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

FMI3_TEST_OUTPUT_CLOCK(Node, 3, done)

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


FMI3_TEST_GET(Float64, fmi3Float64, Node, [10] = &c->period, [11] = &c->u, [12] = &c->v, [13] = &c->y, [14] = &c->z,
    [15] = &c->w)
/* the inputs u and v, and the parameter period before initialization (fixed after) */
FMI3_TEST_SET(Float64, fmi3Float64, Node, "only period (fixed after initialization), u and v",
    [10] = c->initialized ? NULL : &c->period, [11] = &c->u, [12] = &c->v)
/* the counts n_sample, n_trigger, n_rate (20 .. 22) */
FMI3_TEST_GET(Int32, fmi3Int32, Node, [20] = &c->n[0], [21] = &c->n[1], [22] = &c->n[2])
