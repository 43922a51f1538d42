/*
 * Symmetric 3x3 eigen solver: diagonal matrices, random rotations of given
 * spectra (distinct, repeated, rank-1, zero), huge and tiny scales; checks
 * A v = l v, orthonormality and right-handedness to 1e-10 relative. The
 * covariance it is applied to is tested in test_geom_covariance.c.
 */
#include <stdint.h>

#include "amgsplat/geom.h"
#include "harness.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* Random rotation from a random unit quaternion. */
static void random_rotation(double r[3][3])
{
    double q[4], n = 0;
    for (int i = 0; i < 4; i++) {
        q[i] = urand() * 2 - 1;
        n += q[i] * q[i];
    }
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    r[0][0] = 1 - 2 * (y * y + z * z), r[0][1] = 2 * (x * y - w * z), r[0][2] = 2 * (x * z + w * y);
    r[1][0] = 2 * (x * y + w * z), r[1][1] = 1 - 2 * (x * x + z * z), r[1][2] = 2 * (y * z - w * x);
    r[2][0] = 2 * (x * z - w * y), r[2][1] = 2 * (y * z + w * x), r[2][2] = 1 - 2 * (x * x + y * y);
}

/* m = R diag(l) R^T in packed {xx, xy, xz, yy, yz, zz} form. */
static void compose(const double l[3], double r[3][3], double m[6])
{
    double a[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            a[i][j] = 0;
            for (int k = 0; k < 3; k++)
                a[i][j] += r[i][k] * l[k] * r[j][k];
        }
    m[0] = a[0][0], m[1] = a[0][1], m[2] = a[0][2], m[3] = a[1][1], m[4] = a[1][2], m[5] = a[2][2];
}

/* Largest relative error of the decomposition; also checks ordering and handedness. */
static double decomposition_error(const double m[6], const double ev[3], const double V[9])
{
    double a[3][3] = {{m[0], m[1], m[2]}, {m[1], m[3], m[4]}, {m[2], m[4], m[5]}};
    double norm = 0;
    for (int i = 0; i < 6; i++)
        norm = fmax(norm, fabs(m[i]));
    double worst = 0;
    for (int k = 0; k < 3; k++) {
        for (int r = 0; r < 3; r++) {
            double av = 0;
            for (int c = 0; c < 3; c++)
                av += a[r][c] * V[3 * c + k];
            double res = fabs(av - ev[k] * V[3 * r + k]);
            worst = fmax(worst, norm > 0 ? res / norm : res);
        }
        for (int j = 0; j < 3; j++) {
            double dot = 0;
            for (int r = 0; r < 3; r++)
                dot += V[3 * r + k] * V[3 * r + j];
            worst = fmax(worst, fabs(dot - (j == k ? 1.0 : 0.0)));
        }
    }
    if (ev[0] < ev[1] || ev[1] < ev[2])
        worst = INFINITY;
    /* right-handed: det(V) = +1 */
    double det = V[0] * (V[4] * V[8] - V[5] * V[7]) - V[1] * (V[3] * V[8] - V[5] * V[6]) +
                 V[2] * (V[3] * V[7] - V[4] * V[6]);
    worst = fmax(worst, fabs(det - 1.0));
    return worst;
}

static void check_spectrum(double l0, double l1, double l2, int trials, const char *name)
{
    double worst = 0, worst_eval = 0;
    for (int t = 0; t < trials; t++) {
        double r[3][3], m[6], ev[3], V[9];
        double l[3] = {l0, l1, l2};
        random_rotation(r);
        compose(l, r, m);
        asp_eigen_sym3(m, ev, V);
        worst = fmax(worst, decomposition_error(m, ev, V));
        /* expected spectrum, sorted descending */
        double s[3] = {l0, l1, l2};
        for (int i = 0; i < 3; i++)
            for (int j = i + 1; j < 3; j++)
                if (s[j] > s[i]) {
                    double x = s[i];
                    s[i] = s[j];
                    s[j] = x;
                }
        double scale = fmax(fabs(s[0]), fabs(s[2]));
        for (int i = 0; i < 3; i++)
            worst_eval = fmax(worst_eval, fabs(ev[i] - s[i]) / (scale > 0 ? scale : 1));
    }
    CHECK_MSG(worst < 1e-10, "%s: residual %.3g", name, worst);
    CHECK_MSG(worst_eval < 1e-10, "%s: eigenvalue error %.3g", name, worst_eval);
}

static void test_diagonal(void)
{
    double m[6] = {2, 0, 0, 5, 0, -1}, ev[3], V[9];
    asp_eigen_sym3(m, ev, V);
    CHECK(ev[0] == 5 && ev[1] == 2 && ev[2] == -1);
    CHECK(fabs(V[3 * 1 + 0]) == 1.0 && fabs(V[3 * 0 + 1]) == 1.0 && fabs(V[3 * 2 + 2]) == 1.0);
    CHECK(decomposition_error(m, ev, V) < 1e-15);
}

static void test_distinct(void)
{
    check_spectrum(3, 2, 1, 2000, "distinct");
    check_spectrum(1, -4, 0.5, 500, "indefinite");
    check_spectrum(1, 1e-6, 1e-12, 500, "ill-conditioned");
}

static void test_repeated(void)
{
    check_spectrum(2, 2, 1, 500, "double-top");
    check_spectrum(3, 1, 1, 500, "double-bottom");
    check_spectrum(7, 7, 7, 200, "triple");
    check_spectrum(1, 1 + 1e-12, 1 - 1e-12, 500, "near-triple");
}

static void test_rank1_and_zero(void)
{
    check_spectrum(1, 0, 0, 500, "rank-1");
    check_spectrum(1, 1, 0, 500, "rank-2");
    double z[6] = {0}, ev[3], V[9];
    asp_eigen_sym3(z, ev, V);
    CHECK(ev[0] == 0 && ev[1] == 0 && ev[2] == 0);
    CHECK(V[0] == 1 && V[4] == 1 && V[8] == 1 && V[1] == 0);
}

static void test_scales(void)
{
    check_spectrum(3e150, 2e150, 1e150, 200, "huge");
    check_spectrum(3e-150, 2e-150, 1e-150, 200, "tiny");
    check_spectrum(3e-300, 1e-300, 0, 200, "denormal-ish");
}

static void test_non_finite(void)
{
    double m[6] = {1, NAN, 0, 1, 0, 1}, ev[3], V[9];
    asp_eigen_sym3(m, ev, V);
    CHECK(isnan(ev[0]) && isnan(ev[2]));
    CHECK(V[0] == 1 && V[4] == 1 && V[8] == 1);
}

TEST_MAIN(TEST_CASE(test_diagonal), TEST_CASE(test_distinct), TEST_CASE(test_repeated),
          TEST_CASE(test_rank1_and_zero), TEST_CASE(test_scales), TEST_CASE(test_non_finite))
