/*
 * Normal estimation: accuracy and outward orientation on a sphere, two
 * separate spheres (two MST components), a torus and a plane; viewpoint and
 * existing-normal orientation; thread-count independence; the cloud-level
 * asp_cloud_estimate; malformed input.
 */
#include <stdint.h>

#include "amgsplat/geom.h"
#include "harness.h"

static uint64_t rng_state = 0xA0761D6478BD642Full;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* n random points on a sphere; true outward normals to tn (may be NULL). */
static void sphere(float *p, float *tn, size_t n, const float c[3], float r)
{
    for (size_t i = 0; i < n; i++) {
        double z = 2 * urand() - 1, phi = 6.283185307179586 * urand(), s = sqrt(1 - z * z);
        double u[3] = {s * cos(phi), s * sin(phi), z};
        for (int a = 0; a < 3; a++) {
            p[3 * i + a] = (float)(c[a] + r * u[a]);
            if (tn)
                tn[3 * i + a] = (float)u[a];
        }
    }
}

/* Largest angle in degrees between estimated and true normals, and how many point against it. */
static double worst_angle(const float *n, const float *tn, size_t count, size_t *flipped)
{
    double worst = 0;
    *flipped = 0;
    for (size_t i = 0; i < count; i++) {
        double d = 0, len = 0;
        for (int a = 0; a < 3; a++) {
            d += (double)n[3 * i + a] * tn[3 * i + a];
            len += (double)n[3 * i + a] * n[3 * i + a];
        }
        if (d <= 0)
            (*flipped)++;
        worst = fmax(worst, acos(fmin(1.0, fabs(d) / sqrt(len))) * 57.29577951308232);
    }
    return worst;
}

static void test_sphere(void)
{
    size_t n = 20000;
    float *p = malloc(3 * n * sizeof(float)), *tn = malloc(3 * n * sizeof(float)), *nr = malloc(3 * n * sizeof(float));
    sphere(p, tn, n, (float[3]){0, 0, 0}, 1.0f);
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_normals(p, n, 12, &(asp_normals_desc){.k = 16}, nr, NULL, err), err);
    size_t flipped;
    double worst = worst_angle(nr, tn, n, &flipped);
    fprintf(stderr, "sphere: worst angle %.3f deg, %zu inward\n", worst, flipped);
    CHECK_MSG(worst < 2.0, "worst angle %.3f deg", worst);
    CHECK_MSG(flipped == 0, "%zu normals point inwards", flipped);
    int unit = 1;
    for (size_t i = 0; i < n; i++)
        unit &= fabs(sqrt(nr[3 * i] * nr[3 * i] + nr[3 * i + 1] * nr[3 * i + 1] + nr[3 * i + 2] * nr[3 * i + 2]) -
                     1) < 1e-6;
    CHECK(unit);

    /* same result for 1 and 2 threads */
    float *n1 = malloc(3 * n * sizeof(float));
    CHECK_OK(asp_estimate_normals(p, n, 12, NULL, n1, &(asp_context){.threads = 1}, err), err);
    CHECK(memcmp(n1, nr, 3 * n * sizeof(float)) == 0);

    /* viewpoint at the centre: every normal turns inwards */
    CHECK_OK(asp_estimate_normals(p, n, 12, &(asp_normals_desc){.orient = ASP_ORIENT_VIEWPOINT}, n1, NULL, err), err);
    worst_angle(n1, tn, n, &flipped);
    CHECK(flipped == n);

    /* existing normals: keep the (inward) signs passed in */
    for (size_t i = 0; i < 3 * n; i++)
        n1[i] = -tn[i];
    CHECK_OK(asp_estimate_normals(p, n, 12, &(asp_normals_desc){.orient = ASP_ORIENT_EXISTING}, n1, NULL, err), err);
    worst_angle(n1, tn, n, &flipped);
    CHECK(flipped == n);
    free(n1);
    free(p);
    free(tn);
    free(nr);
}

