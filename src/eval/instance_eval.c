/*
 * Measuring a scene of instances (issue 18 item 4's `eval scene.json`): the
 * whole scene at full detail (blended splats at tau 0, seed 001 section 5) is
 * the reference; discs, splats at coarser screen tolerances (seed 001 5.1)
 * and squares (seed 004 3.2.6) are compared with it by the image metrics of
 * eval (PSNR, SSIM, silhouette IoU) and timed, as eval does for one model.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/instances.h"
#include "amgsplat/scene_renderer.h"
#include "util/json_file.h"
#include "util/banned.h"

void asp_instance_eval_result_destroy(asp_instance_eval_result *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->row_count; i++)
        asp_image_release(&r->rows[i].image);
    free(r->rows);
    free(r);
}

int asp_instance_eval_save_json(const asp_instance_eval_result *res, const char *scene, const char *path,
                                asp_error *err)
{
    cJSON *root = cJSON_CreateObject(), *rows = NULL;
    int ok = root && cJSON_AddStringToObject(root, "scene", scene) &&
             cJSON_AddStringToObject(root, "gl_renderer", res->gl_renderer_text) &&
             (rows = cJSON_AddArrayToObject(root, "rows"));
    for (size_t i = 0; ok && i < res->row_count; i++) {
        const asp_instance_eval_row *r = &res->rows[i];
        cJSON *o = cJSON_CreateObject();
        ok = o && cJSON_AddItemToArray(rows, o) && cJSON_AddStringToObject(o, "renderer", r->renderer) &&
             cJSON_AddNumberToObject(o, "tolerance", r->tolerance) &&
             cJSON_AddBoolToObject(o, "reference", i == 0) &&
             cJSON_AddNumberToObject(o, "primitives", (double)r->primitives) &&
             cJSON_AddNumberToObject(o, "instances_drawn", (double)r->instances_drawn) &&
             // JSON has no infinity: identical images have no finite PSNR
             (isfinite(r->psnr) ? cJSON_AddNumberToObject(o, "psnr", r->psnr) != NULL
                                : cJSON_AddNullToObject(o, "psnr") != NULL) &&
             cJSON_AddNumberToObject(o, "ssim", r->ssim) && cJSON_AddNumberToObject(o, "iou", r->iou) &&
             cJSON_AddNumberToObject(o, "frame_ms", r->frame_ms);
    }
    if (!ok) {
        cJSON_Delete(root);
        root = NULL; // reported as out of memory
    }
    return asp__json_save(root, path, err);
}

#ifndef ASP_HAVE_GL
int asp_instance_scene_eval(const asp_instance_scene *s, const asp_instance_eval_desc *desc, const asp_context *ctx,
                            asp_instance_eval_result **out, asp_error *err)
{
    (void)s, (void)desc, (void)ctx, (void)out;
    return asp_error_set(err, ASP_EUNSUPPORTED, "this amgsplat was built without OpenGL (ASP_WITH_GL=OFF)");
}
#else

enum { MAX_TOLERANCES = 32 };

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Renders row's configuration frames times; keeps the last image and the median time. */
static int measure(asp_gl_context *gl, const asp_instance_scene *s, const asp_instance_eval_desc *d,
                   const asp_context *ctx, asp_instance_eval_row *row, asp_error *err)
{
    asp_renderer_options o;
    if (d->options)
        o = *d->options;
    else
        memset(&o, 0, sizeof o);
    o.splat.tolerance = o.square.tolerance = row->tolerance;
    asp_renderer *r = NULL;
    int rc = asp_instance_scene_renderer_create(gl, s, row->renderer, &o, ctx, &r, err);
    if (rc)
        return rc;
    asp_camera cam;
    asp_instance_scene_camera(s, d->orbit, (float)d->width / (float)d->height, 40.0f, d->azimuth, d->elevation,
                              0.0f, &cam);
    asp_render_desc rd = {.width = d->width, .height = d->height, .samples = 1,
                          .background = {255, 255, 255, 255}};
    if (s->has_background)
        memcpy(rd.background, s->background, 4);
    double *ms = calloc(d->frames, sizeof *ms);
    if (!ms)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
    for (size_t f = 0; !rc && f < d->frames; f++) {
        asp_image_release(&row->image);
        double t0 = asp_time_now();
        rc = asp_render_to_image(gl, r, &cam, &rd, &row->image, err);
        ms[f] = 1e3 * (asp_time_now() - t0);
    }
    if (!rc) {
        qsort(ms, d->frames, sizeof *ms, cmp_double);
        row->frame_ms = ms[d->frames / 2];
        row->primitives = asp_renderer_count(r);
        row->instances_drawn = asp_scene_renderer_drawn(r);
    }
    free(ms);
    asp_renderer_destroy(r);
    return rc;
}

