/*
 * Fitting domain primitives to images (issue 27): the textures of a .dps level
 * (journal section 3, thesis 3.3) are projections of their domains' points;
 * here they are optimised so that the level drawn by the default normalized
 * method (Pajarola et al. 2003 sections 5.3-5.4, docs/render-methods.md)
 * matches reference images of the source from views spread over the sphere.
 * With geometry and alpha fixed the normalised blend is linear in the colour
 * texels, so colour is a regularised linear least-squares problem solved by
 * conjugate gradients on the normal equations.
 *
 * Layering: the CPU parts (views, rasteriser, solve) need no GL and build
 * everywhere; asp_fit_run renders the references with the GL renderers and
 * needs an ASP_HAVE_GL build (ASP_EUNSUPPORTED otherwise).
 */
#ifndef AMGSPLAT_FIT_H
#define AMGSPLAT_FIT_H

#include "image.h"
#include "mesh.h"
#include "prim.h"
#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One camera of a fit, in the renderer's frame (world minus the fit's origin). */
typedef struct asp_fit_view {
    float view[16];          /* world (minus origin) to eye, column-major (asp_camera_view_matrix) */
    float proj[16];          /* symmetric perspective, column-major (asp_camera_projection_matrix) */
    uint32_t width, height;  /* pixels */
    float light[3];          /* unit light direction in eye space (0, 0, 1 = headlight) */
} asp_fit_view;

/** How the level is drawn; the zero value is the prim renderer's default (normalized, lit). */
typedef struct asp_fit_draw {
    float alpha_ref;         /* front-layer alpha test (0 = 0.1, as asp_prim_render_options) */
    float depth_window;      /* world units (0 = half the mean primitive radius sqrt(half_u half_v)) */
    int unlit;               /* 1: colour without shading (ASP_RENDER_UNLIT) */
} asp_fit_draw;

/**
 * Draws lv on the CPU exactly as the normalized method draws it without
 * crease clipping (crease_angle < 0): per pixel centre, the front-most
 * front-facing fragment with bilinear alpha > alpha_ref fixes the front depth,
 * and every front-facing fragment with alpha > 0 within depth_window behind it
 * along the eye ray adds (shade(colour) alpha, alpha); the pixel is the ratio,
 * sRGB-encoded, alpha 255 (0 and black where nothing is in front). Texture
 * lookups are bilinear on the sRGB-decoded atlas with clamped edges
 * (GL_LINEAR, GL_CLAMP_TO_EDGE). origin is the frame the view's matrices use.
 * *out must be zeroed or released; it is initialised here. Returns 0,
 * ASP_EINVAL (empty level, zero size), ASP_ENOMEM. Thread-safe.
 */
int asp_fit_render_cpu(const asp_dps_level *lv, const double origin[3], const asp_fit_view *view,
                       const asp_fit_draw *draw, asp_image *out, asp_error *err);

/**
 * Directions spread evenly over the sphere (a Fibonacci lattice, rotated about
 * the up axis by an angle drawn from seed): writes n azimuths and elevations in
 * degrees (asp_camera conventions). Pure.
 */
void asp_fit_directions(size_t n, uint64_t seed, float *azimuth, float *elevation);

/** A line of progress (the loss per iteration); the CLI prints it on stderr. */
typedef void (*asp_fit_log_fn)(void *user, const char *line);

/** Options of a fit; the zero value means the documented defaults. */
typedef struct asp_fit_desc {
    size_t views;            /* training views (0 = 64) */
    size_t holdout;          /* held-out views, another lattice, for the report (0 = 16) */
    uint32_t size;           /* image side, pixels (0 = 128: a few hundred primitives cover 10-40 px each) */
    uint32_t iterations;     /* conjugate-gradient iterations (0 = 60) */
    uint64_t seed;           /* rotates the view lattices (0 = 1) */
    double lambda;           /* weight of ||c - c0||^2, relative to the mean data weight per seen texel (0 = 0.1) */
    double smooth;           /* weight of the squared differences of neighbouring texels' corrections, same
                                scale (0 = 4; < 0 = none; bunny 351 primitives at 256 px: 0.5 lost
                                SSIM to the unfitted level on 13 of 16 held-out views, 4 won all 16) */
    uint64_t texels;         /* asp_fit_run: texel budget of the level (asp_fit_budget) before fitting; 0 = keep */
    size_t bytes;            /* asp_fit_run: GPU-byte budget (asp_dps_level_gpu_bytes); 0 = keep */
    int alpha_rounds;        /* asp_fit_run: silhouette rounds of asp_fit_alpha before the colour (0 = 8; < 0 = none) */
    double alpha_step;       /* largest alpha change of a texel per round (0 = 0.08) */
    int uncompressed;        /* asp_fit_run: 1 = keep the atlases RGBA8; 0 = store them as BC3 blocks after
                                fitting (asp_dps_level_compress; 1 byte a texel, and the budget counts so) */
    asp_fit_draw draw;
    asp_fit_log_fn log;      /* NULL = silent */
    void *log_user;
} asp_fit_desc;

