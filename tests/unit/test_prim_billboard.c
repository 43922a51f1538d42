/*
 * Billboard clouds (issue 30; Decoret et al. 2003): every face (disc) ends
 * within the error bound of its plane, measured here from the vertices
 * independently of the search; plane counts are sane; the result is the same
 * for any thread count; the .dps level keeps its billboards flag and a binary
 * alpha; bad options are refused.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "amgsplat/billboard.h"
#include "amgsplat/io.h"
#include "harness.h"

static void set_tri(asp_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c)
{
    m->triangles[3 * t] = a, m->triangles[3 * t + 1] = b, m->triangles[3 * t + 2] = c;
}

/* An axis-aligned box of sides sx, sy, sz: 8 vertices, 12 triangles. */
static asp_mesh *box(float sx, float sy, float sz)
{
    asp_mesh *m = NULL;
    if (asp_mesh_create(8, 12, 0, NULL, &m, NULL))
        return NULL;
    for (uint32_t v = 0; v < 8; v++) {
        float p[3] = {(v & 1) ? sx / 2 : -sx / 2, (v & 2) ? sy / 2 : -sy / 2, (v & 4) ? sz / 2 : -sz / 2};
        memcpy(m->positions + 3 * v, p, sizeof p);
        float l = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int k = 0; k < 3; k++)
            m->normals[3 * v + k] = p[k] / l;
    }
    static const uint32_t q[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (size_t f = 0; f < 6; f++) {
        set_tri(m, 2 * f, q[f][0], q[f][1], q[f][2]);
        set_tri(m, 2 * f + 1, q[f][0], q[f][2], q[f][3]);
    }
    return m;
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float unit_rand(uint32_t *s)
{
    return (float)lcg(s) / (float)(1u << 24);
}

/*
 * A triangle soup: count crossed pairs of quads (two quads through one vertical axis at right angles,
 * turned at random, like foliage cards), scattered over a square of side 10: disconnected, intersecting.
 */
static asp_mesh *crossed_quads(size_t count, uint32_t seed)
{
    asp_mesh *m = NULL;
    if (asp_mesh_create(8 * count, 4 * count, 0, NULL, &m, NULL))
        return NULL;
    for (size_t c = 0; c < count; c++) {
        float cx = 10 * unit_rand(&seed) - 5, cz = 10 * unit_rand(&seed) - 5, a = 3.14159265f * unit_rand(&seed);
        float h = 1 + unit_rand(&seed), w = 0.5f + 0.5f * unit_rand(&seed), tilt = 0.3f * (unit_rand(&seed) - 0.5f);
        for (int q = 0; q < 2; q++) {
            float ang = a + q * 1.5707963f, dx = cosf(ang) * w, dz = sinf(ang) * w;
            uint32_t v0 = (uint32_t)(8 * c + 4 * (size_t)q);
            float p[4][3] = {{cx - dx, 0, cz - dz}, {cx + dx, 0, cz + dz}, {cx + dx + tilt, h, cz + dz}, {cx - dx + tilt, h, cz - dz}};
            for (int k = 0; k < 4; k++) {
                memcpy(m->positions + 3 * (v0 + (uint32_t)k), p[k], sizeof p[k]);
                float n[3] = {-sinf(ang), 0, cosf(ang)};
                memcpy(m->normals + 3 * (v0 + (uint32_t)k), n, sizeof n);
            }
            set_tri(m, 4 * c + 2 * (size_t)q, v0, v0 + 1, v0 + 2);
            set_tri(m, 4 * c + 2 * (size_t)q + 1, v0, v0 + 2, v0 + 3);
        }
    }
    return m;
}

/* A UV sphere of radius 1 (rings x segs, poles fanned). */
static asp_mesh *sphere(size_t rings, size_t segs)
{
    size_t nv = (rings - 1) * segs + 2, nt = 2 * segs * (rings - 1);
    asp_mesh *m = NULL;
    if (asp_mesh_create(nv, nt, 0, NULL, &m, NULL))
        return NULL;
    const double pi = 3.14159265358979323846;
    float *P = m->positions;
    P[0] = 0, P[1] = 1, P[2] = 0;
    for (size_t r = 1; r < rings; r++)
        for (size_t s = 0; s < segs; s++) {
            double th = pi * (double)r / (double)rings, ph = 2 * pi * (double)s / (double)segs;
            float *p = P + 3 * (1 + (r - 1) * segs + s);
            p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(sin(th) * sin(ph));
        }
    float *last = P + 3 * (nv - 1);
    last[0] = 0, last[1] = -1, last[2] = 0;
    memcpy(m->normals, m->positions, 3 * nv * sizeof(float));
    size_t t = 0;
    for (size_t s = 0; s < segs; s++)
        set_tri(m, t++, 0, (uint32_t)(1 + (s + 1) % segs), (uint32_t)(1 + s));
    for (size_t r = 1; r + 1 < rings; r++)
        for (size_t s = 0; s < segs; s++) {
            uint32_t a = (uint32_t)(1 + (r - 1) * segs + s), b = (uint32_t)(1 + (r - 1) * segs + (s + 1) % segs);
            uint32_t c = a + (uint32_t)segs, d = b + (uint32_t)segs;
            set_tri(m, t++, a, b, d);
            set_tri(m, t++, a, d, c);
        }
    for (size_t s = 0; s < segs; s++)
        set_tri(m, t++, (uint32_t)(nv - 1), (uint32_t)(1 + (rings - 2) * segs + s),
                (uint32_t)(1 + (rings - 2) * segs + (s + 1) % segs));
    return m;
}

static double diagonal(const float *p, size_t n)
{
    float lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            lo[k] = fminf(lo[k], p[3 * i + k]), hi[k] = fmaxf(hi[k], p[3 * i + k]);
    return sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) + (double)(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/*
 * Searches m at bound e and checks every face: assigned to an existing plane, each vertex within
 * e * diagonal of it (a float's rounding of slack). Returns the plane count (0 on failure).
 */
static size_t check_mesh_cover(const asp_mesh *m, double e, int threads, uint32_t *assign_out)
{
    asp_context ctx = {0};
    ctx.threads = threads;
    asp_billboard_plane *planes = NULL;
    size_t np = 0;
    uint32_t *assign = malloc(m->triangle_count * sizeof *assign);
    asp_billboard_stats st;
    asp_error err = {0};
    int rc = asp_billboard_search_mesh(m, &(asp_billboard_desc){.error = e}, &ctx, &planes, &np, assign, &st, &err);
    CHECK_MSG(rc == 0, "search failed: %s", err.msg);
    if (rc) {
        free(assign);
        return 0;
    }
    const double eps = e * diagonal(m->positions, m->vertex_count);
    CHECK_NEAR(st.eps, eps, 1e-6 * eps);
    size_t bad = 0, unassigned = 0, total = 0;
    double worst = 0;
    for (size_t f = 0; f < m->triangle_count; f++) {
        if (assign[f] >= np) {
            unassigned++;
            continue;
        }
        const asp_billboard_plane *P = &planes[assign[f]];
        for (int j = 0; j < 3; j++) {
            const float *v = m->positions + 3 * (size_t)m->triangles[3 * f + (size_t)j];
            double d = fabs(P->normal[0] * v[0] + P->normal[1] * v[1] + P->normal[2] * v[2] - P->offset);
            worst = fmax(worst, d);
            bad += d > eps * (1 + 1e-4);
        }
    }
    for (size_t k = 0; k < np; k++) {
        double l = sqrt(planes[k].normal[0] * planes[k].normal[0] + planes[k].normal[1] * planes[k].normal[1] +
                        planes[k].normal[2] * planes[k].normal[2]);
        CHECK_NEAR(l, 1.0, 1e-6);
        total += planes[k].elements;
    }
    CHECK_MSG(unassigned == 0, "%zu faces on no plane", unassigned);
    CHECK_MSG(bad == 0, "%zu vertices beyond the bound %g (worst %g)", bad, eps, worst);
    CHECK(total == m->triangle_count);
    CHECK(st.planes == np && st.uncovered == 0);
    CHECK(st.max_distance <= eps * (1 + 1e-4));
    fprintf(stderr, "  %zu faces at %g: %zu planes (%zu fallbacks), worst distance %.3g of eps %.3g\n",
            m->triangle_count, e, np, st.fallbacks, worst, eps);
    if (assign_out)
        memcpy(assign_out, assign, m->triangle_count * sizeof *assign);
    free(assign);
    asp_free(&ctx, planes);
    return np;
}

static void test_box_six_planes(void)
{
    asp_mesh *m = box(1, 2, 3);
    CHECK(m != NULL);
    if (!m)
        return;
    /* each side lies in its own plane and no plane within 2% holds two sides */
    size_t np = check_mesh_cover(m, 0.02, 0, NULL);
    CHECK_MSG(np == 6, "a box in %zu planes, expected 6", np);
    asp_mesh_destroy(m);
}

static void test_crossed_quads_soup(void)
{
    asp_mesh *m = crossed_quads(40, 7);
    CHECK(m != NULL);
    if (!m)
        return;
    for (double e = 0.02; e < 0.1; e *= 2) {
        size_t np = check_mesh_cover(m, e, 0, NULL);
        /* every quad is planar: never more planes than quads; sharing must save some at 8% */
        CHECK(np >= 1 && np <= 80);
        if (e > 0.05)
            CHECK_MSG(np < 60, "%zu planes at %g for 80 quads", np, e);
    }
    asp_mesh_destroy(m);
}

static void test_sphere_and_threads(void)
{
    asp_mesh *m = sphere(24, 48);
    CHECK(m != NULL);
    if (!m)
        return;
    uint32_t *a1 = malloc(m->triangle_count * sizeof *a1), *a2 = malloc(m->triangle_count * sizeof *a2);
    size_t n1 = check_mesh_cover(m, 0.04, 1, a1), n2 = check_mesh_cover(m, 0.04, 2, a2);
    /* a sphere of diagonal 2 sqrt 3 at eps 0.14: caps of angle ~ 2 acos(1 - eps) ~ 60 degrees; some dozens */
    CHECK_MSG(n1 >= 8 && n1 <= 120, "sphere in %zu planes", n1);
    CHECK(n1 == n2 && memcmp(a1, a2, m->triangle_count * sizeof *a1) == 0);
    size_t fine = check_mesh_cover(m, 0.01, 0, NULL);
    CHECK_MSG(fine > n1, "a smaller bound needs more planes: %zu at 1%%, %zu at 4%%", fine, n1);
    free(a1);
    free(a2);
    asp_mesh_destroy(m);
}

static void test_point_discs(void)
{
    asp_cloud *c = NULL;
    const size_t n = 2000;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_RADII | ASP_ATTR_COLORS, NULL, &c, NULL), NULL);
    if (!c)
        return;
    uint32_t s = 3;
    for (size_t i = 0; i < n; i++) {
        double z = 2 * unit_rand(&s) - 1, ph = 6.2831853 * unit_rand(&s), r = sqrt(1 - z * z);
        float p[3] = {(float)(r * cos(ph)), (float)(r * sin(ph)), (float)z};
        memcpy(c->positions + 3 * i, p, sizeof p);
        memcpy(c->normals + 3 * i, p, sizeof p);
        c->radii[i] = 0.05f;
        uint8_t col[4] = {200, 100, 50, 255};
        memcpy(c->colors + 4 * i, col, 4);
    }
    asp_billboard_plane *planes = NULL;
    size_t np = 0;
    uint32_t *assign = malloc(n * sizeof *assign);
    asp_billboard_stats st;
    CHECK_OK(asp_billboard_search_cloud(c, &(asp_billboard_desc){.error = 0.04}, NULL, &planes, &np, assign, &st, NULL),
             NULL);
    size_t bad = 0;
    for (size_t i = 0; i < n && planes; i++) {
        CHECK(assign[i] < np);
        if (assign[i] >= np)
            break;
        const asp_billboard_plane *P = &planes[assign[i]];
        const float *p = c->positions + 3 * i;
        double cs = P->normal[0] * p[0] + P->normal[1] * p[1] + P->normal[2] * p[2]; /* normal = position */
        double d = fabs(cs - P->offset) + 0.05 * sqrt(fmax(0, 1 - cs * cs));  /* the disc's rim */
        bad += d > st.eps * (1 + 1e-4);
    }
    CHECK_MSG(bad == 0, "%zu discs beyond the bound", bad);
    CHECK(np >= 8 && np < 200);
    free(assign);
    asp_free(NULL, planes);
    /* the build: a .dps level that keeps its flag and binary alpha through save and load */
    asp_dps *dps = NULL;
    CHECK_OK(asp_billboard_cloud(c, &(asp_billboard_desc){.error = 0.04, .texels = 50000}, "discs", NULL, &dps, &st,
                                 NULL), NULL);
    if (dps) {
        CHECK(dps->level_count == 1 && dps->levels[0].billboards == 1 && dps->levels[0].prim_count == st.planes);
        /* the texel count asked for is met within the sides' rounding */
        CHECK_MSG(fabs((double)st.texels - 50000) < 0.05 * 50000, "%llu texels for 50000",
                  (unsigned long long)st.texels);
        asp_dps_destroy(dps);
    }
    asp_cloud_destroy(c);
}

