/*
 * Normal estimation for raw point sets: PCA of each k-neighbourhood (thesis
 * 3.3.1: the smallest-variance direction is the normal), consistent signs by
 * propagation along a minimum spanning tree of the k-NN graph (Hoppe et al.
 * 1992), and the cloud-level driver that adds normals and radii in one pass.
 */
#include <math.h>
#include <string.h>

#include "geom/kdtree_internal.h"
#include "util/banned.h"

/* ---- PCA ---- */

/* Normal of point i and its k neighbours: PCA of their covariance (asp_covariance_sym3). */
static void pca_normal(const float *pos, size_t stride, size_t i, const asp_index *row, size_t k, float out[3])
{
    const asp_index self = (asp_index)i;
    double c[3], m[6];
    asp_covariance_sym3(pos, stride * sizeof *pos, row, k, &(asp_covariance_desc){.also = &self, .also_count = 1}, c,
                        m);
    double ev[3], V[9];
    asp_eigen_sym3(m, ev, V);
    /* column 2 belongs to the smallest eigenvalue; a zero matrix gives the identity, i.e. +z */
    out[0] = (float)V[2];
    out[1] = (float)V[5];
    out[2] = (float)V[8];
}

/* ---- MST orientation (Hoppe et al. 1992) ---- */

typedef struct mst_heap {
    asp_index *heap; /* point ids */
    uint32_t *pos;   /* point -> heap slot, UINT32_MAX when absent */
    float *key;      /* best known edge weight into the tree */
    size_t n;
} mst_heap;

static inline int heap_less(const mst_heap *h, asp_index a, asp_index b)
{
    return h->key[a] < h->key[b] || (h->key[a] == h->key[b] && a < b);
}

static void heap_place(mst_heap *h, size_t i, asp_index v)
{
    h->heap[i] = v;
    h->pos[v] = (uint32_t)i;
}

static void heap_up(mst_heap *h, size_t i)
{
    asp_index v = h->heap[i];
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!heap_less(h, v, h->heap[p]))
            break;
        heap_place(h, i, h->heap[p]);
        i = p;
    }
    heap_place(h, i, v);
}

static void heap_down(mst_heap *h, size_t i)
{
    asp_index v = h->heap[i];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && heap_less(h, h->heap[c + 1], h->heap[c]))
            c++;
        if (!heap_less(h, h->heap[c], v))
            break;
        heap_place(h, i, h->heap[c]);
        i = c;
    }
    heap_place(h, i, v);
}

static asp_index heap_pop(mst_heap *h)
{
    asp_index top = h->heap[0];
    h->pos[top] = UINT32_MAX;
    if (--h->n > 0) {
        heap_place(h, 0, h->heap[h->n]);
        heap_down(h, 0);
    }
    return top;
}

