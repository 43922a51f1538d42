/*
 * Local surface classification (journal 2.1 eq. 1-3, thesis 2.3): flat
 * neighbourhoods get the maximum 1/alpha and the plane's normal, creases get
 * less (the sharper, the less), degenerate neighbourhoods are reported.
 */
#include "amgsplat/amg.h"
#include "harness.h"

static const double PI = 3.14159265358979323846;

/* A disc of m points of radius r around the origin in the plane with unit normal n, on a spiral. */
static void disc(double *pts, size_t m, double r, const double n[3])
{
    double e0[3], e1[3];
    double h[3] = {fabs(n[0]) < 0.9 ? 1 : 0, fabs(n[0]) < 0.9 ? 0 : 1, 0};
    e0[0] = h[1] * n[2] - h[2] * n[1];
    e0[1] = h[2] * n[0] - h[0] * n[2];
    e0[2] = h[0] * n[1] - h[1] * n[0];
    double l = sqrt(e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]);
    for (int a = 0; a < 3; a++)
        e0[a] /= l;
    e1[0] = n[1] * e0[2] - n[2] * e0[1];
    e1[1] = n[2] * e0[0] - n[0] * e0[2];
    e1[2] = n[0] * e0[1] - n[1] * e0[0];
    for (size_t j = 0; j < m; j++) {
        double rad = r * sqrt(((double)j + 0.5) / (double)m), ang = (double)j * 2.399963;
        for (int a = 0; a < 3; a++)
            pts[3 * j + a] = rad * (cos(ang) * e0[a] + sin(ang) * e1[a]);
    }
}

/* Folds a disc of m points along the y axis by the dihedral deviation angle dev (radians). */
static void crease(double *pts, size_t m, double r, double dev)
{
    const double z[3] = {0, 0, 1};
    disc(pts, m, r, z);
    for (size_t j = 0; j < m; j++)
        if (pts[3 * j] > 0) {
            double x = pts[3 * j];
            pts[3 * j] = x * cos(dev);
            pts[3 * j + 2] = x * sin(dev);
        }
}

static void test_flat(void)
{
    double pts[3 * 60], c, nrm[3];
    const double n[3] = {0.48, -0.6, 0.64};
    for (int kind = 0; kind < 2; kind++) {
        disc(pts, 60, 1.0, n);
        CHECK_OK(asp_amg_classify_points(pts, 60, 1.0, kind, 0, 0, &c, nrm), (asp_error *)NULL);
        CHECK_NEAR(c, 100.0, 1e-6); /* G(0) = 1 / alpha */
        double dot = nrm[0] * n[0] + nrm[1] * n[1] + nrm[2] * n[2];
        CHECK_NEAR(fabs(dot), 1.0, 1e-9);
        /* other constants: G(0) = 1 / alpha */
        CHECK_OK(asp_amg_classify_points(pts, 60, 1.0, kind, 0.5, 3, &c, nrm), (asp_error *)NULL);
        CHECK_NEAR(c, 2.0, 1e-6);
    }
}

static void test_crease_ordering(void)
{
    double pts[3 * 200], nrm[3];
    for (int kind = 0; kind < 2; kind++) {
        double prev = 1e300;
        /* 10, 30, 60, 90 degrees of folding: the classifier falls monotonically */
        const double dev[4] = {10, 30, 60, 90};
        for (int d = 0; d < 4; d++) {
            double c;
            crease(pts, 200, 1.0, dev[d] * PI / 180);
            CHECK_OK(asp_amg_classify_points(pts, 200, 1.0, kind, 0, 0, &c, nrm), (asp_error *)NULL);
            CHECK_MSG(c < prev, "kind %d: %g degrees gives %g, not below %g", kind, dev[d], c, prev);
            CHECK(c > 0 && c < 100);
            prev = c;
        }
        CHECK_MSG(prev < (kind == 0 ? 10.0 : 60.0), "kind %d: a right-angle crease gives %g", kind, prev);
    }
}

static void test_variation_value(void)
{
    /* four points of a regular tetrahedron: isotropic, sigma = 1/3, C = 1 / (0.01 + 100/9) */
    double pts[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1}, c, nrm[3];
    CHECK_OK(asp_amg_classify_points(pts, 4, 2.0, ASP_AMG_CLASSIFIER_VARIATION, 0, 0, &c, nrm), (asp_error *)NULL);
    CHECK_NEAR(c, 1.0 / (0.01 + 100.0 / 9.0), 1e-9);
    /* journal eq. 3 with x off the barycentre: s = |M0 - x| l2 / (eps l0) = sqrt(3) * 1 / (2 * 1) */
    for (int j = 0; j < 4; j++)
        for (int a = 0; a < 3; a++)
            pts[3 * j + a] += 1.0; /* barycentre moves to (1,1,1): |M0 - x| = sqrt(3) */
    CHECK_OK(asp_amg_classify_points(pts, 4, 2.0, ASP_AMG_CLASSIFIER_MOMENT, 0, 0, &c, nrm), (asp_error *)NULL);
    double s = sqrt(3.0) / 2.0;
    CHECK_NEAR(c, 1.0 / (0.01 + 100 * s * s), 1e-9);
}

static void test_degenerate(void)
{
    double pts[9] = {0}, c = -1, nrm[3];
    CHECK(asp_amg_classify_points(pts, 3, 1.0, 0, 0, 0, &c, nrm) == ASP_EDEGENERATE);
    CHECK_NEAR(c, 100.0, 0);
    CHECK_NEAR(nrm[2], 1.0, 0);
    double two[6] = {0, 0, 0, 1, 0, 0};
    CHECK(asp_amg_classify_points(two, 2, 1.0, 0, 0, 0, &c, nrm) == ASP_EDEGENERATE);
    /* colinear points have an eigenvalue, and a well-defined (if arbitrary) normal */
    double line[15] = {0, 0, 0, 1, 1, 1, 2, 2, 2, -1, -1, -1, 3, 3, 3};
    CHECK(asp_amg_classify_points(line, 5, 1.0, 0, 0, 0, &c, nrm) == 0);
    CHECK_NEAR(nrm[0] + nrm[1] + nrm[2], 0.0, 1e-9); /* perpendicular to the line */
    CHECK(isfinite(c));
}

TEST_MAIN(TEST_CASE(test_flat), TEST_CASE(test_crease_ordering), TEST_CASE(test_variation_value),
          TEST_CASE(test_degenerate))
