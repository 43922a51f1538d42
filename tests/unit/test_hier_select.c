/*
 * View-dependent cuts (seed 001 5.1, seed 004 3.2): tau = 0 with nothing
 * culled selects every point, counts never grow with tau, every selection is
 * a cut (no point covered twice), frustum culling drops a cloud outside the
 * view, normal-cone back-face culling drops a plane seen from behind, depth
 * limits, and cuts to a target count.
 */
#include <stdint.h>

#include "amgsplat/hier.h"
#include "harness.h"

static uint64_t rng_state = 77;

static double rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* g x g grid on z = 0 in [-0.5, 0.5]^2, normals +z, radii 0.7 spacing */
static asp_cloud *plane_cloud(size_t g)
{
    asp_cloud *c = NULL;
    asp_cloud_create(g * g, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &c, NULL);
    for (size_t i = 0; i < g * g; i++) {
        c->positions[3 * i] = (float)((i % g) + 0.5) / g - 0.5f;
        c->positions[3 * i + 1] = (float)((i / g) + 0.5) / g - 0.5f;
        c->normals[3 * i + 2] = 1;
        c->radii[i] = 0.7f / g;
    }
    return c;
}

static asp_cloud *sphere_cloud(size_t n)
{
    asp_cloud *c = NULL;
    asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &c, NULL);
    for (size_t i = 0; i < n; i++) {
        double z = 2 * rnd() - 1, t = 6.283185307179586 * rnd(), s = sqrt(1 - z * z);
        double p[3] = {s * cos(t), s * sin(t), z};
        for (int d = 0; d < 3; d++)
            c->positions[3 * i + d] = c->normals[3 * i + d] = (float)p[d];
        c->radii[i] = 0.04f;
    }
    return c;
}

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= l;
}

/* gluLookAt + gluPerspective (fovy radians), or an orthographic box of half-height ortho */
static asp_hier_view make_view(const double eye[3], const double at[3], const double up[3], double fovy,
                               double ortho)
{
    asp_hier_view v;
    memset(&v, 0, sizeof v);
    double f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, s[3], u[3];
    normalize(f);
    cross(f, up, s);
    normalize(s);
    cross(s, f, u);
    for (int i = 0; i < 3; i++) {
        v.view[4 * i + 0] = (float)s[i];
        v.view[4 * i + 1] = (float)u[i];
        v.view[4 * i + 2] = (float)-f[i];
        v.eye[i] = (float)eye[i];
    }
    v.view[12] = (float)-(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    v.view[13] = (float)-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    v.view[14] = (float)(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
    v.view[15] = 1;
    double zn = 0.05, zf = 50;
    if (ortho > 0) {
        v.proj[0] = v.proj[5] = (float)(1 / ortho);
        v.proj[10] = (float)(-2 / (zf - zn));
        v.proj[14] = (float)(-(zf + zn) / (zf - zn));
        v.proj[15] = 1;
    } else {
        double c = 1 / tan(fovy / 2);
        v.proj[0] = v.proj[5] = (float)c;
        v.proj[10] = (float)((zf + zn) / (zn - zf));
        v.proj[11] = -1;
        v.proj[14] = (float)(2 * zf * zn / (zn - zf));
    }
    v.width = v.height = 256;
    return v;
}

static asp_hier *build(const asp_cloud *cl, size_t leaf)
{
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, &(asp_hier_desc){.leaf_size = leaf}, NULL, &h, err), err);
    return h;
}

static size_t count_of(const asp_hier *h, const asp_hier_view *v)
{
    size_t n = 0;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_select(h, v, NULL, 0, &n, err), err);
    return n;
}

/* the selection is a cut: the point sets of the selected splats are disjoint; returns points covered */
static size_t check_cut(const asp_hier *h, const asp_index *ids, size_t n)
{
    size_t nn = asp_hier_node_count(h), np = asp_hier_point_count(h), covered = 0, twice = 0;
    const asp_hier_node *nodes = asp_hier_nodes(h);
    unsigned char *mark = calloc(np, 1);
    for (size_t i = 0; i < n; i++) {
        size_t lo, cnt;
        if (ids[i] < nn) {
            lo = nodes[ids[i]].first_point;
            cnt = nodes[ids[i]].point_count;
        } else {
            lo = ids[i] - nn;
            cnt = 1;
        }
        for (size_t j = lo; j < lo + cnt && j < np; j++) {
            twice += mark[j];
            mark[j] = 1;
            covered++;
        }
    }
    CHECK_MSG(twice == 0, "%zu points covered twice", twice);
    free(mark);
    return covered;
}

