/* The FMI 2.0 logger callback is C-variadic (printf style); stable Rust cannot define one.
 * This shim formats the message (truncated to 4 KiB) and hands it to the importer in Rust:
 * the component environment points to a `LogEnvironment` (src/logger.rs), whose first
 * field is the Rust function that receives the formatted message.
 *
 * An FMU's format string is not trusted. C cannot tell how many arguments a variadic call
 * passed, so the format is formatted one conversion at a time, by this shim:
 *  - a format with %n (writes through an argument), `*` widths or precisions, or
 *    positional `%1$` arguments is not formatted at all: the message says so and shows
 *    the format text;
 *  - a %s argument is read only if it points into readable memory (checked with
 *    process_vm_readv, ReadProcessMemory or vm_read_overwrite, which fail instead of
 *    faulting) outside the importer's own program
 *    image (its code, constants and static data); otherwise the message shows
 *    "<unreadable string>" or "<string in the importer's memory>" in its place. So a %s
 *    without an argument (whatever pointer the register or stack slot holds) never crashes
 *    the importer and never shows its program's data;
 *  - wide strings and characters (%ls, %lc) are not formatted either.
 * Numbers of missing arguments still print whatever the register or stack slot holds: a
 * number, not memory behind it. */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#elif defined(__APPLE__)
#include <dlfcn.h>
#include <mach/mach.h>
#else
#include <dlfcn.h>
#include <sys/uio.h>
#include <unistd.h>
#endif

/* The first field of the object the component environment points to. */
typedef void (*fmi2_sys_receive)(void *env, const char *instance_name, int status, const char *category,
                                 const char *message);

void fmi2_sys_logger(void *env, const char *instance_name, int status, const char *category,
                        const char *format, ...);

#define BUFFER 4096
#define PAGE 4096

/* Reads `n` bytes at `at` of this process into `out` by a system call that fails instead of
 * faulting on unreadable memory: process_vm_readv (Linux), ReadProcessMemory (Windows),
 * vm_read_overwrite (macOS). Returns the bytes read, 0 or less when none could be. */
static long read_own_memory(uintptr_t at, char *out, size_t n) {
#ifdef _WIN32
    SIZE_T got = 0;
    if (!ReadProcessMemory(GetCurrentProcess(), (LPCVOID)at, out, n, &got)) return 0;
    return (long)got;
#elif defined(__APPLE__)
    vm_size_t got = 0;
    if (vm_read_overwrite(mach_task_self(), (vm_address_t)at, n, (vm_address_t)(uintptr_t)out, &got) != KERN_SUCCESS)
        return 0;
    return (long)got;
#else
    struct iovec local = {out, n};
    struct iovec remote = {(void *)at, n};
    return (long)process_vm_readv(getpid(), &local, 1, &remote, 1, 0);
#endif
}

/* read_own_memory for the memory guard of the importer's allocator (fmi2/guard.rs). */
long fmi2_sys_read_own_memory(uintptr_t at, char *out, size_t n) { return read_own_memory(at, out, n); }

/* Copies at most `cap` bytes of the C string at `p` into `out` (NUL-terminated), page by
 * page with read_own_memory. Returns the length copied, or -1 if the first byte is not
 * readable. A string that becomes unreadable before its NUL is cut there. */
static long safe_copy_string(const char *p, char *out, size_t cap) {
    size_t n = 0;
    while (n < cap) {
        uintptr_t at = (uintptr_t)p + n;
        size_t chunk = PAGE - (at % PAGE);
        if (chunk > cap - n) chunk = cap - n;
        long got = read_own_memory(at, out + n, chunk);
        if (got <= 0) {
            if (n == 0) return -1;
            break;
        }
        char *nul = memchr(out + n, 0, (size_t)got);
        if (nul) return (long)(nul - out);
        n += (size_t)got;
        if ((size_t)got < chunk) break;
    }
    out[n < cap ? n : cap] = 0;
    return (long)(n < cap ? n : cap);
}

/* Whether `p` lies in the importer's program image (the executable this shim is linked
 * into: its code, constants and static data). */
static int in_importer_image(const void *p) {
#ifdef _WIN32
    HMODULE mine, theirs;
    DWORD flags = GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT;
    if (!GetModuleHandleExA(flags, (LPCSTR)(uintptr_t)&fmi2_sys_logger, &mine)) return 0;
    if (!GetModuleHandleExA(flags, (LPCSTR)p, &theirs)) return 0;
    return theirs == mine;
#else
    Dl_info mine, theirs;
    if (!dladdr((void *)&fmi2_sys_logger, &mine)) return 0;
    if (!dladdr(p, &theirs)) return 0;
    return theirs.dli_fbase == mine.dli_fbase;
#endif
}

/* Appends to buf[*len .. BUFFER). */
static void append(char *buf, size_t *len, const char *text, size_t n) {
    if (*len >= BUFFER - 1) return;
    if (n > BUFFER - 1 - *len) n = BUFFER - 1 - *len;
    memcpy(buf + *len, text, n);
    *len += n;
    buf[*len] = 0;
}