/** What a fit did; losses are mean squared errors of linear RGB over pixels covered in both images. */
typedef struct asp_fit_stats {
    double train_before, train_after;
    double holdout_before, holdout_after;
    double ssim_before, ssim_after;   /* asp_fit_run: mean SSIM of the GL renders on the held-out views */
    size_t silhouette_before, silhouette_after; /* asp_fit_run: training pixels covered by only one of level
                                                   and reference, before and after asp_fit_alpha */
    size_t texels_seen;               /* texels with data */
    size_t pixels;                    /* covered training pixels */
    uint32_t iterations;
    double seconds;                   /* asp_fit_color: the solve; asp_fit_run: the whole call */
} asp_fit_stats;

/**
 * Fits the colour texels of lv (its atlas is rewritten, BC3 blocks dropped; geometry, alpha and the
 * normal atlas are unchanged) to reference images refs[0 .. nviews-1] (RGBA8
 * sRGB, each of views[i]'s size; pixels with alpha 0 are background and not
 * fitted) seen from views (origin as for asp_fit_render_cpu): minimises
 * sum over pixels covered by both of |blend(c) - ref|^2 in linear light plus
 * lambda |c - c0|^2 + smooth |grad (c - c0)|^2 (c0 the unfitted texels; the
 * gradient between 4-neighbours of one primitive's texture), by conjugate
 * gradients. Texels no view sees keep their value. holdout/href (nholdout, may
 * be 0) only measure. Deterministic for any thread count. stats may be NULL.
 * Returns 0, ASP_EINVAL (a reference of the wrong size, no views),
 * ASP_ENOMEM, ASP_ECANCELED (progress callback). Reports progress "fit".
 */
int asp_fit_color(asp_dps_level *lv, const double origin[3], const asp_fit_view *views, const asp_image *refs,
                  size_t nviews, const asp_fit_view *holdout, const asp_image *href, size_t nholdout,
                  const asp_fit_desc *desc, const asp_context *ctx, asp_fit_stats *stats, asp_error *err);

/**
 * Fits the alpha texels of lv (BC3 blocks dropped) to the silhouettes of refs (alpha > 0 = the
 * reference covers the pixel) seen from views, in desc->alpha_rounds rounds
 * of votes (src/fit/alpha_fit.c says how): texels near the silhouette move by
 * at most desc->alpha_step per round, so the alpha-tested outline grows where
 * the reference is and shrinks where it is not; alpha no vote reaches (inside
 * the surface) is unchanged. Colour, geometry and the normal atlas are not
 * touched. Writes the pixels covered by only one of the two, summed over the
 * views, before and after (either may be NULL). Deterministic for any thread
 * count. Returns 0, ASP_EINVAL, ASP_ENOMEM, ASP_ECANCELED; on failure the
 * alpha is as it was.
 */
int asp_fit_alpha(asp_dps_level *lv, const double origin[3], const asp_fit_view *views, const asp_image *refs,
                  size_t nviews, const asp_fit_desc *desc, const asp_context *ctx, size_t *mismatch_before,
                  size_t *mismatch_after, asp_error *err);

/**
 * The texel budget: scales every texture of lv by one factor (aspect kept, at
 * least 4x4, never up), the largest for which the level holds at most texels
 * texels and at most bytes GPU bytes (asp_dps_level_gpu_bytes; either 0 = no
 * limit; bc3 = 1: the bytes the level will have once compressed, as asp_fit_run
 * does after fitting, so 1 byte a texel, the atlas height rounded up to 4),
 * then resamples them (asp_dps_level_resize, pad texels of padding).
 * Fit afterwards: the budget decides the resolution, the fit the texels.
 * Returns 0, ASP_EINVAL (no budget, or one below 4x4 texels a primitive),
 * ASP_EUNSUPPORTED, ASP_ENOMEM.
 */
int asp_fit_budget(asp_dps_level *lv, uint64_t texels, size_t bytes, uint32_t pad, int bc3, const asp_context *ctx,
                   asp_error *err);

/** The source a fit matches: a mesh (its own render) or a point set (its blended splats). */
typedef struct asp_fit_reference {
    const asp_mesh *mesh;    /* drawn by the mesh renderer; or NULL */
    const asp_cloud *cloud;  /* drawn as splats at tolerance 0 when mesh is NULL */
} asp_fit_reference;

/**
 * The whole fit of dps->levels[level]: desc->views training cameras and
 * desc->holdout held-out cameras (asp_fit_directions, framed on dps->frame as
 * asp_camera_frame frames every representation), reference images of ref
 * rendered through gl (current on this thread), then the texel budget
 * (asp_fit_budget, when desc->texels or desc->bytes), asp_fit_alpha (unless
 * desc->alpha_rounds < 0) and asp_fit_color. ssim_before is the level as given. The held-out SSIM of
 * the GL renders before and after go to stats. Needs GL (ASP_EUNSUPPORTED
 * "built without GL" otherwise); errors as asp_fit_color, ASP_EGL.
 */
int asp_fit_run(asp_gl_context *gl, asp_dps *dps, size_t level, const asp_fit_reference *ref, const asp_fit_desc *desc,
                const asp_context *ctx, asp_fit_stats *stats, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
