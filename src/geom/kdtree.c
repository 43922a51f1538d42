/*
 * Exact static kd-tree: median split on the widest axis, small leaf buckets,
 * points copied into leaf order for cache locality, and k-nearest / radius
 * queries with ties broken by the smaller original index, so results equal a
 * brute-force sort. Neighbourhoods feed PCA classification (journal 3.1).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/kdtree_internal.h"
#include "util/banned.h"

/* ---- build ---- */

typedef struct kd_item {
    float p[3];
    uint32_t idx;
} kd_item;

typedef struct kd_build {
    kd_item *items;
    asp__kd_node *nodes;
    float *box;
    size_t node_count;
    size_t node_cap;
} kd_build;

static void swap_items(kd_item *a, kd_item *b)
{
    kd_item t = *a;
    *a = *b;
    *b = t;
}

static float median3(float x, float y, float z)
{
    if (x > y) {
        float t = x;
        x = y;
        y = t;
    }
    /* now x <= y */
    if (z <= x)
        return x;
    return z < y ? z : y;
}

/*
 * Quickselect with a three-way partition: afterwards v[nth] holds the value a
 * full sort would put there, smaller-or-equal keys before it and
 * greater-or-equal keys after it. The "equal" band makes runs of duplicate
 * coordinates cost one pass instead of degrading to quadratic time.
 */
static void select_nth(kd_item *v, size_t n, size_t nth, int axis)
{
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        float piv = median3(v[lo].p[axis], v[lo + (hi - lo) / 2].p[axis], v[hi - 1].p[axis]);
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            float c = v[i].p[axis];
            if (c < piv)
                swap_items(&v[lt++], &v[i++]);
            else if (c > piv)
                swap_items(&v[i], &v[--gt]);
            else
                i++;
        }
        if (nth < lt)
            hi = lt;
        else if (nth >= gt)
            lo = gt;
        else
            return;
    }
}

static int cmp_item_index(const void *a, const void *b)
{
    uint32_t x = ((const kd_item *)a)->idx, y = ((const kd_item *)b)->idx;
    return (x > y) - (x < y);
}

/* A subtree left for a parallel pass: items[begin, end), nodes from id on. */
typedef struct kd_task {
    uint32_t begin, end, id;
} kd_task;

/* Nodes a subtree of m >= 6 points can need: its leaves hold >= ASP__KD_LEAF_MAX / 2 points. */
static size_t subtree_cap(size_t m)
{
    return 2 * (m / (ASP__KD_LEAF_MAX / 2)) + 2;
}

/*
 * Builds the subtree over items[begin, end) and returns its node index.
 * Depth is at most log2(count) + 1 because every split halves the count, even
 * when many points share the split coordinate. With tasks, the subtrees
 * defer levels down are only reserved (subtree_cap nodes each) and listed,
 * for build_tasks to fill in parallel; the layout does not depend on threads.
 */
