/* An FMI 3.0 Co-Simulation test FMU written against the standard's headers
 * (fmi3Functions.h; the test passes their folder with -I).
 *
 * Variables (value references as in fmi3_counter.xml):
 *   0 time (independent)        1 u  Float64 input (1)      2 y  Float64 output
 *   3 n Int32 output (steps)    4 odd Boolean output        5 mode Enumeration parameter (1)
 *   6 label String parameter    7 stop_at Float64 parameter 8 early_at Float64 parameter
 *   9 k Int32 input             10 m Int32 output (2 k)      11 b Boolean input
 *   12 nb Boolean output (!b)
 *   13 der(y) Float64 local     14 z Float64 local (y - 0.55, the event indicator)
 * and one output of every other type, derived from y and n:
 *   15 f32 Float32 (float)y     16 i8 Int8 n - 5            17 u8 UInt8 20 n
 *   18 i16 Int16 -1000 n        19 u16 UInt16 6000 n        20 u32 UInt32 400000000 n
 *   21 i64 Int64 -2^40 n        22 u64 UInt64 2^48 n        23 bin Binary of n bytes
 *   24 arr Float64[3] (y, 2y, 3y)  25 gains Float64[2] parameter (1 2)
 *   26 gy Float64 gains[1] y + gains[2]   27 flags Boolean[2] (odd, !odd)
 *   28 f32in Float32 input (0.5)   29 f32out Float32 2 f32in
 *   32 i64in Int64 input (0)      33 i64out Int64 output i64in ^ 1 (the lowest bit flipped: exact or not at all)
 *   34 u64in UInt64 input (0)     35 u64out UInt64 output u64in ^ 1
 * and, in the descriptions of the tests of 64-bit arrays only:
 *   36 i64ain Int64[2] input (0 0)   37 i64aout Int64[2] output i64ain[k] ^ 1
 *   38 u64ain UInt64[2] input (0 0)  39 u64aout UInt64[2] output u64ain[k] ^ 1
 *   30 crash_at Float64 parameter: Co-Simulation: the step that starts at or after it crashes;
 *      Model Exchange: a time event there, whose fmi3UpdateDiscreteStates crashes
 *   31 crash_how Int32 parameter: how it crashes: 1 writes through NULL (SIGSEGV), 2 abort()
 *      (SIGABRT), 3 exit(0); 4 no crash: Co-Simulation's step says terminateSimulation with an
 *      early return at lastSuccessfulTime = t + 1000 s, past the step; 5 no crash: an early
 *      return at lastSuccessfulTime = t, no progress; 6 no crash: every call returns early
 *      1/4000 of the way to the step's end (1000 returns do not reach it)
 * and, in the descriptions of the tests of large arrays only (j from 0):
 *   40 big Float64[BIG] output y + j   41 bigi Int32[BIG] output n + j
 *   42 bigb Boolean[BIG] output (n + j) odd   (BIG 100000 unless -DBIG=N)
 *   43 bigw Int64[BIG] output 2^62 + 1 + n + j (none of them an f64)
 *   44 bigw_reads Int32 output: the number of fmi3GetInt64 calls that asked for bigw so far
 * Co-Simulation: each step adds mode * u * h to y (the whole step, or, when the importer allows early
 * return, the part up to early_at when it lies inside it: then it returns early there, once); the step that reaches stop_at says
 * terminateSimulation; with eventModeUsed (a description with hasEventMode), the step in which
 * y reaches 0.55 says eventHandlingNeeded, and fmi3UpdateDiscreteStates then adds 1 to n.
 * Model Exchange: y is the state, der(y) = mode * u; the event
 * indicator z = y - 0.55 crossing zero adds 1 to n, the time event at 0.75 s adds 10, and
 * the time event at stop_at says terminateSimulation; the discrete inputs k and b cannot be set in
 * Continuous-Time Mode (fmi3SetInt32 / fmi3SetBoolean: Illegal call sequence, as the Reference FMUs). Every other fmi3 function
 * exists and returns fmi3Error (fmi3_rest.c, linked beside it). */
#include "fmi3_test.h"

#ifndef BIG
#define BIG 100000 /* the size of the large arrays (-DBIG=N) */
#endif