static uint32_t uf_find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static inline float dot3(const float *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void flip_if(float *n, int cond)
{
    if (cond) {
        n[0] = -n[0];
        n[1] = -n[1];
        n[2] = -n[2];
    }
}

/* Seed sign: +z, or away from the component centroid when the normal is nearly horizontal. */
static void orient_seed(float *n, const float *p, const double centroid[3])
{
    if (fabsf(n[2]) >= 1e-3f) {
        flip_if(n, n[2] < 0);
        return;
    }
    double d = n[0] * (p[0] - centroid[0]) + n[1] * (p[1] - centroid[1]) + n[2] * (p[2] - centroid[2]);
    if (d != 0.0) {
        flip_if(n, d < 0);
        return;
    }
    flip_if(n, fabsf(n[1]) >= 1e-3f ? n[1] < 0 : n[0] < 0);
}

/*
 * Orients normals (n, packed, unit) in place along an MST of the symmetric
 * k-NN graph, one traversal per connected component. Serial: the traversal
 * order is what makes the signs consistent.
 */
static int orient_mst(const float *pos, size_t stride, size_t count, const asp_index *knn, size_t k, float *n,
                      const asp_context *ctx, asp_error *err)
{
    const size_t edges = count * k;
    uint32_t *in_off = asp_calloc(ctx, count + 1, sizeof(uint32_t));
    asp_index *in_src = asp_alloc(ctx, edges * sizeof(asp_index));
    uint32_t *uf = asp_alloc(ctx, count * sizeof(uint32_t));
    asp_index *seed = asp_alloc(ctx, count * sizeof(asp_index));
    double *centroid = asp_calloc(ctx, 4 * count, sizeof(double));
    unsigned char *done = asp_calloc(ctx, count, 1);
    mst_heap h = {asp_alloc(ctx, count * sizeof(asp_index)), asp_alloc(ctx, count * sizeof(uint32_t)),
                  asp_alloc(ctx, count * sizeof(float)), 0};
    int rc = 0;
    if (!in_off || !in_src || !uf || !seed || !centroid || !done || !h.heap || !h.pos || !h.key) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot orient %zu normals: out of memory", count);
        goto out;
    }
    if (edges > UINT32_MAX) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot orient normals: %zu graph edges exceed 2^32", edges);
        goto out;
    }
    /* reverse edges (CSR), so the graph is symmetric even where k-NN is not */
    for (size_t e = 0; e < edges; e++)
        in_off[knn[e] + 1]++;
    for (size_t i = 0; i < count; i++)
        in_off[i + 1] += in_off[i];
    for (size_t i = 0; i < count; i++) {
        for (size_t j = 0; j < k; j++) {
            asp_index t = knn[i * k + j];
            in_src[in_off[t]++] = (asp_index)i;
        }
    }
    for (size_t i = count; i > 0; i--)
        in_off[i] = in_off[i - 1];
    in_off[0] = 0;

    /* connected components; the seed of each is its highest point, ties to the smaller index */
    for (size_t i = 0; i < count; i++)
        uf[i] = (uint32_t)i;
    for (size_t i = 0; i < count; i++)
        for (size_t j = 0; j < k; j++) {
            uint32_t a = uf_find(uf, (uint32_t)i), b = uf_find(uf, knn[i * k + j]);
            if (a != b)
                uf[a > b ? a : b] = a < b ? a : b;
        }
    for (size_t i = 0; i < count; i++) {
        uint32_t r = uf_find(uf, (uint32_t)i);
        const float *p = pos + i * stride;
        if (r == i || p[2] > pos[(size_t)seed[r] * stride + 2])
            seed[r] = (asp_index)i;
        for (int a = 0; a < 3; a++)
            centroid[4 * r + a] += p[a];
        centroid[4 * r + 3] += 1.0;
    }

    for (size_t i = 0; i < count; i++)
        h.pos[i] = UINT32_MAX;
    for (size_t r = 0; r < count && rc == 0; r++) {
        if (uf[r] != r)
            continue;
        asp_index s = seed[r];
        double c[3];
        for (int a = 0; a < 3; a++)
            c[a] = centroid[4 * r + a] / centroid[4 * r + 3];
        orient_seed(n + 3 * (size_t)s, pos + (size_t)s * stride, c);
        /* Prim's algorithm with decrease-key; weight 1 - |n_i . n_j| prefers propagating across flat areas */
        h.key[s] = 0.0f;
        h.n = 0;
        heap_place(&h, h.n++, s);
        while (h.n > 0) {
            asp_index v = heap_pop(&h);
            done[v] = 1;
            const float *nv = n + 3 * (size_t)v;
            for (size_t side = 0; side < 2; side++) {
                const asp_index *nb = side == 0 ? knn + (size_t)v * k : in_src + in_off[v];
                size_t m = side == 0 ? k : in_off[v + 1] - in_off[v];
                for (size_t j = 0; j < m; j++) {
                    asp_index u = nb[j];
                    if (done[u])
                        continue;
                    float *nu = n + 3 * (size_t)u;
                    float w = 1.0f - fabsf(dot3(nv, nu));
                    if (h.pos[u] == UINT32_MAX) {
                        h.key[u] = w;
                        flip_if(nu, dot3(nv, nu) < 0);
                        heap_place(&h, h.n++, u);
                        heap_up(&h, h.n - 1);
                    } else if (w < h.key[u]) {
                        /* the tree parent changes: take the sign from the new parent */
                        h.key[u] = w;
                        flip_if(nu, dot3(nv, nu) < 0);
                        heap_up(&h, h.pos[u]);
                    }
                }
            }
        }
        rc = asp_progress(ctx, "orient", (double)(r + 1) / (double)count);
        if (rc)
            rc = asp_error_set(err, rc, "normal orientation canceled");
    }
