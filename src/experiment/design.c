/*
 * The experiment design of seed 004 2.3: tests in a random order per subject;
 * each test twice, run A with polygons, run B by a random draw polygons again
 * (control group) or the variable representation (variable group).
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

int asp_experiment_plan_draw(uint64_t seed, size_t subject, const asp_experiment_condition *variable,
                             size_t nvariable, int rule, asp_experiment_plan *out, asp_error *err)
{
    ASP_ASSERT(out);
    if (rule < ASP_EXPERIMENT_GROUP_RANDOM || rule > ASP_EXPERIMENT_GROUP_VARIABLE)
        return asp_error_set(err, ASP_EINVAL, "unknown group rule %d", rule);
    if (rule != ASP_EXPERIMENT_GROUP_CONTROL && (!variable || nvariable == 0))
        return asp_error_set(err, ASP_EINVAL, "the variable group needs at least one condition");
    for (size_t i = 0; i < nvariable; i++)
        if (variable[i] == ASP_EXPERIMENT_POLYGONS || (unsigned)variable[i] >= ASP_EXPERIMENT_CONDITION_COUNT)
            return asp_error_set(err, ASP_EINVAL, "variable condition %zu must be points, primitives or blank", i);
    /* one stream per subject, so adding subjects never changes the earlier ones' plans */
    uint64_t s = asp__exp_stream(seed, (uint64_t)subject + 1, 0x504c414eull /* "PLAN" */);
    asp_experiment_plan p;
    for (int i = 0; i < ASP_EXPERIMENT_TEST_COUNT; i++)
        p.order[i] = (asp_experiment_test)i;
    for (int i = ASP_EXPERIMENT_TEST_COUNT - 1; i > 0; i--) { // Fisher-Yates
        int j = (int)asp__exp_below(&s, (uint64_t)i + 1);
        asp_experiment_test t = p.order[i];
        p.order[i] = p.order[j];
        p.order[j] = t;
    }
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        int var = rule == ASP_EXPERIMENT_GROUP_VARIABLE ? 1
                  : rule == ASP_EXPERIMENT_GROUP_CONTROL ? 0
                                                         : (int)(asp__exp_next(&s) >> 63);
        uint64_t pick = asp__exp_below(&s, nvariable ? nvariable : 1); // drawn always: rules share one stream
        p.variable[t] = var;
        p.run_b[t] = var ? variable[pick] : ASP_EXPERIMENT_POLYGONS;
    }
    *out = p;
    return 0;
}