typedef struct {
    double time, u, y, stop_at, early_at, crash_at;
    int n, k, b, early_done, early_allowed, crossed, timed, crash_how, event_mode, in_event_mode;
    /* Model Exchange: instantiated so, and in Continuous-Time Mode (where the discrete inputs
       k and b cannot be set: FMI 3.0 section 3.2.1, as the Reference FMUs refuse them) */
    int me, me_continuous;
    long long mode;
    char label[64];
    double gains[2];
    float f32in;
    long long i64in, i64ain[2];
    unsigned long long u64in, u64ain[2];
    unsigned char bytes[64];
    int bigw_reads;
} State;

typedef struct {
    State s;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Counter;

/* The start values of a new or reset instance (the rest zero). */
static void defaults(State *s) {
    s->u = 1;
    s->mode = 1;
    s->stop_at = 1e300;
    s->early_at = -1;
    s->crash_at = 1e300;
    s->crash_how = 1;
    s->gains[0] = 1;
    s->gains[1] = 2;
    s->f32in = 0.5f;
    strcpy(s->label, "abc");
}

FMI3_TEST_FAIL(Counter)

static Counter *make(fmi3String token, fmi3String resources, fmi3InstanceEnvironment env, fmi3LogMessageCallback log);

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean eventMode, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference req[], size_t nReq, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
    /* an instance named "...no-event-mode..." refuses eventModeUsed although the description
       may declare hasEventMode (as the Reference FMUs' Roberts does) */
    if (eventMode && name && strstr(name, "no-event-mode")) {
        if (log) log(env, fmi3Error, "logStatusError", "eventModeUsed is not supported");
        return NULL;
    }
    Counter *c = make(token, resources, env, log);
    if (!c) return NULL;
    c->s.early_allowed = earlyReturnAllowed != 0;
    c->s.event_mode = eventMode != 0;
    strcpy(c->s.label, "abc");
    return c;
}

static Counter *make(fmi3String token, fmi3String resources, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    if (!token || strcmp(token, "{fmi3-counter}") != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiationToken");
        return NULL;
    }
    FMI3_TEST_NEW(Counter, !resources || resources[0] != '/' || resources[strlen(resources) - 1] != '/',
        "resourcePath is not an absolute path ending in /", defaults(&c->s))
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
    fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    Counter *c = make(token, resources, env, log);
    if (c) c->s.me = 1;
    return c;
}

void fmi3FreeInstance(fmi3Instance instance) { free(instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
    fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((Counter *)instance)->s.time = startTime;
    return fmi3OK;
}
/* with eventModeUsed the instance is in Event Mode after initialization (FMI 3.0): fmi3DoStep
   is an illegal call there until fmi3EnterStepMode */
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Counter *c = instance;
    c->s.in_event_mode = c->s.event_mode;
    return fmi3OK;
}
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance instance) {
    Counter *c = instance;
    fmi3InstanceEnvironment env = c->env;
    fmi3LogMessageCallback log = c->log;
    int early_allowed = c->s.early_allowed, event_mode = c->s.event_mode, me = c->s.me;
    memset(c, 0, sizeof *c);
    c->s.me = me;
    c->s.early_allowed = early_allowed;
    c->s.event_mode = event_mode;
    c->env = env;
    c->log = log;
    defaults(&c->s);
    return fmi3OK;
}

