/*
 * The analysis of a study directory, shared by analyze.c (reading, grading)
 * and report.c (tables, charts). Not public API.
 */
#ifndef ASP_STATS_INTERNAL_H
#define ASP_STATS_INTERNAL_H

#include "amgsplat/stats.h"

enum { STATS_TESTS = 4 };
/* The order of seed 004 chapter 4 and of the log file names. */
extern const char *const asp__stats_tests[STATS_TESTS];

struct stats_run {
    asp_stats_log log;
    int navigation; /* the header has a path: graded */
    asp_grade_result grade;
    asp_stats_naming naming; /* recognition tests */
};

struct asp_stats_analysis {
    char dir[1024];
    double level;
    int all_runs;
    struct stats_run *runs; /* sorted by subject, test, run */
    size_t run_count;
    size_t subjects;
    size_t answers;          /* answers.jsonl lines read */
    size_t answers_lost;     /* answers.jsonl lines cut off */
    size_t answers_mismatch; /* answers whose naming time or correctness differs from the log's events */
    char study_version[64];
    double study_seed; /* NaN without study.json */
    /* the design as the logs show it (analyze.c): subjects per group, a group being run B's condition */
    struct stats_group {
        char name[16]; /* "control" (run B polygons), a condition, or "mixed" (group changed by test) */
        size_t subjects;
    } groups[8];
    size_t group_count;
    char design_warning[512]; /* "" when every group has as many subjects */
};

#endif
