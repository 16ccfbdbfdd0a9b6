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
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3ClockUpdateCallback update;
    fmi3LockPreemptionCallback lock;
    fmi3UnlockPreemptionCallback unlock;
    double u, x, t_later, last_time;
    int n[4], first, out, later_changed;
} Partitions;

FMI3_TEST_FAIL(Partitions)

static void start(Partitions *p, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    p->lock = lock;
    p->unlock = unlock;
    p->u = 1.0;
    p->last_time = -1.0;
}

FMI3_TEST_SCHEDULED_INSTANCE(Partitions, "{fmi3-partitions}", start)
FMI3_TEST_NOTHING_TO_INITIALIZE
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { return fmi3OK; }

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock, fmi3Float64 time) {
    Partitions *p = instance;
    note_first_partition(&p->first, &p->last_time, clock, time);
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

/* the countdown clock later: 0.125 s, changed when slow set it */
FMI3_TEST_ONE_INTERVAL(Partitions, 3, 0.125, later_changed)

FMI3_TEST_OUTPUT_CLOCK(Partitions, 4, out)

FMI3_TEST_GET(Float64, fmi3Float64, Partitions, [10] = &c->u, [11] = &c->x, [12] = &c->t_later)
FMI3_TEST_SET(Float64, fmi3Float64, Partitions, "only u", [10] = &c->u)
/* the counts n_fast .. n_kick (20 .. 23) and first (24) */
FMI3_TEST_GET(Int32, fmi3Int32, Partitions, [20] = &c->n[0], [21] = &c->n[1], [22] = &c->n[2], [23] = &c->n[3],
    [24] = &c->first)
