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
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "geom/kdtree_internal.h"
#include "util/banned.h"

/* Queries between progress reports; the block boundaries do not affect results. */
enum { KNN_BLOCK = 1 << 16 };
/*
 * Defaults (asp__knn_tuning): groups of 32..64 points; gather within 1.25
 * times the expected k-th distance (Poisson noise makes fewer than k points
 * inside rare); first scan within 1.2 times the last k-th squared distance
 * (usually a little more than k points).
 */
enum { KNN_GROUP_MAX = 64 };
#define KNN_REACH 1.25
#define KNN_GUESS 1.2f

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

/* Same expression and order as the tree's point distances (kdtree.c dist2_3). */
static inline float dist2_3(float dx, float dy, float dz)
{
    return dx * dx + dy * dy + dz * dz;
}

/*
 * Gap between [lo, hi] and [glo, ghi] along one axis, 0 when they overlap.
 * For p in the first interval and q in the second, the float difference p - q
 * (or q - p) is at least the gap computed here, because float subtraction is
 * monotonic; so the box bound never exceeds a computed point distance. At most
 * one of a, b is positive and x + |x| is exactly 2 max(x, 0), so this is the
 * max without branches, which lets the leaf loop vectorize.
 */
static inline float axis_gap(float lo, float hi, float glo, float ghi)
{
    float a = lo - ghi, b = glo - hi;
    return 0.5f * ((a + fabsf(a)) + (b + fabsf(b)));
}

/*
 * Per-thread candidate list of a query group: the points of every leaf whose
 * box comes within the group's bound, copied as structure of arrays so the
 * distance loops stream, with each leaf's box for a per-query cull.
 */
typedef struct knn_scratch {
    float *cx, *cy, *cz;
    asp_index *cid;   /* original index of each candidate */
    uint32_t *lbeg;   /* candidate leaf j holds candidates [lbeg[j], lbeg[j + 1]) */
    float *lbox;      /* 6 arrays of cand_max floats: lo x, y, z, hi x, y, z per leaf */
    float *ld;        /* per query: lower bound of the squared distance to each leaf */
    uint64_t *keys;   /* selection buffer, also the tree search scratch */
    uint64_t *far;    /* candidates beyond the guessed k-th distance */
    float guess_factor; /* first scan within guess_factor times the last k-th squared distance */
    double reach_factor; /* gather within reach_factor times the group's largest k-th distance */
    size_t n_cand, n_leaf;
    size_t cap;    /* candidates allowed */
    size_t stride; /* length of each array, >= cap */
} knn_scratch;

typedef struct knn_gather {
    const asp_kdtree *tree;
    knn_scratch *s;
    float glo[3], ghi[3];
    float r2;
    size_t flat_take; /* k + 1: an equal-point leaf never contributes more (see gather_leaf) */
    int overflow;
} knn_gather;

static void gather_leaf(knn_gather *g, const asp__kd_node *nd, const float *box)
{
    knn_scratch *s = g->s;
    size_t n = nd->end - nd->begin;
    /*
     * An equal-point leaf is sorted by index and all its points are equally
     * far from any query: at most k of them are kept, plus the query itself.
     */
    if (nd->axis == ASP__KD_FLAT && n > g->flat_take)
        n = g->flat_take;
    if (s->n_cand + n > s->cap) {
        g->overflow = 1;
        return;
    }
    const float *xyz = g->tree->xyz + 3 * (size_t)nd->begin;
    const asp_index *perm = g->tree->perm + nd->begin;
    size_t c = s->n_cand;
    for (size_t i = 0; i < n; i++) {
        s->cx[c + i] = xyz[3 * i];
        s->cy[c + i] = xyz[3 * i + 1];
        s->cz[c + i] = xyz[3 * i + 2];
        s->cid[c + i] = perm[i];
    }
    size_t j = s->n_leaf++;
    for (int a = 0; a < 6; a++)
        s->lbox[(size_t)a * s->stride + j] = box[a];
    s->n_cand = c + n;
    s->lbeg[j + 1] = (uint32_t)s->n_cand;
}

