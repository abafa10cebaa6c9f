/* The PD autopilot of eq (20) as an FMI 2.0 co-simulation FMU written in C.

       delta_c = Kp wrap(psi - psi_d) + Kd r,   wrap: to (-pi, pi]

   The same law as autopilot_fmu/pd.py (pd_law.h, which its FMI 3.0 twin
   pd_autopilot_c_fmi3.c includes too), to show that an autopilot in any language that
   can export the FMI 2.0 C API drops into the co-simulation (docs/own_autopilot.md).
   Built by fmubuild.cbuild against the FMI 2.0 headers fmpy ships in fmpy/c-code.

   Value references: 0 psi, 1 r, 2 psi_d (inputs), 3 delta_c (output), 4 Kp, 5 Kd.

   As the project's Python FMUs do (docs/robustness.md): a step with an input that is
   not finite fails the FMU, fmi2Error; from then on delta_c reads NaN and every step
   fails with the same reason, until fmi2Reset. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "pd_law.h"

enum { PSI, R, PSI_D, DELTA_C, KP, KD, N_VARIABLES };
enum Phase { INSTANTIATED, INITIALIZATION, STEP, TERMINATED };

typedef struct {
    fmi2Real value[N_VARIABLES];
    enum Phase phase;
    fmi2CallbackFunctions callbacks;
    char *name;
    fmi2Boolean logging;
    char failure[128];                            /* why the FMU failed; "" if it has not */
} Instance;

static const fmi2Real START[N_VARIABLES] = {0.0, 0.0, 0.0, 0.0, 2.0, 50.0};

static void say(Instance *c, fmi2Status status, const char *category, const char *format, ...) {
    char message[512];
    int named;
    va_list args;
    if (status < fmi2Error && !c->logging) return;
    /* Named, as every FMU of this project names itself: some hosts' logs do not. */
    named = snprintf(message, sizeof message, "%s: ", c->name);
    if (named < 0 || (size_t)named >= sizeof message) named = 0;
    va_start(args, format);
    vsnprintf(message + named, sizeof message - (size_t)named, format, args);
    va_end(args);
    /* Passed as the format, without arguments: hosts that cannot take variadic
       callbacks (fmpy's ctypes logger) show the format. No message here holds a '%'. */
    if (c->callbacks.logger)
        c->callbacks.logger(c->callbacks.componentEnvironment, c->name, status, category,
                            message);
}

/* Log an error (always) and return the status the call ends with. */
#define REFUSE(c, status, ...) (say((c), (status), "logStatusError", __VA_ARGS__), (status))

static fmi2Real rudder_command(const Instance *c) {  /* eq (20) */
    const fmi2Real *v = c->value;
    return pd_rudder_command(v[KP], v[KD], v[PSI], v[R], v[PSI_D]);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                              fmi2String resources, const fmi2CallbackFunctions *callbacks,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Instance *c;
    (void)resources; (void)visible;
    if (type != fmi2CoSimulation || !name || !guid
            || strcmp(guid, "{5d0b1c4e-9a51-4b9c-8f57-3f0b5a3d2e71}") != 0)
        return NULL;
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->name = malloc(strlen(name) + 1);
    if (!c->name) { free(c); return NULL; }
    strcpy(c->name, name);
    if (callbacks) c->callbacks = *callbacks;
    c->logging = loggingOn;
    memcpy(c->value, START, sizeof START);
    c->phase = INSTANTIATED;
    return c;
}

void fmi2FreeInstance(fmi2Component component) {
    Instance *c = component;
    if (!c) return;
    free(c->name);
    free(c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn,
                               size_t nCategories, const fmi2String categories[]) {
    (void)nCategories; (void)categories;
    ((Instance *)component)->logging = loggingOn;
    return fmi2OK;
}

/* fmi2OK if the instance is in ``phase``; else an error naming the call. */
static fmi2Status require(Instance *c, enum Phase phase, const char *call) {
    static const char *const after[] = {"fmi2Instantiate", "fmi2EnterInitializationMode",
                                        "fmi2ExitInitializationMode", "fmi2Terminate"};
    if (c->phase == phase) return fmi2OK;
    return REFUSE(c, fmi2Error, "%s is only allowed after %s", call, after[phase]);
}

fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)startTime; (void)stopTimeDefined;
    (void)stopTime;
    return require(component, INSTANTIATED, "fmi2SetupExperiment");
}

