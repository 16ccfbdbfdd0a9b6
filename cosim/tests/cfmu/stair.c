/* An FMI 2.0 FMU that ends its own run, after the Reference FMU Stair, in both interfaces.
 * Real output 0 counter (discrete): 1 at the start, one more at every whole second; when it
 * reaches 10 (at t = 9 s) the FMU ends the simulation:
 *   Model Exchange: time events at 1, 2, ... s; fmi2NewDiscreteStates counts and sets
 *                   terminateSimulation once the counter is 10.
 *   Co-Simulation:  fmi2DoStep counts the whole seconds in (t, t + h]; at the one that makes
 *                   10 it stops there and returns fmi2Discard, with fmi2Terminated true and
 *                   fmi2LastSuccessfulTime that second. */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

/* A whole second within this of a step's end belongs to the step (the communication
 * points are sums of a decimal step, a few ulps off the whole second). */
#define TIME_SLACK 1e-9

typedef struct {
    double counter, time, next_event;
    int terminated;
} Stair;

/* the counter 1, its first event at 1 s, the time 0, not terminated */
static void defaults(Stair *s) { *s = (Stair){.counter = 1.0, .next_event = 1.0}; }

FMI2_TEST_INSTANCE(Stair, 1)
FMI2_TEST_EXIT_INITIALIZATION
FMI2_TEST_CONTINUOUS_TIME(Stair)

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] != 0) return ERR;
        v[i] = ((Stair *)c)->counter;
    }
    return 0;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const double v[]) {
    return n ? ERR : 0;
}

/* one whole second passed: count, and end the run at 10 */
static void tick(Stair *s) {
    s->counter += 1.0;
    s->next_event += 1.0;
    if (s->counter >= 10.0) s->terminated = 1;
}

/* Co-Simulation */
EXPORT fmi2Status fmi2DoStep(fmi2Component c, double t, double h, int noSetPrior) {
    Stair *s = c;
    if (s->terminated) return ERR;
    while (s->next_event <= t + h + TIME_SLACK) {
        s->time = s->next_event;
        tick(s);
        if (s->terminated) return 2; /* fmi2Discard */
    }
    s->time = t + h;
    return 0;
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return ERR; }
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, int kind, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, int kind, double *v) {
    if (kind != 2) return ERR; /* fmi2LastSuccessfulTime */
    *v = ((Stair *)c)->time;
    return 0;
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, int kind, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, int kind, int *v) {
    if (kind != 3) return ERR; /* fmi2Terminated */
    *v = ((Stair *)c)->terminated;
    return 0;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, int kind, const char **v) { return ERR; }
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const int order[], const double v[]) { return ERR; }
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const int order[], double v[]) { return ERR; }

/* Model Exchange */
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Stair *s = c;
    memset(info, 0, sizeof *info);
    if (s->time + TIME_SLACK >= s->next_event) tick(s);
    info->terminateSimulation = s->terminated;
    info->nextEventTimeDefined = 1;
    info->nextEventTime = s->next_event;
    return 0;
}
FMI2_TEST_NO_CONTINUOUS_STATES