static void gather_rec(knn_gather *g, uint32_t node)
{
    const float *b = g->tree->box + 6 * (size_t)node;
    float d = dist2_3(axis_gap(b[0], b[3], g->glo[0], g->ghi[0]), axis_gap(b[1], b[4], g->glo[1], g->ghi[1]),
                      axis_gap(b[2], b[5], g->glo[2], g->ghi[2]));
    if (d > g->r2 || g->overflow)
        return;
    const asp__kd_node *nd = &g->tree->nodes[node];
    if (nd->axis >= ASP__KD_LEAF) {
        gather_leaf(g, nd, b);
        return;
    }
    gather_rec(g, node + 1);
    gather_rec(g, nd->right);
}

/* Collects the candidates of every point within squared distance r2 of the box of node; 0 on overflow. */
static int gather(const asp_kdtree *tree, uint32_t node, float r2, size_t k, knn_scratch *s)
{
    const float *b = tree->box + 6 * (size_t)node;
    knn_gather g = {tree, s, {b[0], b[1], b[2]}, {b[3], b[4], b[5]}, r2, k + 1, 0};
    s->n_cand = 0;
    s->n_leaf = 0;
    s->lbeg[0] = 0;
    gather_rec(&g, 0);
    return !g.overflow;
}

/*
 * Appends to near[] the keys of the candidates of leaves lo < ld <= hi with
 * distance <= split2, and to far[] those with split2 < distance <= r2, except
 * q itself (self).
 */
static void scan_leaves(const knn_scratch *s, const float q[3], asp_index self, float lo, float hi, float split2,
                        float r2, size_t *n_near, size_t *n_far)
{
    const float *restrict cx = s->cx, *restrict cy = s->cy, *restrict cz = s->cz;
    const asp_index *restrict cid = s->cid;
    const float *restrict ld = s->ld;
    uint64_t *restrict near = s->keys, *restrict far = s->far;
    const float qx = q[0], qy = q[1], qz = q[2];
    size_t m = *n_near, mf = *n_far;
    for (size_t j = 0; j < s->n_leaf; j++) {
        if (!(ld[j] > lo && ld[j] <= hi))
            continue;
        /* branch-free append: whether a point is inside is a coin flip for the predictor */
        for (uint32_t i = s->lbeg[j]; i < s->lbeg[j + 1]; i++) {
            float d = dist2_3(cx[i] - qx, cy[i] - qy, cz[i] - qz);
            uint64_t key = asp__kd_key(d, cid[i]);
            int keep = (d <= r2) & (cid[i] != self), is_near = d <= split2;
            near[m] = key;
            far[mf] = key;
            m += (size_t)(keep & is_near);
            mf += (size_t)(keep & !is_near);
        }
    }
    *n_near = m;
    *n_far = mf;
}

/*
 * Collects the keys of the candidates within r2 of q, except q itself (self):
 * those within guess2 go to s->keys, the others to s->far, and *n_far gets
 * their number. guess2 estimates the k-th distance: leaves farther than it
 * are scanned only when fewer than k points lie within it. Leaves farther
 * than r2 are never scanned; the bound makes the result exact, the culls fast.
 */
static size_t scan_candidates(knn_scratch *s, const float q[3], asp_index self, float r2, float guess2, size_t k,
                              size_t *n_far)
{
    const size_t nl = s->n_leaf, stride = s->stride;
    const float *restrict lox = s->lbox, *restrict loy = s->lbox + stride, *restrict loz = s->lbox + 2 * stride;
    const float *restrict hix = s->lbox + 3 * stride, *restrict hiy = s->lbox + 4 * stride;
    const float *restrict hiz = s->lbox + 5 * stride;
    float *restrict ld = s->ld;
    const float qx = q[0], qy = q[1], qz = q[2];
#pragma omp simd
    for (size_t j = 0; j < nl; j++)
        ld[j] = dist2_3(axis_gap(lox[j], hix[j], qx, qx), axis_gap(loy[j], hiy[j], qy, qy),
                        axis_gap(loz[j], hiz[j], qz, qz));
    size_t m = 0, mf = 0;
    scan_leaves(s, q, self, -1.0f, guess2, guess2, r2, &m, &mf);
    if (m < k && guess2 < r2)
        scan_leaves(s, q, self, guess2, r2, guess2, r2, &m, &mf);
    *n_far = mf;
    return m;
}

