/*
 * Inputs without a proper surface (issue 3): two points, colinear points,
 * all points equal, NaN, a flat plane. Each gives a valid decomposition or a
 * clear error, never a crash; outputs stay unchanged on failure.
 */
#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "harness.h"

static asp_cloud *make(size_t n, const float *xyz)
{
    asp_cloud *c = NULL;
    asp_error err;
    if (asp_cloud_create(n, 0, NULL, &c, &err) != 0)
        return NULL;
    memcpy(c->positions, xyz, 12 * n);
    return c;
}

static void expect_fail(asp_cloud *c, int code, const char *words)
{
    asp_error errbuf, *err = &errbuf;
    asp_amg *amg = (asp_amg *)(uintptr_t)0x1; /* sentinel: must stay unchanged */
    if (!c)
        return;
    int rc = asp_amg_decompose(c, NULL, NULL, &amg, err);
    CHECK_MSG(rc == code, "expected %d, got %d (%s)", code, rc, rc ? err->msg : "");
    CHECK(amg == (asp_amg *)(uintptr_t)0x1);
    if (rc)
        CHECK_MSG(strstr(err->msg, words) != NULL, "message '%s' lacks '%s'", err->msg, words);
    asp_cloud_destroy(c);
}

static void test_too_few(void)
{
    const float two[6] = {0, 0, 0, 1, 0, 0};
    expect_fail(make(2, two), ASP_EDEGENERATE, "at least 3");
    expect_fail(make(1, two), ASP_EDEGENERATE, "at least 3");
}

static void test_equal_and_nan(void)
{
    float same[300];
    for (int i = 0; i < 300; i++)
        same[i] = 1.5f;
    expect_fail(make(100, same), ASP_EDEGENERATE, "equal");
    same[7] = NAN;
    asp_cloud *c = make(100, same);
    asp_error err;
    int rc = c ? asp_amg_decompose(c, NULL, NULL, &(asp_amg *){NULL}, &err) : -1;
    CHECK(rc != 0);
    asp_cloud_destroy(c);
}

static void test_colinear(void)
{
    float line[3 * 500];
    for (int i = 0; i < 500; i++) {
        line[3 * i] = (float)i * 0.01f;
        line[3 * i + 1] = (float)i * 0.02f;
        line[3 * i + 2] = -(float)i * 0.005f;
    }
    expect_fail(make(500, line), ASP_EDEGENERATE, "colinear");
    /* three points on a line, the smallest case */
    expect_fail(make(3, line), ASP_EDEGENERATE, "colinear");
}

static void test_flat_plane(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_CHECKER_PLANE, &(asp_synth_desc){.grid = 60}, NULL, &c, err), err);
    if (!c)
        return;
    asp_amg *amg = NULL;
    CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    if (amg) {
        /* a flat grid: classifier at its maximum everywhere, normals +-z */
        const float *cl = asp_amg_classifier(amg);
        for (size_t i = 0; i < c->count; i++)
            CHECK(cl[i] > 99.0f);
        CHECK(fabsf(asp_amg_cloud(amg)->normals[2]) > 0.999f);
        CHECK(asp_amg_level_count(amg) >= 4);
        asp_amg_level_stats st[128];
        CHECK_OK(asp_amg_level_stats_all(amg, 0.05, NULL, st, err), err);
        for (size_t l = 0; l < asp_amg_level_count(amg); l++)
            CHECK(st[l].max_pou_error < 1e-6);
        asp_amg_destroy(amg);
    }
    /* a tiny plane: 4 points in a square (k is clamped to 3) */
    const float sq[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    asp_cloud *s = make(4, sq);
    amg = NULL;
    int rc = asp_amg_decompose(s, NULL, NULL, &amg, err);
    CHECK_MSG(rc == 0 || rc == ASP_EDEGENERATE, "4-point square: %d %s", rc, err->msg);
    asp_amg_destroy(amg);
    asp_cloud_destroy(s);
    asp_cloud_destroy(c);
}

static void test_bad_options(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 500}, NULL, &c, err), err);
    if (!c)
        return;
    asp_amg *amg = NULL;
    CHECK(asp_amg_decompose(c, &(asp_amg_desc){.k_min = 2}, NULL, &amg, err) == ASP_EINVAL);
    CHECK(asp_amg_decompose(c, &(asp_amg_desc){.strong_threshold = 1.5}, NULL, &amg, err) == ASP_EINVAL);
    CHECK(asp_amg_decompose(c, &(asp_amg_desc){.epsilon = -1}, NULL, &amg, err) == ASP_EINVAL);
    CHECK(asp_amg_decompose(c, &(asp_amg_desc){.coarsen = (asp_amg_coarsen)77}, NULL, &amg, err) == ASP_EINVAL);
    CHECK(amg == NULL);
    /* every coarsening and interpolation choice gives a partition of unity */
    for (int co = 0; co <= ASP_AMG_COARSEN_HMIS; co++)
        for (int in = 0; in <= ASP_AMG_INTERP_EXTENDED_I; in++) {
            amg = NULL;
            asp_amg_desc d = {.coarsen = (asp_amg_coarsen)co, .interp = (asp_amg_interp)in, .trunc_factor = 0.1};
            CHECK_OK(asp_amg_decompose(c, &d, NULL, &amg, err), err);
            if (!amg)
                continue;
            asp_amg_level_stats st[128];
            CHECK_OK(asp_amg_level_stats_all(amg, 0.05, NULL, st, err), err);
            for (size_t l = 0; l < asp_amg_level_count(amg); l++)
                CHECK_MSG(st[l].max_pou_error < 1e-6, "coarsen %d interp %d level %zu", co, in, l);
            asp_amg_destroy(amg);
        }
    asp_cloud_destroy(c);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_too_few), TEST_CASE(test_equal_and_nan), TEST_CASE(test_colinear), TEST_CASE(test_flat_plane),
          TEST_CASE(test_bad_options))
