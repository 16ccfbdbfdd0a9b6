/* An FMI 3.0 Co-Simulation test FMU with clocks (Event Mode only), written against the
 * standard's headers (the test passes their folder with -I). Value references as in
 * fmi3_clocks.xml:
 *   1 periodic   input clock, constant: interval 0.25 s, shift 0.1 s (the description's)
 *   2 fixed      input clock, fixed: the interval is the parameter fixed_interval (20, 0.4 s),
 *                given by fmi3GetIntervalDecimal (the description's 0.5 s is not used)
 *   3 changing   input clock, changing: the k-th interval (k = 1, 2, ...) is 0.1 k s, given
 *                (fmi3IntervalChanged) in the event that ends initialization and in the
 *                event of each of its ticks; otherwise fmi3IntervalUnchanged
 *   4 countdown  input clock, countdown: started (interval 0.5 s, fmi3IntervalChanged) in the
 *                event of the second tick of periodic; fmi3IntervalNotYetKnown otherwise
 *   5 trig       input clock, triggered
 *   6 out_clock  output clock: ticks in the event of every second tick of periodic
 *   10..15 n_*   Int32 outputs: the ticks of each clock so far
 *   16 last_tick Float64 output: the time of the last event with a tick
 * fmi3DoStep advances the time and never asks for an event. */
#include "fmi3_test.h"

typedef struct {
    double time, fixed_interval, last_tick;
    int n[6];             /* ticks of clocks 1..6 */
    int in_event_mode, changing_given, countdown_given, out_ticked;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Clocks;

FMI3_TEST_FAIL(Clocks)

static void start(Clocks *c) {
    c->fixed_interval = 0.4;
    c->last_tick = -1;
}

/* no Model Exchange or Scheduled Execution instance: fmi3_rest.c's NULL */
FMI3_TEST_EVENT_MODE_INSTANCE(Clocks, "{fmi3-clocks}", start)

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((Clocks *)instance)->time = startTime;
    return fmi3OK;
}
/* after initialization the instance is in Event Mode (eventModeUsed) */
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ((Clocks *)instance)->changing_given = 0;
    return fmi3EnterEventMode(instance);
}
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Clocks *c = instance;
    c->in_event_mode = 0;
    c->out_ticked = 0;
    return fmi3OK;
}
FMI3_TEST_EVENT_MODE_STEPS(Clocks)
FMI3_TEST_RESET(Clocks, start)

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[]) {
    Clocks *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3SetClock outside Event Mode");
    for (size_t k = 0; k < n; k++) {
        if (vr[k] < 1 || vr[k] > 5) return fail(c, "fmi3SetClock: not an input clock");
        if (!v[k]) continue;
        c->n[vr[k] - 1]++;
        c->last_tick = c->time;
        if (vr[k] == 1 && c->n[0] % 2 == 0) {
            c->n[5]++;
            c->out_ticked = 1;
            if (c->n[0] == 2) c->countdown_given = 1;
        }
        if (vr[k] == 3) c->changing_given = 0;
    }
    return fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Clock v[]) {
    Clocks *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3GetClock outside Event Mode");
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 6) return fail(c, "fmi3GetClock: not an output clock");
        v[k] = c->out_ticked;
    }
    return fmi3OK;
}

/* The qualifier of clock vr's interval now, and what asking it changes; 0: no interval. */
static int interval_qualifier(Clocks *c, fmi3ValueReference vr, fmi3IntervalQualifier *q) {
    switch (vr) {
    case 1: case 2: *q = fmi3IntervalUnchanged; return 1;
    case 3:
        *q = c->changing_given ? fmi3IntervalUnchanged : fmi3IntervalChanged;
        c->changing_given = 1;
        return 1;
    case 4:
        *q = c->countdown_given == 1 ? fmi3IntervalChanged : fmi3IntervalNotYetKnown;
        if (c->countdown_given == 1) c->countdown_given = 2;
        return 1;
    default: return 0;
    }
}

#ifndef FMI3_FRACTION_ONLY
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3Float64 v[], fmi3IntervalQualifier q[]) {
    Clocks *c = instance;
    for (size_t k = 0; k < n; k++) {
        switch (vr[k]) {
        case 1: v[k] = 0.25; break;
        case 2: v[k] = c->fixed_interval; break;
        case 3: v[k] = 0.1 * (c->n[2] + 1); break;
        case 4: v[k] = 0.5; break;
        }
        if (!interval_qualifier(c, vr[k], &q[k])) return fail(c, "fmi3GetIntervalDecimal: no interval");
    }
    return fmi3OK;
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[]) {
    for (size_t k = 0; k < n; k++) v[k] = vr[k] == 1 ? 0.1 : 0.0;
    return fmi3OK;
}
#else
/* Built with FMI3_FRACTION_ONLY (and fmi3_rest.c likewise): the same intervals and shifts as
 * fractions, counter / resolution, and no fmi3GetIntervalDecimal or fmi3GetShiftDecimal at
 * all, so that the importer must use the Fraction functions: periodic 1/4, fixed
 * fixed_interval in thousandths (400/1000), changing k/10, countdown 1/2; periodic's shift
 * 1/10. */
fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier q[]) {
    Clocks *c = instance;
    for (size_t k = 0; k < n; k++) {
        switch (vr[k]) {
        case 1: counters[k] = 1; resolutions[k] = 4; break;
        case 2: counters[k] = (fmi3UInt64)(c->fixed_interval * 1000 + 0.5); resolutions[k] = 1000; break;
        case 3: counters[k] = (fmi3UInt64)(c->n[2] + 1); resolutions[k] = 10; break;
        case 4: counters[k] = 1; resolutions[k] = 2; break;
        }
        if (!interval_qualifier(c, vr[k], &q[k])) return fail(c, "fmi3GetIntervalFraction: no interval");
    }
    return fmi3OK;
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
    fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    for (size_t k = 0; k < n; k++) {
        counters[k] = vr[k] == 1 ? 1 : 0;
        resolutions[k] = 10;
    }
    return fmi3OK;
}
#endif

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    Clocks *c = instance;
    if (!c->in_event_mode) return fail(c, "fmi3UpdateDiscreteStates outside Event Mode");
    return updated_discrete_states(needUpdate, terminate, nominalsChanged, valuesChanged, nextDefined, next);
}

FMI3_TEST_GET(Float64, fmi3Float64, Clocks, [0] = &c->time, [16] = &c->last_tick, [20] = &c->fixed_interval)
FMI3_TEST_SET(Float64, fmi3Float64, Clocks, "not a parameter", [20] = &c->fixed_interval)
/* the tick counts n_* (10 .. 15) */
FMI3_TEST_GET(Int32, fmi3Int32, Clocks, [10] = &c->n[0], [11] = &c->n[1], [12] = &c->n[2], [13] = &c->n[3],
    [14] = &c->n[4], [15] = &c->n[5])
