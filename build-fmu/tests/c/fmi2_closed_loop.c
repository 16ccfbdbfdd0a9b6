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
 * Algorithm: fixed-step Jacobi, as fmpy, libcosim and nigel_cosim's `jacobi` do it: every
 * instance steps from t to t + h with the inputs set at t, the row of t + h is recorded
 * (outputs before any input changes), then every input is set from the outputs at t + h. In Initialization Mode the connections are applied as many times as there are
 * instances, so values reach the end of any feedthrough chain. Time is t0 + n h, with n an
 * integer, so it does not drift; each step is t_(n+1) - t_n. Rows are written with 17 significant digits (%.17g),
 * which round-trip every double.
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

#define MAX_INSTANCES 8
#define MAX_ITEMS 4096
#define LINE 4096

typedef struct {
    char name[64];
    char guid[128];
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

typedef struct { int from, to; fmi2ValueReference from_vr, to_vr; double gain, offset; } Connection;
typedef struct { int instance; fmi2ValueReference vr; char column[128]; } Recorded;

static Instance instances[MAX_INSTANCES];
static int n_instances;
static Connection connections[MAX_ITEMS];
static int n_connections;
static Recorded recorded[MAX_ITEMS];
static int n_recorded;

static void fail(const char *what, const char *detail) {
    fprintf(stderr, "fmi2_closed_loop: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(1);
}

static void check(fmi2Status s, const char *function, const Instance *inst) {
    if (s != fmi2OK) {
        fprintf(stderr, "fmi2_closed_loop: %s of %s returned status %d\n", function, inst->name, (int)s);
        exit(1);
    }
}

static int instance_index(const char *name) {
    for (int i = 0; i < n_instances; i++)
        if (strcmp(instances[i].name, name) == 0) return i;
    fail("unknown instance", name);
    return -1;
}

static void *symbol(library_t l, const char *name, const char *path) {
    void *p = library_symbol(l, name);
    if (!p) {
        fprintf(stderr, "fmi2_closed_loop: %s: no symbol %s\n", path, name);
        exit(1);
    }
    return p;
}

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

static void propagate(void) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        fmi2Real v;
        check(instances[c->from].get_real(instances[c->from].c, &c->from_vr, 1, &v), "fmi2GetReal", &instances[c->from]);
        v = c->gain * v + c->offset;
        check(instances[c->to].set_real(instances[c->to].c, &c->to_vr, 1, &v), "fmi2SetReal", &instances[c->to]);
    }
}

/* Jacobi: every source value read before any input is set. */
static void propagate_jacobi(fmi2Real *buffer) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        check(instances[c->from].get_real(instances[c->from].c, &c->from_vr, 1, &buffer[k]), "fmi2GetReal",
              &instances[c->from]);
        buffer[k] = c->gain * buffer[k] + c->offset;
    }
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        check(instances[c->to].set_real(instances[c->to].c, &c->to_vr, 1, &buffer[k]), "fmi2SetReal", &instances[c->to]);
    }
}

