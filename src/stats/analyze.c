/*
 * Reading a study directory written by `amgsplat experiment run`
 * (docs/experiment-log.md): every DIR/<subject>/<test>-<run>.jsonl log, graded
 * (seed 004 2.4) or timed (2.3), and each subject's answers.jsonl checked
 * against the logs' own events.
 */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "amgsplat/stats.h"
#include "stats/internal.h"
#include "util/banned.h"
#include "util/regular_file.h"

const char *const asp__stats_tests[STATS_TESTS] = {"far", "near", "lowspeed", "highspeed"};

static int test_index(const char *name)
{
    for (int i = 0; i < STATS_TESTS; i++)
        if (strcmp(name, asp__stats_tests[i]) == 0)
            return i;
    return -1;
}

/* "<test>-<A|B>.jsonl" */
static int is_log_name(const char *name)
{
    const char *dash = strrchr(name, '-');
    if (!dash || strcmp(dash + 2, ".jsonl") != 0 || (dash[1] != 'A' && dash[1] != 'B'))
        return 0;
    char test[32];
    size_t n = (size_t)(dash - name);
    if (n >= sizeof test)
        return 0;
    memcpy(test, name, n);
    test[n] = 0;
    return test_index(test) >= 0;
}

/* dir/name into dst; -1 when it does not fit (such a path is refused, never cut short). */
static int join_path(char *dst, size_t cap, const char *dir, const char *name)
{
    int n = snprintf(dst, cap, "%s/%s", dir, name);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Sorted names of dir's entries that pass keep(); readdir's order is the file system's, not ours. */
static int list_dir(const char *dir, int (*keep)(const char *dir, const char *name), char ***out, size_t *count,
                    asp_error *err)
{
    DIR *d = opendir(dir);
    if (!d)
        return asp_error_set(err, ASP_EIO, "cannot open directory '%s'", dir);
    char **names = NULL;
    size_t n = 0, cap = 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.' || !keep(dir, e->d_name))
            continue;
        if (n == cap) {
            size_t ncap = cap ? 2 * cap : 32;
            char **p = realloc(names, ncap * sizeof *p);
            if (!p) {
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory listing '%s'", dir);
                break;
            }
            names = p;
            cap = ncap;
        }
        if (!(names[n] = strdup(e->d_name))) {
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory listing '%s'", dir);
            break;
        }
        n++;
    }
    closedir(d);
    if (rc) {
        for (size_t i = 0; i < n; i++)
            free(names[i]);
        free(names);
        return rc;
    }
    if (n)
        qsort(names, n, sizeof *names, cmp_names);
    *out = names;
    *count = n;
    return 0;
}

static void free_names(char **names, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

static int keep_subject(const char *dir, const char *name)
{
    char path[4096];
    return strcmp(name, "scenes") != 0 && join_path(path, sizeof path, dir, name) == 0 && is_dir(path);
}

static int keep_log(const char *dir, const char *name)
{
    (void)dir;
    return is_log_name(name);
}

static void read_study(asp_stats_analysis *a)
{
    char path[4096];
    FILE *fp = join_path(path, sizeof path, a->dir, "study.json") ? NULL : asp__regular_file_open(path, NULL);
    if (!fp)
        return; // optional: the logs carry what the analysis needs
    char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = 0;
    cJSON *s = cJSON_Parse(buf);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(s, "version"),
                *seed = cJSON_GetObjectItemCaseSensitive(s, "seed");
    if (cJSON_IsString(v))
        snprintf(a->study_version, sizeof a->study_version, "%s", v->valuestring);
    if (cJSON_IsNumber(seed))
        a->study_seed = seed->valuedouble;
    // the groups the design meant to fill, so a group nobody reached is seen as missing, not unknown
    const cJSON *g, *groups = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(s, "design"), "groups");
    cJSON_ArrayForEach (g, groups)
        if (cJSON_IsString(g) && a->group_count < sizeof a->groups / sizeof a->groups[0]) {
            snprintf(a->groups[a->group_count].name, sizeof a->groups[0].name, "%s", g->valuestring);
            a->groups[a->group_count++].subjects = 0;
        }
    cJSON_Delete(s);
}

static const struct stats_group *find_group_const(const asp_stats_analysis *a, const char *name)
{
    for (size_t i = 0; i < a->group_count; i++)
        if (strcmp(a->groups[i].name, name) == 0)
            return &a->groups[i];
    return NULL;
}

static struct stats_group *find_group(asp_stats_analysis *a, const char *name)
{
    for (size_t i = 0; i < a->group_count; i++)
        if (strcmp(a->groups[i].name, name) == 0)
            return &a->groups[i];
    if (a->group_count == sizeof a->groups / sizeof a->groups[0])
        return NULL;
    struct stats_group *g = &a->groups[a->group_count++];
    snprintf(g->name, sizeof g->name, "%s", name);
    g->subjects = 0;
    return g;
}

