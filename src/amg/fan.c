/*
 * Local triangle fans (journal 2.2, Fig. 3b): per point, its neighbours are
 * projected to the tangent plane and the triangles of their 2D Delaunay
 * triangulation around the point are found without triangulating everything:
 * the Delaunay neighbours of p are those whose bisectors bound p's Voronoi cell.
 */
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amg/internal.h"
#include "util/banned.h"

typedef struct vtx {
    double x, y;
    int64_t label; /* neighbour whose bisector carries the edge from this vertex to the next; -1: bounding box */
} vtx;

size_t asp_amg_fan_scratch_size(size_t m)
{
    return m * sizeof(size_t) + m * sizeof(double) + 2 * (m + 8) * sizeof(vtx) + 64;
}

/* Clips the convex polygon a (k vertices, counter-clockwise) by {v : v.q <= |q|^2 / 2}; returns the new count. */
static size_t clip(const vtx *a, size_t k, double qx, double qy, double q2, int64_t label, vtx *b)
{
    /* tolerance in units of length^2, relative to the bisector's distance: corners on the line count as inside */
    const double tol = 1e-9 * q2;
    size_t nb = 0;
    for (size_t i = 0; i < k; i++) {
        const vtx *u = &a[i], *w = &a[i + 1 < k ? i + 1 : 0];
        double fu = u->x * qx + u->y * qy - 0.5 * q2;
        double fw = w->x * qx + w->y * qy - 0.5 * q2;
        int in_u = fu <= tol, in_w = fw <= tol;
        if (in_u && in_w) {
            b[nb++] = *u;
        } else if (in_u) {
            if (fu >= -tol) {
                /* leaving exactly at u: u starts the new edge */
                b[nb++] = (vtx){u->x, u->y, label};
            } else {
                double t = fu / (fu - fw);
                b[nb++] = *u;
                b[nb++] = (vtx){u->x + t * (w->x - u->x), u->y + t * (w->y - u->y), label};
            }
        } else if (in_w && fw < -tol) {
            double t = fu / (fu - fw);
            b[nb++] = (vtx){u->x + t * (w->x - u->x), u->y + t * (w->y - u->y), u->label};
        }
    }
    return nb;
}

size_t asp_amg_fan(const double *xy, size_t m, asp_index *tri, void *scratch)
{
    if (m == 0)
        return 0;
    char *s = scratch;
    size_t *order = (size_t *)s;
    double *d2 = (double *)(s + m * sizeof(size_t));
    vtx *pa = (vtx *)(void *)(s + m * sizeof(size_t) + m * sizeof(double));
    vtx *pb = pa + (m + 8);

    double r2max = 0;
    for (size_t j = 0; j < m; j++) {
        d2[j] = xy[2 * j] * xy[2 * j] + xy[2 * j + 1] * xy[2 * j + 1];
        if (d2[j] > r2max)
            r2max = d2[j];
    }
    if (!(r2max > 0) || !isfinite(r2max))
        return 0;
    /* neighbours at p itself have no bisector */
    const double at_p = 1e-18 * r2max;
    size_t cnt = 0;
    for (size_t j = 0; j < m; j++) {
        if (!(d2[j] > at_p))
            continue;
        size_t q = cnt++;
        while (q > 0 && (d2[order[q - 1]] > d2[j] || (d2[order[q - 1]] == d2[j] && order[q - 1] > j))) {
            order[q] = order[q - 1];
            q--;
        }
        order[q] = j;
    }
    /* a box far outside the neighbourhood stands for the unbounded cell of a hull point */
    const double box = 1e4 * sqrt(r2max);
    pa[0] = (vtx){-box, -box, -1};
    pa[1] = (vtx){box, -box, -1};
    pa[2] = (vtx){box, box, -1};
    pa[3] = (vtx){-box, box, -1};
    size_t k = 4;
    double cell2 = 2 * box * box;
    for (size_t o = 0; o < cnt; o++) {
        size_t j = order[o];
        /* a bisector farther than the farthest cell corner cannot cut the cell, nor can any later one */
        if (d2[j] > 4.0 * cell2 * (1 + 1e-9))
            break;
        size_t nk = clip(pa, k, xy[2 * j], xy[2 * j + 1], d2[j], (int64_t)j, pb);
        vtx *t = pa;
        pa = pb;
        pb = t;
        k = nk;
        cell2 = 0;
        for (size_t v = 0; v < k; v++) {
            double r2 = pa[v].x * pa[v].x + pa[v].y * pa[v].y;
            if (r2 > cell2)
                cell2 = r2;
        }
    }
    /* start after a box edge so an open fan comes out in order */
    size_t start = 0;
    for (size_t v = 0; v < k; v++)
        if (pa[v].label < 0) {
            start = v + 1;
            break;
        }
    size_t ntri = 0;
    for (size_t c = 0; c < k; c++) {
        size_t v = (start + c) % k;
        int64_t before = pa[(v + k - 1) % k].label, after = pa[v].label;
        /* corner v joins the cell edges of two neighbours: a Voronoi vertex, i.e. a Delaunay triangle */
        if (before >= 0 && after >= 0 && before != after) {
            tri[2 * ntri] = (asp_index)before;
            tri[2 * ntri + 1] = (asp_index)after;
            ntri++;
        }
    }
    return ntri;
}

