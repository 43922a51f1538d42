/*
 * Splat radii: discs of the default radii cover every interior point of a
 * uniformly sampled plane (random and jittered-grid samplings), too-small
 * factors do not (so the check can fail), duplicates get positive radii,
 * malformed input is rejected.
 */
#include <stdint.h>

#include "amgsplat/geom.h"
#include "harness.h"

static uint64_t rng_state = 0xD1B54A32D192ED03ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/*
 * Largest over a fine grid of interior points x of min_i |x - p_i| / r_i: the
 * factor the radii would need to be scaled by to cover the plane. <= 1 means
 * every grid point lies in some disc (INFINITY when no disc reaches a grid point). The plane is [0,1]^2 at z = 0; the grid
 * keeps a margin of 0.05 from the boundary, where coverage is not expected.
 */
static double critical_factor(const float *p, const float *r, size_t n, int grid)
{
    float rmax = 0;
    for (size_t i = 0; i < n; i++)
        rmax = r[i] > rmax ? r[i] : rmax;
    asp_kdtree *t = NULL;
    asp_error e;
    if (asp_kdtree_create(p, n, 12, NULL, &t, &e))
        return INFINITY;
    size_t cap = 4096;
    asp_index *idx = malloc(cap * sizeof(asp_index));
    float *d2 = malloc(cap * sizeof(float));
    double worst = 0;
    for (int gy = 0; gy <= grid; gy++)
        for (int gx = 0; gx <= grid; gx++) {
            float q[3] = {0.05f + 0.9f * (float)gx / (float)grid, 0.05f + 0.9f * (float)gy / (float)grid, 0.0f};
            /* only samples within rmax can cover q; beyond 1 the value is a lower bound, still > 1 */
            size_t m = asp_kdtree_radius(t, q, rmax, idx, d2, cap);
            m = m < cap ? m : cap;
            double best = INFINITY;
            for (size_t j = 0; j < m; j++)
                best = fmin(best, sqrt((double)d2[j]) / r[idx[j]]);
            worst = fmax(worst, best);
        }
    free(idx);
    free(d2);
    asp_kdtree_destroy(t);
    return worst;
}

static float *random_plane(size_t n)
{
    float *p = malloc(3 * n * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        p[3 * i] = (float)urand();
        p[3 * i + 1] = (float)urand();
        p[3 * i + 2] = 0.0f;
    }
    return p;
}

static void test_cover_random_plane(void)
{
    size_t n = 20000;
    float *p = random_plane(n);
    float *r = malloc(n * sizeof(float));
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_radii(p, n, 12, NULL, r, NULL, err), err);
    double f = critical_factor(p, r, n, 250);
    fprintf(stderr, "random plane, k = 16: discs need factor %.3f to cover\n", f);
    CHECK_MSG(f <= 1.0, "holes remain: critical factor %.3f", f);
    /* the check can fail: half-size discs leave holes */
    CHECK_OK(asp_estimate_radii(p, n, 12, &(asp_radii_desc){.k = 16, .factor = 0.5f}, r, NULL, err), err);
    CHECK(critical_factor(p, r, n, 250) > 1.0);
    free(r);
    free(p);
}

static void test_cover_jittered_plane(void)
{
    int side = 120;
    size_t n = (size_t)side * (size_t)side;
    float *p = malloc(3 * n * sizeof(float));
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            size_t i = (size_t)y * (size_t)side + (size_t)x;
            p[3 * i] = (float)((x + urand()) / side);
            p[3 * i + 1] = (float)((y + urand()) / side);
            p[3 * i + 2] = 0.0f;
        }
    float *r = malloc(n * sizeof(float));
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_radii(p, n, 12, NULL, r, NULL, err), err);
    double f = critical_factor(p, r, n, 250);
    fprintf(stderr, "jittered plane, k = 16: discs need factor %.3f to cover\n", f);
    CHECK(f <= 1.0);
    /* radii are close to the sampling scale: the 16th neighbour of a unit-density grid is ~2.3 spacings away */
    double mean = 0;
    for (size_t i = 0; i < n; i++)
        mean += r[i];
    mean /= (double)n;
    CHECK_MSG(mean > 1.5 / side && mean < 3.5 / side, "mean radius %.4g", mean);
    free(r);
    free(p);
}

