/* The FMI 2.0 logger callback is C-variadic (printf style); stable Rust cannot define one.
 * This shim formats the message (truncated to 4 KiB) and hands it to the master in Rust. */
#include <stdarg.h>
#include <stdio.h>

extern void nigel_cosim_record_log(void *env, const char *instance_name, int status, const char *category,
                                   const char *message);

void nigel_cosim_logger(void *env, const char *instance_name, int status, const char *category,
                        const char *format, ...) {
    char buffer[4096];
    va_list args;
    buffer[0] = 0;
    if (format) {
        va_start(args, format);
        vsnprintf(buffer, sizeof buffer, format, args);
        va_end(args);
    }
    nigel_cosim_record_log(env, instance_name, status, category, buffer);
}