/*
 * Sorts the k smallest keys into keys[0, k): the m near keys are all smaller
 * than the nf far ones. A near list a little longer than k is sorted whole,
 * cheaper than selecting first.
 */
static void finish_keys(uint64_t *keys, size_t m, uint64_t *far, size_t nf, size_t k)
{
    if (m >= k) {
        if (m > k + k / 2 + 8) {
            asp__kd_select_keys(keys, m, k - 1);
            m = k;
        }
        asp__kd_sort_keys(keys, m);
        return;
    }
    size_t need = k - m;
    if (nf > need)
        asp__kd_select_keys(far, nf, need - 1);
    asp__kd_sort_keys(far, need);
    asp__kd_sort_keys(keys, m);
    memcpy(keys + m, far, need * sizeof(uint64_t));
}

/*
 * Writes one output row. Rows land in original-index order while queries run
 * in leaf order, so every row is a cache miss; with SSE2 (baseline on x86-64)
 * aligned rows are written with streaming stores, which skip reading the
 * lines first (about half the memory traffic). knn_fence() orders them.
 */
static void emit_row(const uint64_t *keys, size_t k, asp_index *restrict idx, float *restrict d)
{
#ifdef __SSE2__
    if (k % 4 == 0 && ((uintptr_t)idx & 15) == 0 && ((uintptr_t)d & 15) == 0) {
        for (size_t j = 0; j < k; j += 4) {
            __m128 a = _mm_castsi128_ps(_mm_loadu_si128((const __m128i *)(const void *)(keys + j)));
            __m128 b = _mm_castsi128_ps(_mm_loadu_si128((const __m128i *)(const void *)(keys + j + 2)));
            _mm_stream_si128((__m128i *)(void *)(idx + j), _mm_castps_si128(_mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0))));
            if (d)
                _mm_stream_ps(d + j, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
        }
        return;
    }
#endif
    for (size_t j = 0; j < k; j++)
        idx[j] = (asp_index)(keys[j] & 0xffffffffu);
    if (d)
        for (size_t j = 0; j < k; j++)
            d[j] = key_distance(keys[j]);
}

/* Makes the streaming stores of this thread visible before the next barrier. */
static void knn_fence(void)
{
#ifdef __SSE2__
    _mm_sfence();
#endif
}

/* Per-thread memory of the last answered query, the source of the coherent bounds. */
typedef struct knn_last {
    size_t group; /* group index + 1 of the last query, 0 when none */
    uint32_t slot;
    float d2;     /* its k-th squared distance */
    float group_d2; /* largest k-th squared distance in the last group */
} knn_last;

/* One query by tree search, bounded by the last query when there is one. */
static void tree_query(const asp_kdtree *tree, size_t k, uint32_t s, knn_last *last, uint64_t *scratch,
                       asp_index *idx, float *dist2)
{
    const float *q = tree->xyz + 3 * (size_t)s;
    float bound2 = last->group ? coherent_bound(q, tree->xyz + 3 * (size_t)last->slot, last->d2) : INFINITY;
    const size_t row = (size_t)tree->perm[s] * k;
    size_t m = asp__kdtree_search(tree, q, k, s, bound2, scratch, dist2 ? dist2 + row : NULL, idx + row);
    last->slot = s;
    last->d2 = key_distance(scratch[m - 1]);
}

/*
 * Answers the queries of one group (a subtree of at most group_max points):
 * one candidate list is gathered for the whole group, then each query scans
 * it (thesis 3.3.1 needs the k-NN of every point; this shares the tree walk
 * among close queries). The gather radius is a guess from the last query's
 * k-th distance: the list holds every point within it of the group's box, so
 * a query that finds k points within it has its exact answer; the others,
 * rare, fall back to a tree search.
 */