int asp_instance_scene_eval(const asp_instance_scene *s, const asp_instance_eval_desc *desc, const asp_context *ctx,
                            asp_instance_eval_result **out, asp_error *err)
{
    ASP_ASSERT(s && out);
    static const asp_instance_eval_desc zero;
    asp_instance_eval_desc d = desc ? *desc : zero;
    static const float default_tau[] = {1, 2, 4, 8};
    if (!d.tolerances) {
        d.tolerances = default_tau;
        d.tolerance_count = 4;
    }
    if (d.tolerance_count > MAX_TOLERANCES)
        return asp_error_set(err, ASP_EINVAL, "%zu tolerances, more than %d", d.tolerance_count, MAX_TOLERANCES);
    float largest = 0;
    for (size_t i = 0; i < d.tolerance_count; i++) {
        if (!(d.tolerances[i] >= 0) || !isfinite(d.tolerances[i]))
            return asp_error_set(err, ASP_EINVAL, "tolerance %g is not a finite number of pixels >= 0",
                                 (double)d.tolerances[i]);
        largest = fmaxf(largest, d.tolerances[i]);
    }
    d.width = d.width ? d.width : 256;
    d.height = d.height ? d.height : 256;
    d.frames = d.frames ? d.frames : 3;
    asp_instance_eval_result *res = calloc(1, sizeof *res);
    size_t nrows = 3 + d.tolerance_count;
    if (res)
        res->rows = calloc(nrows, sizeof *res->rows);
    if (!res || !res->rows) {
        asp_instance_eval_result_destroy(res);
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    }
    res->row_count = nrows;
    // the reference first, then every point, the tolerances, and the cheapest at the coarsest
    snprintf(res->rows[0].renderer, sizeof res->rows[0].renderer, "splat");
    snprintf(res->rows[1].renderer, sizeof res->rows[1].renderer, "disc");
    for (size_t i = 0; i < d.tolerance_count; i++) {
        snprintf(res->rows[2 + i].renderer, sizeof res->rows[2 + i].renderer, "splat");
        res->rows[2 + i].tolerance = d.tolerances[i];
    }
    snprintf(res->rows[nrows - 1].renderer, sizeof res->rows[nrows - 1].renderer, "square");
    res->rows[nrows - 1].tolerance = largest > 0 ? largest : 1.0f;

    asp_gl_context *gl = NULL;
    int rc = asp_gl_context_create_headless(NULL, ctx, &gl, err);
    if (!rc)
        snprintf(res->gl_renderer_text, sizeof res->gl_renderer_text, "%s", asp_gl_context_renderer(gl));
    res->gl_renderer = res->gl_renderer_text;
    static const uint8_t white[3] = {255, 255, 255};
    for (size_t i = 0; !rc && i < nrows; i++) {
        asp_instance_eval_row *row = &res->rows[i];
        rc = measure(gl, s, &d, ctx, row, err);
        if (!rc)
            rc = asp_image_psnr(&res->rows[0].image, &row->image, &row->psnr, err);
        if (!rc)
            rc = asp_image_ssim(&res->rows[0].image, &row->image, &row->ssim, err);
        if (!rc)
            rc = asp_image_silhouette_iou(&res->rows[0].image, &row->image,
                                          s->has_background ? s->background : white, &row->iou, err);
        if (!rc)
            rc = asp_progress(ctx, "eval", (double)(i + 1) / (double)nrows);
    }
    asp_gl_context_destroy(gl);
    if (rc) {
        asp_instance_eval_result_destroy(res);
        return rc;
    }
    *out = res;
    return 0;
}
#endif
