/*
 * me_fixed_step: one FMU through Model Exchange, FMI 2.0 or FMI 3.0, integrated by the
 * classic fourth-order Runge-Kutta method with a fixed step in portable C, so that the two
 * C APIs of the same library can be compared bit for bit on every platform (Linux x86-64
 * with gcc, Windows with mingw-w64 under wine, aarch64 Linux under qemu-user).
 *
 * Built against the FMI 3.0 headers (fmi3FunctionTypes.h, fmi3PlatformTypes.h) from fmpy's
 * c-code folder; the few FMI 2.0 types it needs are in importer.h.
 *
 * Usage: me_fixed_step 2|3 JOB_FILE OUT_CSV
 *
 * The job file (fields separated by one space; the library path is the rest of its line):
 *   experiment STOP_TIME STEP_SIZE
 *   fmu GUID LIBRARY_PATH             the GUID is also the FMI 3.0 instantiationToken
 *   states N                          number of continuous states
 *   real VR2 VR3 VALUE                Real/Float64 start value set before initialization
 *   record VR2 VR3 COLUMN             Real/Float64 variable recorded as column COLUMN
 * (VR2 the FMI 2.0 value reference, VR3 the FMI 3.0 one). Values are read with strtod.
 *
 * Algorithm: initialization, the event iteration until no new discrete states are needed
 * (a time event or a terminate request stops the program: the job's FMU has none),
 * Continuous-Time Mode, then per step t_n = n h -> t_{n+1} = (n + 1) h:
 *   k1 = f(t_n, x), k2 = f(t_n + h/2, x + h/2 k1), k3 = f(t_n + h/2, x + h/2 k2),
 *   k4 = f(t_{n+1}, x + h k3), x += h/6 (k1 + 2 k2 + 2 k3 + k4),
 * with f(t, x) = set time, set continuous states, get derivatives; then the time, the
 * states and the step completed (an event requested there stops the program), and the
 * row: t, the states, the recorded variables. The arithmetic is the same for both APIs;
 * only the calls differ.
 */
#include "importer.h"

#include "fmi3FunctionTypes.h"

#define MAX_ITEMS 4096
#define MAX_STATES 64
#define LINE 4096

static int api; /* 2 or 3 */
static library_t lib;
static const char *lib_path;
static void *c; /* fmi2Component or fmi3Instance */
static size_t nx;

static void fail(const char *what, const char *detail) {
    fprintf(stderr, "me_fixed_step: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(1);
}

static void check(int status, const char *function) {
    if (status != 0) {
        fprintf(stderr, "me_fixed_step: %s returned status %d\n", function, status);
        exit(1);
    }
}

static void *symbol(const char *name) {
    void *p = library_symbol(lib, name);
    if (!p) {
        fprintf(stderr, "me_fixed_step: %s: no symbol %s\n", lib_path, name);
        exit(1);
    }
    return p;
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "[me] %s status %d: %s\n", category ? category : "", (int)status, message ? message : "");
}

/* The calls of either API, by what they do. */
static void set_time(double t) {
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, fmi2Real))symbol("fmi2SetTime"))(c, t), "fmi2SetTime");
    else
        check(((fmi3SetTimeTYPE *)symbol("fmi3SetTime"))(c, t), "fmi3SetTime");
}

static void set_states(const double *x) {
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, const fmi2Real *, size_t))symbol("fmi2SetContinuousStates"))(c, x, nx),
              "fmi2SetContinuousStates");
    else
        check(((fmi3SetContinuousStatesTYPE *)symbol("fmi3SetContinuousStates"))(c, x, nx),
              "fmi3SetContinuousStates");
}

static void get_states(double *x) {
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, fmi2Real *, size_t))symbol("fmi2GetContinuousStates"))(c, x, nx),
              "fmi2GetContinuousStates");
    else
        check(((fmi3GetContinuousStatesTYPE *)symbol("fmi3GetContinuousStates"))(c, x, nx),
              "fmi3GetContinuousStates");
}

static void get_derivatives(double *dx) {
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, fmi2Real *, size_t))symbol("fmi2GetDerivatives"))(c, dx, nx),
              "fmi2GetDerivatives");
    else
        check(((fmi3GetContinuousStateDerivativesTYPE *)symbol("fmi3GetContinuousStateDerivatives"))(c, dx, nx),
              "fmi3GetContinuousStateDerivatives");
}

static void get_reals(const unsigned *vr2, const unsigned *vr3, size_t n, double *out) {
    if (n == 0) return;
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *))symbol("fmi2GetReal"))(
                  c, vr2, n, out),
              "fmi2GetReal");
    else
        check(((fmi3GetFloat64TYPE *)symbol("fmi3GetFloat64"))(c, vr3, n, out, n), "fmi3GetFloat64");
}