static uint32_t build_node(kd_build *b, uint32_t begin, uint32_t end, int defer, kd_task *tasks, size_t *ntasks)
{
    if (tasks && defer == 0) {
        uint32_t at = (uint32_t)b->node_count;
        tasks[(*ntasks)++] = (kd_task){begin, end, at};
        b->node_count += subtree_cap(end - begin);
        return at;
    }
    uint32_t id = (uint32_t)b->node_count++;
    asp__kd_node *nd = &b->nodes[id];
    const kd_item *it = b->items;

    float lo[3] = {it[begin].p[0], it[begin].p[1], it[begin].p[2]};
    float hi[3] = {lo[0], lo[1], lo[2]};
    uint32_t min_index = it[begin].idx;
    for (uint32_t i = begin + 1; i < end; i++) {
        for (int a = 0; a < 3; a++) {
            float c = it[i].p[a];
            lo[a] = c < lo[a] ? c : lo[a];
            hi[a] = c > hi[a] ? c : hi[a];
        }
        min_index = it[i].idx < min_index ? it[i].idx : min_index;
    }
    int axis = 0;
    float ext = hi[0] - lo[0];
    for (int a = 1; a < 3; a++) {
        if (hi[a] - lo[a] > ext) {
            ext = hi[a] - lo[a];
            axis = a;
        }
    }
    memcpy(b->box + 6 * (size_t)id, lo, sizeof lo);
    memcpy(b->box + 6 * (size_t)id + 3, hi, sizeof hi);
    nd->begin = begin;
    nd->end = end;
    nd->min_index = min_index;
    nd->split = 0.0f;
    nd->right = 0;
    if (ext == 0.0f) {
        /* All points equal: one flat leaf in index order lets queries stop early. */
        qsort(b->items + begin, end - begin, sizeof(kd_item), cmp_item_index);
        nd->axis = ASP__KD_FLAT;
        return id;
    }
    if (end - begin <= ASP__KD_LEAF_MAX) {
        nd->axis = ASP__KD_LEAF;
        return id;
    }
    uint32_t mid = begin + (end - begin) / 2;
    select_nth(b->items + begin, end - begin, mid - begin, axis);
    nd->axis = (uint32_t)axis;
    nd->split = b->items[mid].p[axis];
    build_node(b, begin, mid, defer - 1, tasks, ntasks);
    uint32_t right = build_node(b, mid, end, defer - 1, tasks, ntasks);
    b->nodes[id].right = right;
    return id;
}

/* Levels split serially before the subtrees below are built in parallel; fixed, so the tree is too. */
enum { KD_DEFER_LEVELS = 4, KD_PARALLEL_MIN = 1 << 16 };

/*
 * Builds the tree over all items: for large inputs the top KD_DEFER_LEVELS
 * levels serially, then their 2^KD_DEFER_LEVELS subtrees in parallel, each
 * into its own reserved node range (unused slots between ranges are never
 * reached). Returns the number of node slots used.
 */
static size_t build_tree(kd_build *b, uint32_t count, int threads)
{
    if (count < KD_PARALLEL_MIN || threads <= 1) {
        build_node(b, 0, count, -1, NULL, NULL);
        return b->node_count;
    }
    kd_task tasks[1 << KD_DEFER_LEVELS];
    size_t ntasks = 0;
    build_node(b, 0, count, KD_DEFER_LEVELS, tasks, &ntasks);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long t = 0; t < (long long)ntasks; t++) {
        kd_build sub = *b;
        sub.node_count = tasks[t].id;
        build_node(&sub, tasks[t].begin, tasks[t].end, -1, NULL, NULL);
    }
    return b->node_count;
}

int asp_kdtree_create(const float *positions, size_t count, size_t stride_bytes, const asp_context *ctx,
                      asp_kdtree **out, asp_error *err)
{
    if (!out)
        return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: output pointer is NULL");
    if (count == 0)
        return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: no points");
    if (!positions)
        return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: positions are NULL");
    if (count >= UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: %zu points exceed the limit of %u", count,
                             (unsigned)(UINT32_MAX - 1));
    if (stride_bytes < 3 * sizeof(float) || stride_bytes % sizeof(float) != 0)
        return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: stride %zu is not a multiple of 4 >= 12",
                             stride_bytes);
    const size_t stride = stride_bytes / sizeof(float);
    for (size_t i = 0; i < count; i++) {
        const float *p = positions + i * stride;
        for (int a = 0; a < 3; a++)
            if (!isfinite(p[a]))
                return asp_error_set(err, ASP_EINVAL, "cannot build kd-tree: point %zu: coordinate %c is not finite",
                                     i, "xyz"[a]);
    }

    asp_context c = ctx ? *ctx : (asp_context){0};
    /* Every leaf below the root holds >= ASP__KD_LEAF_MAX / 2 points (only nodes above the cap split). */
    size_t cap = subtree_cap(count) + 2 * (1u << KD_DEFER_LEVELS) * 2;
    asp_kdtree *t = asp_calloc(&c, 1, sizeof *t);
    kd_item *items = asp_calloc(&c, count, sizeof(kd_item));
    asp__kd_node *nodes = asp_calloc(&c, cap, sizeof(asp__kd_node));
    float *xyz = asp_calloc(&c, count, 3 * sizeof(float));
    asp_index *perm = asp_calloc(&c, count, sizeof(asp_index));
    float *box = asp_alloc(&c, cap * 6 * sizeof(float));
    if (!t || !items || !nodes || !xyz || !perm || !box) {
        asp_free(&c, box);
        asp_free(&c, t);
        asp_free(&c, items);
        asp_free(&c, nodes);
        asp_free(&c, xyz);
        asp_free(&c, perm);
        return asp_error_set(err, ASP_ENOMEM, "cannot build kd-tree over %zu points: out of memory", count);
    }
    for (size_t i = 0; i < count; i++) {
        const float *p = positions + i * stride;
        items[i] = (kd_item){{p[0], p[1], p[2]}, (uint32_t)i};
    }
    kd_build b = {items, nodes, box, 0, cap};
    build_tree(&b, (uint32_t)count, asp_context_threads(&c));
    for (size_t i = 0; i < count; i++) {
        memcpy(xyz + 3 * i, items[i].p, 3 * sizeof(float));
        perm[i] = items[i].idx;
    }
    asp_free(&c, items);

    t->ctx = c;
    t->count = count;
    t->xyz = xyz;
    t->perm = perm;
    t->nodes = nodes;
    t->box = box;
    t->node_count = b.node_count;
    *out = t;
    return 0;
}

