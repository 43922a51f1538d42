/*
 * Triangle fans from a mesh's own connectivity (journal eq. 4: the stiffness
 * matrix of a triangulated surface): vertex i's fan is the set of mesh
 * triangles incident to it, so asp_amg_decompose_mesh needs neither the
 * tangent-plane projection nor the local Delaunay fans of journal 2.2.
 */
#include "amg/internal.h"
#include "util/banned.h"

int asp__amg_mesh_fans(size_t n, const uint32_t *triangles, size_t ntris, const asp_context *ctx,
                       asp__amg_fans *out, asp_error *err)
{
    uint32_t *deg = asp_calloc(ctx, n ? n : 1, sizeof *deg);
    if (!deg)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the fans of %zu vertices", n);
    size_t stride = 1;
    for (size_t t = 0; t < ntris; t++) {
        const uint32_t *v = triangles + 3 * t;
        if (v[0] >= n || v[1] >= n || v[2] >= n) {
            asp_free(ctx, deg);
            return asp_error_set(err, ASP_EINVAL, "triangle %zu: vertex %u, %u or %u is not below the %zu vertices", t,
                                 v[0], v[1], v[2], n);
        }
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue; /* degenerate: no area, no coupling */
        for (int c = 0; c < 3; c++)
            if (++deg[v[c]] > stride)
                stride = deg[v[c]];
    }
    if (stride > UINT16_MAX) {
        asp_free(ctx, deg);
        return asp_error_set(err, ASP_EUNSUPPORTED, "a vertex has %zu triangles: at most %u are supported", stride,
                             (unsigned)UINT16_MAX);
    }
    asp__amg_fans f = {n, stride, NULL, NULL, NULL};
    f.tri = asp_alloc(ctx, 2 * n * stride * sizeof *f.tri);
    f.ntri = asp_calloc(ctx, n ? n : 1, sizeof *f.ntri);
    asp_free(ctx, deg);
    if (!f.tri || !f.ntri) {
        asp__amg_fans_release(ctx, &f);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the fans of %zu vertices", n);
    }
    for (size_t t = 0; t < ntris; t++) {
        const uint32_t *v = triangles + 3 * t;
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue;
        for (int c = 0; c < 3; c++) {
            uint32_t p = v[c];
            asp_index *tri = f.tri + 2 * ((size_t)p * stride + f.ntri[p]);
            tri[0] = v[(c + 1) % 3]; /* counter-clockwise around p, as the point fans */
            tri[1] = v[(c + 2) % 3];
            f.ntri[p]++;
        }
    }
    asp__amg_fans_compact(ctx, &f);
    *out = f;
    return 0;
}
