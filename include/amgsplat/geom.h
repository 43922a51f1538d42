/*
 * Geometry kernels on point sets: spatial index and nearest-neighbour
 * queries, normal and radius estimation, mesh-to-point sampling and the
 * synthetic test models. Kernels take arrays (positions, count, stride) and
 * write to caller-allocated destinations (STYLE.md section 3).
 */
#ifndef AMGSPLAT_GEOM_H
#define AMGSPLAT_GEOM_H

#include "cloud.h"
#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- nearest neighbours (src/geom/kdtree.c, src/geom/knn.c) ---- */

/** Static kd-tree over a borrowed-then-copied position array. Opaque. */
typedef struct asp_kdtree asp_kdtree;

/**
 * Builds a kd-tree over count points read from positions with stride_bytes
 * between consecutive points (12 for packed xyz; a multiple of 4). The
 * positions are copied into leaf order (about 45 bytes per point in all), so
 * the array may be freed afterwards. Median splits on the widest axis, leaves
 * of at most 12 points; all-equal subsets become one leaf, so duplicates cost
 * no extra depth (depth <= log2(count) + 1). O(n log n); from 65536 points on,
 * the subtrees below the top four levels are built in parallel with
 * asp_context_threads(ctx) threads, and the tree does not depend on the
 * thread count. On success *out owns the tree (free with asp_kdtree_destroy).
 * Returns 0; ASP_ENOMEM;
 * ASP_EINVAL for count == 0, count >= 2^32 - 1, a bad stride, NULL arrays or
 * a non-finite coordinate ("point 17: coordinate y is not finite").
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
 * smaller index, so the result equals a brute-force sort of the float squared
 * distances (dx*dx + dy*dy + dz*dz). Returns the number written (0 for k == 0
 * or NULL arguments). k > 128 allocates a scratch buffer through the context
 * the tree was built with; if that fails the function returns 0. Thread-safe
 * on a shared tree.
 */
size_t asp_kdtree_knn(const asp_kdtree *tree, const float q[3], size_t k,
                      asp_index *idx, float *dist2);

/**
 * All points within distance radius of q (inclusive: squared distance <=
 * radius * radius in float), nearest first with ties by smaller index. Writes
 * the nearest min(total, capacity) results to idx and dist2 (may be NULL) and
 * returns the total number found (which may exceed capacity: call again with a
 * larger buffer; capacity 0 just counts). A negative or NaN radius gives 0.
 * With dist2 NULL and capacity > 128 a scratch buffer is allocated through the
 * tree's context; if that fails the function returns 0. Thread-safe.
 */
size_t asp_kdtree_radius(const asp_kdtree *tree, const float q[3], float radius,
                         asp_index *idx, float *dist2, size_t capacity);

/**
 * k nearest neighbours of every indexed point, in parallel. Row i of idx
 * (count * k entries, count = asp_kdtree_count) lists point i's neighbours,
 * nearest first, excluding i itself, ties by smaller index; dist2 (may be
 * NULL) likewise. 1 <= k < count. Queries run in the tree's leaf order for
 * locality; each writes only its own row, so results are bit-identical for
 * any thread count. Reports progress as stage "knn". Returns 0; ASP_EINVAL;
 * ASP_ENOMEM (per-thread scratch of about 64 min(count, 128 k + 4096) bytes);
 * ASP_ECANCELED, with the rows partially written.
 */
int asp_knn_all(const asp_kdtree *tree, size_t k, asp_index *idx, float *dist2,
                const asp_context *ctx, asp_error *err);

/* ---- critical neighbourhood size (src/geom/critical_k.c) ---- */

/** Options of asp_critical_neighbourhood; the zero value means defaults. */
typedef struct asp_critical_desc {
    size_t k_min; /* smallest neighbourhood tried, the point included (0 = 8; at least 4) */
    size_t k_max; /* largest (0 = 96; at most 1024, below the point count) */
    size_t step;  /* sizes tried: k_min, k_min + step, ... (0 = 4) */
    double jump;  /* smallest increase of sigma over one step that counts as a jump (0 = 0.02) */
} asp_critical_desc;

