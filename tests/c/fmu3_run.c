/* A small FMI 3.0 co-simulation importer in C (issue 47): the same source drives a unit's
 * x86_64-linux binary (gcc, dlopen) and its x86_64-windows binary (mingw-w64, LoadLibrary;
 * under Wine in tests/test_fmi3.py), so the two meet the same calls and their answers compare.
 *
 * Usage: fmu3_run <library> <resources path> <instantiation token> <steps> <step bits>
 *                 <vr>:<count>[,<vr>:<count>...]
 * The step size is the 16 hex digits of its bits. Each <vr>:<count> is a Float64 variable and
 * its number of values (an array's elements), all read in one fmi3GetFloat64 call.
 *
 * Run: instantiate (no event mode), initialize at t = 0, then fmi3DoStep(k h, h) for k = 0 ..
 * steps - 1, printing the values after initialization and after each step. At the middle step
 * the FMU state is taken and serialized; at the end the bytes are deserialized, set, and the
 * second half run again: `rerun <number of values that differ>`. Then the misuse: one value
 * too few for the variables (`status short <fmi3Status>`), a step from the wrong time
 * (`status time <fmi3Status>`). Printed, one item a line, doubles as hex bits: `row <k> <t>
 * <value>...`, `state_size <bytes>`, `rerun <n>`, `status <what> <code>`, `log <status>
 * <category>: <message>`, `done`. Exit 0 at the end, 1 when a call that must pass did not, 2
 * on a usage or loading error. */
#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *Instance;
typedef unsigned char Boolean; /* C's bool: one byte on both compilers */
typedef void (*LogMessage)(void *, int, const char *, const char *);

static struct {
    Instance (*instantiate)(const char *, const char *, const char *, Boolean, Boolean, Boolean,
                            Boolean, const uint32_t *, size_t, void *, LogMessage, void *);
    int (*enter)(Instance, Boolean, double, double, Boolean, double);
    int (*exit_init)(Instance);
    int (*step)(Instance, double, double, Boolean, Boolean *, Boolean *, Boolean *, double *);
    int (*get)(Instance, const uint32_t *, size_t, double *, size_t);
    int (*get_state)(Instance, void **);
    int (*set_state)(Instance, void *);
    int (*free_state)(Instance, void **);
    int (*size)(Instance, void *, size_t *);
    int (*serialize)(Instance, void *, unsigned char *, size_t);
    int (*deserialize)(Instance, const unsigned char *, size_t, void **);
    int (*terminate)(Instance);
    void (*free_instance)(Instance);
} api;

static void hex(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    printf(" %016llx", (unsigned long long)u);
}

static void on_message(void *env, int status, const char *category, const char *message) {
    (void)env;
    printf("log %d %s: ", status, category ? category : "");
    for (const char *c = message; c && *c; c++) putchar(*c == '\n' ? ' ' : *c);
    putchar('\n');
    fflush(stdout);
}

static void *open_library(const char *path) {
#ifdef _WIN32
    return (void *)LoadLibraryA(path);
#else
    return dlopen(path, RTLD_NOW | RTLD_LOCAL);
#endif
}

/* The address of `name` in `lib` into `*slot` (a function pointer), or exit 2. */
static void resolve(void *lib, const char *name, void *slot) {
#ifdef _WIN32
    FARPROC p = GetProcAddress((HMODULE)lib, name);
#else
    void *p = dlsym(lib, name);
#endif
    if (!p) {
        fprintf(stderr, "the library does not export %s\n", name);
        exit(2);
    }
    memcpy(slot, &p, sizeof p);
}

