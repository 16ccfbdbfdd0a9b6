/* A discrete FMI 2.0 Model Exchange FMU with no continuous state, for event iteration
 * across coupled FMUs. Reals (value references): 0 u (input), 1 y (output, discrete),
 * 2 count (output), 3 t_last (output), 4 mode (parameter), 5 t_event (parameter).
 *   mode 0, counter: at each event iteration, if u > 0 and the u of its previous event
 *           iteration was <= 0, count += 1 and t_last = the time; y = count. It never
 *           asks for another iteration itself: it only sees a new u if the master
 *           propagates it within the event.
 *   mode 1, follower: once its time event at t_event has come, y = u at each event
 *           iteration (before, y holds).
 *   mode 2, inverter: at each event iteration y = 1 - u.
 *   mode 3, restless: once its time event at t_event has come, y += 1 at each event
 *           iteration and it always asks for another one (no fixed point on its own).
 * A follower and an inverter in a loop have no fixed point once the follower follows.
 * A time event at t_event (if > 0). Its outputs do not depend on its input directly
 * (they change only in event mode). */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

#define NR 6
typedef struct {
    double r[NR];
    double time, u_prev;
    int fired;
} Latch;

static void defaults(Latch *l) { memset(l, 0, sizeof *l); }

FMI2_TEST_INSTANCE(Latch, type == 0)
FMI2_TEST_CONTINUOUS_TIME(Latch)

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Latch *l = c;
    l->u_prev = l->r[0];
    return 0;
}
EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Latch *l = c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= NR) return ERR;
        v[i] = l->r[vr[i]];
    }
    return 0;
}
FMI2_TEST_SET_REALS(Latch, NR)

EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Latch *l = c;
    double u = l->r[0];
    memset(info, 0, sizeof *info);
    if (l->r[5] > 0.0 && l->time >= l->r[5]) l->fired = 1;
    if (l->r[4] == 1.0) {
        if (l->fired) l->r[1] = u;
    } else if (l->r[4] == 2.0) {
        l->r[1] = 1.0 - u;
    } else if (l->r[4] == 3.0) {
        if (l->fired) {
            l->r[1] += 1.0;
            info->newDiscreteStatesNeeded = 1;
        }
    } else {
        if (u > 0.0 && l->u_prev <= 0.0) {
            l->r[2] += 1.0;
            l->r[3] = l->time;
        }
        l->r[1] = l->r[2];
    }
    l->u_prev = u;
    if (l->r[5] > 0.0 && !l->fired) {
        info->nextEventTimeDefined = 1;
        info->nextEventTime = l->r[5];
    }
    return 0;
}
FMI2_TEST_NO_CONTINUOUS_STATES
