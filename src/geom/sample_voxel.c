/*
 * Voxel sampling after Schwarz 2004 section 3.1: an n^3 grid over the cube
 * around the mean vertex (3.1.1), every cell a triangle touches (3.1.3-3.1.5),
 * one point per occupied cell at the surface point nearest the cell centre,
 * with normals and UV colours averaged over the cell's triangles (3.1.6-3.1.7).
 */
#include <math.h>
#include <string.h>

#include "amgsplat/sample.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

struct cell_hit {
    uint64_t key; /* x + n (y + n z) */
    uint32_t tri;
};

struct grid {
    double lo[3]; /* corner of the cube, relative to the mesh origin */
    double h;     /* cell size */
    uint32_t n;
};

/*
 * Exact triangle/box overlap by the separating axis theorem (Akenine-Moller
 * 2001): 3 box axes, the triangle normal and the 9 edge-axis cross products.
 * The seed's edge walk plus plane flood fill (3.1.4-3.1.5) misses cells the
 * triangle crosses only at a corner between two edge cells; SAT cannot.
 * v are corners relative to the box centre, in cell units (box half-size 0.5);
 * the box is closed, so touching counts.
 */
static int tri_box_overlap(const double v[3][3])
{
    const double hs = 0.5;
    for (int a = 0; a < 3; a++) {
        double mn = fmin(v[0][a], fmin(v[1][a], v[2][a])), mx = fmax(v[0][a], fmax(v[1][a], v[2][a]));
        if (mn > hs || mx < -hs)
            return 0;
    }
    double e[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            e[k][a] = v[(k + 1) % 3][a] - v[k][a];
    double nrm[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                     e[0][0] * e[1][1] - e[0][1] * e[1][0]};
    double d = nrm[0] * v[0][0] + nrm[1] * v[0][1] + nrm[2] * v[0][2];
    if (fabs(d) > hs * (fabs(nrm[0]) + fabs(nrm[1]) + fabs(nrm[2])))
        return 0;
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) {
            /* axis = unit_j x e_k */
            double ax[3] = {0.0, 0.0, 0.0};
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            ax[j1] = -e[k][j2];
            ax[j2] = e[k][j1];
            double p0 = ax[0] * v[0][0] + ax[1] * v[0][1] + ax[2] * v[0][2];
            double p1 = ax[0] * v[1][0] + ax[1] * v[1][1] + ax[2] * v[1][2];
            double p2 = ax[0] * v[2][0] + ax[1] * v[2][1] + ax[2] * v[2][2];
            double r = hs * (fabs(ax[0]) + fabs(ax[1]) + fabs(ax[2]));
            if (fmin(p0, fmin(p1, p2)) > r || fmax(p0, fmax(p1, p2)) < -r)
                return 0;
        }
    return 1;
}

static int64_t clampi(double x, uint32_t n)
{
    if (!(x > 0.0))
        return 0;
    if (x >= (double)(n - 1))
        return (int64_t)n - 1;
    return (int64_t)x;
}

/*
 * Visits every cell triangle t overlaps: columns along the two minor axes of
 * its normal, and in each column only the one to three cells the plane
 * crosses, so a big triangle costs its area in cells, not its bounding box.
 * Writes up to the number counted if hits != NULL; returns the count.
 */
static size_t triangle_cells(const asp_mesh *m, const struct grid *g, size_t t, struct cell_hit *hits)
{
    double p[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            p[k][a] = ((double)m->positions[3 * (size_t)m->triangles[3 * t + k] + a] - g->lo[a]) / g->h;
    double e1[3], e2[3];
    for (int a = 0; a < 3; a++)
        e1[a] = p[1][a] - p[0][a], e2[a] = p[2][a] - p[0][a];
    double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    int ka = 2;
    if (fabs(nrm[0]) >= fabs(nrm[1]) && fabs(nrm[0]) >= fabs(nrm[2]))
        ka = 0;
    else if (fabs(nrm[1]) >= fabs(nrm[2]))
        ka = 1;
    int ia = (ka + 1) % 3, ja = (ka + 2) % 3;
    double mn[3], mx[3];
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        mn[a] = fmin(p[0][a], fmin(p[1][a], p[2][a]));
        mx[a] = fmax(p[0][a], fmax(p[1][a], p[2][a]));
        /* half-open cells: a triangle ending exactly on a cell boundary does not claim the next cell */
        lo[a] = clampi(floor(mn[a]), g->n);
        hi[a] = clampi(ceil(mx[a]) - 1.0, g->n);
        if (hi[a] < lo[a])
            hi[a] = lo[a];
    }
    double plane_d = nrm[0] * p[0][0] + nrm[1] * p[0][1] + nrm[2] * p[0][2];
    size_t count = 0;
    uint64_t n = g->n;
    for (int64_t i = lo[ia]; i <= hi[ia]; i++)
        for (int64_t j = lo[ja]; j <= hi[ja]; j++) {
            int64_t k0 = lo[ka], k1 = hi[ka];
            if (nrm[ka] != 0.0) {
                /* plane height over the four column corners, clipped to the triangle's own extent */
                double zmin = INFINITY, zmax = -INFINITY;
                for (int c = 0; c < 4; c++) {
                    double x = (double)(i + (c & 1)), y = (double)(j + (c >> 1));
                    double z = (plane_d - nrm[ia] * x - nrm[ja] * y) / nrm[ka];
                    zmin = fmin(zmin, z), zmax = fmax(zmax, z);
                }
                zmin = fmax(zmin, mn[ka]), zmax = fmin(zmax, mx[ka]);
                if (zmin > zmax)
                    continue;
                k0 = clampi(floor(zmin), g->n);
                k1 = clampi(floor(zmax), g->n);
                if (k1 > hi[ka] && hi[ka] >= k0)
                    k1 = hi[ka];
            }
            for (int64_t k = k0; k <= k1; k++) {
                int64_t cell[3];
                cell[ia] = i, cell[ja] = j, cell[ka] = k;
                double v[3][3];
                for (int q = 0; q < 3; q++)
                    for (int a = 0; a < 3; a++)
                        v[q][a] = p[q][a] - ((double)cell[a] + 0.5);
                if (!tri_box_overlap(v))
                    continue;
                if (hits) {
                    hits[count].key = (uint64_t)cell[0] + n * ((uint64_t)cell[1] + n * (uint64_t)cell[2]);
                    hits[count].tri = (uint32_t)t;
                }
                count++;
            }
        }
    return count;
}

