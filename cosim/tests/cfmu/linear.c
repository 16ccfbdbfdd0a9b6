/* A stiff linear system, FMI 2.0 Model Exchange, with a closed-form solution:
 *   x1' = -lambda x1 + x2,  x2' = -x2,  x1(0) = x2(0) = 1:
 *   x2 = e^-t,  x1 = (1 - 1/(lambda - 1)) e^(-lambda t) + e^-t / (lambda - 1).
 * No directional derivatives (the master differences the right-hand side).
 * Value references: 0 x1, 1 der(x1), 2 x2, 3 der(x2), 4 lambda (parameter, 1e4). */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

/* x1, der(x1), x2, der(x2), lambda */
FMI2_TEST_REALS_MODEL(Linear, 5, 1.0, 0.0, 1.0, 0.0, 1e4)

FMI2_TEST_MODEL_EXCHANGE(Linear)

static void derivatives(Linear *m) {
    m->r[1] = -m->r[4] * m->r[0] + m->r[2];
    m->r[3] = -m->r[2];
}

FMI2_TEST_TWO_STATES(Linear)
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) {
    Linear *m = c;
    if (n != 2) return ERR;
    derivatives(m);
    dx[0] = m->r[1];
    dx[1] = m->r[3];
    return 0;
}
