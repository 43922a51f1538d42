/*
 * The experiment program of seed 004 2.3: for each subject the four tests in
 * a random order, each run twice (A polygons; B polygons or the subject's
 * group's condition, design.c), every frame logged (docs/experiment-log.md). The runs' input
 * comes from one source, a person at the window (window.c) or the machine
 * observer (observer_source.c); the trial loops (trial.c) are the same for both.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "experiment/internal.h"
#include "util/atomic_file.h"
#include "util/json_file.h"
#include "util/banned.h"

static void say(const exp_study *st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void say(const exp_study *st, const char *fmt, ...)
{
    if (!st->desc->log)
        return;
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    st->desc->log(st->desc->user, line);
}

/* paths under DIR: DIR is checked to be under 2048 bytes, so these never truncate */
static void pathf(char *dst, size_t cap, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void pathf(char *dst, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dst, cap, fmt, ap);
    va_end(ap);
}

static int make_dir(const char *path, asp_error *err)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST) {
        struct stat sb;
        if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
            return 0;
        return asp_error_set(err, ASP_EIO, "'%s' exists and is not a directory", path);
    }
    return asp_error_set(err, ASP_EIO, "cannot create directory '%s': %s", path, strerror(errno));
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* a recognition run's answer, one line of the subject's answers.jsonl */
static int append_answer(exp_run *r, const char *subject_dir, asp_error *err)
{
    char path[4200];
    pathf(path, sizeof path, "%s/answers.jsonl", subject_dir);
    exp_log a;
    int rc = asp__exp_log_open(&a, path, err);
    if (rc)
        return rc;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "subject", r->subject);
    cJSON_AddStringToObject(o, "test", asp_experiment_test_name(r->test));
    cJSON_AddStringToObject(o, "run", r->run == 'A' ? "A" : "B");
    cJSON_AddStringToObject(o, "condition", asp_experiment_condition_name(r->cond));
    cJSON_AddNumberToObject(o, "recognition_s", round(r->res.recognition_s * 1e6) / 1e6);
    cJSON_AddNumberToObject(o, "naming_s", round(r->res.naming_s * 1e6) / 1e6);
    cJSON_AddStringToObject(o, "answer", r->res.answer);
    cJSON_AddBoolToObject(o, "correct", r->res.correct);
    rc = asp__exp_log_write(&a, o, err);
    asp__exp_log_close(&a);
    return rc;
}

static int run_one(exp_study *st, const char *subject, size_t subject_index, const char *subject_dir,
                   asp_experiment_test test, char run, asp_experiment_condition cond, int variable,
                   asp_error *err)
{
    char path[4200];
    pathf(path, sizeof path, "%s/%s-%c.jsonl", subject_dir, asp_experiment_test_name(test), run);
    if (exists(path)) {
        /* only reachable with resume: a log is never rewritten or appended to twice */
        say(st, "%s %s-%c: log exists, kept", subject, asp_experiment_test_name(test), run);
        return 0;
    }
    exp_run r;
    memset(&r, 0, sizeof r);
    r.st = st;
    r.p = &st->prep[test];
    r.test = test;
    r.cond = cond;
    r.run = run;
    r.subject = subject;
    r.rng = asp__exp_stream(st->desc->seed, (uint64_t)subject_index + 1, 0x100u + 2u * (unsigned)test + (run == 'B'));
    snprintf(r.res.subject, sizeof r.res.subject, "%s", subject);
    r.res.test = test;
    r.res.run = run;
    r.res.condition = cond;
    r.res.variable = variable;
    int rc = asp__exp_log_open(&r.log, path, err);
    if (rc)
        return rc;
    rc = asp__exp_write_header(&r, variable, err);
    double t_end = 0.0;
    exp_source *src = st->source;
    if (!rc && src->ops->intro)
        rc = src->ops->intro(src, test, 0, err);
    if (!rc && !st->aborted)
        rc = test <= ASP_EXPERIMENT_NEAR ? asp__exp_trial_recognition(&r, err) : asp__exp_trial_navigation(&r, err);
    else if (!rc)
        rc = asp__exp_write_event(&r, 0.0, "abort", NULL, err);
    if (!rc) {
        t_end = src->fixed_step ? (double)r.res.frames * FIXED_DT : r.last_t;
        rc = asp__exp_write_event(&r, t_end, "end", NULL, err);
    }
    asp__exp_log_close(&r.log);
    if (!rc && test <= ASP_EXPERIMENT_NEAR && r.res.answer[0])
        rc = append_answer(&r, subject_dir, err);
    if (rc)
        return rc;
    r.res.mean_frame_ms = r.res.frames ? r.frame_ms_sum / (double)r.res.frames : 0.0;
    if (st->desc->on_run)
        st->desc->on_run(st->desc->user, &r.res);
    return 0;
}