static void test_tau_zero_all_points(void)
{
    asp_cloud *cl = plane_cloud(48);
    asp_hier *h = build(cl, 4);
    double eye[3] = {0.1, -0.05, 2}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    asp_hier_view views[2] = {make_view(eye, at, up, 1.0, 0), make_view(eye, at, up, 0, 0.8)};
    for (int k = 0; k < 2 && h; k++) {
        asp_hier_view v = views[k];
        v.cull_backfaces = 1;
        size_t np = asp_hier_point_count(h), nn = asp_hier_node_count(h), n = 0;
        asp_index *ids = malloc(asp_hier_select_bound(h) * sizeof *ids);
        asp_error errbuf = {0}, *err = &errbuf;
        CHECK_OK(asp_hier_select(h, &v, ids, asp_hier_select_bound(h), &n, err), err);
        CHECK_MSG(n == np, "view %d: tau 0 selected %zu of %zu", k, n, np);
        size_t points = 0;
        for (size_t i = 0; i < n && i < np; i++)
            points += ids[i] >= nn;
        CHECK(points == np);
        CHECK(check_cut(h, ids, n < np ? n : np) == np);
        /* a coarse tau selects fewer splats that still cover every point */
        v.tau = 40;
        CHECK_OK(asp_hier_select(h, &v, ids, asp_hier_select_bound(h), &n, err), err);
        CHECK(n <= np / 8 && n > 0);
        CHECK(check_cut(h, ids, n) == np);
        /* capacity smaller than the result: the count still reports all */
        size_t small = 0;
        CHECK_OK(asp_hier_select(h, &v, ids, 3, &small, err), err);
        CHECK(small == n);
        free(ids);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_tau_monotone(void)
{
    asp_cloud *cl = sphere_cloud(20000);
    asp_hier *h = build(cl, 8);
    /* whole sphere in view, and a close view that cuts the sphere at the frustum */
    double eyes[3][3] = {{0, 0, 4}, {0.3, 0.2, 1.6}, {2.5, 1.0, -1.2}};
    double at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    size_t bad = 0, sweeps = 0;
    for (int e = 0; e < 3 && h; e++)
        for (int cull = 0; cull < 2; cull++) {
            asp_hier_view v = make_view(eyes[e], at, up, e == 1 ? 0.6 : 0.9, 0);
            v.cull_backfaces = cull;
            size_t prev = SIZE_MAX;
            for (float tau = 0; tau <= 1e5f; tau = tau < 1 ? tau + 0.25f : tau * 1.3f) {
                v.tau = tau;
                size_t n = count_of(h, &v);
                if (n > prev)
                    bad++;
                prev = n;
            }
            sweeps++;
            /* the root is drawn at a large tau, unless the eye is within its ellipse (infinite size) */
            CHECK(e == 1 ? prev <= 64 : prev == 1);
        }
    CHECK_MSG(bad == 0, "%zu increases of the splat count in %zu tau sweeps", bad, sweeps);
    /* back-face culling removes about half the sphere at tau 0 */
    if (h) {
        asp_hier_view v = make_view(eyes[0], at, up, 0.9, 0);
        size_t all = count_of(h, &v);
        v.cull_backfaces = 1;
        size_t front = count_of(h, &v);
        CHECK(all == cl->count);
        CHECK_MSG(front > cl->count * 0.35 && front < cl->count * 0.6, "front %zu of %zu", front, cl->count);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_frustum_cull(void)
{
    asp_cloud *cl = sphere_cloud(3000);
    asp_hier *h = build(cl, 8);
    double up[3] = {0, 1, 0};
    /* looking away from the cloud, and looking at a point far beside it */
    double e1[3] = {0, 0, 3}, a1[3] = {0, 0, 6};
    double e2[3] = {20, 0, 3}, a2[3] = {20, 0, 0};
    asp_hier_view v1 = make_view(e1, a1, up, 1.0, 0), v2 = make_view(e2, a2, up, 0.5, 0);
    if (h) {
        CHECK(count_of(h, &v1) == 0);
        CHECK(count_of(h, &v2) == 0);
        v2.no_frustum_cull = 1;
        CHECK(count_of(h, &v2) == cl->count);
        /* partially visible: strictly between */
        double e3[3] = {0, 0, 1.3}, a3[3] = {0, 0, 0};
        asp_hier_view v3 = make_view(e3, a3, up, 0.5, 0);
        size_t part = count_of(h, &v3);
        CHECK(part > 0 && part < cl->count);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_backface_cull(void)
{
    asp_cloud *cl = plane_cloud(32);
    asp_hier *h = build(cl, 8);
    double below[3] = {0.05, 0.02, -2}, above[3] = {0.05, 0.02, 2}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    for (int ortho = 0; ortho < 2 && h; ortho++) {
        asp_hier_view v = make_view(below, at, up, 1.0, ortho ? 0.8 : 0);
        CHECK(count_of(h, &v) == cl->count);
        v.cull_backfaces = 1;
        CHECK_MSG(count_of(h, &v) == 0, "ortho %d: plane seen from behind kept %zu", ortho, count_of(h, &v));
        v.tau = 4;
        CHECK(count_of(h, &v) == 0);
        asp_hier_view w = make_view(above, at, up, 1.0, ortho ? 0.8 : 0);
        w.cull_backfaces = 1;
        CHECK(count_of(h, &w) == cl->count);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_depth_limit(void)
{
    asp_cloud *cl = plane_cloud(32);
    asp_hier *h = build(cl, 8);
    double eye[3] = {0, 0, 2}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    asp_hier_view v = make_view(eye, at, up, 1.0, 0);
    if (h) {
        asp_index ids[16];
        size_t n = 0;
        v.depth_limit = 1;
        CHECK_OK(asp_hier_select(h, &v, ids, 16, &n, (asp_error *)NULL), (asp_error *)NULL);
        CHECK(n == 1 && ids[0] == 0);
        v.depth_limit = 2;
        CHECK_OK(asp_hier_select(h, &v, ids, 16, &n, (asp_error *)NULL), (asp_error *)NULL);
        CHECK(n == asp_hier_nodes(h)[0].child_count);
        v.depth_limit = asp_hier_depth(h) + 2;
        CHECK(count_of(h, &v) == cl->count);
        /* depths only grow the count */
        size_t prev = 0, bad = 0;
        for (uint32_t d = 1; d <= asp_hier_depth(h) + 2; d++) {
            v.depth_limit = d;
            size_t c = count_of(h, &v);
            bad += c < prev;
            prev = c;
        }
        CHECK(bad == 0);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static int cmp_index(const void *a, const void *b)
{
    asp_index x = *(const asp_index *)a, y = *(const asp_index *)b;
    return (x > y) - (x < y);
}

static void test_select_count(void)
{
    asp_cloud *cl = sphere_cloud(5000);
    asp_hier *h = build(cl, 8);
    double eye[3] = {0, 0.5, 3.5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    asp_hier_view v = make_view(eye, at, up, 0.9, 0);
    v.cull_backfaces = 1;
    size_t cap = h ? asp_hier_select_bound(h) : 0;
    asp_index *ids = malloc((cap + 1) * sizeof *ids), *all = malloc((cap + 1) * sizeof *all);
    asp_error errbuf = {0}, *err = &errbuf;
    size_t targets[] = {1, 7, 50, 500, 1500, 2500};
    size_t visible = 0; // points of the tau = 0 cut: what a count cut can reach
    if (h) {
        size_t m = 0;
        CHECK_OK(asp_hier_select(h, &v, all, cap, &m, err), err);
        for (size_t i = 0; i < m; i++)
            visible += all[i] >= asp_hier_node_count(h);
    }
    CHECK(visible > 1500 && visible < 2500);
    for (size_t k = 0; k < 6 && h; k++) {
        size_t n = 0, want = targets[k] < visible ? targets[k] : visible;
        CHECK_OK(asp_hier_select_count(h, &v, targets[k], ids, cap, &n, err), err);
        CHECK_MSG(n <= want && n + 8 > want, "target %zu: got %zu", targets[k], n);
        check_cut(h, ids, n);
    }
    if (h) {
        /* a target beyond the visible points gives the tau = 0 selection without its fallback nodes
           (at tau = 0 a node is drawn only when all below it was culled) */
        size_t n = 0, m = 0, fallbacks = 0;
        CHECK_OK(asp_hier_select_count(h, &v, cap, ids, cap, &n, err), err);
        CHECK_OK(asp_hier_select(h, &v, all, cap, &m, err), err);
        for (size_t i = 0; i < m; i++)
            if (all[i] < asp_hier_node_count(h))
                fallbacks++;
            else
                all[i - fallbacks] = all[i];
        m -= fallbacks;
        for (size_t i = 0; i < n; i++)
            CHECK(ids[i] >= asp_hier_node_count(h));
        CHECK(n == m);
        if (n == m) {
            qsort(ids, n, sizeof *ids, cmp_index);
            qsort(all, m, sizeof *all, cmp_index);
            CHECK(memcmp(ids, all, n * sizeof *ids) == 0);
        }
        CHECK_OK(asp_hier_select_count(h, &v, 0, ids, cap, &n, err), err);
        CHECK(n == 0);
    }
    free(ids);
    free(all);
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_bad_view(void)
{
    asp_cloud *cl = plane_cloud(8);
    asp_hier *h = build(cl, 8);
    double eye[3] = {0, 0, 2}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    asp_hier_view v = make_view(eye, at, up, 1.0, 0);
    size_t n = 0;
    asp_error err = {0};
    if (h) {
        v.width = 0;
        CHECK(asp_hier_select(h, &v, NULL, 0, &n, &err) == ASP_EINVAL);
        CHECK(strstr(err.msg, "viewport") != NULL);
        v.width = 64;
        v.tau = NAN;
        CHECK(asp_hier_select(h, &v, NULL, 0, &n, &err) == ASP_EINVAL);
        v.tau = -1;
        CHECK(asp_hier_select_count(h, &v, 5, NULL, 0, &n, &err) == ASP_EINVAL);
        v.tau = 0;
        v.proj[5] = INFINITY;
        CHECK(asp_hier_select(h, &v, NULL, 0, &n, &err) == ASP_EINVAL);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

TEST_MAIN(TEST_CASE(test_tau_zero_all_points), TEST_CASE(test_tau_monotone), TEST_CASE(test_frustum_cull),
          TEST_CASE(test_backface_cull), TEST_CASE(test_depth_limit), TEST_CASE(test_select_count),
          TEST_CASE(test_bad_view))
