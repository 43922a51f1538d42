/*
 * Frame time of the experiment's report (seed 004 4.1): Table 4.1 per test and
 * condition with each condition against polygons, Fig 4.1 (frame time against
 * primitives drawn) and Figs 4.2-4.5 (histograms of primitives per frame).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stats/report_internal.h"
#include "util/banned.h"

/* ---- frame time (Table 4.1, Figs 4.1-4.5) ----------------------------- */

static void hist_chart(struct report *r, const char *test)
{
    const asp_stats_analysis *a = r->a;
    double xs[HIST_BINS], ys[MAX_CONDITIONS][HIST_BINS], hi = 0;
    asp_chart_series series[MAX_CONDITIONS];
    size_t ns = 0;
    for (size_t c = 0; c < r->ncond; c++) {
        size_t n;
        double *v = asp__report_frame_values(a, test, r->conditions[c], 1, &n);
        for (size_t i = 0; v && i < n; i++)
            hi = v[i] > hi ? v[i] : hi;
        free(v);
    }
    if (!(hi > 0))
        return; // nothing drawn at all (a blank-only test): no histogram to show
    double w = hi / HIST_BINS;
    for (int b = 0; b < HIST_BINS; b++)
        xs[b] = (b + 0.5) * w;
    for (size_t c = 0; c < r->ncond; c++) {
        size_t n;
        double *v = asp__report_frame_values(a, test, r->conditions[c], 1, &n);
        if (!v)
            continue;
        memset(ys[ns], 0, sizeof ys[ns]);
        for (size_t i = 0; i < n; i++) {
            int b = (int)(v[i] / w);
            ys[ns][b < 0 ? 0 : b >= HIST_BINS ? HIST_BINS - 1 : b] += 1;
        }
        free(v);
        if (n)
            series[ns] = (asp_chart_series){.name = r->conditions[c], .x = xs, .y = ys[ns], .count = HIST_BINS}, ns++;
    }
    char title[96], name[64];
    snprintf(title, sizeof title, "%s: frames by primitives drawn (seed 004 Figs 4.2-4.5)", test);
    snprintf(name, sizeof name, "drawn_%s.png", test);
    asp__report_save_chart(r, series, ns,
                           &(asp_chart_desc){.width = 640,
                                             .height = 360,
                                             .title = title,
                                             .x_label = "primitives drawn per frame",
                                             .y_label = "frames",
                                             .flags = ASP_CHART_BARS},
                           name);
}

/* Fig 4.1: mean frame time (error bars: sd) of frames binned by primitives drawn, log-spaced bins. */
static void scatter_chart(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    double xs[MAX_CONDITIONS][SCATTER_BINS], ys[MAX_CONDITIONS][SCATTER_BINS], es[MAX_CONDITIONS][SCATTER_BINS];
    const double *err_ptr[MAX_CONDITIONS];
    asp_chart_series series[MAX_CONDITIONS];
    size_t ns = 0;
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < a->run_count; i++)
        for (size_t k = 0; k < a->runs[i].log.frame_count; k++) {
            double d = a->runs[i].log.frames[k].drawn;
            if (isfinite(d) && d >= 1) {
                lo = d < lo ? d : lo;
                hi = d > hi ? d : hi;
            }
        }
    if (!(hi >= lo))
        return;
    double l0 = log10(lo), span = log10(hi) - l0 + 1e-9;
    for (size_t c = 0; c < r->ncond; c++) {
        double sum[SCATTER_BINS] = {0}, sum2[SCATTER_BINS] = {0}, sx[SCATTER_BINS] = {0};
        size_t cnt[SCATTER_BINS] = {0};
        for (size_t i = 0; i < a->run_count; i++) {
            const asp_stats_log *l = &a->runs[i].log;
            if (strcmp(l->condition, r->conditions[c]) != 0)
                continue;
            for (size_t k = 0; k < l->frame_count; k++) {
                double d = l->frames[k].drawn, ms = l->frames[k].frame_ms;
                if (!(isfinite(d) && d >= 1))
                    continue;
                int b = (int)((log10(d) - l0) / span * SCATTER_BINS);
                b = b < 0 ? 0 : b >= SCATTER_BINS ? SCATTER_BINS - 1 : b;
                sum[b] += ms;
                sum2[b] += ms * ms;
                sx[b] += d;
                cnt[b]++;
            }
        }
        size_t m = 0;
        for (int b = 0; b < SCATTER_BINS; b++) {
            if (!cnt[b])
                continue;
            double mean = sum[b] / (double)cnt[b];
            double var = cnt[b] > 1 ? (sum2[b] - (double)cnt[b] * mean * mean) / (double)(cnt[b] - 1) : 0;
            xs[ns][m] = sx[b] / (double)cnt[b];
            ys[ns][m] = mean;
            es[ns][m] = var > 0 ? sqrt(var) : 0;
            m++;
        }
        if (m) {
            series[ns] = (asp_chart_series){.name = r->conditions[c], .x = xs[ns], .y = ys[ns], .count = m};
            err_ptr[ns] = es[ns];
            ns++;
        }
    }
    asp__report_save_chart(
        r, series, ns,
        &(asp_chart_desc){.width = 640,
                          .height = 380,
                          .title = "frame time against primitives drawn (seed 004 Fig 4.1; bars: sd)",
                          .x_label = "primitives drawn per frame",
                          .y_label = "ms",
                          .flags = ASP_CHART_LOG_X | ASP_CHART_MARKERS,
                          .y_err = err_ptr},
        "frame_time_vs_drawn.png");
}