out:
    asp_free(ctx, in_off);
    asp_free(ctx, in_src);
    asp_free(ctx, uf);
    asp_free(ctx, seed);
    asp_free(ctx, centroid);
    asp_free(ctx, done);
    asp_free(ctx, h.heap);
    asp_free(ctx, h.pos);
    asp_free(ctx, h.key);
    return rc;
}

/* ---- public entry points ---- */

int asp_normals_from_knn(const float *positions, size_t count, size_t stride_bytes, const asp_index *knn,
                         size_t k, const asp_normals_desc *desc, float *restrict normals, const asp_context *ctx,
                         asp_error *err)
{
    const asp_normals_desc d = desc ? *desc : (asp_normals_desc){0};
    int rc = asp__check_positions(positions, count, stride_bytes, "normals", err);
    if (rc)
        return rc;
    if (!normals || !knn)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate normals: %s is NULL", normals ? "knn" : "normals");
    if (count < 3)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate normals of %zu points: need at least 3", count);
    if (k == 0 || k >= count)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate normals: k = %zu must be in [1, %zu]", k, count - 1);
    if ((unsigned)d.orient > ASP_ORIENT_NONE)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate normals: unknown orientation %d", (int)d.orient);
    if (d.orient == ASP_ORIENT_VIEWPOINT &&
        !(isfinite(d.viewpoint[0]) && isfinite(d.viewpoint[1]) && isfinite(d.viewpoint[2])))
        return asp_error_set(err, ASP_EINVAL, "cannot estimate normals: viewpoint is not finite");
    for (size_t e = 0; e < count * k; e++)
        if (knn[e] >= count)
            return asp_error_set(err, ASP_EINVAL,
                                 "cannot estimate normals: k-NN row %zu, column %zu: index %u is not below %zu",
                                 e / k, e % k, (unsigned)knn[e], count);
    if ((rc = asp__check_spread(positions, count, stride_bytes, "normals", err)) != 0)
        return rc;

    float *n = asp_alloc(ctx, count * 3 * sizeof(float));
    if (!n)
        return asp_error_set(err, ASP_ENOMEM, "cannot estimate %zu normals: out of memory", count);
    const size_t stride = stride_bytes / sizeof(float);
    const long long cnt = (long long)count;
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long i = 0; i < cnt; i++)
        pca_normal(positions, stride, (size_t)i, knn + (size_t)i * k, k, n + 3 * (size_t)i);
    rc = asp_progress(ctx, "normals", 1.0);
    if (rc) {
        asp_free(ctx, n);
        return asp_error_set(err, rc, "normal estimation canceled");
    }

    switch (d.orient) {
    case ASP_ORIENT_MST:
        rc = orient_mst(positions, stride, count, knn, k, n, ctx, err);
        break;
    case ASP_ORIENT_VIEWPOINT:
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
        for (long long i = 0; i < cnt; i++) {
            const float *p = positions + (size_t)i * stride;
            float to[3] = {d.viewpoint[0] - p[0], d.viewpoint[1] - p[1], d.viewpoint[2] - p[2]};
            flip_if(n + 3 * (size_t)i, dot3(n + 3 * (size_t)i, to) < 0);
        }
        break;
    case ASP_ORIENT_EXISTING:
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
        for (long long i = 0; i < cnt; i++)
            flip_if(n + 3 * (size_t)i, dot3(n + 3 * (size_t)i, normals + 3 * (size_t)i) < 0);
        break;
    case ASP_ORIENT_NONE:
        break;
    }
    if (rc == 0)
        memcpy(normals, n, count * 3 * sizeof(float));
    asp_free(ctx, n);
    return rc;
}

int asp_estimate_normals(const float *positions, size_t count, size_t stride_bytes, const asp_normals_desc *desc,
                         float *restrict normals, const asp_context *ctx, asp_error *err)
{
    int rc = asp__check_positions(positions, count, stride_bytes, "normals", err);
    if (rc)
        return rc;
    if (count < 3)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate normals of %zu points: need at least 3", count);
    if ((rc = asp__check_spread(positions, count, stride_bytes, "normals", err)) != 0)
        return rc;
    size_t k = desc && desc->k ? desc->k : ASP_NORMALS_DEFAULT_K;
    k = k < count ? k : count - 1;
    asp_index *idx = NULL;
    if ((rc = asp__knn_graph(positions, count, stride_bytes, k, &idx, NULL, ctx, err)) != 0)
        return rc;
    rc = asp_normals_from_knn(positions, count, stride_bytes, idx, k, desc, normals, ctx, err);
    asp_free(ctx, idx);
    return rc;
}

