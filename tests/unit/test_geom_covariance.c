/*
 * asp_covariance_sym3, the one covariance sum (PCA normals, AMG classifier,
 * point ellipses): known covariances of points on a line, a plane and a
 * weighted set; far from the origin without cancellation; index lists, the
 * appended "also" points, a given centre, the stride, the double entry point
 * agreeing with the float one, and empty or zero-weight input giving zeros.
 */
#include <math.h>

#include "amgsplat/geom.h"
#include "harness.h"

/* Points on the line p = o + t d, t = 0..n-1: variance along d of (n^2 - 1) / 12, none across. */
static void test_line(void)
{
    enum { N = 11 };
    const double o[3] = {1, -2, 3}, d[3] = {2.0 / 3, 1.0 / 3, -2.0 / 3}; /* unit */
    float p[3 * N];
    for (int t = 0; t < N; t++)
        for (int a = 0; a < 3; a++)
            p[3 * t + a] = (float)(o[a] + t * d[a]);
    double c[3], cov[6], ev[3], V[9];
    asp_covariance_sym3(p, 12, NULL, N, NULL, c, cov);
    const double var = (N * N - 1) / 12.0;
    for (int a = 0; a < 3; a++)
        CHECK_NEAR(c[a], o[a] + 5 * d[a], 1e-5);
    /* cov = var d d^T exactly (to the float rounding of the points) */
    const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int e = 0; e < 6; e++)
        CHECK_NEAR(cov[e], var * d[ij[e][0]] * d[ij[e][1]], 1e-5);
    asp_eigen_sym3(cov, ev, V);
    CHECK_NEAR(ev[0], var, 1e-5);
    CHECK_NEAR(ev[1], 0, 1e-5);
    CHECK_NEAR(ev[2], 0, 1e-5);
    CHECK_NEAR(fabs(V[0] * d[0] + V[3] * d[1] + V[6] * d[2]), 1, 1e-9);
}

/*
 * A 4x4 grid on the plane z = 2000 far from the origin, in xyz + padding
 * (stride 16): var x = var y = 5/4 (values 0..3), no z variance, the normal
 * +-z. A naive E[x^2] - E[x]^2 in float would lose it all.
 */
static void test_plane_far_from_origin(void)
{
    float p[4 * 16];
    const float base = 1000.0f;
    for (int i = 0; i < 16; i++) {
        p[4 * i] = base + (float)(i % 4);
        p[4 * i + 1] = -base + (float)(i / 4);
        p[4 * i + 2] = 2 * base;
        p[4 * i + 3] = 1e30f; /* padding, skipped by the stride */
    }
    double c[3], cov[6], ev[3], V[9];
    asp_covariance_sym3(p, 16, NULL, 16, NULL, c, cov);
    CHECK_NEAR(c[0], base + 1.5, 1e-9);
    CHECK_NEAR(c[1], -base + 1.5, 1e-9);
    CHECK_NEAR(c[2], 2 * base, 1e-9);
    CHECK_NEAR(cov[0], 1.25, 1e-12);
    CHECK_NEAR(cov[3], 1.25, 1e-12);
    CHECK_NEAR(cov[1], 0, 1e-12);
    CHECK_NEAR(cov[2], 0, 1e-12);
    CHECK_NEAR(cov[4], 0, 1e-12);
    CHECK_NEAR(cov[5], 0, 1e-12);
    asp_eigen_sym3(cov, ev, V);
    CHECK_NEAR(fabs(V[3 * 2 + 2]), 1.0, 1e-12);
    /* an index list picks a row of the grid: points 4..7 (y = 1), listed out of order */
    const asp_index row[4] = {6, 4, 7, 5};
    asp_covariance_sym3(p, 16, row, 4, NULL, c, cov);
    CHECK_NEAR(c[0], base + 1.5, 1e-9);
    CHECK_NEAR(c[1], -base + 1, 1e-9);
    CHECK_NEAR(cov[0], 1.25, 1e-12);
    CHECK_NEAR(cov[3], 0, 1e-12);
    /* "also" appends points after the list: row 1 plus point 0 (x 0, y 0) */
    const asp_index self = 0;
    asp_covariance_sym3(p, 16, row, 4, &(asp_covariance_desc){.also = &self, .also_count = 1}, c, cov);
    CHECK_NEAR(c[0], base + 6.0 / 5, 1e-9);
    CHECK_NEAR(c[1], -base + 4.0 / 5, 1e-9);
    CHECK_NEAR(cov[3], 4.0 / 25, 1e-12); /* y: four 1s and one 0: (4 * 1/25 + 16/25) / 5 */
    CHECK_NEAR(cov[4], 0, 1e-12);
}

