/*
 * Navigation in the experiment's report (seed 004 4.3-4.4): grades per group
 * and run (Tables 4.4, 4.6), the improvement from run A to B (Tables 4.5, 4.7),
 * the paired test within each group and control against each variable group
 * with the pooled t of 4.2, Welch's test and intervals, and a chart.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stats/report_internal.h"
#include "util/banned.h"

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

static void release_groups(struct nav_group *g, size_t ng)
{
    for (size_t k = 0; k < ng; k++) {
        free(g[k].a);
        free(g[k].b);
        free(g[k].imp);
    }
}

/* The log of the subject's run B of this test, or NULL. */
static const struct stats_run *run_b_of(const asp_stats_analysis *a, const struct stats_run *ra)
{
    for (size_t k = 0; k < a->run_count; k++) {
        const asp_stats_log *l = &a->runs[k].log;
        if (a->runs[k].navigation && !strcmp(l->test, ra->log.test) && !strcmp(l->run, "B") &&
            !strcmp(l->subject, ra->log.subject))
            return &a->runs[k];
    }
    return NULL;
}

/*
 * Pairs each subject's run A with its run B (the paired difference of seed 004 2.3, 4.3) into
 * groups by run B's header, control first. Returns the number of groups; sets r->rc when out of
 * memory (the groups so far are returned for release).
 */
static size_t collect_groups(struct report *r, const char *test, struct nav_group g[MAX_GROUPS], cJSON *subjects)
{
    const asp_stats_analysis *a = r->a;
    size_t ng = 0;
    for (size_t i = 0; i < a->run_count && !r->rc; i++) {
        const struct stats_run *ra = &a->runs[i], *rb;
        if (!ra->navigation || strcmp(ra->log.test, test) || strcmp(ra->log.run, "A"))
            continue;
        rb = run_b_of(a, ra);
        if (!rb || !isfinite(ra->grade.grade) || !isfinite(rb->grade.grade))
            continue; // the seed threw out such cases too (4.4: runs without data)
        char name[40];
        group_of(&rb->log, name, sizeof name);
        size_t k = 0;
        while (k < ng && strcmp(g[k].name, name))
            k++;
        if (k == MAX_GROUPS)
            continue; // NEEDSWORK: more than 8 groups (conditions) are left out
        if (k == ng) {
            snprintf(g[ng].name, sizeof g[ng].name, "%s", name);
            g[ng].a = malloc(a->run_count * sizeof(double));
            g[ng].b = malloc(a->run_count * sizeof(double));
            g[ng].imp = malloc(a->run_count * sizeof(double));
            if (!g[ng++].imp || !g[k].a || !g[k].b) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory");
                break;
            }
        }
        double ga = 100 * ra->grade.grade, gb = 100 * rb->grade.grade;
        g[k].a[g[k].n] = ga;
        g[k].b[g[k].n] = gb;
        g[k].imp[g[k].n++] = gb - ga;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "subject", ra->log.subject);
        cJSON_AddStringToObject(o, "group", name);
        cJSON_AddNumberToObject(o, "grade_a", ga);
        cJSON_AddNumberToObject(o, "grade_b", gb);
        cJSON_AddNumberToObject(o, "improvement", gb - ga);
        cJSON_AddItemToArray(subjects, o);
    }
    // control first: the reference of every test below
    for (size_t k = 1; k < ng; k++)
        if (!strcmp(g[k].name, "control")) {
            struct nav_group tmp = g[0];
            g[0] = g[k];
            g[k] = tmp;
        }
    return ng;
}

static void summary_row(FILE *md, const char *group, const char *run, const asp_stats_summary *s)
{
    char b[5][32];
    fprintf(md, "| %s |%s%s%s %zu | %s | %s | %s | %s | %s |\n", group, run ? " " : "", run ? run : "", run ? " |" : "",
            s->n, asp__report_cell(b[0], 32, s->mean, 1), asp__report_cell(b[1], 32, s->median, 1),
            asp__report_cell(b[2], 32, s->min, 1), asp__report_cell(b[3], 32, s->max, 1),
            asp__report_cell(b[4], 32, s->n > 1 ? s->sd : NAN, 2));
}