static void must(int status, const char *what) {
    if (status != 0) {
        printf("status %s %d\n", what, status);
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc != 7) {
        fprintf(stderr, "usage: fmu3_run LIBRARY RESOURCES TOKEN STEPS STEP_BITS VR:N,...\n");
        return 2;
    }
    void *lib = open_library(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 2;
    }
    resolve(lib, "fmi3InstantiateCoSimulation", &api.instantiate);
    resolve(lib, "fmi3EnterInitializationMode", &api.enter);
    resolve(lib, "fmi3ExitInitializationMode", &api.exit_init);
    resolve(lib, "fmi3DoStep", &api.step);
    resolve(lib, "fmi3GetFloat64", &api.get);
    resolve(lib, "fmi3GetFMUState", &api.get_state);
    resolve(lib, "fmi3SetFMUState", &api.set_state);
    resolve(lib, "fmi3FreeFMUState", &api.free_state);
    resolve(lib, "fmi3SerializedFMUStateSize", &api.size);
    resolve(lib, "fmi3SerializeFMUState", &api.serialize);
    resolve(lib, "fmi3DeserializeFMUState", &api.deserialize);
    resolve(lib, "fmi3Terminate", &api.terminate);
    resolve(lib, "fmi3FreeInstance", &api.free_instance);

    int steps = atoi(argv[4]);
    uint64_t bits = strtoull(argv[5], NULL, 16);
    double h;
    memcpy(&h, &bits, sizeof h);
    uint32_t vrs[256];
    size_t nvr = 0, n = 0;
    for (char *item = strtok(argv[6], ","); item && nvr < 256; item = strtok(NULL, ",")) {
        char *colon = strchr(item, ':');
        vrs[nvr++] = (uint32_t)strtoul(item, NULL, 10);
        n += colon ? strtoul(colon + 1, NULL, 10) : 1;
    }
    double *values = calloc(n + 1, sizeof *values);
    double *first = calloc((size_t)(steps + 1) * n + 1, sizeof *first);

    Instance c = api.instantiate("run", argv[3], argv[2], 0, 0, 0, 0, NULL, 0, NULL, on_message,
                                 NULL);
    if (!c) {
        printf("status instantiate 3\n");
        return 1;
    }
    must(api.enter(c, 0, 0.0, 0.0, 0, 0.0), "enter");
    must(api.exit_init(c), "exit");
    void *state = NULL;
    unsigned char *bytes = NULL;
    size_t size = 0, differ = 0;
    for (int pass = 0; pass < 2; pass++) {
        int from = pass == 0 ? 0 : steps / 2;
        for (int k = from; k <= steps; k++) {
            double t = k * h;
            if (k > from) {
                Boolean event, stop, early;
                double last;
                must(api.step(c, (k - 1) * h, h, 0, &event, &stop, &early, &last), "step");
            }
            must(api.get(c, vrs, nvr, values, n), "get");
            if (pass == 0) {
                memcpy(first + (size_t)k * n, values, n * sizeof *values);
                printf("row %d", k);
                hex(t);
                for (size_t i = 0; i < n; i++) hex(values[i]);
                printf("\n");
            } else {
                for (size_t i = 0; i < n; i++)
                    differ += memcmp(&values[i], first + (size_t)k * n + i, sizeof(double)) != 0;
            }
            if (pass == 0 && k == steps / 2) {
                must(api.get_state(c, &state), "get_state");
                must(api.size(c, state, &size), "size");
                bytes = malloc(size);
                must(api.serialize(c, state, bytes, size), "serialize");
                must(api.free_state(c, &state), "free_state");
                printf("state_size %zu\n", size);
            }
        }
        if (pass == 0) {
            must(api.deserialize(c, bytes, size, &state), "deserialize");
            must(api.set_state(c, state), "set_state");
        }
    }
    printf("rerun %zu\n", differ);
    printf("status short %d\n", api.get(c, vrs, nvr, values, n - 1));
    Boolean event, stop, early;
    double last;
    printf("status time %d\n", api.step(c, 0.5 * h, h, 0, &event, &stop, &early, &last));
    must(api.free_state(c, &state), "free_state");
    must(api.terminate(c), "terminate");
    api.free_instance(c);
    free(bytes);
    free(values);
    free(first);
    printf("done\n");
    return 0;
}
