/*
 * Synthetic models: counts, labels as ground truth, exact normals, points on
 * the analytic surface, discs that close all holes, determinism.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Fraction of query points covered by some disc (|q - x_j| <= r_j among the 24 nearest samples). */
static double covered_fraction(const asp_cloud *c, const float *queries, size_t nq)
{
    asp_kdtree *tree = NULL;
    if (asp_kdtree_create(c->positions, c->count, 12, NULL, &tree, NULL))
        return -1.0;
    size_t hit = 0;
    for (size_t q = 0; q < nq; q++) {
        asp_index idx[24];
        float d2[24];
        size_t got = asp_kdtree_knn(tree, queries + 3 * q, 24, idx, d2);
        for (size_t a = 0; a < got; a++)
            if (d2[a] <= c->radii[idx[a]] * c->radii[idx[a]]) {
                hit++;
                break;
            }
    }
    asp_kdtree_destroy(tree);
    return (double)hit / (double)nq;
}

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

static double urand(uint64_t *s)
{
    return (double)lcg(s) / 9007199254740992.0;
}

static void test_octahedron(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, NULL, NULL, &c, err), err);
    if (!c)
        return;
    CHECK(c->count == 16000);
    CHECK(c->labels && c->normals && c->colors && c->radii);
    size_t per_label[8] = {0};
    int on_surface = 1, normals_exact = 1, labels_match = 1;
    const float k = (float)(1.0 / sqrt(3.0));
    for (size_t i = 0; i < c->count; i++) {
        const float *p = c->positions + 3 * i, *n = c->normals + 3 * i;
        uint32_t l = c->labels[i];
        if (l >= 8) {
            labels_match = 0;
            continue;
        }
        per_label[l]++;
        if (fabs(fabs(p[0]) + fabs(p[1]) + fabs(p[2]) - 1.0) > 1e-6)
            on_surface = 0;
        for (int a = 0; a < 3; a++) {
            float s = (l >> a) & 1 ? -1.0f : 1.0f;
            if (n[a] != s * k)
                normals_exact = 0;
            if (p[a] * s < -1e-7f)
                labels_match = 0;
        }
    }
    CHECK(on_surface);
    CHECK(normals_exact);
    CHECK(labels_match);
    for (int l = 0; l < 8; l++)
        CHECK_MSG(per_label[l] == 2000, "face %d has %zu points", l, per_label[l]);
    /* distinct colours per face */
    for (size_t i = 0; i < 8; i++)
        for (size_t j = i + 1; j < 8; j++) {
            const uint8_t *a = c->colors + 4 * (i * 2000), *b = c->colors + 4 * (j * 2000);
            CHECK(c->labels[i * 2000] != c->labels[j * 2000]);
            CHECK(memcmp(a, b, 3) != 0);
        }
    /* every point of every face is inside some disc */
    enum { NQ = 20000 };
    static float q[3 * NQ];
    uint64_t s = 7;
    for (size_t i = 0; i < NQ; i++) {
        double u = urand(&s), v = urand(&s);
        if (u + v > 1.0)
            u = 1.0 - u, v = 1.0 - v;
        double w[3] = {1.0 - u - v, u, v};
        uint32_t f = (uint32_t)(lcg(&s) % 8);
        for (int a = 0; a < 3; a++)
            q[3 * i + a] = (float)(((f >> a) & 1 ? -1.0 : 1.0) * w[a]);
    }
    double cov = covered_fraction(c, q, NQ);
    CHECK_MSG(cov == 1.0, "covered fraction %.6f", cov);
    /* the radii are not absurdly large: about the point spacing */
    double mean_r = 0.0;
    for (size_t i = 0; i < c->count; i++)
        mean_r += c->radii[i];
    mean_r /= (double)c->count;
    double spacing = sqrt(8.0 * (sqrt(3.0) / 2.0) / 16000.0);
    CHECK_MSG(mean_r > 0.5 * spacing && mean_r < 1.2 * spacing, "mean radius %g, spacing %g", mean_r, spacing);
    asp_cloud_destroy(c);
}