/* From phase ``from`` to ``to``, or an error naming the call. */
static fmi2Status advance(Instance *c, enum Phase from, enum Phase to, const char *call) {
    fmi2Status status = require(c, from, call);
    if (status == fmi2OK) c->phase = to;
    return status;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component) {
    return advance(component, INSTANTIATED, INITIALIZATION, "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    Instance *c = component;
    if (require(c, INITIALIZATION, "fmi2ExitInitializationMode") != fmi2OK) return fmi2Error;
    if (!isfinite(c->value[KP]) || !isfinite(c->value[KD]))
        return REFUSE(c, fmi2Error, "parameter %s is not finite",
                      isfinite(c->value[KP]) ? "Kd" : "Kp");
    c->phase = STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component component) {
    Instance *c = component;
    if (c->failure[0]) {                          /* a failed FMU may end in any phase */
        c->phase = TERMINATED;
        return fmi2OK;
    }
    return advance(c, STEP, TERMINATED, "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component component) {
    Instance *c = component;
    memcpy(c->value, START, sizeof START);
    c->phase = INSTANTIATED;
    c->failure[0] = '\0';
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Instance *c = component;
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES)
            return REFUSE(c, fmi2Error, "no Real variable has value reference %u", vr[i]);
        value[i] = vr[i] != DELTA_C ? c->value[vr[i]] : c->failure[0] ? NAN : rudder_command(c);
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Instance *c = component;
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES || vr[i] == DELTA_C)
            return REFUSE(c, fmi2Error, "value reference %u is not an input or parameter",
                          vr[i]);
        if (vr[i] >= KP && c->phase != INSTANTIATED && c->phase != INITIALIZATION)
            return REFUSE(c, fmi2Error, "parameter %s is fixed after initialization",
                          vr[i] == KP ? "Kp" : "Kd");
    }
    for (i = 0; i < nvr; i++) c->value[vr[i]] = value[i];
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real t, fmi2Real h,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    static const char *const input[] = {"psi", "r", "psi_d"};
    Instance *c = component;
    int i;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (c->failure[0]) return REFUSE(c, fmi2Error, "%s", c->failure);
    if (require(c, STEP, "fmi2DoStep") != fmi2OK) return fmi2Error;
    if (!(h > 0.0))
        return REFUSE(c, fmi2Error, "doStep with a communication step of %g s", h);
    for (i = PSI; i <= PSI_D; i++)
        if (!isfinite(c->value[i])) {
            snprintf(c->failure, sizeof c->failure, "doStep at t = %g: input %s = %g is not "
                     "finite; the FMU has failed (delta_c reads NaN until fmi2Reset)", t,
                     input[i], c->value[i]);
            return REFUSE(c, fmi2Error, "%s", c->failure);
        }
    return fmi2OK;                                /* memoryless: nothing to advance */
}

/* What this FMU does not do. */
static fmi2Status unsupported(fmi2Component component, const char *call) {
    return REFUSE((Instance *)component, fmi2Error, "%s is not supported by this FMU", call);
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2GetInteger") : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2GetBoolean") : fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2GetString") : fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2SetInteger") : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2SetBoolean") : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? unsupported(c, "fmi2SetString") : fmi2OK;
}
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2GetFMUstate");
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    (void)s; return unsupported(c, "fmi2SetFMUstate");
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2FreeFMUstate");
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s; (void)n; return unsupported(c, "fmi2SerializedFMUstateSize");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s; (void)b; (void)n; return unsupported(c, "fmi2SerializeFMUstate");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n,
                                   fmi2FMUstate *s) {
    (void)b; (void)n; (void)s; return unsupported(c, "fmi2DeSerializeFMUstate");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                        size_t nu, const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dv[], fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
fmi2Status fmi2CancelStep(fmi2Component c) { return unsupported(c, "fmi2CancelStep"); }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetRealStatus");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetStringStatus");
}
