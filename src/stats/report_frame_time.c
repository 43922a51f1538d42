/*
 * Frame time of the experiment's report (seed 004 4.1), after the design's
 * groups: per run (mean, median, p95), Table 4.1 per test and condition with
 * each condition against polygons over run means, Fig 4.1 (frame time against
 * primitives drawn) and Figs 4.2-4.5 (histograms of primitives per frame).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>

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
                                             .y_label = "frames (count)",
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
                          .y_label = "frame time (ms)",
                          .flags = ASP_CHART_LOG_X | ASP_CHART_MARKERS,
                          .y_err = err_ptr},
        "frame_time_vs_drawn.png");
}

/* ---- design (who was in which group) --------------------------------- */

/* The groups as the logs show them and the warning of an unbalanced design, before any result. */
static void design_section(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md;
    cJSON *d = cJSON_AddObjectToObject(r->root, "design"), *groups = cJSON_AddArrayToObject(d, "groups");
    fprintf(md, "## Design\n\nSubjects per group (a subject's group is the condition of its runs B; control: "
                "polygons again).\n\n| group | subjects |\n|---|---:|\n");
    for (size_t i = 0; i < a->group_count; i++) {
        fprintf(md, "| %s | %zu |\n", a->groups[i].name, a->groups[i].subjects);
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "group", a->groups[i].name);
        cJSON_AddNumberToObject(o, "subjects", (double)a->groups[i].subjects);
        cJSON_AddItemToArray(groups, o);
    }
    cJSON_AddBoolToObject(d, "balanced", a->design_warning[0] == 0);
    if (a->design_warning[0]) {
        cJSON_AddStringToObject(d, "warning", a->design_warning);
        fprintf(md, "\n**Warning: %s.**\n", a->design_warning);
    }
    fputc('\n', md);
}

/* ---- frame time (Table 4.1, Figs 4.1-4.5) ----------------------------- */

/* one run's frame times: n, mean, median, 95th percentile, min, max (NaN when it has no frame) */
struct run_ft {
    size_t n;
    double mean, median, p95, min, max;
};

static int run_frame_time(const asp_stats_log *l, struct run_ft *out)
{
    *out = (struct run_ft){.mean = NAN, .median = NAN, .p95 = NAN, .min = NAN, .max = NAN};
    double *v = malloc((l->frame_count ? l->frame_count : 1) * sizeof *v);
    if (!v)
        return -1;
    size_t n = 0;
    for (size_t k = 0; k < l->frame_count; k++)
        if (isfinite(l->frames[k].frame_ms))
            v[n++] = l->frames[k].frame_ms;
    if (n) {
        gsl_sort(v, 1, n);
        out->mean = gsl_stats_mean(v, 1, n);
        out->median = gsl_stats_median_from_sorted_data(v, 1, n);
        out->p95 = gsl_stats_quantile_from_sorted_data(v, 1, n, 0.95);
        out->min = v[0];
        out->max = v[n - 1];
    }
    out->n = n;
    free(v);
    return 0;
}

/* The per-run rows: frame time of every run, the unit the test below compares. */
static int runs_table(struct report *r, cJSON *rows)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md;
    char b[5][32];
    fprintf(md, "### Frame time per run\n\nMilliseconds per frame (the time to draw a frame and have it on "
                "screen or read back), one row per run.\n\n"
                "| subject | test | run | condition | frames | mean ms | median ms | p95 ms | max ms |\n"
                "|---|---|---|---|---:|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < a->run_count; i++) {
        const asp_stats_log *l = &a->runs[i].log;
        struct run_ft f;
        if (run_frame_time(l, &f))
            return -1;
        fprintf(md, "| %s | %s | %s | %s | %zu | %s | %s | %s | %s |\n", l->subject, l->test, l->run, l->condition,
                f.n, asp__report_cell(b[0], 32, f.mean, 2), asp__report_cell(b[1], 32, f.median, 2),
                asp__report_cell(b[2], 32, f.p95, 2), asp__report_cell(b[3], 32, f.max, 2));
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "subject", l->subject);
        cJSON_AddStringToObject(o, "group", l->group);
        cJSON_AddStringToObject(o, "test", l->test);
        cJSON_AddStringToObject(o, "run", l->run);
        cJSON_AddStringToObject(o, "condition", l->condition);
        cJSON_AddNumberToObject(o, "frames", (double)f.n);
        cJSON_AddNumberToObject(o, "mean_ms", f.mean);
        cJSON_AddNumberToObject(o, "median_ms", f.median);
        cJSON_AddNumberToObject(o, "p95_ms", f.p95);
        cJSON_AddNumberToObject(o, "min_ms", f.min);
        cJSON_AddNumberToObject(o, "max_ms", f.max);
        cJSON_AddItemToArray(rows, o);
    }
    fputc('\n', md);
    return 0;
}

