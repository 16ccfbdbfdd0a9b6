/* An FMI 2.0 Co-Simulation FMU that reports what the importer told it in
 * fmi2SetupExperiment, as an FMU with an internal solver uses it.
 * Value references: 0 told_tolerance (output: the tolerance, -1 when toleranceDefined is
 * false), 1 y = time (output). */
#define FMI2_TEST_NO_FMU_STATE
#define FMI2_TEST_NO_MODEL_EXCHANGE
#include "fmi2_test.h"

typedef struct {
    double told_tolerance, time;
} Told;

EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                                     const fmi2CallbackFunctions *cb, int visible, int logging) {
    Told *m;
    if (!cb || !cb->logger || type != 1) return NULL;
    m = calloc(1, sizeof *m);
    m->told_tolerance = -2.0; /* fmi2SetupExperiment not called */
    return m;
}
EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, int tolDef, double tol, double t0, int stopDef,
                                      double stop) {
    Told *m = c;
    m->told_tolerance = tolDef ? tol : -1.0;
    m->time = t0;
    return 0;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) { return ERR; }

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Told *m = c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] == 0) v[i] = m->told_tolerance;
        else if (vr[i] == 1) v[i] = m->time;
        else return ERR;
    }
    return 0;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const double v[]) {
    return n ? ERR : 0;
}
EXPORT fmi2Status fmi2DoStep(fmi2Component c, double t, double h, int noSetPrior) {
    ((Told *)c)->time = t + h;
    return 0;
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return ERR; }
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, int s, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, int s, double *v) { *v = ((Told *)c)->time; return 0; }
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, int s, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, int s, int *v) { *v = 0; return 0; }
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, int s, const char **v) { return ERR; }
