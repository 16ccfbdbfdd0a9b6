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
 * After its model's struct and `defaults` (or FMI2_TEST_REALS_MODEL for both), a file may write FMI2_TEST_INSTANCE(Type, accepted)
 * (or, with its own fmi2Instantiate and fmi2Reset, FMI2_TEST_LIFECYCLE(Type)),
 * FMI2_TEST_EXIT_INITIALIZATION, FMI2_TEST_CONTINUOUS_TIME(Type) (the three at once:
 * FMI2_TEST_MODEL_EXCHANGE(Type)), FMI2_TEST_TWO_STATES(Type), FMI2_TEST_SET_REALS(Type, count) or
 * FMI2_TEST_SET_REAL_MEMBERS(Type, ...),
 * FMI2_TEST_UNIT_NOMINALS, FMI2_TEST_NO_STATUS and FMI2_TEST_NO_CONTINUOUS_STATES (below) for the
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

/* The importer's memory callbacks as FMI2_TEST_INSTANCE received them (for a model that
 * allocates through them). */
static void *(*fmi2_test_allocate)(size_t, size_t);
static void (*fmi2_test_free)(void *);

/* A model `Type` whose variables are `count` Reals, value reference k the member r[k], and
 * the time; its `defaults` sets r to the start values `...` (the rest 0) and the time to 0. */
#define FMI2_TEST_REALS_MODEL(Type, count, ...)                   \
    typedef struct {                                              \
        double r[count];                                          \
        double time;                                              \
    } Type;                                                       \
    static void defaults(Type *m) {                               \
        static const double starts[count] = {__VA_ARGS__};        \
        memset(m, 0, sizeof *m);                                  \
        memcpy(m->r, starts, sizeof starts);                      \
    }

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
        fmi2_test_allocate = cb->allocateMemory;                                                        \
        fmi2_test_free = cb->freeMemory;                                                                \
        m = calloc(1, sizeof *m);                                                                       \
        defaults(m);                                                                                    \
        return m;                                                                                       \
    }                                                                                                   \
    FMI2_TEST_LIFECYCLE(Type)                                                                           \
    EXPORT fmi2Status fmi2Reset(fmi2Component c) { defaults(c); return 0; }

/* The lifecycle of a `Type` (a struct with a member `double time`) made by calloc, for a file
 * with its own fmi2Instantiate and fmi2Reset: fmi2FreeInstance frees it, fmi2SetupExperiment
 * sets the time, entering initialization and terminating do nothing. */
#define FMI2_TEST_LIFECYCLE(Type)                                                                       \
    EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }                                          \
    EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, int a, double tol, double t0, int d,         \
                                          double stop) {                                                \
        ((Type *)c)->time = t0;                                                                         \
        return 0;                                                                                       \
    }                                                                                                   \
    EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return 0; }                        \
    EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return 0; }

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

/* The Real variables of a two-state `Type` whose `double r[]` holds, by value reference,
 * 0 x1, 1 der(x1), 2 x2, 3 der(x2), 4 a parameter, then locals; its `static void
 * derivatives(Type *)` fills r[1] and r[3]. fmi2GetReal reads any r (derivatives fresh),
 * fmi2SetReal writes the states and the parameter; the states are r[0] and r[2], with nominal 1
 * and no event indicators; fmi2NewDiscreteStates asks for nothing. The file writes its own
 * fmi2GetDerivatives. */
