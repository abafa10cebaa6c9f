/* The PD autopilot of eq (20) as an FMI 3.0 co-simulation FMU written in C: the twin of
   pd_autopilot_c.c (FMI 2.0), with the same law (pd_law.h), ports, parameters and
   refusals. Built by fmubuild.cbuild against the FMI 3.0 headers fmpy ships in
   fmpy/c-code.

   Value references as the Python FMUs' FMI 3.0 twins number theirs (each one's position
   in the model description, counted from 1, the independent variable written last):
   0 time, 1 psi, 2 r, 3 psi_d (inputs), 4 delta_c (output), 5 Kp, 6 Kd.

   A step with an input that is not finite fails the FMU, fmi3Error (which FMI 3.0 lets a
   host recover from by fmi3Reset); from then on delta_c reads NaN and every step fails
   with the same reason, until fmi3Reset. The FMU exports every function of
   fmi3Functions.h, as FMI 3.0.2 (section 2.5) requires; those of interface types and
   capabilities it lacks (model exchange, scheduled execution, event mode, FMU states,
   derivatives, clocks, variables of other types) log why and return fmi3Error. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "pd_law.h"

enum { TIME, PSI, R, PSI_D, DELTA_C, KP, KD, N_VARIABLES };
enum Phase { INSTANTIATED, INITIALIZATION, STEP, TERMINATED };

static const char TOKEN[] = "{234b9816-08d2-4b4f-8f16-10a4da293776}";

typedef struct {
    fmi3Float64 value[N_VARIABLES];
    enum Phase phase;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback logger;
    char *name;
    fmi3Boolean logging;
    char failure[128];                            /* why the FMU failed; "" if it has not */
} Instance;

static const fmi3Float64 START[N_VARIABLES] = {0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 50.0};

static void say(Instance *c, fmi3Status status, const char *category, const char *format, ...) {
    char message[512];
    int named;
    va_list args;
    if (status < fmi3Error && !c->logging) return;
    /* Named, as every FMU of this project names itself: FMI 3.0's callback does not. */
    named = snprintf(message, sizeof message, "%s: ", c->name);
    if (named < 0 || (size_t)named >= sizeof message) named = 0;
    va_start(args, format);
    vsnprintf(message + named, sizeof message - (size_t)named, format, args);
    va_end(args);
    if (c->logger) c->logger(c->environment, status, category, message);
}

/* Log an error (always) and return the status the call ends with. */
#define REFUSE(c, status, ...) (say((c), (status), "logStatusError", __VA_ARGS__), (status))

static fmi3Float64 rudder_command(const Instance *c) {  /* eq (20) */
    const fmi3Float64 *v = c->value;
    return pd_rudder_command(v[KP], v[KD], v[PSI], v[R], v[PSI_D]);
}

const char *fmi3GetVersion(void) { return fmi3Version; }

