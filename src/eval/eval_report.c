/*
 * Writing an evaluation: CSV and JSON tables and the two charts of issue 7
 * (quality and frame time against primitive count, the trade-off of thesis
 * Fig. 1.1 and journal Table 2). Files appear atomically.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "amgsplat/eval.h"
#include "util/atomic_file.h"
#include "util/json_file.h"
#include "util/banned.h"

/*
 * A JSON number holding v as printf(fmt, v) writes it, so the file keeps the
 * digits the CSV has; null for NaN and infinities, which JSON cannot hold.
 */
static cJSON *num(double v, const char *fmt)
{
    char text[64];
    if (!isfinite(v))
        return cJSON_CreateNull();
    snprintf(text, sizeof text, fmt, v);
    return cJSON_CreateNumber(strtod(text, NULL));
}

static const char csv_header[] = "representation,level,level_name,size,primitives,drawn,texels,psnr_mean,psnr_min,"
                                 "ssim_mean,ssim_min,iou_mean,iou_min,frame_ms,bytes,note\n";

/* A CSV number; NaN (a row without figures, asp_eval_row.note) is an empty field. */
static void csv_num(FILE *fp, double v, const char *fmt)
{
    fputc(',', fp);
    if (!isnan(v))
        fprintf(fp, fmt, v);
}

int asp_eval_save_csv(const asp_eval_result *res, const char *path, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    fputs(csv_header, f.fp);
    for (size_t i = 0; i < res->row_count; i++) {
        const asp_eval_row *r = &res->rows[i];
        fprintf(f.fp, "%s,%u,%s,%u,%zu,%.1f,%llu", r->representation, r->level, r->level_name, r->size, r->primitives,
                r->drawn, (unsigned long long)r->texels);
        csv_num(f.fp, r->psnr_mean, "%.4f");
        csv_num(f.fp, r->psnr_min, "%.4f");
        csv_num(f.fp, r->ssim_mean, "%.6f");
        csv_num(f.fp, r->ssim_min, "%.6f");
        csv_num(f.fp, r->iou_mean, "%.6f");
        csv_num(f.fp, r->iou_min, "%.6f");
        csv_num(f.fp, r->frame_ms, "%.4f");
        fprintf(f.fp, ",%llu,%s\n", (unsigned long long)r->bytes, r->note);
    }
    return asp__atomic_commit(&f, err);
}

static cJSON *row_json(const asp_eval_result *res, size_t i)
{
    const asp_eval_row *r = &res->rows[i];
    cJSON *o = cJSON_CreateObject(), *ssim = cJSON_CreateArray(), *psnr = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "representation", r->representation);
    cJSON_AddNumberToObject(o, "level", r->level);
    cJSON_AddStringToObject(o, "level_name", r->level_name);
    cJSON_AddNumberToObject(o, "size", r->size);
    cJSON_AddNumberToObject(o, "primitives", (double)r->primitives);
    cJSON_AddItemToObject(o, "drawn", num(r->drawn, "%.1f"));
    cJSON_AddNumberToObject(o, "texels", (double)r->texels);
    cJSON_AddNumberToObject(o, "bytes", (double)r->bytes);
    cJSON_AddStringToObject(o, "note", r->note);
    const char *names[7] = {"psnr_mean", "psnr_min", "ssim_mean", "ssim_min", "iou_mean", "iou_min", "frame_ms"};
    const double vals[7] = {r->psnr_mean, r->psnr_min, r->ssim_mean, r->ssim_min, r->iou_mean, r->iou_min, r->frame_ms};
    for (int k = 0; k < 7; k++)
        cJSON_AddItemToObject(o, names[k], num(vals[k], "%.6g"));
    for (size_t v = 0; v < res->views; v++) {
        cJSON_AddItemToArray(ssim, num(res->ssim[i * res->views + v], "%.6f"));
        cJSON_AddItemToArray(psnr, num(res->psnr[i * res->views + v], "%.4f"));
    }
    cJSON_AddItemToObject(o, "ssim_views", ssim);
    cJSON_AddItemToObject(o, "psnr_views", psnr);
    return o;
}

