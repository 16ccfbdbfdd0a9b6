/*
 * importer.h: what the C importers of the platform tests share: mingw's C99 printf (%.17g
 * round-trips every double), loading a library on Windows and on POSIX systems, and the
 * FMI 2.0 C types and logger they use (the types from fmi2TypesPlatform.h and
 * fmi2FunctionTypes.h; the FMI 3.0 ones come from the FMI 3.0 headers of fmpy's c-code
 * folder). Included first.
 */
#ifndef IMPORTER_H
#define IMPORTER_H
#define __USE_MINGW_ANSI_STDIO 1 /* C99 printf in mingw: %.17g round-trips */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library_t;
static library_t library_open(const char *path) { return LoadLibraryA(path); }
static void *library_symbol(library_t l, const char *name) { return (void *)GetProcAddress(l, name); }
#else
#include <dlfcn.h>
typedef void *library_t;
static library_t library_open(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *library_symbol(library_t l, const char *name) { return dlsym(l, name); }
#endif

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef unsigned int fmi2ValueReference;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;
typedef struct {
    fmi2Boolean newDiscreteStatesNeeded, terminateSimulation, nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged, nextEventTimeDefined;
    fmi2Real nextEventTime;
} fmi2EventInfo;

/* The FMI 2.0 logger of the importers: the message to stderr, with the instance's name. */
static inline void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                           fmi2String message, ...) {
    va_list args;
    (void)env;
    fprintf(stderr, "[%s] %s status %d: ", name ? name : "?", category ? category : "", (int)status);
    va_start(args, message);
    vfprintf(stderr, message ? message : "", args);
    va_end(args);
    fputc('\n', stderr);
}

#endif
