/*
 * Running a third-party reader where its crash cannot take the process down
 * (issue #31): the work runs in a forked child with capped address space and
 * CPU time and sends its result back through a pipe; the parent turns the
 * child's death by a signal, its running out of memory or time into an error
 * naming the file. Not public API.
 */
#ifndef ASP_UTIL_CHILD_PROCESS_H
#define ASP_UTIL_CHILD_PROCESS_H

#include <stddef.h>

#include "amgsplat/core.h"

/* Writes exactly len bytes to fd (retrying short writes and EINTR); 0 or -1. */
int asp__fd_write_all(int fd, const void *buf, size_t len);

/* Reads exactly len bytes from fd; 0, or -1 at an early end of the stream or a read error. */
int asp__fd_read_all(int fd, void *buf, size_t len);

/*
 * 0 when the process may grow by need bytes under its address-space limit
 * (ulimit -v, RLIMIT_AS; always 0 without one). Otherwise ASP_ENOMEM "out
 * of memory: <what> needs about N MB of address space, the limit (ulimit -v)
 * leaves M MB". For third-party code that does not survive its allocations
 * failing (issue #31: Mesa's shader compiler died of SIGSEGV or an uncaught
 * std::bad_alloc under ulimit -v), checked before calling it.
 */
int asp__address_space_headroom(size_t need, const char *what, asp_error *err);

/*
 * What the GL driver's code generation (llvmpipe's LLVM) may need, measured under ulimit -v on a
 * 2M-point render: shader compilation crashed with 230 MB left and passed with 327 MB; drawing
 * passed with 295 MB.
 */
#define ASP_GL_SHADER_HEADROOM ((size_t)320 << 20)
#define ASP_GL_DRAW_HEADROOM ((size_t)160 << 20)
/*
 * Creating a headless GL context (Mesa maps its driver and LLVM, llvmpipe starts its threads), the
 * same 2M-point render: it died (SIGSEGV in swrast_dri.so, or epoxy's abort when libGL could not be
 * mapped) with 490 MB left and passed with 495 MB.
 */
#define ASP_GL_CONTEXT_HEADROOM ((size_t)512 << 20)

/* What runs in the child: writes its result to fd; its return value is ignored. */
typedef void (*asp__child_work)(void *user, int fd);

/*
 * What runs in the parent meanwhile: reads the child's result from fd. Returns 0, or an ASP_E*
 * code with err filled; ASP_ECHILD_STREAM when the stream ended early (the child died), in
 * which case asp__child_run reports why the child died instead.
 */
typedef int (*asp__child_receive)(void *user, int fd, asp_error *err);

/* receive's code for a stream that ended before the child's whole result */
#define ASP_ECHILD_STREAM (-1000)

typedef struct asp__child_desc {
    const char *path;     /* the file the child reads, for messages */
    const char *reader;   /* the reader's name for messages ("assimp") */
    size_t memory_budget; /* bytes of address space the child may add to the parent's (0: no cap) */
    unsigned cpu_seconds; /* CPU seconds the child may use (0: no cap) */
} asp__child_desc;

/*
 * Forks; the child caps its address space at the parent's current size plus
 * memory_budget (not under AddressSanitizer, whose shadow memory reserves
 * terabytes) and its CPU time, runs work, and ends with _exit (no atexit
 * handlers, no stdio flush of the parent's buffers). The parent runs receive
 * on the pipe's read end, then reaps the child. Errors: receive's, or
 * ASP_EFORMAT "cannot read '<path>': the reader (<reader>) crashed with
 * signal N (<name>)", ASP_ENOMEM "cannot read '<path>': the reader (<reader>)
 * ran out of memory ...", ASP_EFORMAT "... ran out of time ...", ASP_EIO when
 * no child can be started. Call with stdout flushed (the child's _exit
 * discards buffers anyway).
 */
int asp__child_run(const asp__child_desc *desc, asp__child_work work, asp__child_receive receive, void *user,
                   asp_error *err);

#endif
