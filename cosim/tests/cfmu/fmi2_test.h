/* Shared by the C test FMUs of the master's tests (ball.c, latch.c, linear.c, models.c, ramp.c,
 * stair.c, vdp.c): the FMI 2.0
 * types they use and the exports that are the same in each, which refuse (fmi2Error) or
 * do nothing. Each .c file is one shared library and includes this header once, so the
 * definitions below are that library's exports.
 *
 * Before the #include a file may define:
 *   FMI2_TEST_NO_FMU_STATE       fmi2Get/Set/FreeFMUstate refused (the file has no FMU state)
 *   FMI2_TEST_NO_MODEL_EXCHANGE  every Model Exchange function refused (Co-Simulation only),
 *                                and the Co-Simulation input/output derivatives refused.
 * After its model's struct and `defaults`, a file may write FMI2_TEST_INSTANCE(Type, accepted),
 * FMI2_TEST_EXIT_INITIALIZATION and FMI2_TEST_CONTINUOUS_TIME(Type) (below) for the
 * lifecycle and mode changes that do nothing model-specific: the file then holds its model. */
#ifndef FMI2_TEST_H
#define FMI2_TEST_H

#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef int fmi2Status;
typedef unsigned int fmi2ValueReference;
typedef struct {
    void (*logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void *stepFinished;
    void *componentEnvironment;
} fmi2CallbackFunctions;
typedef struct {
    int newDiscreteStatesNeeded, terminateSimulation, nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged, nextEventTimeDefined;
    double nextEventTime;
} fmi2EventInfo;

#define EXPORT __attribute__((visibility("default")))
/* fmi2Error */
#define ERR 3

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, int on, size_t n, const char *const cat[]) { return 0; }

/* Reals only: any Integer, Boolean or String value reference is refused. */
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, int v[]) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const int v[]) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, int v[]) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const int v[]) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const char *v[]) { return n ? ERR : 0; }
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const char *const v[]) { return n ? ERR : 0; }

/* No serialization and (unless the file defines FMI2_TEST_DIRECTIONAL_DERIVATIVE and its own
 * fmi2GetDirectionalDerivative) no directional derivatives. */
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, void *s, size_t *n) { return ERR; }
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, void *s, char *b, size_t n) { return ERR; }
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const char *b, size_t n, void **s) { return ERR; }
#ifndef FMI2_TEST_DIRECTIONAL_DERIVATIVE
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const double dv[],
                                               double dz[]) { return ERR; }
#endif

#ifdef FMI2_TEST_NO_FMU_STATE
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, void **s) { return ERR; }
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, void *s) { return ERR; }
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, void **s) { return ERR; }
#endif

#ifdef FMI2_TEST_NO_MODEL_EXCHANGE
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const int order[], const double v[]) { return ERR; }
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const int order[], double v[]) { return ERR; }
EXPORT fmi2Status fmi2EnterEventMode(fmi2Component c) { return ERR; }
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) { return ERR; }
EXPORT fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { return ERR; }
EXPORT fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, int a, int *b, int *d) { return ERR; }
EXPORT fmi2Status fmi2SetTime(fmi2Component c, double t) { return ERR; }
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, double x[], size_t n) { return ERR; }
#endif

/* The instance of a test model: a `Type` (a struct with a member `double time`) made by
 * calloc and set up by the file's `static void defaults(Type *)`, accepted where `accepted`
 * holds for the fmi2Type `type` (0 Model Exchange, 1 Co-Simulation). fmi2SetupExperiment
 * sets the time, fmi2Reset the defaults; entering initialization and terminating do nothing.
 * fmi2ExitInitializationMode is FMI2_TEST_EXIT_INITIALIZATION's, or the file's own. */
#define FMI2_TEST_INSTANCE(Type, accepted)                                                              \
    EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res, \
                                         const fmi2CallbackFunctions *cb, int visible, int logging) {   \
        Type *m;                                                                                        \
        if (!cb || !cb->logger || !(accepted)) return NULL;                                             \
        m = calloc(1, sizeof *m);                                                                       \
        defaults(m);                                                                                    \
        return m;                                                                                       \
    }                                                                                                   \
    EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }                                          \
    EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, int a, double tol, double t0, int d,         \
                                          double stop) {                                                \
        ((Type *)c)->time = t0;                                                                         \
        return 0;                                                                                       \
    }                                                                                                   \
    EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return 0; }                        \
    EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return 0; }                                      \
    EXPORT fmi2Status fmi2Reset(fmi2Component c) { defaults(c); return 0; }

#define FMI2_TEST_EXIT_INITIALIZATION \
    EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return 0; }

/* Model Exchange's mode changes of a `Type` as FMI2_TEST_INSTANCE's: entering event mode and
 * continuous-time mode do nothing, fmi2SetTime sets the time, fmi2CompletedIntegratorStep
 * asks for no event and no end. */
#define FMI2_TEST_CONTINUOUS_TIME(Type)                                                                  \
    EXPORT fmi2Status fmi2EnterEventMode(fmi2Component c) { return 0; }                                 \
    EXPORT fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { return 0; }                        \
    EXPORT fmi2Status fmi2SetTime(fmi2Component c, double t) { ((Type *)c)->time = t; return 0; }       \
    EXPORT fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, int noPrior, int *enterEventMode,    \
                                                  int *terminate) {                                     \
        *enterEventMode = 0;                                                                            \
        *terminate = 0;                                                                                 \
        return 0;                                                                                       \
    }

#endif