/* Tables 4.4/4.6 (grades by group and run) and 4.5/4.7 (improvement); si receives the improvements' summaries. */
static void grade_tables(struct report *r, const char *test, const struct nav_group *g, size_t ng, cJSON *tj,
                         asp_stats_summary si[MAX_GROUPS])
{
    FILE *md = r->md, *csv = r->f[F_NAV].fp;
    int low = !strcmp(test, "lowspeed");
    cJSON *grades = cJSON_AddArrayToObject(tj, "grades"), *imps = cJSON_AddArrayToObject(tj, "improvement");
    fprintf(md,
            "### %s navigation\n\nGrades in %% (seed 004 Table %s):\n\n| group | run | n | average | median | "
            "minimum | maximum | sd |\n|---|---|---:|---:|---:|---:|---:|---:|\n",
            test, low ? "4.4" : "4.6");
    for (size_t k = 0; k < ng; k++)
        for (int run = 0; run < 2; run++) {
            asp_stats_summary s;
            asp_stats_summarize(run ? g[k].b : g[k].a, g[k].n, &s, NULL);
            summary_row(md, g[k].name, run ? "B" : "A", &s);
            fprintf(csv, "%s,", test);
            asp__report_csv_str(csv, g[k].name);
            fprintf(csv, ",%c,%zu", run ? 'B' : 'A', s.n);
            const double nums[5] = {s.mean, s.median, s.min, s.max, s.sd};
            for (int q = 0; q < 5; q++) {
                fputc(',', csv);
                asp__report_csv_num(csv, nums[q]);
            }
            fputc('\n', csv);
            cJSON *o = asp__report_json_summary(&s, 1);
            cJSON_AddStringToObject(o, "group", g[k].name);
            cJSON_AddStringToObject(o, "run", run ? "B" : "A");
            cJSON_AddItemToArray(grades, o);
        }
    fprintf(md,
            "\nImprovement from run A to run B in percentage points (seed 004 Table %s):\n\n| group | n | "
            "average | median | minimum | maximum | sd |\n|---|---:|---:|---:|---:|---:|---:|\n",
            low ? "4.5" : "4.7");
    for (size_t k = 0; k < ng; k++) {
        asp_stats_summarize(g[k].imp, g[k].n, &si[k], NULL);
        summary_row(md, g[k].name, NULL, &si[k]);
        cJSON *o = asp__report_json_summary(&si[k], 1);
        cJSON_AddStringToObject(o, "group", g[k].name);
        cJSON_AddItemToArray(imps, o);
    }
}

/* Within each group: did run B differ from run A? (one-sample t of the paired differences against 0) */
static void paired_tests(struct report *r, const struct nav_group *g, size_t ng, const asp_stats_summary *si, cJSON *tj)
{
    char b[6][32];
    fprintf(r->md,
            "\nRun B against run A within each group (paired: one-sample t of the improvements against 0; "
            "p one-sided in the direction of the change):\n\n| group | n | mean change | t | df | p | %g%% "
            "interval |\n|---|---:|---:|---:|---:|---:|---|\n",
            100 * r->a->level);
    cJSON *paired = cJSON_AddArrayToObject(tj, "paired");
    for (size_t k = 0; k < ng; k++) {
        asp_ttest_result pr;
        if (asp_stats_ttest_one(&si[k], 0, &(asp_ttest_desc){.level = r->a->level}, &pr, NULL)) {
            fprintf(r->md, "| %s | %zu | %s | - | - | - | - |\n", g[k].name, si[k].n,
                    asp__report_cell(b[0], 32, si[k].mean, 1));
            continue;
        }
        fprintf(r->md, "| %s | %zu | %s | %s | %s | %s | %s .. %s |\n", g[k].name, si[k].n,
                asp__report_cell(b[0], 32, pr.diff, 1), asp__report_cell(b[1], 32, pr.t, 3),
                asp__report_cell(b[2], 32, pr.df, 0), asp__report_p_cell(b[3], 32, pr.p_one),
                asp__report_cell(b[4], 32, pr.diff_lo, 1), asp__report_cell(b[5], 32, pr.diff_hi, 1));
        cJSON *o = NULL;
        asp_stats_ttest_json(&pr, &(asp_ttest_json_desc){.test = "paired", .one_sample = 1, .mu = 0}, &o, NULL);
        cJSON_AddStringToObject(o, "group", g[k].name);
        cJSON_AddItemToArray(paired, o);
    }
}

