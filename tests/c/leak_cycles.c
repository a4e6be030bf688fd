/* A minimal FMI 2.0 co-simulation master in C for the leak test: loads an extracted FMU's
 * binary with dlopen and runs N cycles of instantiate / initialize / doStep / free.
 * Usage: leak_cycles <binary.so> <resources file URI> <GUID> <cycles>
 *        leak_cycles <binary.so> <resources file URI> <GUID> steps <n>
 * The second form runs one instance for n fmi2DoStep calls and prints the resident memory
 * (KiB) after n/10 and after n calls. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *Component;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

static void logger(void *env, const char *name, int status, const char *category,
                   const char *message, ...) {
    (void)env;
    if (status > 1) fprintf(stderr, "[%s] %s: %s\n", name, category, message);
}

#define LOAD(var, name)                                                   \
    var = dlsym(lib, name);                                               \
    if (!var) { fprintf(stderr, "missing %s\n", name); return 2; }

static long rss_kib(void) {
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f || fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = -1;
    if (f) fclose(f);
    return resident * 4;
}

int main(int argc, char **argv) {
    if (argc != 5 && argc != 6) { fprintf(stderr, "usage: %s lib uri guid cycles | steps n\n", argv[0]); return 2; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 2; }
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    int (*setup)(Component, int, double, double, int, double);
    int (*enter)(Component), (*exit_init)(Component), (*terminate)(Component);
    int (*do_step)(Component, double, double, int);
    void (*free_instance)(Component);
    LOAD(instantiate, "fmi2Instantiate");
    LOAD(setup, "fmi2SetupExperiment");
    LOAD(enter, "fmi2EnterInitializationMode");
    LOAD(exit_init, "fmi2ExitInitializationMode");
    LOAD(do_step, "fmi2DoStep");
    LOAD(terminate, "fmi2Terminate");
    LOAD(free_instance, "fmi2FreeInstance");
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    if (argc == 6) {
        long n = atol(argv[5]), before = 0;
        Component c = instantiate("steps", 1, argv[3], argv[2], &cb, 0, 0);
        if (!c || setup(c, 0, 0.0, 0, 0.0, 0) || enter(c) || exit_init(c)) return 1;
        for (long k = 0; k < n; k++) {
            if (do_step(c, k * 1e-4, 1e-4, 1)) { fprintf(stderr, "doStep failed at %ld\n", k); return 1; }
            if (k == n / 10) before = rss_kib();
        }
        printf("rss %ld %ld\n", before, rss_kib());
        free_instance(c);
        return 0;
    }
    int cycles = atoi(argv[4]);
    for (int k = 0; k < cycles; k++) {
        Component c = instantiate("leak", 1, argv[3], argv[2], &cb, 0, 0);
        if (!c) { fprintf(stderr, "instantiate failed at cycle %d\n", k); return 1; }
        if (setup(c, 0, 0.0, 0, 0.0, 0) || enter(c) || exit_init(c) || do_step(c, 0.0, 1e-3, 1) ||
            terminate(c)) {
            fprintf(stderr, "a call failed at cycle %d\n", k);
            return 1;
        }
        free_instance(c);
    }
    dlclose(lib);
    printf("%d cycles\n", cycles);
    return 0;
}
