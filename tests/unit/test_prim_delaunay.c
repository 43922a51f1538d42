/*
 * 2D Delaunay of projected domain points (thesis 3.3.3): checked against a
 * brute-force exact empty-circumcircle test on the snapped coordinates, the Euler count 2n - 2 - h, and the
 * area of the convex hull, on random, grid (co-circular), duplicated and
 * colinear inputs.
 */
#include <stdint.h>

#include "amgsplat/prim.h"
#include "harness.h"

static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static double cross(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

static int cmp_xy(const void *a, const void *b)
{
    const double *p = a, *q = b;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return p[1] < q[1] ? -1 : p[1] > q[1];
}

/* Andrew's monotone chain: number of strict hull vertices and hull area. */
static size_t hull(const double *xy, size_t n, double *area)
{
    double *p = malloc(n * 2 * sizeof *p), *h = malloc((2 * n + 2) * 2 * sizeof *h);
    memcpy(p, xy, n * 2 * sizeof *p);
    qsort(p, n, 2 * sizeof *p, cmp_xy);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        while (k >= 2 && cross(&h[2 * (k - 2)], &h[2 * (k - 1)], &p[2 * i]) <= 0)
            k--;
        memcpy(&h[2 * k++], &p[2 * i], 2 * sizeof *p);
    }
    for (size_t i = n - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(&h[2 * (k - 2)], &h[2 * (k - 1)], &p[2 * i]) <= 0)
            k--;
        memcpy(&h[2 * k++], &p[2 * i], 2 * sizeof *p);
    }
    k--;
    double a = 0;
    for (size_t i = 0; i < k; i++)
        a += h[2 * i] * h[2 * ((i + 1) % k) + 1] - h[2 * ((i + 1) % k)] * h[2 * i + 1];
    *area = a / 2;
    free(p);
    free(h);
    return k;
}

/* Triangulates, then checks orientation, empty circumcircles (brute force) and edge manifoldness. */
static size_t check_dt(const double *xy, size_t n, double *area_out)
{
    uint32_t *tri = malloc(3 * asp_delaunay2d_bound(n) * sizeof *tri);
    void *scratch = malloc(asp_delaunay2d_scratch_size(n));
    size_t nt = asp_delaunay2d(xy, n, tri, scratch);
    CHECK(nt <= asp_delaunay2d_bound(n));
    double lo[2] = {xy[0], xy[1]}, hi[2] = {xy[0], xy[1]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], xy[2 * i + k]);
            hi[k] = fmax(hi[k], xy[2 * i + k]);
        }
    double scale = 1048575.0 / fmax(hi[0] - lo[0], hi[1] - lo[1]);
    int64_t *gx = malloc(n * sizeof *gx), *gy = malloc(n * sizeof *gy);
    for (size_t i = 0; i < n; i++) {
        gx[i] = (int64_t)((xy[2 * i] - lo[0]) * scale + 0.5);
        gy[i] = (int64_t)((xy[2 * i + 1] - lo[1]) * scale + 0.5);
    }
    double area = 0;
    size_t bad_circle = 0, bad_orient = 0;
    for (size_t t = 0; t < nt; t++) {
        const double *a = &xy[2 * tri[3 * t]], *b = &xy[2 * tri[3 * t + 1]], *c = &xy[2 * tri[3 * t + 2]];
        double o = cross(a, b, c);
        bad_orient += !(o > 0);
        area += o / 2;
        /* brute force on the snapped coordinates the contract is exact on (2^20 - 1 grid over the extent) */
        const uint32_t v[3] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
        for (size_t i = 0; i < n; i++) {
            int64_t dx = gx[i], dy = gy[i];
            __extension__ __int128 m[3][3];
            for (int k = 0; k < 3; k++) {
                int64_t x = gx[v[k]] - dx, y = gy[v[k]] - dy;
                m[k][0] = x, m[k][1] = y, m[k][2] = (__int128)x * x + (__int128)y * y;
            }
            __extension__ __int128 det = m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]) -
                                         m[1][2] * (m[0][0] * m[2][1] - m[0][1] * m[2][0]) +
                                         m[2][2] * (m[0][0] * m[1][1] - m[0][1] * m[1][0]);
            if (det > 0 && bad_circle++ < 3)
                fprintf(stderr, "point %zu inside the circumcircle of triangle %zu\n", i, t);
        }
    }
    CHECK_MSG(bad_orient == 0, "%zu triangles not counter-clockwise", bad_orient);
    CHECK_MSG(bad_circle == 0, "%zu point-in-circumcircle violations", bad_circle);
    /* every directed edge at most once: triangles do not overlap */
    size_t dup = 0;
    for (size_t t = 0; t < nt && nt < 3000; t++)
        for (size_t s = t + 1; s < nt; s++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    dup += tri[3 * t + i] == tri[3 * s + j] && tri[3 * t + (i + 1) % 3] == tri[3 * s + (j + 1) % 3];
    CHECK_MSG(dup == 0, "%zu directed edges used twice", dup);
    free(tri);
    free(scratch);
    free(gx);
    free(gy);
    *area_out = area;
    return nt;
}

