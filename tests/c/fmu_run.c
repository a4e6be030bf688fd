/* A portable FMI 2.0 co-simulation master in C: the same source drives the linux64 unit (gcc,
 * dlopen) and the win64 unit (mingw, LoadLibrary; run under Wine by tests/test_win64.py), so the
 * two binaries of one FMU meet the same call sequence and their answers can be compared.
 *
 * Usage: fmu_run <library> <resources URI> <GUID> <stop> <step> <vr,vr,...> [options]
 * Numbers in doubles (stop, step, amplitude) are given as the 16 hex digits of their bits: C
 * libraries need not read decimal text to the same last bit.
 *   --input <vr>=<amplitude>  a Real input set before every step to
 *                             amplitude * 4 s (1 - s), s = t / stop (no libm: the same bits on
 *                             both platforms)
 *   --integers <vr,vr,...>    Integer outputs (counters) printed once the first run is at its
 *                             end: `integers <value>...`
 *   --nan <vr>                after the run, set this Real to NaN (the status is printed)
 *   --save <file>             write the state serialized at the middle communication point
 *   --restore <file>          instead of initializing, deserialize the state in <file> (taken
 *                             at the middle point) and run from there
 *
 * The run: instantiate, set up, initialize, then doStep(k h, h) for k = 0 .. n - 1 (n = stop / h
 * rounded), reading the outputs after initialization and after each step. At the middle point
 * (k = n / 2) it takes the state (fmi2GetFMUstate) and serializes it, deserializes the bytes
 * into a second state, runs on to the end, then sets each of the two states in turn and runs
 * the second half again: each rerun must give the first run's outputs bit for bit. Then the
 * misuse: NaN into a Real (--nan), doStep with a negative step. Then terminate, free the states
 * and the instance.
 *
 * Output, one item per line (doubles as the 16 hex digits of their bits, so both platforms
 * print them alike): `row <k> <t> <value>...`, `state_size <bytes>`, `rerun <which> <number of
 * differing values>`, `misuse` where the misuse begins, `status <call> <fmi2Status>`,
 * `after_misuse <value>...`, and `log <status> <category>: <message>` for every message of the
 * unit. Exit status 0 when the run got to the end, 1 when a call that
 * must succeed did not, 2 for a usage or loading error. */
#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *Component;
typedef void *State;
typedef unsigned int ValueReference;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

static struct {
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    int (*setup)(Component, int, double, double, int, double);
    int (*enter)(Component);
    int (*exit_init)(Component);
    int (*do_step)(Component, double, double, int);
    int (*get_real)(Component, const ValueReference *, size_t, double *);
    int (*get_integer)(Component, const ValueReference *, size_t, int *);
    int (*set_real)(Component, const ValueReference *, size_t, const double *);
    int (*get_state)(Component, State *);
    int (*set_state)(Component, State);
    int (*free_state)(Component, State *);
    int (*state_size)(Component, State, size_t *);
    int (*serialize)(Component, State, char *, size_t);
    int (*deserialize)(Component, const char *, size_t, State *);
    int (*terminate)(Component);
    void (*free_instance)(Component);
} fmi;

