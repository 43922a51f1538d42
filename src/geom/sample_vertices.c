/*
 * Vertex sampling, as QSplat (Rusinkiewicz & Levoy 2000) turns a scanned mesh
 * into splats: one point per vertex used by a triangle, with the vertex
 * normal, the colour at the vertex and a radius that makes the discs of a
 * triangle's three corners cover the whole triangle.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/sample.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

/*
 * Covering radius of a triangle: the largest distance from a point of the
 * triangle to its nearest corner. QSplat takes the longest adjacent edge,
 * which always covers but blurs (an equilateral triangle needs only 0.577 of
 * its edge); half the longest edge leaves the centroid uncovered. The exact
 * value is the circumradius R = abc / (4 area) for a non-obtuse triangle
 * (the circumcentre is inside and equidistant from all corners). For a
 * triangle obtuse at C the circumcentre lies outside and R blows up for
 * slivers; the farthest points are where the bisectors of CA and CB cross AB,
 * at b / (2 cos A) and a / (2 cos B) from their corners, both below |AB|.
 */
static double covering_radius(const float *pa, const float *pb, const float *pc)
{
    double a2 = 0.0, b2 = 0.0, c2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double bc = (double)pc[k] - pb[k], ca = (double)pa[k] - pc[k], ab = (double)pb[k] - pa[k];
        a2 += bc * bc, b2 += ca * ca, c2 += ab * ab;
    }
    /* rename so that c is the longest side (opposite the largest angle) */
    if (a2 > c2) {
        double t = a2; a2 = c2; c2 = t;
    }
    if (b2 > c2) {
        double t = b2; b2 = c2; c2 = t;
    }
    double c = sqrt(c2);
    if (c2 < a2 + b2) {
        /* Heron in the stable form 16 area^2 = 4 a2 b2 - (a2 + b2 - c2)^2 */
        double s = 4.0 * a2 * b2 - (a2 + b2 - c2) * (a2 + b2 - c2);
        if (s > 0.0) {
            double r = sqrt(a2 * b2 * c2) / sqrt(s);
            return r < c ? r : c;
        }
    }
    double da = b2 + c2 - a2, db = a2 + c2 - b2;
    double r1 = da > 0.0 ? b2 * c / da : c, r2 = db > 0.0 ? a2 * c / db : c;
    double r = r1 > r2 ? r1 : r2;
    return r < c ? r : c;
}

int asp__sample_vertices(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                         asp_sample_stats *st, asp_error *err)
{
    size_t nv = m->vertex_count, nt = m->triangle_count;
    double t0 = asp_time_now();
    /* owner[v] = first triangle using v (its material colours the point) + 1, 0 = unused */
    uint32_t *owner = asp_calloc(ctx, nv + 1, sizeof(uint32_t));
    float *radius = asp_calloc(ctx, nv + 1, sizeof(float));
    float *tri_r = asp_alloc(ctx, (nt + 1) * sizeof(float));
    if (!owner || !radius || !tri_r) {
        asp_free(ctx, owner);
        asp_free(ctx, radius);
        asp_free(ctx, tri_r);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu vertices", nv);
    }
    long long ntl = (long long)nt;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long t = 0; t < ntl; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        tri_r[t] = (float)covering_radius(m->positions + 3 * (size_t)v[0], m->positions + 3 * (size_t)v[1],
                                          m->positions + 3 * (size_t)v[2]);
    }
    size_t used = 0;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->triangles[3 * t + k];
            if (!owner[v]) {
                owner[v] = (uint32_t)t + 1;
                used++;
            }
            /* nextafter: the float rounding of the radius must not shave the cover at the circumcentre */
            float r = nextafterf(tri_r[t], INFINITY);
            if (r > radius[v])
                radius[v] = r;
        }
    asp_free(ctx, tri_r);
    asp_cloud *cl = NULL;
    int rc = asp__sample_cloud_create(m, d, used, ctx, &cl, err);
    if (rc) {
        asp_free(ctx, owner);
        asp_free(ctx, radius);
        return rc;
    }
    size_t i = 0;
    for (size_t v = 0; v < nv; v++) {
        if (!owner[v])
            continue;
        size_t t = owner[v] - 1;
        double w[3] = {0.0, 0.0, 0.0}, pos[3], nrm[3], uv[2];
        float rgba[4] = {0};
        for (int k = 0; k < 3; k++)
            if (m->triangles[3 * t + k] == v)
                w[k] = 1.0;
        asp__surface_point(m, t, w, pos, NULL, uv, cl->colors ? rgba : NULL);
        for (int k = 0; k < 3; k++)
            nrm[k] = m->normals[3 * v + k];
        asp__sample_store(cl, i, pos, nrm, uv, rgba, (uint32_t)t);
        cl->radii[i] = radius[v] * d->radius_scale;
        i++;
    }
    asp_free(ctx, owner);
    asp_free(ctx, radius);
    st->sample_seconds = asp_time_now() - t0;
    st->radii_seconds = 0.0;
    *out = cl;
    return 0;
}