/* ---------------------------------------------------------------- study setup */

static void add_design(cJSON *root, const asp_experiment_desc *d, const asp_experiment_design *des, size_t nsubjects);

static int write_study(exp_study *st, char subjects[][32], size_t nsubjects, const asp_experiment_design *des,
                       const char *path, asp_error *err)
{
    const asp_experiment_desc *d = st->desc;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "format", "amgsplat-study 1");
    cJSON_AddNumberToObject(root, "seed", (double)d->seed);
    cJSON_AddStringToObject(root, "version", ASP_VERSION_STRING);
    cJSON *subj = cJSON_AddArrayToObject(root, "subjects");
    for (size_t i = 0; i < nsubjects; i++)
        cJSON_AddItemToArray(subj, cJSON_CreateString(subjects[i]));
    cJSON *tests = cJSON_AddArrayToObject(root, "tests"), *conds = cJSON_AddArrayToObject(root, "conditions");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        cJSON_AddItemToArray(tests, cJSON_CreateString(asp_experiment_test_name((asp_experiment_test)t)));
    for (int c = 0; c < 3; c++)
        cJSON_AddItemToArray(conds, cJSON_CreateString(asp_experiment_condition_name((asp_experiment_condition)c)));
    cJSON_AddBoolToObject(root, "observer", d->observer != 0);
    if (des)
        add_design(root, d, des, nsubjects);
    cJSON *scenes = cJSON_AddObjectToObject(root, "scenes");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        const exp_prepared *p = &st->prep[t];
        cJSON *o = cJSON_AddObjectToObject(scenes, asp_experiment_test_name((asp_experiment_test)t));
        if (p->scene.kind == 0) {
            cJSON_AddStringToObject(o, "kind", "object");
            cJSON_AddStringToObject(o, "model", p->model_name);
            for (size_t c = 0; c < st->scenes.candidate_count; c++)
                if (strcmp(st->scenes.candidates[c].name, p->model_name) == 0)
                    cJSON_AddStringToObject(o, "file", st->scenes.candidates[c].model);
            cJSON_AddNumberToObject(o, "distance_radii", p->scene.distance_radii);
        } else {
            cJSON_AddStringToObject(o, "kind", p->scene.kind == 1 ? "terrain" : "canyon");
            cJSON_AddNumberToObject(o, "generator_seed", (double)p->scene.seed);
            cJSON_AddNumberToObject(o, "grid", p->scene.grid);
            cJSON_AddNumberToObject(o, "size", p->scene.size);
            cJSON_AddNumberToObject(o, "half_width", p->scene.half_width);
            cJSON_AddNumberToObject(o, "speed", p->scene.speed);
        }
        cJSON_AddNumberToObject(o, "triangles", (double)p->triangles);
        cJSON_AddNumberToObject(o, "points", (double)p->points);
        cJSON_AddNumberToObject(o, "primitives", (double)p->primitives);
        cJSON_AddNumberToObject(o, "points_tolerance_px", d->coarse_tau > 0.0f ? d->coarse_tau : 1.0);
        cJSON_AddNumberToObject(o, "points_depth_limit", d->depth_limit);
        cJSON_AddStringToObject(o, "points_file", p->points_file);
        cJSON_AddStringToObject(o, "primitives_file", p->dps_file);
    }
    return asp__json_save(root, path, err);
}

