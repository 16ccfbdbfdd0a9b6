/*
 * fmi2_closed_loop: a minimal FMI 2.0 Co-Simulation importer in portable C, so that one
 * program drives the FMUs' libraries on every platform (Linux x86-64 with gcc, Windows
 * with mingw-w64 under wine, aarch64 Linux under qemu-user) and writes comparable CSVs.
 *
 * Usage: fmi2_closed_loop JOB_FILE OUT_CSV
 *
 * The job file is plain text, one directive per line (fields separated by one space; the
 * library path is the rest of its line):
 *   experiment STOP_TIME STEP_SIZE
 *   fmu NAME GUID LIBRARY_PATH          instance NAME of the library (modelIdentifier = NAME's FMU)
 *   real NAME VR VALUE                  parameter/start value set before initialization
 *   integer NAME VR VALUE
 *   boolean NAME VR 0|1
 *   connect FROM VR TO VR GAIN OFFSET   Real output -> Real input, to = GAIN * from + OFFSET
 *   record NAME VR COLUMN               Real variable recorded as column COLUMN
 * Values are read with strtod, so hexadecimal floats (%a) carry every bit.
 *
 * Algorithm: closed_loop.h's fixed-step Jacobi; this file binds it to the FMI 2.0 C API.
 */
#include "importer.h"

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                     fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*ComponentOnly)(fmi2Component);
typedef void (*FreeInstance)(fmi2Component);
typedef fmi2Status (*GetSetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*SetInteger)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Integer *);
typedef fmi2Status (*SetBoolean)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Boolean *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);

typedef struct {
    char name[64];
    char token[128]; /* the GUID */
    fmi2Component c;
    Instantiate instantiate;
    SetupExperiment setup_experiment;
    ComponentOnly enter_initialization, exit_initialization, terminate;
    FreeInstance free_instance;
    GetSetReal get_real, set_real;
    SetInteger set_integer;
    SetBoolean set_boolean;
    DoStep do_step;
} Instance;

#define PROGRAM "fmi2_closed_loop"
typedef fmi2ValueReference ValueReference;
#include "closed_loop.h"

static void load(Instance *inst, const char *path) {
    library_t l = library_open(path);
    if (!l) fail("cannot load library", path);
    inst->instantiate = (Instantiate)symbol(l, "fmi2Instantiate", path);
    inst->setup_experiment = (SetupExperiment)symbol(l, "fmi2SetupExperiment", path);
    inst->enter_initialization = (ComponentOnly)symbol(l, "fmi2EnterInitializationMode", path);
    inst->exit_initialization = (ComponentOnly)symbol(l, "fmi2ExitInitializationMode", path);
    inst->terminate = (ComponentOnly)symbol(l, "fmi2Terminate", path);
    inst->free_instance = (FreeInstance)symbol(l, "fmi2FreeInstance", path);
    inst->get_real = (GetSetReal)symbol(l, "fmi2GetReal", path);
    inst->set_real = (GetSetReal)symbol(l, "fmi2SetReal", path);
    inst->set_integer = (SetInteger)symbol(l, "fmi2SetInteger", path);
    inst->set_boolean = (SetBoolean)symbol(l, "fmi2SetBoolean", path);
    inst->do_step = (DoStep)symbol(l, "fmi2DoStep", path);
}

static const fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};

static void instantiate(Instance *inst) {
    inst->c = inst->instantiate(inst->name, fmi2CoSimulation, inst->token, "file:///", &callbacks, 0, 0);
    if (!inst->c) fail("fmi2Instantiate failed", inst->name);
}

/* real, integer and boolean (FMI 2.0 sets an Enumeration as an Integer: no such line). */
static int set_start(Instance *inst, char kind, ValueReference vr, const char *text) {
    if (kind == 'r') {
        fmi2Real v = strtod(text, NULL);
        check(inst->set_real(inst->c, &vr, 1, &v), "fmi2SetReal", inst);
    } else if (kind == 'i') {
        fmi2Integer v = (fmi2Integer)strtol(text, NULL, 10);
        check(inst->set_integer(inst->c, &vr, 1, &v), "fmi2SetInteger", inst);
    } else if (kind == 'b') {
        fmi2Boolean v = strcmp(text, "0") != 0;
        check(inst->set_boolean(inst->c, &vr, 1, &v), "fmi2SetBoolean", inst);
    } else {
        return 0;
    }
    return 1;
}

static double get_real(Instance *inst, ValueReference vr) {
    fmi2Real v;
    check(inst->get_real(inst->c, &vr, 1, &v), "fmi2GetReal", inst);
    return v;
}

static void set_real(Instance *inst, ValueReference vr, double v) {
    check(inst->set_real(inst->c, &vr, 1, &v), "fmi2SetReal", inst);
}

static void setup_experiment(Instance *inst, double stop) {
    check(inst->setup_experiment(inst->c, 0, 0.0, 0.0, 1, stop), "fmi2SetupExperiment", inst);
}

static void enter_initialization(Instance *inst, double stop) {
    (void)stop;
    check(inst->enter_initialization(inst->c), "fmi2EnterInitializationMode", inst);
}

static void exit_initialization(Instance *inst) {
    check(inst->exit_initialization(inst->c), "fmi2ExitInitializationMode", inst);
}

static int do_step(Instance *inst, double t, double h) {
    check(inst->do_step(inst->c, t, h, 1), "fmi2DoStep", inst);
    return 0;
}

static void end(Instance *inst) {
    check(inst->terminate(inst->c), "fmi2Terminate", inst);
    inst->free_instance(inst->c);
}