static void test_cube_sphere_torus(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_CUBE, NULL, NULL, &c, err), err);
    if (c) {
        CHECK(c->count == 24000);
        size_t per[6] = {0};
        int ok = 1;
        for (size_t i = 0; i < c->count; i++) {
            uint32_t f = c->labels[i];
            if (f >= 6) {
                ok = 0;
                continue;
            }
            per[f]++;
            int axis = (int)f / 2;
            float s = (f & 1) ? -1.0f : 1.0f;
            if (c->positions[3 * i + axis] != s || c->normals[3 * i + axis] != s)
                ok = 0;
        }
        CHECK(ok);
        for (int f = 0; f < 6; f++)
            CHECK(per[f] == 4000);
        asp_cloud_destroy(c);
    }
    c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 5000}, NULL, &c, err), err);
    if (c) {
        CHECK(c->count == 5000);
        CHECK(c->labels == NULL);
        double worst = 0.0;
        for (size_t i = 0; i < c->count; i++) {
            const float *p = c->positions + 3 * i, *n = c->normals + 3 * i;
            worst = fmax(worst, fabs(sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0));
            worst = fmax(worst, fabs(p[0] - n[0]) + fabs(p[1] - n[1]) + fabs(p[2] - n[2]));
        }
        CHECK(worst < 1e-6);
        enum { NQ = 5000 };
        static float q[3 * NQ];
        uint64_t s = 3;
        for (size_t i = 0; i < NQ; i++) {
            double z = 2.0 * urand(&s) - 1.0, phi = 2.0 * M_PI * urand(&s), r = sqrt(1.0 - z * z);
            q[3 * i] = (float)(r * cos(phi)), q[3 * i + 1] = (float)(r * sin(phi)), q[3 * i + 2] = (float)z;
        }
        double cov = covered_fraction(c, q, NQ);
        CHECK_MSG(cov == 1.0, "sphere covered fraction %.6f", cov);
        asp_cloud_destroy(c);
    }
    c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_TORUS, &(asp_synth_desc){.points = 8000}, NULL, &c, err), err);
    if (c) {
        double worst = 0.0;
        for (size_t i = 0; i < c->count; i++) {
            const float *p = c->positions + 3 * i;
            double ring = sqrt(p[0] * p[0] + p[1] * p[1]) - 1.0;
            worst = fmax(worst, fabs(sqrt(ring * ring + p[2] * p[2]) - 0.35));
        }
        CHECK(worst < 1e-6);
        /* even density: the outer half (x^2+y^2 > 1) has area share (pi R + 2 r)/(2 pi R) */
        size_t outer = 0;
        for (size_t i = 0; i < c->count; i++)
            outer += c->positions[3 * i] * c->positions[3 * i] + c->positions[3 * i + 1] * c->positions[3 * i + 1] > 1.0f;
        double expect = (M_PI + 2 * 0.35) / (2 * M_PI);
        CHECK_NEAR((double)outer / (double)c->count, expect, 0.01);
        asp_cloud_destroy(c);
    }
}

static void test_checker_plane(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_CHECKER_PLANE, NULL, NULL, &c, err), err);
    if (!c)
        return;
    CHECK(c->count == 262144);
    size_t ones = 0;
    int ok = 1;
    double spacing = 2.0 / 511.0;
    for (size_t i = 0; i < c->count; i++) {
        ones += c->labels[i];
        if (c->normals[3 * i + 2] != 1.0f || c->positions[3 * i + 2] != 0.0f)
            ok = 0;
        if (!(c->radii[i] >= spacing * sqrt(0.5)) || c->radii[i] > spacing)
            ok = 0;
    }
    CHECK(ok);
    CHECK(ones == 131072);
    /* the square pattern: point (i, j) in square (i / 64, j / 64), colours alternate */
    CHECK(c->labels[0] == 0 && c->labels[63] == 0 && c->labels[64] == 1 && c->labels[64 * 512] == 1);
    CHECK(c->labels[64 * 512 + 64] == 0);
    CHECK(memcmp(c->colors, c->colors + 4 * 64, 3) != 0);
    asp_cloud_destroy(c);
}

static void test_determinism(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_cloud *a = NULL, *b = NULL, *d = NULL;
    asp_context one = {.threads = 1}, two = {.threads = 2};
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000, .seed = 5}, &one, &a, err), err);
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000, .seed = 5}, &two, &b, err), err);
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000, .seed = 6}, &two, &d, err), err);
    if (a && b && d) {
        CHECK(memcmp(a->positions, b->positions, 12 * a->count) == 0);
        CHECK(memcmp(a->radii, b->radii, 4 * a->count) == 0);
        CHECK(memcmp(a->positions, d->positions, 12 * a->count) != 0);
    }
    asp_cloud_destroy(a);
    asp_cloud_destroy(b);
    asp_cloud_destroy(d);
}

static void test_errors(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_cloud *c = NULL;
    CHECK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 10}, NULL, &c, err) == ASP_EINVAL);
    CHECK(strstr(err->msg, "octahedron") != NULL);
    CHECK(asp_synth((asp_synth_shape)42, NULL, NULL, &c, err) == ASP_EINVAL);
    CHECK(asp_synth(ASP_SYNTH_CHECKER_PLANE, &(asp_synth_desc){.grid = 1}, NULL, &c, err) == ASP_EINVAL);
    CHECK(c == NULL);
    asp_synth_shape s;
    CHECK(asp_synth_shape_parse("checker-plane", &s, err) == 0 && s == ASP_SYNTH_CHECKER_PLANE);
    CHECK(asp_synth_shape_parse("dodecahedron", &s, err) == ASP_EINVAL);
    CHECK(strstr(err->msg, "dodecahedron") != NULL);
    CHECK(strcmp(asp_synth_shape_name(ASP_SYNTH_TORUS), "torus") == 0);
}

TEST_MAIN(TEST_CASE(test_octahedron), TEST_CASE(test_cube_sphere_torus), TEST_CASE(test_checker_plane),
          TEST_CASE(test_determinism), TEST_CASE(test_errors))
