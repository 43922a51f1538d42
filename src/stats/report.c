/*
 * The report of `amgsplat experiment analyze`: the tables and figures of seed
 * 004 chapter 4 from a study's logs. Frame time per test and condition (Table
 * 4.1) with frame time against primitives drawn (Fig 4.1) and histograms of
 * primitives per frame (Figs 4.2-4.5); recognition accuracy and naming time
 * (Tables 4.2-4.3); navigation grades per group and run and the improvement
 * from run A to B (Tables 4.4-4.7) with the pooled t test of 4.2, Welch's
 * test and confidence intervals; lost frames per log. Markdown, CSV, JSON
 * (cJSON) and PNG, each file written atomically.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "amgsplat/eval.h"
#include "amgsplat/stats.h"
#include "stats/internal.h"
#include "util/atomic_file.h"
#include "util/banned.h"

enum { MAX_CONDITIONS = 8, MAX_GROUPS = 8, HIST_BINS = 24, SCATTER_BINS = 16 };

enum { F_MD, F_LOGS, F_FRAME, F_RECOG, F_NAV, F_IMPROVE, F_COUNT };
static const char *const file_names[F_COUNT] = {"report.md",       "logs.csv",       "frame_time.csv",
                                                "recognition.csv", "navigation.csv", "improvement.csv"};

struct report {
    const asp_stats_analysis *a;
    const char *dir;
    asp__atomic_file f[F_COUNT];
    FILE *md;
    cJSON *root;
    const char *conditions[MAX_CONDITIONS];
    size_t ncond;
    asp_error *err;
    int rc;
};

/* ---- small helpers ---------------------------------------------------- */

static void csv_str(FILE *fp, const char *s)
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

static void csv_num(FILE *fp, double v)
{
    if (isfinite(v))
        fprintf(fp, "%.6g", v);
}

/* A table cell: a number at the given precision, or a dash. */
static const char *cell(char *buf, size_t cap, double v, int prec)
{
    if (isfinite(v))
        snprintf(buf, cap, "%.*f", prec, v);
    else
        snprintf(buf, cap, "-");
    return buf;
}

static const char *p_cell(char *buf, size_t cap, double p)
{
    if (!isfinite(p))
        snprintf(buf, cap, "-");
    else if (p < 1e-4)
        snprintf(buf, cap, "%.1e", p);
    else
        snprintf(buf, cap, "%.4f", p);
    return buf;
}

static cJSON *json_summary(const asp_stats_summary *s, double scale)
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

static cJSON *json_ttest(const asp_ttest_result *r)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "test", r->welch ? "welch" : "pooled");
    cJSON_AddNumberToObject(o, "diff", r->diff);
    cJSON_AddNumberToObject(o, "se", r->se);
    cJSON_AddNumberToObject(o, "t", r->t);
    cJSON_AddNumberToObject(o, "df", r->df);
    cJSON_AddNumberToObject(o, "p_greater", r->p_greater);
    cJSON_AddNumberToObject(o, "p_less", r->p_less);
    cJSON_AddNumberToObject(o, "p_two", r->p_two);
    cJSON_AddNumberToObject(o, "level", r->level);
    cJSON *ci = cJSON_AddArrayToObject(o, "diff_ci");
    cJSON_AddItemToArray(ci, cJSON_CreateNumber(r->diff_lo));
    cJSON_AddItemToArray(ci, cJSON_CreateNumber(r->diff_hi));
    return o;
}

/* Both tests of sample a against sample b; 0 when at least one could be made, t.t NaN otherwise. */
static void both_tests(const asp_stats_summary *a, const asp_stats_summary *b, double level, asp_ttest_result out[2])
{
    for (int w = 0; w < 2; w++) {
        memset(&out[w], 0, sizeof out[w]);
        out[w].t = out[w].df = out[w].p_greater = out[w].p_less = out[w].p_two = NAN;
        out[w].diff_lo = out[w].diff_hi = out[w].diff = out[w].se = NAN;
        out[w].welch = w;
        out[w].level = level;
        // too few values or no spread: the cells stay empty ("-"), the report says n
        asp_stats_ttest(a, b, &(asp_ttest_desc){.welch = w, .level = level}, &out[w], NULL);
    }
}

static int add_condition(struct report *r, const char *c)
{
    for (size_t i = 0; i < r->ncond; i++)
        if (strcmp(r->conditions[i], c) == 0)
            return 0;
    if (r->ncond == MAX_CONDITIONS)
        return -1;
    r->conditions[r->ncond++] = c;
    return 0;
}

/* polygons first (the seed's reference), then the order the logs name them */
static void collect_conditions(struct report *r)
{
    static const char *const known[] = {"polygons", "points", "primitives", "blank"};
    for (size_t k = 0; k < 4; k++)
        for (size_t i = 0; i < r->a->run_count; i++)
            if (strcmp(r->a->runs[i].log.condition, known[k]) == 0) {
                add_condition(r, known[k]);
                break;
            }
    for (size_t i = 0; i < r->a->run_count; i++)
        add_condition(r, r->a->runs[i].log.condition); // NEEDSWORK: more than 8 conditions are left out
}

