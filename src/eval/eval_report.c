/*
 * Writing an evaluation: CSV and JSON tables and the two charts of issue 7
 * (quality and frame time against primitive count, the trade-off of thesis
 * Fig. 1.1 and journal Table 2). Files appear atomically.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "util/atomic_file.h"
#include "util/banned.h"

/* JSON has no NaN or infinity: null instead. */
static void json_num(FILE *fp, double v, const char *fmt)
{
    if (isfinite(v))
        fprintf(fp, fmt, v);
    else
        fputs("null", fp);
}

static void json_str(FILE *fp, const char *s)
{
    fputc('"', fp);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(fp, "\\%c", c);
        else if (c < 0x20)
            fprintf(fp, "\\u%04x", c);
        else
            fputc(c, fp);
    }
    fputc('"', fp);
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

int asp_eval_save_json(const asp_eval_result *res, const char *model, const char *path, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    FILE *fp = f.fp;
    fputs("{\"model\": ", fp);
    json_str(fp, model ? model : "");
    fprintf(fp, ", \"points\": %zu, \"views\": %zu, \"levels\": %zu, \"gl_renderer\": ", res->points, res->views,
            res->level_count);
    json_str(fp, res->gl_renderer);
    fprintf(fp, ", \"crease_angle\": %g, \"clipped_points\": %zu", (double)res->crease_angle, res->clipped_points);
    fprintf(fp, ", \"mesh_triangles\": %zu, \"simplify_seconds\": %.4f", res->mesh_triangles, res->t_simplify);
    fprintf(fp, ", \"decompose_seconds\": %.4f, \"build_seconds\": %.4f, \"render_seconds\": %.4f,\n \"rows\": [",
            res->t_decompose, res->t_build, res->t_render);
    for (size_t i = 0; i < res->row_count; i++) {
        const asp_eval_row *r = &res->rows[i];
        fprintf(fp, "%s\n  {\"representation\": ", i ? "," : "");
        json_str(fp, r->representation);
        fprintf(fp, ", \"level\": %u, \"level_name\": ", r->level);
        json_str(fp, r->level_name);
        fprintf(fp, ", \"size\": %u, \"primitives\": %zu, \"drawn\": %.1f, \"texels\": %llu", r->size, r->primitives,
                r->drawn, (unsigned long long)r->texels);
        fprintf(fp, ", \"bytes\": %llu, \"note\": ", (unsigned long long)r->bytes);
        json_str(fp, r->note);
        const char *names[7] = {"psnr_mean", "psnr_min", "ssim_mean", "ssim_min", "iou_mean", "iou_min", "frame_ms"};
        const double vals[7] = {r->psnr_mean, r->psnr_min, r->ssim_mean, r->ssim_min,
                                r->iou_mean,  r->iou_min,  r->frame_ms};
        for (int k = 0; k < 7; k++) {
            fprintf(fp, ", \"%s\": ", names[k]);
            json_num(fp, vals[k], "%.6g");
        }
        fputs(", \"ssim_views\": [", fp);
        for (size_t v = 0; v < res->views; v++) {
            fputs(v ? ", " : "", fp);
            json_num(fp, res->ssim[i * res->views + v], "%.6f");
        }
        fputs("], \"psnr_views\": [", fp);
        for (size_t v = 0; v < res->views; v++) {
            fputs(v ? ", " : "", fp);
            json_num(fp, res->psnr[i * res->views + v], "%.4f");
        }
        fputs("]}", fp);
    }
    fputs("\n]}\n", fp);
    return asp__atomic_commit(&f, err);
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
    snprintf(title, sizeof title, "%s at %ux%u, mean of %zu views", which == 0 ? "SSIM" : "frame time (ms)", size,
             size, res->views);
    asp_chart_desc cd = {.title = title, .x_label = "primitives", .y_label = which == 0 ? "SSIM" : "ms",
                         .flags = ASP_CHART_LOG_X | (which == 1 ? ASP_CHART_LOG_Y : 0)};
    int rc = asp_chart_draw(series, ns, &cd, dst, err);
    asp_free(&res->ctx, xy);
    return rc;
}
