/*
 * Local triangle fans (journal 2.2, Fig. 3b): the Voronoi-clipping fan finder
 * must give exactly the triangles around p of a full 2D Delaunay triangulation
 * (a plain Bowyer-Watson here) on random, co-circular and duplicated inputs.
 */
#include <stdint.h>

#include "amgsplat/amg.h"
#include "harness.h"

enum { MAXP = 80, MAXT = 4 * MAXP };
static const double PI = 3.14159265358979323846;

static uint64_t rng = 88172645463325252ull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

typedef struct { int a, b, c; } tri3;

static double orient(const double *p, const double *q, const double *r)
{
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
}

/* Strictly inside the circumcircle of the counter-clockwise triangle (a, b, c). */
static int in_circle(const double *a, const double *b, const double *c, const double *d)
{
    double ax = a[0] - d[0], ay = a[1] - d[1], bx = b[0] - d[0], by = b[1] - d[1], cx = c[0] - d[0], cy = c[1] - d[1];
    double det = (ax * ax + ay * ay) * (bx * cy - cx * by) - (bx * bx + by * by) * (ax * cy - cx * ay) +
                 (cx * cx + cy * cy) * (ax * by - bx * ay);
    return det > 1e-12;
}

/*
 * Reference: Bowyer-Watson on pts[0..n-1] (pts[0] = p); returns the triangles
 * with corner 0 as pairs (a, b) counter-clockwise, sorted. Points listed in
 * skip are not inserted (duplicates).
 */
static size_t delaunay_fan(double (*pts)[2], size_t n, const int *skip, int (*out)[2])
{
    static double P[MAXP + 3][2];
    static tri3 t[MAXT], keep[MAXT];
    static int edges[3 * MAXT][2];
    for (size_t i = 0; i < n; i++) {
        P[i][0] = pts[i][0];
        P[i][1] = pts[i][1];
    }
    /* super triangle far outside */
    P[n][0] = -1e5;
    P[n][1] = -1e5;
    P[n + 1][0] = 1e5;
    P[n + 1][1] = -1e5;
    P[n + 2][0] = 0;
    P[n + 2][1] = 1e5;
    size_t nt = 1;
    t[0] = (tri3){(int)n, (int)n + 1, (int)n + 2};
    for (size_t i = 0; i < n; i++) {
        if (skip[i])
            continue;
        size_t ne = 0, nk = 0;
        for (size_t k = 0; k < nt; k++) {
            if (in_circle(P[t[k].a], P[t[k].b], P[t[k].c], P[i])) {
                int e[3][2] = {{t[k].a, t[k].b}, {t[k].b, t[k].c}, {t[k].c, t[k].a}};
                for (int j = 0; j < 3; j++) {
                    edges[ne][0] = e[j][0];
                    edges[ne++][1] = e[j][1];
                }
            } else {
                keep[nk++] = t[k];
            }
        }
        for (size_t e = 0; e < ne; e++) {
            int shared = 0;
            for (size_t f = 0; f < ne; f++)
                if (f != e && edges[f][0] == edges[e][1] && edges[f][1] == edges[e][0])
                    shared = 1;
            if (!shared)
                keep[nk++] = (tri3){edges[e][0], edges[e][1], (int)i};
        }
        for (size_t k = 0; k < nk; k++)
            t[k] = keep[k];
        nt = nk;
    }
    size_t m = 0;
    for (size_t k = 0; k < nt; k++) {
        int v[3] = {t[k].a, t[k].b, t[k].c};
        if (v[0] >= (int)n || v[1] >= (int)n || v[2] >= (int)n)
            continue;
        for (int j = 0; j < 3; j++)
            if (v[j] == 0) {
                out[m][0] = v[(j + 1) % 3];
                out[m][1] = v[(j + 2) % 3];
                m++;
            }
    }
    return m;
}

static int cmp_pair(const void *x, const void *y)
{
    const int *a = x, *b = y;
    return a[0] != b[0] ? a[0] - b[0] : a[1] - b[1];
}

