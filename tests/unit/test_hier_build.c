/*
 * Hierarchy build invariants (seed 001 section 3): every point in exactly one
 * leaf, covariance sums equal direct sums (eq. 2-4), ellipses cover their
 * children's ellipses (Fig. 6), spheres and normal cones contain their
 * children's, linear-light colour means, determinism across thread counts,
 * and degenerate inputs.
 */
#include <stdint.h>

#include "amgsplat/hier.h"
#include "harness.h"
#include "hier/internal.h"

static uint64_t rng_state;

static double rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* n points on a noisy unit sphere with outward normals; attrs chooses colours/radii */
static asp_cloud *sphere_cloud(size_t n, unsigned attrs, uint64_t seed)
{
    asp_cloud *c = NULL;
    if (asp_cloud_create(n, attrs, NULL, &c, NULL) != 0)
        return NULL;
    rng_state = seed;
    for (size_t i = 0; i < n; i++) {
        double z = 2 * rnd() - 1, t = 2 * 3.14159265358979 * rnd(), s = sqrt(1 - z * z);
        double r = 1 + 0.01 * (rnd() - 0.5);
        double p[3] = {s * cos(t), s * sin(t), z};
        for (int d = 0; d < 3; d++) {
            c->positions[3 * i + d] = (float)(r * p[d]);
            if (c->normals)
                c->normals[3 * i + d] = (float)p[d];
        }
        if (c->colors)
            for (int d = 0; d < 4; d++)
                c->colors[4 * i + d] = (uint8_t)(rnd() * 256);
        if (c->radii)
            c->radii[i] = 0.02f + 0.03f * (float)rnd();
    }
    return c;
}

static double dot3d(const float *a, const float *b)
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

/* points on the boundary of member m, projected into s's plane, inside s's ellipse */
static int covers_boundary(const asp_hier_splat *s, const asp_hier_splat *m, double tol)
{
    int ok = 1;
    for (int k = 0; k < 32; k++) {
        double t = 2 * 3.14159265358979 * k / 32;
        float q[3];
        for (int d = 0; d < 3; d++)
            q[d] = (float)(m->center[d] + m->a * cos(t) * m->u[d] + m->b * sin(t) * m->v[d]);
        double r = asp__ellipse_point_norm(s, q);
        if (!(r <= 1 + tol))
            ok = 0;
    }
    return ok;
}

