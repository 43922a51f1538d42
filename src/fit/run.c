/*
 * The whole fit of one level (issue 27): cameras on two Fibonacci lattices
 * (training, held-out) framed as every representation is framed
 * (asp_camera_frame), the reference images drawn by the GL renderers (the
 * mesh's own render, or the full point set's blended splats at tolerance 0,
 * seed 001 section 5), the colour solve, and the held-out SSIM of the level as
 * the default renderer draws it before and after.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/scene.h"
#include "fit/internal.h"
#include "util/banned.h"

#ifndef ASP_HAVE_GL

int asp_fit_run(asp_gl_context *gl, asp_dps *dps, size_t level, const asp_fit_reference *ref,
                const asp_fit_desc *desc, const asp_context *ctx, asp_fit_stats *stats, asp_error *err)
{
    (void)gl, (void)dps, (void)level, (void)ref, (void)desc, (void)ctx, (void)stats;
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot fit: built without GL (reference images need it)");
}

#else

/* The frame to view the level in: the file's, else the primitives' bounding sphere. */
static asp_frame level_frame(const asp_dps *dps, const asp_dps_level *lv)
{
    if (dps->frame.radius > 0)
        return dps->frame;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < lv->prim_count; i++)
        for (int a = 0; a < 3; a++)
            lo[a] = fmin(lo[a], lv->prims[i].centre[a]), hi[a] = fmax(hi[a], lv->prims[i].centre[a]);
    asp_frame f = {.center = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])}};
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        double d2 = 0;
        for (int a = 0; a < 3; a++)
            d2 += (p->centre[a] - f.center[a]) * (p->centre[a] - f.center[a]);
        f.radius = fmax(f.radius, sqrt(d2) + hypot(p->half_u, p->half_v));
    }
    return f;
}

static void make_views(size_t n, uint64_t seed, uint32_t size, const asp_frame *frame, const double origin[3],
                       asp_camera *cams, asp_fit_view *views)
{
    float az[256], el[256];
    asp_fit_directions(n, seed, az, el);
    for (size_t i = 0; i < n; i++) {
        asp_camera_init(&cams[i]);
        cams[i].azimuth = az[i];
        cams[i].elevation = el[i];
        asp_camera_frame(&cams[i], frame, origin, 1.0f, 0.0f);
        asp_camera_view_matrix(&cams[i], views[i].view);
        asp_camera_projection_matrix(&cams[i], views[i].proj);
        views[i].width = views[i].height = size;
        // render_image.c: the light at azimuth 0, elevation 0 relative to the view is the headlight
        views[i].light[0] = 0, views[i].light[1] = 0, views[i].light[2] = 1;
    }
}

static int reference_renderer(asp_gl_context *gl, const asp_fit_reference *ref, const double origin[3],
                              const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    const asp_renderer_kind *kind = NULL;
    asp_render_source src = {0};
    memcpy(src.origin, origin, sizeof src.origin);
    if (ref->mesh) {
        int rc = asp_renderer_kind_find("mesh", 0, &kind, err);
        if (rc)
            return rc;
        asp_render_material *mats = asp_calloc(ctx, ref->mesh->material_count + 1, sizeof *mats);
        if (!mats)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu materials", ref->mesh->material_count);
        asp_render_mesh rm;
        asp_scene_mesh_describe(ref->mesh, mats, &rm);
        src.mesh = &rm;
        rc = kind->create(gl, &src, NULL, ctx, out, err);
        asp_free(ctx, mats);
        return rc;
    }
    int rc = asp_renderer_kind_find("splat", 0, &kind, err);
    if (rc)
        return rc;
    src.cloud = ref->cloud;
    rc = kind->create(gl, &src, NULL, ctx, out, err);
    if (!rc)
        rc = asp_renderer_set_lod(*out, 0.0f, 0, err); // every point: the reference of eval
    return rc;
}

static int render_all(asp_gl_context *gl, asp_renderer *r, const asp_camera *cams, size_t n, uint32_t size,
                      asp_image *out, asp_error *err)
{
    asp_render_desc rd = {.width = size, .height = size};
    for (size_t v = 0; v < n; v++) {
        int rc = asp_render_to_image(gl, r, &cams[v], &rd, &out[v], err);
        if (rc)
            return rc;
    }
    return 0;
}

