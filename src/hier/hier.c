/*
 * The asp_hier object: allocation, accessors and colour averaging helpers.
 * Node colours are means in linear light (seed 001 section 3.2 "average
 * color"), converted back to 8-bit sRGB, so a coarse splat is as bright as
 * the surface it replaces.
 */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* madvise(MADV_HUGEPAGE) */
#endif
#include <math.h>
#include <stdint.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "hier/internal.h"
#include "util/banned.h"

void asp__hier_huge_pages(void *ptr, size_t size)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    /*
     * A 1M-point build first-touches ~250 MB; with 4 KB pages a quarter of its
     * CPU time went to page faults. Only whole 2 MB runs inside the block are
     * advised, and failure (no THP, a custom allocator's memory) is harmless.
     */
    const uintptr_t huge = (uintptr_t)2 << 20;
    uintptr_t lo = ((uintptr_t)ptr + huge - 1) & ~(huge - 1), hi = ((uintptr_t)ptr + size) & ~(huge - 1);
    if (ptr && hi > lo)
        (void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
#else
    (void)ptr;
    (void)size;
#endif
}

int asp__hier_alloc(const asp_context *ctx, size_t node_count, size_t point_count, asp_hier **out,
                    asp_error *err)
{
    asp_hier *h = asp_calloc(ctx, 1, sizeof *h);
    if (!h)
        return asp_error_set(err, ASP_ENOMEM, "cannot allocate a hierarchy");
    if (ctx)
        h->ctx = *ctx;
    h->node_count = node_count;
    h->point_count = point_count;
    /* not zeroed: build and load write every field, and zeroing 200 MB is measurable */
    h->nodes = node_count < SIZE_MAX / sizeof *h->nodes ? asp_alloc(ctx, node_count * sizeof *h->nodes) : NULL;
    h->splats = node_count + point_count >= node_count && node_count + point_count < SIZE_MAX / sizeof *h->splats
                    ? asp_alloc(ctx, (node_count + point_count) * sizeof *h->splats)
                    : NULL;
    h->cov = node_count < SIZE_MAX / (ASP_HIER_COV * sizeof(double))
                 ? asp_alloc(ctx, node_count * ASP_HIER_COV * sizeof(double))
                 : NULL;
    if (h->nodes && h->splats && h->cov) {
        asp__hier_huge_pages(h->nodes, node_count * sizeof *h->nodes);
        asp__hier_huge_pages(h->splats, (node_count + point_count) * sizeof *h->splats);
        asp__hier_huge_pages(h->cov, node_count * ASP_HIER_COV * sizeof(double));
    }
    if (!h->nodes || !h->splats || !h->cov) {
        asp_hier_destroy(h);
        return asp_error_set(err, ASP_ENOMEM, "cannot allocate a hierarchy of %zu nodes and %zu points",
                             node_count, point_count);
    }
    *out = h;
    return 0;
}

void asp_hier_destroy(asp_hier *hier)
{
    if (!hier)
        return;
    asp_context ctx = hier->ctx;
    asp_free(&ctx, hier->nodes);
    asp_free(&ctx, hier->splats);
    asp_free(&ctx, hier->cov);
    asp_free(&ctx, hier);
}

size_t asp_hier_node_count(const asp_hier *hier)
{
    return hier->node_count;
}

size_t asp_hier_point_count(const asp_hier *hier)
{
    return hier->point_count;
}

uint32_t asp_hier_depth(const asp_hier *hier)
{
    return hier->depth;
}

unsigned asp_hier_flags(const asp_hier *hier)
{
    return hier->flags;
}

size_t asp_hier_leaf_size(const asp_hier *hier)
{
    return hier->leaf_size;
}

const asp_frame *asp_hier_frame(const asp_hier *hier)
{
    return &hier->frame;
}

void asp_hier_origin(const asp_hier *hier, double out[3])
{
    memcpy(out, hier->origin, sizeof hier->origin);
}

const asp_hier_node *asp_hier_nodes(const asp_hier *hier)
{
    return hier->nodes;
}

const asp_hier_splat *asp_hier_splats(const asp_hier *hier)
{
    return hier->splats;
}

const double *asp_hier_covariances(const asp_hier *hier)
{
    return hier->cov;
}

size_t asp_hier_select_bound(const asp_hier *hier)
{
    return hier->point_count;
}

void asp__srgb_table(float lin[256])
{
    /* IEC 61966-2-1 decoding */
    for (int i = 0; i < 256; i++) {
        double c = i / 255.0;
        lin[i] = (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
    }
}

uint8_t asp__linear_to_srgb8(const float lin[256], double v)
{
    /* the 8-bit code whose linear value is nearest: binary search on midpoints, no pow per node */
    int lo = 0, hi = 255;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (v > 0.5 * ((double)lin[mid] + lin[mid + 1]))
            lo = mid + 1;
        else
            hi = mid;
    }
    return (uint8_t)lo;
}
