/*
 * Object recognition in the experiment's report (seed 004 4.2): accuracy and
 * naming time per test and condition (Tables 4.2-4.3), each condition against
 * polygons with the pooled and Welch tests.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stats/report_internal.h"
#include "util/banned.h"

/* ---- recognition (Tables 4.2-4.3) ------------------------------------- */

static int counted_run(const asp_stats_analysis *a, const asp_stats_log *l)
{
    return a->all_runs || strcmp(l->run, "B") == 0;
}

void asp__report_recognition(struct report *r)
{
    const asp_stats_analysis *a = r->a;
    FILE *md = r->md, *csv = r->f[F_RECOG].fp;
    cJSON *rec = cJSON_AddObjectToObject(r->root, "recognition");
    cJSON_AddStringToObject(rec, "runs", a->all_runs ? "A and B" : "B");
    cJSON *rows = cJSON_AddArrayToObject(rec, "rows"), *tests = cJSON_AddArrayToObject(rec, "tests");
    char b[9][32];
    /* the logs' conditions and the design's groups nobody reached (study.json), so a missing one gets a row */
    const char *conds[2 * MAX_CONDITIONS];
    size_t ncond = 0;
    for (size_t c = 0; c < r->ncond; c++)
        conds[ncond++] = r->conditions[c];
    for (size_t g = 0; g < a->group_count; g++) {
        const char *name = a->groups[g].name;
        int known = strcmp(name, "control") == 0 || strcmp(name, "mixed") == 0;
        for (size_t c = 0; c < ncond && !known; c++)
            known = strcmp(conds[c], name) == 0;
        if (!known && ncond < 2 * MAX_CONDITIONS)
            conds[ncond++] = name;
    }
    fprintf(md,
            "## Object recognition (seed 004 Tables 4.2-4.3)\n\nRuns %s (seed 004 4.2 treats run A as practice). "
            "Naming time (seconds from Enter to the typed name) of the correct answers.\n\n"
            "| test | condition | correct | incorrect | no answer | %% correct | average s | median | minimum | "
            "maximum | sd |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            a->all_runs ? "A and B" : "B");
    fprintf(csv, "test,condition,correct,incorrect,unanswered,percent_correct,naming_n,naming_mean_s,"
                 "naming_median_s,naming_min_s,naming_max_s,naming_sd_s\n");
    for (int t = 0; t < 2; t++) {
        const char *test = asp__stats_tests[t];
        asp_stats_summary poly = {0}, seen[2 * MAX_CONDITIONS];
        const char *seen_cond[2 * MAX_CONDITIONS];
        size_t seen_runs[2 * MAX_CONDITIONS];
        size_t nseen = 0;
        int have_poly = 0;
        for (size_t c = 0; c < ncond; c++) {
            size_t correct = 0, wrong = 0, none = 0, n = 0;
            double *v = malloc((a->run_count + 1) * sizeof *v);
            if (!v) {
                r->rc = asp_error_set(r->err, ASP_ENOMEM, "out of memory");
                return;
            }
            for (size_t i = 0; i < a->run_count; i++) {
                const struct stats_run *run = &a->runs[i];
                if (strcmp(run->log.test, test) || strcmp(run->log.condition, conds[c]) ||
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
            if (correct + wrong + none == 0) {
                if (strcmp(conds[c], "polygons") != 0) { // in the study, not in this test's runs
                    seen_runs[nseen] = 0;
                    seen[nseen] = s;
                    seen_cond[nseen++] = conds[c];
                }
                continue;
            }
            double pct = correct + wrong ? 100.0 * (double)correct / (double)(correct + wrong) : NAN;
            fprintf(md, "| %s | %s | %zu | %zu | %zu | %s | %s | %s | %s | %s | %s |\n", test, conds[c],
                    correct, wrong, none, asp__report_cell(b[0], 32, pct, 0), asp__report_cell(b[1], 32, s.mean, 2),
                    asp__report_cell(b[2], 32, s.median, 2), asp__report_cell(b[3], 32, s.min, 2),
                    asp__report_cell(b[4], 32, s.max, 2), asp__report_cell(b[5], 32, s.n > 1 ? s.sd : NAN, 2));
            fprintf(csv, "%s,", test);
            asp__report_csv_str(csv, conds[c]);
            fprintf(csv, ",%zu,%zu,%zu,", correct, wrong, none);
            asp__report_csv_num(csv, pct);
            fprintf(csv, ",%zu", s.n);
            const double nums[5] = {s.mean, s.median, s.min, s.max, s.sd};
            for (int k = 0; k < 5; k++) {
                fputc(',', csv);
                asp__report_csv_num(csv, nums[k]);
            }
            fputc('\n', csv);
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "test", test);
            cJSON_AddStringToObject(o, "condition", conds[c]);
            cJSON_AddNumberToObject(o, "correct", (double)correct);
            cJSON_AddNumberToObject(o, "incorrect", (double)wrong);
            cJSON_AddNumberToObject(o, "unanswered", (double)none);
            cJSON_AddNumberToObject(o, "percent_correct", pct);
            cJSON_AddItemToObject(o, "naming_s", asp__report_json_summary(&s, 1));
            cJSON_AddItemToArray(rows, o);
            if (strcmp(conds[c], "polygons") == 0) {
                poly = s;
                have_poly = 1;
            } else {
                seen_runs[nseen] = correct + wrong + none;
                seen[nseen] = s;
                seen_cond[nseen++] = conds[c];
            }
        }
        /*
         * Every condition of the test gets its row against polygons, also when no test can be made:
         * the row then says why (no control run B, no correct answer, a single value on a side), as
         * an empty table cannot (issue 29: a 2-subject study whose runs B of a test were never
         * polygons and a condition at once left only the header).
         */
        for (size_t k = 0; k < nseen; k++) {
            asp_ttest_result tr[2];
            asp__report_both_tests(&seen[k], &poly, a->level, tr);
            const char *why = !seen_runs[k] ? "no counted run of this test showed this condition"
                              : !have_poly      ? "no counted polygons run in this test (no control subject)"
                              : poly.n == 0    ? "no correct answer with polygons"
                              : seen[k].n == 0 ? "no correct answer in this condition"
                              : seen[k].n + poly.n < 3 ? "one naming time on each side: difference only, no test"
                              : isnan(tr[1].t)         ? "a single naming time on a side: no Welch test"
                                                       : "";
            double diff = seen[k].n && poly.n ? seen[k].mean - poly.mean : NAN;
            cJSON *o2 = cJSON_CreateObject();
            cJSON_AddStringToObject(o2, "test", test);
            cJSON_AddStringToObject(o2, "condition", seen_cond[k]);
            cJSON_AddStringToObject(o2, "against", "polygons");
            cJSON_AddNumberToObject(o2, "n", (double)seen[k].n);
            cJSON_AddNumberToObject(o2, "n_polygons", (double)poly.n);
            cJSON_AddNumberToObject(o2, "diff", diff);
            if (why[0])
                cJSON_AddStringToObject(o2, "note", why);
            cJSON_AddItemToObject(o2, "pooled", asp__report_json_ttest(&tr[0]));
            cJSON_AddItemToObject(o2, "welch", asp__report_json_ttest(&tr[1]));
            cJSON_AddItemToArray(tests, o2);
        }
    }
    fprintf(md,
            "\nNaming time, condition minus polygons (correct answers of the counted runs; one-sided p in the "
            "direction of the difference; a dash where a test cannot be made, the note says why):\n\n"
            "| test | condition | n | n polygons | difference s | pooled t | df | p | Welch t | df | p | %g%% "
            "interval (Welch) | note |\n"
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n",
            100 * a->level);
    if (cJSON_GetArraySize(tests) == 0)
        fprintf(md, "| - | - | - | - | - | - | - | - | - | - | - | - | no condition but polygons in the study: "
                    "nothing to compare |\n");
    cJSON *it;
    cJSON_ArrayForEach (it, tests) {
        const cJSON *p = cJSON_GetObjectItem(it, "pooled"), *w = cJSON_GetObjectItem(it, "welch");
        const cJSON *ci = cJSON_GetObjectItem(w, "diff_ci"), *note = cJSON_GetObjectItem(it, "note");
        double pg = cJSON_GetObjectItem(p, "p_greater")->valuedouble,
               pl = cJSON_GetObjectItem(p, "p_less")->valuedouble;
        double wg = cJSON_GetObjectItem(w, "p_greater")->valuedouble,
               wl = cJSON_GetObjectItem(w, "p_less")->valuedouble;
        fprintf(md, "| %s | %s | %.0f | %.0f | %s | %s | %s | %s | %s | %s | %s | %s .. %s | %s |\n",
                cJSON_GetObjectItem(it, "test")->valuestring, cJSON_GetObjectItem(it, "condition")->valuestring,
                cJSON_GetObjectItem(it, "n")->valuedouble, cJSON_GetObjectItem(it, "n_polygons")->valuedouble,
                asp__report_cell(b[0], 32, cJSON_GetObjectItem(it, "diff")->valuedouble, 2),
                asp__report_cell(b[1], 32, cJSON_GetObjectItem(p, "t")->valuedouble, 3),
                asp__report_cell(b[2], 32, cJSON_GetObjectItem(p, "df")->valuedouble, 0),
                asp__report_p_cell(b[3], 32, pg < pl ? pg : pl),
                asp__report_cell(b[4], 32, cJSON_GetObjectItem(w, "t")->valuedouble, 3),
                asp__report_cell(b[5], 32, cJSON_GetObjectItem(w, "df")->valuedouble, 1),
                asp__report_p_cell(b[6], 32, wg < wl ? wg : wl),
                asp__report_cell(b[7], 32, cJSON_GetArrayItem(ci, 0)->valuedouble, 2),
                asp__report_cell(b[8], 32, cJSON_GetArrayItem(ci, 1)->valuedouble, 2),
                cJSON_IsString(note) ? note->valuestring : "");
    }
    fputc('\n', md);
}