static void set_reals(const unsigned *vr2, const unsigned *vr3, size_t n, const double *values) {
    if (n == 0) return;
    if (api == 2)
        check(((fmi2Status(*)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *))symbol(
                  "fmi2SetReal"))(c, vr2, n, values),
              "fmi2SetReal");
    else
        check(((fmi3SetFloat64TYPE *)symbol("fmi3SetFloat64"))(c, vr3, n, values, n), "fmi3SetFloat64");
}

static void instantiate(const char *guid, double stop) {
    static fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};
    if (api == 2) {
        c = ((fmi2Component(*)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                               fmi2Boolean, fmi2Boolean))symbol("fmi2Instantiate"))("me", fmi2ModelExchange, guid,
                                                                                    "file:///", &callbacks, 0, 0);
        if (!c) fail("fmi2Instantiate returned NULL", lib_path);
        check(((fmi2Status(*)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real))symbol(
                  "fmi2SetupExperiment"))(c, 0, 0.0, 0.0, 1, stop),
              "fmi2SetupExperiment");
    } else {
        c = ((fmi3InstantiateModelExchangeTYPE *)symbol("fmi3InstantiateModelExchange"))("me", guid, NULL, fmi3False,
                                                                                       fmi3False, NULL, logger3);
        if (!c) fail("fmi3InstantiateModelExchange returned NULL", lib_path);
    }
    (void)stop;
}

static void initialize(double stop) {
    if (api == 2) {
        fmi2Status (*enter)(fmi2Component) = (fmi2Status(*)(fmi2Component))symbol("fmi2EnterInitializationMode");
        check(enter(c), "fmi2EnterInitializationMode");
        check(((fmi2Status(*)(fmi2Component))symbol("fmi2ExitInitializationMode"))(c), "fmi2ExitInitializationMode");
        fmi2EventInfo info;
        do {
            check(((fmi2Status(*)(fmi2Component, fmi2EventInfo *))symbol("fmi2NewDiscreteStates"))(c, &info),
                  "fmi2NewDiscreteStates");
            if (info.terminateSimulation) fail("the FMU asked to terminate at initialization", NULL);
        } while (info.newDiscreteStatesNeeded);
        if (info.nextEventTimeDefined) fail("the FMU announced a time event: not handled here", NULL);
        check(((fmi2Status(*)(fmi2Component))symbol("fmi2EnterContinuousTimeMode"))(c), "fmi2EnterContinuousTimeMode");
    } else {
        check(((fmi3EnterInitializationModeTYPE *)symbol("fmi3EnterInitializationMode"))(c, fmi3False, 0.0, 0.0,
                                                                                        fmi3True, stop),
              "fmi3EnterInitializationMode");
        check(((fmi3ExitInitializationModeTYPE *)symbol("fmi3ExitInitializationMode"))(c), "fmi3ExitInitializationMode");
        fmi3Boolean needed, terminate, nominals, values, defined;
        fmi3Float64 next;
        do {
            check(((fmi3UpdateDiscreteStatesTYPE *)symbol("fmi3UpdateDiscreteStates"))(c, &needed, &terminate,
                                                                                     &nominals, &values, &defined,
                                                                                     &next),
                  "fmi3UpdateDiscreteStates");
            if (terminate) fail("the FMU asked to terminate at initialization", NULL);
        } while (needed);
        if (defined) fail("the FMU announced a time event: not handled here", NULL);
        check(((fmi3EnterContinuousTimeModeTYPE *)symbol("fmi3EnterContinuousTimeMode"))(c),
              "fmi3EnterContinuousTimeMode");
    }
}

/* The step is completed at the current time and states; 1 when the run must end. */
static int completed_integrator_step(void) {
    if (api == 2) {
        fmi2Boolean event = 0, terminate = 0;
        check(((fmi2Status(*)(fmi2Component, fmi2Boolean, fmi2Boolean *, fmi2Boolean *))symbol(
                  "fmi2CompletedIntegratorStep"))(c, 1, &event, &terminate),
              "fmi2CompletedIntegratorStep");
        if (event) fail("the FMU asked for an event after a step: not handled here", NULL);
        return terminate != 0;
    } else {
        fmi3Boolean event = fmi3False, terminate = fmi3False;
        check(((fmi3CompletedIntegratorStepTYPE *)symbol("fmi3CompletedIntegratorStep"))(c, fmi3True, &event,
                                                                                        &terminate),
              "fmi3CompletedIntegratorStep");
        if (event) fail("the FMU asked for an event after a step: not handled here", NULL);
        return terminate != fmi3False;
    }
}

static void finish(void) {
    if (api == 2) {
        check(((fmi2Status(*)(fmi2Component))symbol("fmi2Terminate"))(c), "fmi2Terminate");
        ((void (*)(fmi2Component))symbol("fmi2FreeInstance"))(c);
    } else {
        check(((fmi3TerminateTYPE *)symbol("fmi3Terminate"))(c), "fmi3Terminate");
        ((fmi3FreeInstanceTYPE *)symbol("fmi3FreeInstance"))(c);
    }
}