/* every structural and geometric invariant of a built hierarchy over cloud */
static void check_invariants(const asp_hier *h, const asp_cloud *cl, size_t leaf_size)
{
    size_t nn = asp_hier_node_count(h), np = asp_hier_point_count(h);
    const asp_hier_node *nodes = asp_hier_nodes(h);
    const asp_hier_splat *sp = asp_hier_splats(h);
    const double *cov = asp_hier_covariances(h);
    CHECK(np == cl->count);
    CHECK(nn >= 1 && nn <= 2 * np);
    unsigned char *seen = calloc(np, 1);
    size_t leaves = 0, bad_leaf = 0, bad_child = 0, bad_cov = 0, bad_cover = 0, bad_sphere = 0, bad_cone = 0,
           bad_axes = 0;
    uint32_t maxdepth = 0;
    int unoriented = (asp_hier_flags(h) & ASP_HIER_UNORIENTED) != 0;
    for (size_t i = 0; i < nn; i++) {
        const asp_hier_node *n = &nodes[i];
        const asp_hier_splat *s = &sp[i];
        maxdepth = n->depth > maxdepth ? n->depth : maxdepth;
        if (fabs(dot3d(s->u, s->u) - 1) > 1e-5 || fabs(dot3d(s->v, s->v) - 1) > 1e-5 ||
            fabs(dot3d(s->u, s->v)) > 1e-5 || fabs(dot3d(s->u, s->normal)) > 1e-5 ||
            fabs(dot3d(s->normal, s->normal) - 1) > 1e-5 || !(s->a >= s->b && s->b >= 0) || s->index != i)
            bad_axes++;
        /* covariance sums against the direct sum over the subtree's points */
        double direct[10] = {0};
        for (uint32_t j = 0; j < n->point_count; j++) {
            asp_index src = sp[nn + n->first_point + j].index;
            const float *p = cl->positions + 3 * (size_t)src;
            double x = p[0], y = p[1], z = p[2];
            double t[10] = {x * x, x * y, x * z, x, y * y, y * z, y, z * z, z, 1};
            for (int k = 0; k < 10; k++)
                direct[k] += t[k];
        }
        for (int k = 0; k < 10; k++)
            if (fabs(direct[k] - cov[10 * i + k]) > 1e-9 * (1 + fabs(direct[k])))
                bad_cov++;
        if (n->child_count == 0) {
            leaves++;
            if (n->point_count < 1 || n->point_count > leaf_size)
                bad_leaf++;
            for (uint32_t j = 0; j < n->point_count; j++) {
                const asp_hier_splat *p = &sp[nn + n->first_point + j];
                if (p->index >= np || seen[p->index]++)
                    bad_leaf++;
                if (!covers_boundary(s, p, 1e-4) || asp__ellipse_point_norm(s, p->center) > 1 + 1e-4)
                    bad_cover++;
                double dx = p->center[0] - n->sphere[0], dy = p->center[1] - n->sphere[1],
                       dz = p->center[2] - n->sphere[2];
                if (sqrt(dx * dx + dy * dy + dz * dz) + p->a > n->sphere[3] * (1 + 1e-6) + 1e-6)
                    bad_sphere++;
                double ang = acos(fmin(1, fmax(-1, dot3d(s->normal, p->normal))));
                if (!unoriented && ang > n->cone_angle + 1e-5)
                    bad_cone++;
            }
            continue;
        }
        if (n->child_count < 2 || n->child_count > 8 || n->first_child <= i || n->first_child + n->child_count > nn)
            bad_child++;
        uint32_t next = n->first_point;
        for (uint32_t c = 0; c < n->child_count && n->first_child + c < nn; c++) {
            const asp_hier_node *k = &nodes[n->first_child + c];
            const asp_hier_splat *ks = &sp[n->first_child + c];
            if (k->parent != i || k->depth != n->depth + 1 || k->first_point != next)
                bad_child++;
            next += k->point_count;
            if (!covers_boundary(s, ks, 1e-4))
                bad_cover++;
            double dx = k->sphere[0] - n->sphere[0], dy = k->sphere[1] - n->sphere[1], dz = k->sphere[2] - n->sphere[2];
            if (sqrt(dx * dx + dy * dy + dz * dz) + k->sphere[3] > n->sphere[3] * (1 + 1e-6) + 1e-6)
                bad_sphere++;
            double ang = acos(fmin(1, fmax(-1, dot3d(s->normal, ks->normal))));
            if (ang + k->cone_angle > n->cone_angle + 1e-5 && n->cone_angle < 3.14159f)
                bad_cone++;
        }
        if (next != n->first_point + n->point_count)
            bad_child++;
    }
    size_t missing = 0;
    for (size_t j = 0; j < np; j++)
        missing += seen[j] != 1;
    CHECK_MSG(missing == 0, "%zu points not in exactly one leaf", missing);
    CHECK_MSG(bad_leaf == 0, "%zu bad leaf entries", bad_leaf);
    CHECK_MSG(bad_child == 0, "%zu bad child links", bad_child);
    CHECK_MSG(bad_cov == 0, "%zu covariance entries differ from direct sums", bad_cov);
    CHECK_MSG(bad_cover == 0, "%zu members not covered by their parent's ellipse", bad_cover);
    CHECK_MSG(bad_sphere == 0, "%zu members outside their parent's sphere", bad_sphere);
    CHECK_MSG(bad_cone == 0, "%zu members outside their parent's normal cone", bad_cone);
    CHECK_MSG(bad_axes == 0, "%zu splats with bad axes", bad_axes);
    CHECK(maxdepth == asp_hier_depth(h));
    CHECK(nodes[0].parent == UINT32_MAX && nodes[0].point_count == np && leaves >= (np + leaf_size - 1) / leaf_size);
    free(seen);
}