static void test_dps_roundtrip_binary_alpha(void)
{
    asp_mesh *m = crossed_quads(10, 11);
    CHECK(m != NULL);
    if (!m)
        return;
    /* a material colour to find in the texture */
    m->materials[0].diffuse[0] = 1.0f, m->materials[0].diffuse[1] = 0.5f, m->materials[0].diffuse[2] = 0.0f;
    m->materials[0].has_color = 1;
    asp_dps *dps = NULL;
    asp_billboard_stats st;
    asp_error err = {0};
    CHECK_OK(asp_billboard_mesh(m, &(asp_billboard_desc){.error = 0.02, .texel_size = 0.01, .normal_map = 1}, "soup",
                                NULL, &dps, &st, &err), &err);
    if (!dps) {
        asp_mesh_destroy(m);
        return;
    }
    const asp_dps_level *lv = &dps->levels[0];
    size_t opaque = 0, other = 0, orange = 0;
    for (size_t k = 0; k < lv->prim_count; k++) {
        const asp_prim *p = &lv->prims[k];
        for (uint32_t j = 0; j < p->tex_h; j++)
            for (uint32_t i = 0; i < p->tex_w; i++) {
                const uint8_t *t = lv->atlas.pixels + 4 * ((size_t)(p->tex_y + j) * lv->atlas.width + p->tex_x + i);
                opaque += t[3] == 255;
                other += t[3] != 255 && t[3] != 0;
                orange += t[3] == 255 && t[0] == 255 && t[1] == 128 && t[2] == 0;
            }
        /* the rectangle is the texture: tex_w texels of the texel edge */
        CHECK_NEAR(p->tex_w * p->texel, 2 * p->half_u, 1e-3 * p->half_u + 1e-6);
    }
    CHECK(other == 0);
    CHECK(opaque > 0 && orange == opaque);
    CHECK(lv->normal_atlas.width == lv->atlas.width);
    CHECK(asp_dps_save(dps, "test_prim_billboard.dps", &err) == 0);
    asp_dps *back = NULL;
    CHECK_OK(asp_dps_load("test_prim_billboard.dps", NULL, &back, &err), &err);
    if (back) {
        CHECK(back->levels[0].billboards == 1 && back->levels[0].prim_count == lv->prim_count);
        CHECK(back->levels[0].texels == lv->texels);
        asp_dps_destroy(back);
    }
    remove("test_prim_billboard.dps");
    asp_dps_destroy(dps);
    asp_mesh_destroy(m);
}