static void answer_group(const asp_kdtree *tree, size_t k, size_t gi, uint32_t node, knn_scratch *s,
                         knn_last *last, asp_index *idx, float *dist2)
{
    const asp__kd_node *nd = &tree->nodes[node];
    uint32_t b = nd->begin;
    const uint32_t e = nd->end;
    if (last->group == 0 || last->group != gi) { /* no recent query (chunk start): start with a search */
        last->group = 0;
        tree_query(tree, k, b++, last, s->keys, idx, dist2);
        last->group_d2 = last->d2;
    }
    last->group = gi + 1;
    if (b == e)
        return;
    const float *box = tree->box + 6 * (size_t)node;
    double reach = 0.0;
    for (uint32_t q = b; q < e; q++) {
        const float *p = tree->xyz + 3 * (size_t)q;
        double r = 0.0;
        for (int a = 0; a < 3; a++) {
            double c = 0.5 * ((double)box[a] + box[a + 3]) - p[a];
            r += c * c;
        }
        reach = r > reach ? r : reach;
    }
    /* farthest query from the box centre plus the expected k-th distance with a margin */
    double rg = sqrt(reach) + s->reach_factor * sqrt((double)last->group_d2);
    rg = rg * rg;
    const float r2g = rg < FLT_MAX ? (float)rg : FLT_MAX;
    if (!gather(tree, node, r2g, k, s)) {
        for (uint32_t q = b; q < e; q++)
            tree_query(tree, k, q, last, s->keys, idx, dist2);
        last->group_d2 = last->d2;
        return;
    }
    float group_d2 = 0.0f;
    for (uint32_t q = b; q < e; q++) {
        const float *p = tree->xyz + 3 * (size_t)q;
        /* a proven bound from the last query, clipped to what the list covers */
        float rq = coherent_bound(p, tree->xyz + 3 * (size_t)last->slot, last->d2);
        rq = rq < r2g ? rq : r2g;
        float guess = last->d2 * s->guess_factor;
        size_t nf = 0;
        size_t m = scan_candidates(s, p, tree->perm[q], rq, guess < rq ? guess : rq, k, &nf);
        if (m + nf < k) {
            tree_query(tree, k, q, last, s->keys, idx, dist2);
        } else {
            finish_keys(s->keys, m, s->far, nf, k);
            const size_t row = (size_t)tree->perm[q] * k;
            emit_row(s->keys, k, idx + row, dist2 ? dist2 + row : NULL);
            last->slot = q;
            last->d2 = key_distance(s->keys[k - 1]);
        }
        group_d2 = last->d2 > group_d2 ? last->d2 : group_d2;
    }
    knn_fence();
    last->group_d2 = group_d2;
}

/* Preorder list of the query groups: subtrees of at most group_max points, or leaves. */
static size_t list_groups(const asp_kdtree *tree, size_t group_max, uint32_t *groups)
{
    size_t n = 0, top = 0;
    uint32_t stack[72];
    stack[top++] = 0;
    while (top > 0) {
        uint32_t id = stack[--top];
        const asp__kd_node *nd = &tree->nodes[id];
        if (nd->axis >= ASP__KD_LEAF || nd->end - nd->begin <= group_max) {
            groups[n++] = id;
            continue;
        }
        stack[top++] = nd->right;
        stack[top++] = id + 1;
    }
    return n;
}

static size_t round16(size_t n)
{
    return (n + 15) & ~(size_t)15;
}