/* Two spheres far apart: two components of the k-NN graph, each seeded on its own. */
static void test_two_spheres(void)
{
    size_t n1 = 6000, n2 = 3000, n = n1 + n2;
    float *p = malloc(3 * n * sizeof(float)), *tn = malloc(3 * n * sizeof(float)), *nr = malloc(3 * n * sizeof(float));
    sphere(p, tn, n1, (float[3]){0, 0, 0}, 1.0f);
    sphere(p + 3 * n1, tn + 3 * n1, n2, (float[3]){4, 1, -2}, 0.5f);
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_normals(p, n, 12, NULL, nr, NULL, err), err);
    size_t flipped;
    double worst = worst_angle(nr, tn, n, &flipped);
    fprintf(stderr, "two spheres: worst angle %.3f deg, %zu inward\n", worst, flipped);
    CHECK(flipped == 0);
    CHECK(worst < 5.0);
    free(p);
    free(tn);
    free(nr);
}

static void test_torus(void)
{
    size_t n = 20000;
    const double R = 1.0, r = 0.35;
    float *p = malloc(3 * n * sizeof(float)), *tn = malloc(3 * n * sizeof(float)), *nr = malloc(3 * n * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        /* area-uniform by rejection on the tube angle */
        double u, v;
        do {
            u = 6.283185307179586 * urand();
            v = 6.283185307179586 * urand();
        } while (urand() * (R + r) > R + r * cos(v));
        double nx = cos(v) * cos(u), ny = cos(v) * sin(u), nz = sin(v);
        p[3 * i] = (float)(R * cos(u) + r * nx);
        p[3 * i + 1] = (float)(R * sin(u) + r * ny);
        p[3 * i + 2] = (float)(r * nz);
        tn[3 * i] = (float)nx, tn[3 * i + 1] = (float)ny, tn[3 * i + 2] = (float)nz;
    }
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_normals(p, n, 12, NULL, nr, NULL, err), err);
    size_t flipped;
    double worst = worst_angle(nr, tn, n, &flipped);
    fprintf(stderr, "torus: worst angle %.3f deg, %zu inward\n", worst, flipped);
    CHECK(flipped == 0);
    /* the tube radius 0.35 curves 3x more than the unit sphere, and PCA bias grows with curvature */
    CHECK(worst < 8.0);
    free(p);
    free(tn);
    free(nr);
}

/* A noisy-free plane z = 0 seeded on its first highest point: all normals +z. */
static void test_plane_and_small(void)
{
    size_t n = 3000;
    float *p = malloc(3 * n * sizeof(float)), *nr = malloc(3 * n * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        p[3 * i] = (float)urand();
        p[3 * i + 1] = (float)urand();
        p[3 * i + 2] = 0.0f;
    }
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_estimate_normals(p, n, 12, NULL, nr, NULL, err), err);
    int up = 1;
    for (size_t i = 0; i < n; i++)
        up &= nr[3 * i + 2] == 1.0f || fabsf(nr[3 * i + 2] - 1.0f) < 1e-6f;
    CHECK(up);
    /* three points: k is clamped to 2, the normal is the triangle's */
    float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK_OK(asp_estimate_normals(tri, 3, 12, &(asp_normals_desc){.k = 99}, nr, NULL, err), err);
    CHECK_NEAR(nr[2], 1.0, 1e-6);
    CHECK_NEAR(nr[5], 1.0, 1e-6);
    free(p);
    free(nr);
}