/**
 * Critical neighbourhood size per point (thesis 2.3, Pauly et al. 2003): the
 * surface variation sigma_k = l0 / (l0 + l1 + l2) of the k nearest points
 * (the point included) for k = k_min, k_min + step, ..., k_max; k_out[i] is
 * the size tried just before sigma's largest increase over one step, when
 * that increase is at least desc->jump, else k_max (no jump: the
 * neighbourhood stays on one part of the surface). k_out holds count values.
 * Deterministic for any thread count. Returns 0; ASP_EINVAL (bad options,
 * NULL arrays, non-finite coordinates); ASP_EDEGENERATE (count <= k_max);
 * ASP_ENOMEM (count x k_max neighbour indices); ASP_ECANCELED.
 */
int asp_critical_neighbourhood(const float *positions, size_t count, const asp_critical_desc *desc,
                               const asp_context *ctx, uint32_t *k_out, asp_error *err);

/* ---- PCA (src/geom/eigen3.c) ---- */

/**
 * Eigen-decomposition of the symmetric 3x3 matrix m = {xx, xy, xz, yy, yz, zz}
 * by cyclic Jacobi rotations in double precision. Writes evals in descending
 * order and evecs as a row-major 3x3 matrix whose column k (evecs[3*r + k],
 * r = 0..2) is the unit eigenvector of evals[k]; the columns are orthonormal
 * and right-handed (column 2 = column 0 x column 1), and columns 0 and 1 have
 * their largest-magnitude component positive. Accurate to a few ulps of the
 * largest |entry| for any scale, including repeated eigenvalues, rank-1 and
 * zero matrices (zero gives evals 0 and the identity). A non-finite entry gives
 * NaN evals and the identity. Never fails; thread-safe; no allocation.
 */
void asp_eigen_sym3(const double m[6], double evals[3], double evecs[9]);

/* ---- covariance (src/geom/covariance.c) ---- */

/** Optional parameters of asp_covariance_sym3; the zero value means none. */
typedef struct asp_covariance_desc {
    /*
     * also_count more point indices summed after idx's: e.g. the point itself
     * after its kNN row, which does not list it.
     */
    const asp_index *also;
    size_t also_count;
    /*
     * Per-point weights >= 0, indexed like positions (weights[p] for point p,
     * so per-point attributes serve directly); NULL: every point weighs 1.
     */
    const float *weights;
    /*
     * Sum the outer products about this point instead of the (weighted) mean:
     * the second moment about a given centre (a splat's bounding ellipse).
     * centroid still reports the mean.
     */
    const double *center;
} asp_covariance_desc;

/**
 * The one covariance sum of the library (PCA normals, the AMG classifier's
 * first moment M1, point ellipses): centroid = weighted mean and cov = the 6
 * unique entries {xx, xy, xz, yy, yz, zz} of sum_j w_j (p_j - m)(p_j - m)^T /
 * sum_j w_j, ready for asp_eigen_sym3, with m the centroid (or desc->center).
 * Accumulated in double in two passes, the mean first, so points far from the
 * origin relative to their spread keep their digits (E[x^2] - E[x]^2 would
 * cancel them). The points are positions[idx[j]] for j < n (the first n
 * points when idx is NULL), then positions[desc->also[j]]; consecutive points
 * are stride_bytes apart (12 for packed xyz). desc may be NULL. No points or a
 * total weight of 0 give zeros. Never fails; thread-safe; no allocation.
 */
void asp_covariance_sym3(const float *positions, size_t stride_bytes, const asp_index *idx, size_t n,
                         const asp_covariance_desc *desc, double centroid[3], double cov[6]);

/**
 * asp_covariance_sym3 of double positions (stride_bytes apart, 24 for packed
 * xyz), for points already held as double offsets (asp_amg_classify_points).
 * The same sum, the same order, the same contract.
 */
void asp_covariance_sym3d(const double *positions, size_t stride_bytes, const asp_index *idx, size_t n,
                          const asp_covariance_desc *desc, double centroid[3], double cov[6]);

/* ---- normals (src/geom/normals.c) ---- */

/** How estimated normals are given a consistent sign. */
typedef enum asp_orient {
    /*
     * Hoppe et al. 1992: propagate along a minimum spanning tree of the
     * symmetric k-NN graph with weights 1 - |n_i . n_j|. Each connected
     * component starts from its highest point (largest z, then smallest index),
     * whose normal is turned to +z (or away from the component centroid when
     * it is nearly horizontal). Closed surfaces come out pointing outwards.
     */
    ASP_ORIENT_MST = 0,
    ASP_ORIENT_VIEWPOINT = 1, /* every normal faces desc.viewpoint: n . (viewpoint - p) >= 0 */
    ASP_ORIENT_EXISTING = 2,  /* keep the sign of the normals passed in the output array */
    ASP_ORIENT_NONE = 3       /* raw PCA sign (deterministic, not consistent) */
} asp_orient;

