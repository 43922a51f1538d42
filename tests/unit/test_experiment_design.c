/*
 * The design of seed 004 2.3 (asp_experiment_plan_draw): every test once per
 * subject in a permutation, run B polygons exactly in the control group,
 * both groups drawn, the same plan for the same seed, and the scene file
 * round trip with its malformed-input errors.
 */
#include "amgsplat/amgsplat.h"
#include "amgsplat/experiment.h"
#include "harness.h"

static const asp_experiment_condition vars[2] = {ASP_EXPERIMENT_POINTS, ASP_EXPERIMENT_PRIMITIVES};

static void test_plan_is_a_design(void)
{
    size_t variable = 0, first[ASP_EXPERIMENT_TEST_COUNT] = {0}, picked[ASP_EXPERIMENT_CONDITION_COUNT] = {0};
    for (size_t s = 0; s < 200; s++) {
        asp_experiment_plan p, q;
        CHECK_OK(asp_experiment_plan_draw(7, s, vars, 2, ASP_EXPERIMENT_GROUP_RANDOM, &p, NULL), NULL);
        CHECK_OK(asp_experiment_plan_draw(7, s, vars, 2, ASP_EXPERIMENT_GROUP_RANDOM, &q, NULL), NULL);
        CHECK(memcmp(&p, &q, sizeof p) == 0);
        int seen[ASP_EXPERIMENT_TEST_COUNT] = {0};
        for (int i = 0; i < ASP_EXPERIMENT_TEST_COUNT; i++)
            seen[p.order[i]]++;
        for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
            CHECK(seen[t] == 1);
            CHECK(p.variable[t] ? p.run_b[t] != ASP_EXPERIMENT_POLYGONS : p.run_b[t] == ASP_EXPERIMENT_POLYGONS);
            variable += (size_t)p.variable[t];
            picked[p.run_b[t]]++;
        }
        first[p.order[0]]++;
    }
    // 800 fair coins: 400 +- 4.5 sigma (sigma 14)
    CHECK_MSG(variable > 337 && variable < 463, "variable group drawn %zu times of 800", variable);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        CHECK_MSG(first[t] > 20, "test %d came first %zu times of 200", t, first[t]);
    CHECK(picked[ASP_EXPERIMENT_POINTS] > 100 && picked[ASP_EXPERIMENT_PRIMITIVES] > 100);
    CHECK(picked[ASP_EXPERIMENT_BLANK] == 0);
}

static void test_rules_and_seeds(void)
{
    asp_experiment_plan p, q;
    const asp_experiment_condition blank = ASP_EXPERIMENT_BLANK;
    CHECK_OK(asp_experiment_plan_draw(1, 0, &blank, 1, ASP_EXPERIMENT_GROUP_VARIABLE, &p, NULL), NULL);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        CHECK(p.variable[t] == 1 && p.run_b[t] == ASP_EXPERIMENT_BLANK);
    CHECK_OK(asp_experiment_plan_draw(1, 0, NULL, 0, ASP_EXPERIMENT_GROUP_CONTROL, &p, NULL), NULL);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        CHECK(p.variable[t] == 0 && p.run_b[t] == ASP_EXPERIMENT_POLYGONS);
    // another seed or subject gives another plan for some of 20 subjects
    int differ = 0;
    for (size_t s = 0; s < 20; s++) {
        asp_experiment_plan_draw(1, s, vars, 2, 0, &p, NULL);
        asp_experiment_plan_draw(2, s, vars, 2, 0, &q, NULL);
        differ += memcmp(&p, &q, sizeof p) != 0;
    }
    CHECK(differ >= 15);
    asp_error err = {0};
    const asp_experiment_condition poly = ASP_EXPERIMENT_POLYGONS;
    CHECK(asp_experiment_plan_draw(1, 0, NULL, 0, 0, &p, &err) == ASP_EINVAL);
    CHECK(asp_experiment_plan_draw(1, 0, &poly, 1, 0, &p, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "points, primitives or blank") != NULL);
    asp_experiment_condition c;
    CHECK(asp_experiment_condition_parse("primitives", &c, NULL) == 0 && c == ASP_EXPERIMENT_PRIMITIVES);
    CHECK(asp_experiment_condition_parse("splats", &c, &err) == ASP_EINVAL && strstr(err.msg, "'splats'"));
    CHECK(strcmp(asp_experiment_test_name(ASP_EXPERIMENT_HIGHSPEED), "highspeed") == 0);
    CHECK(asp_experiment_test_name((asp_experiment_test)4) == NULL);
}