static void test_cloud_estimate(void)
{
    size_t n = 5000;
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_cloud_create(n, 0, NULL, &c, err), err);
    if (!c)
        return;
    float *tn = malloc(3 * n * sizeof(float));
    sphere(c->positions, tn, n, (float[3]){0, 0, 0}, 2.0f);
    CHECK_OK(asp_cloud_estimate(c, &(asp_estimate_desc){.k = 12, .normals = 1, .radii = 1}, err), err);
    CHECK((asp_cloud_attrs(c) & (ASP_ATTR_NORMALS | ASP_ATTR_RADII)) == (ASP_ATTR_NORMALS | ASP_ATTR_RADII));
    size_t flipped;
    if (c->normals) {
        double worst = worst_angle(c->normals, tn, n, &flipped);
        CHECK(flipped == 0 && worst < 5.0);
    }
    /* radii equal the standalone estimator's */
    float *r = malloc(n * sizeof(float));
    CHECK_OK(asp_estimate_radii(c->positions, n, 12, NULL, r, NULL, err), err);
    CHECK(c->radii && memcmp(r, c->radii, n * sizeof(float)) == 0);
    /* present attributes are kept without force, recomputed with it */
    c->radii[0] = 123.0f;
    c->normals[0] = 5.0f;
    CHECK_OK(asp_cloud_estimate(c, &(asp_estimate_desc){.normals = 1, .radii = 1}, err), err);
    CHECK(c->radii[0] == 123.0f && c->normals[0] == 5.0f);
    CHECK_OK(asp_cloud_estimate(c, &(asp_estimate_desc){.radii = 1, .force = 1}, err), err);
    CHECK(c->radii[0] == r[0] && c->normals[0] == 5.0f);
    /* force + existing orientation: flip the stored normals inwards first */
    for (size_t i = 0; i < 3 * n; i++)
        c->normals[i] = -tn[i];
    CHECK_OK(asp_cloud_estimate(c, &(asp_estimate_desc){.normals = 1, .force = 1, .orient = ASP_ORIENT_EXISTING}, err),
             err);
    worst_angle(c->normals, tn, n, &flipped);
    CHECK(flipped == n);
    free(r);
    free(tn);
    asp_cloud_destroy(c);

    /* failure leaves the cloud unchanged */
    CHECK_OK(asp_cloud_create(4, 0, NULL, &c, err), err);
    CHECK(asp_cloud_estimate(c, &(asp_estimate_desc){.normals = 1, .radii = 1}, err) == ASP_EDEGENERATE);
    CHECK(asp_cloud_attrs(c) == 0);
    asp_cloud_destroy(c);
}

static void test_errors(void)
{
    asp_error e = {0}, *err = &e;
    float nr[12] = {9, 9, 9};
    float two[6] = {0, 0, 0, 1, 0, 0};
    CHECK(asp_estimate_normals(two, 2, 12, NULL, nr, NULL, err) == ASP_EDEGENERATE);
    CHECK_MSG(strstr(err->msg, "at least 3") != NULL, "%s", err->msg);
    float same[12] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    CHECK(asp_estimate_normals(same, 4, 12, NULL, nr, NULL, err) == ASP_EDEGENERATE);
    CHECK_MSG(strstr(err->msg, "all 4 points are equal") != NULL, "%s", err->msg);
    float nan[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN};
    CHECK(asp_estimate_normals(nan, 4, 12, NULL, nr, NULL, err) == ASP_EINVAL);
    CHECK_MSG(strstr(err->msg, "point 3: coordinate z") != NULL, "%s", err->msg);
    float quad[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    asp_index knn[4] = {1, 2, 3, 4};
    CHECK(asp_normals_from_knn(quad, 4, 12, knn, 1, NULL, nr, NULL, err) == ASP_EINVAL);
    CHECK_MSG(strstr(err->msg, "row 3, column 0: index 4") != NULL, "%s", err->msg);
    CHECK(asp_normals_from_knn(quad, 4, 12, knn, 0, NULL, nr, NULL, err) == ASP_EINVAL);
    CHECK(asp_estimate_normals(quad, 4, 12, &(asp_normals_desc){.orient = (asp_orient)17}, nr, NULL, err) ==
          ASP_EINVAL);
    CHECK(asp_estimate_normals(quad, 4, 12,
                               &(asp_normals_desc){.orient = ASP_ORIENT_VIEWPOINT, .viewpoint = {NAN, 0, 0}}, nr,
                               NULL, err) == ASP_EINVAL);
    CHECK(nr[0] == 9 && nr[1] == 9);
}

TEST_MAIN(TEST_CASE(test_sphere), TEST_CASE(test_two_spheres), TEST_CASE(test_torus),
          TEST_CASE(test_plane_and_small), TEST_CASE(test_cloud_estimate), TEST_CASE(test_errors))
