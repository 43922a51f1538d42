/*
 * Neighbourhoods N(x) of journal 2.1: the k_min nearest points, extended by
 * every further point inside the ball B_epsilon(x), capped at k_max so memory
 * and time stay bounded. Also resolves the option defaults (asp_amg_desc).
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "amgsplat/geom.h"
#include "util/banned.h"

int asp__amg_resolve_desc(const asp_amg_desc *in, size_t count, asp_amg_desc *out, asp_error *err)
{
    asp_amg_desc d;
    if (in)
        d = *in;
    else
        memset(&d, 0, sizeof d);
    /*
     * Defaults by experiment (docs/cli/decompose.md): 24 neighbours already
     * give a stable tangent plane on the test models and keep the 1M-point
     * budget; the journal uses 50..100 (2.2), reachable with --k.
     */
    if (d.k_min == 0)
        d.k_min = 24;
    if (d.k_max == 0)
        d.k_max = 2 * d.k_min;
    if (d.fan_k == 0)
        d.fan_k = 16;
    if (d.alpha == 0)
        d.alpha = 0.01; /* journal eq. 3 */
    if (d.beta == 0)
        d.beta = 100;
    /*
     * 0.9 by experiment (docs/cli/decompose.md): with hypre's 0.25 domains
     * spill over creases at fine levels and faces merge through crease
     * slivers; 0.9 coarsens by about 2-2.5 per level. 0.5 gives slightly purer
     * faces (+0.3..1 point) for about 50% more AMG time.
     */
    if (d.strong_threshold == 0)
        d.strong_threshold = 0.9;
    if (d.max_levels == 0)
        d.max_levels = 25;
    if (d.max_coarse == 0)
        d.max_coarse = 4;
    if (d.drop_tol == 0)
        d.drop_tol = 1e-4;
    if (d.crease_cut == 0)
        d.crease_cut = 0.25; /* by experiment, docs/cli/decompose.md */
    else if (d.crease_cut < 0)
        d.crease_cut = -1; /* off */
    if (d.k_min < 3 || d.k_max < d.k_min || d.k_max > 1024)
        return asp_error_set(err, ASP_EINVAL, "invalid neighbourhood sizes k_min %zu, k_max %zu: expected 3 <= k_min <= k_max <= 1024",
                             d.k_min, d.k_max);
    if (d.fan_k < 3)
        return asp_error_set(err, ASP_EINVAL, "invalid fan neighbourhood %zu: expected at least 3", d.fan_k);
    if (!(d.epsilon >= 0) || !isfinite(d.epsilon))
        return asp_error_set(err, ASP_EINVAL, "invalid epsilon %g: expected a finite value >= 0", d.epsilon);
    if (!(d.alpha > 0) || !(d.beta > 0) || !isfinite(d.alpha) || !isfinite(d.beta))
        return asp_error_set(err, ASP_EINVAL, "invalid classifier constants alpha %g, beta %g: expected > 0", d.alpha,
                             d.beta);
    if ((unsigned)d.classifier > ASP_AMG_CLASSIFIER_MOMENT || (unsigned)d.coarsen > ASP_AMG_COARSEN_HMIS ||
        (unsigned)d.interp > ASP_AMG_INTERP_EXTENDED_I || (unsigned)d.stiffness > ASP_AMG_STIFFNESS_UNCLAMPED)
        return asp_error_set(err, ASP_EINVAL, "invalid classifier, coarsening or interpolation choice");
    if (!(d.strong_threshold > 0 && d.strong_threshold < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid strong threshold %g: expected a value in (0, 1)",
                             d.strong_threshold);
    if (!(d.trunc_factor >= 0 && d.trunc_factor < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid truncation factor %g: expected a value in [0, 1)",
                             d.trunc_factor);
    if (d.max_levels < 2 || d.max_levels > 100)
        return asp_error_set(err, ASP_EINVAL, "invalid level limit %zu: expected 2..100", d.max_levels);
    if (!(d.weak_coupling >= 0 && d.weak_coupling < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid weak-coupling cut %g: expected a value in [0, 1)",
                             d.weak_coupling);
    if (!(d.crease_cut <= 1) || !isfinite(d.crease_cut))
        return asp_error_set(err, ASP_EINVAL, "invalid crease cut %g: expected a value <= 1 (negative: off)",
                             d.crease_cut);
    if (!(d.drop_tol < 0.01) || d.drop_tol != d.drop_tol)
        return asp_error_set(err, ASP_EINVAL, "invalid drop tolerance %g: expected a value below 0.01", d.drop_tol);
    /* small clouds: every other point is a neighbour */
    if (count >= 2) {
        if (d.k_max > count - 1)
            d.k_max = count - 1;
        if (d.k_min > d.k_max)
            d.k_min = d.k_max;
        if (d.fan_k > d.k_max)
            d.fan_k = d.k_max;
    }
    *out = d;
    return 0;
}

/* k-th smallest of v[0..n-1] (destroys the order), Hoare's selection: deterministic, O(n) on average. */
static float select_kth(float *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        float pivot = v[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                float t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            break;
    }
    return v[k];
}

/*
 * Squared distance as the kd-tree computes it (kdtree.c dist2_3: float, same
 * expression and order; (p - q)^2 equals (q - p)^2 exactly), so a recomputed
 * distance is bit-identical to the one the search ranked by.
 */
static inline float dist2(const float *p, const float *q)
{
    float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

int asp__amg_neighbourhoods(const float *pos, size_t n, asp_amg_desc *desc, const asp_context *ctx,
                            asp__amg_nbhd *out, double *mean_size, asp_error *err)
{
    const size_t kmax = desc->k_max, kmin = desc->k_min;
    const int threads = asp_context_threads(ctx);
    (void)threads; /* read by the OpenMP pragmas only */
    asp_kdtree *tree = NULL;
    float *kth = NULL;
    asp__amg_nbhd nb = {n, kmax, NULL, NULL, NULL};
    int rc = asp_kdtree_create(pos, n, 3 * sizeof(float), ctx, &tree, err);
    if (rc)
        return rc;
    nb.nbr = asp_alloc(ctx, n * kmax * sizeof *nb.nbr);
    nb.nn = asp_alloc(ctx, n * sizeof *nb.nn);
    kth = asp_alloc(ctx, n * sizeof *kth);
    if (!nb.nbr || !nb.nn || !kth) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu neighbourhoods of %zu points", n, kmax);
        goto done;
    }
    /*
     * No distance array (issue 19: n k_max floats, as large as the indices):
     * the two distances per point that are needed, the k_min-th for epsilon
     * and the ball test, are recomputed exactly from the positions.
     */
    rc = asp_knn_all(tree, kmax, nb.nbr, NULL, ctx, err);
    asp_kdtree_destroy(tree);
    tree = NULL;
    if (rc)
        goto done;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        kth[i] = dist2(pos + 3 * (size_t)nb.nbr[i * kmax + kmin - 1], pos + 3 * i);
    }
    if (desc->epsilon == 0) {
        /* journal 2.1 leaves epsilon to the user: the median k_min-th neighbour distance is the typical scale */
        desc->epsilon = sqrt((double)select_kth(kth, n, n / 2));
        if (!(desc->epsilon > 0)) {
            rc = asp_error_set(err, ASP_EDEGENERATE,
                               "cannot decompose: most points coincide with %zu others (no neighbourhood radius)", kmin);
            goto done;
        }
    }
    const float eps2 = (float)(desc->epsilon * desc->epsilon);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii, m = kmin;
        const asp_index *row = nb.nbr + i * kmax;
        while (m < kmax && dist2(pos + 3 * (size_t)row[m], pos + 3 * i) <= eps2)
            m++;
        nb.nn[i] = (uint16_t)m;
    }
    double total = 0;
    for (size_t i = 0; i < n; i++)
        total += (double)nb.nn[i];
    *mean_size = total / (double)n;
    *out = nb;
    nb.nbr = NULL;
    nb.nn = NULL;
    nb.first = NULL;
done:
    asp__amg_nbhd_release(ctx, &nb);
    asp_free(ctx, kth);
    asp_kdtree_destroy(tree);
    return rc;
}