int asp_cloud_estimate(asp_cloud *cloud, const asp_estimate_desc *desc, asp_error *err)
{
    if (!cloud || !desc)
        return asp_error_set(err, ASP_EINVAL, "cannot estimate attributes: cloud or desc is NULL");
    const asp_context *ctx = &cloud->ctx;
    const size_t count = cloud->count;
    int want_n = desc->normals && (desc->force || !cloud->normals);
    int want_r = desc->radii && (desc->force || !cloud->radii);
    if (!want_n && !want_r)
        return 0;
    if (desc->orient == ASP_ORIENT_EXISTING && want_n && !cloud->normals)
        return asp_error_set(err, ASP_EINVAL, "cannot keep the orientation of normals: the cloud has none");
    int rc = asp__check_positions(cloud->positions, count, 12, want_n ? "normals" : "radii", err);
    if (rc)
        return rc;
    if (count < (want_n ? 3u : 2u))
        return asp_error_set(err, ASP_EDEGENERATE, "cannot estimate %s of %zu points: need at least %d",
                             want_n ? "normals" : "radii", count, want_n ? 3 : 2);
    if ((rc = asp__check_spread(cloud->positions, count, 12, want_n ? "normals" : "radii", err)) != 0)
        return rc;

    size_t kn = desc->k ? desc->k : ASP_NORMALS_DEFAULT_K;
    size_t kr = desc->radius_k ? desc->radius_k : ASP_RADII_DEFAULT_K;
    kn = kn < count ? kn : count - 1;
    kr = kr < count ? kr : count - 1;
    size_t kmax = want_n ? kn : 0;
    kmax = want_r && kr > kmax ? kr : kmax;

    asp_index *idx = NULL;
    float *d2 = NULL;
    float *n = want_n ? asp_alloc(ctx, count * 3 * sizeof(float)) : NULL;
    float *r = want_r ? asp_alloc(ctx, count * sizeof(float)) : NULL;
    if ((want_n && !n) || (want_r && !r)) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot estimate attributes of %zu points: out of memory", count);
        goto out;
    }
    if ((rc = asp__knn_graph(cloud->positions, count, 12, kmax, &idx, &d2, ctx, err)) != 0)
        goto out;
    if (want_n) {
        /*
         * asp_knn_all rows are sorted nearest first, so the first kn columns of
         * a kmax-wide row are the kn nearest: compact them into a kn-wide graph.
         */
        asp_index *g = idx;
        if (kn < kmax) {
            g = asp_alloc(ctx, count * kn * sizeof(asp_index));
            if (!g) {
                rc = asp_error_set(err, ASP_ENOMEM, "cannot estimate normals: out of memory");
                goto out;
            }
            for (size_t i = 0; i < count; i++)
                memcpy(g + i * kn, idx + i * kmax, kn * sizeof(asp_index));
        }
        asp_normals_desc nd = {kn, desc->orient, {desc->viewpoint[0], desc->viewpoint[1], desc->viewpoint[2]}};
        if (desc->orient == ASP_ORIENT_EXISTING)
            memcpy(n, cloud->normals, count * 3 * sizeof(float));
        rc = asp_normals_from_knn(cloud->positions, count, 12, g, kn, &nd, n, ctx, err);
        if (g != idx)
            asp_free(ctx, g);
        if (rc)
            goto out;
    }
    if (want_r) {
        asp_radii_desc rd = {kr, desc->radius_factor};
        if ((rc = asp_radii_from_knn(d2, count, kmax, &rd, r, ctx, err)) != 0)
            goto out;
    }
    if ((rc = asp_cloud_add_attrs(cloud, (want_n ? ASP_ATTR_NORMALS : 0u) | (want_r ? ASP_ATTR_RADII : 0u), err)) !=
        0)
        goto out;
    if (want_n)
        memcpy(cloud->normals, n, count * 3 * sizeof(float));
    if (want_r)
        memcpy(cloud->radii, r, count * sizeof(float));
out:
    asp_free(ctx, idx);
    asp_free(ctx, d2);
    asp_free(ctx, n);
    asp_free(ctx, r);
    return rc;
}
