/*
 * Crease clip planes (src/geom/crease.c): on the synthetic octahedron and
 * cube every plane found is the exact plane of a face next to the point's own,
 * points well inside a face get none, points on an edge get one and keep
 * themselves; smooth and two-sided surfaces get none; bad input fails cleanly.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static asp_error *ep(asp_error *e)
{
    return e;
}

/* Squared distance of point p to the edges of its face, and the face's unit normal, per model. */
typedef struct model {
    asp_synth_shape shape;
    size_t faces;
    double spacing; /* sqrt(face area / points per face) */
    double (*edge_distance)(const float *p, uint32_t label);
    void (*face_plane)(uint32_t label, double n[3], double *d); /* n . x + d = 0, n outwards */
    int (*adjacent)(uint32_t a, uint32_t b);                     /* share an edge or a vertex */
} model;

static void oct_signs(uint32_t f, double s[3])
{
    s[0] = (f & 1) ? -1.0 : 1.0;
    s[1] = (f & 2) ? -1.0 : 1.0;
    s[2] = (f & 4) ? -1.0 : 1.0;
}

/* Barycentric weight w_a = s_a p_a vanishes on the edge opposite vertex a; the face's heights are sqrt(6)/2. */
static double oct_edge_distance(const float *p, uint32_t f)
{
    double s[3], best = INFINITY;
    oct_signs(f, s);
    for (int a = 0; a < 3; a++)
        best = fmin(best, s[a] * p[a] * sqrt(6.0) / 2.0);
    return best;
}

static void oct_plane(uint32_t f, double n[3], double *d)
{
    double s[3];
    oct_signs(f, s);
    for (int a = 0; a < 3; a++)
        n[a] = s[a] / sqrt(3.0);
    *d = -1.0 / sqrt(3.0);
}

/* Faces differing in one sign share an edge, in two a vertex; three is the parallel opposite face. */
static int oct_adjacent(uint32_t a, uint32_t b)
{
    uint32_t x = (a ^ b) & 7;
    return x != 0 && x != 7;
}

static double cube_edge_distance(const float *p, uint32_t f)
{
    int axis = (int)(f / 2);
    return fmin(1.0 - fabs(p[(axis + 1) % 3]), 1.0 - fabs(p[(axis + 2) % 3]));
}

static void cube_plane(uint32_t f, double n[3], double *d)
{
    n[0] = n[1] = n[2] = 0.0;
    n[f / 2] = (f & 1) ? -1.0 : 1.0;
    *d = -1.0;
}

static int cube_adjacent(uint32_t a, uint32_t b)
{
    return a / 2 != b / 2;
}

/* The face whose plane p_ equals (normal within 1 degree, offset within 1e-4), or -1. */
static int matching_face(const model *m, const float *pl)
{
    for (uint32_t f = 0; f < m->faces; f++) {
        double n[3], d;
        m->face_plane(f, n, &d);
        double c = pl[0] * n[0] + pl[1] * n[1] + pl[2] * n[2];
        double len = sqrt((double)pl[0] * pl[0] + (double)pl[1] * pl[1] + (double)pl[2] * pl[2]);
        if (!(len > 0) || fabs(c / len) < cos(1.0 * M_PI / 180.0))
            continue;
        double sign = c < 0 ? -1.0 : 1.0; // the plane may keep either side of the face plane
        if (fabs(pl[3] / len - sign * d) <= 1e-4)
            return (int)f;
    }
    return -1;
}

