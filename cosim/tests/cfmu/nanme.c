/* Exponential decay x' = -x (x(0) = 1), FMI 2.0 Model Exchange, that misbehaves from
 * t >= t_bad on, all with fmi2OK: mode 1, the derivative is NaN; mode 2, the derivative is
 * +Inf (Dormand-Prince's error estimate then sums +Inf and -Inf stages: NaN); mode 3,
 * fmi2NewDiscreteStates defines a next event time of NaN (at every event iteration).
 * Value references: 0 x, 1 der(x), 2 t_bad, 3 mode. */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"
#include <math.h>

/* x, der(x), t_bad, mode */
FMI2_TEST_REALS_MODEL(Decay, 4, 1.0, 0.0, 0.5, 0.0)

FMI2_TEST_MODEL_EXCHANGE(Decay)

static double derivative(const Decay *d) {
    if (d->time >= d->r[2] && d->r[3] == 1.0) return NAN;
    if (d->time >= d->r[2] && d->r[3] == 2.0) return INFINITY;
    return -d->r[0];
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Decay *d = c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= 4) return ERR;
        v[i] = vr[i] == 1 ? derivative(d) : d->r[vr[i]];
    }
    return 0;
}
FMI2_TEST_SET_REALS(Decay, 4)
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Decay *d = c;
    memset(info, 0, sizeof *info);
    if (d->r[3] == 3.0) {
        info->nextEventTimeDefined = 1;
        info->nextEventTime = NAN;
    }
    return 0;
}
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) {
    if (n != 1) return ERR;
    ((Decay *)c)->r[0] = x[0];
    return 0;
}
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) {
    if (n != 1) return ERR;
    x[0] = ((Decay *)c)->r[0];
    return 0;
}
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) {
    if (n != 1) return ERR;
    dx[0] = derivative((Decay *)c);
    return 0;
}
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) {
    return n == 0 ? 0 : ERR;
}
FMI2_TEST_UNIT_NOMINALS