/* issue 29: permuted blocks fill every group once per block; a subject keeps its group; the check warns */
static void test_balanced_blocks(void)
{
    for (uint64_t seed = 1; seed <= 20; seed++) {
        size_t got[ASP_EXPERIMENT_CONDITION_COUNT] = {0};
        for (size_t s = 0; s < 6; s++) {
            asp_experiment_plan p, r;
            CHECK_OK(asp_experiment_plan_draw(seed, s, vars, 2, ASP_EXPERIMENT_GROUP_BALANCED, &p, NULL), NULL);
            CHECK_OK(asp_experiment_plan_draw(seed, s, vars, 2, ASP_EXPERIMENT_GROUP_RANDOM, &r, NULL), NULL);
            CHECK(memcmp(p.order, r.order, sizeof p.order) == 0); // the seed's order draw is kept
            for (int t = 1; t < ASP_EXPERIMENT_TEST_COUNT; t++)
                CHECK(p.run_b[t] == p.run_b[0] && p.variable[t] == p.variable[0]);
            CHECK(p.variable[0] == (p.run_b[0] != ASP_EXPERIMENT_POLYGONS));
            got[p.run_b[0]]++;
            if (s == 2 || s == 5) // a complete block: one subject per group so far in each block
                CHECK(got[ASP_EXPERIMENT_POLYGONS] == got[ASP_EXPERIMENT_POINTS] &&
                      got[ASP_EXPERIMENT_POINTS] == got[ASP_EXPERIMENT_PRIMITIVES] &&
                      got[ASP_EXPERIMENT_POLYGONS] == (s + 1) / 3);
        }
    }
    asp_experiment_design d;
    CHECK_OK(asp_experiment_design_check(1, 3, vars, 2, ASP_EXPERIMENT_GROUP_BALANCED, &d, NULL), NULL);
    CHECK(d.balanced && d.group_count == 3 && d.warning[0] == 0 && d.runs_b[ASP_EXPERIMENT_PRIMITIVES] == 4);
    CHECK_OK(asp_experiment_design_check(1, 2, vars, 2, ASP_EXPERIMENT_GROUP_BALANCED, &d, NULL), NULL);
    CHECK_MSG(!d.balanced && strstr(d.warning, "2 subjects over 3 groups") != NULL, "%s", d.warning);
    CHECK_OK(asp_experiment_design_check(1, 4, vars, 2, ASP_EXPERIMENT_GROUP_VARIABLE, &d, NULL), NULL);
    CHECK(d.balanced && d.group_count == 2 && d.runs_b[ASP_EXPERIMENT_POLYGONS] == 0);
    asp_error err = {0};
    const asp_experiment_condition twice[2] = {ASP_EXPERIMENT_POINTS, ASP_EXPERIMENT_POINTS};
    CHECK(asp_experiment_design_check(1, 3, twice, 2, 0, &d, &err) == ASP_EINVAL && strstr(err.msg, "twice"));
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

static void test_scene_file(void)
{
    char dir[] = "/tmp/asp_exp_scenesXXXXXX", path[128];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/s.json", dir);
    asp_experiment_scenes a, b;
    asp_experiment_scenes_default(&a);
    CHECK(a.candidate_count == 3 && a.tests[ASP_EXPERIMENT_LOWSPEED].kind == 1);
    a.tests[ASP_EXPERIMENT_LOWSPEED].half_width = 2.25f;
    a.tests[ASP_EXPERIMENT_HIGHSPEED].seed = 99;
    CHECK_OK(asp_experiment_scenes_save(&a, path, NULL), NULL);
    CHECK_OK(asp_experiment_scenes_load(path, &b, NULL), NULL);
    CHECK(b.tests[ASP_EXPERIMENT_LOWSPEED].half_width == 2.25f && b.tests[ASP_EXPERIMENT_HIGHSPEED].seed == 99);
    CHECK(strcmp(b.tests[ASP_EXPERIMENT_FAR].answer, a.tests[ASP_EXPERIMENT_FAR].answer) == 0);
    CHECK(strcmp(b.candidates[2].model, a.candidates[2].model) == 0);
    // a partial file keeps the defaults for what it leaves out
    write_text(path, "{\"format\":\"amgsplat-scenes 1\",\"tests\":{\"far\":{\"answer\":\"horse\"}}}");
    CHECK_OK(asp_experiment_scenes_load(path, &b, NULL), NULL);
    CHECK(strcmp(b.tests[ASP_EXPERIMENT_FAR].answer, "horse") == 0 && b.tests[ASP_EXPERIMENT_NEAR].kind == 0);
    static const struct { const char *text, *msg; } bad[] = {
        {"{\"format\":\"other\"}", "\"format\""},
        {"{\"format\":\"amgsplat-scenes 1\",\"tests\":{\"far\":{\"answer\":\"dog\"}}}", "'dog' is not a candidate"},
        {"{\"format\":\"amgsplat-scenes 1\",\"tests\":{\"lowspeed\":{\"grid\":3}}}", "'grid' must be a number"},
        {"{\"format\":\"amgsplat-scenes 1\",\"tests\":{\"near\":{\"kind\":\"canyon\"}}}", "kind must be object"},
        {"{\"format\":\"amgsplat-scenes 1\",\"candidates\":{\"cat\":7}}", "candidate 'cat'"},
        {"{\"format\":", "not JSON"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        asp_error err = {0};
        write_text(path, bad[i].text);
        CHECK(asp_experiment_scenes_load(path, &b, &err) == ASP_EFORMAT);
        CHECK_MSG(strstr(err.msg, bad[i].msg) != NULL, "'%s' gave '%s'", bad[i].text, err.msg);
    }
    remove(path);
    rmdir(dir);
}

TEST_MAIN(TEST_CASE(test_plan_is_a_design), TEST_CASE(test_rules_and_seeds), TEST_CASE(test_balanced_blocks),
          TEST_CASE(test_scene_file))