static int save_chart(struct report *r, const asp_chart_series *s, size_t n, const asp_chart_desc *d,
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
static double *frame_values(const asp_stats_analysis *a, const char *test, const char *cond, int drawn, size_t *n)
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

/* ---- logs and lost frames --------------------------------------------- */

static void section_logs(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_LOGS].fp;
    cJSON *logs = cJSON_AddArrayToObject(r->root, "logs");
    size_t lost = 0, cut = 0;
    for (size_t i = 0; i < a->run_count; i++) {
        lost += a->runs[i].log.lost_frames;
        cut += a->runs[i].log.lost_frames > 0;
    }
    asp_stats_analysis_info info;
    asp_stats_analysis_info_get(a, &info);
    fprintf(md, "## Logs\n\n%zu logs of %zu subjects, %zu frames; **%zu frames lost** in %zu logs "
                "(lines cut off by a crash or unparsable).\n\n",
            a->run_count, a->subjects, info.frames, lost, cut);
    fprintf(md, "| subject | group | test | run | condition | frames | lost frames | first lost line | ms/frame | "
                "grade %% | naming s | correct |\n|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---|\n");
    fprintf(csv, "file,subject,group,test,run,condition,frames,lost_frames,first_lost_line,ignored_lines,events,"
                 "frame_ms_mean,grade,moving,along,away,backwards,out,recognition_s,naming_s,answer,correct\n");
    for (size_t i = 0; i < a->run_count; i++) {
        const struct stats_run *run = &a->runs[i];
        const asp_stats_log *l = &run->log;
        char b1[32], b2[32], b3[32];
        // the frame rate a run reached is part of what the seed measured (2.3, 4.1)
        double mean_ms = 0;
        for (size_t k = 0; k < l->frame_count; k++)
            mean_ms += l->frames[k].frame_ms;
        mean_ms = l->frame_count ? mean_ms / (double)l->frame_count : NAN;
        fprintf(md, "| %s | %s | %s | %s | %s | %zu | %zu | %zu | %s | %s | %s | %s |\n", l->subject, l->group,
                l->test, l->run, l->condition, l->frame_count, l->lost_frames, l->first_lost_line,
                cell(b3, sizeof b3, mean_ms, 2), cell(b1, sizeof b1, run->navigation ? 100 * run->grade.grade : NAN, 1),
                cell(b2, sizeof b2, run->naming.answered ? run->naming.naming_s : NAN, 2),
                run->navigation ? "" : run->naming.answered ? (run->naming.correct ? "yes" : "no") : "no answer");
        const char *strs[6] = {l->file, l->subject, l->group, l->test, l->run, l->condition};
        for (int k = 0; k < 6; k++) {
            csv_str(csv, strs[k]);
            fputc(',', csv);
        }
        fprintf(csv, "%zu,%zu,%zu,%zu,%zu,", l->frame_count, l->lost_frames, l->first_lost_line, l->ignored_lines,
                l->event_count);
        csv_num(csv, mean_ms);
        fputc(',', csv);
        csv_num(csv, run->navigation ? run->grade.grade : NAN);
        fprintf(csv, ",%zu,%zu,%zu,%zu,%zu,", run->grade.moving, run->grade.along, run->grade.away,
                run->grade.backwards, run->grade.out);
        csv_num(csv, run->naming.recognition_s);
        fputc(',', csv);
        csv_num(csv, run->naming.naming_s);
        fputc(',', csv);
        csv_str(csv, run->naming.answer);
        fprintf(csv, ",%s\n", run->naming.answered ? (run->naming.correct ? "true" : "false") : "");

        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", l->file);
        cJSON_AddStringToObject(o, "subject", l->subject);
        cJSON_AddStringToObject(o, "group", l->group);
        cJSON_AddStringToObject(o, "test", l->test);
        cJSON_AddStringToObject(o, "run", l->run);
        cJSON_AddStringToObject(o, "condition", l->condition);
        cJSON_AddStringToObject(o, "version", l->version);
        cJSON_AddNumberToObject(o, "seed", (double)l->seed);
        cJSON_AddBoolToObject(o, "observer", l->observer);
        cJSON_AddNumberToObject(o, "frames", (double)l->frame_count);
        cJSON_AddNumberToObject(o, "lost_frames", (double)l->lost_frames);
        cJSON_AddNumberToObject(o, "first_lost_line", (double)l->first_lost_line);
        cJSON_AddNumberToObject(o, "ignored_lines", (double)l->ignored_lines);
        cJSON_AddNumberToObject(o, "events", (double)l->event_count);
        cJSON_AddNumberToObject(o, "frame_ms_mean", mean_ms);
        if (run->navigation) {
            cJSON *g = cJSON_AddObjectToObject(o, "grade");
            cJSON_AddNumberToObject(g, "grade", run->grade.grade);
            cJSON_AddNumberToObject(g, "moving", (double)run->grade.moving);
            cJSON_AddNumberToObject(g, "along", (double)run->grade.along);
            cJSON_AddNumberToObject(g, "away", (double)run->grade.away);
            cJSON_AddNumberToObject(g, "backwards", (double)run->grade.backwards);
            cJSON_AddNumberToObject(g, "out", (double)run->grade.out);
        } else {
            cJSON *nm = cJSON_AddObjectToObject(o, "naming");
            cJSON_AddBoolToObject(nm, "answered", run->naming.answered);
            cJSON_AddNumberToObject(nm, "recognition_s", run->naming.recognition_s);
            cJSON_AddNumberToObject(nm, "naming_s", run->naming.naming_s);
            cJSON_AddStringToObject(nm, "answer", run->naming.answer);
            cJSON_AddStringToObject(nm, "expected", l->answer_expected);
            cJSON_AddBoolToObject(nm, "correct", run->naming.correct);
        }
        cJSON_AddItemToArray(logs, o);
    }
    fputc('\n', md);
}