/* Control against each variable group: on the improvement (seed 004 4.3) and on run B's grade alone. */
static void control_tests(struct report *r, const char *test, const struct nav_group *g, size_t ng,
                          const asp_stats_summary *si, cJSON *tj)
{
    FILE *md = r->md, *csv = r->f[F_IMPROVE].fp;
    cJSON *tests = cJSON_AddArrayToObject(tj, "tests");
    if (!ng || strcmp(g[0].name, "control")) {
        fprintf(md, "\nNo control group with both runs: no test against it.\n");
        return;
    }
    fprintf(md,
            "\nControl against each variable group (alternative of seed 004 4.3: the control group "
            "improves more; one-sided p = P(T >= t)), and run B alone:\n\n| compared | variable group | "
            "difference | pooled t | df | p | Welch t | df | p | %g%% interval (Welch) |\n"
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
            100 * r->a->level);
    for (size_t k = 1; k < ng; k++)
        for (int grade_b = 0; grade_b < 2; grade_b++) {
            asp_stats_summary c0 = si[0], c1 = si[k];
            if (grade_b) {
                asp_stats_summarize(g[0].b, g[0].n, &c0, NULL);
                asp_stats_summarize(g[k].b, g[k].n, &c1, NULL);
            }
            asp_ttest_result tr[2];
            asp__report_both_tests(&c0, &c1, r->a->level, tr);
            const char *label = grade_b ? "grade B" : "improvement";
            char b[9][32];
            fprintf(md, "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s .. %s |\n", label, g[k].name,
                    asp__report_cell(b[0], 32, tr[0].diff, 1), asp__report_cell(b[1], 32, tr[0].t, 3),
                    asp__report_cell(b[2], 32, tr[0].df, 0), asp__report_p_cell(b[3], 32, tr[0].p_greater),
                    asp__report_cell(b[4], 32, tr[1].t, 3), asp__report_cell(b[5], 32, tr[1].df, 1),
                    asp__report_p_cell(b[6], 32, tr[1].p_greater), asp__report_cell(b[7], 32, tr[1].diff_lo, 1),
                    asp__report_cell(b[8], 32, tr[1].diff_hi, 1));
            fprintf(csv, "%s,%s,", test, label);
            asp__report_csv_str(csv, g[k].name);
            fprintf(csv, ",%zu,%zu", c0.n, c1.n);
            const double nums[11] = {c0.mean, c1.mean,  tr[0].diff,      tr[0].t,       tr[0].df,     tr[0].p_greater,
                                     tr[1].t, tr[1].df, tr[1].p_greater, tr[1].diff_lo, tr[1].diff_hi};
            for (int q = 0; q < 11; q++) {
                fputc(',', csv);
                asp__report_csv_num(csv, nums[q]);
            }
            fputc('\n', csv);
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "compared", grade_b ? "grade_b" : "improvement");
            cJSON_AddStringToObject(o, "control", "control");
            cJSON_AddStringToObject(o, "variable", g[k].name);
            cJSON_AddItemToObject(o, "pooled", asp__report_json_ttest(&tr[0]));
            cJSON_AddItemToObject(o, "welch", asp__report_json_ttest(&tr[1]));
            cJSON_AddItemToArray(tests, o);
        }
}

/* Every subject's improvement (dots, group k at x = k + 1) and each group's mean with its interval. */
static void improvement_chart(struct report *r, const char *test, const struct nav_group *g, size_t ng,
                              const asp_stats_summary *si)
{
    size_t total = 0;
    for (size_t k = 0; k < ng; k++)
        total += g[k].n;
    if (!ng || !total)
        return;
    double *xs = malloc(total * sizeof *xs), *ys = malloc(total * sizeof *ys);
    double mx[MAX_GROUPS], my[MAX_GROUPS], me[MAX_GROUPS];
    if (!xs || !ys) {
        free(xs);
        free(ys);
        r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory");
        return;
    }
    size_t np = 0;
    char title[200], legend[64], name[64];
    const char *groups[MAX_GROUPS]; // the x axis names each group: "control", "variable points", ...
    snprintf(title, sizeof title, "%s: grade improvement from run A to run B, per group", test);
    for (size_t k = 0; k < ng; k++) {
        groups[k] = g[k].name;
        for (size_t q = 0; q < g[k].n; q++) {
            xs[np] = (double)(k + 1) - 0.1;
            ys[np++] = g[k].imp[q];
        }
        double lo, hi;
        asp_stats_mean_interval(&si[k], r->a->level, &lo, &hi);
        mx[k] = (double)(k + 1) + 0.1;
        my[k] = si[k].mean;
        me[k] = isfinite(lo) ? 0.5 * (hi - lo) : 0;
    }
    snprintf(legend, sizeof legend, "mean, %g%% interval", 100 * r->a->level);
    snprintf(name, sizeof name, "grades_%s.png", test);
    const asp_chart_series series[2] = {{.name = "subjects", .x = xs, .y = ys, .count = np},
                                        {.name = legend, .x = mx, .y = my, .count = ng}};
    const double *errs[2] = {NULL, me};
    fprintf(r->md, "\n![%s: improvement per group](%s)\n\n", test, name);
    asp__report_save_chart(r, series, 2,
                           &(asp_chart_desc){.width = 640,
                                             .height = 380,
                                             .title = title,
                                             .x_label = "group (by run B's condition)",
                                             .y_label = "improvement B - A (grade, % points)",
                                             .flags = ASP_CHART_MARKERS | ASP_CHART_X_INTEGER,
                                             .y_err = errs,
                                             .x_categories = groups,
                                             .x_category_count = ng},
                           name);
    free(xs);
    free(ys);
}

static void section_navigation_test(struct report *r, const char *test, cJSON *nav)
{
    struct nav_group g[MAX_GROUPS];
    memset(g, 0, sizeof g);
    cJSON *tj = cJSON_AddObjectToObject(nav, test);
    size_t ng = collect_groups(r, test, g, cJSON_AddArrayToObject(tj, "subjects"));
    if (!r->rc) {
        asp_stats_summary si[MAX_GROUPS];
        grade_tables(r, test, g, ng, tj, si);
        paired_tests(r, g, ng, si, tj);
        control_tests(r, test, g, ng, si, tj);
        improvement_chart(r, test, g, ng, si);
    }
    release_groups(g, ng);
}

void asp__report_navigation(struct report *r)
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
