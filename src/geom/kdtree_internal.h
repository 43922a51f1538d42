/*
 * Private layout of the kd-tree shared by kdtree.c (build, single queries)
 * and knn.c (all-points queries). Not part of the public API.
 */
#ifndef ASP_GEOM_KDTREE_INTERNAL_H
#define ASP_GEOM_KDTREE_INTERNAL_H

#include <string.h>

#include "amgsplat/geom.h"

/*
 * A node splits at the median along its widest axis; leaves hold at most
 * ASP__KD_LEAF_MAX points unless all their points are equal, in which case
 * they are "flat" leaves of any size, sorted by original index.
 */
enum { ASP__KD_LEAF_MAX = 12, ASP__KD_LEAF = 3, ASP__KD_FLAT = 4 };

/* Candidate keys a k-NN search needs as scratch. */
#define ASP__KD_SCRATCH(k) (2 * (size_t)(k) + ASP__KD_LEAF_MAX)

typedef struct asp__kd_node {
    float split;        /* inner: left child coords <= split <= right child coords */
    uint32_t right;     /* inner: index of the right child (left child is this + 1) */
    uint32_t begin;     /* slots [begin, end) of the subtree in leaf order */
    uint32_t end;
    uint32_t min_index; /* smallest original index in the subtree, for exact tie pruning */
    uint32_t axis;      /* 0..2 for inner nodes, ASP__KD_LEAF or ASP__KD_FLAT */
} asp__kd_node;

struct asp_kdtree {
    asp_context ctx;
    size_t count;
    float *xyz;          /* 3 * count, in leaf order (slot order) */
    asp_index *perm;     /* slot -> original index */
    asp__kd_node *nodes; /* preorder, root at 0 */
    float *box;          /* 6 per node: tight bounding box lo[3], hi[3] of the subtree's points */
    size_t node_count;
};

/* Candidate key: squared distance bits << 32 | original index (see kdtree.c). */
static inline uint64_t asp__kd_key(float d, asp_index i)
{
    uint32_t bits;
    memcpy(&bits, &d, sizeof bits);
    return (uint64_t)bits << 32 | i;
}

/* Partial sort of distinct keys: afterwards v[nth] is in sorted position, smaller keys before it. */
void asp__kd_select_keys(uint64_t *v, size_t n, size_t nth);
/* Ascending sort of distinct keys. */
void asp__kd_sort_keys(uint64_t *v, size_t n);

/*
 * Exact k nearest neighbours of q, skipping slot exclude (UINT32_MAX for none).
 * bound2 is INFINITY or a squared distance known to hold at least k candidates
 * (it only speeds up pruning). scratch holds ASP__KD_SCRATCH(k) keys; on return scratch[0]
 * ... scratch[m-1] are the sorted result keys (distance bits << 32 | index).
 * Writes m = min(k, available) results to idx (original indices) and d
 * (squared distances; may be NULL), ascending by (distance, index).
 */
size_t asp__kdtree_search(const asp_kdtree *tree, const float q[3], size_t k, uint32_t exclude, float bound2,
                          uint64_t *scratch, float *d, asp_index *idx);

/*
 * Shared by the estimators: checks positions, stride and finiteness ("cannot
 * estimate WHAT: point 3: coordinate y is not finite"); returns 0 or ASP_EINVAL.
 */
int asp__check_positions(const float *positions, size_t count, size_t stride_bytes, const char *what,
                         asp_error *err);
/* ASP_EDEGENERATE when all count >= 1 points are equal, else 0. */
int asp__check_spread(const float *positions, size_t count, size_t stride_bytes, const char *what, asp_error *err);
/*
 * Builds a kd-tree and the k-NN graph of all points (1 <= k < count): *idx gets
 * count * k indices and, when dist2 is not NULL, *dist2 the squared distances,
 * both from asp_alloc(ctx). On failure nothing is allocated.
 */
int asp__knn_graph(const float *positions, size_t count, size_t stride_bytes, size_t k, asp_index **idx,
                   float **dist2, const asp_context *ctx, asp_error *err);

/*
 * Tuning of asp_knn_all, exposed so tests and the benchmark can force every
 * code path; the zero value means the defaults. Results never depend on it.
 * group_max: queries answered together share one candidate list (subtrees of
 * at most this many points). cand_max: candidate points a group may gather
 * before it falls back to one tree search per query (1 forces that). reach:
 * the gather radius in units of the last group's largest k-th distance (tiny
 * values make most queries fall back). guess: the first scan radius, in units
 * of the last k-th squared distance. tree_only: one tree search per query.
 */
typedef struct asp__knn_tuning {
    size_t group_max;
    size_t cand_max;
    double reach;
    float guess;
    int tree_only;
} asp__knn_tuning;

int asp__knn_all_tuned(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2, const asp__knn_tuning *tuning,
                       const asp_context *ctx, asp_error *err);

#endif
