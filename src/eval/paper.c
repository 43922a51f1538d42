/*
 * The seeds' tables measured on our pipeline: journal Table 1 (pre-processing
 * times) and Table 2 / thesis Table 5.2 (per level: polygons, texels, error,
 * times, frame rates at three screen sizes), thesis Table 5.3 (frame rate of
 * points against domain primitives) and Table 5.4 (construction time per
 * texture method and texel size 2, 1, 0.5).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/hier.h"
#include "amgsplat/render.h"
#include "util/banned.h"

void asp_eval_paper_destroy(asp_eval_paper *p)
{
    if (!p)
        return;
    asp_context ctx = p->ctx;
    asp_free(&ctx, p->levels);
    asp_free(&ctx, p);
}

enum { MAX_SIZES = 8, MAX_FRAMES = 1000 };

#ifdef ASP_HAVE_GL
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/*
 * Frames per second of r: median of frames finished frames, the model filling
 * a square view of side size (journal Table 2 measures at 128, 256 and 512).
 */
static int fps(asp_gl_context *gl, asp_renderer *r, const asp_frame *frame, const double origin[3], uint32_t size,
               size_t frames, double *out, asp_error *err)
{
    asp_camera cam;
    asp_camera_init(&cam);
    cam.up = frame->up;
    cam.azimuth = 30;
    cam.elevation = 20;
    asp_camera_frame(&cam, frame, origin, 1.0f, 0.0f); // the one framing of render, view and eval
    asp_render_desc rd = {.width = size, .height = size, .flags = ASP_RENDER_WAIT};
    double t[MAX_FRAMES];
    int rc = asp_render_frame(gl, r, &cam, &rd, err); // warm-up: uploads, shader compilation
    for (size_t i = 0; !rc && i < frames; i++) {
        double t0 = asp_time_now();
        rc = asp_render_frame(gl, r, &cam, &rd, err);
        t[i] = asp_time_now() - t0;
    }
    if (rc)
        return rc;
    qsort(t, frames, sizeof *t, cmp_double);
    double med = frames % 2 ? t[frames / 2] : 0.5 * (t[frames / 2 - 1] + t[frames / 2]);
    *out = med > 0 ? 1.0 / med : INFINITY;
    return 0;
}

static int frame_rates(const asp_cloud *cloud, const asp_dps *dps, asp_eval_paper *p, size_t frames,
                       const asp_context *ctx, asp_error *err)
{
    asp_gl_context *gl = NULL;
    asp_renderer *r = NULL;
    asp_frame frame;
    int rc = asp_cloud_frame(cloud, &frame, err);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, ctx, &gl, err);
    if (!rc) {
        snprintf(p->gl_renderer, sizeof p->gl_renderer, "%s", asp_gl_context_renderer(gl));
        // thesis 5.2.3: the points drawn as splats, the full set (QSplat at its finest)
        rc = asp_splat_renderer_create(gl, cloud, NULL, ctx, &r, err);
    }
    for (size_t i = 0; !rc && i < p->size_count; i++)
        rc = fps(gl, r, &frame, cloud->origin, p->sizes[i], frames, &p->fps_points[i], err);
    asp_renderer_destroy(r);
    r = NULL;
    // thesis 5.2.3 measures "the overlapping domains method"
    snprintf(p->fps_method, sizeof p->fps_method, "%s", asp_prim_render_method_name(ASP_PRIM_RENDER_OVERLAP));
    for (size_t l = 0; !rc && l < p->level_count; l++) {
        const asp_dps_level *lv = &dps->levels[dps->level_count - 1 - l];
        asp_prim_renderer_desc pd = {.options = {.method = ASP_PRIM_RENDER_OVERLAP}};
        memcpy(pd.origin, cloud->origin, sizeof pd.origin);
        rc = asp_prim_renderer_create(gl, lv, &pd, &r, err);
        for (size_t i = 0; !rc && i < p->size_count; i++)
            rc = fps(gl, r, &frame, cloud->origin, p->sizes[i], frames, &p->levels[l].fps[i], err);
        asp_renderer_destroy(r);
        r = NULL;
    }
    asp_gl_context_destroy(gl);
    return rc;
}
#else
static int frame_rates(const asp_cloud *cloud, const asp_dps *dps, asp_eval_paper *p, size_t frames,
                       const asp_context *ctx, asp_error *err)
{
    (void)cloud, (void)dps, (void)p, (void)frames, (void)ctx, (void)err;
    return 0; // frame rates stay NAN: this build cannot render
}
#endif

/* Thesis Table 5.4: dpc seconds of one level per texture method, at texel sizes 2, 1 and 0.5. */
static int texture_methods(const asp_amg *amg, const asp_cloud *cloud, size_t level, const asp_prim_desc *base,
                           const asp_context *ctx, asp_eval_paper *p, asp_error *err)
{
    static const double texel[3] = {2, 1, 0.5};
    for (int t = 0; t < 3; t++) {
        p->t54_texel_size[t] = texel[t];
        for (int m = 0; m < 4; m++) {
            asp_prim_desc pd = base ? *base : (asp_prim_desc){0};
            pd.texel_size = texel[t];
            pd.method = m == 3 ? ASP_PRIM_AFFINE : ASP_PRIM_RADIAL;
            pd.shape = m == 0 ? ASP_PRIM_CONSTANT : m == 2 ? ASP_PRIM_GAUSSIAN : ASP_PRIM_LINEAR;
            asp_dps *dps = NULL;
            int rc = asp_prim_build(amg, cloud, &level, 1, &pd, NULL, ctx, &dps, err);
            if (rc)
                return rc;
            p->t54_seconds[t][m] = dps->levels[0].t_construct;
            if (m == 3)
                p->t54_texels[t] = dps->levels[0].texels;
            asp_dps_destroy(dps);
            if ((rc = asp_progress(ctx, "texture methods", (t * 4 + m + 1) / 12.0)))
                return rc;
        }
    }
    return 0;
}

