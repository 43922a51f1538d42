/*
 * amgsplat experiment analyze: the tables and charts of seed 004 chapter 4
 * from the logs of `amgsplat experiment run` (asp_stats_analyze,
 * asp_stats_report_write; docs/experiment-analysis.md).
 */
#include <stdio.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "amgsplat/stats.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat experiment analyze DIR -o REPORT_DIR [--level P] [--all-runs] [--json]\n"
    "\n"
    "Reads the logs DIR/<subject>/<test>-<A|B>.jsonl written by 'amgsplat experiment run' and\n"
    "writes REPORT_DIR/report.md, report.json, CSV tables and PNG charts: frame time\n"
    "per run (mean, median, p95 ms) and per test and condition, compared over run means (one\n"
    "value per run), and against primitives drawn (seed 004 Table 4.1, Figs 4.1-4.5), recognition\n"
    "accuracy and naming time (Tables 4.2-4.3), navigation grades and the improvement from run\n"
    "A to B per group (Tables 4.4-4.7) with the pooled t test, Welch's test, one-sided p and\n"
    "P-level intervals (default 0.95). A log cut off mid-line (a crash) still analyses: the\n"
    "report counts its lost frames. Recognition uses run B only, as the seed does (run A is\n"
    "practice); --all-runs counts both. Groups of unequal size are warned about on stderr and\n"
    "in the report.";

int cmd_experiment_analyze(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL;
    double level = 0.95;
    int all_runs = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "REPORT_DIR", "directory for the report (created if missing)"},
        {"level", 0, CLI_DOUBLE, &level, "P", "confidence level of the intervals, 0 < P < 1 (default 0.95)"},
        {"all-runs", 0, CLI_FLAG, &all_runs, NULL, "recognition tables from runs A and B (default: B)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one study directory, got %d; see 'amgsplat experiment analyze -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o REPORT_DIR");
    if (!(level > 0 && level < 1))
        return cli_usage_error(env, "--level expects a probability between 0 and 1, got %g", level);
    // the report beside the logs, not over them
    const char *inputs[1] = {argv[0]};
    if ((rc = cli_check_output(env, output, NULL, 1, inputs, 1)) != 0)
        return rc;
    asp_error err = {0};
    asp_stats_analysis *a = NULL;
    if (asp_stats_analyze(argv[0], &(asp_stats_analyze_desc){.level = level, .all_runs = all_runs}, &a, &err))
        return cli_fail(env, &err);
    if (asp_stats_report_write(a, output, &err)) {
        asp_stats_analysis_destroy(a);
        return cli_fail(env, &err);
    }
    asp_stats_analysis_info info;
    asp_stats_analysis_info_get(a, &info);
    asp_stats_analysis_destroy(a);
    // an unbalanced design weakens every comparison of the report: said even with -q
    if (info.design_warning[0])
        fprintf(stderr, "amgsplat experiment analyze: warning: %s\n", info.design_warning);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "dir", argv[0]);
        cJSON_AddStringToObject(o, "report", output);
        cJSON_AddNumberToObject(o, "logs", (double)info.logs);
        cJSON_AddNumberToObject(o, "subjects", (double)info.subjects);
        cJSON_AddNumberToObject(o, "frames", (double)info.frames);
        cJSON_AddNumberToObject(o, "lost_frames", (double)info.lost_frames);
        cJSON_AddNumberToObject(o, "answers", (double)info.answers);
        cJSON_AddNumberToObject(o, "groups", (double)info.groups);
        cJSON_AddBoolToObject(o, "balanced", info.design_warning[0] == 0);
        if (info.design_warning[0])
            cJSON_AddStringToObject(o, "design_warning", info.design_warning);
        if (cli_json_print(env, o))
            return 1;
    } else if (!env->quiet) {
        printf("%zu logs of %zu subjects, %zu frames, %zu frames lost; report in %s/report.md\n", info.logs,
               info.subjects, info.frames, info.lost_frames, output);
    }
    return 0;
}