/*
 * Subjects per group, a subject's group being the condition of its runs B
 * (polygons: control), and a warning when the groups differ in size or one
 * is empty: the between-group comparisons of seed 004 4.2 then rest on
 * fewer subjects on one side, or cannot be made at all.
 */
static void read_design(asp_stats_analysis *a)
{
    const char *last = NULL;
    for (size_t i = 0; i < a->run_count; i++) {
        const char *subject = a->runs[i].log.subject;
        if (last && strcmp(last, subject) == 0)
            continue; // runs are sorted by subject: one pass per subject
        last = subject;
        const char *cond = NULL;
        int mixed = 0;
        for (size_t k = i; k < a->run_count && strcmp(a->runs[k].log.subject, subject) == 0; k++) {
            const asp_stats_log *l = &a->runs[k].log;
            if (strcmp(l->run, "B") != 0)
                continue;
            mixed |= cond && strcmp(cond, l->condition) != 0;
            cond = l->condition;
        }
        if (!cond)
            continue; // no run B (yet): in no group
        struct stats_group *g = find_group(a, mixed ? "mixed" : strcmp(cond, "polygons") == 0 ? "control" : cond);
        if (g)
            g->subjects++;
    }
    size_t lo = SIZE_MAX, hi = 0, used = 0;
    char list[256] = "";
    for (size_t i = 0; i < a->group_count && used < sizeof list; i++) {
        size_t n = a->groups[i].subjects;
        lo = n < lo ? n : lo;
        hi = n > hi ? n : hi;
        int k = snprintf(list + used, sizeof list - used, "%s%s %zu", i ? ", " : "", a->groups[i].name, n);
        used += k > 0 ? (size_t)k : 0;
    }
    if (find_group_const(a, "mixed"))
        snprintf(a->design_warning, sizeof a->design_warning,
                 "unbalanced design: subjects change group from test to test (%s subjects); the comparisons "
                 "between groups then mix people across conditions",
                 list);
    else if (a->group_count && lo != hi)
        snprintf(a->design_warning, sizeof a->design_warning,
                 "unbalanced design: the groups have %s subjects; comparisons with a group of fewer than 2 "
                 "subjects have no test",
                 list);
}

static const struct stats_run *find_run(const asp_stats_analysis *a, const char *subject, const char *test,
                                        const char *run)
{
    for (size_t i = 0; i < a->run_count; i++) {
        const asp_stats_log *l = &a->runs[i].log;
        if (strcmp(l->subject, subject) == 0 && strcmp(l->test, test) == 0 && strcmp(l->run, run) == 0)
            return &a->runs[i];
    }
    return NULL;
}

/* answers.jsonl (append-only, one line per answer): counted and checked against the logs' events. */
static void read_answers(asp_stats_analysis *a, const char *subject_dir)
{
    char path[4096];
    FILE *fp = join_path(path, sizeof path, subject_dir, "answers.jsonl") ? NULL : asp__regular_file_open(path, NULL);
    if (!fp)
        return;
    char *line = NULL;
    size_t cap = 0;
    while (getline(&line, &cap, fp) >= 0) {
        cJSON *o = cJSON_Parse(line);
        if (!cJSON_IsObject(o)) {
            a->answers_lost += line[strspn(line, " \t\r\n")] != 0;
            cJSON_Delete(o);
            continue;
        }
        a->answers++;
        const cJSON *subj = cJSON_GetObjectItemCaseSensitive(o, "subject"),
                    *test = cJSON_GetObjectItemCaseSensitive(o, "test"),
                    *run = cJSON_GetObjectItemCaseSensitive(o, "run"),
                    *naming = cJSON_GetObjectItemCaseSensitive(o, "naming_s"),
                    *correct = cJSON_GetObjectItemCaseSensitive(o, "correct");
        const struct stats_run *r = NULL;
        if (cJSON_IsString(subj) && cJSON_IsString(test) && cJSON_IsString(run))
            r = find_run(a, subj->valuestring, test->valuestring, run->valuestring);
        // the log's events are the record; a disagreeing answers line is reported, not preferred
        if (!r || !r->naming.answered || !cJSON_IsNumber(naming) ||
            fabs(naming->valuedouble - r->naming.naming_s) > 1e-3 || cJSON_IsTrue(correct) != r->naming.correct)
            a->answers_mismatch++;
        cJSON_Delete(o);
    }
    free(line);
    fclose(fp);
}

