/*
 * Statistics of the perceptual experiment (seed 004 sections 2.3-2.4 and
 * chapter 4): sample summaries, the pooled two-sample t test the seed uses and
 * Welch's test, 95% confidence intervals, the direction grading of the
 * navigation tests (Figs 2.1-2.2), the reader of the experiment logs
 * (docs/experiment-log.md) and the analysis that writes the report of
 * `amgsplat experiment analyze`. No GL: built in every configuration.
 */
#ifndef AMGSPLAT_STATS_H
#define AMGSPLAT_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* Summaries and t tests (src/stats/summary.c, src/stats/ttest.c)           */
/* ------------------------------------------------------------------------ */

/** The columns of seed 004 Tables 4.1 and 4.3-4.7 for one sample. */
typedef struct asp_stats_summary {
    size_t n;
    double mean, median, min, max;
    double sd; /* sample standard deviation (divisor n - 1); 0 when n < 2 */
} asp_stats_summary;

/**
 * Summarises x[0..n) (GSL: mean, sd, median of a sorted copy). Non-finite
 * values are refused. n == 0 gives n = 0 and NaN elsewhere (an empty cell of a
 * table, not an error). Returns 0, ASP_EINVAL (a NaN or infinity, naming its
 * index) or ASP_ENOMEM; out unchanged on failure. Thread safe.
 */
int asp_stats_summarize(const double *x, size_t n, asp_stats_summary *out, asp_error *err);

/** Options of asp_stats_ttest; the zero value means the seed's test at 95%. */
typedef struct asp_ttest_desc {
    int welch;    /* 0: pooled variance, df = n1 + n2 - 2 (seed 004 4.2); 1: Welch-Satterthwaite */
    double level; /* confidence level of the intervals in (0, 1); 0 = 0.95 */
} asp_ttest_desc;

/** Result of a two-sample t test of mean1 - mean2. */
typedef struct asp_ttest_result {
    int welch;
    double diff;                   /* mean1 - mean2 */
    double se;                     /* standard error of diff */
    double t, df;                  /* df is fractional for Welch */
    double p_greater;              /* one-sided, alternative mean1 > mean2: P(T >= t) */
    double p_less;                 /* one-sided, alternative mean1 < mean2: P(T <= t) */
    double p_one;                  /* one-sided in the direction of the observed difference: min(p_greater, p_less) */
    double p_two;                  /* two-sided */
    double level;                  /* confidence level of the intervals */
    double diff_lo, diff_hi;       /* interval of mean1 - mean2 (with this test's se and df) */
    double mean_lo[2], mean_hi[2]; /* interval of each mean, t with n - 1 df (NaN when n < 2) */
} asp_ttest_result;

/**
 * Two-sample t test from summary figures: only n, mean and sd of a and b are
 * read, so the seed's tables can be re-checked from what they print. The t
 * distribution is GSL's (gsl_cdf_tdist_Q / _Pinv). Returns 0, ASP_EINVAL (a
 * non-finite figure, a negative sd, n1 + n2 < 3 pooled or an n < 2 for Welch)
 * or ASP_EDEGENERATE (standard error 0: both sd 0); out unchanged on failure.
 * Thread safe.
 */
int asp_stats_ttest(const asp_stats_summary *a, const asp_stats_summary *b, const asp_ttest_desc *desc,
                    asp_ttest_result *out, asp_error *err);

/**
 * One-sample t test of a's mean against mu: t = (mean - mu) / (sd / sqrt(n)),
 * df = n - 1. On the per-subject differences B - A it is the paired test of
 * seed 004 2.3 within one group (did run B differ from run A?). out->diff is
 * mean - mu, the interval is that of mean - mu, mean_lo/hi[0] that of the mean
 * and [1] NaN; desc->welch is ignored. Returns 0, ASP_EINVAL (n < 2, a
 * non-finite figure, negative sd) or ASP_EDEGENERATE (sd 0). Thread safe.
 */
int asp_stats_ttest_one(const asp_stats_summary *a, double mu, const asp_ttest_desc *desc, asp_ttest_result *out,
                        asp_error *err);

/** What asp_stats_ttest_json writes beside the result; the zero value means a two-sample test alone. */
typedef struct asp_ttest_json_desc {
    const char *test;                 /* the "test" name; NULL = "welch" or "pooled" from the result */
    int one_sample;                   /* the result is asp_stats_ttest_one's: "mu" is written */
    double mu;                        /* one sample: the mean it was tested against */
    const asp_stats_summary *samples; /* NULL, or the 1 (one sample) or 2 samples tested: n, mean, sd, mean_ci */
} asp_ttest_json_desc;