/* The misbehaviour of third-party FMUs that --isolate contains. */
static void crash(const State *s) {
    if (s->crash_how == 2) abort();
    if (s->crash_how == 3) exit(0);
    *(volatile int *)0 = 1;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
    fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
    fmi3Float64 *lastSuccessfulTime) {
    Counter *c = instance;
    State *s = &c->s;
    double end = t + h;
    if (s->in_event_mode) return fail(c, "fmi3DoStep: Illegal call sequence: in Event Mode (fmi3EnterStepMode first)");
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    if (t >= s->crash_at && s->crash_how == 4) {
        /* no crash: terminateSimulation with an early return "at" t + 1000 s, past the step */
        *terminateSimulation = fmi3True;
        *earlyReturn = fmi3True;
        *lastSuccessfulTime = t + 1000.0;
        return fmi3OK;
    }
    if (t >= s->crash_at && (s->crash_how == 5 || s->crash_how == 6)) {
        /* no crash: an early return without progress (5) or by a 4000th of the step (6) */
        *earlyReturn = fmi3True;
        *lastSuccessfulTime = s->crash_how == 5 ? t : t + h / 4000.0;
        return fmi3OK;
    }
    if (t >= s->crash_at) crash(s);
    if (s->early_allowed && !s->early_done && s->early_at > t && s->early_at < end) {
        s->early_done = 1;
        s->y += (double)s->mode * s->u * (s->early_at - t);
        s->time = s->early_at;
        *earlyReturn = fmi3True;
        *lastSuccessfulTime = s->early_at;
        return fmi3OK;
    }
    s->y += (double)s->mode * s->u * h;
    s->n += 1;
    s->time = end;
    *lastSuccessfulTime = end;
    if (s->event_mode && !s->crossed && s->y - 0.55 >= 0) *eventHandlingNeeded = fmi3True;
    if (end >= s->stop_at) *terminateSimulation = fmi3True;
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3Float64 values[], size_t nValues) {
    Counter *c = instance;
    size_t k = 0;
    for (size_t i = 0; i < nvr; i++) {
        size_t size = vr[i] == 24 ? 3 : vr[i] == 25 ? 2 : vr[i] == 40 ? BIG : 1;
        if (k + size > nValues) return fail(c, "fmi3GetFloat64: nValues too small");
        switch (vr[i]) {
        case 0: values[k] = c->s.time; break;
        case 1: values[k] = c->s.u; break;
        case 2: values[k] = c->s.y; break;
        case 7: values[k] = c->s.stop_at; break;
        case 8: values[k] = c->s.early_at; break;
        case 13: values[k] = (double)c->s.mode * c->s.u; break;
        case 14: values[k] = c->s.y - 0.55; break;
        case 24: values[k] = c->s.y; values[k + 1] = 2 * c->s.y; values[k + 2] = 3 * c->s.y; break;
        case 25: values[k] = c->s.gains[0]; values[k + 1] = c->s.gains[1]; break;
        case 26: values[k] = c->s.gains[0] * c->s.y + c->s.gains[1]; break;
        case 30: values[k] = c->s.crash_at; break;
        case 40: for (size_t j = 0; j < BIG; j++) values[k + j] = c->s.y + (double)j; break;
        default: return fail(c, "fmi3GetFloat64: no such Float64");
        }
        k += size;
    }
    if (k != nValues) return fail(c, "fmi3GetFloat64: nValues is not the number of values");
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3Float64 values[], size_t nValues) {
    Counter *c = instance;
    size_t k = 0;
    for (size_t i = 0; i < nvr; i++) {
        size_t size = vr[i] == 25 ? 2 : 1;
        if (k + size > nValues) return fail(c, "fmi3SetFloat64: nValues too small");
        switch (vr[i]) {
        case 1: c->s.u = values[k]; break;
        case 7: c->s.stop_at = values[k]; break;
        case 8: c->s.early_at = values[k]; break;
        case 25: c->s.gains[0] = values[k]; c->s.gains[1] = values[k + 1]; break;
        case 30: c->s.crash_at = values[k]; break;
        default: return fail(c, "fmi3SetFloat64: not settable");
        }
        k += size;
    }
    if (k != nValues) return fail(c, "fmi3SetFloat64: nValues is not the number of values");
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3Int32 values[], size_t nValues) {
    Counter *c = instance;
    if (nvr == 1 && vr[0] == 41) { /* the array bigi */
        if (nValues != BIG) return fail(c, "fmi3GetInt32: nValues is not the size of bigi");
        for (size_t j = 0; j < BIG; j++) values[j] = c->s.n + (fmi3Int32)j;
        return fmi3OK;
    }
    if (nvr != nValues) return fail(c, "fmi3GetInt32: nValues != nValueReferences");
    for (size_t i = 0; i < nvr; i++) {
        switch (vr[i]) {
        case 3: values[i] = c->s.n; break;
        case 9: values[i] = c->s.k; break;
        case 31: values[i] = c->s.crash_how; break;
        case 44: values[i] = c->s.bigw_reads; break;
        case 10: values[i] = 2 * c->s.k; break;
        default: return fail(c, "fmi3GetInt32: no such Int32");
        }
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3Int32 values[], size_t nValues) {
    Counter *c = instance;
    if (nvr != nValues) return fail(c, "fmi3SetInt32: nValues != nValueReferences");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == 9 && c->s.me_continuous)
            return fail(c, "fmi3SetInt32: Illegal call sequence (the discrete input k in Continuous-Time Mode)");
        if (vr[i] == 9) c->s.k = values[i];
        else if (vr[i] == 31 && values[i] >= 1 && values[i] <= 6) c->s.crash_how = values[i];
        else return fail(c, "fmi3SetInt32: not settable");
    }
    return fmi3OK;
}

