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

#include "stats/report_internal.h"
#include "util/json_file.h"
#include "util/regular_file.h"
#include "util/banned.h"

static const char *const file_names[F_COUNT] = {"report.md",       "logs.csv",       "frame_time.csv",
                                                "recognition.csv", "navigation.csv", "improvement.csv"};

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
    fprintf(md,
            "## Logs\n\n%zu logs of %zu subjects, %zu frames; **%zu frames lost** in %zu logs "
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
        fprintf(md, "| %s | %s | %s | %s | %s | %zu | %zu | %zu | %s | %s | %s | %s |\n", l->subject, l->group, l->test,
                l->run, l->condition, l->frame_count, l->lost_frames, l->first_lost_line,
                asp__report_cell(b3, sizeof b3, mean_ms, 2),
                asp__report_cell(b1, sizeof b1, run->navigation ? 100 * run->grade.grade : NAN, 1),
                asp__report_cell(b2, sizeof b2, run->naming.answered ? run->naming.naming_s : NAN, 2),
                run->navigation        ? ""
                : run->naming.answered ? (run->naming.correct ? "yes" : "no")
                                       : "no answer");
        const char *strs[6] = {l->file, l->subject, l->group, l->test, l->run, l->condition};
        for (int k = 0; k < 6; k++) {
            asp__report_csv_str(csv, strs[k]);
            fputc(',', csv);
        }
        fprintf(csv, "%zu,%zu,%zu,%zu,%zu,", l->frame_count, l->lost_frames, l->first_lost_line, l->ignored_lines,
                l->event_count);
        asp__report_csv_num(csv, mean_ms);
        fputc(',', csv);
        asp__report_csv_num(csv, run->navigation ? run->grade.grade : NAN);
        fprintf(csv, ",%zu,%zu,%zu,%zu,%zu,", run->grade.moving, run->grade.along, run->grade.away,
                run->grade.backwards, run->grade.out);
        asp__report_csv_num(csv, run->naming.recognition_s);
        fputc(',', csv);
        asp__report_csv_num(csv, run->naming.naming_s);
        fputc(',', csv);
        asp__report_csv_str(csv, run->naming.answer);
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
    fprintf(r->md,
            "# Experiment report\n\nStudy `%s` (written by amgsplat %s), analysed by amgsplat %s. Intervals "
            "at %g%%.\n\n",
            a->dir, a->study_version[0] ? a->study_version : "of unknown version", ASP_VERSION_STRING, 100 * a->level);
    if (isfinite(a->study_seed))
        fprintf(r->md, "Study seed: %.0f.\n\n", a->study_seed);
    fprintf(r->md,
            "answers.jsonl: %zu answers, %zu lines cut off, %zu disagreeing with the logs' events (the logs "
            "are used).\n\n",
            a->answers, a->answers_lost, a->answers_mismatch);
}

int asp_stats_report_write(const asp_stats_analysis *a, const char *report_dir, asp_error *err)
{
    ASP_ASSERT(a && report_dir);
    int rc = asp__dir_ensure(report_dir, "report directory", err);
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
            asp__report_frame_time(&r);
        if (!r.rc)
            asp__report_recognition(&r);
        if (!r.rc)
            asp__report_navigation(&r);
    }
    if (!r.rc) {
        char path[4096];
        snprintf(path, sizeof path, "%s/report.json", report_dir);
        r.rc = asp__json_save(r.root, path, err);
    } else {
        cJSON_Delete(r.root);
    }
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
