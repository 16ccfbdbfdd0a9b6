/*
 * fmi3_closed_loop: a minimal FMI 3.0 Co-Simulation importer in portable C, the FMI 3.0
 * counterpart of fmi2_closed_loop.c: one program drives the FMI 3.0 archives' libraries on
 * every platform (Linux x86-64 with gcc, Windows with mingw-w64 under wine, aarch64 Linux
 * under qemu-user) and writes CSVs comparable with fmi2_closed_loop's.
 *
 * Built against the FMI 3.0 headers (fmi3FunctionTypes.h, fmi3PlatformTypes.h), which the
 * test takes from fmpy's c-code folder: -I .../site-packages/fmpy/c-code.
 *
 * Usage: fmi3_closed_loop JOB_FILE OUT_CSV
 *
 * The job file is fmi2_closed_loop's, with FMI 3.0 value references and the
 * instantiationToken in place of the GUID (fields separated by one space; the library path
 * is the rest of its line):
 *   experiment STOP_TIME STEP_SIZE
 *   fmu NAME TOKEN LIBRARY_PATH         instance NAME of the library
 *   real NAME VR VALUE                  Float64 parameter/start value set before initialization
 *   integer NAME VR VALUE               Int32
 *   enumeration NAME VR VALUE           Enumeration (fmi3SetInt64)
 *   boolean NAME VR 0|1
 *   connect FROM VR TO VR GAIN OFFSET   Float64 output -> Float64 input, to = GAIN * from + OFFSET
 *   record NAME VR COLUMN               Float64 variable recorded as column COLUMN
 * Values are read with strtod, so hexadecimal floats (%a) carry every bit.
 *
 * Algorithm: closed_loop.h's fixed-step Jacobi, fmi2_closed_loop's step for step (the same
 * grid t_n = n h, the same order of gets and sets), so that the same library gives the same
 * numbers through either ABI; this file binds it to the FMI 3.0 C API. Instances are
 * instantiated without event mode and without early return; fmi3DoStep must then report no
 * event to handle, no early return and lastSuccessfulTime = t + h. An instance that asks to
 * terminate ends the run after the row of that step (the CSV is then shorter, and the test
 * says so).
 */
#include "importer.h"

#include "fmi3FunctionTypes.h"

typedef struct {
    char name[64];
    char token[128];
    fmi3Instance c;
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3EnterInitializationModeTYPE *enter_initialization;
    fmi3ExitInitializationModeTYPE *exit_initialization;
    fmi3TerminateTYPE *terminate;
    fmi3FreeInstanceTYPE *free_instance;
    fmi3GetFloat64TYPE *get_float64;
    fmi3SetFloat64TYPE *set_float64;
    fmi3SetInt32TYPE *set_int32;
    fmi3SetInt64TYPE *set_int64;
    fmi3SetBooleanTYPE *set_boolean;
    fmi3DoStepTYPE *do_step;
} Instance;

#define PROGRAM "fmi3_closed_loop"
typedef fmi3ValueReference ValueReference;
#include "closed_loop.h"

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    const Instance *inst = (const Instance *)env;
    fprintf(stderr, "[%s] %s status %d: %s\n", inst ? inst->name : "?", category ? category : "", (int)status,
            message ? message : "");
}

static void load(Instance *inst, const char *path) {
    library_t l = library_open(path);
    if (!l) fail("cannot load library", path);
    inst->instantiate = (fmi3InstantiateCoSimulationTYPE *)symbol(l, "fmi3InstantiateCoSimulation", path);
    inst->enter_initialization = (fmi3EnterInitializationModeTYPE *)symbol(l, "fmi3EnterInitializationMode", path);
    inst->exit_initialization = (fmi3ExitInitializationModeTYPE *)symbol(l, "fmi3ExitInitializationMode", path);
    inst->terminate = (fmi3TerminateTYPE *)symbol(l, "fmi3Terminate", path);
    inst->free_instance = (fmi3FreeInstanceTYPE *)symbol(l, "fmi3FreeInstance", path);
    inst->get_float64 = (fmi3GetFloat64TYPE *)symbol(l, "fmi3GetFloat64", path);
    inst->set_float64 = (fmi3SetFloat64TYPE *)symbol(l, "fmi3SetFloat64", path);
    inst->set_int32 = (fmi3SetInt32TYPE *)symbol(l, "fmi3SetInt32", path);
    inst->set_int64 = (fmi3SetInt64TYPE *)symbol(l, "fmi3SetInt64", path);
    inst->set_boolean = (fmi3SetBooleanTYPE *)symbol(l, "fmi3SetBoolean", path);
    inst->do_step = (fmi3DoStepTYPE *)symbol(l, "fmi3DoStep", path);
}