/* ---- frame time (Table 4.1, Figs 4.1-4.5) ----------------------------- */

static void hist_chart(struct report *r, const char *test)
{
    const asp_stats_analysis *a = r->a;
    double xs[HIST_BINS], ys[MAX_CONDITIONS][HIST_BINS], hi = 0;
    asp_chart_series series[MAX_CONDITIONS];
    size_t ns = 0;
    for (size_t c = 0; c < r->ncond; c++) {
        size_t n;
        double *v = frame_values(a, test, r->conditions[c], 1, &n);
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
        double *v = frame_values(a, test, r->conditions[c], 1, &n);
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
    save_chart(r, series, ns,
               &(asp_chart_desc){.width = 640, .height = 360, .title = title, .x_label = "primitives drawn per frame",
                                 .y_label = "frames", .flags = ASP_CHART_BARS},
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
    save_chart(r, series, ns,
               &(asp_chart_desc){.width = 640, .height = 380,
                                 .title = "frame time against primitives drawn (seed 004 Fig 4.1; bars: sd)",
                                 .x_label = "primitives drawn per frame", .y_label = "ms",
                                 .flags = ASP_CHART_LOG_X | ASP_CHART_MARKERS, .y_err = err_ptr},
               "frame_time_vs_drawn.png");
}

static void section_frame_time(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_FRAME].fp;
    cJSON *rows = cJSON_AddArrayToObject(r->root, "frame_time"), *tests = cJSON_AddArrayToObject(r->root,
                                                                                                   "frame_time_tests");
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
            double *v = frame_values(a, test, r->conditions[c], 0, &n);
            double *d = frame_values(a, test, r->conditions[c], 1, &nd);
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
                    cell(b[0], 32, s.mean, 2), cell(b[1], 32, s.median, 2), cell(b[2], 32, s.min, 2),
                    cell(b[3], 32, s.max, 2), cell(b[4], 32, s.sd, 3), cell(b[5], 32, sd.mean, 0));
            fprintf(csv, "%s,", test);
            csv_str(csv, r->conditions[c]);
            fprintf(csv, ",%zu,", s.n);
            const double nums[6] = {s.mean, s.median, s.min, s.max, s.sd, sd.mean};
            for (int k = 0; k < 6; k++) {
                csv_num(csv, nums[k]);
                fputc(k < 5 ? ',' : '\n', csv);
            }
            cJSON *o = json_summary(&s, 1);
            cJSON_AddStringToObject(o, "test", test);
            cJSON_AddStringToObject(o, "condition", r->conditions[c]);
            cJSON_AddNumberToObject(o, "drawn_mean", sd.mean);
            cJSON_AddItemToArray(rows, o);
            if (strcmp(r->conditions[c], "polygons") == 0) {
                poly = s;
                have_poly = 1;
            } else if (have_poly) {
                asp_ttest_result tr[2];
                both_tests(&s, &poly, a->level, tr);
                cJSON *o2 = json_ttest(&tr[1]);
                cJSON_AddStringToObject(o2, "test_name", test);
                cJSON_AddStringToObject(o2, "condition", r->conditions[c]);
                cJSON_AddStringToObject(o2, "against", "polygons");
                cJSON_AddItemToArray(tests, o2);
            }
        }
    }
    // the comparisons below the table, as the seed's text does under Table 4.1
    fprintf(md, "\nDifference of mean frame time, condition minus polygons (Welch; the seed's z interval of 4.1 "
                "is the large-sample limit of this one):\n\n| test | condition | difference ms | %g%% interval | t | df "
                "| p (two-sided) |\n|---|---|---:|---|---:|---:|---:|\n",
            100 * a->level);
    cJSON *it;
    cJSON_ArrayForEach(it, tests)
    {
        double diff = cJSON_GetObjectItem(it, "diff")->valuedouble;
        const cJSON *ci = cJSON_GetObjectItem(it, "diff_ci");
        fprintf(md, "| %s | %s | %s | %s .. %s | %s | %s | %s |\n", cJSON_GetObjectItem(it, "test_name")->valuestring,
                cJSON_GetObjectItem(it, "condition")->valuestring, cell(b[0], 32, diff, 3),
                cell(b[1], 32, cJSON_GetArrayItem(ci, 0)->valuedouble, 3),
                cell(b[2], 32, cJSON_GetArrayItem(ci, 1)->valuedouble, 3),
                cell(b[3], 32, cJSON_GetObjectItem(it, "t")->valuedouble, 2),
                cell(b[4], 32, cJSON_GetObjectItem(it, "df")->valuedouble, 1),
                p_cell(b[5], 32, cJSON_GetObjectItem(it, "p_two")->valuedouble));
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

/* ---- recognition (Tables 4.2-4.3) ------------------------------------- */

static int counted_run(const asp_stats_analysis *a, const asp_stats_log *l)
{
    return a->all_runs || strcmp(l->run, "B") == 0;
}

static void section_recognition(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_RECOG].fp;
    cJSON *rec = cJSON_AddObjectToObject(r->root, "recognition");
    cJSON_AddStringToObject(rec, "runs", a->all_runs ? "A and B" : "B");
    cJSON *rows = cJSON_AddArrayToObject(rec, "rows"), *tests = cJSON_AddArrayToObject(rec, "tests");
    char b[8][32];
    fprintf(md, "## Object recognition (seed 004 Tables 4.2-4.3)\n\nRuns %s (seed 004 4.2 treats run A as practice). "
                "Naming time (seconds from Enter to the typed name) of the correct answers.\n\n"
                "| test | condition | correct | incorrect | no answer | %% correct | average s | median | minimum | "
                "maximum | sd |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            a->all_runs ? "A and B" : "B");
    fprintf(csv, "test,condition,correct,incorrect,unanswered,percent_correct,naming_n,naming_mean_s,"
                 "naming_median_s,naming_min_s,naming_max_s,naming_sd_s\n");
    for (int t = 0; t < 2; t++) {
        const char *test = asp__stats_tests[t];
        asp_stats_summary poly = {0};
        int have_poly = 0;
        for (size_t c = 0; c < r->ncond; c++) {
            size_t correct = 0, wrong = 0, none = 0, n = 0;
            double *v = malloc((a->run_count + 1) * sizeof *v);
            if (!v) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory");
                return;
            }
            for (size_t i = 0; i < a->run_count; i++) {
                const struct stats_run *run = &a->runs[i];
                if (strcmp(run->log.test, test) || strcmp(run->log.condition, r->conditions[c]) ||
                    !counted_run(a, &run->log))
                    continue;
                if (!run->naming.answered)
                    none++;
                else if (run->naming.correct) {
                    correct++;
                    v[n++] = run->naming.naming_s;
                } else
                    wrong++;
            }
            asp_stats_summary s;
            asp_stats_summarize(v, n, &s, NULL);
            free(v);
            if (correct + wrong + none == 0)
                continue;
            double pct = correct + wrong ? 100.0 * (double)correct / (double)(correct + wrong) : NAN;
            fprintf(md, "| %s | %s | %zu | %zu | %zu | %s | %s | %s | %s | %s | %s |\n", test, r->conditions[c],
                    correct, wrong, none, cell(b[0], 32, pct, 0), cell(b[1], 32, s.mean, 2),
                    cell(b[2], 32, s.median, 2), cell(b[3], 32, s.min, 2), cell(b[4], 32, s.max, 2),
                    cell(b[5], 32, s.sd, 2));
            fprintf(csv, "%s,", test);
            csv_str(csv, r->conditions[c]);
            fprintf(csv, ",%zu,%zu,%zu,", correct, wrong, none);
            csv_num(csv, pct);
            fprintf(csv, ",%zu", s.n);
            const double nums[5] = {s.mean, s.median, s.min, s.max, s.sd};
            for (int k = 0; k < 5; k++) {
                fputc(',', csv);
                csv_num(csv, nums[k]);
            }
            fputc('\n', csv);
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "test", test);
            cJSON_AddStringToObject(o, "condition", r->conditions[c]);
            cJSON_AddNumberToObject(o, "correct", (double)correct);
            cJSON_AddNumberToObject(o, "incorrect", (double)wrong);
            cJSON_AddNumberToObject(o, "unanswered", (double)none);
            cJSON_AddNumberToObject(o, "percent_correct", pct);
            cJSON_AddItemToObject(o, "naming_s", json_summary(&s, 1));
            cJSON_AddItemToArray(rows, o);
            if (strcmp(r->conditions[c], "polygons") == 0) {
                poly = s;
                have_poly = 1;
            } else if (have_poly) {
                asp_ttest_result tr[2];
                both_tests(&s, &poly, a->level, tr);
                cJSON *o2 = cJSON_CreateObject();
                cJSON_AddStringToObject(o2, "test", test);
                cJSON_AddStringToObject(o2, "condition", r->conditions[c]);
                cJSON_AddStringToObject(o2, "against", "polygons");
                cJSON_AddItemToObject(o2, "pooled", json_ttest(&tr[0]));
                cJSON_AddItemToObject(o2, "welch", json_ttest(&tr[1]));
                cJSON_AddItemToArray(tests, o2);
            }
        }
    }
    fprintf(md, "\nNaming time, condition minus polygons (one-sided p in the direction of the difference):\n\n"
                "| test | condition | difference s | pooled t | df | p | Welch t | df | p | %g%% interval (Welch) |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
            100 * a->level);
    cJSON *it;
    cJSON_ArrayForEach(it, tests)
    {
        const cJSON *p = cJSON_GetObjectItem(it, "pooled"), *w = cJSON_GetObjectItem(it, "welch");
        const cJSON *ci = cJSON_GetObjectItem(w, "diff_ci");
        double pg = cJSON_GetObjectItem(p, "p_greater")->valuedouble, pl = cJSON_GetObjectItem(p, "p_less")->valuedouble;
        double wg = cJSON_GetObjectItem(w, "p_greater")->valuedouble, wl = cJSON_GetObjectItem(w, "p_less")->valuedouble;
        fprintf(md, "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s .. %s |\n",
                cJSON_GetObjectItem(it, "test")->valuestring, cJSON_GetObjectItem(it, "condition")->valuestring,
                cell(b[0], 32, cJSON_GetObjectItem(p, "diff")->valuedouble, 2),
                cell(b[1], 32, cJSON_GetObjectItem(p, "t")->valuedouble, 3),
                cell(b[2], 32, cJSON_GetObjectItem(p, "df")->valuedouble, 0), p_cell(b[3], 32, pg < pl ? pg : pl),
                cell(b[4], 32, cJSON_GetObjectItem(w, "t")->valuedouble, 3),
                cell(b[5], 32, cJSON_GetObjectItem(w, "df")->valuedouble, 1), p_cell(b[6], 32, wg < wl ? wg : wl),
                cell(b[7], 32, cJSON_GetArrayItem(ci, 0)->valuedouble, 2),
                cell(b[7] + 16, 16, cJSON_GetArrayItem(ci, 1)->valuedouble, 2));
    }
    fputc('\n', md);
}

