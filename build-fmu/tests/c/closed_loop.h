/*
 * closed_loop.h: the fixed-step Jacobi closed loop of fmi2_closed_loop.c and
 * fmi3_closed_loop.c, once: reading the job file, the connections, the rows, the steps.
 * Each importer is this loop bound to one C API. Before including it, a file includes
 * importer.h (and its API's headers) and defines:
 *
 *   PROGRAM             the program's name, for its messages
 *   ValueReference      its API's value reference type
 *   Instance            a struct with `char name[64]`, `char token[128]` (GUID or
 *                       instantiationToken) and its API's functions
 * and these functions of an Instance (each stops the program with a message on an error):
 *   load(inst, path)                       the API's functions from the library at path
 *   instantiate(inst)                      a Co-Simulation instance (name and token set)
 *   set_start(inst, kind, vr, text)        a start value of job line `kind` (real, integer,
 *                                          enumeration, boolean); 0 if the API has no such kind
 *   get_real(inst, vr) / set_real(inst, vr, v)   one Real (Float64) value
 *   setup_experiment(inst, stop)           before Initialization Mode (FMI 2.0's call)
 *   enter_initialization(inst, stop), exit_initialization(inst)
 *   do_step(inst, t, h)                    one step from t to t + h; nonzero when the
 *                                          instance asks to terminate (the run then ends
 *                                          after the row of that step)
 *   end(inst)                              terminate and free the instance
 *
 * Algorithm: fixed-step Jacobi, as fmpy, libcosim and nigel_cosim's `jacobi` do it: every
 * instance steps from t to t + h with the inputs set at t, the row of t + h is recorded
 * (outputs before any input changes), then every input is set from the outputs at t + h.
 * In Initialization Mode the connections are applied as many times as there are
 * instances, so values reach the end of any feedthrough chain. Time is t0 + n h, with n an
 * integer, so it does not drift; each step is t_(n+1) - t_n. Rows are written with 17
 * significant digits (%.17g), which round-trip every double.
 */
#ifndef CLOSED_LOOP_H
#define CLOSED_LOOP_H

#define MAX_INSTANCES 8
#define MAX_ITEMS 4096
#define LINE 4096

typedef struct { int from, to; ValueReference from_vr, to_vr; double gain, offset; } Connection;
typedef struct { int instance; ValueReference vr; char column[128]; } Recorded;

static Instance instances[MAX_INSTANCES];
static int n_instances;
static Connection connections[MAX_ITEMS];
static int n_connections;
static Recorded recorded[MAX_ITEMS];
static int n_recorded;

static void fail(const char *what, const char *detail) {
    fprintf(stderr, PROGRAM ": %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(1);
}

/* Stops the program unless `status` is OK (0 in both APIs). */
static void check(int status, const char *function, const Instance *inst) {
    if (status != 0) {
        fprintf(stderr, PROGRAM ": %s of %s returned status %d\n", function, inst->name, status);
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
        fprintf(stderr, PROGRAM ": %s: no symbol %s\n", path, name);
        exit(1);
    }
    return p;
}

static void load(Instance *inst, const char *path);
static void instantiate(Instance *inst);
static int set_start(Instance *inst, char kind, ValueReference vr, const char *text);
static double get_real(Instance *inst, ValueReference vr);
static void set_real(Instance *inst, ValueReference vr, double v);
static void setup_experiment(Instance *inst, double stop);
static void enter_initialization(Instance *inst, double stop);
static void exit_initialization(Instance *inst);
static int do_step(Instance *inst, double t, double h);
static void end(Instance *inst);

static void propagate(void) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        double v = get_real(&instances[c->from], c->from_vr);
        set_real(&instances[c->to], c->to_vr, c->gain * v + c->offset);
    }
}

/* Jacobi: every source value read before any input is set. */
static void propagate_jacobi(double *buffer) {
    for (int k = 0; k < n_connections; k++) {
        const Connection *c = &connections[k];
        buffer[k] = get_real(&instances[c->from], c->from_vr);
        buffer[k] = c->gain * buffer[k] + c->offset;
    }
    for (int k = 0; k < n_connections; k++) set_real(&instances[connections[k].to], connections[k].to_vr, buffer[k]);
}

static void write_row(FILE *out, double t) {
    fprintf(out, "%.17g", t);
    for (int k = 0; k < n_recorded; k++) fprintf(out, ",%.17g", get_real(&instances[recorded[k].instance], recorded[k].vr));
    fputc('\n', out);
}

