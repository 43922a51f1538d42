/*
 * The experiment design of seed 004 2.3: tests in a random order per subject;
 * each test twice, run A with polygons, run B polygons again (control group)
 * or a variable representation (a variable group). Subjects go to the groups
 * in permuted blocks (balanced), or by the seed's literal coin per test.
 */
#include <string.h>

#include "experiment/internal.h"
#include "util/banned.h"

static const char *const test_names[ASP_EXPERIMENT_TEST_COUNT] = {"far", "near", "lowspeed", "highspeed"};
static const char *const condition_names[ASP_EXPERIMENT_CONDITION_COUNT] = {"polygons", "points", "primitives",
                                                                            "blank"};

const char *asp_experiment_test_name(asp_experiment_test t)
{
    return (unsigned)t < ASP_EXPERIMENT_TEST_COUNT ? test_names[t] : NULL;
}

const char *asp_experiment_condition_name(asp_experiment_condition c)
{
    return (unsigned)c < ASP_EXPERIMENT_CONDITION_COUNT ? condition_names[c] : NULL;
}

int asp_experiment_condition_parse(const char *name, asp_experiment_condition *out, asp_error *err)
{
    for (int i = 0; i < ASP_EXPERIMENT_CONDITION_COUNT; i++)
        if (name && strcmp(name, condition_names[i]) == 0) {
            *out = (asp_experiment_condition)i;
            return 0;
        }
    return asp_error_set(err, ASP_EINVAL, "unknown condition '%s' (expected polygons, points, primitives, blank)",
                         name ? name : "(null)");
}

/* the groups a rule spreads subjects over: control (run B polygons) and/or one per variable condition */
static size_t rule_groups(int rule, const asp_experiment_condition *variable, size_t nvariable,
                          asp_experiment_condition *out)
{
    size_t g = 0;
    if (rule != ASP_EXPERIMENT_GROUP_VARIABLE)
        out[g++] = ASP_EXPERIMENT_POLYGONS;
    if (rule != ASP_EXPERIMENT_GROUP_CONTROL)
        for (size_t i = 0; i < nvariable; i++)
            out[g++] = variable[i];
    return g;
}

static int check_rule(int rule, const asp_experiment_condition *variable, size_t nvariable, asp_error *err)
{
    if (rule < ASP_EXPERIMENT_GROUP_BALANCED || rule > ASP_EXPERIMENT_GROUP_RANDOM)
        return asp_error_set(err, ASP_EINVAL, "unknown group rule %d", rule);
    if (rule != ASP_EXPERIMENT_GROUP_CONTROL && (!variable || nvariable == 0))
        return asp_error_set(err, ASP_EINVAL, "the variable group needs at least one condition");
    if (nvariable >= ASP_EXPERIMENT_CONDITION_COUNT)
        return asp_error_set(err, ASP_EINVAL, "at most %d variable conditions, got %zu",
                             ASP_EXPERIMENT_CONDITION_COUNT - 1, nvariable);
    for (size_t i = 0; i < nvariable; i++) {
        if (variable[i] == ASP_EXPERIMENT_POLYGONS || (unsigned)variable[i] >= ASP_EXPERIMENT_CONDITION_COUNT)
            return asp_error_set(err, ASP_EINVAL, "variable condition %zu must be points, primitives or blank", i);
        for (size_t j = 0; j < i; j++)
            if (variable[j] == variable[i])
                return asp_error_set(err, ASP_EINVAL, "variable condition '%s' is named twice",
                                     asp_experiment_condition_name(variable[i]));
    }
    return 0;
}