/*
 * Closest point of triangle t to q (Ericson, Real-Time Collision Detection
 * 5.1.5) as barycentric weights: the seed projects the cell centre onto the
 * triangle's plane; clamping into the triangle keeps the sample on the surface.
 */
static void closest_on_triangle(const asp_mesh *m, size_t t, const double q[3], double w[3])
{
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; k++) {
        a[k] = m->positions[3 * (size_t)m->triangles[3 * t] + k];
        b[k] = m->positions[3 * (size_t)m->triangles[3 * t + 1] + k];
        c[k] = m->positions[3 * (size_t)m->triangles[3 * t + 2] + k];
    }
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; k++)
        ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = q[k] - a[k], bp[k] = q[k] - b[k], cp[k] = q[k] - c[k];
#define DOT(x, y) ((x)[0] * (y)[0] + (x)[1] * (y)[1] + (x)[2] * (y)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap), d3 = DOT(ab, bp), d4 = DOT(ac, bp), d5 = DOT(ab, cp),
           d6 = DOT(ac, cp);
#undef DOT
    double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0.0 && d2 <= 0.0) {
        w[0] = 1.0, w[1] = 0.0, w[2] = 0.0;
    } else if (d3 >= 0.0 && d4 <= d3) {
        w[0] = 0.0, w[1] = 1.0, w[2] = 0.0;
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        double s = d1 / (d1 - d3);
        w[0] = 1.0 - s, w[1] = s, w[2] = 0.0;
    } else if (d6 >= 0.0 && d5 <= d6) {
        w[0] = 0.0, w[1] = 0.0, w[2] = 1.0;
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        double s = d2 / (d2 - d6);
        w[0] = 1.0 - s, w[1] = 0.0, w[2] = s;
    } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[0] = 0.0, w[1] = 1.0 - s, w[2] = s;
    } else {
        double den = va + vb + vc;
        if (!(den > 0.0)) { /* degenerate triangle: any corner is as close as the rest */
            w[0] = 1.0, w[1] = 0.0, w[2] = 0.0;
            return;
        }
        w[1] = vb / den, w[2] = vc / den, w[0] = 1.0 - w[1] - w[2];
    }
}

/* Stable LSD radix sort on key (11-bit digits); stability keeps triangle order inside a cell. */
static void radix_sort(struct cell_hit *a, struct cell_hit *tmp, size_t count, int bits)
{
    enum { DIGIT = 11, BUCKETS = 1 << DIGIT };
    size_t hist[BUCKETS];
    for (int shift = 0; shift < bits; shift += DIGIT) {
        memset(hist, 0, sizeof hist);
        for (size_t i = 0; i < count; i++)
            hist[(a[i].key >> shift) & (BUCKETS - 1)]++;
        size_t sum = 0;
        for (size_t b = 0; b < BUCKETS; b++) {
            size_t c = hist[b];
            hist[b] = sum;
            sum += c;
        }
        for (size_t i = 0; i < count; i++)
            tmp[hist[(a[i].key >> shift) & (BUCKETS - 1)]++] = a[i];
        memcpy(a, tmp, count * sizeof *a);
    }
}

static void make_grid(const asp_mesh *m, uint32_t n, struct grid *g)
{
    /* 3.1.1: C = mean vertex, D = largest per-axis distance from C, cube [C - D, C + D]^3 */
    double mean[3] = {0.0, 0.0, 0.0}, dmax = 0.0;
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int a = 0; a < 3; a++)
            mean[a] += m->positions[3 * v + a];
    for (int a = 0; a < 3; a++)
        mean[a] /= (double)m->vertex_count;
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int a = 0; a < 3; a++)
            dmax = fmax(dmax, fabs(m->positions[3 * v + a] - mean[a]));
    for (int a = 0; a < 3; a++)
        g->lo[a] = mean[a] - dmax;
    g->h = 2.0 * dmax / (double)n;
    g->n = n;
}