struct cJSON;

/**
 * The one JSON object of a t test, written by `experiment ttest --json` and in
 * every test of `experiment analyze`'s report.json (docs/experiment-analysis.md
 * lists the keys): "test", "mu" (one sample), "samples" (when given), "diff",
 * "se", "t", "df", "p_one", "p_greater", "p_less", "p_two", "level",
 * "diff_ci"; a NaN figure (a test that could not be made) is null. Returns 0
 * and *out, a new cJSON object the caller owns (cJSON_Delete), or ASP_ENOMEM
 * with *out unchanged. Thread safe.
 */
int asp_stats_ttest_json(const asp_ttest_result *r, const asp_ttest_json_desc *desc, struct cJSON **out,
                         asp_error *err);

/**
 * The level interval of a mean from its summary: mean +- t_{(1+level)/2, n-1}
 * sd / sqrt(n); *lo = *hi = NaN when n < 2 or level is outside (0, 1). Pure.
 */
void asp_stats_mean_interval(const asp_stats_summary *s, double level, double *lo, double *hi);

/* ------------------------------------------------------------------------ */
/* Navigation grading (src/stats/grade.c; seed 004 2.4, Figs 2.1-2.2)       */
/* ------------------------------------------------------------------------ */

/** Why a step scored what it did. */
typedef enum asp_grade_verdict {
    ASP_GRADE_STILL = 0,     /* no movement in the ground plane: not graded */
    ASP_GRADE_ALONG = 1,     /* along the path or toward its centre: 100% */
    ASP_GRADE_AWAY = 2,      /* away from the centre: cosine to the optimal direction, 0..100% */
    ASP_GRADE_BACKWARDS = 3, /* more than 90 degrees from the optimal direction: 0% */
    ASP_GRADE_OUT = 4        /* beyond half_width from the centre line: 0% */
} asp_grade_verdict;

/**
 * Grades one step from `from` to `to` (world xyz, y up) against the path's
 * centre polyline path[0..3*count) (start to goal, count >= 2) with half width
 * half_width > 0. Grading is in the ground plane (x, z): the nearest segment
 * to `from` gives the path direction t; the optimal direction is t turned
 * toward the centre line by the fraction d / half_width of the distance d
 * (g = normalize(t + (d / half_width) c), c the unit vector toward the
 * centre). Moving along t or toward the centre scores 1; moving away scores
 * (u . g) / (t . g), the cosine to g scaled so that straight along t is 1,
 * falling to 0 at perpendicular to g; backwards (u . g <= 0) and `to` out of
 * bounds score 0. Returns the score in [0, 1], or -1 for a step without
 * movement; *verdict (may be NULL) says which rule applied. Pure.
 */
double asp_stats_grade_step(const float *path, size_t count, double half_width, const double from[3],
                            const double to[3], asp_grade_verdict *verdict);

/** A run's grade (seed 004 2.4: the mean over the samples that show movement). */
typedef struct asp_grade_result {
    double grade;                       /* mean score of the moving steps, 0..1; 0 when the track has
                                           frames but never moved; NaN for fewer than 2 frames */
    size_t moving;                      /* steps graded */
    size_t along, away, backwards, out; /* steps by verdict */
} asp_grade_result;

/**
 * Grades the track pos[0..3*n) (consecutive frame positions) step by step
 * with asp_stats_grade_step. Returns 0 or ASP_EINVAL (count < 2, half_width
 * not positive and finite, a non-finite coordinate naming its frame); out
 * unchanged on failure. Thread safe.
 */