/* PNGs of every test in every condition from its start view, for the docs and for checking a lab's scenes */
static int write_screenshots(exp_study *st, asp_error *err)
{
    int rc = make_dir(st->desc->screenshots_dir, err);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT && !rc; t++) {
        exp_prepared *p = &st->prep[t];
        for (int c = 0; c < ASP_EXPERIMENT_CONDITION_COUNT && !rc; c++) {
            asp_camera cam;
            const uint8_t *bg = p->scene.kind ? asp__exp_sky : asp__exp_backdrop;
            if (p->scene.kind) {
                const asp_experiment_world *w = &p->world;
                float yaw = atan2f(w->path[3 * 6] - w->path[0], w->path[3 * 6 + 2] - w->path[2]);
                float eye[3] = {w->path[0], w->path[1] + p->scene.eye_height, w->path[2]};
                asp__exp_first_person(&cam, p->origin[c], eye, yaw, (t == ASP_EXPERIMENT_HIGHSPEED ? -8.0f : -14.0f) * DEG,
                             (float)st->width / (float)st->height, 1.5f * w->size);
            } else {
                asp__exp_object_camera(&cam, p, p->origin[c], 30.0f, 15.0f, p->scene.distance_radii,
                              (float)st->width / (float)st->height);
            }
            asp_image img = {0};
            double ms;
            size_t drawn;
            rc = asp__exp_draw(st, p, (asp_experiment_condition)c, &cam, bg, &img, &ms, &drawn, err);
            char path[4300];
            pathf(path, sizeof path, "%s/%s-%s.png", st->desc->screenshots_dir,
                     asp_experiment_test_name((asp_experiment_test)t),
                     asp_experiment_condition_name((asp_experiment_condition)c));
            if (!rc)
                rc = asp_image_save_png(&img, path, err);
            asp_image_release(&img);
        }
    }
    return rc;
}

static int subject_id_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= 32)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_'))
            return 0;
    }
    return 1;
}

static int has_logs(const char *dir)
{
    char path[4200];
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        for (int r = 0; r < 2; r++) {
            pathf(path, sizeof path, "%s/%s-%c.jsonl", dir, asp_experiment_test_name((asp_experiment_test)t),
                     r ? 'B' : 'A');
            if (exists(path))
                return 1;
        }
    pathf(path, sizeof path, "%s/answers.jsonl", dir);
    return exists(path);
}

/*
 * A person's practice, shown but not logged: a quarter of the walking test and
 * a quarter of the flight, each in polygons after its instruction screen, so
 * both kinds of navigation are tried before anything counts (seed 004 2.3 has
 * the learning effect measured by run A against run B, not by the first
 * contact with the keys); then a "practice over" screen, so the subject knows
 * the measured tests start. The same with --short (shorter runs).
 */
static int practice(exp_study *st, asp_error *err)
{
    static const asp_experiment_test kinds[2] = {ASP_EXPERIMENT_LOWSPEED, ASP_EXPERIMENT_HIGHSPEED};
    exp_source *src = st->source;
    int rc = 0;
    for (int k = 0; k < 2 && !rc && !st->aborted; k++) {
        exp_run r;
        memset(&r, 0, sizeof r);
        r.st = st;
        r.p = &st->prep[kinds[k]];
        r.test = kinds[k];
        r.cond = ASP_EXPERIMENT_POLYGONS;
        r.run = 'A';
        r.subject = "practice";
        say(st, "practice: %s (not recorded)", asp_experiment_test_name(kinds[k]));
        rc = src->ops->intro ? src->ops->intro(src, kinds[k], 1, err) : 0;
        if (!rc && !st->aborted) {
            rc = asp__exp_trial_navigation(&r, err); // r.log.fp NULL: nothing is written
            say(st, "practice: %s over, %zu frames, %.0f%% of the way", asp_experiment_test_name(kinds[k]),
                r.res.frames, 100.0 * r.res.progress);
        }
    }
    if (!rc && !st->aborted && src->ops->intro)
        rc = src->ops->intro(src, ASP_EXPERIMENT_LOWSPEED, 2, err);
    return rc;
}

static const char *group_name(asp_experiment_condition c)
{
    return c == ASP_EXPERIMENT_POLYGONS ? "control" : asp_experiment_condition_name(c);
}