/* ---- navigation (Tables 4.4-4.7) -------------------------------------- */

struct nav_group {
    char name[40]; /* "control" or "variable <condition>" */
    double *a, *b, *imp;
    size_t n;
};

static void group_of(const asp_stats_log *b, char *name, size_t cap)
{
    if (strcmp(b->group, "variable") == 0)
        snprintf(name, cap, "variable %s", b->condition);
    else
        snprintf(name, cap, "%s", b->group[0] ? b->group : "control");
}

static void section_navigation_test(struct report *r, const char *test, cJSON *nav)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md;
    struct nav_group g[MAX_GROUPS];
    size_t ng = 0;
    memset(g, 0, sizeof g);
    cJSON *tj = cJSON_AddObjectToObject(nav, test), *subjects = cJSON_AddArrayToObject(tj, "subjects");
    // pair each subject's run A with its run B: the paired difference of seed 004 4.3
    for (size_t i = 0; i < a->run_count; i++) {
        const struct stats_run *ra = &a->runs[i];
        if (!ra->navigation || strcmp(ra->log.test, test) || strcmp(ra->log.run, "A"))
            continue;
        const struct stats_run *rb = NULL;
        for (size_t k = 0; k < a->run_count; k++)
            if (a->runs[k].navigation && !strcmp(a->runs[k].log.test, test) && !strcmp(a->runs[k].log.run, "B") &&
                !strcmp(a->runs[k].log.subject, ra->log.subject))
                rb = &a->runs[k];
        if (!rb || !isfinite(ra->grade.grade) || !isfinite(rb->grade.grade))
            continue; // the seed threw out such cases too (4.4: runs without data)
        char name[40];
        group_of(&rb->log, name, sizeof name);
        size_t k = 0;
        while (k < ng && strcmp(g[k].name, name))
            k++;
        if (k == ng) {
            if (ng == MAX_GROUPS)
                continue;
            snprintf(g[ng].name, sizeof g[ng].name, "%s", name);
            g[ng].a = malloc(a->run_count * sizeof(double));
            g[ng].b = malloc(a->run_count * sizeof(double));
            g[ng].imp = malloc(a->run_count * sizeof(double));
            if (!g[ng].a || !g[ng].b || !g[ng].imp) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory");
                ng++;
                goto done;
            }
            ng++;
        }
        g[k].a[g[k].n] = 100 * ra->grade.grade;
        g[k].b[g[k].n] = 100 * rb->grade.grade;
        g[k].imp[g[k].n] = 100 * (rb->grade.grade - ra->grade.grade);
        g[k].n++;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "subject", ra->log.subject);
        cJSON_AddStringToObject(o, "group", name);
        cJSON_AddNumberToObject(o, "grade_a", 100 * ra->grade.grade);
        cJSON_AddNumberToObject(o, "grade_b", 100 * rb->grade.grade);
        cJSON_AddNumberToObject(o, "improvement", 100 * (rb->grade.grade - ra->grade.grade));
        cJSON_AddItemToArray(subjects, o);
    }
    // control first: the reference of every test below
    for (size_t k = 1; k < ng; k++)
        if (!strcmp(g[k].name, "control")) {
            struct nav_group tmp = g[0];
            g[0] = g[k];
            g[k] = tmp;
        }
    {
        char b[8][32];
        const char *table = !strcmp(test, "lowspeed") ? "4.4" : "4.6", *imp = !strcmp(test, "lowspeed") ? "4.5" : "4.7";
        fprintf(md, "### %s navigation\n\nGrades in %% (seed 004 Table %s):\n\n| group | run | n | average | median | "
                    "minimum | maximum | sd |\n|---|---|---:|---:|---:|---:|---:|---:|\n",
                test, table);
        cJSON *grades = cJSON_AddArrayToObject(tj, "grades"), *imps = cJSON_AddArrayToObject(tj, "improvement"),
              *tests = cJSON_AddArrayToObject(tj, "tests");
        asp_stats_summary si[MAX_GROUPS];
        FILE *csv = r->f[F_NAV].fp, *icsv = r->f[F_IMPROVE].fp;
        for (size_t k = 0; k < ng; k++)
            for (int run = 0; run < 2; run++) {
                asp_stats_summary s;
                asp_stats_summarize(run ? g[k].b : g[k].a, g[k].n, &s, NULL);
                fprintf(md, "| %s | %c | %zu | %s | %s | %s | %s | %s |\n", g[k].name, run ? 'B' : 'A', s.n,
                        cell(b[0], 32, s.mean, 1), cell(b[1], 32, s.median, 1), cell(b[2], 32, s.min, 1),
                        cell(b[3], 32, s.max, 1), cell(b[4], 32, s.sd, 2));
                fprintf(csv, "%s,", test);
                csv_str(csv, g[k].name);
                fprintf(csv, ",%c,%zu", run ? 'B' : 'A', s.n);
                const double nums[5] = {s.mean, s.median, s.min, s.max, s.sd};
                for (int q = 0; q < 5; q++) {
                    fputc(',', csv);
                    csv_num(csv, nums[q]);
                }
                fputc('\n', csv);
                cJSON *o = json_summary(&s, 1);
                cJSON_AddStringToObject(o, "group", g[k].name);
                cJSON_AddStringToObject(o, "run", run ? "B" : "A");
                cJSON_AddItemToArray(grades, o);
            }
        fprintf(md, "\nImprovement from run A to run B in percentage points (seed 004 Table %s):\n\n| group | n | "
                    "average | median | minimum | maximum | sd |\n|---|---:|---:|---:|---:|---:|---:|\n",
                imp);
        for (size_t k = 0; k < ng; k++) {
            asp_stats_summarize(g[k].imp, g[k].n, &si[k], NULL);
            const asp_stats_summary *s = &si[k];
            fprintf(md, "| %s | %zu | %s | %s | %s | %s | %s |\n", g[k].name, s->n, cell(b[0], 32, s->mean, 1),
                    cell(b[1], 32, s->median, 1), cell(b[2], 32, s->min, 1), cell(b[3], 32, s->max, 1),
                    cell(b[4], 32, s->sd, 2));
            cJSON *o = json_summary(s, 1);
            cJSON_AddStringToObject(o, "group", g[k].name);
            cJSON_AddItemToArray(imps, o);
        }
        // within each group: did run B differ from run A? (one-sample t on the paired differences)
        fprintf(md, "\nRun B against run A within each group (paired: one-sample t of the improvements against 0; "
                    "p one-sided in the direction of the change):\n\n| group | n | mean change | t | df | p | %g%% "
                    "interval |\n|---|---:|---:|---:|---:|---:|---|\n",
                100 * a->level);
        cJSON *paired = cJSON_AddArrayToObject(tj, "paired");
        for (size_t k = 0; k < ng; k++) {
            asp_ttest_result pr;
            if (asp_stats_ttest_one(&si[k], 0, &(asp_ttest_desc){.level = a->level}, &pr, NULL)) {
                fprintf(md, "| %s | %zu | %s | - | - | - | - |\n", g[k].name, si[k].n, cell(b[0], 32, si[k].mean, 1));
                continue;
            }
            fprintf(md, "| %s | %zu | %s | %s | %s | %s | %s .. %s |\n", g[k].name, si[k].n, cell(b[0], 32, pr.diff, 1),
                    cell(b[1], 32, pr.t, 3), cell(b[2], 32, pr.df, 0), p_cell(b[3], 32, pr.p_one),
                    cell(b[4], 32, pr.diff_lo, 1), cell(b[5], 32, pr.diff_hi, 1));
            cJSON *o = json_ttest(&pr);
            cJSON_ReplaceItemInObject(o, "test", cJSON_CreateString("paired"));
            cJSON_AddStringToObject(o, "group", g[k].name);
            cJSON_AddItemToArray(paired, o);
        }
        if (ng && !strcmp(g[0].name, "control")) {
            fprintf(md, "\nControl against each variable group (alternative of seed 004 4.3: the control group "
                        "improves more; one-sided p = P(T >= t)), and run B alone:\n\n| compared | variable group | "
                        "difference | pooled t | df | p | Welch t | df | p | %g%% interval (Welch) |\n"
                        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
                    100 * a->level);
            for (size_t k = 1; k < ng; k++)
                for (int what = 0; what < 2; what++) {
                    asp_stats_summary c0, c1;
                    if (what == 0) {
                        c0 = si[0];
                        c1 = si[k];
                    } else {
                        asp_stats_summarize(g[0].b, g[0].n, &c0, NULL);
                        asp_stats_summarize(g[k].b, g[k].n, &c1, NULL);
                    }
                    asp_ttest_result tr[2];
                    both_tests(&c0, &c1, a->level, tr);
                    const char *label = what ? "grade B" : "improvement";
                    fprintf(md, "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s .. %s |\n", label, g[k].name,
                            cell(b[0], 32, tr[0].diff, 1), cell(b[1], 32, tr[0].t, 3), cell(b[2], 32, tr[0].df, 0),
                            p_cell(b[3], 32, tr[0].p_greater), cell(b[4], 32, tr[1].t, 3),
                            cell(b[5], 32, tr[1].df, 1), p_cell(b[6], 32, tr[1].p_greater),
                            cell(b[7], 32, tr[1].diff_lo, 1), cell(b[7] + 16, 16, tr[1].diff_hi, 1));
                    fprintf(icsv, "%s,%s,", test, label);
                    csv_str(icsv, g[k].name);
                    fprintf(icsv, ",%zu,%zu", c0.n, c1.n);
                    const double nums[11] = {c0.mean, c1.mean, tr[0].diff, tr[0].t, tr[0].df, tr[0].p_greater,
                                             tr[1].t, tr[1].df, tr[1].p_greater, tr[1].diff_lo, tr[1].diff_hi};
                    for (int q = 0; q < 11; q++) {
                        fputc(',', icsv);
                        csv_num(icsv, nums[q]);
                    }
                    fputc('\n', icsv);
                    cJSON *o = cJSON_CreateObject();
                    cJSON_AddStringToObject(o, "compared", what ? "grade_b" : "improvement");
                    cJSON_AddStringToObject(o, "control", "control");
                    cJSON_AddStringToObject(o, "variable", g[k].name);
                    cJSON_AddItemToObject(o, "pooled", json_ttest(&tr[0]));
                    cJSON_AddItemToObject(o, "welch", json_ttest(&tr[1]));
                    cJSON_AddItemToArray(tests, o);
                }
        } else {
            fprintf(md, "\nNo control group with both runs: no t test.\n");
        }
        // the chart: every subject's improvement (dots) and each group's mean with its interval
        double xs[MAX_GROUPS * 64], ys[MAX_GROUPS * 64], mx[MAX_GROUPS], my[MAX_GROUPS], me[MAX_GROUPS];
        size_t np = 0;
        char title[160] = "", legend[64];
        int used = snprintf(title, sizeof title, "%s: improvement B-A, %% points;", test);
        for (size_t k = 0; k < ng; k++) {
            for (size_t q = 0; q < g[k].n && np < MAX_GROUPS * 64; q++) {
                xs[np] = (double)(k + 1) - 0.1;
                ys[np++] = g[k].imp[q];
            }
            double lo, hi;
            asp_stats_mean_interval(&si[k], a->level, &lo, &hi);
            mx[k] = (double)(k + 1) + 0.1;
            my[k] = si[k].mean;
            me[k] = isfinite(lo) ? 0.5 * (hi - lo) : 0;
            if (used > 0 && (size_t)used < sizeof title)
                used += snprintf(title + used, sizeof title - (size_t)used, " %zu %s", k + 1, g[k].name);
        }
        snprintf(legend, sizeof legend, "mean, %g%% interval", 100 * a->level);
        const asp_chart_series series[2] = {{.name = "subjects", .x = xs, .y = ys, .count = np},
                                            {.name = legend, .x = mx, .y = my, .count = ng}};
        const double *errs[2] = {NULL, me};
        char name[64];
        snprintf(name, sizeof name, "grades_%s.png", test);
        if (ng) {
            fprintf(md, "\n![%s: improvement per group](%s)\n\n", test, name);
            save_chart(r, series, 2,
                       &(asp_chart_desc){.width = 640, .height = 380, .title = title, .x_label = "group",
                                         .y_label = "points", .flags = ASP_CHART_MARKERS, .y_err = errs},
                       name);
        }
    }
