/* Van der Pol oscillator, FMI 2.0 Model Exchange, after the Reference FMU VanDerPol:
 *   x0' = x1,  x1' = mu (1 - x0^2) x1 - x0,  x0(0) = 2, x1(0) = 0,
 * with fmi2GetDirectionalDerivative of the state derivatives with respect to the states
 * (the Jacobian [[0, 1], [-2 mu x0 x1 - 1, mu (1 - x0^2)]]), each call counted.
 * Value references: 0 x0, 1 der(x0), 2 x1, 3 der(x1), 4 mu (parameter), 5 directional_calls,
 * 6 derivative_calls (locals: the calls of fmi2GetDirectionalDerivative and of
 * fmi2GetDerivatives so far). Built with -DWRONG_JACOBIAN every partial derivative is doubled;
 * with -DOVERRUN_OWN_BLOCK fmi2GetDirectionalDerivative writes 16 bytes past a block of two
 * doubles the instance allocated through allocateMemory at its first call and keeps (as MapleSim 2023's
 * ControlledTemperature does with a block of its own); with -DOVERRUN_DV_UNKNOWN it writes
 * dvUnknown[nUnknown] and dvUnknown[nUnknown + 1], past the master's buffer. */
#define FMI2_TEST_NO_FMU_STATE
#define FMI2_TEST_DIRECTIONAL_DERIVATIVE
#include "fmi2_test.h"

typedef struct {
    double r[7];
    double time;
    double *work; /* -DOVERRUN_OWN_BLOCK: the instance's block of two doubles */
} Vdp;

static void defaults(Vdp *v) {
    memset(v, 0, sizeof *v);
    v->r[0] = 2.0;
    v->r[4] = 1.0;
}

FMI2_TEST_MODEL_EXCHANGE(Vdp)

static void derivatives(Vdp *v) {
    double x0 = v->r[0], x1 = v->r[2], mu = v->r[4];
    v->r[1] = x1;
    v->r[3] = mu * (1.0 - x0 * x0) * x1 - x0;
}

FMI2_TEST_TWO_STATES(Vdp)

/* d der(vr_unknown) / d state(vr_known) */
static int partial(const Vdp *m, fmi2ValueReference unknown, fmi2ValueReference known, double *out) {
    double x0 = m->r[0], x1 = m->r[2], mu = m->r[4];
    if (unknown == 1 && known == 0) *out = 0.0;
    else if (unknown == 1 && known == 2) *out = 1.0;
    else if (unknown == 3 && known == 0) *out = -2.0 * mu * x0 * x1 - 1.0;
    else if (unknown == 3 && known == 2) *out = mu * (1.0 - x0 * x0);
    else return 0;
#ifdef WRONG_JACOBIAN
    *out *= 2.0; /* a wrong Jacobian: built with -DWRONG_JACOBIAN */
#endif
    return 1;
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const double dv[],
                                               double dz[]) {
    Vdp *m = c;
    size_t i, j;
    double p;
#ifdef OVERRUN_OWN_BLOCK
    if (!m->work && !(m->work = fmi2_test_allocate(2, sizeof *m->work))) return ERR;
    for (i = 0; i < 4; i++) m->work[i] = 0.0; /* two doubles past the block's end */
#endif
#ifdef OVERRUN_DV_UNKNOWN
    dz[nu] = dz[nu + 1] = 0.0; /* past the nu values of the master's buffer */
#endif
    m->r[5] += 1.0;
    for (i = 0; i < nu; i++) {
        dz[i] = 0.0;
        for (j = 0; j < nz; j++) {
            if (!partial(m, u[i], z[j], &p)) return ERR;
            dz[i] += p * dv[j];
        }
    }
    return 0;
}

EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) {
    Vdp *m = c;
    if (n != 2) return ERR;
    m->r[6] += 1.0;
    derivatives(m);
    dx[0] = m->r[1];
    dx[1] = m->r[3];
    return 0;
}