/* Weights: two points weighted 3 and 1 equal four points with one repeated three times. */
static void test_weighted(void)
{
    const float p[6] = {0, 0, 0, 4, 2, 0};
    const float w[2] = {3, 1};
    double c[3], cov[6];
    asp_covariance_sym3(p, 12, NULL, 2, &(asp_covariance_desc){.weights = w}, c, cov);
    /* mean (1, 0.5, 0); var x = (3 * 1 + 9) / 4 = 3, cov xy = (3 * 0.5 + 3 * 1.5) / 4 = 1.5, var y = 0.75 */
    CHECK_NEAR(c[0], 1, 1e-15);
    CHECK_NEAR(c[1], 0.5, 1e-15);
    CHECK_NEAR(cov[0], 3, 1e-15);
    CHECK_NEAR(cov[1], 1.5, 1e-15);
    CHECK_NEAR(cov[3], 0.75, 1e-15);
    CHECK_NEAR(cov[5], 0, 1e-15);
    const float rep[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 4, 2, 0};
    double c2[3], cov2[6];
    asp_covariance_sym3(rep, 12, NULL, 4, NULL, c2, cov2);
    for (int e = 0; e < 6; e++)
        CHECK_NEAR(cov2[e], cov[e], 1e-15);
    /* weights are indexed by point: through an index list the weight follows the point */
    const asp_index rev[2] = {1, 0};
    asp_covariance_sym3(p, 12, rev, 2, &(asp_covariance_desc){.weights = w}, c2, cov2);
    CHECK(c2[0] == c[0] && cov2[0] == cov[0] && cov2[1] == cov[1]);
    /* all weights 0, or no points: zeros, never NaN */
    const float zero[2] = {0, 0};
    asp_covariance_sym3(p, 12, NULL, 2, &(asp_covariance_desc){.weights = zero}, c2, cov2);
    CHECK(c2[0] == 0 && c2[1] == 0 && cov2[0] == 0 && cov2[3] == 0);
    asp_covariance_sym3(p, 12, NULL, 0, NULL, c2, cov2);
    CHECK(c2[0] == 0 && cov2[0] == 0 && cov2[5] == 0);
}

/* About a given centre: the second moment, sum (p - centre)(p - centre)^T / n, while centroid stays the mean. */
static void test_about_centre(void)
{
    const float p[9] = {1, 0, 0, -1, 0, 0, 0, 2, 0};
    const double at[3] = {0, 0, 1};
    double c[3], cov[6];
    asp_covariance_sym3(p, 12, NULL, 3, &(asp_covariance_desc){.center = at}, c, cov);
    CHECK_NEAR(c[1], 2.0 / 3, 1e-15);
    CHECK_NEAR(cov[0], 2.0 / 3, 1e-15); /* x: 1 + 1 + 0 */
    CHECK_NEAR(cov[3], 4.0 / 3, 1e-15); /* y: 0 + 0 + 4 */
    CHECK_NEAR(cov[5], 1, 1e-15);       /* z: each point 1 below the centre */
    CHECK_NEAR(cov[4], -2.0 / 3, 1e-15);
    CHECK_NEAR(cov[1], 0, 1e-15);
}

/* The double entry point sums the same thing: same values for the same points (bit for bit, same order). */
static void test_double_matches_float(void)
{
    enum { N = 50 };
    float pf[3 * N];
    double pd[3 * N];
    uint32_t s = 7;
    for (int i = 0; i < 3 * N; i++) {
        s = s * 1664525u + 1013904223u;
        pf[i] = (float)(s >> 8) / (float)(1 << 24) * 3.0f - 1.0f;
        pd[i] = pf[i];
    }
    const asp_index idx[5] = {3, 40, 7, 7, 12}, also[2] = {0, 49};
    const asp_covariance_desc desc = {.also = also, .also_count = 2};
    double cf[3], covf[6], cd[3], covd[6];
    asp_covariance_sym3(pf, 12, idx, 5, &desc, cf, covf);
    asp_covariance_sym3d(pd, 24, idx, 5, &desc, cd, covd);
    CHECK(memcmp(cf, cd, sizeof cf) == 0 && memcmp(covf, covd, sizeof covf) == 0);
    CHECK(covf[0] > 0 && covf[3] > 0 && covf[5] > 0);
}

TEST_MAIN(TEST_CASE(test_line), TEST_CASE(test_plane_far_from_origin), TEST_CASE(test_weighted),
          TEST_CASE(test_about_centre), TEST_CASE(test_double_matches_float))