static void instantiate(Instance *inst) {
    /* no resources folder in our FMUs: the resource path is not read (NULL is allowed) */
    inst->c = inst->instantiate(inst->name, inst->token, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                                inst, logger, NULL);
    if (!inst->c) fail("fmi3InstantiateCoSimulation failed", inst->name);
}

/* real (Float64), integer (Int32), enumeration (Int64) and boolean. */
static int set_start(Instance *inst, char kind, ValueReference vr, const char *text) {
    if (kind == 'r') {
        fmi3Float64 v = strtod(text, NULL);
        check(inst->set_float64(inst->c, &vr, 1, &v, 1), "fmi3SetFloat64", inst);
    } else if (kind == 'i') {
        fmi3Int32 v = (fmi3Int32)strtol(text, NULL, 10);
        check(inst->set_int32(inst->c, &vr, 1, &v, 1), "fmi3SetInt32", inst);
    } else if (kind == 'e') {
        fmi3Int64 v = (fmi3Int64)strtoll(text, NULL, 10);
        check(inst->set_int64(inst->c, &vr, 1, &v, 1), "fmi3SetInt64", inst);
    } else {
        fmi3Boolean v = strcmp(text, "0") != 0;
        check(inst->set_boolean(inst->c, &vr, 1, &v, 1), "fmi3SetBoolean", inst);
    }
    return 1;
}

static double get_real(Instance *inst, ValueReference vr) {
    fmi3Float64 v;
    check(inst->get_float64(inst->c, &vr, 1, &v, 1), "fmi3GetFloat64", inst);
    return v;
}

static void set_real(Instance *inst, ValueReference vr, double v) {
    check(inst->set_float64(inst->c, &vr, 1, &v, 1), "fmi3SetFloat64", inst);
}

/* FMI 3.0 has no fmi2SetupExperiment: the experiment comes with Initialization Mode. */
static void setup_experiment(Instance *inst, double stop) {
    (void)inst;
    (void)stop;
}

static void enter_initialization(Instance *inst, double stop) {
    check(inst->enter_initialization(inst->c, fmi3False, 0.0, 0.0, fmi3True, stop), "fmi3EnterInitializationMode",
          inst);
}

static void exit_initialization(Instance *inst) {
    check(inst->exit_initialization(inst->c), "fmi3ExitInitializationMode", inst);
}

static int do_step(Instance *inst, double t, double h) {
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    fmi3Float64 last = -1.0;
    check(inst->do_step(inst->c, t, h, fmi3True, &event, &terminate, &early, &last), "fmi3DoStep", inst);
    if (event || early) {
        fprintf(stderr, "fmi3_closed_loop: fmi3DoStep of %s at t = %.17g: eventHandlingNeeded %d, earlyReturn %d "
                        "without event mode or early return allowed\n",
                inst->name, t, (int)event, (int)early);
        exit(1);
    }
    if (last != t + h) {
        fprintf(stderr, "fmi3_closed_loop: fmi3DoStep of %s at t = %.17g: lastSuccessfulTime %.17g, not t + h = %.17g\n",
                inst->name, t, last, t + h);
        exit(1);
    }
    if (terminate) {
        fprintf(stderr, "fmi3_closed_loop: %s asked to terminate at t = %.17g\n", inst->name, t + h);
        return 1;
    }
    return 0;
}

static void end(Instance *inst) {
    check(inst->terminate(inst->c), "fmi3Terminate", inst);
    inst->free_instance(inst->c);
}