int asp__knn_all_tuned(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2, const asp__knn_tuning *tuning,
                       const asp_context *ctx, asp_error *err)
{
    if (!tree || !idx)
        return asp_error_set(err, ASP_EINVAL, "cannot compute k-nearest neighbours: tree or output is NULL");
    const size_t n = tree->count;
    if (k == 0 || k >= n)
        return asp_error_set(err, ASP_EINVAL,
                             "cannot compute %zu nearest neighbours of %zu points: k must be in [1, %zu]", k, n,
                             n - 1);
    const asp__knn_tuning tune = tuning ? *tuning : (asp__knn_tuning){0};
    const size_t group_max = tune.tree_only ? 0 : tune.group_max ? tune.group_max : KNN_GROUP_MAX;
    /*
     * Candidates never exceed n; a group's neighbourhood holds far fewer than
     * 128 k + 4096 points unless the data is very uneven, and an overflow
     * only sends that group to the per-query search.
     */
    size_t cap = n;
    if (k < (SIZE_MAX - 4096) / 128 && 128 * k + 4096 < n)
        cap = 128 * k + 4096;
    if (tune.cand_max)
        cap = tune.cand_max < cap ? tune.cand_max : cap;
    const size_t nkeys = round16(cap > ASP__KD_SCRATCH(k) ? cap : ASP__KD_SCRATCH(k));
    const size_t cap16 = round16(cap);
    /* per thread: 3 coordinate + 1 index + 6 box + 1 bound arrays of cap, cap + 1 leaf starts, the keys */
    const size_t per_thread = (11 * cap16 + round16(cap + 1)) * 4 + (nkeys + cap16) * 8;
    const int threads = asp_context_threads(ctx);
    if (per_thread > SIZE_MAX / 2 / (size_t)threads)
        return asp_error_set(err, ASP_ENOMEM, "cannot compute %zu nearest neighbours: out of memory", k);
    unsigned char *mem = asp_alloc(ctx, (size_t)threads * per_thread);
    knn_last *lasts = asp_calloc(ctx, (size_t)threads, sizeof(knn_last));
    uint32_t *groups = asp_alloc(ctx, tree->node_count * sizeof(uint32_t));
    if (!mem || !lasts || !groups) {
        asp_free(ctx, mem);
        asp_free(ctx, lasts);
        asp_free(ctx, groups);
        return asp_error_set(err, ASP_ENOMEM, "cannot compute %zu nearest neighbours: out of memory", k);
    }
    const size_t ngroups = list_groups(tree, group_max, groups);
    int rc = 0;
    for (size_t g0 = 0; g0 < ngroups && rc == 0;) {
        /* a block of whole groups of about KNN_BLOCK queries */
        size_t g1 = g0;
        const uint32_t first = tree->nodes[groups[g0]].begin;
        while (g1 < ngroups && tree->nodes[groups[g1]].begin - first < KNN_BLOCK)
            g1++;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long gi = (long long)g0; gi < (long long)g1; gi++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            unsigned char *base = mem + (size_t)tid * per_thread;
            knn_scratch s;
            s.keys = (uint64_t *)(void *)base;
            s.far = s.keys + nkeys;
            s.guess_factor = tune.guess > 0.0f ? tune.guess : KNN_GUESS;
            s.reach_factor = tune.reach > 0.0 ? tune.reach : KNN_REACH;
            s.cx = (float *)(void *)(base + (nkeys + cap16) * 8);
            s.cy = s.cx + cap16;
            s.cz = s.cy + cap16;
            s.ld = s.cz + cap16;
            s.lbox = s.ld + cap16;
            s.cid = (asp_index *)(void *)(s.lbox + 6 * cap16);
            s.lbeg = s.cid + cap16;
            s.cap = cap;
            s.stride = cap16;
            s.n_cand = s.n_leaf = 0;
            const uint32_t node = groups[gi];
            if (group_max == 0) {
                const asp__kd_node *nd = &tree->nodes[node];
                if (lasts[tid].group != (size_t)gi)
                    lasts[tid].group = 0;
                for (uint32_t q = nd->begin; q < nd->end; q++) {
                    tree_query(tree, k, q, &lasts[tid], s.keys, idx, dist2);
                    lasts[tid].group = (size_t)gi + 1;
                }
            } else {
                answer_group(tree, k, (size_t)gi, node, &s, &lasts[tid], idx, dist2);
            }
        }
        const size_t done = g1 < ngroups ? tree->nodes[groups[g1]].begin : n;
        rc = asp_progress(ctx, "knn", (double)done / (double)n);
        g0 = g1;
    }
    asp_free(ctx, mem);
    asp_free(ctx, lasts);
    asp_free(ctx, groups);
    if (rc)
        return asp_error_set(err, rc, "k-nearest neighbours canceled");
    return 0;
}

int asp_knn_all(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2, const asp_context *ctx,
                asp_error *err)
{
    return asp__knn_all_tuned(tree, k, idx, dist2, NULL, ctx, err);
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
