/*
 * amgsplat core: error reporting, allocation, execution context and progress.
 * Every fallible function returns 0 or a negative ASP_E* code and fills an
 * optional asp_error (STYLE.md section 4). There is no global state: threads,
 * allocator and progress reporting travel in an asp_context.
 */
#ifndef AMGSPLAT_CORE_H
#define AMGSPLAT_CORE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ASP_VERSION_MAJOR 0
#define ASP_VERSION_MINOR 1
#define ASP_VERSION_PATCH 0
#define ASP_VERSION_STRING "0.1.0"

/** Error codes: 0 is success, failures are negative. */
enum asp_error_code {
    ASP_OK = 0,
    ASP_EINVAL = -1,       /* invalid argument or option value */
    ASP_ENOMEM = -2,       /* out of memory, or a size that cannot be allocated */
    ASP_EIO = -3,          /* operating-system I/O failure (open, read, write, rename) */
    ASP_EFORMAT = -4,      /* malformed or truncated file contents */
    ASP_EUNSUPPORTED = -5, /* valid input this build or function does not handle */
    ASP_EDEGENERATE = -6,  /* input is empty, all equal, colinear, zero area ... */
    ASP_EGL = -7,          /* no GL context, GL error, shader compile failure */
    ASP_ESOLVER = -8,      /* hypre / numerical failure */
    ASP_ECANCELED = -9     /* progress callback asked to stop */
};

/** Error report filled by fallible functions; may be passed as NULL. */
typedef struct asp_error {
    int code;       /* one of asp_error_code */
    char msg[256];  /* "cannot open 'x.ply': No such file or directory" */
} asp_error;

/**
 * Fills err (when not NULL) with code and a printf-style message, and returns
 * code so callers can write `return asp_error_set(err, ASP_EINVAL, ...)`.
 */
int asp_error_set(asp_error *err, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/**
 * Programmer errors (STYLE.md section 4): a NULL where the contract forbids it, a count of 0 where
 * one is required, a broken internal invariant. Unlike assert() it stays on whatever NDEBUG says,
 * as meshopt's and git's BUG() do: a Release build that silently continues past a broken contract
 * corrupts memory later, far from the cause. On failure it prints "file:line: assertion failed:
 * cond" to stderr and calls abort(); that is the one place the library prints. Runtime errors
 * (bad files, I/O, out of memory) never use it: they return an ASP_E* code.
 * cond is evaluated exactly once.
 */
#define ASP_ASSERT(cond) ((cond) ? (void)0 : asp__assert_fail(__FILE__, __LINE__, #cond))

/** ASP_ASSERT's failure path: prints file:line and the condition to stderr, then abort(). */
#if defined(__GNUC__)
__attribute__((noreturn, cold))
#endif
void asp__assert_fail(const char *file, int line, const char *cond);

/** Returns a short constant name for an error code ("ASP_EFORMAT"). */
const char *asp_error_name(int code);

/** Allocator hooks; all-zero means the C library with 64-byte alignment. */
typedef struct asp_allocator {
    void *(*alloc)(void *user, size_t size, size_t alignment);
    void (*free)(void *user, void *ptr);
    void *user;
} asp_allocator;

/**
 * Progress callback: stage names a step ("knn", "read"), fraction in [0,1].
 * Returns non-zero to ask the long-running function to stop with ASP_ECANCELED.
 * Called only from the thread that called the library function.
 */
typedef int (*asp_progress_fn)(void *user, const char *stage, double fraction);

/**
 * Warning callback: a file was read or written, but something in it was
 * repaired or left out (message in the asp_error style, naming the file).
 * The library never prints (STYLE.md 4); the caller decides where it goes.
 * Called only from the thread that called the library function.
 */
typedef void (*asp_warning_fn)(void *user, const char *message);

/**
 * Execution context, owned by the caller; the zero value (or a NULL pointer
 * wherever a `const asp_context *` is taken) means: all OpenMP threads, the C
 * allocator, no progress reporting.
 */
typedef struct asp_context {
    int threads;               /* 0 = OpenMP default, else exact count */
    asp_allocator allocator;
    asp_progress_fn progress;  /* may be NULL */
    void *progress_user;
    asp_warning_fn warning;    /* may be NULL: warnings are then dropped */
    void *warning_user;
} asp_context;

/** Thread count a kernel should use under ctx (>= 1). */
int asp_context_threads(const asp_context *ctx);

/** 64-byte-aligned allocation through ctx's allocator; NULL when out of memory or size overflows. */
void *asp_alloc(const asp_context *ctx, size_t size);
/** Like asp_alloc but zero-filled; count * size is checked for overflow. */
void *asp_calloc(const asp_context *ctx, size_t count, size_t size);
/** Frees memory from asp_alloc/asp_calloc; NULL is accepted. */
void asp_free(const asp_context *ctx, void *ptr);
/** Reallocates (copying min(old_size,new_size) bytes); on failure returns NULL and ptr stays valid. */
void *asp_realloc(const asp_context *ctx, void *ptr, size_t old_size, size_t new_size);

/** Reports progress if ctx has a callback; returns ASP_ECANCELED if it asked to stop, else 0. */
int asp_progress(const asp_context *ctx, const char *stage, double fraction);

/** Formats a warning and hands it to ctx's warning callback, if any (the text is cut at 256 bytes). */
void asp_warn(const asp_context *ctx, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** Seconds on a monotonic clock, for timings reported by the library. */
double asp_time_now(void);

#ifdef __cplusplus
}
#endif
#endif
