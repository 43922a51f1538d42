/*
 * amgsplat experiment: the perceptual experiment of seed 004 chapters 2 and 4.
 * `run` administers the tests (to a person at a window or to the machine
 * observer) and logs every frame; `analyze` and `ttest` (their own files) grade
 * and compare. This file is the dispatcher and the `run` options.
 */
static const char usage[] =
    "usage: amgsplat experiment run --observer [--subjects N] | --subject ID [--practice]  -o DIR [options]\n"
    "       amgsplat experiment analyze DIR -o REPORT   (see 'amgsplat experiment analyze -h')\n"
    "       amgsplat experiment ttest N1,MEAN1,SD1 N2,MEAN2,SD2\n"
    "\n"
    "run: the four tests of seed 004 2.3 (far and near object recognition, low-speed\n"
    "navigation on a terrain path, high-speed flight through a canyon) in a seeded random\n"
    "order per subject, each twice: run A polygons, run B polygons (control group) or the\n"
    "subject's variable condition (points, primitives; blank with --conditions). Subjects go\n"
    "to the groups in seeded blocks (control + each condition: 3 subjects = one each); a\n"
    "subject count that cannot be balanced is warned about on stderr and in study.json.\n"
    "Every frame goes to DIR/<subject>/<test>-<A|B>.jsonl (docs/experiment-log.md),\n"
    "answers to DIR/<subject>/answers.jsonl. Scenes come from --scenes FILE (the defaults\n"
    "are written to DIR/scenes.json); derived points and primitives are cached in\n"
    "DIR/scenes (or --cache). --observer replaces the person with a program that sees\n"
    "only the rendered frames; the same --seed gives the same logs apart from frame_ms\n"
    "and timestamps. A subject directory with logs is refused unless --resume.";

#include <stdio.h>
#include <string.h>

#include "amgsplat/experiment.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

struct run_table {
    struct cli_env *env;
    size_t rows;
    cJSON *rows_json; /* --json: one object per run */
};

static void on_log(void *user, const char *line)
{
    struct run_table *t = user;
    cli_info(t->env, "%s", line);
}

/* an unbalanced design: on stderr even with -q, as a result the user has to know about */
static void on_warn(void *user, const char *line)
{
    struct run_table *t = user;
    fprintf(stderr, "amgsplat %s: warning: %s\n", t->env->cmd ? t->env->cmd : "experiment run", line);
}

static void on_run(void *user, const asp_experiment_run_result *r)
{
    struct run_table *t = user;
    int recog = r->test <= ASP_EXPERIMENT_NEAR;
    if (t->env->json) {
        /* one array printed at the end (cli_json_print); a row that cannot be built makes it NULL */
        cJSON *o = cJSON_CreateObject();
        if (o) {
            cJSON_AddStringToObject(o, "subject", r->subject);
            cJSON_AddStringToObject(o, "test", asp_experiment_test_name(r->test));
            cJSON_AddStringToObject(o, "run", r->run == 'A' ? "A" : "B");
            cJSON_AddStringToObject(o, "condition", asp_experiment_condition_name(r->condition));
            cJSON_AddStringToObject(o, "group", r->variable ? "variable" : "control");
            cJSON_AddNumberToObject(o, "frames", (double)r->frames);
            cJSON_AddItemToObject(o, "mean_frame_ms", cli_json_number("%.4f", r->mean_frame_ms));
            cJSON_AddNumberToObject(o, "drawn", (double)r->drawn);
            if (recog) {
                cJSON_AddStringToObject(o, "answer", r->answer);
                cJSON_AddBoolToObject(o, "correct", r->correct);
                cJSON_AddItemToObject(o, "recognition_s", cli_json_number("%.4f", r->recognition_s));
                cJSON_AddItemToObject(o, "naming_s", cli_json_number("%.4f", r->naming_s));
            } else {
                cJSON_AddItemToObject(o, "progress", cli_json_number("%.4f", r->progress));
                cJSON_AddNumberToObject(o, "off_path", (double)r->off_path);
            }
        }
        if (!o || !t->rows_json || !cJSON_AddItemToArray(t->rows_json, o)) {
            cJSON_Delete(o);
            cJSON_Delete(t->rows_json);
            t->rows_json = NULL;
        }
    } else {
        if (!t->rows)
            printf("subject  test       run  condition   frames  frame_ms    drawn  result\n");
        printf("%-8s %-10s %c    %-10s %7zu %9.2f %8zu  ", r->subject, asp_experiment_test_name(r->test), r->run,
               asp_experiment_condition_name(r->condition), r->frames, r->mean_frame_ms, r->drawn);
        if (recog)
            printf("answer %s (%s), recognised %.2f s, named %.2f s\n", r->answer, r->correct ? "right" : "wrong",
                   r->recognition_s, r->naming_s);
        else
            printf("progress %.1f%%, %zu %s\n", 100.0 * r->progress, r->off_path,
                   r->test == ASP_EXPERIMENT_HIGHSPEED ? "collisions" : "off path");
    }
    if (!t->env->json)
        fflush(stdout);
    t->rows++;
}

