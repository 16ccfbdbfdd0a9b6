/* An FMI 2.0 Model Exchange FMU with no continuous states and no event indicators, which
 * refuses (fmi2Error) every call of fmi2GetContinuousStates, fmi2SetContinuousStates,
 * fmi2GetDerivatives, fmi2GetNominalsOfContinuousStates and fmi2GetEventIndicators, as
 * some third-party FMUs refuse them with nx = 0 or nz = 0.
 * Value references: 0 y = slope * time + offset (output, continuous), 1 slope (parameter),
 * 2 t_step (parameter), 3 offset (local, discrete: 0, then 1 from the time event at
 * t_step). */
#define FMI2_TEST_NO_FMU_STATE
#include "fmi2_test.h"

typedef struct {
    double slope, t_step, offset, time;
} Ramp;

/* offset and time 0 */
static void defaults(Ramp *r) { *r = (Ramp){.slope = 2.0, .t_step = 0.55}; }

FMI2_TEST_MODEL_EXCHANGE(Ramp)

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, double v[]) {
    Ramp *r = c;
    size_t i;
    for (i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: v[i] = r->slope * r->time + r->offset; break;
        case 1: v[i] = r->slope; break;
        case 2: v[i] = r->t_step; break;
        case 3: v[i] = r->offset; break;
        default: return ERR;
        }
    }
    return 0;
}
FMI2_TEST_SET_REAL_MEMBERS(Ramp, [1] = &m->slope, [2] = &m->t_step)

EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Ramp *r = c;
    memset(info, 0, sizeof *info);
    if (r->offset == 0.0 && r->time >= r->t_step) r->offset = 1.0;
    if (r->offset == 0.0) {
        info->nextEventTimeDefined = 1;
        info->nextEventTime = r->t_step;
    }
    return 0;
}
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const double x[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, double x[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, double dx[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, double z[], size_t n) { return ERR; }
EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, double x[], size_t n) { return ERR; }