void asp__amg_nbhd_compact(const asp_context *ctx, asp__amg_nbhd *nb, size_t fan_k)
{
    if (nb->first || !nb->nbr)
        return;
    const size_t n = nb->n, kmax = nb->kmax;
    const int threads = asp_context_threads(ctx);
    (void)threads; /* read by the OpenMP pragma only */
    /* rows keep at least fan_k entries: the fans (fan.c) project the fan_k nearest whatever N(x) holds */
    const size_t keep_min = fan_k < kmax ? fan_k : kmax;
    size_t *first = asp_alloc(ctx, (n + 1) * sizeof *first);
    asp_index *compact = NULL;
    if (first) {
        first[0] = 0;
        for (size_t i = 0; i < n; i++)
            first[i + 1] = first[i] + (nb->nn[i] > keep_min ? nb->nn[i] : keep_min);
        compact = asp_alloc(ctx, (first[n] + 1) * sizeof *compact);
    }
    if (!compact) {
        asp_free(ctx, first); /* out of memory: the stride layout serves as well */
        return;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        memcpy(compact + first[i], nb->nbr + i * kmax, (first[i + 1] - first[i]) * sizeof *compact);
    }
    asp_free(ctx, nb->nbr);
    nb->nbr = compact;
    nb->first = first;
}

void asp__amg_nbhd_release(const asp_context *ctx, asp__amg_nbhd *nb)
{
    asp_free(ctx, nb->nbr);
    asp_free(ctx, nb->nn);
    asp_free(ctx, nb->first);
    nb->nbr = NULL;
    nb->nn = NULL;
    nb->first = NULL;
}
