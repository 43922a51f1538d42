/*
 * Execution context: thread count, allocator hooks and progress reporting.
 * Allocations are 64-byte aligned (STYLE.md section 6) so every array can be
 * bound as a GL buffer or read with aligned SIMD loads.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amgsplat/core.h"
#include "util/banned.h"

enum { ASP_ALIGNMENT = 64 };

int asp_context_threads(const asp_context *ctx)
{
    if (ctx && ctx->threads > 0)
        return ctx->threads;
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

void *asp_alloc(const asp_context *ctx, size_t size)
{
    if (size == 0)
        size = 1;
    if (size > SIZE_MAX - ASP_ALIGNMENT)
        return NULL;
    if (ctx && ctx->allocator.alloc)
        return ctx->allocator.alloc(ctx->allocator.user, size, ASP_ALIGNMENT);
    /* aligned_alloc wants a multiple of the alignment */
    size_t rounded = (size + ASP_ALIGNMENT - 1) / ASP_ALIGNMENT * ASP_ALIGNMENT;
    return aligned_alloc(ASP_ALIGNMENT, rounded);
}

void *asp_calloc(const asp_context *ctx, size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    void *p = asp_alloc(ctx, count * size);
    if (p)
        memset(p, 0, count * size > 0 ? count * size : 1);
    return p;
}

void asp_free(const asp_context *ctx, void *ptr)
{
    if (!ptr)
        return;
    if (ctx && ctx->allocator.free)
        ctx->allocator.free(ctx->allocator.user, ptr);
    else
        free(ptr);
}

void *asp_realloc(const asp_context *ctx, void *ptr, size_t old_size, size_t new_size)
{
    void *p = asp_alloc(ctx, new_size);
    if (!p)
        return NULL;
    if (ptr) {
        memcpy(p, ptr, old_size < new_size ? old_size : new_size);
        asp_free(ctx, ptr);
    }
    return p;
}

int asp_progress(const asp_context *ctx, const char *stage, double fraction)
{
    if (ctx && ctx->progress && ctx->progress(ctx->progress_user, stage, fraction))
        return ASP_ECANCELED;
    return 0;
}

void asp_warn(const asp_context *ctx, const char *fmt, ...)
{
    if (!ctx || !ctx->warning)
        return;
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx->warning(ctx->warning_user, msg);
}

double asp_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
