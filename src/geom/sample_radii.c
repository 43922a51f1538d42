/*
 * Covering radii for splats: each point gets the largest distance to its own
 * Voronoi cell in the tangent plane, so every surface point lies in some disc
 * (the condition QSplat and Pajarola et al. 2003 section 3 state as "splats
 * must overlap to close all holes"), computed from the k nearest neighbours.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

enum { MAX_K = 32, MAX_POLY = 4 + MAX_K + 4 };

/* Unit tangents t1, t2 with (t1, t2, n) right-handed; branch-free construction of Duff et al. 2017. */
static void tangent_frame(const float n[3], double t1[3], double t2[3])
{
    double nx = n[0], ny = n[1], nz = n[2];
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    if (!(len > 0.0)) {
        nx = 0.0, ny = 0.0, nz = 1.0;
    } else {
        nx /= len, ny /= len, nz /= len;
    }
    double sign = copysign(1.0, nz);
    double a = -1.0 / (sign + nz), b = nx * ny * a;
    t1[0] = 1.0 + sign * nx * nx * a, t1[1] = sign * b, t1[2] = -sign * nx;
    t2[0] = b, t2[1] = sign + ny * ny * a, t2[2] = -ny;
}

/* Keeps the part of polygon (px, py, n vertices) with x * qx + y * qy <= c; returns the new vertex count. */
static int clip_halfplane(double *px, double *py, int n, double qx, double qy, double c, double *ox, double *oy)
{
    int m = 0;
    for (int a = 0; a < n; a++) {
        int b = (a + 1) % n;
        double da = px[a] * qx + py[a] * qy - c, db = px[b] * qx + py[b] * qy - c;
        if (da <= 0.0)
            ox[m] = px[a], oy[m] = py[a], m++;
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            double t = da / (da - db);
            ox[m] = px[a] + t * (px[b] - px[a]), oy[m] = py[a] + t * (py[b] - py[a]), m++;
        }
    }
    return m;
}

static float cell_radius(const asp_kdtree *tree, const float *positions, const float *normals, size_t i, size_t k)
{
    asp_index idx[MAX_K + 1];
    float d2[MAX_K + 1];
    size_t got = asp_kdtree_knn(tree, positions + 3 * i, k + 1, idx, d2);
    double t1[3], t2[3];
    tangent_frame(normals + 3 * i, t1, t2);
    /*
     * Start from a square whose corners lie at the k-th neighbour distance:
     * inside a surface the bisectors cut the cell far below that, while on an
     * open border (where no neighbour bounds the cell) it caps the disc.
     */
    double dk = sqrt((double)d2[got - 1]);
    double h = dk * 0.70710678118654752440;
    double bx[2][MAX_POLY], by[2][MAX_POLY];
    double *px = bx[0], *py = by[0], *qx = bx[1], *qy = by[1];
    px[0] = -h, py[0] = -h, px[1] = h, py[1] = -h, px[2] = h, py[2] = h, px[3] = -h, py[3] = h;
    int n = 4;
    const float *pi = positions + 3 * i, *ni = normals + 3 * i;
    for (size_t a = 0; a < got && n > 0; a++) {
        if (idx[a] == i)
            continue;
        const float *pj = positions + 3 * (size_t)idx[a], *nj = normals + 3 * (size_t)idx[a];
        /* the far side of a thin sheet (an ear, a fin) is near in space but bounds nothing on this side */
        if (ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2] < -0.3f)
            continue;
        double d[3] = {(double)pj[0] - pi[0], (double)pj[1] - pi[1], (double)pj[2] - pi[2]};
        double x = d[0] * t1[0] + d[1] * t1[1] + d[2] * t1[2];
        double y = d[0] * t2[0] + d[1] * t2[1] + d[2] * t2[2];
        /*
         * The 3D bisector plane of i and j cut with the tangent plane: across a
         * crease j sits below the plane and its projection is closer than it
         * really is, so bisecting the projections would shrink the cell.
         */
        double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (!(x * x + y * y > 1e-12 * dd) || !(dd > 0.0))
            continue; /* duplicate or straight above: no bisector in the tangent plane */
        n = clip_halfplane(px, py, n, x, y, 0.5 * dd, qx, qy);
        double *t = px; px = qx; qx = t;
        t = py; py = qy; qy = t;
    }
    double r2 = 0.0;
    for (int a = 0; a < n; a++)
        r2 = fmax(r2, px[a] * px[a] + py[a] * py[a]);
    return (float)sqrt(r2);
}

int asp__covering_radii(const float *positions, const float *normals, size_t count, size_t k, float scale,
                        float floor_radius, const asp_context *ctx, float *radii, asp_error *err)
{
    if (count < 2)
        return asp_error_set(err, ASP_EINVAL, "covering radii need at least 2 points, got %zu", count);
    if (k > MAX_K)
        k = MAX_K;
    if (k > count - 1)
        k = count - 1;
    asp_kdtree *tree = NULL;
    int rc = asp_kdtree_create(positions, count, 3 * sizeof(float), ctx, &tree, err);
    if (rc)
        return rc;
    rc = asp_progress(ctx, "radii", 0.0);
    if (rc) {
        asp_kdtree_destroy(tree);
        return asp_error_set(err, rc, "radius estimation canceled");
    }
    long long nn = (long long)count;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long i = 0; i < nn; i++) {
        float r = cell_radius(tree, positions, normals, (size_t)i, k) * scale;
        radii[i] = r > floor_radius ? r : floor_radius;
    }
    asp_kdtree_destroy(tree);
    return asp_progress(ctx, "radii", 1.0) ? asp_error_set(err, ASP_ECANCELED, "radius estimation canceled") : 0;
}