/* Orthonormal tangent basis (e0, e1) for unit normal nrm. */
static void tangent_basis(const float *nrm, double e0[3], double e1[3])
{
    double n[3] = {nrm[0], nrm[1], nrm[2]};
    double h[3] = {0, 0, 0};
    int a = fabs(n[0]) <= fabs(n[1]) ? (fabs(n[0]) <= fabs(n[2]) ? 0 : 2) : (fabs(n[1]) <= fabs(n[2]) ? 1 : 2);
    h[a] = 1;
    e0[0] = h[1] * n[2] - h[2] * n[1];
    e0[1] = h[2] * n[0] - h[0] * n[2];
    e0[2] = h[0] * n[1] - h[1] * n[0];
    double l = sqrt(e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]);
    for (int c = 0; c < 3; c++)
        e0[c] /= l;
    e1[0] = n[1] * e0[2] - n[2] * e0[1];
    e1[1] = n[2] * e0[0] - n[0] * e0[2];
    e1[2] = n[0] * e0[1] - n[1] * e0[0];
}

int asp__amg_build_fans(const float *pos, const float *normals, const asp__amg_nbhd *nb, size_t fan_k,
                        const asp_context *ctx, asp__amg_fans *out, asp_error *err)
{
    const size_t n = nb->n;
    const int threads = asp_context_threads(ctx);
    const size_t scratch_size = asp_amg_fan_scratch_size(fan_k) + 2 * fan_k * sizeof(double);
    asp__amg_fans f = {n, fan_k, NULL, NULL, NULL};
    f.tri = asp_alloc(ctx, 2 * n * fan_k * sizeof *f.tri);
    f.ntri = asp_alloc(ctx, n * sizeof *f.ntri);
    char *scratch = asp_alloc(ctx, (size_t)threads * scratch_size);
    if (!f.tri || !f.ntri || !scratch) {
        asp_free(ctx, scratch);
        asp__amg_fans_release(ctx, &f);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the triangle fans of %zu points", n);
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        char *sc = scratch + (size_t)t * scratch_size;
        double *xy = (double *)(void *)sc;
        void *fan_scratch = sc + 2 * fan_k * sizeof(double);
        double e0[3], e1[3];
        tangent_basis(normals + 3 * i, e0, e1);
        const float *x = pos + 3 * i;
        const asp_index *row = asp__amg_nbhd_row(nb, i);
        for (size_t j = 0; j < fan_k; j++) {
            const float *q = pos + 3 * (size_t)row[j];
            double d[3] = {(double)q[0] - x[0], (double)q[1] - x[1], (double)q[2] - x[2]};
            xy[2 * j] = d[0] * e0[0] + d[1] * e0[1] + d[2] * e0[2];
            xy[2 * j + 1] = d[0] * e1[0] + d[1] * e1[1] + d[2] * e1[2];
        }
        asp_index *tri = f.tri + 2 * i * fan_k; /* the stride layout until asp__amg_fans_compact */
        size_t nt = asp_amg_fan(xy, fan_k, tri, fan_scratch);
        for (size_t c = 0; c < 2 * nt; c++)
            tri[c] = row[tri[c]];
        f.ntri[i] = (uint16_t)nt;
    }
    asp_free(ctx, scratch);
    *out = f;
    (void)err;
    return 0;
}

void asp__amg_fans_compact(const asp_context *ctx, asp__amg_fans *f)
{
    if (f->first)
        return;
    const int threads = asp_context_threads(ctx);
    (void)threads; /* read by the OpenMP pragma only */
    size_t *first = asp_alloc(ctx, (f->n + 1) * sizeof *first);
    asp_index *tri = NULL;
    if (first) {
        first[0] = 0;
        for (size_t i = 0; i < f->n; i++)
            first[i + 1] = first[i] + f->ntri[i];
        tri = asp_alloc(ctx, (2 * first[f->n] + 1) * sizeof *tri);
    }
    if (!tri) {
        asp_free(ctx, first); /* the stride layout stays valid */
        return;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)f->n; ii++) {
        size_t i = (size_t)ii;
        memcpy(tri + 2 * first[i], f->tri + 2 * i * f->stride, 2 * (size_t)f->ntri[i] * sizeof *tri);
    }
    asp_free(ctx, f->tri);
    f->tri = tri;
    f->first = first;
}

void asp__amg_fans_release(const asp_context *ctx, asp__amg_fans *f)
{
    asp_free(ctx, f->tri);
    asp_free(ctx, f->ntri);
    asp_free(ctx, f->first);
    f->tri = NULL;
    f->ntri = NULL;
    f->first = NULL;
}