static void check_model(const model *m)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(m->shape, NULL, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    size_t n = c->count, clipped = 0;
    float *planes = malloc(8 * n * sizeof(float));
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err), ep(&err));
    size_t bad_plane = 0, not_adjacent = 0, far_clipped = 0, near_total = 0, near_missed = 0, self_cut = 0;
    size_t with_plane = 0, two_planes = 0, overhang_total = 0, overhang_missed = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = c->positions + 3 * i, *q = planes + 8 * i;
        double e = m->edge_distance(p, c->labels[i]) / m->spacing;
        int count = 0;
        for (int k = 0; k < 2; k++) {
            const float *pl = q + 4 * k;
            if (pl[0] == 0 && pl[1] == 0 && pl[2] == 0 && pl[3] == 0)
                continue;
            count++;
            int f = matching_face(m, pl);
            if (f < 0)
                bad_plane++;
            else if (!m->adjacent((uint32_t)f, c->labels[i]))
                not_adjacent++;
            if (pl[0] * p[0] + pl[1] * p[1] + pl[2] * p[2] + pl[3] < -1e-6f)
                self_cut++;
        }
        with_plane += count > 0;
        two_planes += count == 2;
        if (e > 3.0 && count)
            far_clipped++;
        // the disc reaches past the edge: exactly the splats that need a clip
        if (e * m->spacing < c->radii[i]) {
            overhang_total++;
            overhang_missed += count == 0;
        }
        if (e < 0.5) {
            near_total++;
            near_missed += count == 0;
        }
    }
    fprintf(stderr, "%s: %zu of %zu points clipped (%zu by two planes), %zu within 0.5 spacing of an edge\n",
            asp_synth_shape_name(m->shape), clipped, n, two_planes, near_total);
    CHECK(clipped == with_plane);
    CHECK_MSG(bad_plane == 0, "%zu planes are not a face plane", bad_plane);
    CHECK_MSG(not_adjacent == 0, "%zu planes belong to a face not next to the point's", not_adjacent);
    CHECK_MSG(self_cut == 0, "%zu points are on the clipped side of their own plane", self_cut);
    CHECK_MSG(far_clipped == 0, "%zu points further than 3 spacings from every edge are clipped", far_clipped);
    CHECK(near_total > 100);
    CHECK_MSG(near_missed == 0, "%zu of %zu points within 0.5 spacing of an edge have no plane", near_missed,
              near_total);
    CHECK(overhang_total > near_total);
    CHECK_MSG(overhang_missed == 0, "%zu of %zu discs reaching past an edge have no plane", overhang_missed,
              overhang_total);
    CHECK(two_planes > 0); // corners, where three faces meet
    free(planes);
    asp_cloud_destroy(c);
}

static void test_octahedron(void)
{
    model m = {ASP_SYNTH_OCTAHEDRON, 8, sqrt(sqrt(3.0) / 2.0 / 2000.0), oct_edge_distance, oct_plane, oct_adjacent};
    check_model(&m);
}

static void test_cube(void)
{
    model m = {ASP_SYNTH_CUBE, 6, sqrt(4.0 / 4000.0), cube_edge_distance, cube_plane, cube_adjacent};
    check_model(&m);
}

/* A smooth surface has no crease at 60 degrees, and the result does not depend on the thread count. */
static void test_sphere_and_threads(void)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, NULL, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    size_t clipped = 99;
    float *planes = malloc(8 * c->count * sizeof(float));
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err), ep(&err));
    CHECK(clipped == 0);
    size_t nonzero = 0;
    for (size_t i = 0; i < 8 * c->count; i++)
        nonzero += planes[i] != 0.0f;
    CHECK(nonzero == 0);
    free(planes);
    asp_cloud_destroy(c);

    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000}, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    float *a = malloc(8 * c->count * sizeof(float)), *b = malloc(8 * c->count * sizeof(float));
    size_t ca = 0, cb = 0;
    CHECK_OK(asp_crease_clip_planes(c, NULL, &(asp_context){.threads = 1}, a, &ca, &err),
             ep(&err));
    CHECK_OK(asp_crease_clip_planes(c, NULL, &(asp_context){.threads = 3}, b, &cb, &err),
             ep(&err));
    CHECK(ca == cb && ca > 0 && memcmp(a, b, 8 * c->count * sizeof(float)) == 0);
    // a wider angle keeps the octahedron's 70.5-degree creases inside S: no planes
    CHECK_OK(asp_crease_clip_planes(c, &(asp_crease_desc){.angle_deg = 75}, NULL, a, &ca, &err), ep(&err));
    CHECK(ca == 0);
    free(a);
    free(b);
    asp_cloud_destroy(c);
}

