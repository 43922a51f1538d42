/*
 * Geometry kernels on point sets: spatial index and nearest-neighbour
 * queries, normal and radius estimation, mesh-to-point sampling and the
 * synthetic test models. Kernels take arrays (positions, count, stride) and
 * write to caller-allocated destinations (STYLE.md section 3).
 */
#ifndef AMGSPLAT_GEOM_H
#define AMGSPLAT_GEOM_H

#include "cloud.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- nearest neighbours (src/geom/kdtree.c, src/geom/knn.c) ---- */

/** Static kd-tree over a borrowed-then-copied position array. Opaque. */
typedef struct asp_kdtree asp_kdtree;

/**
 * Builds a kd-tree over count points read from positions with stride_bytes
 * between consecutive points (12 for packed xyz). The positions are copied, so
 * the array may be freed afterwards. Returns 0, ASP_ENOMEM, or ASP_EINVAL for
 * count == 0 or count >= 2^32.
 */
int asp_kdtree_create(const float *positions, size_t count, size_t stride_bytes,
                      const asp_context *ctx, asp_kdtree **out, asp_error *err);
/** Frees the tree; NULL is accepted. */
void asp_kdtree_destroy(asp_kdtree *tree);
/** Number of points indexed. */
size_t asp_kdtree_count(const asp_kdtree *tree);

/**
 * Exact k nearest neighbours of query q: writes min(k, count) indices to idx and
 * squared distances to dist2 (may be NULL), nearest first, ties broken by
 * smaller index. Returns the number written. Thread-safe on a shared tree.
 */
size_t asp_kdtree_knn(const asp_kdtree *tree, const float q[3], size_t k,
                      asp_index *idx, float *dist2);

/**
 * All points within distance radius of q (inclusive), nearest first. Writes at
 * most capacity results and returns the total number found (which may exceed
 * capacity: call again with a larger buffer). Thread-safe.
 */
size_t asp_kdtree_radius(const asp_kdtree *tree, const float q[3], float radius,
                         asp_index *idx, float *dist2, size_t capacity);

/**
 * k nearest neighbours of every indexed point, in parallel. Row i of idx
 * (count * k entries, count = asp_kdtree_count) lists point i's neighbours,
 * nearest first, excluding i itself; dist2 (may be NULL) likewise. k must be
 * < count. Deterministic for any thread count. Returns 0, ASP_EINVAL,
 * ASP_ECANCELED.
 */
int asp_knn_all(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2,
                const asp_context *ctx, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
