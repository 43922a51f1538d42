/*
 * A billboard cloud matched to a domain-primitive level (issue 30; thesis
 * Table 6.1 compares the two at one texel count): the error bound whose
 * plane count is nearest the level's primitive count, found by bisection on
 * log(eps) with the plane search alone (the plane count falls as the bound
 * grows), then the whole cloud built at that bound with the level's texels.
 */
#include <math.h>
#include <stdlib.h>

#include "amgsplat/billboard.h"
#include "eval/internal.h"
#include "util/banned.h"

enum { STEPS = 8 };

static int planes_at(const asp_mesh *mesh, const asp_cloud *cloud, double e, const asp_context *ctx, size_t *np,
                     asp_error *err)
{
    size_t n = mesh ? mesh->triangle_count : cloud->count;
    uint32_t *assign = asp_alloc(ctx, n * sizeof *assign);
    if (!assign)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboard elements", n);
    asp_billboard_plane *planes = NULL;
    asp_billboard_desc d = {.error = e};
    int rc = mesh ? asp_billboard_search_mesh(mesh, &d, ctx, &planes, np, assign, NULL, err)
                  : asp_billboard_search_cloud(cloud, &d, ctx, &planes, np, assign, NULL, err);
    asp_free(ctx, planes);
    asp_free(ctx, assign);
    return rc;
}

int asp__eval_billboards(const asp_mesh *mesh, const asp_cloud *cloud, size_t target, uint64_t texels,
                         const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, double *error,
                         asp_error *err)
{
    /* 0.2% to 50% of the diagonal: from thousands of planes down to one or two */
    double lo = log(0.002), hi = log(0.5), best_e = 0.06;
    size_t best_gap = SIZE_MAX;
    for (int i = 0; i < STEPS; i++) {
        double mid = 0.5 * (lo + hi), e = exp(mid);
        size_t np = 0;
        int rc = planes_at(mesh, cloud, e, ctx, &np, err);
        if (rc)
            return rc;
        size_t gap = np > target ? np - target : target - np;
        if (gap < best_gap || (gap == best_gap && e > best_e))
            best_gap = gap, best_e = e;
        if (np > target)
            lo = mid;
        else
            hi = mid;
        if (!gap)
            break;
    }
    asp_billboard_desc d = {.error = best_e, .texels = texels};
    int rc = mesh ? asp_billboard_mesh(mesh, &d, NULL, ctx, out, stats, err)
                  : asp_billboard_cloud(cloud, &d, NULL, ctx, out, stats, err);
    if (!rc && error)
        *error = best_e;
    return rc;
}