/* the mean frame time of each run of this test and condition that has frames; NULL when out of memory */
static double *run_means(const asp_stats_analysis *a, const char *test, const char *cond, size_t *n)
{
    double *v = malloc((a->run_count ? a->run_count : 1) * sizeof *v);
    *n = 0;
    for (size_t i = 0; v && i < a->run_count; i++) {
        const asp_stats_log *l = &a->runs[i].log;
        struct run_ft f;
        if (strcmp(l->test, test) || strcmp(l->condition, cond))
            continue;
        if (run_frame_time(l, &f)) {
            free(v);
            return NULL;
        }
        if (f.n)
            v[(*n)++] = f.mean;
    }
    return v;
}

void asp__report_frame_time(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_FRAME].fp;
    design_section(r);
    cJSON *rows = cJSON_AddArrayToObject(r->root, "frame_time"),
          *run_rows = cJSON_AddArrayToObject(r->root, "frame_time_runs"),
          *tests = cJSON_AddArrayToObject(r->root, "frame_time_tests");
    cJSON_AddStringToObject(r->root, "frame_time_unit", "ms per frame");
    char b[9][32];
    fprintf(md, "## Frame time (seed 004 Table 4.1, Figs 4.1-4.5)\n\n");
    if (runs_table(r, run_rows)) {
        r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory summarising frame times");
        return;
    }
    fprintf(md, "### Frame time per test and condition\n\nMilliseconds per frame over every frame of the test's "
                "runs in that condition, and the runs' means (one value per run).\n\n"
                "| test | condition | runs | frames | average | median | minimum | maximum | sd | run means: "
                "average | run means: sd | drawn (mean) |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    fprintf(csv, "test,condition,frames,mean_ms,median_ms,min_ms,max_ms,sd_ms,drawn_mean,runs,run_mean_ms,"
                 "run_sd_ms\n");
    for (int t = 0; t < STATS_TESTS; t++) {
        const char *test = asp__stats_tests[t];
        asp_stats_summary poly = {0};
        int have_poly = 0;
        for (size_t c = 0; c < r->ncond; c++) {
            size_t n, nd, nr;
            double *v = asp__report_frame_values(a, test, r->conditions[c], 0, &n);
            double *d = asp__report_frame_values(a, test, r->conditions[c], 1, &nd);
            double *m = run_means(a, test, r->conditions[c], &nr);
            asp_stats_summary s = {0}, sd = {0}, sr = {0};
            int ok = v && d && m && !asp_stats_summarize(v, n, &s, NULL) && !asp_stats_summarize(d, nd, &sd, NULL) &&
                     !asp_stats_summarize(m, nr, &sr, NULL);
            free(v);
            free(d);
            free(m);
            if (!ok) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory summarising frame times");
                return;
            }
            if (!n)
                continue;
            fprintf(md, "| %s | %s | %zu | %zu | %s | %s | %s | %s | %s | %s | %s | %s |\n", test, r->conditions[c],
                    sr.n, s.n, asp__report_cell(b[0], 32, s.mean, 2), asp__report_cell(b[1], 32, s.median, 2),
                    asp__report_cell(b[2], 32, s.min, 2), asp__report_cell(b[3], 32, s.max, 2),
                    asp__report_cell(b[4], 32, s.n > 1 ? s.sd : NAN, 3), asp__report_cell(b[5], 32, sr.mean, 2),
                    asp__report_cell(b[6], 32, sr.n > 1 ? sr.sd : NAN, 3), asp__report_cell(b[7], 32, sd.mean, 0));
            fprintf(csv, "%s,", test);
            asp__report_csv_str(csv, r->conditions[c]);
            fprintf(csv, ",%zu,", s.n);
            const double nums[6] = {s.mean, s.median, s.min, s.max, s.sd, sd.mean};
            for (int k = 0; k < 6; k++) {
                asp__report_csv_num(csv, nums[k]);
                fputc(',', csv);
            }
            fprintf(csv, "%zu,", sr.n);
            asp__report_csv_num(csv, sr.mean);
            fputc(',', csv);
            asp__report_csv_num(csv, sr.n > 1 ? sr.sd : NAN);
            fputc('\n', csv);
            cJSON *o = asp__report_json_summary(&s, 1);
            cJSON_AddStringToObject(o, "test", test);
            cJSON_AddStringToObject(o, "condition", r->conditions[c]);
            cJSON_AddNumberToObject(o, "drawn_mean", sd.mean);
            cJSON_AddItemToObject(o, "run_means", asp__report_json_summary(&sr, 1));
            cJSON_AddItemToArray(rows, o);
            if (strcmp(r->conditions[c], "polygons") == 0) {
                poly = sr;
                have_poly = 1;
            } else if (have_poly) {
                /*
                 * The test is over run means, one value per run, never over frames: the frames of one
                 * run share its scene, view path, machine state and the renderer's caches, so they are
                 * strongly correlated, and counting each as an independent sample is pseudo-replication
                 * (Hurlbert 1984): it gave p = 1.5e-59 from 16 runs (issue 29). The run is the unit
                 * that was repeated; its mean is what varies from one repetition to the next.
                 */
                asp_ttest_result tr[2];
                asp__report_both_tests(&sr, &poly, a->level, tr);
                cJSON *o2 = asp__report_json_ttest(&tr[1]);
                cJSON_AddStringToObject(o2, "test_name", test);
                cJSON_AddStringToObject(o2, "condition", r->conditions[c]);
                cJSON_AddStringToObject(o2, "against", "polygons");
                cJSON_AddStringToObject(o2, "unit", "run mean");
                cJSON_AddNumberToObject(o2, "runs", (double)sr.n);
                cJSON_AddNumberToObject(o2, "runs_against", (double)poly.n);
                // the difference stands without a test: say why the test is missing instead
                cJSON_ReplaceItemInObject(o2, "diff", cJSON_CreateNumber(sr.n && poly.n ? sr.mean - poly.mean : NAN));
                if (isnan(tr[1].t))
                    cJSON_AddStringToObject(o2, "note", sr.n < 2 || poly.n < 2 ? "fewer than 2 runs on a side: no test"
                                                                               : "no spread: no test");
                cJSON_AddItemToArray(tests, o2);
            }
        }
    }
    // the comparisons below the table, as the seed's text does under Table 4.1
    fprintf(md,
            "\nDifference of mean frame time, condition minus polygons, over the runs' means (one value per run: "
            "the frames of a run are correlated, so they are not independent samples). Welch's test; the seed's "
            "z interval of 4.1 is its large-sample limit.\n\n"
            "| test | condition | runs | polygons runs | difference ms | %g%% interval | t | df | p (two-sided) | "
            "note |\n|---|---|---:|---:|---:|---|---:|---:|---:|---|\n",
            100 * a->level);
    cJSON *it;
    cJSON_ArrayForEach (it, tests) {
        double diff = cJSON_GetObjectItem(it, "diff")->valuedouble;
        const cJSON *ci = cJSON_GetObjectItem(it, "diff_ci");
        const cJSON *note = cJSON_GetObjectItem(it, "note");
        fprintf(md, "| %s | %s | %.0f | %.0f | %s | %s .. %s | %s | %s | %s | %s |\n",
                cJSON_GetObjectItem(it, "test_name")->valuestring, cJSON_GetObjectItem(it, "condition")->valuestring,
                cJSON_GetObjectItem(it, "runs")->valuedouble, cJSON_GetObjectItem(it, "runs_against")->valuedouble,
                asp__report_cell(b[0], 32, diff, 3),
                asp__report_cell(b[1], 32, cJSON_GetArrayItem(ci, 0)->valuedouble, 3),
                asp__report_cell(b[2], 32, cJSON_GetArrayItem(ci, 1)->valuedouble, 3),
                asp__report_cell(b[3], 32, cJSON_GetObjectItem(it, "t")->valuedouble, 2),
                asp__report_cell(b[4], 32, cJSON_GetObjectItem(it, "df")->valuedouble, 1),
                asp__report_p_cell(b[5], 32, cJSON_GetObjectItem(it, "p_two")->valuedouble),
                cJSON_IsString(note) ? note->valuestring : "");
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