static double parse_bits(const char *hex) {
    uint64_t u = strtoull(hex, NULL, 16);
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

static void print_bits(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    char hex[17];
    for (int i = 15; i >= 0; i--, u >>= 4) hex[i] = "0123456789abcdef"[u & 15];
    hex[16] = 0;
    printf(" %s", hex);
}

static void logger(void *env, const char *name, int status, const char *category,
                   const char *message, ...) {
    (void)env;
    (void)name;
    char text[2048];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    for (char *c = text; *c; c++)
        if (*c == '\n' || *c == '\r') *c = ' ';
    printf("log %d %s: %s\n", status, category ? category : "", text);
    fflush(stdout);
}

static void *load(const char *path) {
#ifdef _WIN32
    return (void *)LoadLibraryA(path);
#else
    return dlopen(path, RTLD_NOW | RTLD_LOCAL);
#endif
}

typedef void (*Function)(void);

static Function symbol(void *lib, const char *name) {
#ifdef _WIN32
    Function f = (Function)(void (*)(void))GetProcAddress((HMODULE)lib, name);
#else
    Function f;
    void *p = dlsym(lib, name);
    memcpy(&f, &p, sizeof f);
#endif
    if (!f) {
        fprintf(stderr, "the library does not export %s\n", name);
        exit(2);
    }
    return f;
}

#define LOAD(field, name)                     \
    do {                                      \
        Function f_ = symbol(lib, name);      \
        memcpy(&fmi.field, &f_, sizeof f_);   \
    } while (0)

static void unload(void *lib) {
#ifdef _WIN32
    FreeLibrary((HMODULE)lib);
#else
    dlclose(lib);
#endif
}

static Component component;
static size_t n_out, n_int;
static ValueReference *out_vr, *int_vr;
static double *out_values;
static long input_vr = -1, nan_vr = -1;
static double amplitude, stop_time, step_size;

static void fail(const char *what, int status) {
    printf("status %s %d\n", what, status);
    fprintf(stderr, "%s returned %d\n", what, status);
    exit(1);
}

static void check(const char *what, int status) {
    if (status != 0) fail(what, status);
}

/* Sets the input for the step that starts at t. */
static void set_input(double t) {
    if (input_vr < 0) return;
    double s = t / stop_time, u = amplitude * 4.0 * s * (1.0 - s);
    ValueReference vr = (ValueReference)input_vr;
    check("fmi2SetReal(input)", fmi.set_real(component, &vr, 1, &u));
}

/* Steps k0 .. n - 1; the outputs after each step go to rows[(k + 1) * n_out ...] when rows is
 * not NULL, else they are printed. */
static void run(long k0, long n, double *rows) {
    for (long k = k0; k < n; k++) {
        double t = (double)k * step_size;
        set_input(t);
        check("fmi2DoStep", fmi.do_step(component, t, step_size, 1));
        double *v = rows ? rows + (size_t)(k + 1) * n_out : out_values;
        check("fmi2GetReal", fmi.get_real(component, out_vr, n_out, v));
        if (!rows) {
            printf("row %ld", k + 1);
            print_bits((double)(k + 1) * step_size);
            for (size_t i = 0; i < n_out; i++) print_bits(v[i]);
            printf("\n");
        }
    }
}

/* The value references of a comma-separated list, and their count. */
static ValueReference *parse_vrs(const char *text, size_t *count) {
    *count = 1;
    for (const char *c = text; *c; c++) *count += *c == ',';
    ValueReference *vr = calloc(*count, sizeof *vr);
    char *end = (char *)text;
    for (size_t i = 0; i < *count; i++) vr[i] = (ValueReference)strtoul(end + (i > 0), &end, 10);
    return vr;
}

static void print_integers(void) {
    if (!n_int) return;
    int *v = calloc(n_int, sizeof *v);
    check("fmi2GetInteger", fmi.get_integer(component, int_vr, n_int, v));
    printf("integers");
    for (size_t i = 0; i < n_int; i++) printf(" %d", v[i]);
    printf("\n");
    free(v);
}

static char *read_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "cannot read %s\n", path); exit(2); }
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *data = malloc(len > 0 ? (size_t)len : 1);
    if (!data || fread(data, 1, (size_t)len, f) != (size_t)len) { fprintf(stderr, "cannot read %s\n", path); exit(2); }
    fclose(f);
    *size = (size_t)len;
    return data;
}