int asp_experiment_plan_draw(uint64_t seed, size_t subject, const asp_experiment_condition *variable,
                             size_t nvariable, int rule, asp_experiment_plan *out, asp_error *err)
{
    ASP_ASSERT(out);
    int rc = check_rule(rule, variable, nvariable, err);
    if (rc)
        return rc;
    /* one stream per subject, so adding subjects never changes the earlier ones' plans */
    uint64_t s = asp__exp_stream(seed, (uint64_t)subject + 1, 0x504c414eull /* "PLAN" */);
    asp_experiment_plan p;
    for (int i = 0; i < ASP_EXPERIMENT_TEST_COUNT; i++)
        p.order[i] = (asp_experiment_test)i;
    /* seed 004 2.3's counterbalancing: the tests in a random order per subject */
    for (int i = ASP_EXPERIMENT_TEST_COUNT - 1; i > 0; i--) { // Fisher-Yates
        int j = (int)asp__exp_below(&s, (uint64_t)i + 1);
        asp_experiment_test t = p.order[i];
        p.order[i] = p.order[j];
        p.order[j] = t;
    }
    if (rule == ASP_EXPERIMENT_GROUP_RANDOM) {
        /* seed 004 2.3 literally: a coin per test; with few subjects whole conditions can go missing */
        for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
            int var = (int)(asp__exp_next(&s) >> 63);
            uint64_t pick = asp__exp_below(&s, nvariable);
            p.variable[t] = var;
            p.run_b[t] = var ? variable[pick] : ASP_EXPERIMENT_POLYGONS;
        }
    } else {
        /*
         * Permuted blocks: subjects 0..G-1 form block 0, G..2G-1 block 1, and so on, each block a
         * seeded permutation of the G groups, so every complete block puts one subject in every
         * group and N subjects spread as evenly as N allows (a multiple of G: exactly). The
         * subject keeps its group in all four tests, as seed 004 2.3's "control category" and
         * "variable category" are groups of subjects, and the between-group comparison of 4.2
         * then compares different people, each counted once.
         */
        asp_experiment_condition groups[ASP_EXPERIMENT_CONDITION_COUNT];
        size_t g = rule_groups(rule, variable, nvariable, groups);
        uint64_t b = asp__exp_stream(seed, (uint64_t)(subject / g) + 1, 0x424c4f4bull /* "BLOK" */);
        for (size_t i = g - 1; i > 0; i--) {
            size_t j = (size_t)asp__exp_below(&b, (uint64_t)i + 1);
            asp_experiment_condition c = groups[i];
            groups[i] = groups[j];
            groups[j] = c;
        }
        asp_experiment_condition mine = groups[subject % g];
        for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
            p.variable[t] = mine != ASP_EXPERIMENT_POLYGONS;
            p.run_b[t] = mine;
        }
    }
    *out = p;
    return 0;
}

int asp_experiment_design_check(uint64_t seed, size_t nsubjects, const asp_experiment_condition *variable,
                                size_t nvariable, int rule, asp_experiment_design *out, asp_error *err)
{
    ASP_ASSERT(out);
    memset(out, 0, sizeof *out);
    int rc = check_rule(rule, variable, nvariable, err);
    if (rc)
        return rc;
    asp_experiment_condition groups[ASP_EXPERIMENT_CONDITION_COUNT];
    out->group_count = rule_groups(rule, variable, nvariable, groups);
    for (size_t i = 0; i < out->group_count; i++)
        out->groups[i] = groups[i];
    for (size_t s = 0; s < nsubjects; s++) {
        asp_experiment_plan p;
        rc = asp_experiment_plan_draw(seed, s, variable, nvariable, rule, &p, err);
        if (rc)
            return rc;
        for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
            out->runs_b[p.run_b[t]]++;
    }
    size_t lo = SIZE_MAX, hi = 0;
    for (size_t i = 0; i < out->group_count; i++) {
        size_t n = out->runs_b[groups[i]];
        lo = n < lo ? n : lo;
        hi = n > hi ? n : hi;
    }
    out->balanced = lo == hi && nsubjects > 0;
    if (out->balanced)
        return 0;
    /* the warning names what each group got, so a lab sees which condition is short */
    char list[160] = "";
    size_t used = 0;
    for (size_t i = 0; i < out->group_count && used < sizeof list; i++) {
        size_t n = out->runs_b[groups[i]];
        int k = snprintf(list + used, sizeof list - used, "%s%s %zu", i ? ", " : "",
                         groups[i] == ASP_EXPERIMENT_POLYGONS ? "control" : asp_experiment_condition_name(groups[i]),
                         rule == ASP_EXPERIMENT_GROUP_RANDOM ? n : n / ASP_EXPERIMENT_TEST_COUNT);
        used += k > 0 ? (size_t)k : 0;
    }
    if (rule == ASP_EXPERIMENT_GROUP_RANDOM)
        snprintf(out->warning, sizeof out->warning,
                 "unbalanced design: the per-test coin of --group random gave runs B %s (of %zu subjects x 4 "
                 "tests); use the default balanced groups",
                 list, nsubjects);
    else
        snprintf(out->warning, sizeof out->warning,
                 "unbalanced design: %zu subjects over %zu groups give subjects %s; use a multiple of %zu "
                 "subjects so that every group has as many",
                 nsubjects, out->group_count, list, out->group_count);
    return 0;
}