/** Normal estimation options; the zero value means k = 16 and MST orientation. */
typedef struct asp_normals_desc {
    size_t k;           /* neighbours besides the point itself; 0 = ASP_NORMALS_DEFAULT_K */
    asp_orient orient;
    float viewpoint[3]; /* for ASP_ORIENT_VIEWPOINT, in the positions' coordinates */
} asp_normals_desc;

#define ASP_NORMALS_DEFAULT_K 16

/**
 * Estimates unit normals by PCA of each point together with its k nearest
 * neighbours (the eigenvector of the smallest covariance eigenvalue, thesis
 * 3.3.1), then orients them per desc->orient. desc may be NULL (defaults); k is
 * clamped to count - 1. positions: count points, stride_bytes apart. normals:
 * 3 * count floats, written packed; for ASP_ORIENT_EXISTING it holds the
 * reference normals on entry. Points whose neighbours are all equal get
 * (0, 0, 1) before orientation. Returns 0; ASP_EINVAL (NULL arrays, stride,
 * non-finite coordinate, named by point); ASP_EDEGENERATE (fewer than 3
 * points, or all points equal); ASP_ENOMEM; ASP_ECANCELED. On failure normals
 * is unchanged. Uses asp_context_threads(ctx) threads for the kNN and PCA;
 * the MST pass is serial. Results do not depend on the thread count.
 */
int asp_estimate_normals(const float *positions, size_t count, size_t stride_bytes, const asp_normals_desc *desc,
                         float *restrict normals, const asp_context *ctx, asp_error *err);

/**
 * As asp_estimate_normals, on a precomputed k-NN graph: knn has count rows of
 * k indices (as written by asp_knn_all, the point itself excluded); desc->k is
 * ignored. Returns ASP_EINVAL when an index is >= count (naming row and
 * column), otherwise as asp_estimate_normals.
 */
int asp_normals_from_knn(const float *positions, size_t count, size_t stride_bytes, const asp_index *knn,
                         size_t k, const asp_normals_desc *desc, float *restrict normals, const asp_context *ctx,
                         asp_error *err);

/* ---- splat radii (src/geom/radii.c) ---- */

/**
 * Radius options; the zero value means r_i = 1.0 * (distance from point i to
 * its 16th nearest neighbour). With that choice, discs of radius r_i cover
 * every point of a uniformly (even randomly) sampled surface: the largest
 * empty circle among n random samples has area about ln(n) / density, while
 * the 16th-neighbour disc has area about 16 / density, and a hole only makes
 * the radii of the samples around it larger (tests/unit/test_geom_radii.c).
 */
typedef struct asp_radii_desc {
    size_t k;     /* which neighbour's distance; 0 = ASP_RADII_DEFAULT_K */
    float factor; /* multiplier; 0 = 1 */
} asp_radii_desc;

#define ASP_RADII_DEFAULT_K 16

/**
 * Writes count radii (see asp_radii_desc) to radii. desc may be NULL; k is
 * clamped to count - 1. Returns 0, ASP_EINVAL (NULL arrays, bad stride,
 * non-finite coordinate, negative or non-finite factor), ASP_EDEGENERATE
 * (fewer than 2 points, or all points equal), ASP_ENOMEM, ASP_ECANCELED. On
 * failure radii is unchanged. A point with k duplicates of itself gets the
 * smallest positive radius of the set, so no splat has zero size. Parallel,
 * deterministic.
 */
int asp_estimate_radii(const float *positions, size_t count, size_t stride_bytes, const asp_radii_desc *desc,
                       float *restrict radii, const asp_context *ctx, asp_error *err);

/**
 * As asp_estimate_radii from precomputed squared neighbour distances: dist2
 * has count rows of k_stride values, ascending (as written by asp_knn_all).
 * desc->k must be <= k_stride (0 means min(16, k_stride)). Returns 0,
 * ASP_EINVAL, ASP_EDEGENERATE (every distance is zero).
 */
int asp_radii_from_knn(const float *dist2, size_t count, size_t k_stride, const asp_radii_desc *desc,
                       float *restrict radii, const asp_context *ctx, asp_error *err);

/* ---- cloud-level convenience (src/geom/normals.c) ---- */

