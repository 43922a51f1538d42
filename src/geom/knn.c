/*
 * k nearest neighbours of every point of a kd-tree, in parallel: the k-NN
 * graph behind PCA classification and normal/radius estimation (journal 3.1,
 * thesis 3.3.1). Queries run in the tree's leaf order so consecutive queries
 * touch the same cells; each query writes only its own output row.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "geom/kdtree_internal.h"
#include "util/banned.h"

/* Queries between progress reports; the block boundaries do not affect results. */
enum { KNN_BLOCK = 1 << 16 };

static float key_distance(uint64_t key)
{
    uint32_t bits = (uint32_t)(key >> 32);
    float d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/*
 * Queries run in leaf order, so the previous query p is usually a few cells
 * away: its k neighbours (with p replacing q among them) lie within
 * |q - p| + r_p of q, a bound that lets the search prune from the first cell.
 * The bound is widened by 1e-5 relative plus FLT_MIN so float rounding of the
 * distances can never push a true neighbour past it; results stay exact.
 */
static float coherent_bound(const float *q, const float *p, float p_kth_d2)
{
    double dx = (double)q[0] - p[0], dy = (double)q[1] - p[1], dz = (double)q[2] - p[2];
    double r = sqrt(dx * dx + dy * dy + dz * dz) + sqrt((double)p_kth_d2);
    double b = r * r * (1.0 + 1e-5) + FLT_MIN;
    return b < FLT_MAX ? (float)b : INFINITY;
}

int asp_knn_all(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2, const asp_context *ctx,
                asp_error *err)
{
    if (!tree || !idx)
        return asp_error_set(err, ASP_EINVAL, "cannot compute k-nearest neighbours: tree or output is NULL");
    const size_t n = tree->count;
    if (k == 0 || k >= n)
        return asp_error_set(err, ASP_EINVAL,
                             "cannot compute %zu nearest neighbours of %zu points: k must be in [1, %zu]", k, n,
                             n - 1);
    const int threads = asp_context_threads(ctx);
    /* candidate keys per thread, allocated before the parallel region */
    if (k > SIZE_MAX / 32 / (size_t)threads)
        return asp_error_set(err, ASP_ENOMEM, "cannot compute %zu nearest neighbours: out of memory", k);
    uint64_t *scratch = asp_alloc(ctx, (size_t)threads * ASP__KD_SCRATCH(k) * sizeof(uint64_t));
    if (!scratch)
        return asp_error_set(err, ASP_ENOMEM, "cannot compute %zu nearest neighbours: out of memory", k);
    uint64_t *last = asp_alloc(ctx, (size_t)threads * sizeof(uint64_t));
    float *last_d2 = asp_alloc(ctx, (size_t)threads * sizeof(float));
    if (!last || !last_d2) {
        asp_free(ctx, scratch);
    asp_free(ctx, last);
    asp_free(ctx, last_d2);
        asp_free(ctx, last);
        asp_free(ctx, last_d2);
        return asp_error_set(err, ASP_ENOMEM, "cannot compute %zu nearest neighbours: out of memory", k);
    }
    for (int t = 0; t < threads; t++)
        last[t] = UINT64_MAX;
    int rc = 0;
    for (size_t b0 = 0; b0 < n && rc == 0; b0 += KNN_BLOCK) {
        const long long b1 = (long long)(b0 + KNN_BLOCK < n ? b0 + KNN_BLOCK : n);
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long s = (long long)b0; s < b1; s++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            const size_t row = (size_t)tree->perm[s] * k;
            const float *q = tree->xyz + 3 * (size_t)s;
            uint64_t *buf = scratch + (size_t)tid * ASP__KD_SCRATCH(k);
            float bound2 = INFINITY;
            if (s > (long long)b0 && last[tid] == (uint64_t)(s - 1))
                bound2 = coherent_bound(q, tree->xyz + 3 * (size_t)(s - 1), last_d2[tid]);
            size_t m = asp__kdtree_search(tree, q, k, (uint32_t)s, bound2, buf, dist2 ? dist2 + row : NULL,
                                          idx + row);
            last[tid] = (uint64_t)s;
            last_d2[tid] = key_distance(buf[m - 1]);
        }
        rc = asp_progress(ctx, "knn", (double)b1 / (double)n);
    }
    asp_free(ctx, scratch);
    asp_free(ctx, last);
    asp_free(ctx, last_d2);
    if (rc)
        return asp_error_set(err, rc, "k-nearest neighbours canceled");
    return 0;
}

/* Checks arrays, stride and finiteness; returns 0 or ASP_EINVAL naming the first bad point. */
int asp__check_positions(const float *positions, size_t count, size_t stride_bytes, const char *what,
                           asp_error *err)
{
    if (!positions)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate %s: positions are NULL", what);
    if (stride_bytes < 3 * sizeof(float) || stride_bytes % sizeof(float) != 0)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate %s: stride %zu is not a multiple of 4 >= 12", what,
                             stride_bytes);
    const size_t stride = stride_bytes / sizeof(float);
    for (size_t i = 0; i < count; i++)
        for (int a = 0; a < 3; a++)
            if (!isfinite(positions[i * stride + a]))
                return asp_error_set(err, ASP_EINVAL, "cannot estimate %s: point %zu: coordinate %c is not finite",
                                     what, i, "xyz"[a]);
    return 0;
}

/* ASP_EDEGENERATE when every point equals the first. */
int asp__check_spread(const float *positions, size_t count, size_t stride_bytes, const char *what,
                        asp_error *err)
{
    const size_t stride = stride_bytes / sizeof(float);
    for (size_t i = 1; i < count; i++)
        if (memcmp(positions + i * stride, positions, 3 * sizeof(float)) != 0)
            return 0;
    return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate %s: all %zu points are equal", what, count);
}

/* Builds the k-NN graph (and squared distances when dist2 is not NULL); k < count. */
int asp__knn_graph(const float *positions, size_t count, size_t stride_bytes, size_t k, asp_index **idx,
                     float **dist2, const asp_context *ctx, asp_error *err)
{
    asp_kdtree *tree = NULL;
    int rc = asp_kdtree_create(positions, count, stride_bytes, ctx, &tree, err);
    if (rc)
        return rc;
    asp_index *i2 = asp_alloc(ctx, count * k * sizeof(asp_index));
    float *d2 = dist2 ? asp_alloc(ctx, count * k * sizeof(float)) : NULL;
    if (!i2 || (dist2 && !d2))
        rc = asp_error_set(err, ASP_ENOMEM, "cannot store %zu neighbours of %zu points: out of memory", k, count);
    else
        rc = asp_knn_all(tree, k, i2, d2, ctx, err);
    asp_kdtree_destroy(tree);
    if (rc) {
        asp_free(ctx, i2);
        asp_free(ctx, d2);
        return rc;
    }
    *idx = i2;
    if (dist2)
        *dist2 = d2;
    return 0;
}