static void test_random(void)
{
    size_t n = 1500;
    double *xy = malloc(2 * n * sizeof *xy);
    for (size_t i = 0; i < 2 * n; i++)
        xy[i] = 10 + 3 * urand();
    double area, harea;
    size_t nt = check_dt(xy, n, &area);
    size_t h = hull(xy, n, &harea);
    CHECK_MSG(nt == 2 * n - 2 - h, "random: %zu triangles, expected %zu", nt, 2 * n - 2 - h);
    CHECK_NEAR(area, harea, 1e-9 * harea);
    free(xy);
}

static void test_grid_cocircular(void)
{
    size_t k = 25, n = k * k;
    double *xy = malloc(2 * n * sizeof *xy);
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] = (double)(i % k) * 0.1 - 5;
        xy[2 * i + 1] = (double)(i / k) * 0.1 + 7;
    }
    double area;
    size_t nt = check_dt(xy, n, &area);
    CHECK(nt == 2 * (k - 1) * (k - 1));
    CHECK_NEAR(area, 0.01 * (double)((k - 1) * (k - 1)), 1e-9);
    free(xy);
}

static void test_duplicates_and_colinear(void)
{
    /* 300 random points, each repeated twice: same triangulation as without the repeats */
    size_t n = 300;
    double *xy = malloc(4 * n * sizeof *xy);
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] = xy[2 * (i + n)] = urand();
        xy[2 * i + 1] = xy[2 * (i + n) + 1] = urand();
    }
    double area, harea;
    size_t nt = check_dt(xy, 2 * n, &area);
    size_t h = hull(xy, n, &harea);
    CHECK(nt == 2 * n - 2 - h);
    uint32_t tri[3 * 16];
    char scratch[4096];
    CHECK(asp_delaunay2d_scratch_size(5) <= sizeof scratch);
    double line[10] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4};
    CHECK(asp_delaunay2d(line, 5, tri, scratch) == 0);
    double same[6] = {1, 1, 1, 1, 1, 1};
    CHECK(asp_delaunay2d(same, 3, tri, scratch) == 0);
    double two[4] = {0, 0, 1, 0};
    CHECK(asp_delaunay2d(two, 2, tri, scratch) == 0);
    /* colinear points plus one off the line: a fan of n - 2 triangles */
    double fan[12] = {0, 0, 1, 0, 2, 0, 3, 0, 4, 0, 2, 1};
    CHECK(asp_delaunay2d(fan, 6, tri, scratch) == 4);
    free(xy);
}

static void test_clustered(void)
{
    /* non-uniform: two clusters 200x smaller than their distance, and co-circular points */
    size_t n = 1200;
    double *xy = malloc(2 * n * sizeof *xy);
    for (size_t i = 0; i < n; i++) {
        if (i < 400) {
            xy[2 * i] = 0.5 * urand();
            xy[2 * i + 1] = 0.5 * urand();
        } else if (i < 800) {
            xy[2 * i] = 100 + 0.2 * urand();
            xy[2 * i + 1] = 50 + 0.2 * urand();
        } else {
            double a = 6.283185307179586 * (double)(i - 800) / 400.0;
            xy[2 * i] = 50 + 20 * cos(a);
            xy[2 * i + 1] = 25 + 20 * sin(a);
        }
    }
    double area;
    size_t nt = check_dt(xy, n, &area);
    CHECK(nt > n);
    free(xy);
}

TEST_MAIN(TEST_CASE(test_random), TEST_CASE(test_grid_cocircular), TEST_CASE(test_duplicates_and_colinear),
          TEST_CASE(test_clustered))