static void derivatives(double t, const double *x, double *dx) {
    set_time(t);
    set_states(x);
    get_derivatives(dx);
}

int main(int argc, char **argv) {
    static char line[LINE], guid[256], path[LINE], columns[MAX_ITEMS][128];
    static unsigned set_vr2[MAX_ITEMS], set_vr3[MAX_ITEMS], rec_vr2[MAX_ITEMS], rec_vr3[MAX_ITEMS];
    static double set_values[MAX_ITEMS], recorded[MAX_ITEMS];
    size_t n_set = 0, n_rec = 0;
    double stop = -1.0, h = -1.0;
    if (argc != 4 || (strcmp(argv[1], "2") != 0 && strcmp(argv[1], "3") != 0))
        fail("usage", "me_fixed_step 2|3 JOB_FILE OUT_CSV");
    api = argv[1][0] - '0';
    FILE *job = fopen(argv[2], "r");
    if (!job) fail("cannot open job file", argv[2]);
    guid[0] = path[0] = '\0';
    while (fgets(line, sizeof line, job)) {
        char kind[32];
        int pos = 0;
        line[strcspn(line, "\r\n")] = '\0';
        if (sscanf(line, "%31s%n", kind, &pos) != 1) continue;
        if (strcmp(kind, "experiment") == 0) {
            if (sscanf(line + pos, "%lf %lf", &stop, &h) != 2) fail("bad line", line);
        } else if (strcmp(kind, "fmu") == 0) {
            int rest = 0;
            if (sscanf(line + pos, " %255s %n", guid, &rest) != 1 || rest == 0) fail("bad line", line);
            strncpy(path, line + pos + rest, sizeof path - 1);
        } else if (strcmp(kind, "states") == 0) {
            if (sscanf(line + pos, "%zu", &nx) != 1 || nx > MAX_STATES) fail("bad line", line);
        } else if (strcmp(kind, "real") == 0) {
            char value[64];
            if (n_set == MAX_ITEMS || sscanf(line + pos, "%u %u %63s", &set_vr2[n_set], &set_vr3[n_set], value) != 3)
                fail("bad line", line);
            set_values[n_set++] = strtod(value, NULL);
        } else if (strcmp(kind, "record") == 0) {
            if (n_rec == MAX_ITEMS ||
                sscanf(line + pos, "%u %u %127s", &rec_vr2[n_rec], &rec_vr3[n_rec], columns[n_rec]) != 3)
                fail("bad line", line);
            n_rec++;
        } else {
            fail("unknown line", line);
        }
    }
    fclose(job);
    if (stop <= 0.0 || h <= 0.0 || !path[0]) fail("the job needs experiment and fmu lines", argv[2]);
    lib_path = path;
    lib = library_open(path);
    if (!lib) fail("cannot load library", path);

    instantiate(guid, stop);
    set_reals(set_vr2, set_vr3, n_set, set_values);
    initialize(stop);

    FILE *out = fopen(argv[3], "w");
    if (!out) fail("cannot write", argv[3]);
    fprintf(out, "time");
    for (size_t i = 0; i < nx; i++) fprintf(out, ",x%zu", i);
    for (size_t i = 0; i < n_rec; i++) fprintf(out, ",%s", columns[i]);
    fputc('\n', out);

    double x[MAX_STATES], xs[MAX_STATES], k1[MAX_STATES], k2[MAX_STATES], k3[MAX_STATES], k4[MAX_STATES];
    get_states(x);
    long steps = (long)(stop / h + 0.5);
    for (long n = 0;; n++) {
        double t = (double)n * h;
        get_reals(rec_vr2, rec_vr3, n_rec, recorded);
        fprintf(out, "%.17g", t);
        for (size_t i = 0; i < nx; i++) fprintf(out, ",%.17g", x[i]);
        for (size_t i = 0; i < n_rec; i++) fprintf(out, ",%.17g", recorded[i]);
        fputc('\n', out);
        if (n == steps) break;
        double t_next = (double)(n + 1) * h, t_half = t + 0.5 * h;
        derivatives(t, x, k1);
        for (size_t i = 0; i < nx; i++) xs[i] = x[i] + 0.5 * h * k1[i];
        derivatives(t_half, xs, k2);
        for (size_t i = 0; i < nx; i++) xs[i] = x[i] + 0.5 * h * k2[i];
        derivatives(t_half, xs, k3);
        for (size_t i = 0; i < nx; i++) xs[i] = x[i] + h * k3[i];
        derivatives(t_next, xs, k4);
        for (size_t i = 0; i < nx; i++) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        set_time(t_next);
        set_states(x);
        if (completed_integrator_step()) break;
    }
    fclose(out);
    finish();
    return 0;
}