done:
    for (size_t k = 0; k < ng; k++) {
        free(g[k].a);
        free(g[k].b);
        free(g[k].imp);
    }
}

static void section_navigation(struct report *r)
{
    cJSON *nav = cJSON_AddObjectToObject(r->root, "navigation");
    fprintf(r->md, "## Navigation (seed 004 Tables 4.4-4.7)\n\nGrade of a run: the mean score of its moving frames "
                   "(seed 004 2.4; docs/experiment-analysis.md). Groups by run B: control (polygons twice) or "
                   "variable (run B in another condition).\n\n");
    for (int t = 2; t < STATS_TESTS && !r->rc; t++) {
        int any = 0;
        for (size_t i = 0; i < r->a->run_count; i++)
            any |= r->a->runs[i].navigation && !strcmp(r->a->runs[i].log.test, asp__stats_tests[t]);
        if (any)
            section_navigation_test(r, asp__stats_tests[t], nav);
    }
}

static void section_counts(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    asp_stats_analysis_info info;
    asp_stats_analysis_info_get(a, &info);
    cJSON_AddStringToObject(r->root, "format", "amgsplat-experiment-report 1");
    cJSON_AddStringToObject(r->root, "dir", a->dir);
    cJSON_AddStringToObject(r->root, "version", ASP_VERSION_STRING);
    cJSON_AddNumberToObject(r->root, "level", a->level);
    cJSON_AddStringToObject(r->root, "recognition_runs", a->all_runs ? "A and B" : "B");
    cJSON *study = cJSON_AddObjectToObject(r->root, "study");
    cJSON_AddStringToObject(study, "version", a->study_version);
    cJSON_AddNumberToObject(study, "seed", a->study_seed);
    cJSON *c = cJSON_AddObjectToObject(r->root, "counts");
    cJSON_AddNumberToObject(c, "logs", (double)info.logs);
    cJSON_AddNumberToObject(c, "subjects", (double)info.subjects);
    cJSON_AddNumberToObject(c, "frames", (double)info.frames);
    cJSON_AddNumberToObject(c, "lost_frames", (double)info.lost_frames);
    cJSON_AddNumberToObject(c, "answers", (double)a->answers);
    cJSON_AddNumberToObject(c, "answers_lost", (double)a->answers_lost);
    cJSON_AddNumberToObject(c, "answers_mismatch", (double)a->answers_mismatch);
    fprintf(r->md, "# Experiment report\n\nStudy `%s` (written by amgsplat %s), analysed by amgsplat %s. Intervals "
                   "at %g%%.\n\n",
            a->dir, a->study_version[0] ? a->study_version : "of unknown version", ASP_VERSION_STRING, 100 * a->level);
    if (isfinite(a->study_seed))
        fprintf(r->md, "Study seed: %.0f.\n\n", a->study_seed);
    fprintf(r->md, "answers.jsonl: %zu answers, %zu lines cut off, %zu disagreeing with the logs' events (the logs "
                   "are used).\n\n",
            a->answers, a->answers_lost, a->answers_mismatch);
}

