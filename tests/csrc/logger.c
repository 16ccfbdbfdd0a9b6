/* The FMI 2.0 logger is C-variadic (printf style); stable Rust cannot define one, so the
 * test importer's logger is this C shim. It formats the message and hands it to Rust. */
#include <stdarg.h>
#include <stdio.h>

extern void nigel_test_record_log(void *env, int status, const char *category, const char *message);

void nigel_test_logger(void *env, const char *instance_name, int status, const char *category,
                       const char *format, ...) {
    char buffer[4096];
    va_list args;
    (void)instance_name;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    nigel_test_record_log(env, status, category, buffer);
}
