/*
 * Formatting shared by the report's sections (report_internal.h): CSV fields,
 * Markdown cells, cJSON objects of summaries and t tests, and the charts.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stats/report_internal.h"
#include "util/banned.h"

void asp__report_csv_str(FILE *fp, const char *s)
{
    if (!strpbrk(s, ",\"\n\r")) {
        fputs(s, fp);
        return;
    }
    fputc('"', fp);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', fp);
        fputc(*s, fp);
    }
    fputc('"', fp);
}

void asp__report_csv_num(FILE *fp, double v)
{
    if (isfinite(v))
        fprintf(fp, "%.6g", v);
}

/* A table cell: a number at the given precision, or a dash. */
const char *asp__report_cell(char *buf, size_t cap, double v, int prec)
{
    if (isfinite(v))
        snprintf(buf, cap, "%.*f", prec, v);
    else
        snprintf(buf, cap, "-");
    return buf;
}

const char *asp__report_p_cell(char *buf, size_t cap, double p)
{
    if (!isfinite(p))
        snprintf(buf, cap, "-");
    else if (p < 1e-4)
        snprintf(buf, cap, "%.1e", p);
    else
        snprintf(buf, cap, "%.4f", p);
    return buf;
}

cJSON *asp__report_json_summary(const asp_stats_summary *s, double scale)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "n", (double)s->n);
    cJSON_AddNumberToObject(o, "mean", s->mean * scale);
    cJSON_AddNumberToObject(o, "median", s->median * scale);
    cJSON_AddNumberToObject(o, "min", s->min * scale);
    cJSON_AddNumberToObject(o, "max", s->max * scale);
    cJSON_AddNumberToObject(o, "sd", s->sd * scale);
    return o;
}

cJSON *asp__report_json_ttest(const asp_ttest_result *r)
{
    cJSON *o = NULL;
    asp_stats_ttest_json(r, NULL, &o, NULL); // out of memory: NULL, which cJSON's adders refuse
    return o;
}

/* Both tests of sample a against sample b; 0 when at least one could be made, t.t NaN otherwise. */
void asp__report_both_tests(const asp_stats_summary *a, const asp_stats_summary *b, double level,
                            asp_ttest_result out[2])
{
    for (int w = 0; w < 2; w++) {
        memset(&out[w], 0, sizeof out[w]);
        out[w].t = out[w].df = out[w].p_greater = out[w].p_less = out[w].p_one = out[w].p_two = NAN;
        out[w].diff_lo = out[w].diff_hi = out[w].diff = out[w].se = NAN;
        out[w].welch = w;
        out[w].level = level;
        // too few values or no spread: the cells stay empty ("-"), the report says n
        asp_stats_ttest(a, b, &(asp_ttest_desc){.welch = w, .level = level}, &out[w], NULL);
    }
}

int asp__report_save_chart(struct report *r, const asp_chart_series *s, size_t n, const asp_chart_desc *d,
                           const char *name)
{
    if (r->rc)
        return r->rc;
    asp_image img = {0};
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", r->dir, name) >= (int)sizeof path)
        return r->rc = asp_error_set(r->err, ASP_EINVAL, "report path '%s/%s' is too long", r->dir, name);
    r->rc = asp_chart_draw(s, n, d, &img, r->err);
    if (!r->rc)
        r->rc = asp_image_save_png(&img, path, r->err);
    asp_image_release(&img);
    return r->rc;
}

/* Values of the frames of every log with this test (NULL = any) and condition: frame_ms or drawn. */
double *asp__report_frame_values(const asp_stats_analysis *a, const char *test, const char *cond, int drawn, size_t *n)
{
    size_t total = 0;
    for (size_t i = 0; i < a->run_count; i++) {
        const asp_stats_log *l = &a->runs[i].log;
        if ((!test || strcmp(l->test, test) == 0) && strcmp(l->condition, cond) == 0)
            total += l->frame_count;
    }
    double *v = malloc((total ? total : 1) * sizeof *v);
    *n = 0;
    if (!v)
        return NULL;
    for (size_t i = 0; i < a->run_count; i++) {
        const asp_stats_log *l = &a->runs[i].log;
        if ((test && strcmp(l->test, test) != 0) || strcmp(l->condition, cond) != 0)
            continue;
        for (size_t k = 0; k < l->frame_count; k++) {
            double x = drawn ? l->frames[k].drawn : l->frames[k].frame_ms;
            if (isfinite(x))
                v[(*n)++] = x;
        }
    }
    return v;
}