static int make_dir(const char *dir, asp_error *err)
{
    struct stat st;
    if (mkdir(dir, 0777) == 0)
        return 0;
    if (errno == EEXIST && stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    return asp_error_set(err, ASP_EIO, "cannot create report directory '%s': %s", dir,
                         errno == EEXIST ? "a file of that name exists" : strerror(errno));
}

int asp_stats_report_write(const asp_stats_analysis *a, const char *report_dir, asp_error *err)
{
    ASP_ASSERT(a && report_dir);
    int rc = make_dir(report_dir, err);
    if (rc)
        return rc;
    struct report r = {.a = a, .dir = report_dir, .err = err};
    size_t opened = 0;
    for (; opened < F_COUNT && !r.rc; opened++) {
        char path[4096];
        if (snprintf(path, sizeof path, "%s/%s", report_dir, file_names[opened]) >= (int)sizeof path)
            r.rc = asp_error_set(err, ASP_EINVAL, "report directory name '%s' is too long", report_dir);
        else
            r.rc = asp__atomic_open(&r.f[opened], path, err);
        if (r.rc)
            break;
    }
    r.root = cJSON_CreateObject();
    if (!r.rc && !r.root)
        r.rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
    if (!r.rc) {
        r.md = r.f[F_MD].fp;
        fprintf(r.f[F_NAV].fp, "test,group,run,n,mean,median,min,max,sd\n");
        fprintf(r.f[F_IMPROVE].fp, "test,compared,variable_group,n_control,n_variable,mean_control,mean_variable,"
                                   "diff,pooled_t,pooled_df,pooled_p_one,welch_t,welch_df,welch_p_one,welch_ci_lo,"
                                   "welch_ci_hi\n");
        collect_conditions(&r);
        section_counts(&r);
        section_logs(&r);
        if (!r.rc)
            section_frame_time(&r);
        if (!r.rc)
            section_recognition(&r);
        if (!r.rc)
            section_navigation(&r);
    }
    char *json = NULL;
    if (!r.rc) {
        json = cJSON_Print(r.root);
        if (!json)
            r.rc = asp_error_set(err, ASP_ENOMEM, "out of memory printing the JSON report");
    }
    if (!r.rc) {
        char path[4096];
        asp__atomic_file jf;
        snprintf(path, sizeof path, "%s/report.json", report_dir);
        r.rc = asp__atomic_open(&jf, path, err);
        if (!r.rc) {
            fputs(json, jf.fp);
            fputc('\n', jf.fp);
            r.rc = asp__atomic_commit(&jf, err);
        }
    }
    cJSON_free(json);
    cJSON_Delete(r.root);
    for (size_t i = 0; i < opened && i < F_COUNT; i++) {
        if (r.rc)
            asp__atomic_abort(&r.f[i]);
        else
            r.rc = asp__atomic_commit(&r.f[i], err);
    }
    // a failed commit leaves the later temporaries: remove them
    for (size_t i = 0; r.rc && i < opened && i < F_COUNT; i++)
        asp__atomic_abort(&r.f[i]);
    return r.rc;
}
