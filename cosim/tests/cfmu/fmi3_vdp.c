/* Van der Pol's oscillator as an FMI 3.0 Model Exchange test FMU (tests/cfmu/vdp.c's model):
 *   x0' = x1,  x1' = mu (1 - x0^2) x1 - x0,  x0(0) = 2, x1(0) = 0,
 * with fmi3GetDirectionalDerivative of the state derivatives with respect to the states
 * (the Jacobian [[0, 1], [-2 mu x0 x1 - 1, mu (1 - x0^2)]]). Value references: 1 x0,
 * 2 der(x0), 3 x1, 4 der(x1), 5 mu (parameter). Built with -DOVERRUN_SENSITIVITY,
 * fmi3GetDirectionalDerivative writes sensitivity[nSensitivity] and
 * sensitivity[nSensitivity + 1], past the master's buffer. No event indicators, no events. */
#include "fmi3_test.h"

typedef struct {
    double time, x0, x1, mu;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Vdp;

FMI3_TEST_FAIL(Vdp)

static void start(Vdp *v) {
    v->x0 = 2.0;
    v->mu = 1.0;
}

FMI3_TEST_MODEL_EXCHANGE_INSTANCE(Vdp, "{fmi3-vdp}", start)
void fmi3FreeInstance(fmi3Instance instance) { free(instance); }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) { return fmi3OK; }
fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
    fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ((Vdp *)instance)->time = startTime;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3EnterEventMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { return fmi3OK; }
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime) {
    return updated_discrete_states(discreteStatesNeedUpdate, terminateSimulation, nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged, nextEventTimeDefined, nextEventTime);
}
FMI3_TEST_NO_STEP_EVENTS
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Vdp *)instance)->time = time;
    return fmi3OK;
}

static double derivative(const Vdp *v, int k) { return k == 0 ? v->x1 : v->mu * (1.0 - v->x0 * v->x0) * v->x1 - v->x0; }

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
    size_t nValues) {
    Vdp *v = instance;
    if (nvr != nValues) return fail(v, "fmi3GetFloat64: nValues != nValueReferences");
    for (size_t i = 0; i < nvr; i++) {
        switch (vr[i]) {
        case 0: values[i] = v->time; break;
        case 1: values[i] = v->x0; break;
        case 2: values[i] = derivative(v, 0); break;
        case 3: values[i] = v->x1; break;
        case 4: values[i] = derivative(v, 1); break;
        case 5: values[i] = v->mu; break;
        default: return fail(v, "fmi3GetFloat64: no such variable");
        }
    }
    return fmi3OK;
}
FMI3_TEST_SET(Float64, fmi3Float64, Vdp, "not settable", [1] = &c->x0, [3] = &c->x1, [5] = &c->mu)
FMI3_TEST_CONTINUOUS_STATES(Vdp, 2, &c->x0, &c->x1)
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) {
    Vdp *v = instance;
    if (n != 2) return fail(v, "fmi3GetContinuousStateDerivatives: n != 2");
    dx[0] = derivative(v, 0);
    dx[1] = derivative(v, 1);
    return fmi3OK;
}

/* d der(unknown) / d state(known), by value reference */
static int partial(const Vdp *v, fmi3ValueReference unknown, fmi3ValueReference known, double *out) {
    if (unknown == 2 && known == 1) *out = 0.0;
    else if (unknown == 2 && known == 3) *out = 1.0;
    else if (unknown == 4 && known == 1) *out = -2.0 * v->mu * v->x0 * v->x1 - 1.0;
    else if (unknown == 4 && known == 3) *out = v->mu * (1.0 - v->x0 * v->x0);
    else return 0;
    return 1;
}
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
    fmi3Float64 sensitivity[], size_t nSensitivity) {
    Vdp *v = instance;
    double p;
    if (nSeed != nKnowns || nSensitivity != nUnknowns) return fail(v, "fmi3GetDirectionalDerivative: sizes");
#ifdef OVERRUN_SENSITIVITY
    sensitivity[nSensitivity] = sensitivity[nSensitivity + 1] = 0.0; /* past the master's buffer */
#endif
    for (size_t i = 0; i < nUnknowns; i++) {
        sensitivity[i] = 0.0;
        for (size_t j = 0; j < nKnowns; j++) {
            if (!partial(v, unknowns[i], knowns[j], &p)) return fail(v, "fmi3GetDirectionalDerivative: not a partial");
            sensitivity[i] += p * seed[j];
        }
    }
    return fmi3OK;
}