void asp__report_frame_time(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_FRAME].fp;
    cJSON *rows = cJSON_AddArrayToObject(r->root, "frame_time"),
          *tests = cJSON_AddArrayToObject(r->root, "frame_time_tests");
    char b[6][32];
    fprintf(md, "## Frame time (seed 004 Table 4.1, Figs 4.1-4.5)\n\nMilliseconds per frame over every frame of "
                "the test's runs in that condition.\n\n"
                "| test | condition | frames | average | median | minimum | maximum | sd | drawn (mean) |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    fprintf(csv, "test,condition,frames,mean_ms,median_ms,min_ms,max_ms,sd_ms,drawn_mean\n");
    for (int t = 0; t < STATS_TESTS; t++) {
        const char *test = asp__stats_tests[t];
        asp_stats_summary poly = {0};
        int have_poly = 0;
        for (size_t c = 0; c < r->ncond; c++) {
            size_t n, nd;
            double *v = asp__report_frame_values(a, test, r->conditions[c], 0, &n);
            double *d = asp__report_frame_values(a, test, r->conditions[c], 1, &nd);
            asp_stats_summary s = {0}, sd = {0};
            int ok = v && d && !asp_stats_summarize(v, n, &s, NULL) && !asp_stats_summarize(d, nd, &sd, NULL);
            free(v);
            free(d);
            if (!ok) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory summarising frame times");
                return;
            }
            if (!n)
                continue;
            fprintf(md, "| %s | %s | %zu | %s | %s | %s | %s | %s | %s |\n", test, r->conditions[c], s.n,
                    asp__report_cell(b[0], 32, s.mean, 2), asp__report_cell(b[1], 32, s.median, 2),
                    asp__report_cell(b[2], 32, s.min, 2), asp__report_cell(b[3], 32, s.max, 2),
                    asp__report_cell(b[4], 32, s.n > 1 ? s.sd : NAN, 3), asp__report_cell(b[5], 32, sd.mean, 0));
            fprintf(csv, "%s,", test);
            asp__report_csv_str(csv, r->conditions[c]);
            fprintf(csv, ",%zu,", s.n);
            const double nums[6] = {s.mean, s.median, s.min, s.max, s.sd, sd.mean};
            for (int k = 0; k < 6; k++) {
                asp__report_csv_num(csv, nums[k]);
                fputc(k < 5 ? ',' : '\n', csv);
            }
            cJSON *o = asp__report_json_summary(&s, 1);
            cJSON_AddStringToObject(o, "test", test);
            cJSON_AddStringToObject(o, "condition", r->conditions[c]);
            cJSON_AddNumberToObject(o, "drawn_mean", sd.mean);
            cJSON_AddItemToArray(rows, o);
            if (strcmp(r->conditions[c], "polygons") == 0) {
                poly = s;
                have_poly = 1;
            } else if (have_poly) {
                asp_ttest_result tr[2];
                asp__report_both_tests(&s, &poly, a->level, tr);
                cJSON *o2 = asp__report_json_ttest(&tr[1]);
                cJSON_AddStringToObject(o2, "test_name", test);
                cJSON_AddStringToObject(o2, "condition", r->conditions[c]);
                cJSON_AddStringToObject(o2, "against", "polygons");
                cJSON_AddItemToArray(tests, o2);
            }
        }
    }
    // the comparisons below the table, as the seed's text does under Table 4.1
    fprintf(md,
            "\nDifference of mean frame time, condition minus polygons (Welch; the seed's z interval of 4.1 "
            "is the large-sample limit of this one):\n\n| test | condition | difference ms | %g%% interval | t | df "
            "| p (two-sided) |\n|---|---|---:|---|---:|---:|---:|\n",
            100 * a->level);
    cJSON *it;
    cJSON_ArrayForEach (it, tests) {
        double diff = cJSON_GetObjectItem(it, "diff")->valuedouble;
        const cJSON *ci = cJSON_GetObjectItem(it, "diff_ci");
        fprintf(md, "| %s | %s | %s | %s .. %s | %s | %s | %s |\n", cJSON_GetObjectItem(it, "test_name")->valuestring,
                cJSON_GetObjectItem(it, "condition")->valuestring, asp__report_cell(b[0], 32, diff, 3),
                asp__report_cell(b[1], 32, cJSON_GetArrayItem(ci, 0)->valuedouble, 3),
                asp__report_cell(b[2], 32, cJSON_GetArrayItem(ci, 1)->valuedouble, 3),
                asp__report_cell(b[3], 32, cJSON_GetObjectItem(it, "t")->valuedouble, 2),
                asp__report_cell(b[4], 32, cJSON_GetObjectItem(it, "df")->valuedouble, 1),
                asp__report_p_cell(b[5], 32, cJSON_GetObjectItem(it, "p_two")->valuedouble));
    }
    fprintf(md, "\n![frame time against primitives drawn](frame_time_vs_drawn.png)\n\n");
    scatter_chart(r);
    for (int t = 0; t < STATS_TESTS; t++) {
        int any = 0;
        for (size_t i = 0; i < a->run_count; i++)
            any |= strcmp(a->runs[i].log.test, asp__stats_tests[t]) == 0 && a->runs[i].log.frame_count > 0;
        if (!any)
            continue;
        fprintf(md, "![%s: primitives per frame](drawn_%s.png)\n", asp__stats_tests[t], asp__stats_tests[t]);
        hist_chart(r, asp__stats_tests[t]);
    }
    fputc('\n', md);
}