/* Mean SSIM of the level drawn by the default prim renderer against refs. */
static int level_ssim(asp_gl_context *gl, const asp_dps_level *lv, const double origin[3], const asp_camera *cams,
                      const asp_image *refs, size_t n, uint32_t size, const asp_context *ctx, double *mean,
                      asp_error *err)
{
    const asp_renderer_kind *kind = NULL;
    asp_renderer *r = NULL;
    asp_render_source src = {.level = lv};
    memcpy(src.origin, origin, sizeof src.origin);
    int rc = asp_renderer_kind_find("prim", 0, &kind, err);
    if (!rc)
        rc = kind->create(gl, &src, NULL, ctx, &r, err);
    double sum = 0;
    asp_render_desc rd = {.width = size, .height = size};
    for (size_t v = 0; v < n && !rc; v++) {
        asp_image img = {0};
        double s = 0;
        rc = asp_render_to_image(gl, r, &cams[v], &rd, &img, err);
        if (!rc)
            rc = asp_image_ssim(&img, &refs[v], &s, err);
        sum += s;
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    *mean = n ? sum / (double)n : 0.0;
    return rc;
}

int asp_fit_run(asp_gl_context *gl, asp_dps *dps, size_t level, const asp_fit_reference *ref,
                const asp_fit_desc *desc_in, const asp_context *ctx, asp_fit_stats *stats, asp_error *err)
{
    double t0 = asp_time_now();
    asp_fit_desc desc = desc_in ? *desc_in : (asp_fit_desc){0};
    size_t nv = desc.views ? desc.views : 64, nh = desc.holdout ? desc.holdout : 16;
    uint32_t size = desc.size ? desc.size : 128;
    uint64_t seed = desc.seed ? desc.seed : 1;
    if (!gl || !dps || !ref || (!ref->mesh && !ref->cloud))
        return asp_error_set(err, ASP_EINVAL, "cannot fit: no GL context, file or reference");
    if (level >= dps->level_count)
        return asp_error_set(err, ASP_EINVAL, "cannot fit: no level %zu (the file has %zu)", level,
                             dps->level_count);
    if (nv > 256 || nh > 256 || size > 4096)
        return asp_error_set(err, ASP_EINVAL, "cannot fit: at most 256 views of 4096 px (got %zu + %zu of %u)", nv,
                             nh, size);
    asp_dps_level *lv = &dps->levels[level];
    asp_frame frame = level_frame(dps, lv);
    double origin[3];
    // points are drawn in their cloud's frame (the splat renderer's own origin); meshes and primitives anywhere
    memcpy(origin, ref->mesh ? frame.center : ref->cloud->origin, sizeof origin);
    size_t n = nv + nh;
    asp_camera *cams = asp_calloc(ctx, n, sizeof *cams);
    asp_fit_view *views = asp_calloc(ctx, n, sizeof *views);
    asp_image *refs = asp_calloc(ctx, n, sizeof *refs);
    asp_renderer *r = NULL;
    int rc = 0;
    if (!cams || !views || !refs) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu views", n);
        goto done;
    }
    make_views(nv, seed, size, &frame, origin, cams, views);
    make_views(nh, seed + 0x51ed27, size, &frame, origin, cams + nv, views + nv);
    rc = reference_renderer(gl, ref, origin, ctx, &r, err);
    if (!rc)
        rc = render_all(gl, r, cams, n, size, refs, err);
    asp_renderer_destroy(r);
    double ssim_before = 0, ssim_after = 0;
    if (!rc)
        rc = level_ssim(gl, lv, origin, cams + nv, refs + nv, nh, size, ctx, &ssim_before, err);
    asp_fit_stats st = {0};
    size_t sil_before = 0, sil_after = 0;
    if (!rc && (desc.texels || desc.bytes))
        rc = asp_fit_budget(lv, desc.texels, desc.bytes, dps->desc.padding ? dps->desc.padding : 2,
                            !desc.uncompressed, ctx, err);
    if (!rc) // refitting a compressed level: its texels change, the blocks go stale
        asp__fit_drop_blocks(lv, ctx);
    if (!rc && desc.alpha_rounds >= 0)
        rc = asp_fit_alpha(lv, origin, views, refs, nv, &desc, ctx, &sil_before, &sil_after, err);
    if (!rc)
        rc = asp_fit_color(lv, origin, views, refs, nv, views + nv, refs + nv, nh, &desc, ctx, &st, err);
    if (!rc && !desc.uncompressed) // after the solve: held-out SSIM is then of the BC3 texels the GPU samples
        rc = asp_dps_level_compress(lv, ctx, err);
    if (!rc)
        rc = level_ssim(gl, lv, origin, cams + nv, refs + nv, nh, size, ctx, &ssim_after, err);
    if (!rc) {
        st.ssim_before = ssim_before, st.ssim_after = ssim_after;
        st.silhouette_before = sil_before, st.silhouette_after = sil_after;
        st.seconds = asp_time_now() - t0; // the whole fit: references, budget, alpha, colour, the SSIM renders
        if (stats)
            *stats = st;
    }
done:
    for (size_t v = 0; refs && v < n; v++)
        asp_image_release(&refs[v]);
    asp_free(ctx, cams), asp_free(ctx, views), asp_free(ctx, refs);
    return rc;
}

#endif
