/*
 * Area sampling: N points spread evenly over a mesh. Counts are stratified by
 * triangle area (systematic error diffusion along the triangle order), points
 * inside a triangle follow the R2 sequence through Heitz's square-to-triangle
 * map, and radii come from each point's Voronoi cell (sample_radii.c).
 */
#include <math.h>
#include <string.h>

#include "amgsplat/sample.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

/*
 * Counts per triangle: c_t = floor(S_t + 1/2) - floor(S_{t-1} + 1/2) with S_t
 * the running expected count N * (A_1 + .. + A_t) / A. Each c_t is the floor
 * or ceiling of its expectation, the total is exactly N, and the error never
 * piles up: neighbouring small triangles (adjacent in most files) share their
 * points instead of all rounding down. first[t] receives the prefix sums.
 */
static void triangle_counts(const asp_mesh *m, const double *area, double total, size_t n, size_t *first)
{
    double cum = 0.0;
    size_t prev = 0;
    first[0] = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        cum += area[t];
        size_t upto = t + 1 == m->triangle_count ? n : (size_t)floor((double)n * (cum / total) + 0.5);
        if (upto > n)
            upto = n;
        if (upto < prev)
            upto = prev;
        first[t + 1] = upto;
        prev = upto;
    }
}

int asp__sample_area(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                     asp_sample_stats *st, asp_error *err)
{
    size_t nt = m->triangle_count, n = d->points;
    if (n < 2)
        return asp_error_set(err, ASP_EINVAL, "area sampling needs at least 2 points, got %zu", n);
    double *area = asp_alloc(ctx, nt * sizeof(double));
    size_t *first = asp_alloc(ctx, (nt + 1) * sizeof(size_t));
    if (!area || !first) {
        asp_free(ctx, area);
        asp_free(ctx, first);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu triangles", nt);
    }
    double t0 = asp_time_now();
    double total = 0.0;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        const float *a = m->positions + 3 * (size_t)v[0], *b = m->positions + 3 * (size_t)v[1],
                    *c = m->positions + 3 * (size_t)v[2];
        double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
        double e2[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
        area[t] = 0.5 * sqrt(x * x + y * y + z * z);
        total += area[t];
    }
    triangle_counts(m, area, total, n, first);
    asp_free(ctx, area);
    asp_cloud *cl = NULL;
    int rc = asp__sample_cloud_create(m, d, n, ctx, &cl, err);
    if (rc) {
        asp_free(ctx, first);
        return rc;
    }
    if ((rc = asp_progress(ctx, "sample", 0.0)) != 0) {
        asp_free(ctx, first);
        asp_cloud_destroy(cl);
        return asp_error_set(err, rc, "sampling canceled");
    }
    long long ntl = (long long)nt;
    uint64_t seed = d->seed;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long tl = 0; tl < ntl; tl++) {
        size_t t = (size_t)tl;
        /* per-triangle offsets make the sequences of neighbouring triangles independent, and the seed matter */
        uint64_t h = asp__mix64(seed ^ asp__mix64((uint64_t)t));
        double ou = asp__unit(h), ov = asp__unit(asp__mix64(h));
        for (size_t i = first[t]; i < first[t + 1]; i++) {
            double u, v, w[3], pos[3], nrm[3], uv[2];
            float rgba[4] = {0};
            asp__r2(i - first[t], ou, ov, &u, &v);
            asp__square_to_triangle(u, v, &w[1], &w[2]);
            w[0] = 1.0 - w[1] - w[2];
            asp__surface_point(m, t, w, pos, nrm, uv, cl->colors ? rgba : NULL);
            asp__sample_store(cl, i, pos, nrm, uv, rgba, (uint32_t)t);
        }
    }
    asp_free(ctx, first);
    double t1 = asp_time_now();
    /* a floor for points whose neighbours all coincide with them (no Voronoi cell to measure) */
    float floor_r = (float)(0.1 * sqrt(total / (M_PI * (double)n)));
    rc = asp__covering_radii(cl->positions, cl->normals, n, 12, ASP__COVER_MARGIN * d->radius_scale, floor_r, ctx,
                             cl->radii, err);
    if (rc) {
        asp_cloud_destroy(cl);
        return rc;
    }
    st->sample_seconds = t1 - t0;
    st->radii_seconds = asp_time_now() - t1;
    *out = cl;
    return 0;
}
