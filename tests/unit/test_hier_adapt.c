/*
 * Adaptive traversal depth (seed 004 3.2.5, Fig. 3.5) with synthetic frame
 * times: single steps of the pseudocode, convergence into the [f_min, f_max]
 * band for a cost model that doubles per level, recovery after the scene gets
 * heavier, and the tau variant.
 */
#include "amgsplat/hier.h"
#include "harness.h"

static void test_steps(void)
{
    asp_hier_adapt a;
    asp_error err = {0};
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 0.01, .f_max = 0.03, .depth_min = 3,
                                                          .depth_max = 6},
                              &err) == 0);
    CHECK(a.depth == 3 && a.depth_min == 3);
    /* fast: k_min++ and k_0 = k_min, refine */
    CHECK(asp_hier_adapt_update(&a, 0.005, 0) == 1);
    CHECK(a.depth_min == 4 && a.depth == 4);
    /* in band: nothing changes */
    CHECK(asp_hier_adapt_update(&a, 0.02, 0) == 1);
    CHECK(a.depth_min == 4 && a.depth == 4);
    /* slow: k_0--, no refine; k_min follows it down */
    CHECK(asp_hier_adapt_update(&a, 0.05, 0) == 0);
    CHECK(a.depth == 3 && a.depth_min == 3 && a.refine == 0);
    /* fast frames stop at depth_max */
    for (int i = 0; i < 10; i++)
        asp_hier_adapt_update(&a, 0.001, 0);
    CHECK(a.depth == 6 && a.depth_min == 6);
    /* depth never drops below 1 */
    for (int i = 0; i < 10; i++)
        asp_hier_adapt_update(&a, 1.0, 0);
    CHECK(a.depth == 1 && a.depth_min == 1);
    /* an event resets k_0 to k_min */
    asp_hier_adapt_update(&a, 0.001, 0);
    asp_hier_adapt_update(&a, 0.001, 0);
    CHECK(a.depth == 3);
    a.depth = 5; /* as if the depth had been raised elsewhere */
    asp_hier_adapt_update(&a, 0.02, 1);
    CHECK(a.depth == 3);
    /* a NaN frame time changes nothing */
    CHECK(asp_hier_adapt_update(&a, NAN, 0) == 1 && a.depth == 3);
    asp_hier_view v = {0};
    asp_hier_adapt_apply(&a, &v);
    CHECK(v.depth_limit == 3 && v.tau == 0);
}

/* frame time of a scene whose cost doubles with each level: base * 2^depth */
static double frame(double base, uint32_t depth)
{
    return base * ldexp(1.0, (int)depth);
}

static void test_converges(void)
{
    asp_hier_adapt a;
    asp_error err = {0};
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 1.0 / 60, .f_max = 1.0 / 30, .depth_max = 20},
                              &err) == 0);
    double base = 1e-5, f = frame(base, a.depth);
    int in_band = 0;
    for (int i = 0; i < 60; i++) {
        asp_hier_adapt_update(&a, f, 0);
        f = frame(base, a.depth);
        in_band += i >= 20 && f >= 1.0 / 60 && f <= 1.0 / 30;
    }
    /* 1e-5 * 2^11 = 0.0205 s is the only depth in the band */
    CHECK_MSG(a.depth == 11, "depth %u", a.depth);
    CHECK(in_band == 40);
    /* the scene gets 8x heavier: the depth comes down three levels and stays */
    base *= 8;
    f = frame(base, a.depth);
    for (int i = 0; i < 30; i++) {
        asp_hier_adapt_update(&a, f, i == 15);
        f = frame(base, a.depth);
    }
    CHECK_MSG(a.depth == 8, "depth %u after the load grew", a.depth);
    CHECK(f >= 1.0 / 60 && f <= 1.0 / 30);
}

static void test_tau_mode(void)
{
    asp_hier_adapt a;
    asp_error err = {0};
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 0.01, .f_max = 0.02, .mode = ASP_HIER_ADAPT_TAU,
                                                          .tau = 4, .tau_step = 2, .tau_min = 1, .tau_max = 16},
                              &err) == 0);
    CHECK(asp_hier_adapt_update(&a, 0.005, 0) == 1 && a.tau == 2);
    CHECK(asp_hier_adapt_update(&a, 0.005, 0) == 1 && a.tau == 1);
    CHECK(asp_hier_adapt_update(&a, 0.005, 0) == 1 && a.tau == 1);
    CHECK(asp_hier_adapt_update(&a, 0.015, 1) == 1 && a.tau == 1);
    CHECK(asp_hier_adapt_update(&a, 0.05, 0) == 0 && a.tau == 2);
    for (int i = 0; i < 10; i++)
        asp_hier_adapt_update(&a, 0.05, 0);
    CHECK(a.tau == 16);
    asp_hier_view v = {0};
    asp_hier_adapt_apply(&a, &v);
    CHECK(v.tau == 16 && v.depth_limit == 0);
    /* a cost model in which the splat count, hence time, falls as 1/tau^2 */
    asp_hier_adapt b;
    CHECK(asp_hier_adapt_init(&b, &(asp_hier_adapt_desc){.f_min = 0.01, .f_max = 0.02, .mode = ASP_HIER_ADAPT_TAU},
                              &err) == 0);
    for (int i = 0; i < 50; i++)
        asp_hier_adapt_update(&b, 0.5 / ((double)b.tau * b.tau), 0);
    double f = 0.5 / ((double)b.tau * b.tau);
    CHECK_MSG(f >= 0.01 && f <= 0.02, "frame time %g at tau %g", f, (double)b.tau);
}

static void test_invalid(void)
{
    asp_hier_adapt a;
    asp_error err = {0};
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 0.03, .f_max = 0.01}, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "band") != NULL);
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){0}, &err) == ASP_EINVAL);
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 0.01, .f_max = 0.02, .mode = 7}, &err) ==
          ASP_EINVAL);
    CHECK(asp_hier_adapt_init(&a, &(asp_hier_adapt_desc){.f_min = 0.01, .f_max = 0.02, .tau_step = 0.5f}, &err) ==
          ASP_EINVAL);
}

TEST_MAIN(TEST_CASE(test_steps), TEST_CASE(test_converges), TEST_CASE(test_tau_mode), TEST_CASE(test_invalid))