/* Why `format` is not formatted, or NULL if it can be. */
static const char *refusal(const char *format) {
    for (const char *f = format; *f; f++) {
        if (*f != '%') continue;
        f++;
        if (*f == '%') continue;
        for (; *f && !strchr("diouxXeEfFgGaAcspnm", *f); f++) {
            if (*f == '*') return "a * width or precision";
            if (*f == '$') return "a positional argument ($)";
            if (*f == 'l' && (f[1] == 's' || f[1] == 'c')) return "a wide string or character (%ls, %lc)";
        }
        if (*f == 'n') return "%n, which writes to memory";
        if (!*f) return "an incomplete conversion at its end";
    }
    return NULL;
}

static void format_message(char *buf, const char *format, va_list args) {
    size_t len = 0;
    buf[0] = 0;
    const char *why = refusal(format);
    if (why) {
        snprintf(buf, BUFFER, "[log message not formatted: its format contains %s] %.512s", why, format);
        return;
    }
    for (const char *f = format; *f;) {
        if (*f != '%') {
            const char *next = strchr(f, '%');
            size_t n = next ? (size_t)(next - f) : strlen(f);
            append(buf, &len, f, n);
            f += n;
            continue;
        }
        /* one conversion: %[flags][width][.precision][length]conversion */
        char spec[64];
        size_t k = 0;
        const char *start = f++;
        if (*f == '%') {
            append(buf, &len, "%", 1);
            f++;
            continue;
        }
        while (*f && !strchr("diouxXeEfFgGaAcspm", *f)) f++;
        char conv = *f++;
        size_t spec_len = (size_t)(f - start);
        if (spec_len >= sizeof spec) { /* absurdly long flags and digits: shown as text */
            append(buf, &len, start, spec_len);
            continue;
        }
        memcpy(spec, start, spec_len);
        spec[spec_len] = 0;
        k = spec_len;
        /* the length modifier decides the argument's type */
        int longs = 0, shorts = 0, big = 0, sized = 0;
        for (size_t i = 1; i + 1 < k; i++) {
            switch (spec[i]) {
            case 'l': longs++; break;
            case 'h': shorts++; break;
            case 'L': case 'q': big = 1; break;
            case 'j': case 'z': case 't': sized = 1; break;
            default: break;
            }
        }
        char piece[BUFFER];
        piece[0] = 0;
        switch (conv) {
        case 'd': case 'i': case 'o': case 'u': case 'x': case 'X': case 'c':
            if (longs >= 2 || big) snprintf(piece, sizeof piece, spec, va_arg(args, long long));
            else if (longs == 1 || sized) snprintf(piece, sizeof piece, spec, va_arg(args, long));
            else snprintf(piece, sizeof piece, spec, va_arg(args, int));
            (void)shorts; /* char and short are promoted to int */
            break;
        case 'e': case 'E': case 'f': case 'F': case 'g': case 'G': case 'a': case 'A':
            if (big) snprintf(piece, sizeof piece, spec, va_arg(args, long double));
            else snprintf(piece, sizeof piece, spec, va_arg(args, double));
            break;
        case 'p':
            snprintf(piece, sizeof piece, spec, va_arg(args, void *));
            break;
        case 'm':
            snprintf(piece, sizeof piece, "%s", spec); /* no argument; shown as written */
            break;
        case 's': {
            const char *s = va_arg(args, const char *);
            char text[BUFFER];
            if (!s) {
                snprintf(text, sizeof text, "(null)");
            } else if (in_importer_image(s)) {
                snprintf(text, sizeof text, "<string in the importer's memory>");
            } else if (safe_copy_string(s, text, BUFFER - 1) < 0) {
                snprintf(text, sizeof text, "<unreadable string>");
            }
            spec[k - 1] = 's';
            snprintf(piece, sizeof piece, spec, text); /* width and precision as asked */
            break;
        }
        default:
            break;
        }
        append(buf, &len, piece, strlen(piece));
    }
}

void fmi2_sys_logger(void *env, const char *instance_name, int status, const char *category,
                        const char *format, ...) {
    /* the format, the category and the name are the FMU's pointers too: copied safely */
    char buffer[BUFFER], format_copy[BUFFER], category_copy[256], name_copy[256];
    va_list args;
    buffer[0] = 0;
    if (!category || safe_copy_string(category, category_copy, sizeof category_copy - 1) < 0) category_copy[0] = 0;
    if (!instance_name || safe_copy_string(instance_name, name_copy, sizeof name_copy - 1) < 0) name_copy[0] = 0;
    if (format) {
        if (safe_copy_string(format, format_copy, sizeof format_copy - 1) < 0) {
            snprintf(buffer, sizeof buffer, "<unreadable log format>");
        } else {
            va_start(args, format);
            format_message(buffer, format_copy, args);
            va_end(args);
        }
    }
    if (env) {
        fmi2_sys_receive receive = *(fmi2_sys_receive *)env;
        if (receive) receive(env, name_copy, status, category_copy, buffer);
    }
}
