/*
 * A level's textures at other resolutions (issue 27 item 2, the texel
 * budget): each primitive's texture resampled to a given size, box-filtered
 * when it shrinks (colour averaged in linear light, thesis 5.1's sRGB atlas),
 * bilinear when it grows, then packed and padded again as the build packs
 * them (atlas.c). Geometry is kept; the rectangle still maps to its texture's
 * edges, so texels may become slightly non-square.
 */
#include <math.h>
#include <string.h>

#include "prim/internal.h"
#include "util/banned.h"

static double to_linear(uint8_t v)
{
    double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static uint8_t to_srgb(double c)
{
    c = c <= 0 ? 0 : c >= 1 ? 1 : c;
    return (uint8_t)lround(255.0 * (c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055));
}

/* Old texels [a, b) along one axis of n: their overlap with new texel i of m (box), as weights. */
static void resample_rect(const asp_image *src, const asp_prim *p, uint32_t nw, uint32_t nh, int srgb,
                          asp_image *dst, uint32_t dx, uint32_t dy)
{
    double sx = (double)p->tex_w / nw, sy = (double)p->tex_h / nh;
    for (uint32_t j = 0; j < nh; j++)
        for (uint32_t i = 0; i < nw; i++) {
            double acc[4] = {0, 0, 0, 0}, wsum = 0;
            // the new texel's footprint in old texel units, at least one old texel wide (bilinear-like growth)
            double x0 = i * sx, x1 = (i + 1) * sx, y0 = j * sy, y1 = (j + 1) * sy;
            if (sx < 1) {
                double c = (i + 0.5) * sx;
                x0 = c - 0.5, x1 = c + 0.5;
            }
            if (sy < 1) {
                double c = (j + 0.5) * sy;
                y0 = c - 0.5, y1 = c + 0.5;
            }
            for (long y = (long)floor(y0); y < (long)ceil(y1); y++)
                for (long x = (long)floor(x0); x < (long)ceil(x1); x++) {
                    double w = (fmin(x1, x + 1.0) - fmax(x0, (double)x)) * (fmin(y1, y + 1.0) - fmax(y0, (double)y));
                    if (!(w > 0))
                        continue;
                    long cx = x < 0 ? 0 : x >= (long)p->tex_w ? (long)p->tex_w - 1 : x;
                    long cy = y < 0 ? 0 : y >= (long)p->tex_h ? (long)p->tex_h - 1 : y;
                    const uint8_t *s =
                        src->pixels + 4 * ((size_t)(p->tex_y + (uint32_t)cy) * src->width + p->tex_x + (uint32_t)cx);
                    for (int a = 0; a < 4; a++)
                        acc[a] += w * (srgb && a < 3 ? to_linear(s[a]) : s[a] / 255.0);
                    wsum += w;
                }
            uint8_t *d = dst->pixels + 4 * ((size_t)(dy + j) * dst->width + dx + i);
            for (int a = 0; a < 4; a++) {
                double v = wsum > 0 ? acc[a] / wsum : 0;
                d[a] = srgb && a < 3 ? to_srgb(v) : (uint8_t)lround(fmin(fmax(v, 0), 1) * 255.0);
            }
        }
}

int asp_dps_level_resize(asp_dps_level *lv, const uint32_t *tex_w, const uint32_t *tex_h, uint32_t pad,
                         const asp_context *ctx, asp_error *err)
{
    size_t n = lv->prim_count;
    for (size_t i = 0; i < n; i++)
        if (tex_w[i] < 1 || tex_h[i] < 1 || tex_w[i] > 16384 || tex_h[i] > 16384)
            return asp_error_set(err, ASP_EINVAL, "primitive %zu: texture %ux%u, expected 1..16384 a side", i,
                                 tex_w[i], tex_h[i]);
    uint32_t *x = asp_alloc(ctx, (n + 1) * sizeof *x), *y = asp_alloc(ctx, (n + 1) * sizeof *y);
    asp_prim *prims = asp_alloc(ctx, (n + 1) * sizeof *prims);
    asp_image atlas = {0}, normals = {0};
    uint32_t aw = 0, ah = 0;
    int rc = 0;
    if (!x || !y || !prims) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory resizing %zu textures", n);
        goto done;
    }
    int pr = asp__atlas_pack(tex_w, tex_h, n, pad, 16384, x, y, &aw, &ah, ctx);
    if (pr) {
        rc = pr == -2 ? asp_error_set(err, ASP_ENOMEM, "out of memory packing %zu textures", n)
                      : asp_error_set(err, ASP_EUNSUPPORTED, "the resized textures do not fit a 16384 atlas");
        goto done;
    }
    rc = asp_image_init(&atlas, aw, ah, err);
    if (!rc && lv->normal_atlas.width)
        rc = asp_image_init(&normals, aw, ah, err);
    if (rc)
        goto done;
    uint64_t texels = 0;
    for (size_t i = 0; i < n; i++) {
        const asp_prim *p = &lv->prims[i];
        resample_rect(&lv->atlas, p, tex_w[i], tex_h[i], 1, &atlas, x[i], y[i]);
        if (normals.width)
            resample_rect(&lv->normal_atlas, p, tex_w[i], tex_h[i], 0, &normals, x[i], y[i]);
        prims[i] = *p;
        prims[i].tex_x = x[i], prims[i].tex_y = y[i], prims[i].tex_w = tex_w[i], prims[i].tex_h = tex_h[i];
        // the texel edge a primitive records: the mean of its two (rounding makes them differ slightly)
        prims[i].texel = (float)(0.5 * (2.0 * p->half_u / tex_w[i] + 2.0 * p->half_v / tex_h[i]));
        texels += (uint64_t)tex_w[i] * tex_h[i];
    }
    asp__atlas_pad(&atlas, prims, n, pad);
    if (normals.width)
        asp__atlas_pad(&normals, prims, n, pad);
    memcpy(lv->prims, prims, n * sizeof *prims);
    asp_image_release(&lv->atlas);
    lv->atlas = atlas;
    memset(&atlas, 0, sizeof atlas);
    if (normals.width) {
        asp_image_release(&lv->normal_atlas);
        lv->normal_atlas = normals;
        memset(&normals, 0, sizeof normals);
    }
    lv->texels = texels;
    asp_free(ctx, lv->atlas_bc3); /* resampled texels are RGBA8 until compressed again */
    asp_free(ctx, lv->normal_bc3);
    lv->atlas_bc3 = lv->normal_bc3 = NULL;
done:
    asp_image_release(&atlas);
    asp_image_release(&normals);
    asp_free(ctx, x), asp_free(ctx, y), asp_free(ctx, prims);
    return rc;
}
