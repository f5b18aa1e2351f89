/* The wheel as an FMI 2.0 co-simulation FMU (wpm_export/fmu.py writes the archive): inputs
 * wheel load and slip, outputs DP, torque, sinkage, motion resistance and their 95 %
 * half-widths, from resources/wpm.csv through libswtwpm; no Python at run time.
 *
 * Value references (modelDescription.xml by wpm_export/fmu.py lists the same):
 *   0 load_n (input), 1 slip (input), 2 multipass (parameter, Integer), 3 allow_extrapolation
 *   (parameter, Boolean), 4 soil and 5 wheel (parameters, String; "" = the only one);
 *   10 + q value, 20 + q conf95, 30 + q pred95 (outputs; q = 0 dp_n, 1 torque_nm,
 *   2 sinkage_m, 3 resistance_n), 40 status (output, Integer: 0 ok, > 0 warning flags,
 *   < 0 a swtwpm error code).
 * A query the library refuses (a load outside the tested ones, NaN, another wheel) sets the
 * outputs to NaN, logs the library's message (the Python runtime's, dp_n's first) and
 * returns fmi2Error from fmi2GetReal; an extrapolated load (allowed) logs its warning. The FMI 2.0 types and signatures are written out here (FMI 2.0 standard,
 * fmi2TypesPlatform.h / fmi2FunctionTypes.h, with the standard's names). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "swtwpm.h"

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated }
    fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT
#define N_OUT 4
#define VR_STATUS 40

typedef struct {
    swtwpm *model;
    fmi2CallbackFunctions callbacks;
    char *name;
    double load_n, slip, time;
    int multipass, allow_extrapolation, status, dirty, bands_dirty;
    char soil[256], wheel[256];
    double value[N_OUT], conf95[N_OUT], pred95[N_OUT];
} wheel_fmu;

static void say(wheel_fmu *w, fmi2Status status, const char *format, ...)
{
    char text[2048];
    va_list args;
    if (!w->callbacks.logger)
        return;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    w->callbacks.logger(w->callbacks.componentEnvironment, w->name, status,
                        status == fmi2OK ? "logAll" : "logStatusError", "%s", text);
}

/* the outputs at the current inputs (the half-widths only when asked for): fmi2OK,
 * fmi2Warning or fmi2Error (message logged) */
static fmi2Status update(wheel_fmu *w, int bands)
{
    char msg[1024] = "", warning[1024] = "";
    int set, q, worst = 0;
    if (!w->dirty && !(bands && w->bands_dirty))
        return w->status < 0 ? fmi2Error : w->status > 0 ? fmi2Warning : fmi2OK;
    w->dirty = 0;
    w->bands_dirty = !bands;
    for (q = 0; q < N_OUT; ++q)
        w->value[q] = w->conf95[q] = w->pred95[q] = NAN;
    set = swtwpm_select(w->model, *w->soil ? w->soil : NULL, *w->wheel ? w->wheel : NULL,
                        w->multipass, msg, sizeof msg);
    if (set < 0) {
        w->status = set;
        say(w, fmi2Error, "%s", msg);
        return fmi2Error;
    }
    for (q = 0; q < N_OUT; ++q) {
        int code;
        if (!swtwpm_has_quantity(w->model, set, q))
            continue;
        code = bands ? swtwpm_value_band(w->model, set, q, w->load_n, w->slip,
                                         w->allow_extrapolation ? SWTWPM_ALLOW_EXTRAPOLATION
                                                                : 0,
                                         &w->value[q], &w->conf95[q], &w->pred95[q], msg,
                                         sizeof msg)
                     : swtwpm_value(w->model, set, q, w->load_n, w->slip,
                                    w->allow_extrapolation ? SWTWPM_ALLOW_EXTRAPOLATION : 0,
                                    &w->value[q], msg, sizeof msg);
        if (code < 0) {
            w->status = code;
            for (q = 0; q < N_OUT; ++q)
                w->value[q] = w->conf95[q] = w->pred95[q] = NAN;
            say(w, fmi2Error, "t = %g s: %s", w->time, msg);
            return fmi2Error;
        }
        if (code & SWTWPM_WARN_LOAD_EXTRAPOLATED && !*warning)
            strcpy(warning, msg);
        worst |= code;
    }
    w->status = worst;
    if (*warning)
        say(w, fmi2Warning, "t = %g s: %s", w->time, warning);
    return fmi2OK;
}