static int parse_conditions(struct cli_env *env, const char *text, asp_experiment_condition *out, size_t *n)
{
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return cli_usage_error(env, "--conditions is too long");
    snprintf(buf, sizeof buf, "%s", text);
    *n = 0;
    for (char *s = buf; s && *s;) {
        char *comma = strchr(s, ',');
        if (comma)
            *comma = 0;
        asp_error err = {0};
        if (*n >= ASP_EXPERIMENT_CONDITION_COUNT || asp_experiment_condition_parse(s, &out[*n], &err) ||
            out[*n] == ASP_EXPERIMENT_POLYGONS)
            return cli_usage_error(env, "--conditions takes points, primitives and blank, comma-separated; got '%s'",
                                   s);
        (*n)++;
        s = comma ? comma + 1 : NULL;
    }
    return *n ? 0 : cli_usage_error(env, "--conditions is empty");
}

static int cmd_experiment_run(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *scenes = NULL, *cache = NULL, *subject = NULL, *conditions = NULL, *group = NULL,
               *size = NULL, *shots = NULL, *keys = NULL;
    size_t subjects = 0, seed = 1, depth = 0, number = 0;
    int observer = 0, short_tests = 0, resume = 0, practice = 0, adapt = 0, realtime = 0;
    double tau = 0.0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "DIR", "study directory (logs, study.json, scenes.json)"},
        {"observer", 0, CLI_FLAG, &observer, NULL, "the machine observer instead of a person (headless)"},
        {"subjects", 'n', CLI_SIZE, &subjects, "N", "observer: simulated subjects S01..SNN (default 1)"},
        {"subject", 0, CLI_STRING, &subject, "ID", "person: the subject's id (letters, digits, - and _)"},
        {"subject-number", 0, CLI_SIZE, &number, "K", "person: place 1..999 in the design (its group; default 1)"},
        {"seed", 0, CLI_SIZE, &seed, "S", "seed of the design and the observer (default 1)"},
        {"scenes", 0, CLI_STRING, &scenes, "FILE", "scene file (JSON, see docs/cli/experiment.md)"},
        {"cache", 0, CLI_STRING, &cache, "DIR", "cache of sampled points and primitives (default DIR/scenes)"},
        {"conditions", 0, CLI_STRING, &conditions, "LIST", "variable group's conditions (default points,primitives)"},
        {"group", 0, CLI_STRING, &group, "G",
         "balanced (default: blocks over control + conditions), control, variable or random (per test)"},
        {"coarse", 0, CLI_DOUBLE, &tau, "PX", "points: octree cut tolerance in pixels (default 1; e.g. 8 = coarse)"},
        {"depth", 0, CLI_SIZE, &depth, "K", "points: deepest octree level drawn (seed 004 3.2.5; coarse cut)"},
        {"adapt", 0, CLI_FLAG, &adapt, NULL, "points: seed 004 3.2.5 depth control by frame time"},
        {"realtime", 0, CLI_FLAG, &realtime, NULL, "observer: step by the measured frame time (not reproducible)"},
        {"short", 0, CLI_FLAG, &short_tests, NULL, "short runs and smaller scenes (tests, CI)"},
        {"size", 0, CLI_STRING, &size, "WxH", "frame size (default 160x120 for the observer)"},
        {"screenshots", 0, CLI_STRING, &shots, "DIR", "PNG of every test in every condition"},
        {"resume", 0, CLI_FLAG, &resume, NULL, "add the missing runs to existing subject directories"},
        {"practice", 0, CLI_FLAG, &practice, NULL, "person: practice walking and flying first (not logged)"},
        {"keys", 0, CLI_STRING, &keys, "KEYS", "person: scripted keys, one per frame (tests; docs/cli/experiment.md)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 0)
        return cli_usage_error(env, "unexpected argument '%s'; see 'amgsplat experiment run -h'", argv[0]);
    if (!output)
        return cli_usage_error(env, "missing -o DIR");
    if (observer == !!subject)
        return cli_usage_error(env, "give either --observer or --subject ID");
    if (keys && !subject)
        return cli_usage_error(env, "--keys scripts a person's session (--subject ID)");
    if (number && !subject)
        return cli_usage_error(env, "--subject-number places a person (--subject ID); the observer numbers S01..");
    if (number > 999)
        return cli_usage_error(env, "--subject-number expects 1..999, got %zu", number);
    if (subject && subjects)
        return cli_usage_error(env, "--subjects is for the observer; a person is one --subject");
    if (tau < 0.0 || tau > 1024.0)
        return cli_usage_error(env, "--coarse expects 0..1024 pixels, got %g", tau);
    if (depth > 64)
        return cli_usage_error(env, "--depth expects 0..64, got %zu", depth);
    asp_experiment_desc d = {.depth_limit = (uint32_t)depth, .output_dir = output, .scenes_path = scenes, .cache_dir = cache, .seed = seed,
                             .observer = observer, .subjects = subjects, .subject = subject,
                             .short_tests = short_tests, .resume = resume, .practice = practice,
                             .coarse_tau = (float)tau, .adapt = adapt, .realtime = realtime,
                             .screenshots_dir = shots, .keys = keys,
                             .subject_number = number};
    asp_experiment_condition conds[ASP_EXPERIMENT_CONDITION_COUNT];
    size_t nconds = 0;
    if (conditions) {
        if (parse_conditions(env, conditions, conds, &nconds))
            return 2;
        d.variable = conds;
        d.variable_count = nconds;
    }
    if (group) {
        if (strcmp(group, "balanced") == 0)
            d.group_rule = ASP_EXPERIMENT_GROUP_BALANCED;
        else if (strcmp(group, "random") == 0)
            d.group_rule = ASP_EXPERIMENT_GROUP_RANDOM;
        else if (strcmp(group, "control") == 0)
            d.group_rule = ASP_EXPERIMENT_GROUP_CONTROL;
        else if (strcmp(group, "variable") == 0)
            d.group_rule = ASP_EXPERIMENT_GROUP_VARIABLE;
        else
            return cli_usage_error(env, "--group expects balanced, control, variable or random, got '%s'", group);
    }
    if (size) {
        unsigned w = 0, h = 0;
        if (cli_parse_size2(size, &w, &h) || w < 32 || h < 32 || w > 4096 || h > 4096)
            return cli_usage_error(env, "--size expects WxH with 32..4096 pixels a side, got '%s'", size);
        d.width = w;
        d.height = h;
    }
    struct run_table table = {.env = env, .rows_json = env->json ? cJSON_CreateArray() : NULL};
    d.on_run = on_run;
    d.log = on_log;
    d.warn = on_warn;
    d.user = &table;
    asp_error err = {0};
    rc = asp_experiment_run(&d, &env->ctx, &err);
    asp_amg_shutdown(); // the primitives' decomposition may have started MPI (once per process)
    if (rc) {
        cJSON_Delete(table.rows_json);
        return cli_fail(env, &err);
    }
    return env->json ? cli_json_print(env, table.rows_json) : 0;
}

int cmd_experiment(int argc, char **argv, struct cli_env *env)
{
    if (argc < 2 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        FILE *fp = argc < 2 ? stderr : stdout;
        fprintf(fp, "%s\n", usage);
        return argc < 2 ? 2 : 0;
    }
    const char *sub = argv[1];
    if (strcmp(sub, "run") == 0) {
        env->cmd = "experiment run";
        return cmd_experiment_run(argc - 1, argv + 1, env);
    }
    if (strcmp(sub, "analyze") == 0) {
        env->cmd = "experiment analyze";
        return cmd_experiment_analyze(argc - 1, argv + 1, env);
    }
    if (strcmp(sub, "ttest") == 0) {
        env->cmd = "experiment ttest";
        return cmd_experiment_ttest(argc - 1, argv + 1, env);
    }
    return cli_usage_error(env, "unknown subcommand '%s' (expected run, analyze, ttest)", sub);
}