static void write_row(FILE *out, double t) {
    fprintf(out, "%.17g", t);
    for (int k = 0; k < n_recorded; k++) {
        const Recorded *r = &recorded[k];
        fmi2Real v;
        check(instances[r->instance].get_real(instances[r->instance].c, &r->vr, 1, &v), "fmi2GetReal",
              &instances[r->instance]);
        fprintf(out, ",%.17g", v);
    }
    fputc('\n', out);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: fmi2_closed_loop JOB_FILE OUT_CSV\n");
        return 2;
    }
    FILE *job = fopen(argv[1], "r");
    if (!job) fail("cannot open job file", argv[1]);
    double stop = 0.0, step = 0.0;
    char line[LINE];
    while (fgets(line, sizeof line, job)) {
        line[strcspn(line, "\r\n")] = 0;
        char kind[32], a[128], b[128], c[128], d[128];
        int pos = 0;
        if (sscanf(line, "%31s%n", kind, &pos) != 1) continue;
        if (strcmp(kind, "experiment") == 0) {
            if (sscanf(line + pos, "%127s %127s", a, b) != 2) fail("bad line", line);
            stop = strtod(a, NULL);
            step = strtod(b, NULL);
        } else if (strcmp(kind, "fmu") == 0) {
            int rest = 0;
            if (n_instances == MAX_INSTANCES) fail("too many instances", line);
            Instance *inst = &instances[n_instances];
            if (sscanf(line + pos, " %63s %127s %n", inst->name, inst->guid, &rest) != 2 || rest == 0)
                fail("bad line", line);
            load(inst, line + pos + rest);
            inst->c = inst->instantiate(inst->name, fmi2CoSimulation, inst->guid, "file:///", &callbacks, 0, 0);
            if (!inst->c) fail("fmi2Instantiate failed", inst->name);
            n_instances++;
        } else if (strcmp(kind, "real") == 0 || strcmp(kind, "integer") == 0 || strcmp(kind, "boolean") == 0) {
            if (sscanf(line + pos, "%127s %127s %127s", a, b, c) != 3) fail("bad line", line);
            Instance *inst = &instances[instance_index(a)];
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(b, NULL, 10);
            if (kind[0] == 'r') {
                fmi2Real v = strtod(c, NULL);
                check(inst->set_real(inst->c, &vr, 1, &v), "fmi2SetReal", inst);
            } else if (kind[0] == 'i') {
                fmi2Integer v = (fmi2Integer)strtol(c, NULL, 10);
                check(inst->set_integer(inst->c, &vr, 1, &v), "fmi2SetInteger", inst);
            } else {
                fmi2Boolean v = strcmp(c, "0") != 0;
                check(inst->set_boolean(inst->c, &vr, 1, &v), "fmi2SetBoolean", inst);
            }
        } else if (strcmp(kind, "connect") == 0) {
            char e[128], f[128];
            if (sscanf(line + pos, "%127s %127s %127s %127s %127s %127s", a, b, c, d, e, f) != 6) fail("bad line", line);
            if (n_connections == MAX_ITEMS) fail("too many connections", line);
            Connection *k = &connections[n_connections++];
            k->from = instance_index(a);
            k->from_vr = (fmi2ValueReference)strtoul(b, NULL, 10);
            k->to = instance_index(c);
            k->to_vr = (fmi2ValueReference)strtoul(d, NULL, 10);
            k->gain = strtod(e, NULL);
            k->offset = strtod(f, NULL);
        } else if (strcmp(kind, "record") == 0) {
            if (n_recorded == MAX_ITEMS) fail("too many recorded variables", line);
            Recorded *r = &recorded[n_recorded];
            if (sscanf(line + pos, "%127s %127s %127s", a, b, r->column) != 3) fail("bad line", line);
            r->instance = instance_index(a);
            r->vr = (fmi2ValueReference)strtoul(b, NULL, 10);
            n_recorded++;
        } else {
            fail("unknown directive", line);
        }
    }
    fclose(job);
    if (!(step > 0.0) || !(stop > 0.0)) fail("no experiment line with a positive stop time and step", argv[1]);

    for (int i = 0; i < n_instances; i++)
        check(instances[i].setup_experiment(instances[i].c, 0, 0.0, 0.0, 1, stop), "fmi2SetupExperiment", &instances[i]);
    for (int i = 0; i < n_instances; i++)
        check(instances[i].enter_initialization(instances[i].c), "fmi2EnterInitializationMode", &instances[i]);
    for (int pass = 0; pass < n_instances; pass++) propagate();
    for (int i = 0; i < n_instances; i++)
        check(instances[i].exit_initialization(instances[i].c), "fmi2ExitInitializationMode", &instances[i]);

    FILE *out = fopen(argv[2], "w");
    if (!out) fail("cannot write", argv[2]);
    fprintf(out, "\"time\"");
    for (int k = 0; k < n_recorded; k++) fprintf(out, ",\"%s\"", recorded[k].column);
    fputc('\n', out);
    write_row(out, 0.0);
    /* the number of steps, rounded: stop is a multiple of step up to rounding of the text */
    long steps = (long)(stop / step + 0.5);
    fmi2Real *buffer = calloc((size_t)n_connections + 1, sizeof(fmi2Real));
    for (long n = 0; n < steps; n++) {
        /* from t_n = n h to t_(n+1) = (n + 1) h: the step is their difference, so that
           t_n + step lands on the grid (nigel_cosim does the same) */
        double t = (double)n * step, t_next = (double)(n + 1) * step;
        for (int i = 0; i < n_instances; i++)
            check(instances[i].do_step(instances[i].c, t, t_next - t, 1), "fmi2DoStep", &instances[i]);
        write_row(out, t_next);
        propagate_jacobi(buffer);
    }
    free(buffer);
    if (fclose(out) != 0) fail("cannot write", argv[2]);
    for (int i = 0; i < n_instances; i++) {
        check(instances[i].terminate(instances[i].c), "fmi2Terminate", &instances[i]);
        instances[i].free_instance(instances[i].c);
    }
    return 0;
}