static void test_plane_budget_and_bad_options(void)
{
    asp_mesh *m = crossed_quads(20, 5);
    CHECK(m != NULL);
    if (!m)
        return;
    asp_billboard_plane *planes = NULL;
    size_t np = 0;
    uint32_t *assign = malloc(m->triangle_count * sizeof *assign);
    asp_billboard_stats st;
    CHECK_OK(asp_billboard_search_mesh(m, &(asp_billboard_desc){.error = 0.01, .max_planes = 3}, NULL, &planes, &np,
                                       assign, &st, NULL), NULL);
    CHECK(np == 3 && st.uncovered > 0);
    size_t none = 0;
    for (size_t f = 0; f < m->triangle_count; f++)
        none += assign[f] == UINT32_MAX;
    CHECK(none == st.uncovered);
    asp_free(NULL, planes);
    asp_error err = {0};
    planes = NULL;
    CHECK(asp_billboard_search_mesh(m, &(asp_billboard_desc){.error = 0}, NULL, &planes, &np, assign, NULL, &err) ==
          ASP_EINVAL);
    CHECK(planes == NULL && strstr(err.msg, "error bound") != NULL);
    asp_dps *dps = NULL;
    CHECK(asp_billboard_mesh(m, &(asp_billboard_desc){.error = 0.05, .texels = 10, .texel_size = 0.1}, NULL, NULL, &dps,
                             NULL, &err) == ASP_EINVAL);
    CHECK(dps == NULL);
    free(assign);
    asp_mesh_destroy(m);
}

TEST_MAIN(TEST_CASE(test_box_six_planes), TEST_CASE(test_crossed_quads_soup), TEST_CASE(test_sphere_and_threads),
          TEST_CASE(test_point_discs), TEST_CASE(test_dps_roundtrip_binary_alpha),
          TEST_CASE(test_plane_budget_and_bad_options))