void asp_kdtree_destroy(asp_kdtree *tree)
{
    if (!tree)
        return;
    asp_context c = tree->ctx;
    asp_free(&c, tree->xyz);
    asp_free(&c, tree->perm);
    asp_free(&c, tree->nodes);
    asp_free(&c, tree->box);
    asp_free(&c, tree);
}

size_t asp_kdtree_count(const asp_kdtree *tree)
{
    return tree ? tree->count : 0;
}

/* ---- queries ---- */

/*
 * Bounded max-heap of (distance, index) pairs: the root is the worst kept
 * candidate. Ordering by the pair, not by distance alone, is what makes the
 * result equal a brute-force sort when distances tie.
 */
typedef struct kd_search {
    const float *xyz;
    const asp_index *perm;
    const asp__kd_node *nodes;
    float q[3];
    uint32_t exclude;
    size_t k, n;
    float *d;
    asp_index *idx;
    float r2;     /* radius queries: inclusive bound */
    size_t total; /* radius queries: all points found */
} kd_search;

static inline int pair_less(float d1, asp_index i1, float d2, asp_index i2)
{
    return d1 < d2 || (d1 == d2 && i1 < i2);
}

static void sift_down(float *d, asp_index *idx, size_t n, size_t i)
{
    float dv = d[i];
    asp_index iv = idx[i];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && pair_less(d[c], idx[c], d[c + 1], idx[c + 1]))
            c++;
        if (!pair_less(dv, iv, d[c], idx[c]))
            break;
        d[i] = d[c];
        idx[i] = idx[c];
        i = c;
    }
    d[i] = dv;
    idx[i] = iv;
}

/* Offers a candidate; returns 0 when it was rejected (not better than the worst kept). */
static inline int heap_offer(kd_search *s, float dd, asp_index id)
{
    if (s->n < s->k) {
        size_t i = s->n++;
        while (i > 0) {
            size_t p = (i - 1) / 2;
            if (!pair_less(s->d[p], s->idx[p], dd, id))
                break;
            s->d[i] = s->d[p];
            s->idx[i] = s->idx[p];
            i = p;
        }
        s->d[i] = dd;
        s->idx[i] = id;
        return 1;
    }
    if (!pair_less(dd, id, s->d[0], s->idx[0]))
        return 0;
    s->d[0] = dd;
    s->idx[0] = id;
    sift_down(s->d, s->idx, s->n, 0);
    return 1;
}

static void heap_sort_ascending(float *d, asp_index *idx, size_t n)
{
    for (size_t m = n; m > 1; m--) {
        float td = d[0];
        asp_index ti = idx[0];
        d[0] = d[m - 1];
        idx[0] = idx[m - 1];
        d[m - 1] = td;
        idx[m - 1] = ti;
        sift_down(d, idx, m - 1, 0);
    }
}

