/* A Co-Simulation FMU that misbehaves in fmi2DoStep once t >= t_crash, as third-party FMUs
 * do. Reals: 0 y (output, = the time reached), 1 mode (parameter), 2 t_crash (parameter).
 *   mode 0: behaves (y = t + h); 1: writes through a null pointer (SIGSEGV); 2: abort()
 *   (SIGABRT); 3: unbounded recursion (stack overflow); 4: exit(0); 5: never returns;
 *   6: logs one warning of 10 MB (10,000,000 'x') and goes on; 7: behaves, but
 *   fmi2FreeInstance frees its memory twice (glibc aborts: SIGABRT). */
#define FMI2_TEST_NO_FMU_STATE
#define FMI2_TEST_NO_MODEL_EXCHANGE
#include "fmi2_test.h"
#include <unistd.h>

typedef struct {
    double r[3];
} Crash;

typedef void (*Logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
static Logger logger;
static void *log_env;
EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                                     const fmi2CallbackFunctions *cb, int visible, int logging) {
    Crash *c;
    if (!cb || !cb->logger || type != 1) return NULL;
    c = calloc(1, sizeof *c);
    if (c) c->r[2] = 0.5;
    logger = (Logger)cb->logger;
    log_env = cb->componentEnvironment;
    return c;
}
EXPORT void fmi2FreeInstance(fmi2Component c) {
    int twice = ((Crash *)c)->r[1] == 7;
    free(c);
    if (twice) free(*(void *volatile *)&c);
}
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, int a, double tol, double t0, int d, double stop) {
    ((Crash *)c)->r[0] = t0;
    return 0;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) { return 0; }
EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= 3) return ERR;
        v[i] = ((Crash *)c)->r[vr[i]];
    }
    return 0;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const double v[]) {
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= 3) return ERR;
        ((Crash *)c)->r[vr[i]] = v[i];
    }
    return 0;
}

static volatile int sink;
static int deep(int n) {
    volatile char frame[4096];
    frame[0] = (char)n;
    return deep(n + 1) + frame[0];
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, double t, double h, int noSetPrior) {
    Crash *s = c;
    if (t + 1e-12 >= s->r[2]) {
        switch ((int)s->r[1]) {
        case 1: *(volatile int *)0 = 1; break;
        case 2: abort();
        case 3: sink = deep(0); break;
        case 4: exit(0);
        case 5: for (;;) pause();
        case 6: {
            char *text = malloc(10000001);
            if (!text) return ERR;
            memset(text, 'x', 10000000);
            text[10000000] = 0;
            logger(log_env, "crash", 1, "log", "%s", text); /* a warning: shown */
            free(text);
            s->r[1] = 0; /* once */
            break;
        }
        default: break;
        }
    }
    s->r[0] = t + h;
    return 0;
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return ERR; }
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, int s, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, int s, double *v) { return ERR; }
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, int s, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, int s, int *v) { return ERR; }
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, int s, const char **v) { return ERR; }