/** What asp_cloud_estimate computes; zero fields take the defaults above. */
typedef struct asp_estimate_desc {
    size_t k;            /* neighbours for normals; 0 = ASP_NORMALS_DEFAULT_K */
    int normals;         /* estimate normals (when missing, or always with force) */
    int radii;           /* estimate radii (when missing, or always with force) */
    int force;           /* recompute attributes the cloud already has */
    asp_orient orient;   /* ASP_ORIENT_EXISTING with force keeps the old normals' signs */
    float viewpoint[3];  /* for ASP_ORIENT_VIEWPOINT, relative to cloud->origin */
    size_t radius_k;     /* 0 = ASP_RADII_DEFAULT_K */
    float radius_factor; /* 0 = 1 */
} asp_estimate_desc;

/**
 * Adds normals and/or radii to cloud, sharing one k-NN pass, using cloud->ctx
 * for threads and memory. Attributes already present are left alone unless
 * desc->force. Returns 0 or the errors of asp_estimate_normals /
 * asp_estimate_radii; on failure the cloud is unchanged. Not thread-safe on
 * the same cloud.
 */
int asp_cloud_estimate(asp_cloud *cloud, const asp_estimate_desc *desc, asp_error *err);

/* ---- sharp creases (src/geom/crease.c) ---- */

/** Crease detection options; the zero value means 60 degrees, k = 16, 2 supporting neighbours. */
typedef struct asp_crease_desc {
    float angle_deg;    /* normals further apart than this mark a crease; 0 = 60; else in (0, 90) */
    size_t k;           /* neighbours examined per point; 0 = 16; clamped to count - 1 */
    size_t min_support; /* neighbours needed on each side; 0 = 2 */
} asp_crease_desc;

/**
 * Clip planes for the splats of points near sharp creases (Pauly et al. 2003,
 * Zwicker et al. 2004, Botsch et al. 2005: a splat that straddles a crease is
 * cut along the other surface's plane, so it neither covers the neighbouring
 * face nor sticks out of a silhouette). Per point, its k nearest neighbours
 * are split by unoriented normal angle into the point's own side S (within
 * angle_deg of n_i, the point included) and the others O; O is clustered
 * into at most two surfaces by normal, and each surface with at least
 * min_support members gives the plane through its mean position with its mean
 * normal, oriented so that S's mean position is on the kept side.
 *
 * dst: 8 * cloud->count floats, two planes (nx, ny, nz, d) per point in the
 * cloud's local frame (positions as stored, relative to cloud->origin). A
 * fragment x of point i's disc or splat is KEPT where n . x + d >= 0 for both
 * planes; a plane of four zeros means no clip (points away from creases get
 * two of them, as do thin two-sided sheets: opposite normals count as equal).
 * *clipped (may be NULL) = the number of points with at least one plane.
 * Normals need not be unit length; points with a zero normal get no planes.
 * Returns 0; ASP_EINVAL (NULL cloud or dst, cloud without normals: "crease
 * clipping needs normals", bad desc values); ASP_EDEGENERATE (fewer than 2
 * points); ASP_EFORMAT (a non-finite position or normal, naming the point);
 * ASP_ENOMEM; ASP_ECANCELED (progress callback of ctx, stage "knn").
 * All points equal gives no planes. On failure dst and *clipped are
 * unchanged. Parallel over points with asp_context_threads(ctx) threads
 * (ctx may be NULL); bit-identical for any thread count. Thread-safe.
 */
int asp_crease_clip_planes(const asp_cloud *cloud, const asp_crease_desc *desc, const asp_context *ctx, float *dst,
                           size_t *clipped, asp_error *err);

/* ---- mesh simplification (src/geom/mesh_simplify.c, meshoptimizer) ---- */

/** Bits of asp_mesh_simplify_desc.flags; 0 is the safe default. */
enum asp_mesh_simplify_flags {
    /*
     * When the topology-preserving simplifier stops more than 5% above
     * target_triangles, run meshopt_simplifySloppy (vertex clustering, ignores
     * topology and UV seams: textures can tear) and keep its result when it is
     * closer to the target. stats->sloppy says whether it was used.
     */
    ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK = 1 << 0,
    /* Recompute area-weighted normals on the simplified mesh instead of keeping the original vertices' normals. */
    ASP_MESH_SIMPLIFY_RECOMPUTE_NORMALS = 1 << 1,
    /* Never move vertices on an open border (for meshes that are parts of a larger one). */
    ASP_MESH_SIMPLIFY_LOCK_BORDER = 1 << 2
};