static const char *rule_name(int rule)
{
    return rule == ASP_EXPERIMENT_GROUP_CONTROL    ? "control"
           : rule == ASP_EXPERIMENT_GROUP_VARIABLE ? "variable"
           : rule == ASP_EXPERIMENT_GROUP_RANDOM   ? "random"
                                                   : "balanced";
}

/* study.json's "design": the groups, how many subjects each got, and the warning when they differ */
static void add_design(cJSON *root, const asp_experiment_desc *d, const asp_experiment_design *des, size_t nsubjects)
{
    cJSON *o = cJSON_AddObjectToObject(root, "design");
    cJSON_AddStringToObject(o, "rule", rule_name(d->group_rule));
    cJSON *groups = cJSON_AddArrayToObject(o, "groups"), *counts = cJSON_AddObjectToObject(o, "runs_b");
    for (size_t i = 0; i < des->group_count; i++) {
        cJSON_AddItemToArray(groups, cJSON_CreateString(group_name(des->groups[i])));
        cJSON_AddNumberToObject(counts, group_name(des->groups[i]), (double)des->runs_b[des->groups[i]]);
    }
    cJSON_AddNumberToObject(o, "subjects", (double)nsubjects);
    cJSON_AddBoolToObject(o, "balanced", des->balanced);
    if (des->warning[0])
        cJSON_AddStringToObject(o, "warning", des->warning);
}