int asp_stats_grade_track(const float *path, size_t count, double half_width, const double *pos, size_t n,
                          asp_grade_result *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Experiment logs (src/stats/log_read.c; format in docs/experiment-log.md) */
/* ------------------------------------------------------------------------ */

/** One frame line. */
typedef struct asp_stats_frame {
    double t;        /* seconds since the start of the run */
    double frame_ms; /* frame time */
    double pos[3], dir[3];
    double drawn;    /* primitives drawn (triangles, points or primitives) */
    int moving_keys; /* the input state was not empty */
} asp_stats_frame;

/** One event line. */
typedef struct asp_stats_event {
    double t;
    char what[16]; /* recognised, answer, off_path, collision, abort, end */
    char text[64];
} asp_stats_event;

/** A whole log, one subject, test and run. */
typedef struct asp_stats_log {
    char file[512];
    char subject[64], group[16], test[16], run[4], condition[16], version[64], started[40];
    char answer_expected[64];
    uint64_t seed;
    int observer;
    unsigned screen[2];
    float *path; /* 3 * path_count, NULL when the header has none */
    size_t path_count;
    double half_width;                                      /* 0 when the header has none */
    double drawn_triangles, drawn_points, drawn_primitives; /* header "drawn" */
    asp_stats_frame *frames;
    size_t frame_count;
    asp_stats_event *events;
    size_t event_count;
    size_t lines;           /* lines read, the header included */
    size_t lost_frames;     /* lines cut off mid-way or unparsable: frames lost by a crash */
    size_t first_lost_line; /* 1-based line of the first lost one, 0 if none */
    size_t ignored_lines;   /* valid JSON objects of a type this reader does not know */
} asp_stats_log;

/**
 * Reads a log (JSON Lines, cJSON per line). The first line must be a header
 * with format "amgsplat-experiment-log 1"; otherwise ASP_EFORMAT naming the
 * file and line 1. A line that is not a complete JSON object (cut off by a
 * crash, or glued to the next by an append after one) counts as a lost frame,
 * never an error; a complete object glued behind a cut one is still read. A complete frame or event line missing a
 * required field is ASP_EFORMAT naming the file, line and field. Returns 0, ASP_EIO, ASP_EFORMAT or ASP_ENOMEM; on
 * failure log is zeroed. Release with asp_stats_log_release.
 */
int asp_stats_log_load(asp_stats_log *log, const char *path, asp_error *err);
/** Frees a log and zeroes it; safe on a zeroed log. */
void asp_stats_log_release(asp_stats_log *log);

/** Naming of one recognition run from its events (seed 004 2.3). */
typedef struct asp_stats_naming {
    int answered;         /* both "recognised" and "answer" events found */
    double recognition_s; /* t(recognised) */
    double naming_s;      /* t(answer) - t(recognised) */
    int correct;          /* answer equals answer_expected, ignoring case and surrounding blanks */
    char answer[64];
} asp_stats_naming;

/** Naming time and correctness of a recognition log (first recognised/answer pair). Pure. */
void asp_stats_log_naming(const asp_stats_log *log, asp_stats_naming *out);

/* ------------------------------------------------------------------------ */
/* The analysis of a study directory (src/stats/analyze.c, report.c)        */
/* ------------------------------------------------------------------------ */

typedef struct asp_stats_analysis asp_stats_analysis;

/** Options of asp_stats_analyze; the zero value means defaults. */
typedef struct asp_stats_analyze_desc {
    double level; /* confidence level of intervals; 0 = 0.95 */
    int all_runs; /* recognition: also count run A (seed 004 4.2 treats run A as practice) */
} asp_stats_analyze_desc;

/**
 * Reads every DIR/<subject>/<test>-<run>.jsonl (and answers.jsonl) of a
 * directory written by `amgsplat experiment run` and computes the tables of
 * seed 004 chapter 4. Returns 0, ASP_EIO (no such directory), ASP_EFORMAT (a
 * log without a valid header; the message names the file and line),
 * ASP_EDEGENERATE (no log found) or ASP_ENOMEM. *out is NULL on failure;
 * destroy with asp_stats_analysis_destroy.
 */
int asp_stats_analyze(const char *dir, const asp_stats_analyze_desc *desc, asp_stats_analysis **out, asp_error *err);
void asp_stats_analysis_destroy(asp_stats_analysis *a);

/** Counts of an analysis (for a CLI summary line). */
typedef struct asp_stats_analysis_info {
    size_t logs, subjects, frames, lost_frames, answers;
    size_t groups;             /* groups of the design (control, each variable condition) */
    char design_warning[512];  /* why the design is unbalanced (groups of unequal size, one missing); "" if not */
} asp_stats_analysis_info;
void asp_stats_analysis_info_get(const asp_stats_analysis *a, asp_stats_analysis_info *out);

/**
 * Writes the report into report_dir (created if missing): report.md,
 * report.json, CSV tables (logs.csv, frame_time.csv, recognition.csv,
 * navigation.csv, improvement.csv) and PNG charts (frame_time_vs_drawn.png,
 * drawn_<test>.png, grades_<test>.png). Each file appears atomically.
 * Returns 0, ASP_EIO or ASP_ENOMEM.
 */
int asp_stats_report_write(const asp_stats_analysis *a, const char *report_dir, asp_error *err);

#ifdef __cplusplus
}
#endif

#endif
