/* A damped oscillator as an FMI 2.0 co-simulation unit, written independently of the engine:
 *   m x'' + c x' + k x = F + k_c (u - x)
 * F is an external force input, u the position of a coupling partner (input) attached by a
 * spring k_c. Inputs are held over a step or follow u(t) = u0 + u1 (t - t0) + u2 (t - t0)^2 / 2
 * from fmi2SetRealInputDerivatives (orders 1 and 2). Classic RK4 with internal steps of at most
 * `dt`. A step longer than the parameter `max_step` (> 0) is refused with fmi2Discard, the state
 * unchanged: a test of a master's rollback. FMU state: a copy of the instance's numbers. */
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))
#define GUID "{8c4e810f-3df3-4a00-8276-176fa3dfe28a}"

/* Value references, as in modelDescription.xml. */
enum { VR_M, VR_K, VR_C, VR_KC, VR_X0, VR_V0, VR_DT, VR_MAX_STEP, VR_F, VR_U, VR_X, VR_V, VR_SPRING, N_REALS };

typedef struct {
    double r[N_REALS];
    double t, u_der[2], F_der[2], t_inputs; /* inputs extrapolated from t_inputs */
    int initialized;
} Numbers;

typedef struct {
    Numbers n;
    fmi2CallbackFunctions cb;
    char name[64];
} Osc;

static void say(Osc *o, fmi2Status s, const char *fmt, ...) {
    char text[512], escaped[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    /* The message is the logger's format string: '%' doubled, no arguments. */
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = 0;
    if (o->cb.logger) o->cb.logger(o->cb.componentEnvironment, o->name, s, s == fmi2OK ? "log" : "error", escaped);
}

static double input_at(const Numbers *n, int vr, double t) {
    const double *d = vr == VR_U ? n->u_der : n->F_der;
    double s = t - n->t_inputs;
    return n->r[vr] + d[0] * s + 0.5 * d[1] * s * s;
}

static void rhs(const Numbers *n, double t, double x, double v, double *dx, double *dv) {
    const double *r = n->r;
    double force = input_at(n, VR_F, t) + r[VR_KC] * (input_at(n, VR_U, t) - x);
    *dx = v;
    *dv = (force - r[VR_C] * v - r[VR_K] * x) / r[VR_M];
}

static void outputs(Numbers *n) {
    n->r[VR_SPRING] = n->r[VR_KC] * (input_at(n, VR_U, n->t) - n->r[VR_X]);
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                                     const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    (void)res; (void)visible; (void)logging;
    if (!cb || type != fmi2CoSimulation || !guid || strcmp(guid, GUID) != 0) return NULL;
    Osc *o = calloc(1, sizeof *o);
    if (!o) return NULL;
    o->cb = *cb;
    snprintf(o->name, sizeof o->name, "%s", name ? name : "oscillator");
    double start[N_REALS] = {1.0, 100.0, 0.0, 0.0, 0.1, 0.0, 1e-4, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0};
    memcpy(o->n.r, start, sizeof start);
    return o;
}

EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)c; (void)on; (void)n; (void)cat; return fmi2OK;
}
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol, fmi2Real start,
                                      fmi2Boolean stop_defined, fmi2Real stop) {
    (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
    ((Osc *)c)->n.t = start;
    ((Osc *)c)->n.t_inputs = start;
    return fmi2OK;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Osc *o = c;
    if (!(o->n.r[VR_M] > 0) || !(o->n.r[VR_DT] > 0)) {
        say(o, fmi2Error, "m = %g and dt = %g must be positive", o->n.r[VR_M], o->n.r[VR_DT]);
        return fmi2Error;
    }
    o->n.r[VR_X] = o->n.r[VR_X0];
    o->n.r[VR_V] = o->n.r[VR_V0];
    o->n.initialized = 1;
    outputs(&o->n);
    return fmi2OK;
}
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Osc *o = c;
    fmi2CallbackFunctions cb = o->cb;
    char name[64];
    memcpy(name, o->name, sizeof name);
    fmi2Component fresh = fmi2Instantiate(name, fmi2CoSimulation, GUID, "", &cb, 0, 0);
    if (!fresh) return fmi2Error;
    memcpy(o, fresh, sizeof *o);
    free(fresh);
    return fmi2OK;
}