/* fmi3Get<Kind> and fmi3Set<Kind> of the 64-bit integers (C type fmi3<Kind>): the 2-element
 * array input `array` (value reference `array_vr`) and its output (array_vr + 1), each element
 * with its lowest bit flipped, the output array of BIG elements `big_vr` read by
 * `get_big(c, values)`, then the scalars, read by `get_scalar(c, vr, &value)` (0: no such
 * variable) and set by `set_scalar(c, vr, value)` (NULL, or why not). Values are consumed in
 * order, an array taking as many as it has elements. */
#define WIDE_GET_SET(Kind, array_vr, array, big_vr, get_big, get_scalar, set_scalar)               \
    fmi3Status fmi3Get##Kind(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,    \
        fmi3##Kind values[], size_t nValues) {                                                     \
        Counter *c = instance;                                                                     \
        size_t j = 0;                                                                              \
        for (size_t i = 0; i < nvr; i++) {                                                         \
            if (vr[i] == big_vr) {                                                                 \
                if (j + BIG > nValues) return fail(c, "fmi3Get" #Kind ": nValues too small");       \
                get_big(c, values + j);                                                            \
                j += BIG;                                                                          \
                continue;                                                                          \
            }                                                                                      \
            size_t size = vr[i] == array_vr || vr[i] == array_vr + 1 ? 2 : 1;                      \
            if (j + size > nValues) return fail(c, "fmi3Get" #Kind ": nValues too small");          \
            if (size == 2)                                                                         \
                for (int k = 0; k < 2; k++) values[j++] = vr[i] == array_vr ? c->s.array[k] : c->s.array[k] ^ 1; \
            else if (!get_scalar(c, vr[i], &values[j++]))                                          \
                return fail(c, "fmi3Get" #Kind ": no such variable");                              \
        }                                                                                          \
        return j == nValues ? fmi3OK : fail(c, "fmi3Get" #Kind ": nValues does not match");        \
    }                                                                                              \
    fmi3Status fmi3Set##Kind(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,    \
        const fmi3##Kind values[], size_t nValues) {                                               \
        Counter *c = instance;                                                                     \
        size_t j = 0;                                                                              \
        for (size_t i = 0; i < nvr; i++) {                                                         \
            size_t size = vr[i] == array_vr ? 2 : 1;                                               \
            if (j + size > nValues) return fail(c, "fmi3Set" #Kind ": nValues too small");          \
            const char *refusal = NULL;                                                            \
            if (size == 2)                                                                         \
                for (int k = 0; k < 2; k++) c->s.array[k] = values[j++];                           \
            else if ((refusal = set_scalar(c, vr[i], values[j++])))                                \
                return fail(c, refusal);                                                           \
        }                                                                                          \
        return j == nValues ? fmi3OK : fail(c, "fmi3Set" #Kind ": nValues does not match");        \
    }

static int get_int64(const Counter *c, fmi3ValueReference vr, fmi3Int64 *value) {
    switch (vr) {
    case 5: *value = c->s.mode; return 1;
    case 21: *value = -(1LL << 40) * c->s.n; return 1;
    case 32: *value = c->s.i64in; return 1;
    case 33: *value = c->s.i64in ^ 1; return 1;
    default: return 0;
    }
}
static const char *set_int64(Counter *c, fmi3ValueReference vr, fmi3Int64 value) {
    if (vr == 32) c->s.i64in = value;
    else if (vr != 5) return "fmi3SetInt64: not settable";
    else if (value != 1 && value != 2) return "fmi3SetInt64: mode must be 1 or 2";
    else c->s.mode = value;
    return NULL;
}
/* bigw, counting its reads */
static void get_bigw(Counter *c, fmi3Int64 values[]) {
    for (size_t e = 0; e < BIG; e++) values[e] = (1LL << 62) + 1 + c->s.n + (fmi3Int64)e;
    c->s.bigw_reads += 1;
}
WIDE_GET_SET(Int64, 36, i64ain, 43, get_bigw, get_int64, set_int64)

static int get_uint64(const Counter *c, fmi3ValueReference vr, fmi3UInt64 *value) {
    switch (vr) {
    case 22: *value = (1ULL << 48) * (unsigned long long)c->s.n; return 1;
    case 34: *value = c->s.u64in; return 1;
    case 35: *value = c->s.u64in ^ 1; return 1;
    default: return 0;
    }
}
static const char *set_uint64(Counter *c, fmi3ValueReference vr, fmi3UInt64 value) {
    if (vr != 34) return "fmi3SetUInt64: not settable";
    c->s.u64in = value;
    return NULL;
}
/* no UInt64 array of BIG elements: a value reference no variable has */
static void no_big(Counter *c, fmi3UInt64 values[]) {}
WIDE_GET_SET(UInt64, 38, u64ain, 0xFFFFFFFFu, no_big, get_uint64, set_uint64)

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3Boolean values[], size_t nValues) {
    Counter *c = instance;
    size_t k = 0;
    for (size_t i = 0; i < nvr; i++) {
        size_t size = vr[i] == 27 ? 2 : vr[i] == 42 ? BIG : 1;
        if (k + size > nValues) return fail(c, "fmi3GetBoolean: nValues too small");
        switch (vr[i]) {
        case 4: values[k] = (c->s.n % 2) == 1; break;
        case 11: values[k] = c->s.b != 0; break;
        case 12: values[k] = c->s.b == 0; break;
        case 27: values[k] = (c->s.n % 2) == 1; values[k + 1] = (c->s.n % 2) == 0; break;
        case 42: for (size_t j = 0; j < BIG; j++) values[k + j] = ((c->s.n + j) % 2) == 1; break;
        default: return fail(c, "fmi3GetBoolean: no such Boolean");
        }
        k += size;
    }
    return k == nValues ? fmi3OK : fail(c, "fmi3GetBoolean: nValues is not the number of values");
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3Boolean values[], size_t nValues) {
    Counter *c = instance;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != 11) return fail(c, "fmi3SetBoolean: not settable");
        if (c->s.me_continuous)
            return fail(c, "fmi3SetBoolean: Illegal call sequence (the discrete input b in Continuous-Time Mode)");
        c->s.b = values[i] ? 1 : 0;
    }
    return fmi3OK;
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    fmi3String values[], size_t nValues) {
    Counter *c = instance;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != 6) return fail(c, "fmi3GetString: no such String");
        values[i] = c->s.label;
    }
    return fmi3OK;
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
    const fmi3String values[], size_t nValues) {
    Counter *c = instance;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != 6 || !values[i] || strlen(values[i]) >= sizeof c->s.label) return fail(c, "fmi3SetString: not settable");
        strcpy(c->s.label, values[i]);
    }
    return fmi3OK;
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    Counter *c = instance;
    if (!*state) *state = malloc(sizeof(State));
    if (!*state) return fail(c, "fmi3GetFMUState: out of memory");
    memcpy(*state, &c->s, sizeof(State));
    return fmi3OK;
}
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    memcpy(&((Counter *)instance)->s, state, sizeof(State));
    return fmi3OK;
}
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    free(*state);
    *state = NULL;
    return fmi3OK;
}

