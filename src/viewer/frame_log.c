/*
 * Every frame's figures in a viewer run (issue 18 item 5): the frame time the
 * user waits for, the drawing time, tau, the depth limit and the count, so a
 * scripted fly-through under a frame budget can be judged by its median and
 * spread (GSL quantiles) and read back from JSON (cJSON, atomic write).
 */
#include <math.h>
#include <string.h>

#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>

#include "util/json_file.h"
#include "viewer/internal.h"
#include "util/banned.h"

int asp__viewer_frame_log_add(asp__viewer_frame_log *log, const asp_context *ctx, const asp__viewer_frame *f,
                              asp_error *err)
{
    if (log->count == log->cap) {
        size_t cap = log->cap ? 2 * log->cap : 512;
        asp__viewer_frame *p = asp_realloc(ctx, log->frames, log->cap * sizeof *p, cap * sizeof *p);
        if (!p)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for the figures of %zu frames", cap);
        log->frames = p;
        log->cap = cap;
    }
    log->frames[log->count++] = *f;
    return 0;
}

void asp__viewer_frame_log_summary(const asp__viewer_frame_log *log, const asp_context *ctx, asp_viewer_stats *st)
{
    st->median_frame_ms = st->p10_frame_ms = st->p90_frame_ms = 0;
    st->tolerance_min = st->tolerance_max = 0;
    st->count_min = st->count_max = 0;
    size_t n = log->count;
    double *ms = n ? asp_alloc(ctx, n * sizeof *ms) : NULL;
    if (!ms)
        return;
    int have_tau = 0;
    st->count_min = SIZE_MAX;
    for (size_t i = 0; i < n; i++) {
        const asp__viewer_frame *f = &log->frames[i];
        ms[i] = f->frame_ms;
        st->count_min = f->count < st->count_min ? f->count : st->count_min;
        st->count_max = f->count > st->count_max ? f->count : st->count_max;
        if (isnan(f->tolerance))
            continue;
        st->tolerance_min = have_tau ? fminf(st->tolerance_min, f->tolerance) : f->tolerance;
        st->tolerance_max = have_tau ? fmaxf(st->tolerance_max, f->tolerance) : f->tolerance;
        have_tau = 1;
    }
    gsl_sort(ms, 1, n);
    st->median_frame_ms = gsl_stats_median_from_sorted_data(ms, 1, n);
    st->p10_frame_ms = gsl_stats_quantile_from_sorted_data(ms, 1, n, 0.1);
    st->p90_frame_ms = gsl_stats_quantile_from_sorted_data(ms, 1, n, 0.9);
    asp_free(ctx, ms);
}

/* A number rounded for reading (cJSON prints doubles with 17 digits otherwise). */
static cJSON *rounded(double x, double unit)
{
    return cJSON_CreateNumber(round(x / unit) * unit);
}

int asp__viewer_frame_log_save(const asp__viewer_frame_log *log, const asp_viewer_stats *st,
                               const asp_viewer_desc *d, const char *input, const char *path, asp_error *err)
{
    cJSON *root = cJSON_CreateObject(), *frames = cJSON_CreateArray();
    if (!root || !frames) {
        cJSON_Delete(frames);
        return asp__json_save(NULL, path, err);
    }
    cJSON_AddStringToObject(root, "input", input);
    cJSON_AddStringToObject(root, "renderer", st->renderer);
    cJSON_AddStringToObject(root, "gl_renderer", st->gl_renderer);
    cJSON_AddNumberToObject(root, "width", st->width);
    cJSON_AddNumberToObject(root, "height", st->height);
    if (d->frame_ms > 0)
        cJSON_AddNumberToObject(root, "budget_ms", d->frame_ms);
    else
        cJSON_AddNullToObject(root, "budget_ms");
    cJSON_AddBoolToObject(root, "budget_applied", st->budget_applied);
    cJSON_AddBoolToObject(root, "fly", d->fly != 0);
    cJSON_AddNumberToObject(root, "frames", (double)log->count);
    cJSON_AddItemToObject(root, "median_frame_ms", rounded(st->median_frame_ms, 1e-3));
    cJSON_AddItemToObject(root, "p10_frame_ms", rounded(st->p10_frame_ms, 1e-3));
    cJSON_AddItemToObject(root, "p90_frame_ms", rounded(st->p90_frame_ms, 1e-3));
    cJSON_AddItemToObject(root, "mean_draw_ms", rounded(st->mean_frame_ms, 1e-3));
    cJSON_AddItemToObject(root, "tolerance_min", rounded(st->tolerance_min, 1e-4));
    cJSON_AddItemToObject(root, "tolerance_max", rounded(st->tolerance_max, 1e-4));
    cJSON_AddNumberToObject(root, "count_min", (double)st->count_min);
    cJSON_AddNumberToObject(root, "count_max", (double)st->count_max);
    for (size_t i = 0; i < log->count; i++) {
        const asp__viewer_frame *f = &log->frames[i];
        cJSON *o = cJSON_CreateObject();
        if (!o) {
            cJSON_Delete(frames);
            cJSON_Delete(root);
            return asp__json_save(NULL, path, err);
        }
        cJSON_AddItemToObject(o, "frame_ms", rounded(f->frame_ms, 1e-3));
        cJSON_AddItemToObject(o, "draw_ms", rounded(f->draw_ms, 1e-3));
        if (isnan(f->tolerance))
            cJSON_AddNullToObject(o, "tolerance");
        else
            cJSON_AddItemToObject(o, "tolerance", rounded(f->tolerance, 1e-4));
        cJSON_AddNumberToObject(o, "depth_limit", f->depth_limit);
        cJSON_AddNumberToObject(o, "count", (double)f->count);
        cJSON_AddItemToObject(o, "azimuth", rounded(f->azimuth, 1e-3));
        cJSON_AddItemToObject(o, "elevation", rounded(f->elevation, 1e-3));
        cJSON_AddItemToObject(o, "distance", rounded(f->distance, 1e-6));
        cJSON_AddItemToArray(frames, o);
    }
    cJSON_AddItemToObject(root, "per_frame", frames);
    return asp__json_save(root, path, err);
}

void asp__viewer_frame_log_release(asp__viewer_frame_log *log, const asp_context *ctx)
{
    asp_free(ctx, log->frames);
    memset(log, 0, sizeof *log);
}