/* The job file's directives (see the importers' heads); returns the stop time and step. */
static void read_job(const char *path, double *stop, double *step) {
    FILE *job = fopen(path, "r");
    if (!job) fail("cannot open job file", path);
    char line[LINE];
    while (fgets(line, sizeof line, job)) {
        line[strcspn(line, "\r\n")] = 0;
        char kind[32], a[128], b[128], c[128], d[128];
        int pos = 0;
        if (sscanf(line, "%31s%n", kind, &pos) != 1) continue;
        if (strcmp(kind, "experiment") == 0) {
            if (sscanf(line + pos, "%127s %127s", a, b) != 2) fail("bad line", line);
            *stop = strtod(a, NULL);
            *step = strtod(b, NULL);
        } else if (strcmp(kind, "fmu") == 0) {
            int rest = 0;
            if (n_instances == MAX_INSTANCES) fail("too many instances", line);
            Instance *inst = &instances[n_instances];
            if (sscanf(line + pos, " %63s %127s %n", inst->name, inst->token, &rest) != 2 || rest == 0)
                fail("bad line", line);
            load(inst, line + pos + rest);
            instantiate(inst);
            n_instances++;
        } else if (strcmp(kind, "real") == 0 || strcmp(kind, "integer") == 0 || strcmp(kind, "enumeration") == 0 ||
                   strcmp(kind, "boolean") == 0) {
            if (sscanf(line + pos, "%127s %127s %127s", a, b, c) != 3) fail("bad line", line);
            Instance *inst = &instances[instance_index(a)];
            if (!set_start(inst, kind[0], (ValueReference)strtoul(b, NULL, 10), c)) fail("unknown directive", line);
        } else if (strcmp(kind, "connect") == 0) {
            char e[128], f[128];
            if (sscanf(line + pos, "%127s %127s %127s %127s %127s %127s", a, b, c, d, e, f) != 6) fail("bad line", line);
            if (n_connections == MAX_ITEMS) fail("too many connections", line);
            Connection *k = &connections[n_connections++];
            k->from = instance_index(a);
            k->from_vr = (ValueReference)strtoul(b, NULL, 10);
            k->to = instance_index(c);
            k->to_vr = (ValueReference)strtoul(d, NULL, 10);
            k->gain = strtod(e, NULL);
            k->offset = strtod(f, NULL);
        } else if (strcmp(kind, "record") == 0) {
            if (n_recorded == MAX_ITEMS) fail("too many recorded variables", line);
            Recorded *r = &recorded[n_recorded];
            if (sscanf(line + pos, "%127s %127s %127s", a, b, r->column) != 3) fail("bad line", line);
            r->instance = instance_index(a);
            r->vr = (ValueReference)strtoul(b, NULL, 10);
            n_recorded++;
        } else {
            fail("unknown directive", line);
        }
    }
    fclose(job);
    if (!(*step > 0.0) || !(*stop > 0.0)) fail("no experiment line with a positive stop time and step", path);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: " PROGRAM " JOB_FILE OUT_CSV\n");
        return 2;
    }
    double stop = 0.0, step = 0.0;
    read_job(argv[1], &stop, &step);

    for (int i = 0; i < n_instances; i++) setup_experiment(&instances[i], stop);
    for (int i = 0; i < n_instances; i++) enter_initialization(&instances[i], stop);
    for (int pass = 0; pass < n_instances; pass++) propagate();
    for (int i = 0; i < n_instances; i++) exit_initialization(&instances[i]);

    FILE *out = fopen(argv[2], "w");
    if (!out) fail("cannot write", argv[2]);
    fprintf(out, "\"time\"");
    for (int k = 0; k < n_recorded; k++) fprintf(out, ",\"%s\"", recorded[k].column);
    fputc('\n', out);
    write_row(out, 0.0);
    /* the number of steps, rounded: stop is a multiple of step up to rounding of the text */
    long steps = (long)(stop / step + 0.5);
    double *buffer = calloc((size_t)n_connections + 1, sizeof(double));
    int terminated = 0;
    for (long n = 0; n < steps && !terminated; n++) {
        /* from t_n = n h to t_(n+1) = (n + 1) h: the step is their difference, so that
           t_n + step lands on the grid (nigel_cosim does the same) */
        double t = (double)n * step, t_next = (double)(n + 1) * step;
        for (int i = 0; i < n_instances; i++) terminated |= do_step(&instances[i], t, t_next - t);
        write_row(out, t_next);
        propagate_jacobi(buffer);
    }
    free(buffer);
    if (fclose(out) != 0) fail("cannot write", argv[2]);
    for (int i = 0; i < n_instances; i++) end(&instances[i]);
    return 0;
}

#endif