/* The outputs of the other types (one value each). */
#define SCALAR_GETTER(T, VR, EXPR) \
    fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3##T values[], size_t nValues) { \
        Counter *c = instance; \
        if (nvr != nValues) return fail(c, "fmi3Get" #T ": nValues != nValueReferences"); \
        for (size_t i = 0; i < nvr; i++) { \
            if (vr[i] != VR) return fail(c, "fmi3Get" #T ": no such variable"); \
            values[i] = (fmi3##T)(EXPR); \
        } \
        return fmi3OK; \
    }
SCALAR_GETTER(Int8, 16, c->s.n - 5)
SCALAR_GETTER(UInt8, 17, 20 * c->s.n)
SCALAR_GETTER(Int16, 18, -1000 * c->s.n)
SCALAR_GETTER(UInt16, 19, 6000 * c->s.n)
SCALAR_GETTER(UInt32, 20, 400000000u * (unsigned)c->s.n)

fmi3Status fmi3GetFloat32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float32 values[], size_t nValues) {
    Counter *c = instance;
    if (nvr != nValues) return fail(c, "fmi3GetFloat32: nValues != nValueReferences");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == 15) values[i] = (float)c->s.y;
        else if (vr[i] == 28) values[i] = c->s.f32in;
        else if (vr[i] == 29) values[i] = 2 * c->s.f32in;
        else return fail(c, "fmi3GetFloat32: no such Float32");
    }
    return fmi3OK;
}
fmi3Status fmi3SetFloat32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float32 values[], size_t nValues) {
    Counter *c = instance;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != 28) return fail(c, "fmi3SetFloat32: not settable");
        c->s.f32in = values[i];
    }
    return fmi3OK;
}
fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, size_t sizes[],
    fmi3Binary values[], size_t nValues) {
    Counter *c = instance;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != 23) return fail(c, "fmi3GetBinary: no such Binary");
        sizes[i] = (size_t)c->s.n < sizeof c->s.bytes ? (size_t)c->s.n : sizeof c->s.bytes;
        values[i] = c->s.bytes;
    }
    return fmi3OK;
}