/* No instance: only a co-simulation instance without event mode is made. */
static fmi3Instance not_instantiated(fmi3String name, fmi3InstanceEnvironment environment,
                                     fmi3LogMessageCallback logger, const char *why) {
    char message[256];
    if (logger) {
        snprintf(message, sizeof message, "%s: %s", name ? name : "pd_autopilot_c", why);
        logger(environment, fmi3Error, "logStatusError", message);
    }
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(
        fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
        fmi3Boolean earlyReturnAllowed,
        const fmi3ValueReference requiredIntermediateVariables[],
        size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    Instance *c;
    (void)resourcePath; (void)visible; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (!instanceName || !instantiationToken || strcmp(instantiationToken, TOKEN) != 0)
        return NULL;
    if (eventModeUsed)
        return not_instantiated(instanceName, instanceEnvironment, logMessage,
                                "this FMU has no event mode (hasEventMode is false)");
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->name = malloc(strlen(instanceName) + 1);
    if (!c->name) { free(c); return NULL; }
    strcpy(c->name, instanceName);
    c->environment = instanceEnvironment;
    c->logger = logMessage;
    c->logging = loggingOn;
    memcpy(c->value, START, sizeof START);
    c->phase = INSTANTIATED;
    return c;
}

fmi3Instance fmi3InstantiateModelExchange(
        fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage) {
    (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    return not_instantiated(instanceName, instanceEnvironment, logMessage,
                            "this FMU is for co-simulation only, not model exchange");
}

fmi3Instance fmi3InstantiateScheduledExecution(
        fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
        fmi3LockPreemptionCallback lockPreemption,
        fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    return not_instantiated(instanceName, instanceEnvironment, logMessage,
                            "this FMU is for co-simulation only, not scheduled execution");
}

void fmi3FreeInstance(fmi3Instance instance) {
    Instance *c = instance;
    if (!c) return;
    free(c->name);
    free(c);
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn,
                               size_t nCategories, const fmi3String categories[]) {
    (void)nCategories; (void)categories;
    ((Instance *)instance)->logging = loggingOn;
    return fmi3OK;
}

/* fmi3OK if the instance is in ``phase``; else an error naming the call. */
static fmi3Status require(Instance *c, enum Phase phase, const char *call) {
    static const char *const after[] = {"fmi3InstantiateCoSimulation",
                                        "fmi3EnterInitializationMode",
                                        "fmi3ExitInitializationMode", "fmi3Terminate"};
    if (c->phase == phase) return fmi3OK;
    return REFUSE(c, fmi3Error, "%s is only allowed after %s", call, after[phase]);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Instance *c = instance;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (require(c, INSTANTIATED, "fmi3EnterInitializationMode") != fmi3OK) return fmi3Error;
    c->value[TIME] = startTime;
    c->phase = INITIALIZATION;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Instance *c = instance;
    if (require(c, INITIALIZATION, "fmi3ExitInitializationMode") != fmi3OK) return fmi3Error;
    if (!isfinite(c->value[KP]) || !isfinite(c->value[KD]))
        return REFUSE(c, fmi3Error, "parameter %s is not finite",
                      isfinite(c->value[KP]) ? "Kd" : "Kp");
    c->phase = STEP;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    Instance *c = instance;
    if (c->failure[0]) {                          /* a failed FMU may end in any phase */
        c->phase = TERMINATED;
        return fmi3OK;
    }
    if (require(c, STEP, "fmi3Terminate") != fmi3OK) return fmi3Error;
    c->phase = TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    Instance *c = instance;
    memcpy(c->value, START, sizeof START);
    c->phase = INSTANTIATED;
    c->failure[0] = '\0';
    return fmi3OK;
}

/* fmi3OK if there is one value for each value reference: every variable is a scalar. */
static fmi3Status scalars(Instance *c, size_t nValueReferences, size_t nValues) {
    if (nValues == nValueReferences) return fmi3OK;
    return REFUSE(c, fmi3Error, "%lu values for %lu value references (every variable is a "
                  "scalar)", (unsigned long)nValues, (unsigned long)nValueReferences);
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 values[], size_t nValues) {
    Instance *c = instance;
    size_t i;
    if (scalars(c, nvr, nValues) != fmi3OK) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES)
            return REFUSE(c, fmi3Error, "no Float64 variable has value reference %u", vr[i]);
        values[i] = vr[i] != DELTA_C ? c->value[vr[i]]
                    : c->failure[0] ? NAN : rudder_command(c);
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 values[], size_t nValues) {
    Instance *c = instance;
    size_t i;
    if (scalars(c, nvr, nValues) != fmi3OK) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES || vr[i] == DELTA_C || vr[i] == TIME)
            return REFUSE(c, fmi3Error, "value reference %u is not an input or parameter",
                          vr[i]);
        if (vr[i] >= KP && c->phase != INSTANTIATED && c->phase != INITIALIZATION)
            return REFUSE(c, fmi3Error, "parameter %s is fixed after initialization",
                          vr[i] == KP ? "Kp" : "Kd");
    }
    for (i = 0; i < nvr; i++) c->value[vr[i]] = values[i];
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    static const char *const input[] = {"time", "psi", "r", "psi_d"};
    Instance *c = instance;
    fmi3Float64 t = currentCommunicationPoint, h = communicationStepSize;
    int i;
    (void)noSetFMUStatePriorToCurrentPoint;
    /* Written whatever the outcome: a host may read them after an error too. */
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = c->value[TIME];
    if (c->failure[0]) return REFUSE(c, fmi3Error, "%s", c->failure);
    if (require(c, STEP, "fmi3DoStep") != fmi3OK) return fmi3Error;
    if (!(h > 0.0))
        return REFUSE(c, fmi3Error, "doStep with a communication step of %g s", h);
    for (i = PSI; i <= PSI_D; i++)
        if (!isfinite(c->value[i])) {
            snprintf(c->failure, sizeof c->failure, "doStep at t = %g: input %s = %g is not "
                     "finite; the FMU has failed (delta_c reads NaN until fmi3Reset)", t,
                     input[i], c->value[i]);
            return REFUSE(c, fmi3Error, "%s", c->failure);
        }
    c->value[TIME] = *lastSuccessfulTime = t + h;  /* memoryless: nothing else advances */
    return fmi3OK;
}

