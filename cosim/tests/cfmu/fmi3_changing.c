/* An FMI 3.0 Scheduled Execution test FMU with a changing (aperiodic) clock as a model
 * partition, written against the standard's headers.
 *
 * Clocks (value references as the test's description has them):
 *   1 steps  input, changing, priority 0: its first tick `first_delay` after the start (the
 *            interval fmi3GetIntervalDecimal gives in Initialization Mode), and after its
 *            k-th activation the next one 0.25 (k + 1) s later (the interval
 *            fmi3GetIntervalDecimal gives right after that activation, fmi3IntervalChanged;
 *            asked again before the next activation, the same with fmi3IntervalUnchanged).
 *            An activation at another time than the tick the FMU gave is an error.
 *   2 fast   input, constant, every 0.5 s, priority 1
 * Variables: 10 first_delay Float64 parameter (0.25 s), 11 t_steps Float64 output (the time
 *   of steps' latest activation), 20 n_steps, 21 n_fast Int32 outputs (activations), 22
 *   first Int32 output: the clock (value reference) of the first partition activated at the
 *   latest activation time. */
#include "fmi3_test.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3ClockUpdateCallback update;
    double first_delay, t_steps, last_time, next_steps, interval;
    int n_steps, n_fast, first, changed, initializing;
} Changing;

FMI3_TEST_FAIL(Changing)

static void start(Changing *c, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    c->first_delay = 0.25;
    c->last_time = -1.0;
}

FMI3_TEST_SCHEDULED_INSTANCE(Changing, "{fmi3-changing}", start)

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Changing *c = instance;
    c->initializing = 1;
    c->interval = c->first_delay;
    c->next_steps = startTime + c->first_delay;
    c->changed = 1;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Changing *c = instance;
    c->initializing = 0;
    return fmi3OK;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock, fmi3Float64 time) {
    Changing *c = instance;
    note_first_partition(&c->first, &c->last_time, clock, time);
    switch (clock) {
    case 1:
        if (time != c->next_steps) return fail(c, "steps activated at another time than the tick the FMU gave");
        c->n_steps++;
        c->t_steps = time;
        c->interval = 0.25 * (c->n_steps + 1);
        c->next_steps = time + c->interval;
        c->changed = 1;
        return fmi3OK;
    case 2:
        c->n_fast++;
        return fmi3OK;
    default:
        return fail(c, "fmi3ActivateModelPartition: not an input clock");
    }
}

/* steps: the interval to its next tick, changed at initialization and after each activation */
FMI3_TEST_ONE_INTERVAL(Changing, 1, c->interval, changed)

FMI3_TEST_GET(Float64, fmi3Float64, Changing, [10] = &c->first_delay, [11] = &c->t_steps)
FMI3_TEST_SET(Float64, fmi3Float64, Changing, "only first_delay", [10] = &c->first_delay)
FMI3_TEST_GET(Int32, fmi3Int32, Changing, [20] = &c->n_steps, [21] = &c->n_fast, [22] = &c->first)
