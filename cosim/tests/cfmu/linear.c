/* A stiff linear system, FMI 2.0 Model Exchange, with a closed-form solution:
 *   x1' = -lambda x1 + x2,  x2' = -x2,  x1(0) = x2(0) = 1:
 *   x2 = e^-t,  x1 = (1 - 1/(lambda - 1)) e^(-lambda t) + e^-t / (lambda - 1).
 * No directional derivatives (the master differences the right-hand side).
 * Value references: 0 x1, 1 der(x1), 2 x2, 3 der(x2), 4 lambda (parameter, 1e4). */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

typedef struct {
    double r[5];
    double time;
} Linear;

static void defaults(Linear *m) {
    memset(m, 0, sizeof *m);
    m->r[0] = 1.0;
    m->r[2] = 1.0;
    m->r[4] = 1e4;
}

FMI2_TEST_INSTANCE(Linear, type == 0)
FMI2_TEST_EXIT_INITIALIZATION
FMI2_TEST_CONTINUOUS_TIME(Linear)

static void derivatives(Linear *m) {
    m->r[1] = -m->r[4] * m->r[0] + m->r[2];
    m->r[3] = -m->r[2];
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Linear *m = c;
    size_t i;
    derivatives(m);
    for (i = 0; i < n; i++) {
        if (vr[i] >= 5) return ERR;
        v[i] = m->r[vr[i]];
    }
    return 0;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const double v[]) {
    Linear *m = c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] != 0 && vr[i] != 2 && vr[i] != 4) return ERR;
        m->r[vr[i]] = v[i];
    }
    return 0;
}
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    memset(info, 0, sizeof *info);
    return 0;
}
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) {
    Linear *m = c;
    if (n != 2) return ERR;
    m->r[0] = x[0];
    m->r[2] = x[1];
    return 0;
}
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) {
    Linear *m = c;
    if (n != 2) return ERR;
    x[0] = m->r[0];
    x[1] = m->r[2];
    return 0;
}
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) {
    Linear *m = c;
    if (n != 2) return ERR;
    derivatives(m);
    dx[0] = m->r[1];
    dx[1] = m->r[3];
    return 0;
}
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, double x[], size_t n) {
    size_t i;
    for (i = 0; i < n; i++) x[i] = 1.0;
    return 0;
}
