/*
 * The texel budget (issue 27 item 2): a level's atlas outweighs a mesh of as
 * many triangles a hundredfold, while at the sizes a level is meant for a
 * primitive covers tens of pixels, so a few texels a side carry what shows.
 * Every texture is scaled by one factor (its aspect kept, at least 4 a side),
 * the largest whose texel count, or GPU bytes as asp_dps_level_gpu_bytes
 * counts them, stays within the budget; the fit then solves for the texels.
 * NEEDSWORK: per-primitive resolutions chosen by the error each removes.
 */
#include <math.h>
#include <string.h>

#include "fit/internal.h"
#include "util/banned.h"

enum { MIN_SIDE = 4 };

static void sizes(const asp_dps_level *lv, double s, uint32_t *w, uint32_t *h, uint64_t *texels)
{
    uint64_t t = 0;
    for (size_t i = 0; i < lv->prim_count; i++) {
        double a = lround(lv->prims[i].tex_w * s), b = lround(lv->prims[i].tex_h * s);
        w[i] = (uint32_t)(a < MIN_SIDE ? MIN_SIDE : a > 16384 ? 16384 : a);
        h[i] = (uint32_t)(b < MIN_SIDE ? MIN_SIDE : b > 16384 ? 16384 : b);
        t += (uint64_t)w[i] * h[i];
    }
    *texels = t;
}

/* GPU bytes lv would have at scale s: resized on a copy of what resizing touches. */
static int trial_bytes(const asp_dps_level *lv, double s, uint32_t pad, int bc3, uint32_t *w, uint32_t *h,
                       const asp_context *ctx, size_t *bytes, asp_error *err)
{
    uint64_t t;
    sizes(lv, s, w, h, &t);
    asp_dps_level copy = *lv;
    copy.prims = asp_alloc(ctx, lv->prim_count * sizeof *copy.prims);
    memset(&copy.atlas, 0, sizeof copy.atlas);
    memset(&copy.normal_atlas, 0, sizeof copy.normal_atlas);
    copy.atlas_bc3 = copy.normal_bc3 = NULL; /* lv's blocks: resizing the copy must not free them */
    int rc = copy.prims ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for a budget trial");
    if (!rc)
        memcpy(copy.prims, lv->prims, lv->prim_count * sizeof *copy.prims);
    if (!rc)
        rc = asp_image_init(&copy.atlas, lv->atlas.width, lv->atlas.height, err);
    if (!rc && lv->normal_atlas.width)
        rc = asp_image_init(&copy.normal_atlas, lv->normal_atlas.width, lv->normal_atlas.height, err);
    if (!rc) {
        memcpy(copy.atlas.pixels, lv->atlas.pixels, 4 * (size_t)lv->atlas.width * lv->atlas.height);
        if (lv->normal_atlas.width)
            memcpy(copy.normal_atlas.pixels, lv->normal_atlas.pixels,
                   4 * (size_t)lv->normal_atlas.width * lv->normal_atlas.height);
        rc = asp_dps_level_resize(&copy, w, h, pad, ctx, err);
    }
    if (!rc) {
        asp_mesh_bytes b;
        asp_dps_level_gpu_bytes(&copy, &b);
        if (bc3) { /* what asp_dps_level_compress will leave: 1 byte a texel, the height a multiple of 4 */
            size_t side = (size_t)copy.atlas.width * ((copy.atlas.height + 3) & ~3u);
            b.texture = side * (copy.normal_atlas.width ? 2 : 1);
        }
        *bytes = b.vertex + b.index + b.texture;
    }
    asp_free(ctx, copy.prims);
    asp_image_release(&copy.atlas);
    asp_image_release(&copy.normal_atlas);
    return rc;
}

int asp_fit_budget(asp_dps_level *lv, uint64_t texels, size_t bytes, uint32_t pad, int bc3, const asp_context *ctx,
                   asp_error *err)
{
    if (!lv || !lv->prim_count || (!texels && !bytes))
        return asp_error_set(err, ASP_EINVAL, "cannot apply a texel budget: empty level or no budget");
    size_t n = lv->prim_count;
    if (texels && texels < (uint64_t)n * MIN_SIDE * MIN_SIDE)
        return asp_error_set(err, ASP_EINVAL, "a budget of %llu texels is below %zu (4x4 for each of %zu primitives)",
                             (unsigned long long)texels, n * MIN_SIDE * MIN_SIDE, n);
    uint32_t *w = asp_alloc(ctx, (n + 1) * sizeof *w), *h = asp_alloc(ctx, (n + 1) * sizeof *h);
    if (!w || !h) {
        asp_free(ctx, w), asp_free(ctx, h);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu texture sizes", n);
    }
    // bisection on the scale: the count (and the packed bytes, nearly) grow with it
    double lo = 0, hi = 1;
    int rc = 0;
    for (int it = 0; it < 30 && !rc; it++) {
        double mid = 0.5 * (lo + hi);
        uint64_t t;
        size_t b = 0;
        sizes(lv, mid, w, h, &t);
        int ok = !texels || t <= texels;
        if (ok && bytes) {
            rc = trial_bytes(lv, mid, pad, bc3, w, h, ctx, &b, err);
            ok = b <= bytes;
        }
        if (ok)
            lo = mid;
        else
            hi = mid;
    }
    if (!rc) {
        uint64_t t;
        sizes(lv, lo, w, h, &t);
        size_t b = 0;
        if (bytes)
            rc = trial_bytes(lv, lo, pad, bc3, w, h, ctx, &b, err);
        if (!rc && ((texels && t > texels) || (bytes && b > bytes)))
            rc = asp_error_set(err, ASP_EINVAL,
                               "a budget of %zu bytes is below what %zu primitives of 4x4 texels take (%zu)", bytes,
                               n, b);
        if (!rc)
            rc = asp_dps_level_resize(lv, w, h, pad, ctx, err);
    }
    asp_free(ctx, w), asp_free(ctx, h);
    return rc;
}