/* A two-sided sheet (both sides sampled, opposite normals) is one surface for unoriented normals. */
static void test_two_sided_sheet(void)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_CHECKER_PLANE, &(asp_synth_desc){.grid = 40}, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    for (size_t i = 0; i < c->count; i += 2)
        c->normals[3 * i + 2] = -1.0f;
    float *planes = malloc(8 * c->count * sizeof(float));
    size_t clipped = 99;
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err), ep(&err));
    CHECK(clipped == 0);
    free(planes);
    asp_cloud_destroy(c);
}

static void test_errors(void)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    float planes[8 * 16];
    for (size_t i = 0; i < 8 * 16; i++)
        planes[i] = 42.0f;
    size_t clipped = 77;
    // no normals
    CHECK_OK(asp_cloud_create(16, 0, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    for (size_t i = 0; i < 16; i++)
        c->positions[3 * i] = (float)i;
    CHECK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "needs normals") != NULL);
    asp_cloud_destroy(c);

    // one point
    CHECK_OK(asp_cloud_create(1, ASP_ATTR_NORMALS, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    c->normals[2] = 1.0f;
    CHECK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err) == ASP_EDEGENERATE);
    asp_cloud_destroy(c);

    // NaN position, then NaN normal, named by point
    CHECK_OK(asp_cloud_create(16, ASP_ATTR_NORMALS, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    for (size_t i = 0; i < 16; i++) {
        c->positions[3 * i] = (float)(i % 4);
        c->positions[3 * i + 1] = (float)(i / 4);
        c->normals[3 * i + 2] = 1.0f;
    }
    c->positions[3 * 5 + 1] = NAN;
    CHECK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "point 5") != NULL, "message '%s'", err.msg);
    c->positions[3 * 5 + 1] = 1.0f;
    c->normals[3 * 9] = INFINITY;
    CHECK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "point 9") != NULL, "message '%s'", err.msg);
    c->normals[3 * 9] = 0.0f;
    // bad options
    CHECK(asp_crease_clip_planes(c, &(asp_crease_desc){.angle_deg = 90}, NULL, planes, &clipped, &err) == ASP_EINVAL);
    CHECK(asp_crease_clip_planes(c, &(asp_crease_desc){.angle_deg = -5}, NULL, planes, &clipped, &err) == ASP_EINVAL);
    CHECK(asp_crease_clip_planes(c, &(asp_crease_desc){.angle_deg = NAN}, NULL, planes, &clipped, &err) == ASP_EINVAL);
    CHECK(asp_crease_clip_planes(c, NULL, NULL, NULL, &clipped, &err) == ASP_EINVAL);
    CHECK(asp_crease_clip_planes(NULL, NULL, NULL, planes, &clipped, &err) == ASP_EINVAL);
    // outputs unchanged on every failure above
    int untouched = clipped == 77;
    for (size_t i = 0; i < 8 * 16; i++)
        untouched &= planes[i] == 42.0f;
    CHECK(untouched);

    // all points equal, normals in every direction: no crease can be placed, and no crash
    for (size_t i = 0; i < 16; i++) {
        c->positions[3 * i] = c->positions[3 * i + 1] = c->positions[3 * i + 2] = 0.5f;
        c->normals[3 * i] = (float)(i % 3 == 0);
        c->normals[3 * i + 1] = (float)(i % 3 == 1);
        c->normals[3 * i + 2] = (float)(i % 3 == 2);
    }
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err), ep(&err));
    CHECK(clipped == 0);
    // zero normals are ignored rather than counted as another surface
    for (size_t i = 0; i < 16; i++) {
        c->positions[3 * i] = (float)(i % 4);
        c->positions[3 * i + 1] = (float)(i / 4);
        c->positions[3 * i + 2] = 0.0f;
        c->normals[3 * i] = c->normals[3 * i + 1] = 0.0f;
        c->normals[3 * i + 2] = i % 2 ? 1.0f : 0.0f;
    }
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err), ep(&err));
    CHECK(clipped == 0);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_octahedron), TEST_CASE(test_cube), TEST_CASE(test_sphere_and_threads),
          TEST_CASE(test_two_sided_sheet), TEST_CASE(test_errors))