int asp__sample_voxel(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                      asp_sample_stats *st, asp_error *err)
{
    double t0 = asp_time_now();
    struct grid g;
    make_grid(m, d->grid, &g);
    if (!(g.h > 0.0))
        return asp_error_set(err, ASP_EDEGENERATE, "mesh has all vertices at one point; no grid to sample");
    size_t nt = m->triangle_count;
    size_t *first = asp_alloc(ctx, (nt + 1) * sizeof(size_t));
    if (!first)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu triangles", nt);
    long long ntl = (long long)nt;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long t = 0; t < ntl; t++)
        first[t + 1] = triangle_cells(m, &g, (size_t)t, NULL);
    first[0] = 0;
    for (size_t t = 0; t < nt; t++)
        first[t + 1] += first[t];
    size_t nhits = first[nt];
    struct cell_hit *hits = asp_calloc(ctx, nhits + 1, sizeof *hits);
    struct cell_hit *tmp = asp_calloc(ctx, nhits + 1, sizeof *tmp);
    if (!hits || !tmp) {
        asp_free(ctx, first);
        asp_free(ctx, hits);
        asp_free(ctx, tmp);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu cell-triangle pairs at grid %u", nhits, g.n);
    }
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long t = 0; t < ntl; t++)
        triangle_cells(m, &g, (size_t)t, hits + first[t]);
    asp_free(ctx, first);
    int bits = 0;
    while (bits < 64 && ((uint64_t)g.n * g.n * g.n - 1) >> bits)
        bits++;
    radix_sort(hits, tmp, nhits, bits);
    /* tmp now holds the run starts: cells in key order, each a run of hits */
    size_t *run = (size_t *)tmp, cells = 0;
    for (size_t i = 0; i < nhits; i++)
        if (i == 0 || hits[i].key != hits[i - 1].key)
            run[cells++] = i;
    run[cells] = nhits;
    asp_cloud *cl = NULL;
    int rc = asp_progress(ctx, "sample", 0.5);
    if (rc == 0)
        rc = asp__sample_cloud_create(m, d, cells, ctx, &cl, err);
    else
        asp_error_set(err, rc, "sampling canceled");
    if (rc) {
        asp_free(ctx, hits);
        asp_free(ctx, tmp);
        return rc;
    }
    uint64_t n = g.n;
    /* half the cell diagonal: the disc then spans the cell in any orientation of the surface */
    float radius = (float)(0.5 * sqrt(3.0) * g.h) * d->radius_scale;
    long long ncl = (long long)cells;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long c = 0; c < ncl; c++) {
        uint64_t key = hits[run[c]].key;
        double centre[3] = {g.lo[0] + ((double)(key % n) + 0.5) * g.h, g.lo[1] + ((double)(key / n % n) + 0.5) * g.h,
                            g.lo[2] + ((double)(key / n / n) + 0.5) * g.h};
        double pos[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, uv[2] = {0, 0}, best = INFINITY;
        float rgba[4] = {0, 0, 0, 0};
        size_t b = run[c], e = run[c + 1];
        for (size_t i = b; i < e; i++) {
            double w[3], tp[3], tn[3], tuv[2];
            float tc[4] = {0, 0, 0, 0};
            closest_on_triangle(m, hits[i].tri, centre, w);
            asp__surface_point(m, hits[i].tri, w, tp, tn, tuv, cl->colors ? tc : NULL);
            /*
             * Position: the surface point nearest the cell centre. The seed's
             * mean of the per-triangle projections leaves the surface at
             * creases and, with clamping, drifts a quarter cell wherever two
             * triangles share the cell. Normals, UVs and colours are averaged
             * over the cell's triangles as in 3.1.6-3.1.7; the
             * stored UV is the one of the position.
             */
            double d2 = 0.0;
            for (int a = 0; a < 3; a++)
                d2 += (tp[a] - centre[a]) * (tp[a] - centre[a]);
            if (d2 < best) {
                best = d2;
                memcpy(pos, tp, sizeof pos);
                uv[0] = tuv[0], uv[1] = tuv[1]; /* the uv belongs to the position */
            }
            for (int a = 0; a < 3; a++)
                nrm[a] += tn[a];
            for (int a = 0; a < 4; a++)
                rgba[a] += tc[a];
        }
        double inv = 1.0 / (double)(e - b);
        for (int a = 0; a < 4; a++)
            rgba[a] = (float)(rgba[a] * inv);
        if (!(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2] > 1e-24))
            asp__surface_point(m, hits[b].tri, (double[3]){1.0 / 3, 1.0 / 3, 1.0 / 3}, NULL, nrm, NULL, NULL);
        asp__sample_store(cl, (size_t)c, pos, nrm, uv, rgba, hits[b].tri);
        cl->radii[c] = radius;
    }
    asp_free(ctx, hits);
    asp_free(ctx, tmp);
    st->sample_seconds = asp_time_now() - t0;
    st->radii_seconds = 0.0;
    *out = cl;
    return 0;
}