#define FMI2_TEST_TWO_STATES(Type)                                                                       \
    EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) { \
        Type *m = c;                                                                                     \
        size_t i;                                                                                        \
        derivatives(m);                                                                                  \
        for (i = 0; i < n; i++) {                                                                        \
            if (vr[i] >= sizeof m->r / sizeof m->r[0]) return ERR;                                       \
            v[i] = m->r[vr[i]];                                                                          \
        }                                                                                                \
        return 0;                                                                                        \
    }                                                                                                    \
    EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,              \
                                  const double v[]) {                                                    \
        Type *m = c;                                                                                     \
        size_t i;                                                                                        \
        for (i = 0; i < n; i++) {                                                                        \
            if (vr[i] != 0 && vr[i] != 2 && vr[i] != 4) return ERR;                                      \
            m->r[vr[i]] = v[i];                                                                          \
        }                                                                                                \
        return 0;                                                                                        \
    }                                                                                                    \
    EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {                     \
        memset(info, 0, sizeof *info);                                                                   \
        return 0;                                                                                        \
    }                                                                                                    \
    EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) {             \
        Type *m = c;                                                                                     \
        if (n != 2) return ERR;                                                                          \
        m->r[0] = x[0];                                                                                  \
        m->r[2] = x[1];                                                                                  \
        return 0;                                                                                        \
    }                                                                                                    \
    EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) {                   \
        Type *m = c;                                                                                     \
        if (n != 2) return ERR;                                                                          \
        x[0] = m->r[0];                                                                                  \
        x[1] = m->r[2];                                                                                  \
        return 0;                                                                                        \
    }                                                                                                    \
    EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) { return n ? ERR : 0; } \
    FMI2_TEST_UNIT_NOMINALS

/* Every continuous state has nominal 1. */
#define FMI2_TEST_UNIT_NOMINALS                                                                         \
    EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, double x[], size_t n) {         \
        size_t i;                                                                                        \
        for (i = 0; i < n; i++) x[i] = 1.0;                                                              \
        return 0;                                                                                        \
    }

/* A Model Exchange only model (FMI2_TEST_INSTANCE accepting fmi2ModelExchange) with
 * FMI2_TEST_EXIT_INITIALIZATION and FMI2_TEST_CONTINUOUS_TIME. */
#define FMI2_TEST_MODEL_EXCHANGE(Type) \
    FMI2_TEST_INSTANCE(Type, type == 0) \
    FMI2_TEST_EXIT_INITIALIZATION      \
    FMI2_TEST_CONTINUOUS_TIME(Type)

/* fmi2SetReal of a `Type` whose settable Reals are at the addresses `...`, designated
 * initializers `[vr] = &m->member` (`m` the instance); another value reference is refused
 * (fmi2Error). */
#define FMI2_TEST_SET_REAL_MEMBERS(Type, ...)                                                            \
    EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,              \
                                  const double v[]) {                                                    \
        Type *m = c;                                                                                     \
        double *slots[] = {__VA_ARGS__};                                                                 \
        size_t i;                                                                                        \
        for (i = 0; i < n; i++) {                                                                        \
            if (vr[i] >= sizeof slots / sizeof *slots || !slots[vr[i]]) return ERR;                      \
            *slots[vr[i]] = v[i];                                                                        \
        }                                                                                                \
        return 0;                                                                                        \
    }

/* fmi2SetReal of a `Type` whose `double r[]` holds its Real variables by value reference:
 * any of the first `count` may be set, a value reference beyond them is refused. */
#define FMI2_TEST_SET_REALS(Type, count)                                                                 \
    EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,              \
                                  const double v[]) {                                                    \
        Type *m = c;                                                                                     \
        size_t i;                                                                                        \
        for (i = 0; i < n; i++) {                                                                        \
            if (vr[i] >= (count)) return ERR;                                                            \
            m->r[vr[i]] = v[i];                                                                          \
        }                                                                                                \
        return 0;                                                                                        \
    }

/* Co-Simulation without asynchronous steps or status queries: fmi2CancelStep and every
 * fmi2Get*Status refused. */
#define FMI2_TEST_NO_STATUS                                                                            \
    EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return ERR; }                                   \
    EXPORT fmi2Status fmi2GetStatus(fmi2Component c, int s, int *v) { return ERR; }                     \
    EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, int s, double *v) { return ERR; }              \
    EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, int s, int *v) { return ERR; }              \
    EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, int s, int *v) { return ERR; }              \
    EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, int s, const char **v) { return ERR; }

/* Model Exchange of a model without continuous states or event indicators: each of their
 * calls accepts only zero of them. */
#define FMI2_TEST_NO_CONTINUOUS_STATES                                                                  \
    EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) { return n ? ERR : 0; } \
    EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) { return n ? ERR : 0; } \
    EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) { return n ? ERR : 0; } \
    EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) { return n ? ERR : 0; } \
    EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, double x[], size_t n) { return n ? ERR : 0; }

#endif
