/*
 * The affine method's triangulation of a built level (thesis 3.3.3, Fig. 3.8)
 * for the thesis viewer's debug drawing (appendix C): the triangles are made
 * during the build and not stored, so the level's domains are made again from
 * the decomposition and each domain's points projected to its primitive.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "prim/internal.h"
#include "util/banned.h"

/* Appends the 3 edges of the kept triangles of primitive P (points idx[0..n-1]) to lines. */
static size_t prim_edges(const asp_prim *P, const asp_cloud *c, const float *radii, int project, const asp_index *idx,
                         size_t n, void *scratch, const double origin[3], float *lines)
{
    float *x = scratch, *y = x + n, *r = y + n;
    void *ts = (void *)(((uintptr_t)(r + n) + 63) & ~(uintptr_t)63); // the triangulation's doubles: aligned
    for (size_t k = 0; k < n; k++) {
        const float *p = &c->positions[3 * idx[k]];
        double d[3], s = 0, t = 0;
        for (int a = 0; a < 3; a++) {
            d[a] = c->origin[a] + p[a] - P->centre[a];
            s += d[a] * P->axis_u[a], t += d[a] * P->axis_v[a];
        }
        x[k] = (float)((s + P->half_u) / P->texel), y[k] = (float)((t + P->half_v) / P->texel);
        double rr = radii[idx[k]];
        if (project && c->normals) { // thesis 3.1 as the build does (build.c point_radius)
            const float *nn = &c->normals[3 * idx[k]];
            rr *= fmax(fabs(nn[0] * P->normal[0] + nn[1] * P->normal[1] + nn[2] * P->normal[2]), 0.05);
        }
        r[k] = (float)(rr / P->texel);
    }
    asp__tex_input in = {.n = n, .x = x, .y = y, .r = r, .channels = 4, .w = P->tex_w, .h = P->tex_h};
    uint32_t *tri = NULL;
    size_t nt = n >= 3 ? asp__prim_affine_triangles(&in, ts, &tri) : 0;
    for (size_t t = 0; lines && t < nt; t++)
        for (int e = 0; e < 3; e++)
            for (int end = 0; end < 2; end++) {
                uint32_t v = tri[3 * t + (size_t)((e + end) % 3)];
                double s = (double)x[v] * P->texel - P->half_u, tt = (double)y[v] * P->texel - P->half_v;
                for (int a = 0; a < 3; a++)
                    *lines++ = (float)(P->centre[a] - origin[a] + s * P->axis_u[a] + tt * P->axis_v[a]);
            }
    return 3 * nt;
}

int asp_prim_level_triangles(const asp_amg *amg, const asp_dps *dps, size_t index, const double origin[3],
                             const asp_context *ctx, float **lines, size_t *segments, asp_error *err)
{
    ASP_ASSERT(amg && dps && lines && segments);
    static const double zero[3] = {0, 0, 0};
    origin = origin ? origin : zero;
    const asp_cloud *c = asp_amg_cloud(amg);
    if (index >= dps->level_count)
        return asp_error_set(err, ASP_EINVAL, "level index %zu out of range: the file holds %zu levels", index,
                             dps->level_count);
    const asp_dps_level *lv = &dps->levels[index];
    if (c->count != dps->source_points || lv->level >= asp_amg_level_count(amg))
        return asp_error_set(err, ASP_EINVAL, "the decomposition (%zu points, %zu levels) is not the one the file was "
                             "built from (%llu points, level %u)", c->count, asp_amg_level_count(amg),
                             (unsigned long long)dps->source_points, lv->level);
    asp_amg_csr *psi = NULL, *dom = NULL;
    float *own = NULL, *out = NULL;
    uint8_t *scratch = NULL;
    int rc = asp_amg_basis(amg, lv->level, ctx, &psi, err);
    if (!rc)
        rc = lv->strict ? asp_amg_strict_domain_rows(psi, ctx, &dom, err) : asp_amg_domains(psi, dps->desc.tau, ctx, &dom, err);
    const float *radii = c->radii;
    if (!rc && !radii) { // as the build estimates them (build.c prepare_src)
        own = asp_alloc(ctx, c->count * sizeof *own);
        rc = own ? asp_estimate_radii(c->positions, c->count, 12, NULL, own, ctx, err)
                 : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu radii", c->count);
        radii = own;
    }
    size_t max_n = 0, bound = 0;
    for (size_t k = 0; !rc && k < lv->prim_count; k++) {
        const asp_prim *P = &lv->prims[k];
        if (P->merged != 1 || P->basis >= dom->rows)
            continue; // a merged primitive's domain is a sum of rows: not redrawn
        size_t n = dom->row_ptr[P->basis + 1] - dom->row_ptr[P->basis];
        max_n = n > max_n ? n : max_n;
        bound += 3 * asp_delaunay2d_bound(n);
    }
    size_t sbytes = 3 * max_n * sizeof(float) + 64 + 2 * max_n * sizeof(double) + (6 * max_n + 2) * sizeof(uint32_t) +
                    asp_delaunay2d_scratch_size(max_n) + 64;
    if (!rc) {
        scratch = asp_alloc(ctx, sbytes);
        out = asp_alloc(ctx, (6 * bound + 1) * sizeof *out);
        if (!scratch || !out)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the triangulation of %zu primitives", lv->prim_count);
    }
    size_t total = 0;
    for (size_t k = 0; !rc && k < lv->prim_count; k++) {
        const asp_prim *P = &lv->prims[k];
        if (P->merged != 1 || P->basis >= dom->rows)
            continue;
        size_t a = dom->row_ptr[P->basis], n = dom->row_ptr[P->basis + 1] - a;
        total += prim_edges(P, c, radii, dps->desc.project_radii, &dom->col[a], n, scratch, origin, out + 6 * total);
    }
    asp_amg_csr_destroy(psi);
    asp_amg_csr_destroy(dom);
    asp_free(ctx, own);
    asp_free(ctx, scratch);
    if (rc) {
        asp_free(ctx, out);
        return rc;
    }
    *lines = out;
    *segments = total;
    return 0;
}