/*
 * The same expression, in the same order, is used for point distances and for
 * cell lower bounds: float rounding is monotonic, so a bound computed from
 * per-axis offsets that are <= the point's offsets never exceeds the point's
 * computed distance, and pruning stays exact.
 */
static inline float dist2_3(float dx, float dy, float dz)
{
    return dx * dx + dy * dy + dz * dz;
}

/*
 * k-NN candidates are 64-bit keys (distance bits << 32 | index): squared
 * distances are >= +0, whose IEEE bits order like the values, so one integer
 * compare orders by (distance, index) exactly as a brute-force sort does.
 * Accepted candidates are appended to a buffer of 2k keys; a full buffer is cut
 * back to its k smallest by selection. This costs O(1) per candidate instead of
 * a heap update, which dominated the profile for k = 64.
 */
typedef struct kn_search {
    const float *xyz;
    const asp_index *perm;
    const asp__kd_node *nodes;
    float q[3];
    uint32_t exclude;
    size_t k;       /* wanted */
    size_t n;       /* keys in buf */
    uint64_t bound; /* keys >= bound cannot be among the k nearest */
    uint64_t *buf;  /* 2k keys */
} kn_search;

static inline uint64_t make_key(float d, asp_index i)
{
    return asp__kd_key(d, i);
}

static inline void swap_keys(uint64_t *a, uint64_t *b)
{
    uint64_t t = *a;
    *a = *b;
    *b = t;
}

/*
 * Quickselect with a branch-free Lomuto partition: afterwards v[nth] is in
 * sorted position with smaller keys before it (keys are distinct). Candidate
 * distances are random, so a branchy partition mispredicts half its compares.
 */
void asp__kd_select_keys(uint64_t *v, size_t n, size_t nth)
{
    size_t lo = 0, hi = n; /* [lo, hi) */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2, last = hi - 1;
        /* median of three moved to the end as the pivot */
        uint64_t a = v[lo], b = v[mid], c = v[last];
        size_t m = (a < b) == (b < c) ? mid : (b < a) == (a < c) ? lo : last;
        swap_keys(&v[m], &v[last]);
        uint64_t piv = v[last];
        size_t store = lo;
        for (size_t i = lo; i < last; i++) {
            uint64_t x = v[i];
            v[i] = v[store];
            v[store] = x;
            store += x < piv;
        }
        swap_keys(&v[store], &v[last]);
        if (nth < store)
            hi = store;
        else if (nth > store)
            lo = store + 1;
        else
            return;
    }
}

static void insertion_sort_keys(uint64_t *v, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        uint64_t x = v[i];
        size_t j = i;
        for (; j > 0 && v[j - 1] > x; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
}

enum { KD_BUCKET_MAX = 512 };

/*
 * Distribution pass for 17..KD_BUCKET_MAX keys: the distance bits (the high
 * word, which orders like the distance) are spread linearly over 2n buckets,
 * leaving an almost sorted array that one insertion pass finishes. Results
 * do not depend on how well the buckets spread, only the time does.
 */
static void bucket_sort_keys(uint64_t *v, size_t n)
{
    uint64_t tmp[KD_BUCKET_MAX];
    uint16_t bucket[KD_BUCKET_MAX];
    uint16_t start[2 * KD_BUCKET_MAX + 1];
    uint32_t lo = UINT32_MAX, hi = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t b = (uint32_t)(v[i] >> 32);
        lo = b < lo ? b : lo;
        hi = b > hi ? b : hi;
    }
    /* 2n buckets: bucket = (bits - lo) * (nb - 1) / (hi - lo), by a 32.32 fixed-point multiplier */
    const size_t nb = 2 * n;
    uint64_t mul = hi > lo ? ((uint64_t)(nb - 1) << 32) / (hi - lo) : 0;
    memset(start, 0, (nb + 1) * sizeof start[0]);
    for (size_t i = 0; i < n; i++) {
        uint64_t b = ((uint64_t)((uint32_t)(v[i] >> 32) - lo) * mul) >> 32;
        bucket[i] = (uint16_t)(b < nb ? b : nb - 1);
        start[bucket[i] + 1]++;
    }
    for (size_t b = 0; b < nb; b++)
        start[b + 1] = (uint16_t)(start[b + 1] + start[b]);
    for (size_t i = 0; i < n; i++)
        tmp[start[bucket[i]]++] = v[i];
    memcpy(v, tmp, n * sizeof v[0]);
    insertion_sort_keys(v, n);
}