/* Model Exchange. */
fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    Counter *c = instance;
    c->s.in_event_mode = c->s.event_mode;
    c->s.me_continuous = 0;
    return fmi3OK;
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    ((Counter *)instance)->s.me_continuous = 1;
    return fmi3OK;
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Counter *)instance)->s.time = time;
    return fmi3OK;
}
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    State *s = &((Counter *)instance)->s;
    if (s->time >= s->crash_at) crash(s);
    if (!s->crossed && s->y - 0.55 >= 0) {
        s->crossed = 1;
        s->n += 1;
    }
    if (!s->timed && s->time >= 0.75) {
        s->timed = 1;
        s->n += 10;
    }
    *needUpdate = fmi3False;
    *terminate = s->time >= s->stop_at;
    *nominalsChanged = fmi3False;
    *valuesChanged = fmi3False;
    /* the next of the time events at 0.75 s (once), stop_at and crash_at */
    *next = s->stop_at;
    if (!s->timed && 0.75 < *next) *next = 0.75;
    if (s->crash_at > s->time && s->crash_at < *next) *next = s->crash_at;
    *nextDefined = *next < 1e300;
    return fmi3OK;
}
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetPrior, fmi3Boolean *enterEventMode,
    fmi3Boolean *terminate) {
    *enterEventMode = fmi3False;
    *terminate = fmi3False;
    return fmi3OK;
}
fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) {
    Counter *c = instance;
    if (n != 1) return fail(c, "fmi3SetContinuousStates: one state");
    c->s.y = x[0];
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {
    Counter *c = instance;
    if (n != 1) return fail(c, "fmi3GetContinuousStates: one state");
    x[0] = c->s.y;
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) {
    Counter *c = instance;
    if (n != 1) return fail(c, "fmi3GetContinuousStateDerivatives: one state");
    dx[0] = (double)c->s.mode * c->s.u;
    return fmi3OK;
}
fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) {
    Counter *c = instance;
    if (n != 1) return fail(c, "fmi3GetEventIndicators: one event indicator");
    z[0] = c->s.y - 0.55;
    return fmi3OK;
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {
    for (size_t i = 0; i < n; i++) x[i] = 1;
    return fmi3OK;
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) { *n = 1; return fmi3OK; }
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) { *n = 1; return fmi3OK; }
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Counter *c = instance;
    if (!c->s.event_mode) return fail(c, "fmi3EnterStepMode: not instantiated with eventModeUsed");
    c->s.in_event_mode = 0;
    return fmi3OK;
}
