/* Tiny FMI 2.0 Co-Simulation test models for the master's tests, one per MODEL value:
 *   1 source:     output y = slope * t                     (y depends on nothing)
 *   2 gain:       input u, output y = k * u                 (direct feedthrough)
 *   3 integrator: input u, output x, x' = u (exact for inputs held over a step)
 *   4 faulty:     output y = t; from t >= fail_time doStep returns `mode` (3 Error, 2 Discard)
 * Value references: Reals 0.. in the order listed in each modelDescription.xml.
 * Built with -DOMIT_DOSTEP the library lacks fmi2DoStep; with -DWORK=N each fmi2DoStep also
 * does N rounds of floating-point work (a heavier FMU for the thread benchmarks). */
#include <stdarg.h>
#include <stdio.h>
#define FMI2_TEST_NO_MODEL_EXCHANGE
#include "fmi2_test.h"

#define NR 8
typedef struct {
    double r[NR];
    double time;
    fmi2CallbackFunctions cb;
    char name[64];
} Model;

static void log_msg(Model *m, fmi2Status s, const char *msg) {
    if (m->cb.logger) m->cb.logger(m->cb.componentEnvironment, m->name, s, "log", "%s", msg);
}

static void defaults(Model *m) {
    memset(m->r, 0, sizeof m->r);
#if MODEL == 1
    m->r[1] = 1.0; /* slope */
#elif MODEL == 2
    m->r[2] = 2.0; /* k */
#elif MODEL == 4
    m->r[1] = 0.5; /* fail_time */
    m->r[2] = 3.0; /* mode */
    m->r[3] = 0.0; /* max_ok_step: larger steps are discarded (0: off) */
#endif
}

static void outputs(Model *m) {
#if MODEL == 1
    m->r[0] = m->r[1] * m->time;
#elif MODEL == 2
    m->r[1] = m->r[2] * m->r[0];
#elif MODEL == 4
    m->r[0] = m->time;
#endif
}

EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                                     const fmi2CallbackFunctions *cb, int visible, int logging) {
    Model *m;
    if (!cb || !cb->logger) return NULL;
    if (strncmp(guid, "{test-", 6) != 0) { /* each model has its own GUID {test-<id>} */
        cb->logger(cb->componentEnvironment, name, 3, "log", "%s", "wrong GUID");
        return NULL;
    }
    m = calloc(1, sizeof *m);
    m->cb = *cb;
    snprintf(m->name, sizeof m->name, "%s", name);
    defaults(m);
    return m;
}
FMI2_TEST_LIFECYCLE(Model)
FMI2_TEST_EXIT_INITIALIZATION
EXPORT fmi2Status fmi2Reset(fmi2Component c) { defaults((Model *)c); return 0; }

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Model *m = c;
    size_t i;
    outputs(m);
    for (i = 0; i < n; i++) {
        if (vr[i] >= NR) { log_msg(m, 3, "bad value reference"); return 3; }
        v[i] = m->r[vr[i]];
    }
    return 0;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const double v[]) {
    Model *m = c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= NR) { log_msg(m, 3, "bad value reference"); return 3; }
        m->r[vr[i]] = v[i];
    }
    return 0;
}

#ifndef OMIT_DOSTEP
EXPORT fmi2Status fmi2DoStep(fmi2Component c, double t, double h, int noSetPrior) {
    Model *m = c;
#ifdef WORK
    {
        volatile double acc = 0.0;
        int k;
        for (k = 0; k < WORK; k++) acc = acc * 0.999 + (double)k * h;
    }
#endif
#if MODEL == 3
    m->r[1] += m->r[0] * h;
#elif MODEL == 4
    if (m->r[3] > 0.0 && h > m->r[3] * (1.0 + 1e-9)) {
        log_msg(m, 2, "step too large, discarded");
        return 2;
    }
    if (t >= m->r[1]) {
        char msg[128];
        snprintf(msg, sizeof msg, "failing on purpose at t = %g", t);
        log_msg(m, (int)m->r[2], msg);
        return (int)m->r[2];
    }
#endif
    m->time = t + h;
    return 0;
}
#endif
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return 3; }
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, int s, int *v) { return 3; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, int s, double *v) { *v = ((Model *)c)->time; return 0; }
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, int s, int *v) { return 3; }
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, int s, int *v) { *v = 0; return 0; }
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, int s, const char **v) { return 3; }

/* FMU state: a copy of the instance. The remaining functions of the 44 (importers such as
 * fmpy resolve all of them) are fmi2_test.h's: no serialization, derivatives or Model Exchange. */
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, void **s) {
    if (!*s) *s = malloc(sizeof(Model));
    memcpy(*s, c, sizeof(Model));
    return 0;
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, void *s) {
    Model *m = c;
    fmi2CallbackFunctions cb = m->cb; /* keep the current instance's callbacks */
    memcpy(m, s, sizeof(Model));
    m->cb = cb;
    return 0;
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, void **s) { free(*s); *s = NULL; return 0; }