static int bad_vr(Osc *o, const fmi2ValueReference vr[], size_t n) {
    for (size_t i = 0; i < n; i++)
        if (vr[i] >= N_REALS) { say(o, fmi2Error, "unknown value reference %u", vr[i]); return 1; }
    return 0;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    Osc *o = c;
    if (bad_vr(o, vr, n)) return fmi2Error;
    for (size_t i = 0; i < n; i++) v[i] = o->n.r[vr[i]];
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    Osc *o = c;
    if (bad_vr(o, vr, n)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= VR_X || (o->n.initialized && vr[i] < VR_MAX_STEP)) {
            say(o, fmi2Error, "value reference %u cannot be set now", vr[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) {
        o->n.r[vr[i]] = v[i];
        if (vr[i] == VR_U) o->n.u_der[0] = o->n.u_der[1] = 0;
        if (vr[i] == VR_F) o->n.F_der[0] = o->n.F_der[1] = 0;
    }
    o->n.t_inputs = o->n.t;
    if (o->n.initialized) outputs(&o->n);
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real v[]) {
    Osc *o = c;
    for (size_t i = 0; i < n; i++) {
        if ((vr[i] != VR_U && vr[i] != VR_F) || order[i] < 1 || order[i] > 2) {
            say(o, fmi2Error, "fmi2SetRealInputDerivatives: vr %u order %d not accepted", vr[i], order[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) (vr[i] == VR_U ? o->n.u_der : o->n.F_der)[order[i] - 1] = v[i];
    o->n.t_inputs = o->n.t;
    return fmi2OK;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)no_prior;
    Osc *o = c;
    Numbers *n = &o->n;
    if (!n->initialized) { say(o, fmi2Error, "fmi2DoStep before initialization"); return fmi2Error; }
    if (!(h > 0) || (t - n->t) > 1e-9 * (1 + (t > 0 ? t : -t)) || (n->t - t) > 1e-9 * (1 + (t > 0 ? t : -t))) {
        say(o, fmi2Error, "fmi2DoStep(t = %.17g, h = %g) but the unit is at t = %.17g", t, h, n->t);
        return fmi2Error;
    }
    if (n->r[VR_MAX_STEP] > 0 && h > n->r[VR_MAX_STEP] * (1 + 1e-12)) {
        say(o, fmi2Discard, "step h = %g refused: longer than max_step = %g", h, n->r[VR_MAX_STEP]);
        return fmi2Discard;
    }
    int steps = (int)(h / n->r[VR_DT] - 1e-9) + 1;
    double dt = h / steps, x = n->r[VR_X], v = n->r[VR_V];
    for (int i = 0; i < steps; i++) {
        double s = t + i * dt, k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
        rhs(n, s, x, v, &k1x, &k1v);
        rhs(n, s + dt / 2, x + dt / 2 * k1x, v + dt / 2 * k1v, &k2x, &k2v);
        rhs(n, s + dt / 2, x + dt / 2 * k2x, v + dt / 2 * k2v, &k3x, &k3v);
        rhs(n, s + dt, x + dt * k3x, v + dt * k3v, &k4x, &k4v);
        x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    n->r[VR_X] = x;
    n->r[VR_V] = v;
    n->t = t + h;
    outputs(n);
    return fmi2OK;
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }

/* FMU state: a heap copy of the numbers. */
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    if (!*s) *s = malloc(sizeof(Numbers));
    if (!*s) return fmi2Error;
    memcpy(*s, &((Osc *)c)->n, sizeof(Numbers));
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    if (!s) return fmi2Error;
    memcpy(&((Osc *)c)->n, s, sizeof(Numbers));
    return fmi2OK;
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)c;
    free(*s);
    *s = NULL;
    return fmi2OK;
}

/* Not offered (capability flags false): refuse with a message. */
static fmi2Status not_offered(fmi2Component c, const char *f) {
    say(c, fmi2Error, "%s is not offered by this unit", f);
    return fmi2Error;
}
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s; (void)n; return not_offered(c, "fmi2SerializedFMUstateSize");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s; (void)b; (void)n; return not_offered(c, "fmi2SerializeFMUstate");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)s; (void)b; (void)n; return not_offered(c, "fmi2DeSerializeFMUstate");
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference a[], size_t na,
                                               const fmi2ValueReference b[], size_t nb, const fmi2Real dv[], fmi2Real r[]) {
    (void)a; (void)na; (void)b; (void)nb; (void)dv; (void)r; return not_offered(c, "fmi2GetDirectionalDerivative");
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Integer o[], fmi2Real v[]) {
    (void)vr; (void)n; (void)o; (void)v; return not_offered(c, "fmi2GetRealOutputDerivatives");
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2GetInteger") : fmi2OK;
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2SetInteger") : fmi2OK;
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2GetBoolean") : fmi2OK;
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2SetBoolean") : fmi2OK;
}
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2GetString") : fmi2OK;
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v; return n ? not_offered(c, "fmi2SetString") : fmi2OK;
}
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) {
    (void)k; (void)v; return not_offered(c, "fmi2GetStatus");
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    Osc *o = c;
    if (k == fmi2LastSuccessfulTime) { *v = o->n.t; return fmi2OK; }
    return not_offered(c, "fmi2GetRealStatus");
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) {
    (void)k; (void)v; return not_offered(c, "fmi2GetIntegerStatus");
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    (void)k; (void)v; return not_offered(c, "fmi2GetBooleanStatus");
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) {
    (void)k; (void)v; return not_offered(c, "fmi2GetStringStatus");
}