static int check_desc(const asp_eval_paper_desc *d, asp_error *err)
{
    if (d->sizes && (d->size_count == 0 || d->size_count > MAX_SIZES))
        return asp_error_set(err, ASP_EINVAL, "expected 1..%d screen sizes, got %zu", MAX_SIZES, d->size_count);
    for (size_t i = 0; d->sizes && i < d->size_count; i++)
        if (d->sizes[i] < 16 || d->sizes[i] > 4096)
            return asp_error_set(err, ASP_EINVAL, "screen size %u is outside 16..4096", d->sizes[i]);
    if (d->frames > MAX_FRAMES)
        return asp_error_set(err, ASP_EINVAL, "frames must be at most %d, got %zu", MAX_FRAMES, d->frames);
    return 0;
}

int asp_eval_paper_run(const asp_cloud *cloud, const asp_eval_paper_desc *desc, const asp_context *ctx,
                       asp_eval_paper **out,
                       asp_error *err)
{
    asp_eval_paper_desc d = desc ? *desc : (asp_eval_paper_desc){0};
    int rc = check_desc(&d, err);
    if (rc)
        return rc;
    asp_eval_paper *p = asp_calloc(ctx, 1, sizeof *p);
    if (!p)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the tables");
    if (ctx)
        p->ctx = *ctx;
    static const uint32_t default_sizes[3] = {128, 256, 512};
    p->size_count = d.sizes ? d.size_count : 3;
    memcpy(p->sizes, d.sizes ? d.sizes : default_sizes, p->size_count * sizeof *p->sizes);
    for (size_t i = 0; i < MAX_SIZES; i++)
        p->fps_points[i] = NAN;
    for (int t = 0; t < 3; t++)
        for (int m = 0; m < 4; m++)
            p->t54_seconds[t][m] = NAN;
    p->points = cloud->count;

    double t0 = asp_time_now();
    asp_amg *amg = NULL;
    asp_dps *dps = NULL;
    rc = asp_amg_decompose(cloud, d.amg, ctx, &amg, err);
    p->t_decompose = asp_time_now() - t0;
    size_t levels[64], n = 0, budget_level = 0, max = d.max_primitives ? d.max_primitives : 2000;
    if (!rc)
        rc = asp_prim_level_for_budget(amg, d.budget ? d.budget : 500, &budget_level, err);
    if (!rc) {
        for (size_t l = 1; l < asp_amg_level_count(amg) && n < 63; l++)
            if (asp_amg_level_size(amg, l) <= max || l == budget_level)
                levels[n++] = l;
        rc = asp_prim_build(amg, cloud, levels, n, d.prim, NULL, ctx, &dps, err);
    }
    if (!rc) {
        p->level_count = dps->level_count;
        p->levels = asp_calloc(ctx, p->level_count, sizeof *p->levels);
        if (!p->levels)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu table rows", p->level_count);
    }
    if (!rc) {
        asp_dps_summary rows[64];
        if (asp_dps_summarize(dps, rows, 64) > 64) // AMG hierarchies stop far below 64 levels
            rc = asp_error_set(err, ASP_EUNSUPPORTED, "%zu levels, at most 64 are tabulated", dps->level_count);
    }
    if (!rc) {
        asp_dps_summary rows[64];
        asp_dps_summarize(dps, rows, 64);
        p->budget_level = 0;
        for (size_t l = 0; l < p->level_count; l++) {
            // the thesis lists the coarsest level first
            const asp_dps_summary *s = &rows[dps->level_count - 1 - l];
            asp_eval_paper_level *pl = &p->levels[l];
            pl->level = s->level;
            snprintf(pl->name, sizeof pl->name, "%s", s->name);
            pl->primitives = s->primitives;
            pl->texels = s->texels;
            pl->error = s->error;
            pl->error_norm = s->error_norm;
            pl->t_basis = s->t_basis;
            pl->t_construct = s->t_construct;
            for (size_t i = 0; i < MAX_SIZES; i++)
                pl->fps[i] = NAN;
            if (s->level == budget_level)
                p->budget_level = l;
        }
        rc = frame_rates(cloud, dps, p, d.frames ? d.frames : 10, ctx, err);
    }
    if (!rc && !d.skip_texture_methods)
        rc = texture_methods(amg, cloud, p->levels[p->budget_level].level, d.prim, ctx, p, err);
    asp_dps_destroy(dps);
    asp_amg_destroy(amg);
    if (rc) {
        asp_eval_paper_destroy(p);
        return rc;
    }
    *out = p;
    return 0;
}