static void test_values_and_duplicates(void)
{
    /* 4 points on a line at 0, 1, 3 and a duplicate of 3 */
    float p[12] = {0, 0, 0, 1, 0, 0, 3, 0, 0, 3, 0, 0};
    float r[4];
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_radii(p, 4, 12, &(asp_radii_desc){.k = 1, .factor = 2.0f}, r, NULL, err), err);
    /* nearest neighbour distances 1, 1, 0, 0: duplicates borrow the smallest positive radius */
    CHECK_NEAR(r[0], 2.0, 1e-6);
    CHECK_NEAR(r[1], 2.0, 1e-6);
    CHECK_NEAR(r[2], 2.0, 1e-6);
    CHECK_NEAR(r[3], 2.0, 1e-6);
    CHECK_OK(asp_estimate_radii(p, 4, 12, &(asp_radii_desc){.k = 2}, r, NULL, err), err);
    CHECK_NEAR(r[0], 3.0, 1e-6);
    CHECK_NEAR(r[1], 2.0, 1e-6);
    CHECK_NEAR(r[2], 2.0, 1e-6);
    /* k larger than the set is clamped to count - 1 */
    CHECK_OK(asp_estimate_radii(p, 4, 12, &(asp_radii_desc){.k = 50}, r, NULL, err), err);
    CHECK_NEAR(r[0], 3.0, 1e-6);
    CHECK_NEAR(r[1], 2.0, 1e-6);
    /* from a precomputed distance table */
    float d2[6] = {1, 4, 0, 9, 0, 0};
    CHECK_OK(asp_radii_from_knn(d2, 3, 2, &(asp_radii_desc){.k = 2}, r, NULL, err), err);
    CHECK_NEAR(r[0], 2.0, 1e-6);
    CHECK_NEAR(r[1], 3.0, 1e-6);
    CHECK_NEAR(r[2], 2.0, 1e-6);
}

static void test_errors(void)
{
    asp_error e = {0}, *err = &e;
    float r[4] = {-7, -7, -7, -7};
    float same[9] = {1, 2, 3, 1, 2, 3, 1, 2, 3};
    CHECK(asp_estimate_radii(same, 3, 12, NULL, r, NULL, err) == ASP_EDEGENERATE);
    CHECK_MSG(strstr(err->msg, "all 3 points are equal") != NULL, "%s", err->msg);
    CHECK(r[0] == -7);
    CHECK(asp_estimate_radii(same, 1, 12, NULL, r, NULL, err) == ASP_EDEGENERATE);
    CHECK(asp_estimate_radii(same, 0, 12, NULL, r, NULL, err) == ASP_EDEGENERATE);
    float bad[6] = {0, 0, 0, 1, INFINITY, 0};
    CHECK(asp_estimate_radii(bad, 2, 12, NULL, r, NULL, err) == ASP_EINVAL);
    CHECK_MSG(strstr(err->msg, "point 1: coordinate y") != NULL, "%s", err->msg);
    float ok[6] = {0, 0, 0, 1, 0, 0};
    CHECK(asp_estimate_radii(ok, 2, 12, &(asp_radii_desc){.factor = -1}, r, NULL, err) == ASP_EINVAL);
    CHECK(asp_estimate_radii(ok, 2, 12, &(asp_radii_desc){.factor = NAN}, r, NULL, err) == ASP_EINVAL);
    CHECK(asp_estimate_radii(ok, 2, 4, NULL, r, NULL, err) == ASP_EINVAL);
    CHECK(asp_estimate_radii(ok, 2, 12, NULL, NULL, NULL, err) == ASP_EINVAL);
    CHECK(r[0] == -7);
    float d2[4] = {0, 0, 0, 0};
    CHECK(asp_radii_from_knn(d2, 2, 2, NULL, r, NULL, err) == ASP_EDEGENERATE);
    CHECK(asp_radii_from_knn(d2, 2, 2, &(asp_radii_desc){.k = 3}, r, NULL, err) == ASP_EINVAL);
    float dn[2] = {1, NAN};
    CHECK(asp_radii_from_knn(dn, 2, 1, NULL, r, NULL, err) == ASP_EINVAL);
    CHECK(r[0] == -7);
}

TEST_MAIN(TEST_CASE(test_cover_random_plane), TEST_CASE(test_cover_jittered_plane),
          TEST_CASE(test_values_and_duplicates), TEST_CASE(test_errors))