/** Options for asp_mesh_simplify; the zero value keeps the mesh as it is (no target). */
typedef struct asp_mesh_simplify_desc {
    size_t target_triangles; /* triangles to reach; 0: only target_error limits the simplification */
    /*
     * Largest error allowed, relative to the mesh extent as meshoptimizer
     * measures it (0.01 = 1% of the largest bounding-box side); 0: no limit,
     * so target_triangles alone decides.
     */
    double target_error;
    unsigned flags; /* asp_mesh_simplify_flags */
} asp_mesh_simplify_desc;

/** What asp_mesh_simplify did. */
typedef struct asp_mesh_simplify_stats {
    size_t input_triangles, input_vertices;
    size_t output_triangles, output_vertices;
    size_t target_triangles; /* the target asked (desc->target_triangles) */
    double error;            /* meshoptimizer's result error, relative to the extent (largest over materials) */
    double error_world;      /* the same in world units (error times meshopt_simplifyScale) */
    int short_of_target;     /* 1: output_triangles exceeds the target by more than 5% */
    int sloppy;              /* 1: the sloppy fallback produced the result */
    size_t material_groups;  /* materials simplified separately (their borders locked) */
} asp_mesh_simplify_stats;

/**
 * Simplifies mesh into a new mesh (*out; free with asp_mesh_destroy) of about
 * desc->target_triangles triangles with meshoptimizer's edge-collapse
 * simplifier (meshopt_simplify: quadric error metric, Garland and Heckbert
 * 1997). Vertices never move (a collapse keeps one end), so every output
 * vertex is an input vertex with its position, UV, colour and normal
 * (recomputed with ASP_MESH_SIMPLIFY_RECOMPUTE_NORMALS). Materials and their
 * textures are copied; material ids follow the triangles.
 *
 * UV seams: asp_mesh splits vertices at seams (same position, different UV).
 * meshoptimizer 0.18 finds such vertices by their bit-identical positions and
 * collapses seam vertices only along the seam and both sides together, so
 * seams neither tear nor drift; the cost is that seam-heavy meshes may stop
 * above the target (stats->short_of_target). With more than one material in
 * use, each material's triangles are simplified on their own with their
 * borders locked (meshopt_SimplifyLockBorder), so material boundaries stay
 * closed; the target is shared in proportion to triangle counts.
 *
 * target_triangles at or above the input count gives a copy (compacted to the
 * vertices in use). desc may be NULL (copy); stats may be NULL.
 * Errors: ASP_EFORMAT (a triangle index out of range), ASP_ENOMEM. On failure
 * *out is unchanged. meshoptimizer allocates its scratch with operator new,
 * outside the context's allocator (NEEDSWORK: its global meshopt_setAllocator
 * is not thread safe, so it is left alone). Reentrant; mesh is only read.
 */
int asp_mesh_simplify(const asp_mesh *mesh, const asp_mesh_simplify_desc *desc, const asp_context *ctx,
                      asp_mesh **out, asp_mesh_simplify_stats *stats, asp_error *err);

/* ---- colour by a per-point scalar (issue 29: a surveyor sees the scan's own fields) ---- */

/** The colour of class code cls in the ASPRS palette asp_cloud_color_by uses for "classification" (RGB). */
void asp_scalar_color_class(unsigned cls, uint8_t rgb[3]);
/** The colour at t in [0, 1] (clamped; NaN gives t = 0) of the viridis ramp (RGB). */
void asp_scalar_color_ramp(double t, uint8_t rgb[3]);

/**
 * Overwrites cloud's colours (adding them when absent; alpha 255) from a per-point
 * scalar named by what:
 *   "elevation"      the world coordinate along up (ASP_UP_Z: z, -z: -z, ...), viridis from min to max;
 *   "classification" the property of that name, ASPRS palette (asp_scalar_color_class);
 *   "intensity"      the property of that name, grey between its 1st and 99th percentile;
 *   "prop:NAME" or any other NAME: the property NAME, viridis from its min to its max.
 * A constant field takes the ramp's start. Returns 0; ASP_EINVAL for an unknown name,
 * the message listing the cloud's properties; ASP_ENOMEM.
 */
int asp_cloud_color_by(asp_cloud *cloud, const char *what, asp_up_axis up, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
