/*
 * Splat radii from neighbour distances. Every point sample carries a radius
 * (journal 3.4, thesis 3.1) that rendering and texture resampling use as the
 * support of its disc; r_i = factor * (distance to the k-th neighbour) makes
 * the discs of a uniformly sampled surface overlap into a hole-free cover.
 */
#include <math.h>
#include <string.h>

#include "geom/kdtree_internal.h"
#include "util/banned.h"

int asp_radii_from_knn(const float *dist2, size_t count, size_t k_stride, const asp_radii_desc *desc,
                       float *restrict radii, const asp_context *ctx, asp_error *err)
{
    if (!dist2 || !radii)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate radii: %s is NULL", dist2 ? "radii" : "dist2");
    if (count == 0 || k_stride == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate radii: no points or no neighbours");
    size_t k = desc && desc->k ? desc->k : (k_stride < ASP_RADII_DEFAULT_K ? k_stride : ASP_RADII_DEFAULT_K);
    float factor = desc && desc->factor != 0.0f ? desc->factor : 1.0f;
    if (k > k_stride)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate radii: neighbour %zu requested, rows hold %zu", k,
                             k_stride);
    if (!(factor > 0.0f) || !isfinite(factor))
        return asp_error_set(err, ASP_EINVAL, "cannot estimate radii: factor %g must be positive and finite",
                             (double)factor);
    float *r = asp_alloc(ctx, count * sizeof(float));
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "cannot estimate %zu radii: out of memory", count);
    const long long cnt = (long long)count;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long i = 0; i < cnt; i++)
        r[i] = factor * sqrtf(dist2[(size_t)i * k_stride + k - 1]);
    /*
     * A point with k exact duplicates has distance 0 to its k-th neighbour; a
     * zero-size splat would leave a hole, so it borrows the smallest positive
     * radius of the set (a serial min is deterministic).
     */
    float min_pos = INFINITY;
    for (size_t i = 0; i < count; i++) {
        if (!isfinite(r[i]) || r[i] < 0.0f) {
            asp_free(ctx, r);
            return asp_error_set(err, ASP_EINVAL, "cannot estimate radii: point %zu: neighbour distance is not finite",
                                 i);
        }
        if (r[i] > 0.0f && r[i] < min_pos)
            min_pos = r[i];
    }
    if (min_pos == INFINITY) {
        asp_free(ctx, r);
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot estimate radii: every point has %zu neighbours at distance 0", k);
    }
    for (size_t i = 0; i < count; i++)
        r[i] = r[i] > 0.0f ? r[i] : min_pos;
    memcpy(radii, r, count * sizeof(float));
    asp_free(ctx, r);
    return 0;
}

int asp_estimate_radii(const float *positions, size_t count, size_t stride_bytes, const asp_radii_desc *desc,
                       float *restrict radii, const asp_context *ctx, asp_error *err)
{
    int rc = asp__check_positions(positions, count, stride_bytes, "radii", err);
    if (rc)
        return rc;
    if (!radii)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate radii: radii is NULL");
    if (count < 2)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate radii of %zu points: need at least 2", count);
    if ((rc = asp__check_spread(positions, count, stride_bytes, "radii", err)) != 0)
        return rc;
    size_t k = desc && desc->k ? desc->k : ASP_RADII_DEFAULT_K;
    k = k < count ? k : count - 1;
    asp_index *idx = NULL;
    float *d2 = NULL;
    if ((rc = asp__knn_graph(positions, count, stride_bytes, k, &idx, &d2, ctx, err)) != 0)
        return rc;
    asp_radii_desc d = {k, desc ? desc->factor : 0.0f};
    rc = asp_radii_from_knn(d2, count, k, &d, radii, ctx, err);
    asp_free(ctx, idx);
    asp_free(ctx, d2);
    return rc;
}