/* What this FMU does not do. */
static fmi3Status unsupported(fmi3Instance instance, const char *call) {
    return REFUSE((Instance *)instance, fmi3Error, "%s is not supported by this FMU", call);
}

/* The getter and setter of a type this FMU has no variable of: none to get or set. */
#define NO_VARIABLES_OF(Type, type)                                                         \
    fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,   \
                             type values[], size_t nValues) {                             \
        (void)vr; (void)values; (void)nValues;                                             \
        return nvr ? unsupported(c, "fmi3Get" #Type) : fmi3OK;                             \
    }                                                                                      \
    fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,   \
                             const type values[], size_t nValues) {                       \
        (void)vr; (void)values; (void)nValues;                                             \
        return nvr ? unsupported(c, "fmi3Set" #Type) : fmi3OK;                             \
    }
NO_VARIABLES_OF(Float32, fmi3Float32)
NO_VARIABLES_OF(Int8, fmi3Int8)
NO_VARIABLES_OF(UInt8, fmi3UInt8)
NO_VARIABLES_OF(Int16, fmi3Int16)
NO_VARIABLES_OF(UInt16, fmi3UInt16)
NO_VARIABLES_OF(Int32, fmi3Int32)
NO_VARIABLES_OF(UInt32, fmi3UInt32)
NO_VARIABLES_OF(Int64, fmi3Int64)
NO_VARIABLES_OF(UInt64, fmi3UInt64)
NO_VARIABLES_OF(Boolean, fmi3Boolean)
NO_VARIABLES_OF(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)vr; (void)valueSizes; (void)values; (void)nValues;
    return nvr ? unsupported(c, "fmi3GetBinary") : fmi3OK;
}
fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                         const size_t valueSizes[], const fmi3Binary values[],
                         size_t nValues) {
    (void)vr; (void)valueSizes; (void)values; (void)nValues;
    return nvr ? unsupported(c, "fmi3SetBinary") : fmi3OK;
}
fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                        fmi3Clock values[]) {
    (void)vr; (void)values;
    return nvr ? unsupported(c, "fmi3GetClock") : fmi3OK;
}
fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                        const fmi3Clock values[]) {
    (void)vr; (void)values;
    return nvr ? unsupported(c, "fmi3SetClock") : fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance c) { return unsupported(c, "fmi3EnterEventMode"); }
