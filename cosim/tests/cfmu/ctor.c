/* The FMU of crash.c (modelIdentifier "ctor") whose library crashes while it is loaded: a
 * load-time initializer (as C++ static constructors and licence checks in third-party
 * FMUs run) writes through a null pointer, so the process that dlopens it gets SIGSEGV
 * before any fmi2 function is called. */
#include "crash.c"

/* a null the compiler cannot see through (a store through a literal null it may drop) */
static int *volatile nowhere;

__attribute__((constructor)) static void crash_while_loading(void) { *nowhere = 1; }
