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
 * Algorithm: fmi2_closed_loop's fixed-step Jacobi, step for step (the same grid t_n = n h,
 * the same order of gets and sets), so that the same library gives the same numbers through
 * either ABI. Instances are instantiated without event mode and without early return;
 * fmi3DoStep must then report no event to handle, no early return and
 * lastSuccessfulTime = t + h. An instance that asks to terminate ends the run after the
 * row of that step (the CSV is then shorter, and the test says so).
 */
#include "importer.h"

#include "fmi3FunctionTypes.h"

#define MAX_INSTANCES 8
#define MAX_ITEMS 4096
#define LINE 4096

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

typedef struct { int from, to; fmi3ValueReference from_vr, to_vr; double gain, offset; } Connection;
typedef struct { int instance; fmi3ValueReference vr; char column[128]; } Recorded;

static Instance instances[MAX_INSTANCES];
static int n_instances;
static Connection connections[MAX_ITEMS];
static int n_connections;
static Recorded recorded[MAX_ITEMS];
static int n_recorded;

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    const Instance *inst = (const Instance *)env;
    fprintf(stderr, "[%s] %s status %d: %s\n", inst ? inst->name : "?", category ? category : "", (int)status,
            message ? message : "");
}

static void fail(const char *what, const char *detail) {
    fprintf(stderr, "fmi3_closed_loop: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(1);
}

static void check(fmi3Status s, const char *function, const Instance *inst) {
    if (s != fmi3OK) {
        fprintf(stderr, "fmi3_closed_loop: %s of %s returned status %d\n", function, inst->name, (int)s);
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
        fprintf(stderr, "fmi3_closed_loop: %s: no symbol %s\n", path, name);
        exit(1);
    }
    return p;
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

static void propagate(void) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        fmi3Float64 v;
        check(instances[c->from].get_float64(instances[c->from].c, &c->from_vr, 1, &v, 1), "fmi3GetFloat64",
              &instances[c->from]);
        v = c->gain * v + c->offset;
        check(instances[c->to].set_float64(instances[c->to].c, &c->to_vr, 1, &v, 1), "fmi3SetFloat64",
              &instances[c->to]);
    }
}

/* Jacobi: every source value read before any input is set. */
static void propagate_jacobi(fmi3Float64 *buffer) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        check(instances[c->from].get_float64(instances[c->from].c, &c->from_vr, 1, &buffer[k], 1), "fmi3GetFloat64",
              &instances[c->from]);
        buffer[k] = c->gain * buffer[k] + c->offset;
    }
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        check(instances[c->to].set_float64(instances[c->to].c, &c->to_vr, 1, &buffer[k], 1), "fmi3SetFloat64",
              &instances[c->to]);
    }
}