fmi3Status fmi3EnterStepMode(fmi3Instance c) { return unsupported(c, "fmi3EnterStepMode"); }
fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3EnterConfigurationMode");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3ExitConfigurationMode");
}
fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference vr,
                                               size_t *n) {
    (void)vr; (void)n; return unsupported(c, "fmi3GetNumberOfVariableDependencies");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents;
    (void)elementIndicesOfIndependents; (void)dependencyKinds; (void)nDependencies;
    return unsupported(c, "fmi3GetVariableDependencies");
}
fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *s) {
    (void)s; return unsupported(c, "fmi3GetFMUState");
}
fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState s) {
    (void)s; return unsupported(c, "fmi3SetFMUState");
}
fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *s) {
    (void)s; return unsupported(c, "fmi3FreeFMUState");
}
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState s, size_t *n) {
    (void)s; (void)n; return unsupported(c, "fmi3SerializedFMUStateSize");
}
fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState s, fmi3Byte b[], size_t n) {
    (void)s; (void)b; (void)n; return unsupported(c, "fmi3SerializeFMUState");
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte b[], size_t n,
                                   fmi3FMUState *s) {
    (void)b; (void)n; (void)s; return unsupported(c, "fmi3DeserializeFMUState");
}
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[],
                                        size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    (void)sensitivity; (void)nSensitivity;
    return unsupported(c, "fmi3GetDirectionalDerivative");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    (void)sensitivity; (void)nSensitivity;
    return unsupported(c, "fmi3GetAdjointDerivative");
}
fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)vr; (void)nvr; (void)orders; (void)values; (void)nValues;
    return unsupported(c, "fmi3GetOutputDerivatives");
}

/* Clocks: this FMU has none. */
fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                  fmi3Float64 intervals[], fmi3IntervalQualifier q[]) {
    (void)vr; (void)nvr; (void)intervals; (void)q;
    return unsupported(c, "fmi3GetIntervalDecimal");
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                   fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier q[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions; (void)q;
    return unsupported(c, "fmi3GetIntervalFraction");
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                               fmi3Float64 shifts[]) {
    (void)vr; (void)nvr; (void)shifts; return unsupported(c, "fmi3GetShiftDecimal");
}
fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3GetShiftFraction");
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[]) {
    (void)vr; (void)nvr; (void)intervals; return unsupported(c, "fmi3SetIntervalDecimal");
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3SetIntervalFraction");
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                               const fmi3Float64 shifts[]) {
    (void)vr; (void)nvr; (void)shifts; return unsupported(c, "fmi3SetShiftDecimal");
}
fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3SetShiftFraction");
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) {
    return unsupported(c, "fmi3EvaluateDiscreteStates");
}
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    (void)discreteStatesNeedUpdate; (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged; (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined; (void)nextEventTime;
    return unsupported(c, "fmi3UpdateDiscreteStates");
}

/* Model exchange's functions (no instance of it is ever made). */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) {
    return unsupported(c, "fmi3EnterContinuousTimeMode");
}
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    return unsupported(c, "fmi3CompletedIntegratorStep");
}
fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time) {
    (void)time; return unsupported(c, "fmi3SetTime");
}
fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 x[], size_t n) {
    (void)x; (void)n; return unsupported(c, "fmi3SetContinuousStates");
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 dx[], size_t n) {
    (void)dx; (void)n; return unsupported(c, "fmi3GetContinuousStateDerivatives");
}
fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 z[], size_t n) {
    (void)z; (void)n; return unsupported(c, "fmi3GetEventIndicators");
}
fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 x[], size_t n) {
    (void)x; (void)n; return unsupported(c, "fmi3GetContinuousStates");
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t n) {
    (void)nominals; (void)n; return unsupported(c, "fmi3GetNominalsOfContinuousStates");
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *n) {
    (void)n; return unsupported(c, "fmi3GetNumberOfEventIndicators");
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *n) {
    (void)n; return unsupported(c, "fmi3GetNumberOfContinuousStates");
}

/* Scheduled execution's (no instance of it is ever made). */
fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return unsupported(c, "fmi3ActivateModelPartition");
}
