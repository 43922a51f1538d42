/*
 * Private to src/fit: the per-pixel linear form of the normalized blend. A
 * rasterised view is, per covered pixel, a list of (atlas texel, coefficient)
 * such that the pixel's linear colour is sum coef * colour(texel): the
 * coefficient is a_f shade_f b_fk / sum_f a_f for fragment f's bilinear texel
 * k (Pajarola et al. 2003 5.4; the division makes the blend a convex
 * combination, the partition of unity restored after projection).
 */
#ifndef ASP_FIT_INTERNAL_H
#define ASP_FIT_INTERNAL_H

#include "amgsplat/fit.h"

/* One view's linear rows; pixel p has entries first[p] .. first[p + 1] - 1 (none: not covered). */
typedef struct asp__fit_rows {
    uint32_t width, height;
    size_t *first;          /* width * height + 1 */
    uint32_t *texel;        /* atlas texel index y * atlas width + x */
    float *coef;
    size_t total;
} asp__fit_rows;

/* One fragment of a pixel: a front-facing support rectangle hit by the pixel centre's eye ray. */
typedef struct asp__fit_frag {
    uint32_t prim;
    float a, shade;                /* bilinear alpha; the shade factor that multiplies the colour */
    float tx, ty;                  /* atlas texel coordinates (texel i spans [i, i + 1)) */
    double z, len;                 /* -z_eye and |eye point| */
} asp__fit_frag;

/* alpha_ref and the depth window resolved as the prim renderer resolves them. */
void asp__fit_draw_resolve(const asp_dps_level *lv, const asp_fit_draw *in, asp_fit_draw *out, double *window);

/*
 * Fragments per pixel as CSR (first: width * height + 1, allocated through ctx; frags likewise), in
 * primitive order; all = 0 keeps only alpha > 0 (what the blend sees), 1 every hit. draw resolved.
 */
int asp__fit_fragments(const asp_dps_level *lv, const double origin[3], const asp_fit_view *v,
                       const asp_fit_draw *draw, int all, const asp_context *ctx, size_t **first,
                       asp__fit_frag **frags, asp_error *err);

/* GL_LINEAR taps of img at texel coordinates (tx, ty), clamped to the edge: indices and weights. */
void asp__fit_bilinear(const asp_image *img, float tx, float ty, uint32_t idx[4], float wgt[4]);

/* Rasterises lv seen from view into rows (zeroed on entry; free with asp__fit_rows_release). */
int asp__fit_raster(const asp_dps_level *lv, const double origin[3], const asp_fit_view *view,
                    const asp_fit_draw *draw, const asp_context *ctx, asp__fit_rows *rows, asp_error *err);
void asp__fit_rows_release(asp__fit_rows *rows, const asp_context *ctx);

/* sRGB byte to linear light, and back (rounded, clamped). */
float asp__fit_srgb_to_linear(uint8_t v);
uint8_t asp__fit_linear_to_srgb(double v);

/* The atlas's colour in linear light, 3 floats per texel (allocated through ctx). */
float *asp__fit_atlas_linear(const asp_image *atlas, const asp_context *ctx);

/* Mean squared error of linear RGB over the pixels covered by rows and by ref (alpha > 0); *count pixels. */
double asp__fit_rows_loss(const asp__fit_rows *rows, const float *lin, const asp_image *ref, size_t *count);

/* A fit rewrites lv's texels: BC3 blocks of the old ones (asp_dps_level_compress) would go stale. */
static inline void asp__fit_drop_blocks(asp_dps_level *lv, const asp_context *ctx)
{
    asp_free(ctx, lv->atlas_bc3), asp_free(ctx, lv->normal_bc3);
    lv->atlas_bc3 = lv->normal_bc3 = NULL;
}

#endif
