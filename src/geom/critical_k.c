/*
 * Critical neighbourhood size (thesis 2.3, after Pauly, Keiser and Gross 2003):
 * the surface variation sigma_k = l0 / (l0 + l1 + l2) of a point's k nearest
 * points grows smoothly while the neighbourhood stays on one connected part of
 * the surface, and jumps when points of another part (the other side of a thin
 * plate, a neighbouring finger) enter it. The k before the largest jump is the
 * largest neighbourhood a classifier can use at that point.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "util/banned.h"

/* sigma of the point plus its first m neighbours, from sums relative to the point (no cancellation) */
static double variation(const double s1[3], const double s2[6], double n)
{
    double c[6] = {s2[0] / n - s1[0] * s1[0] / (n * n), s2[1] / n - s1[0] * s1[1] / (n * n),
                   s2[2] / n - s1[0] * s1[2] / (n * n), s2[3] / n - s1[1] * s1[1] / (n * n),
                   s2[4] / n - s1[1] * s1[2] / (n * n), s2[5] / n - s1[2] * s1[2] / (n * n)};
    double ev[3], vec[9];
    asp_eigen_sym3(c, ev, vec);
    double sum = ev[0] + ev[1] + ev[2];
    return sum > 0 ? fmax(ev[2], 0.0) / sum : 0.0;
}

int asp_critical_neighbourhood(const float *positions, size_t count, const asp_critical_desc *desc,
                               const asp_context *ctx, uint32_t *k_out, asp_error *err)
{
    asp_critical_desc d = desc ? *desc : (asp_critical_desc){0};
    if (d.k_min == 0)
        d.k_min = 8;
    if (d.k_max == 0)
        d.k_max = 96;
    if (d.step == 0)
        d.step = 4;
    if (d.jump == 0)
        d.jump = 0.02;
    if (!positions || !k_out)
        return asp_error_set(err, ASP_EINVAL, "critical neighbourhood: positions and k_out are required");
    if (d.k_min < 4 || d.k_max < d.k_min + d.step || d.k_max > 1024 || !(d.jump > 0 && d.jump < 1))
        return asp_error_set(err, ASP_EINVAL,
                             "critical neighbourhood: expected 4 <= k_min, k_min + step <= k_max <= 1024 and jump "
                             "in (0, 1), got k_min %zu, k_max %zu, step %zu, jump %g",
                             d.k_min, d.k_max, d.step, d.jump);
    if (count <= d.k_max)
        return asp_error_set(err, ASP_EDEGENERATE, "critical neighbourhood: %zu points, need more than k_max %zu",
                             count, d.k_max);
    asp_kdtree *tree = NULL;
    int rc = asp_kdtree_create(positions, count, 3 * sizeof(float), ctx, &tree, err);
    if (rc)
        return rc;
    const size_t kn = d.k_max - 1; /* the point itself is the first of its k nearest */
    asp_index *nn = asp_alloc(ctx, count * kn * sizeof *nn);
    if (!nn) {
        asp_kdtree_destroy(tree);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu x %zu neighbours", count, kn);
    }
    rc = asp_knn_all(tree, kn, nn, NULL, ctx, err);
    asp_kdtree_destroy(tree);
    if (!rc) {
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
        for (long long ii = 0; ii < (long long)count; ii++) {
            size_t i = (size_t)ii;
            const float *p = positions + 3 * i;
            const asp_index *row = nn + i * kn;
            /* sums in double relative to p: sigma is a ratio of small differences */
            double s1[3] = {0, 0, 0}, s2[6] = {0, 0, 0, 0, 0, 0};
            double prev = -1, best_jump = 0;
            size_t used = 0, best_k = d.k_max;
            for (size_t k = d.k_min; k <= d.k_max; k += d.step) {
                for (; used < k - 1; used++) {
                    const float *q = positions + 3 * (size_t)row[used];
                    double x = (double)q[0] - p[0], y = (double)q[1] - p[1], z = (double)q[2] - p[2];
                    s1[0] += x, s1[1] += y, s1[2] += z;
                    s2[0] += x * x, s2[1] += x * y, s2[2] += x * z, s2[3] += y * y, s2[4] += y * z, s2[5] += z * z;
                }
                double sigma = variation(s1, s2, (double)k);
                if (prev >= 0 && sigma - prev >= d.jump && sigma - prev > best_jump) {
                    best_jump = sigma - prev;
                    best_k = k - d.step;
                }
                prev = sigma;
            }
            k_out[i] = (uint32_t)best_k;
        }
    }
    asp_free(ctx, nn);
    return rc;
}