static void test_sphere_radii(void)
{
    asp_cloud *cl = sphere_cloud(5000, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, 1);
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, &(asp_hier_desc){.leaf_size = 8}, NULL, &h, err), err);
    if (h) {
        check_invariants(h, cl, 8);
        CHECK(asp_hier_flags(h) == ASP_HIER_HAS_COLORS);
        /* point splats are circles of the input radius */
        const asp_hier_splat *p = asp_hier_splats(h) + asp_hier_node_count(h);
        CHECK_NEAR(p[0].a, cl->radii[p[0].index], 1e-7);
        CHECK_NEAR(p[0].b, cl->radii[p[0].index], 1e-7);
        /* the root's normal cone on a closed sphere spans everything */
        CHECK(asp_hier_nodes(h)[0].cone_angle > 3.0f);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_sphere_knn(void)
{
    asp_cloud *cl = sphere_cloud(3000, ASP_ATTR_NORMALS, 2);
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, &(asp_hier_desc){.leaf_size = 4, .k = 8}, NULL, &h, err), err);
    if (h) {
        check_invariants(h, cl, 4);
        CHECK(asp_hier_flags(h) & ASP_HIER_KNN_ELLIPSES);
        /* each point ellipse bounds its 8 nearest neighbours (brute force) */
        const asp_hier_splat *p = asp_hier_splats(h) + asp_hier_node_count(h);
        size_t bad = 0;
        for (size_t j = 0; j < cl->count; j += 97) {
            const float *q = cl->positions + 3 * (size_t)p[j].index;
            double best[9];
            for (int k = 0; k < 9; k++)
                best[k] = INFINITY;
            size_t bi[9] = {0};
            for (size_t o = 0; o < cl->count; o++) {
                const float *r = cl->positions + 3 * o;
                double d = (q[0] - r[0]) * (q[0] - r[0]) + (q[1] - r[1]) * (q[1] - r[1]) + (q[2] - r[2]) * (q[2] - r[2]);
                for (int k = 0; k < 9; k++)
                    if (d < best[k]) {
                        for (int m = 8; m > k; m--) {
                            best[m] = best[m - 1];
                            bi[m] = bi[m - 1];
                        }
                        best[k] = d;
                        bi[k] = o;
                        break;
                    }
            }
            for (int k = 0; k < 9; k++)
                if (asp__ellipse_point_norm(&p[j], cl->positions + 3 * bi[k]) > 1 + 1e-4)
                    bad++;
            if (!(p[j].a > 0 && p[j].a < 0.5))
                bad++;
        }
        CHECK_MSG(bad == 0, "%zu neighbours outside point ellipses", bad);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_unoriented(void)
{
    asp_cloud *cl = sphere_cloud(2000, 0, 3);
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, NULL, NULL, &h, err), err);
    if (h) {
        check_invariants(h, cl, 8);
        CHECK(asp_hier_flags(h) & ASP_HIER_UNORIENTED);
        CHECK(asp_hier_nodes(h)[1].cone_angle >= 3.14159f);
        /* PCA normals of a sphere are radial up to sign */
        const asp_hier_splat *p = asp_hier_splats(h) + asp_hier_node_count(h);
        size_t bad = 0;
        for (size_t j = 0; j < cl->count; j++) {
            const float *q = p[j].center;
            double len = sqrt(dot3d(q, q));
            if (fabs(dot3d(p[j].normal, q)) / len < 0.95)
                bad++;
        }
        CHECK_MSG(bad < cl->count / 50, "%zu PCA normals far from radial", bad);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_colors_linear(void)
{
    /* half black, half white: the linear mean 0.5 is sRGB 188, not 128 */
    asp_cloud *cl = sphere_cloud(400, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, 4);
    for (size_t i = 0; i < cl->count; i++) {
        memset(cl->colors + 4 * i, i % 2 ? 255 : 0, 3);
        cl->colors[4 * i + 3] = i % 2 ? 255 : 55;
    }
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, NULL, NULL, &h, err), err);
    if (h) {
        const asp_hier_splat *root = &asp_hier_splats(h)[0];
        CHECK(root->color[0] == 188 && root->color[1] == 188 && root->color[2] == 188);
        CHECK(root->color[3] == 155);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
}

static void test_deterministic(void)
{
    asp_cloud *cl = sphere_cloud(300000, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, 5);
    asp_hier *h1 = NULL, *h2 = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, NULL, &(asp_context){.threads = 1}, &h1, err), err);
    CHECK_OK(asp_hier_build(cl, NULL, &(asp_context){.threads = 3}, &h2, err), err);
    if (h1 && h2) {
        size_t nn = asp_hier_node_count(h1);
        CHECK(nn == asp_hier_node_count(h2));
        if (nn == asp_hier_node_count(h2)) {
            CHECK(memcmp(asp_hier_nodes(h1), asp_hier_nodes(h2), nn * sizeof(asp_hier_node)) == 0);
            CHECK(memcmp(asp_hier_splats(h1), asp_hier_splats(h2), (nn + cl->count) * sizeof(asp_hier_splat)) == 0);
            CHECK(memcmp(asp_hier_covariances(h1), asp_hier_covariances(h2), nn * 10 * sizeof(double)) == 0);
        }
    }
    asp_hier_destroy(h1);
    asp_hier_destroy(h2);
    asp_cloud_destroy(cl);
}