static int load_run(asp_stats_analysis *a, const char *path, asp_error *err)
{
    struct stats_run *r = &a->runs[a->run_count];
    memset(r, 0, sizeof *r);
    int rc = asp_stats_log_load(&r->log, path, err);
    if (rc)
        return rc;
    a->run_count++;
    r->grade.grade = NAN;
    asp_stats_log_naming(&r->log, &r->naming);
    if (r->log.path) {
        r->navigation = 1;
        size_t n = r->log.frame_count;
        double *pos = malloc((n ? n : 1) * 3 * sizeof *pos);
        if (!pos)
            return asp_error_set(err, ASP_ENOMEM, "out of memory grading '%s'", path);
        for (size_t i = 0; i < n; i++)
            memcpy(pos + 3 * i, r->log.frames[i].pos, sizeof r->log.frames[i].pos);
        rc = asp_stats_grade_track(r->log.path, r->log.path_count, r->log.half_width, pos, n, &r->grade, err);
        free(pos);
        if (rc && err) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            asp_error_set(err, rc, "'%s': %s", path, msg);
        }
        return rc;
    }
    return 0;
}

static int read_subject(asp_stats_analysis *a, const char *subject_dir, asp_error *err)
{
    char **names = NULL;
    size_t n = 0;
    int rc = list_dir(subject_dir, keep_log, &names, &n, err);
    if (rc)
        return rc;
    if (n) {
        struct stats_run *p = realloc(a->runs, (a->run_count + n) * sizeof *p);
        if (!p) {
            free_names(names, n);
            return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", subject_dir);
        }
        a->runs = p;
        a->subjects++;
    }
    for (size_t i = 0; i < n && !rc; i++) {
        char path[4096];
        if (join_path(path, sizeof path, subject_dir, names[i]))
            rc = asp_error_set(err, ASP_EINVAL, "path of '%s' in '%s' is too long", names[i], subject_dir);
        else
            rc = load_run(a, path, err);
    }
    free_names(names, n);
    if (!rc && n)
        read_answers(a, subject_dir);
    return rc;
}

int asp_stats_analyze(const char *dir, const asp_stats_analyze_desc *desc, asp_stats_analysis **out, asp_error *err)
{
    ASP_ASSERT(dir && out);
    *out = NULL;
    asp_stats_analyze_desc d = desc ? *desc : (asp_stats_analyze_desc){0};
    if (d.level == 0)
        d.level = 0.95;
    if (!(d.level > 0 && d.level < 1))
        return asp_error_set(err, ASP_EINVAL, "confidence level %g is outside (0, 1)", d.level);
    if (!is_dir(dir))
        return asp_error_set(err, ASP_EIO, "cannot read '%s': not a directory of experiment logs", dir);
    asp_stats_analysis *a = calloc(1, sizeof *a);
    if (!a)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    snprintf(a->dir, sizeof a->dir, "%s", dir);
    a->level = d.level;
    a->all_runs = d.all_runs;
    a->study_seed = NAN;
    read_study(a);
    char **subjects = NULL;
    size_t ns = 0;
    int rc = list_dir(dir, keep_subject, &subjects, &ns, err);
    for (size_t i = 0; i < ns && !rc; i++) {
        char path[4096];
        if (join_path(path, sizeof path, dir, subjects[i]))
            rc = asp_error_set(err, ASP_EINVAL, "path of '%s' in '%s' is too long", subjects[i], dir);
        else
            rc = read_subject(a, path, err);
    }
    free_names(subjects, ns);
    if (!rc && a->run_count == 0)
        rc = asp_error_set(err, ASP_EDEGENERATE, "no experiment log (<subject>/<test>-<A|B>.jsonl) in '%s'", dir);
    if (!rc)
        read_design(a);
    if (rc) {
        asp_stats_analysis_destroy(a);
        return rc;
    }
    *out = a;
    return 0;
}

void asp_stats_analysis_destroy(asp_stats_analysis *a)
{
    if (!a)
        return;
    for (size_t i = 0; i < a->run_count; i++)
        asp_stats_log_release(&a->runs[i].log);
    free(a->runs);
    free(a);
}

void asp_stats_analysis_info_get(const asp_stats_analysis *a, asp_stats_analysis_info *out)
{
    ASP_ASSERT(a && out);
    memset(out, 0, sizeof *out);
    out->logs = a->run_count;
    out->subjects = a->subjects;
    out->answers = a->answers;
    out->groups = a->group_count;
    snprintf(out->design_warning, sizeof out->design_warning, "%s", a->design_warning);
    for (size_t i = 0; i < a->run_count; i++) {
        out->frames += a->runs[i].log.frame_count;
        out->lost_frames += a->runs[i].log.lost_frames;
    }
}