/* "file:///a/b%20c/resources" -> "/a/b c/resources/wpm.csv" */
static void csv_path(fmi2String location, char *out, size_t size)
{
    const char *s = location ? location : "";
    size_t n = 0;
    if (!strncmp(s, "file://", 7))
        s += 7;
    if (!strncmp(s, "localhost/", 10))
        s += 9;
    while (*s && n + 1 < size) {
        if (s[0] == '%' && s[1] && s[2]) {
            char hex[3] = {s[1], s[2], 0};
            out[n++] = (char)strtol(hex, NULL, 16);
            s += 3;
        } else
            out[n++] = *s++;
    }
    out[n] = '\0';
    if (n && out[n - 1] == '/')
        out[--n] = '\0';
    strncat(out, "/wpm.csv", size - n - 1);
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                     fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                     const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                     fmi2Boolean loggingOn)
{
    wheel_fmu *w = calloc(1, sizeof *w);
    char path[4096], msg[1024];
    (void)fmuGUID;
    (void)visible;
    (void)loggingOn;
    if (!w)
        return NULL;
    if (functions)
        w->callbacks = *functions;
    w->name = malloc(strlen(instanceName ? instanceName : "wheel") + 1);
    if (w->name)
        strcpy(w->name, instanceName ? instanceName : "wheel");
    if (fmuType != fmi2CoSimulation) {
        say(w, fmi2Error, "this FMU is for co-simulation only");
        free(w->name);
        free(w);
        return NULL;
    }
    csv_path(fmuResourceLocation, path, sizeof path);
    if (!w->name || swtwpm_open(path, &w->model, msg, sizeof msg) < 0) {
        say(w, fmi2Error, "%s", w->name ? msg : "out of memory");
        free(w->name);
        free(w);
        return NULL;
    }
    w->load_n = NAN;
    w->slip = 0.0;
    w->multipass = -1; /* any: resources/wpm.csv holds the one set the FMU was made for */
    w->dirty = 1;
    return w;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    wheel_fmu *w = c;
    if (!w)
        return;
    swtwpm_free(w->model);
    free(w->name);
    free(w);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n,
                                      const fmi2String categories[])
{
    (void)c, (void)on, (void)n, (void)categories;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                      fmi2Real tolerance, fmi2Real startTime,
                                      fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    wheel_fmu *w = c;
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    w->time = startTime;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }

EXPORT fmi2Status fmi2Reset(fmi2Component c)
{
    wheel_fmu *w = c;
    w->load_n = NAN;
    w->slip = 0.0;
    w->multipass = -1;
    w->allow_extrapolation = 0;
    w->soil[0] = w->wheel[0] = '\0';
    w->dirty = 1;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              fmi2Real value[])
{
    wheel_fmu *w = c;
    fmi2Status status = fmi2OK;
    size_t i;
    int needs_outputs = 0, needs_bands = 0;
    for (i = 0; i < nvr; ++i) {
        needs_outputs |= vr[i] >= 10;
        needs_bands |= vr[i] >= 20;
    }
    if (needs_outputs)
        status = update(w, needs_bands);
    for (i = 0; i < nvr; ++i) {
        unsigned r = vr[i];
        if (r == 0)
            value[i] = w->load_n;
        else if (r == 1)
            value[i] = w->slip;
        else if (r >= 10 && r < 10 + N_OUT)
            value[i] = w->value[r - 10];
        else if (r >= 20 && r < 20 + N_OUT)
            value[i] = w->conf95[r - 20];
        else if (r >= 30 && r < 30 + N_OUT)
            value[i] = w->pred95[r - 30];
        else {
            say(w, fmi2Error, "no Real variable with value reference %u", r);
            return fmi2Error;
        }
    }
    return status == fmi2Warning ? fmi2OK : status;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              const fmi2Real value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] == 0)
            w->load_n = value[i];
        else if (vr[i] == 1)
            w->slip = value[i];
        else {
            say(w, fmi2Error, "Real variable %u cannot be set", vr[i]);
            return fmi2Error;
        }
        w->dirty = 1;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 fmi2Integer value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] == 2)
            value[i] = w->multipass;
        else if (vr[i] == VR_STATUS) {
            update(w, 0);
            value[i] = w->status;
        } else
            return fmi2Error;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Integer value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] != 2)
            return fmi2Error;
        w->multipass = value[i];
        w->dirty = 1;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 fmi2Boolean value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] != 3)
            return fmi2Error;
        value[i] = w->allow_extrapolation;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Boolean value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] != 3)
            return fmi2Error;
        w->allow_extrapolation = value[i] != 0;
        w->dirty = 1;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                fmi2String value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        if (vr[i] != 4 && vr[i] != 5)
            return fmi2Error;
        value[i] = vr[i] == 4 ? w->soil : w->wheel;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                const fmi2String value[])
{
    wheel_fmu *w = c;
    size_t i;
    for (i = 0; i < nvr; ++i) {
        char *target = vr[i] == 4 ? w->soil : vr[i] == 5 ? w->wheel : NULL;
        if (!target || !value[i] || strlen(value[i]) >= sizeof w->soil) {
            say(w, fmi2Error, "String variable %u: unknown or longer than 255 bytes", vr[i]);
            return fmi2Error;
        }
        strcpy(target, value[i]);
        w->dirty = 1;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    wheel_fmu *w = c;
    (void)noSetFMUStatePriorToCurrentPoint;
    w->time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK; /* no state: the outputs are algebraic in the inputs (fmi2GetReal) */
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2OK; }

static fmi2Status unsupported(fmi2Component c, const char *what)
{
    if (c)
        say(c, fmi2Error, "%s is not supported", what);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    (void)s;
    return unsupported(c, "fmi2GetFMUstate");
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s)
{
    (void)s;
    return unsupported(c, "fmi2SetFMUstate");
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    (void)s;
    return unsupported(c, "fmi2FreeFMUstate");
}
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n)
{
    (void)s, (void)n;
    return unsupported(c, "fmi2SerializedFMUstateSize");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[],
                                        size_t n)
{
    (void)s, (void)b, (void)n;
    return unsupported(c, "fmi2SerializeFMUstate");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n,
                                          fmi2FMUstate *s)
{
    (void)s, (void)b, (void)n;
    return unsupported(c, "fmi2DeSerializeFMUstate");
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                               size_t nu, const fmi2ValueReference z[],
                                               size_t nz, const fmi2Real dv[], fmi2Real dz[])
{
    (void)u, (void)nu, (void)z, (void)nz, (void)dv, (void)dz;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                              size_t nvr, const fmi2Integer order[],
                                              const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                               size_t nvr, const fmi2Integer order[],
                                               fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s, (void)value;
    return unsupported(c, "fmi2GetStatus");
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    wheel_fmu *w = c;
    if (s == fmi2LastSuccessfulTime) {
        *value = w->time;
        return fmi2OK;
    }
    return unsupported(c, "fmi2GetRealStatus");
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Integer *value)
{
    (void)s, (void)value;
    return unsupported(c, "fmi2GetIntegerStatus");
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Boolean *value)
{
    (void)s, (void)value;
    return unsupported(c, "fmi2GetBooleanStatus");
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s,
                                      fmi2String *value)
{
    (void)s, (void)value;
    return unsupported(c, "fmi2GetStringStatus");
}
