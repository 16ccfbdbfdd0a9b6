/* A Co-Simulation FMU that misbehaves without returning an error:
 *  - fmi2Instantiate logs hostile format strings (the master must neither crash nor show
 *    its own memory) and one well-formed message with arguments, in this order:
 *      1 "%s%n%n%s" without arguments
 *      2 "%s" whose argument points into the master's program (its logger function)
 *      3 "%s" whose argument is an unmapped address
 *      4 "%*d" (a width read from the arguments)
 *      5 "x = %g, n = %d, s = %s, %5.2f%%, %c%lld" with its arguments
 *  - output y = t (value reference 0) until t >= t_bad (parameter, value reference 1,
 *    default 0.5), then y = `bad` (value reference 2: 0 NaN, 1 +Inf, 2 -Inf), with fmi2OK. */
#include <math.h>
#include <stdio.h>
#define FMI2_TEST_NO_MODEL_EXCHANGE
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

typedef struct {
    double y, t_bad, bad, time;
} Model;

typedef void (*Logger6)(void *, const char *, fmi2Status, const char *, const char *, const char *);

EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                                     const fmi2CallbackFunctions *cb, int visible, int logging) {
    Model *m;
    void *env = cb->componentEnvironment;
    /* the same ABI as a variadic call with one argument: the register a missing
     * argument is read from holds the address of the master's logger */
    Logger6 six = (Logger6)cb->logger;
    cb->logger(env, name, 1, "log", "%s%n%n%s");
    six(env, name, 1, "log", "%s", (const char *)cb->logger);
    six(env, name, 1, "log", "%s", (const char *)16);
    cb->logger(env, name, 1, "log", "%*d");
    cb->logger(env, name, 1, "log", "x = %g, n = %d, s = %s, %5.2f%%, %c%lld", 1.5, 42, "ok", 3.14159, 'Z', -7LL);
    m = calloc(1, sizeof *m);
    m->t_bad = 0.5;
    return m;
}
FMI2_TEST_LIFECYCLE(Model)
FMI2_TEST_EXIT_INITIALIZATION
EXPORT fmi2Status fmi2Reset(fmi2Component c) { return 0; }
static void outputs(Model *m) {
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    int k = (int)m->bad;
    m->y = m->time >= m->t_bad ? bad[k >= 0 && k < 3 ? k : 0] : m->time;
}
EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Model *m = c;
    size_t i;
    outputs(m);
    for (i = 0; i < n; i++) {
        if (vr[i] == 0) v[i] = m->y;
        else if (vr[i] == 1) v[i] = m->t_bad;
        else if (vr[i] == 2) v[i] = m->bad;
        else return ERR;
    }
    return 0;
}
FMI2_TEST_SET_REAL_MEMBERS(Model, [1] = &m->t_bad, [2] = &m->bad)
EXPORT fmi2Status fmi2DoStep(fmi2Component c, double t, double h, int noSetPrior) {
    ((Model *)c)->time = t + h;
    return 0;
}
FMI2_TEST_NO_STATUS