int asp_experiment_run(const asp_experiment_desc *desc, const asp_context *ctx, asp_error *err)
{
    ASP_ASSERT(desc);
    if (!desc->output_dir || !desc->output_dir[0] || strlen(desc->output_dir) >= 2048)
        return asp_error_set(err, ASP_EINVAL, "no output directory, or one over 2047 bytes");
    if ((desc->cache_dir && strlen(desc->cache_dir) >= 2048) ||
        (desc->screenshots_dir && strlen(desc->screenshots_dir) >= 2048))
        return asp_error_set(err, ASP_EINVAL, "cache or screenshot directory over 2047 bytes");
    if (!desc->observer && !desc->subject)
        return asp_error_set(err, ASP_EINVAL, "a person's session needs a subject id");
    size_t nsubjects = desc->subjects ? desc->subjects : 1;
    if (nsubjects > 999)
        return asp_error_set(err, ASP_EINVAL, "at most 999 subjects, got %zu", nsubjects);
    if (desc->subject && !subject_id_ok(desc->subject))
        return asp_error_set(err, ASP_EINVAL, "subject id '%s' must be 1..31 letters, digits, '-' or '_'",
                             desc->subject);
    if (desc->width > 4096 || desc->height > 4096 || (desc->width && desc->width < 32) ||
        (desc->height && desc->height < 32))
        return asp_error_set(err, ASP_EINVAL, "frame size must be 32..4096 pixels a side");
    static const asp_experiment_condition default_variable[2] = {ASP_EXPERIMENT_POINTS, ASP_EXPERIMENT_PRIMITIVES};
    const asp_experiment_condition *variable = desc->variable ? desc->variable : default_variable;
    size_t nvariable = desc->variable ? desc->variable_count : 2;
    if (desc->subject_number > 999)
        return asp_error_set(err, ASP_EINVAL, "subject number %zu is over 999", desc->subject_number);
    /* a person's session is one subject, placed in the design by its number; the observer's are 0..n-1 */
    size_t first_index = !desc->observer && desc->subject_number ? desc->subject_number - 1 : 0;
    asp_experiment_design design;
    int rc = asp_experiment_design_check(desc->seed, desc->observer ? nsubjects : first_index + 1, variable, nvariable,
                                         desc->group_rule, &design, err);
    if (rc)
        return rc;
    /* the person's sessions add up to a design only across sessions: the lab's numbering decides */
    if (desc->observer && !design.balanced) {
        if (desc->warn)
            desc->warn(desc->user, design.warning);
        else if (desc->log)
            desc->log(desc->user, design.warning);
    }

    char (*subjects)[32] = asp_calloc(ctx, nsubjects, 32);
    exp_study *st = asp_calloc(ctx, 1, sizeof *st);
    if (!subjects || !st) {
        asp_free(ctx, subjects);
        asp_free(ctx, st);
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    }
    if (desc->subject && nsubjects == 1)
        snprintf(subjects[0], 32, "%s", desc->subject);
    else
        for (size_t i = 0; i < nsubjects; i++)
            snprintf(subjects[i], 32, "S%02zu", i + 1);
    st->desc = desc;
    st->ctx = ctx;
    st->width = desc->width ? desc->width : desc->observer ? 160 : 1024;
    st->height = desc->height ? desc->height : desc->observer ? 120 : 640;

    char path[4200];
    rc = make_dir(desc->output_dir, err);
    pathf(path, sizeof path, "%s/study.json", desc->output_dir);
    int study_exists = exists(path);
    for (size_t i = 0; i < nsubjects && !rc && !desc->resume; i++) {
        char dir[4200];
        pathf(dir, sizeof dir, "%s/%s", desc->output_dir, subjects[i]);
        if (has_logs(dir))
            rc = asp_error_set(err, ASP_EINVAL,
                               "subject '%s' already has logs in '%s': a subject's answers are never overwritten "
                               "(--resume adds the missing runs)",
                               subjects[i], dir);
    }
    if (!rc) {
        if (desc->scenes_path)
            rc = asp_experiment_scenes_load(desc->scenes_path, &st->scenes, err);
        else
            asp_experiment_scenes_default(&st->scenes);
    }
    pathf(path, sizeof path, "%s/scenes.json", desc->output_dir);
    if (!rc && !exists(path))
        rc = asp_experiment_scenes_save(&st->scenes, path, err);
    if (desc->cache_dir)
        snprintf(st->cache_dir, sizeof st->cache_dir, "%s", desc->cache_dir);
    else
        snprintf(st->cache_dir, sizeof st->cache_dir, "%s/scenes", desc->output_dir);
    if (!rc)
        rc = make_dir(st->cache_dir, err);
    if (!rc)
        rc = desc->observer ? asp__exp_observer_open(st, &st->source, err) : asp__exp_person_open(st, &st->source, err);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT && !rc; t++) {
        say(st, "preparing %s", asp_experiment_test_name((asp_experiment_test)t));
        rc = asp__exp_prepare(&st->scenes, (asp_experiment_test)t, st->cache_dir, desc->short_tests, st->gl, desc,
                              ctx, &st->prep[t], err);
    }
    if (!rc && st->source->ops->ready)
        rc = st->source->ops->ready(st->source, err);
    pathf(path, sizeof path, "%s/study.json", desc->output_dir);
    if (!rc && !study_exists)
        rc = write_study(st, subjects, nsubjects, desc->observer ? &design : NULL, path, err);
    if (!rc && desc->screenshots_dir)
        rc = write_screenshots(st, err);
    if (!rc && !desc->observer && desc->practice)
        rc = practice(st, err);
    for (size_t s = 0; s < nsubjects && !rc && !st->aborted; s++) {
        asp_experiment_plan plan;
        char dir[4200];
        pathf(dir, sizeof dir, "%s/%s", desc->output_dir, subjects[s]);
        rc = make_dir(dir, err);
        size_t index = first_index + s;
        if (!rc)
            rc = asp_experiment_plan_draw(desc->seed, index, variable, nvariable, desc->group_rule, &plan, err);
        for (int k = 0; k < ASP_EXPERIMENT_TEST_COUNT && !rc && !st->aborted; k++) {
            asp_experiment_test t = plan.order[k];
            say(st, "%s %s: A polygons, B %s (group %s)", subjects[s], asp_experiment_test_name(t),
                asp_experiment_condition_name(plan.run_b[t]), group_name(plan.run_b[t]));
            rc = run_one(st, subjects[s], index, dir, t, 'A', ASP_EXPERIMENT_POLYGONS, plan.variable[t], err);
            if (!rc && !st->aborted)
                rc = run_one(st, subjects[s], index, dir, t, 'B', plan.run_b[t], plan.variable[t], err);
        }
    }
    if (!rc && st->aborted)
        say(st, "session stopped by Esc; what was recorded stays");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        asp__exp_prepared_release(&st->prep[t]);
    if (st->source)
        st->source->ops->close(st->source);
    asp_gl_context_destroy(st->gl);
    asp_free(ctx, st);
    asp_free(ctx, subjects);
    return rc;
}
