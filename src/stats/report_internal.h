/*
 * The report of `amgsplat experiment analyze`, shared by report*.c: the open
 * output files, the conditions found, and the formatting helpers every
 * section uses. Not public API.
 */
#ifndef ASP_STATS_REPORT_INTERNAL_H
#define ASP_STATS_REPORT_INTERNAL_H

#include <stdio.h>

#include <cjson/cJSON.h>

#include "amgsplat/eval.h"
#include "amgsplat/stats.h"
#include "stats/internal.h"
#include "util/atomic_file.h"

enum { MAX_CONDITIONS = 8, MAX_GROUPS = 8, HIST_BINS = 24, SCATTER_BINS = 16 };

/* The files written as the sections go; report.json is printed from root at the end. */
enum { F_MD, F_LOGS, F_FRAME, F_RECOG, F_NAV, F_IMPROVE, F_COUNT };

struct report {
    const asp_stats_analysis *a;
    const char *dir;
    asp__atomic_file f[F_COUNT];
    FILE *md;
    cJSON *root;
    const char *conditions[MAX_CONDITIONS]; /* polygons first */
    size_t ncond;
    asp_error *err;
    int rc; /* the first failure; later sections do nothing */
};

/* A CSV field, quoted when it holds a comma, quote or line break. */
void asp__report_csv_str(FILE *fp, const char *s);
/* A CSV number; an empty field for NaN. */
void asp__report_csv_num(FILE *fp, double v);
/* A Markdown table cell: v at prec decimals, or "-" for NaN. Returns buf. */
const char *asp__report_cell(char *buf, size_t cap, double v, int prec);
/* A p-value cell: 4 decimals, scientific below 1e-4. Returns buf. */
const char *asp__report_p_cell(char *buf, size_t cap, double p);
cJSON *asp__report_json_summary(const asp_stats_summary *s, double scale);
/* asp_stats_ttest_json of a two-sample test; NULL when out of memory */
cJSON *asp__report_json_ttest(const asp_ttest_result *r);
/* The pooled ([0]) and Welch ([1]) tests of a against b; a test that cannot be made has NaN fields. */
void asp__report_both_tests(const asp_stats_summary *a, const asp_stats_summary *b, double level,
                            asp_ttest_result out[2]);
/* Draws and saves REPORT_DIR/name; sets r->rc on failure. */
int asp__report_save_chart(struct report *r, const asp_chart_series *s, size_t n, const asp_chart_desc *d,
                           const char *name);
/*
 * The frame times (drawn = 0) or primitive counts (drawn = 1) of every frame of the logs with this
 * test (NULL = any) and condition; NULL when out of memory. free() it.
 */
double *asp__report_frame_values(const asp_stats_analysis *a, const char *test, const char *cond, int drawn, size_t *n);

/* The sections (seed 004 chapter 4), each writing Markdown, CSV and JSON. */
void asp__report_frame_time(struct report *r);  /* Table 4.1, Figs 4.1-4.5 (report_frame_time.c) */
void asp__report_recognition(struct report *r); /* Tables 4.2-4.3 (report_recognition.c) */
void asp__report_navigation(struct report *r);  /* Tables 4.4-4.7 (report_navigation.c) */

#endif