void asp__kd_sort_keys(uint64_t *v, size_t n)
{
    if (n > 16 && n <= KD_BUCKET_MAX) {
        bucket_sort_keys(v, n);
        return;
    }
    while (n > KD_BUCKET_MAX) {
        size_t m = n / 2;
        asp__kd_select_keys(v, n, m);
        /* recurse into the smaller half, loop on the larger */
        asp__kd_sort_keys(v, m);
        v += m + 1;
        n -= m + 1;
    }
    if (n > 16)
        bucket_sort_keys(v, n);
    else
        insertion_sort_keys(v, n);
}

/* Restores the buffer invariants after appends: a bound once k keys exist, at most 2k keys kept. */
static void kn_settle(kn_search *s)
{
    if (s->n >= s->k && s->bound == UINT64_MAX) {
        /* first k candidates: their maximum is a valid bound without selection */
        uint64_t mx = 0;
        for (size_t i = 0; i < s->n; i++)
            mx = s->buf[i] > mx ? s->buf[i] : mx;
        s->bound = mx + 1;
    }
    if (s->n >= 2 * s->k) {
        asp__kd_select_keys(s->buf, s->n, s->k - 1);
        s->n = s->k;
        s->bound = s->buf[s->k - 1];
    }
}

static void kn_scan_leaf(kn_search *s, const asp__kd_node *nd)
{
    const float *q = s->q;
    if (nd->axis == ASP__KD_FLAT) {
        const float *p = s->xyz + 3 * (size_t)nd->begin;
        float dd = dist2_3(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
        for (uint32_t j = nd->begin; j < nd->end; j++) {
            if (j == s->exclude)
                continue;
            /* equal distances, ascending indices: the first rejection ends the leaf */
            uint64_t key = make_key(dd, s->perm[j]);
            if (key >= s->bound)
                break;
            s->buf[s->n++] = key;
            kn_settle(s);
        }
        return;
    }
    /*
     * Branch-free append (the buffer has ASP__KD_LEAF_MAX keys of slack):
     * whether a candidate beats the bound is a coin flip the predictor loses.
     */
    uint64_t *out = s->buf + s->n;
    const uint64_t bound = s->bound;
    size_t m = 0;
    for (uint32_t j = nd->begin; j < nd->end; j++) {
        const float *p = s->xyz + 3 * (size_t)j;
        uint64_t key = make_key(dist2_3(p[0] - q[0], p[1] - q[1], p[2] - q[2]), s->perm[j]);
        key = j == s->exclude ? UINT64_MAX : key;
        out[m] = key;
        m += key < bound;
    }
    s->n += m;
    kn_settle(s);
}

static void kn_rec(kn_search *s, uint32_t node, float off[3])
{
    const asp__kd_node *nd = &s->nodes[node];
    if (nd->axis >= ASP__KD_LEAF) {
        kn_scan_leaf(s, nd);
        return;
    }
    int a = (int)nd->axis;
    float diff = s->q[a] - nd->split;
    uint32_t near_child = diff <= 0.0f ? node + 1 : nd->right;
    uint32_t far_child = diff <= 0.0f ? nd->right : node + 1;
    kn_rec(s, near_child, off);

    float saved = off[a];
    off[a] = diff;
    /* A tie on the bound can still hide an equally distant point with a smaller index. */
    if (make_key(dist2_3(off[0], off[1], off[2]), s->nodes[far_child].min_index) < s->bound)
        kn_rec(s, far_child, off);
    off[a] = saved;
}

size_t asp__kdtree_search(const asp_kdtree *tree, const float q[3], size_t k, uint32_t exclude, float bound2,
                          uint64_t *scratch, float *d, asp_index *idx)
{
    if (k == 0)
        return 0;
    uint64_t bound = bound2 < INFINITY ? make_key(bound2, UINT32_MAX) : UINT64_MAX;
    kn_search s = {tree->xyz, tree->perm, tree->nodes, {q[0], q[1], q[2]}, exclude, k, 0, bound, scratch};
    float off[3] = {0.0f, 0.0f, 0.0f};
    kn_rec(&s, 0, off);
    size_t m = s.n;
    if (m > k) {
        asp__kd_select_keys(scratch, m, k - 1);
        m = k;
    }
    asp__kd_sort_keys(scratch, m);
    for (size_t j = 0; j < m; j++) {
        idx[j] = (asp_index)(scratch[j] & 0xffffffffu);
        if (d) {
            uint32_t bits = (uint32_t)(scratch[j] >> 32);
            memcpy(&d[j], &bits, sizeof bits);
        }
    }
    return m;
}

enum { KD_STACK_K = 128 };

size_t asp_kdtree_knn(const asp_kdtree *tree, const float q[3], size_t k, asp_index *idx, float *dist2)
{
    if (!tree || !q || !idx || k == 0)
        return 0;
    if (k > tree->count)
        k = tree->count;
    uint64_t stack_buf[ASP__KD_SCRATCH(KD_STACK_K)];
    uint64_t *buf = k <= KD_STACK_K ? stack_buf : asp_alloc(&tree->ctx, ASP__KD_SCRATCH(k) * sizeof(uint64_t));
    if (!buf)
        return 0;
    size_t n = asp__kdtree_search(tree, q, k, UINT32_MAX, INFINITY, buf, dist2, idx);
    if (buf != stack_buf)
        asp_free(&tree->ctx, buf);
    return n;
}

static void radius_rec(kd_search *s, uint32_t node, float off[3])
{
    const asp__kd_node *nd = &s->nodes[node];
    const float *q = s->q;
    if (nd->axis == ASP__KD_FLAT) {
        const float *p = s->xyz + 3 * (size_t)nd->begin;
        float dd = dist2_3(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
        if (!(dd <= s->r2))
            return;
        s->total += nd->end - nd->begin;
        for (uint32_t j = nd->begin; j < nd->end && s->k > 0; j++)
            if (!heap_offer(s, dd, s->perm[j]))
                break;
        return;
    }
    if (nd->axis == ASP__KD_LEAF) {
        for (uint32_t j = nd->begin; j < nd->end; j++) {
            const float *p = s->xyz + 3 * (size_t)j;
            float dd = dist2_3(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            if (dd <= s->r2) {
                s->total++;
                if (s->k > 0)
                    heap_offer(s, dd, s->perm[j]);
            }
        }
        return;
    }
    int a = (int)nd->axis;
    float diff = q[a] - nd->split;
    uint32_t near_child = diff <= 0.0f ? node + 1 : nd->right;
    uint32_t far_child = diff <= 0.0f ? nd->right : node + 1;
    radius_rec(s, near_child, off);
    float saved = off[a];
    off[a] = diff;
    if (dist2_3(off[0], off[1], off[2]) <= s->r2)
        radius_rec(s, far_child, off);
    off[a] = saved;
}

size_t asp_kdtree_radius(const asp_kdtree *tree, const float q[3], float radius, asp_index *idx, float *dist2,
                         size_t capacity)
{
    if (!tree || !q || !(radius >= 0.0f) || (capacity > 0 && !idx))
        return 0;
    float stack_d[KD_STACK_K];
    float *d = dist2 ? dist2 : capacity <= KD_STACK_K ? stack_d : asp_alloc(&tree->ctx, capacity * sizeof(float));
    if (!d)
        return 0;
    kd_search s = {tree->xyz, tree->perm, tree->nodes, {q[0], q[1], q[2]}, UINT32_MAX, capacity, 0, d, idx,
                   radius * radius, 0};
    float off[3] = {0.0f, 0.0f, 0.0f};
    radius_rec(&s, 0, off);
    heap_sort_ascending(d, idx, s.n);
    if (d != dist2 && d != stack_d)
        asp_free(&tree->ctx, d);
    return s.total;
}
