/* Bouncing ball, FMI 2.0 Model Exchange: h' = v, v' = -g; event indicator z = h; at
 * h <= 0 with v < 0 the ball bounces: v = -e v, h = 0. A time event at t_kick (if > 0)
 * adds `kick` to v. Value references: 0 h, 1 v, 2 der(h), 3 der(v), 4 g, 5 e,
 * 6 t_kick, 7 kick. Compiled with -DINDICATORS=N it has N event indicators, all z = h. */
#ifndef INDICATORS
#define INDICATORS 1
#endif
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

typedef struct {
    double r[8];
    double time;
    int kicked;
} Ball;

static void defaults(Ball *b) {
    memset(b, 0, sizeof *b);
    b->r[0] = 1.0;  /* h */
    b->r[4] = 9.81; /* g */
    b->r[5] = 0.7;  /* e */
}

FMI2_TEST_MODEL_EXCHANGE(Ball)

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Ball *b = c;
    size_t i;
    b->r[2] = b->r[1];
    b->r[3] = -b->r[4];
    for (i = 0; i < n; i++) {
        if (vr[i] >= 8) return ERR;
        v[i] = b->r[vr[i]];
    }
    return 0;
}
FMI2_TEST_SET_REALS(Ball, 8)

EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Ball *b = c;
    memset(info, 0, sizeof *info);
    if (b->r[0] <= 0.0 && b->r[1] < 0.0) {
        b->r[0] = 0.0;
        b->r[1] = -b->r[5] * b->r[1];
        info->valuesOfContinuousStatesChanged = 1;
    }
    if (b->r[6] > 0.0 && !b->kicked && b->time >= b->r[6]) {
        b->r[1] += b->r[7];
        b->kicked = 1;
        info->valuesOfContinuousStatesChanged = 1;
    }
    if (b->r[6] > 0.0 && !b->kicked) {
        info->nextEventTimeDefined = 1;
        info->nextEventTime = b->r[6];
    }
    return 0;
}
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) {
    if (n != 2) return ERR;
    ((Ball *)c)->r[0] = x[0];
    ((Ball *)c)->r[1] = x[1];
    return 0;
}
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) {
    if (n != 2) return ERR;
    x[0] = ((Ball *)c)->r[0];
    x[1] = ((Ball *)c)->r[1];
    return 0;
}
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) {
    if (n != 2) return ERR;
    dx[0] = ((Ball *)c)->r[1];
    dx[1] = -((Ball *)c)->r[4];
    return 0;
}
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) {
    size_t i;
    if (n != INDICATORS) return ERR;
    for (i = 0; i < n; i++) z[i] = ((Ball *)c)->r[0];
    return 0;
}
FMI2_TEST_UNIT_NOMINALS