/* Runs both on p = origin plus m neighbours xy; returns 1 when the triangle sets agree. */
static int compare(const double *xy, size_t m, int verbose)
{
    static double pts[MAXP][2];
    static int skip[MAXP], ref[MAXT][2], got[MAXT][2];
    static asp_index tri[2 * MAXP];
    static char scratch[1 << 16];
    pts[0][0] = pts[0][1] = 0;
    skip[0] = 0;
    for (size_t j = 0; j < m; j++) {
        pts[j + 1][0] = xy[2 * j];
        pts[j + 1][1] = xy[2 * j + 1];
        skip[j + 1] = xy[2 * j] == 0 && xy[2 * j + 1] == 0;
        for (size_t q = 0; q < j && !skip[j + 1]; q++)
            if (xy[2 * q] == xy[2 * j] && xy[2 * q + 1] == xy[2 * j + 1])
                skip[j + 1] = 1; /* same position, earlier index: the first one stands */
    }
    size_t nr = delaunay_fan(pts, m + 1, skip, ref);
    CHECK(asp_amg_fan_scratch_size(m) <= sizeof scratch);
    size_t ng = asp_amg_fan(xy, m, tri, scratch);
    for (size_t t = 0; t < ng; t++) {
        got[t][0] = (int)tri[2 * t] + 1;
        got[t][1] = (int)tri[2 * t + 1] + 1;
        /* every fan triangle is counter-clockwise around p */
        CHECK(orient(pts[0], pts[got[t][0]], pts[got[t][1]]) > 0);
    }
    for (size_t t = 1; t < ng; t++)
        CHECK(got[t][0] == got[t - 1][1]); /* consecutive triangles share an edge */
    qsort(ref, nr, sizeof ref[0], cmp_pair);
    qsort(got, ng, sizeof got[0], cmp_pair);
    int same = nr == ng && memcmp(ref, got, nr * sizeof ref[0]) == 0;
    if (!same && verbose) {
        fprintf(stderr, "fan mismatch: reference %zu triangles, fan %zu\n", nr, ng);
        for (size_t t = 0; t < nr; t++)
            fprintf(stderr, "  ref (%d,%d)\n", ref[t][0], ref[t][1]);
        for (size_t t = 0; t < ng; t++)
            fprintf(stderr, "  got (%d,%d)\n", got[t][0], got[t][1]);
    }
    return same;
}

static void test_random(void)
{
    double xy[2 * 40];
    int fails = 0;
    for (int trial = 0; trial < 500; trial++) {
        size_t m = 5 + (size_t)(rnd() * 30);
        /* p mostly inside, sometimes near the edge or outside the cloud (open fans) */
        double cx = trial % 5 == 0 ? 0.9 : 0.0;
        for (size_t j = 0; j < m; j++) {
            xy[2 * j] = 2 * rnd() - 1 + cx;
            xy[2 * j + 1] = 2 * rnd() - 1;
        }
        fails += !compare(xy, m, fails == 0);
    }
    CHECK_MSG(fails == 0, "%d of 500 random fans differ from Delaunay", fails);
}

static void test_cocircular(void)
{
    double xy[2 * 64];
    for (size_t n = 3; n <= 24; n++) {
        double phase = rnd();
        for (size_t j = 0; j < n; j++) {
            double a = phase + 2 * PI * (double)j / (double)n;
            xy[2 * j] = 0.3 * cos(a);
            xy[2 * j + 1] = 0.3 * sin(a);
        }
        /* a regular polygon around p: p's cell is the polygon's dual, every vertex is a Delaunay neighbour */
        CHECK_MSG(compare(xy, n, 1), "regular %zu-gon", n);
        asp_index tri[2 * 40];
        static char scratch[1 << 16];
        CHECK(asp_amg_fan(xy, n, tri, scratch) == n);
        /* plus an outer ring of farther points that must not enter the fan */
        for (size_t j = 0; j < n; j++) {
            double a = phase + 2 * PI * ((double)j + 0.5) / (double)n;
            xy[2 * (n + j)] = 0.9 * cos(a);
            xy[2 * (n + j) + 1] = 0.9 * sin(a);
        }
        if (n >= 5)
            CHECK_MSG(compare(xy, 2 * n, 1), "regular %zu-gon with an outer ring", n);
    }
}

static void test_duplicates(void)
{
    double xy[2 * 40];
    int fails = 0;
    for (int trial = 0; trial < 300; trial++) {
        size_t m = 6 + (size_t)(rnd() * 20), extra = 1 + (size_t)(rnd() * 6);
        for (size_t j = 0; j < m; j++) {
            xy[2 * j] = 2 * rnd() - 1;
            xy[2 * j + 1] = 2 * rnd() - 1;
        }
        for (size_t e = 0; e < extra; e++) {
            size_t src = (size_t)(rnd() * (double)m);
            if (e == 0 && trial % 3 == 0) {
                xy[2 * (m + e)] = 0; /* a duplicate of p itself */
                xy[2 * (m + e) + 1] = 0;
            } else {
                xy[2 * (m + e)] = xy[2 * src];
                xy[2 * (m + e) + 1] = xy[2 * src + 1];
            }
        }
        fails += !compare(xy, m + extra, fails == 0);
    }
    CHECK_MSG(fails == 0, "%d of 300 fans with duplicates differ from Delaunay", fails);
}

static void test_degenerate(void)
{
    static char scratch[1 << 16];
    asp_index tri[64];
    double colinear[10] = {1, 0, 2, 0, -1, 0, -2, 0, 3, 0};
    /* all neighbours on a line through p: Voronoi cell is a strip, no triangle */
    CHECK(asp_amg_fan(colinear, 5, tri, scratch) == 0);
    double same[6] = {0, 0, 0, 0, 0, 0};
    CHECK(asp_amg_fan(same, 3, tri, scratch) == 0);
    CHECK(asp_amg_fan(same, 0, tri, scratch) == 0);
    double nan[4] = {NAN, 0, 1, 1};
    CHECK(asp_amg_fan(nan, 2, tri, scratch) == 0);
}

TEST_MAIN(TEST_CASE(test_random), TEST_CASE(test_cocircular), TEST_CASE(test_duplicates), TEST_CASE(test_degenerate))