int main(int argc, char **argv) {
    if (argc < 7) {
        fprintf(stderr, "usage: %s library uri guid stop step vr,vr,... [--input vr=amplitude] "
                        "[--nan vr] [--save file] [--restore file]\n", argv[0]);
        return 2;
    }
    const char *save = NULL, *restore = NULL;
    stop_time = parse_bits(argv[4]);
    step_size = parse_bits(argv[5]);
    for (int i = 7; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--input")) {
            input_vr = strtol(argv[i + 1], NULL, 10);
            const char *eq = strchr(argv[i + 1], '=');
            amplitude = eq ? parse_bits(eq + 1) : 1.0;
        } else if (!strcmp(argv[i], "--nan")) nan_vr = strtol(argv[i + 1], NULL, 10);
        else if (!strcmp(argv[i], "--integers")) int_vr = parse_vrs(argv[i + 1], &n_int);
        else if (!strcmp(argv[i], "--save")) save = argv[i + 1];
        else if (!strcmp(argv[i], "--restore")) restore = argv[i + 1];
        else { fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
    }
    out_vr = parse_vrs(argv[6], &n_out);
    out_values = calloc(n_out, sizeof *out_values);
    long n = lround(stop_time / step_size), mid = n / 2;

    void *lib = load(argv[1]);
    if (!lib) { fprintf(stderr, "cannot load %s\n", argv[1]); return 2; }
    LOAD(instantiate, "fmi2Instantiate");
    LOAD(setup, "fmi2SetupExperiment");
    LOAD(enter, "fmi2EnterInitializationMode");
    LOAD(exit_init, "fmi2ExitInitializationMode");
    LOAD(do_step, "fmi2DoStep");
    LOAD(get_real, "fmi2GetReal");
    LOAD(set_real, "fmi2SetReal");
    LOAD(get_integer, "fmi2GetInteger");
    LOAD(get_state, "fmi2GetFMUstate");
    LOAD(set_state, "fmi2SetFMUstate");
    LOAD(free_state, "fmi2FreeFMUstate");
    LOAD(state_size, "fmi2SerializedFMUstateSize");
    LOAD(serialize, "fmi2SerializeFMUstate");
    LOAD(deserialize, "fmi2DeSerializeFMUstate");
    LOAD(terminate, "fmi2Terminate");
    LOAD(free_instance, "fmi2FreeInstance");

    Callbacks cb = {logger, calloc, free, NULL, NULL};
    component = fmi.instantiate("fmu_run", 1, argv[3], argv[2], &cb, 0, 1);
    if (!component) { printf("status fmi2Instantiate null\n"); return 1; }
    check("fmi2SetupExperiment", fmi.setup(component, 0, 0.0, 0.0, 1, stop_time));

    long k0 = 0;
    if (restore) {
        size_t size;
        char *bytes = read_file(restore, &size);
        State s = NULL;
        check("fmi2DeSerializeFMUstate", fmi.deserialize(component, bytes, size, &s));
        check("fmi2SetFMUstate", fmi.set_state(component, s));
        check("fmi2FreeFMUstate", fmi.free_state(component, &s));
        free(bytes);
        k0 = mid;
    } else {
        check("fmi2EnterInitializationMode", fmi.enter(component));
        check("fmi2ExitInitializationMode", fmi.exit_init(component));
    }
    check("fmi2GetReal", fmi.get_real(component, out_vr, n_out, out_values));
    printf("row %ld", k0);
    print_bits((double)k0 * step_size);
    for (size_t i = 0; i < n_out; i++) print_bits(out_values[i]);
    printf("\n");

    if (restore) {
        run(k0, n, NULL);
        print_integers();
    } else {
        /* first half, the states at the middle point, second half kept for the reruns */
        run(0, mid, NULL);
        State taken = NULL, restored = NULL;
        size_t size = 0;
        check("fmi2GetFMUstate", fmi.get_state(component, &taken));
        check("fmi2SerializedFMUstateSize", fmi.state_size(component, taken, &size));
        char *bytes = malloc(size);
        check("fmi2SerializeFMUstate", fmi.serialize(component, taken, bytes, size));
        check("fmi2DeSerializeFMUstate", fmi.deserialize(component, bytes, size, &restored));
        printf("state_size %lu\n", (unsigned long)size);
        if (save) {
            FILE *f = fopen(save, "wb");
            if (!f || fwrite(bytes, 1, size, f) != size || fclose(f)) { fprintf(stderr, "cannot write %s\n", save); return 2; }
        }
        free(bytes);
        size_t count = (size_t)(n + 1) * n_out;
        double *first = calloc(count, sizeof *first), *again = calloc(count, sizeof *again);
        run(mid, n, first);
        print_integers();
        for (long k = mid + 1; k <= n; k++) {
            printf("row %ld", k);
            print_bits((double)k * step_size);
            for (size_t i = 0; i < n_out; i++) print_bits(first[(size_t)k * n_out + i]);
            printf("\n");
        }
        State which[2] = {taken, restored};
        const char *names[2] = {"fmi2SetFMUstate", "fmi2DeSerializeFMUstate"};
        for (int w = 0; w < 2; w++) {
            check(names[w], fmi.set_state(component, which[w]));
            memset(again, 0, count * sizeof *again);
            run(mid, n, again);
            size_t differ = 0;
            for (size_t i = (size_t)(mid + 1) * n_out; i < count; i++)
                differ += memcmp(&first[i], &again[i], sizeof(double)) != 0;
            printf("rerun %s %lu\n", names[w], (unsigned long)differ);
        }
        free(first);
        free(again);
        check("fmi2FreeFMUstate", fmi.free_state(component, &taken));
        check("fmi2FreeFMUstate", fmi.free_state(component, &restored));
    }

    /* misuse: each must fail with a status and a message, and leave the instance usable */
    double t_end = (double)n * step_size;
    printf("misuse\n");
    if (nan_vr >= 0) {
        ValueReference vr = (ValueReference)nan_vr;
        double nan = NAN;
        printf("status fmi2SetReal(NaN) %d\n", fmi.set_real(component, &vr, 1, &nan));
    }
    printf("status fmi2DoStep(negative) %d\n", fmi.do_step(component, t_end, -step_size, 1));
    check("fmi2GetReal", fmi.get_real(component, out_vr, n_out, out_values));
    printf("after_misuse");
    for (size_t i = 0; i < n_out; i++) print_bits(out_values[i]);
    printf("\n");
    check("fmi2Terminate", fmi.terminate(component));
    fmi.free_instance(component);
    unload(lib);
    free(out_vr);
    free(int_vr);
    free(out_values);
    printf("done\n");
    return 0;
}