static void write_row(FILE *out, double t) {
    fprintf(out, "%.17g", t);
    for (int k = 0; k < n_recorded; k++) {
        const Recorded *r = &recorded[k];
        fmi3Float64 v;
        check(instances[r->instance].get_float64(instances[r->instance].c, &r->vr, 1, &v, 1), "fmi3GetFloat64",
              &instances[r->instance]);
        fprintf(out, ",%.17g", v);
    }
    fputc('\n', out);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: fmi3_closed_loop JOB_FILE OUT_CSV\n");
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
            if (sscanf(line + pos, " %63s %127s %n", inst->name, inst->token, &rest) != 2 || rest == 0)
                fail("bad line", line);
            load(inst, line + pos + rest);
            /* no resources folder in our FMUs: the resource path is not read (NULL is allowed) */
            inst->c = inst->instantiate(inst->name, inst->token, NULL, fmi3False, fmi3False, fmi3False, fmi3False,
                                        NULL, 0, inst, logger, NULL);
            if (!inst->c) fail("fmi3InstantiateCoSimulation failed", inst->name);
            n_instances++;
        } else if (strcmp(kind, "real") == 0 || strcmp(kind, "integer") == 0 || strcmp(kind, "enumeration") == 0 ||
                   strcmp(kind, "boolean") == 0) {
            if (sscanf(line + pos, "%127s %127s %127s", a, b, c) != 3) fail("bad line", line);
            Instance *inst = &instances[instance_index(a)];
            fmi3ValueReference vr = (fmi3ValueReference)strtoul(b, NULL, 10);
            if (kind[0] == 'r') {
                fmi3Float64 v = strtod(c, NULL);
                check(inst->set_float64(inst->c, &vr, 1, &v, 1), "fmi3SetFloat64", inst);
            } else if (kind[0] == 'i') {
                fmi3Int32 v = (fmi3Int32)strtol(c, NULL, 10);
                check(inst->set_int32(inst->c, &vr, 1, &v, 1), "fmi3SetInt32", inst);
            } else if (kind[0] == 'e') {
                fmi3Int64 v = (fmi3Int64)strtoll(c, NULL, 10);
                check(inst->set_int64(inst->c, &vr, 1, &v, 1), "fmi3SetInt64", inst);
            } else {
                fmi3Boolean v = strcmp(c, "0") != 0;
                check(inst->set_boolean(inst->c, &vr, 1, &v, 1), "fmi3SetBoolean", inst);
            }
        } else if (strcmp(kind, "connect") == 0) {
            char e[128], f[128];
            if (sscanf(line + pos, "%127s %127s %127s %127s %127s %127s", a, b, c, d, e, f) != 6) fail("bad line", line);
            if (n_connections == MAX_ITEMS) fail("too many connections", line);
            Connection *k = &connections[n_connections++];
            k->from = instance_index(a);
            k->from_vr = (fmi3ValueReference)strtoul(b, NULL, 10);
            k->to = instance_index(c);
            k->to_vr = (fmi3ValueReference)strtoul(d, NULL, 10);
            k->gain = strtod(e, NULL);
            k->offset = strtod(f, NULL);
        } else if (strcmp(kind, "record") == 0) {
            if (n_recorded == MAX_ITEMS) fail("too many recorded variables", line);
            Recorded *r = &recorded[n_recorded];
            if (sscanf(line + pos, "%127s %127s %127s", a, b, r->column) != 3) fail("bad line", line);
            r->instance = instance_index(a);
            r->vr = (fmi3ValueReference)strtoul(b, NULL, 10);
            n_recorded++;
        } else {
            fail("unknown directive", line);
        }
    }
    fclose(job);
    if (!(step > 0.0) || !(stop > 0.0)) fail("no experiment line with a positive stop time and step", argv[1]);

    for (int i = 0; i < n_instances; i++)
        check(instances[i].enter_initialization(instances[i].c, fmi3False, 0.0, 0.0, fmi3True, stop),
              "fmi3EnterInitializationMode", &instances[i]);
    for (int pass = 0; pass < n_instances; pass++) propagate();
    for (int i = 0; i < n_instances; i++)
        check(instances[i].exit_initialization(instances[i].c), "fmi3ExitInitializationMode", &instances[i]);

    FILE *out = fopen(argv[2], "w");
    if (!out) fail("cannot write", argv[2]);
    fprintf(out, "\"time\"");
    for (int k = 0; k < n_recorded; k++) fprintf(out, ",\"%s\"", recorded[k].column);
    fputc('\n', out);
    write_row(out, 0.0);
    /* the number of steps, rounded: stop is a multiple of step up to rounding of the text */
    long steps = (long)(stop / step + 0.5);
    fmi3Float64 *buffer = calloc((size_t)n_connections + 1, sizeof(fmi3Float64));
    int terminated = 0;
    for (long n = 0; n < steps && !terminated; n++) {
        /* from t_n = n h to t_(n+1) = (n + 1) h, as fmi2_closed_loop steps */
        double t = (double)n * step, t_next = (double)(n + 1) * step, h = t_next - t;
        for (int i = 0; i < n_instances; i++) {
            fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
            fmi3Float64 last = -1.0;
            check(instances[i].do_step(instances[i].c, t, h, fmi3True, &event, &terminate, &early, &last), "fmi3DoStep",
                  &instances[i]);
            if (event || early) {
                fprintf(stderr, "fmi3_closed_loop: fmi3DoStep of %s at t = %.17g: eventHandlingNeeded %d, earlyReturn %d "
                                "without event mode or early return allowed\n",
                        instances[i].name, t, (int)event, (int)early);
                exit(1);
            }
            if (last != t + h) {
                fprintf(stderr, "fmi3_closed_loop: fmi3DoStep of %s at t = %.17g: lastSuccessfulTime %.17g, not t + h = %.17g\n",
                        instances[i].name, t, last, t + h);
                exit(1);
            }
            if (terminate) {
                fprintf(stderr, "fmi3_closed_loop: %s asked to terminate at t = %.17g\n", instances[i].name, t_next);
                terminated = 1;
            }
        }
        write_row(out, t_next);
        propagate_jacobi(buffer);
    }
    free(buffer);
    if (fclose(out) != 0) fail("cannot write", argv[2]);
    for (int i = 0; i < n_instances; i++) {
        check(instances[i].terminate(instances[i].c), "fmi3Terminate", &instances[i]);
        instances[i].free_instance(instances[i].c);
    }
    return 0;
}