static void build_and_check(asp_cloud *cl, const char *what)
{
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    int rc = asp_hier_build(cl, &(asp_hier_desc){.leaf_size = 2}, NULL, &h, err);
    CHECK_MSG(rc == 0, "%s: %s", what, err->msg);
    if (h) {
        check_invariants(h, cl, 2);
        CHECK(asp_hier_depth(h) <= ASP_HIER_MAX_DEPTH);
    }
    asp_hier_destroy(h);
}

static void test_degenerate(void)
{
    asp_cloud *cl = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    /* one point, with and without attributes */
    CHECK_OK(asp_cloud_create(1, 0, NULL, &cl, err), err);
    build_and_check(cl, "one point");
    asp_cloud_destroy(cl);
    CHECK_OK(asp_cloud_create(1, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &cl, err), err);
    cl->normals[2] = 1;
    cl->radii[0] = 0.5f;
    build_and_check(cl, "one point with radius");
    asp_cloud_destroy(cl);
    /* all points equal: the octant split makes no progress */
    CHECK_OK(asp_cloud_create(1000, ASP_ATTR_NORMALS, NULL, &cl, err), err);
    for (size_t i = 0; i < cl->count; i++) {
        cl->positions[3 * i] = 1.5f;
        cl->normals[3 * i + 1] = 1;
    }
    build_and_check(cl, "all equal");
    asp_cloud_destroy(cl);
    CHECK_OK(asp_cloud_create(500, 0, NULL, &cl, err), err);
    build_and_check(cl, "all zero, no normals");
    asp_cloud_destroy(cl);
    /* colinear */
    CHECK_OK(asp_cloud_create(500, 0, NULL, &cl, err), err);
    for (size_t i = 0; i < cl->count; i++)
        for (int d = 0; d < 3; d++)
            cl->positions[3 * i + d] = (float)i * (d + 1) * 0.01f;
    build_and_check(cl, "colinear");
    asp_cloud_destroy(cl);
    /* a geometric series: the mean split peels one point per level, the count split bounds the depth */
    CHECK_OK(asp_cloud_create(2000, 0, NULL, &cl, err), err);
    for (size_t i = 0; i < cl->count; i++)
        cl->positions[3 * i] = (float)pow(1.02, (double)i);
    build_and_check(cl, "geometric");
    asp_cloud_destroy(cl);
}

static void test_bad_input(void)
{
    asp_cloud *cl = NULL;
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_cloud_create(0, 0, NULL, &cl, err), err);
    CHECK(asp_hier_build(cl, NULL, NULL, &h, err) == ASP_EDEGENERATE && h == NULL);
    asp_cloud_destroy(cl);
    cl = sphere_cloud(100, 0, 6);
    cl->positions[3 * 17 + 1] = NAN;
    CHECK(asp_hier_build(cl, NULL, NULL, &h, err) == ASP_EINVAL && h == NULL);
    CHECK(strstr(err->msg, "17") != NULL);
    cl->positions[3 * 17 + 1] = 0;
    CHECK(asp_hier_build(cl, &(asp_hier_desc){.leaf_size = 1u << 20}, NULL, &h, err) == ASP_EINVAL && h == NULL);
    asp_cloud_destroy(cl);
}

static int stop_at_half(void *user, const char *stage, double fraction)
{
    (void)stage;
    ++*(int *)user;
    return fraction >= 0.5;
}

static void test_cancel(void)
{
    asp_cloud *cl = sphere_cloud(1000, ASP_ATTR_NORMALS | ASP_ATTR_RADII, 7);
    asp_hier *h = NULL;
    asp_error err = {0};
    int calls = 0;
    asp_context ctx = {.progress = stop_at_half, .progress_user = &calls};
    CHECK(asp_hier_build(cl, NULL, &ctx, &h, &err) == ASP_ECANCELED && h == NULL);
    CHECK(calls == 2 && strstr(err.msg, "canceled") != NULL);
    asp_cloud_destroy(cl);
}

TEST_MAIN(TEST_CASE(test_sphere_radii), TEST_CASE(test_sphere_knn), TEST_CASE(test_unoriented),
          TEST_CASE(test_colors_linear), TEST_CASE(test_deterministic), TEST_CASE(test_degenerate),
          TEST_CASE(test_bad_input), TEST_CASE(test_cancel))