int asp_eval_save_json(const asp_eval_result *res, const char *model, const char *path, asp_error *err)
{
    cJSON *o = cJSON_CreateObject(), *rows = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "model", model ? model : "");
    cJSON_AddNumberToObject(o, "points", (double)res->points);
    cJSON_AddNumberToObject(o, "views", (double)res->views);
    cJSON_AddNumberToObject(o, "levels", (double)res->level_count);
    cJSON_AddStringToObject(o, "gl_renderer", res->gl_renderer);
    cJSON_AddItemToObject(o, "crease_angle", num((double)res->crease_angle, "%g"));
    cJSON_AddNumberToObject(o, "clipped_points", (double)res->clipped_points);
    cJSON_AddNumberToObject(o, "mesh_triangles", (double)res->mesh_triangles);
    cJSON_AddItemToObject(o, "simplify_seconds", num(res->t_simplify, "%.4f"));
    cJSON_AddItemToObject(o, "decompose_seconds", num(res->t_decompose, "%.4f"));
    cJSON_AddItemToObject(o, "build_seconds", num(res->t_build, "%.4f"));
    cJSON_AddItemToObject(o, "render_seconds", num(res->t_render, "%.4f"));
    for (size_t i = 0; i < res->row_count; i++)
        cJSON_AddItemToArray(rows, row_json(res, i));
    cJSON_AddItemToObject(o, "rows", rows);
    return asp__json_save(o, path, err); // indented: eval.json is read by people as well as by scripts
}

enum { MAX_SERIES = 16 };

int asp_eval_chart(const asp_eval_result *res, uint32_t size, int which, asp_image *dst, asp_error *err)
{
    if (which != 0 && which != 1)
        return asp_error_set(err, ASP_EINVAL, "chart %d does not exist (0 = SSIM, 1 = frame time)", which);
    size_t n = 0;
    for (size_t i = 0; i < res->row_count; i++)
        n += res->rows[i].size == size;
    if (!n)
        return asp_error_set(err, ASP_EINVAL, "the evaluation has no rows of size %u", size);
    double *xy = asp_alloc(&res->ctx, 2 * n * sizeof *xy);
    if (!xy)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a chart of %zu points", n);
    // rows of one representation are consecutive (asp_eval_result.rows): one series each
    asp_chart_series series[MAX_SERIES];
    size_t ns = 0, k = 0;
    for (size_t i = 0; i < res->row_count; i++) {
        const asp_eval_row *r = &res->rows[i];
        if (r->size != size || r->note[0])
            continue;
        if (ns == 0 || strcmp(series[ns - 1].name, r->representation) != 0) {
            if (ns == MAX_SERIES)
                break;
            series[ns++] = (asp_chart_series){.name = r->representation, .x = xy + k, .y = xy + n + k};
        }
        xy[k] = (double)r->primitives;
        xy[n + k] = which == 0 ? r->ssim_mean : r->frame_ms;
        series[ns - 1].count++;
        k++;
    }
    char title[96];
    if (which == 0)
        snprintf(title, sizeof title, "SSIM against the reference at %ux%u px, mean of %zu views", size, size,
                 res->views);
    else
        snprintf(title, sizeof title, "frame time at %ux%u px (median of view 0)", size, size);
    asp_chart_desc cd = {.title = title,
                         .x_label = "primitives of the level (log scale)",
                         .y_label = which == 0 ? "SSIM (1 = identical)" : "frame time (ms, log scale)",
                         .flags = ASP_CHART_LOG_X | (which == 1 ? ASP_CHART_LOG_Y : 0)};
    int rc = asp_chart_draw(series, ns, &cd, dst, err);
    asp_free(&res->ctx, xy);
    return rc;
}
