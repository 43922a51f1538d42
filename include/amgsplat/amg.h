/*
 * Multiscale surface decomposition by algebraic multigrid (journal 2.1-2.3,
 * thesis 2.3-2.5): a moment-based classifier per point, local triangle fans
 * in the tangent plane, a classifier-weighted stiffness matrix, its BoomerAMG
 * hierarchy, the basis functions Psi^l of every level and their domains.
 */
#ifndef AMGSPLAT_AMG_H
#define AMGSPLAT_AMG_H

#include "cloud.h"
#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- sparse matrices ---- */

/**
 * Compressed sparse rows. Row r holds columns col[row_ptr[r] .. row_ptr[r+1]-1]
 * in increasing order with values val[...]. Fields are public for reading;
 * create and free only through the library (asp_amg_csr_destroy).
 */
typedef struct asp_amg_csr {
    size_t rows, cols;
    size_t *row_ptr;  /* rows + 1 */
    asp_index *col;   /* row_ptr[rows] */
    double *val;      /* row_ptr[rows] */
    asp_context ctx;  /* allocator that owns the arrays */
} asp_amg_csr;

/**
 * Allocates an empty rows x cols matrix with room for nnz entries (row_ptr
 * zeroed, col/val uninitialised). Returns 0, ASP_ENOMEM, or ASP_EINVAL when
 * rows or cols exceed 2^32-1. The caller frees it with asp_amg_csr_destroy.
 */
int asp_amg_csr_create(size_t rows, size_t cols, size_t nnz, const asp_context *ctx, asp_amg_csr **out,
                       asp_error *err);
/** Frees the matrix; NULL is accepted. */
void asp_amg_csr_destroy(asp_amg_csr *m);

/** Results of asp_amg_csr_check_stiffness. */
typedef struct asp_amg_matrix_check {
    double max_asymmetry;     /* max |A_ij - A_ji| */
    double max_row_sum;       /* max |sum_j A_ij| */
    double max_offdiag;       /* largest off-diagonal value (must be <= 0) */
    double min_diag;          /* smallest diagonal value (must be >= 0) */
    size_t empty_rows;        /* rows with no off-diagonal entry (isolated points) */
} asp_amg_matrix_check;

/**
 * Measures the stiffness-matrix invariants of a square matrix (journal eq. 6-7):
 * symmetry, zero row sums, non-positive off-diagonals. Always succeeds for a
 * valid matrix. Thread-safe.
 */
void asp_amg_csr_check_stiffness(const asp_amg_csr *a, asp_amg_matrix_check *out);

/* ---- kernels (usable and testable alone) ---- */

/**
 * Which local classifier weights the stiffness matrix (--classifier). The
 * default is the thesis's surface variation: on the octahedron the journal's
 * moment classifier with alpha = 0.01, beta = 100 is only about 5x lower on
 * the creases than on the faces (surface variation: about 30x), too little for
 * AMG to keep the faces apart; with beta = 1e4 it works as well
 * (docs/cli/decompose.md).
 */
typedef enum asp_amg_classifier_kind {
    ASP_AMG_CLASSIFIER_VARIATION = 0, /* thesis eq. 2.2: sigma = l2 / (l0 + l1 + l2), weighted as C = G(sigma) */
    ASP_AMG_CLASSIFIER_MOMENT = 1     /* journal eq. 3: C = G(|M0 - x| l2 / (eps l0)), in (0, 1/alpha] */
} asp_amg_classifier_kind;

/**
 * Classifier of one neighbourhood (journal 2.1). pts holds m points, xyz
 * packed, as double offsets from x (so x itself is the origin; it may be among
 * them). epsilon > 0 is the neighbourhood radius of eq. 3; alpha, beta the
 * constants of G (0 = 0.01 and 100). Writes the classifier value to *c and the
 * unit tangent-plane normal (eigenvector of the smallest eigenvalue of M1) to
 * normal. Returns 0, or ASP_EDEGENERATE when m < 3 or every point coincides
 * (then *c = 1/alpha and normal = +z, so callers may go on). Thread-safe.
 */
int asp_amg_classify_points(const double *pts, size_t m, double epsilon, asp_amg_classifier_kind kind,
                            double alpha, double beta, double *c, double normal[3]);

/**
 * Triangle fan of the origin p among m neighbours projected to its tangent
 * plane (journal 2.2, Fig. 3b): the triangles (p, a, b) of the 2D Delaunay
 * triangulation of {p} and the neighbours that have p as a corner, found by
 * clipping p's Voronoi cell with the neighbours' bisectors. xy holds m points
 * (x, y packed) relative to p, in any order. Points at p itself (closer than
 * 1e-9 times the farthest one) and repeated positions after their first
 * occurrence in order of distance (ties: lower index) are ignored; among
 * co-circular points, bisectors that only touch a cell corner make no edge.
 * Writes triangle t as tri[2t], tri[2t+1] (indices into xy, counter-clockwise
 * around p), consecutive triangles sharing an edge; returns the number of
 * triangles, at most m (tri holds 2m entries). A closed fan (p inside the
 * hull) has as many triangles as neighbours. scratch must hold
 * asp_amg_fan_scratch_size(m) bytes. Thread-safe.
 */
size_t asp_amg_fan(const double *xy, size_t m, asp_index *tri, void *scratch);
/** Bytes of scratch asp_amg_fan needs for m neighbours. */
size_t asp_amg_fan_scratch_size(size_t m);

/* ---- the decomposition ---- */

/** Coarsening algorithms of BoomerAMG (exposed by experiment, journal 2.3). */
typedef enum asp_amg_coarsen {
    ASP_AMG_COARSEN_DEFAULT = 0, /* = RS */
    ASP_AMG_COARSEN_RS,          /* classical Ruge-Stueben (hypre 3) */
    ASP_AMG_COARSEN_FALGOUT,     /* hypre 6 */
    ASP_AMG_COARSEN_CLJP,        /* hypre 0 */
    ASP_AMG_COARSEN_PMIS,        /* hypre 8 */
    ASP_AMG_COARSEN_HMIS         /* hypre 10 */
} asp_amg_coarsen;

/** Interpolation operators of BoomerAMG. */
typedef enum asp_amg_interp {
    ASP_AMG_INTERP_DEFAULT = 0,  /* = CLASSICAL */
    ASP_AMG_INTERP_CLASSICAL,    /* modified classical (hypre 0) */
    ASP_AMG_INTERP_DIRECT,       /* direct (hypre 3) */
    ASP_AMG_INTERP_STANDARD,     /* standard (hypre 8) */
    ASP_AMG_INTERP_EXTENDED_I    /* extended+i (hypre 6) */
} asp_amg_interp;

/**
 * Positive off-diagonal entries of A = (A~ + A~^T) / 2 (journal eq. 5-7, thesis 2.4). They come from
 * obtuse angles of the lifted 3D fans (a fan Delaunay in the tangent plane need not be Delaunay on the
 * surface). The seeds keep them; amgsplat clamps them to 0 by default because classical AMG
 * interpolation is built for M-matrices: a positive coupling can give negative interpolation weights,
 * which the hierarchy drops before renormalising the row (asp_amg_info.repaired_rows), so P stays a
 * partition of unity with values in [0, 1] either way (docs/seeds.md has the measurement).
 */
typedef enum asp_amg_stiffness {
    ASP_AMG_STIFFNESS_CLAMPED = 0,  /* positive A_ij set to 0 (diagonal = -sum of the rest), counted in info */
    ASP_AMG_STIFFNESS_UNCLAMPED = 1 /* the seeds' matrix as assembled; still counted in info */
} asp_amg_stiffness;

/**
 * Options; the zero value means the documented defaults, so
 * `&(asp_amg_desc){ .k_min = 40 }` works.
 */
typedef struct asp_amg_desc {
    size_t k_min;            /* minimum neighbourhood size (0 = 24) */
    size_t k_max;            /* cap on the neighbourhood with its epsilon-ball extension (0 = 2 * k_min) */
    double epsilon;          /* ball radius of journal 2.1 (0 = median distance to the k_min-th neighbour) */
    size_t fan_k;            /* nearest neighbours projected for the fan (0 = 16, at most k_max) */
    asp_amg_classifier_kind classifier; /* 0 = VARIATION */
    double alpha, beta;      /* G(s) = 1 / (alpha + beta s^2) (0 = 0.01, 100) */
    asp_amg_coarsen coarsen;
    asp_amg_interp interp;
    double strong_threshold; /* BoomerAMG strength threshold (0 = 0.9) */
    double trunc_factor;     /* interpolation truncation (0 = none); rows renormalised */
    size_t max_levels;       /* 0 = 25 */
    size_t max_coarse;       /* stop coarsening at this many unknowns (0 = 4) */
    double weak_coupling;    /* cut coarse couplings weaker than this times the median fine coupling (0 = off; see hierarchy.c) */
    double drop_tol;         /* basis entries below this are dropped and rows renormalised (0 = 1e-4, < 0 keeps all) */
    double crease_cut;       /* cut coarse couplings whose interface classifier is below this times the smaller
                                interior classifier of the two unknowns (0 = 0.25, < 0 = off; hierarchy.c) */
    asp_amg_stiffness stiffness; /* 0 = CLAMPED */
    int keep_matrix;         /* 1: asp_amg_matrix returns A^0; 0 (default): A^0 is freed as soon as hypre has its
                                copy, about 90 bytes per point less at the peak (issue 19) */
} asp_amg_desc;

/** Opaque decomposition: points, classifier and the AMG hierarchy. */
typedef struct asp_amg asp_amg;

/** Counts and timings of one run of asp_amg_decompose (seconds, wall). */
typedef struct asp_amg_info {
    double epsilon;             /* neighbourhood radius used */
    size_t k_min, k_max, fan_k;
    double mean_neighbourhood;  /* mean |N(x)| */
    double mean_fan;            /* mean fan size */
    size_t matrix_nnz;          /* non-zeros of A^0 */
    size_t positive_offdiag;    /* positive A_ij (obtuse 3D fans): clamped to 0 unless desc.stiffness is UNCLAMPED */
    size_t isolated_points;     /* points without any fan neighbour */
    size_t repaired_rows;       /* P rows hypre left empty, filled to keep the partition of unity */
    double t_neighbours, t_classifier, t_fans, t_assembly, t_amg, t_basis;
} asp_amg_info;

/**
 * Decomposes cloud (count >= 3, finite positions) with the options in desc
 * (NULL = defaults). The result keeps a copy of the positions. Returns 0,
 * ASP_EINVAL (bad option), ASP_EDEGENERATE (fewer than 3 points, all points
 * equal or colinear: no surface), ASP_ENOMEM, ASP_ESOLVER (hypre failed),
 * ASP_EUNSUPPORTED (built without hypre), ASP_ECANCELED. The first call
 * initialises MPI (single process) if nobody did; see asp_amg_shutdown.
 * Not thread-safe against other hypre users in the process (hypre keeps global state).
 */
int asp_amg_decompose(const asp_cloud *cloud, const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out,
                      asp_error *err);

/**
 * As asp_amg_decompose, taking ownership of *cloud: the result keeps that
 * cloud (with normals added when it had none, and whatever else it holds)
 * instead of a copy of its points, which saves 28 bytes a point or more at
 * the peak (issue 19). *cloud is set to NULL in every case; on failure the
 * cloud has been destroyed. The cloud's context is the result's allocator
 * for the points.
 */
int asp_amg_decompose_take(asp_cloud **cloud, const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out,
                           asp_error *err);

/**
 * Decomposes a triangle mesh through its own connectivity (journal eq. 4):
 * as asp_amg_decompose on the mesh's vertices (the classifier still comes
 * from each vertex's neighbourhood, journal 2.1), but the stiffness matrix is
 * assembled on the mesh triangles incident to each vertex instead of the
 * local Delaunay fans of journal 2.2 (desc->fan_k is unused). triangles holds
 * 3 * triangle_count vertex indices, counter-clockwise; degenerate triangles
 * are skipped. Errors as asp_amg_decompose, and ASP_EINVAL (no triangles, an
 * index not below vertices->count).
 */
int asp_amg_decompose_mesh(const asp_cloud *vertices, const uint32_t *triangles, size_t triangle_count,
                           const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out, asp_error *err);

/** Frees a decomposition; NULL is accepted. */
void asp_amg_destroy(asp_amg *amg);

/** Finalises hypre and MPI if asp_amg_decompose initialised them; call once at exit. Idempotent. */
void asp_amg_shutdown(void);

/**
 * The input point set, kept whole so that domain primitives can be built from
 * a decomposition or an .amg file alone (thesis 2.6): positions with origin,
 * normals, and the colours, radii, uvs and labels the input had (NULL when it
 * had none). normals is never NULL: the input's normals when it had them
 * (asp_amg_has_input_normals), else the unoriented tangent-plane normals.
 * Extra properties, faces and comments are not kept. Valid until asp_amg_destroy.
 */
const asp_cloud *asp_amg_cloud(const asp_amg *amg);

/**
 * Frame (asp_cloud_frame) of the point set the decomposition was made from,
 * recorded in the .amg file, so render, view and eval frame an .amg exactly as
 * its source points. Valid until asp_amg_destroy.
 */
const asp_frame *asp_amg_frame(const asp_amg *amg);
/**
 * Tangent-plane normal per point (3 * count floats, unit, unoriented): the
 * eigenvector of the smallest eigenvalue of the neighbourhood's M1 (journal
 * 2.1), used for the fans. Valid until asp_amg_destroy.
 */
const float *asp_amg_tangent_normals(const asp_amg *amg);
/** 1 if asp_amg_cloud(amg)->normals are the input's normals, 0 if they are the tangent-plane normals. */
int asp_amg_has_input_normals(const asp_amg *amg);
/** Classifier value per point (asp_amg_cloud(amg)->count); valid until asp_amg_destroy. */
const float *asp_amg_classifier(const asp_amg *amg);
/** Run statistics; the timings are zero for a loaded file. */
const asp_amg_info *asp_amg_get_info(const asp_amg *amg);
/** Fine stiffness matrix A^0 when desc.keep_matrix was set, else NULL (and for a loaded file). Valid until asp_amg_destroy. */
const asp_amg_csr *asp_amg_matrix(const asp_amg *amg);

/** Number of levels L+1: level 0 is the points, level L (= count-1) the coarsest. */
size_t asp_amg_level_count(const asp_amg *amg);
/** Unknowns (basis functions) on level l (level 0: the points). */
size_t asp_amg_level_size(const asp_amg *amg, size_t level);
/**
 * Prolongation P^l (l >= 1), a level_size(l-1) x level_size(l) matrix with
 * rows summing to 1 and entries in [0,1]; NULL for l == 0 or out of range.
 */
const asp_amg_csr *asp_amg_prolongation(const asp_amg *amg, size_t level);

/**
 * Parses a level name: "L" (coarsest), "L-3" (three finer), or an absolute
 * index "3". Returns 0 and sets *level, or ASP_EINVAL naming the text and the
 * valid range.
 */
int asp_amg_level_parse(const asp_amg *amg, const char *text, size_t *level, asp_error *err);

/**
 * Basis Psi^l = P^1 P^2 ... P^l at the points (journal 2.3), a count x
 * level_size(l) matrix: entries below desc.drop_tol were dropped and each row
 * renormalised, so rows sum to 1 (to rounding) and values lie in [0,1].
 * The caller frees *out with asp_amg_csr_destroy. Returns 0, ASP_EINVAL
 * (level out of range), ASP_ENOMEM. Thread-safe on a shared amg.
 */
int asp_amg_basis(const asp_amg *amg, size_t level, const asp_context *ctx, asp_amg_csr **out, asp_error *err);

/**
 * Thresholded domains D_i = {x : Psi_i(x) > tau} (journal eq. 8; tau = 0.05 in
 * the journal, the thesis's K = 0.01): the transpose of psi restricted to
 * entries > tau, one row per basis function listing its points and Psi values.
 * Returns 0, ASP_EINVAL (tau outside [0,1)), ASP_ENOMEM.
 */
int asp_amg_domains(const asp_amg_csr *psi, double tau, const asp_context *ctx, asp_amg_csr **out, asp_error *err);

/**
 * Strict domains (thesis eq. 2.5): label[x] = the basis function with the
 * largest Psi at x (ties: the smaller index). label holds psi->rows entries.
 */
void asp_amg_strict_domains(const asp_amg_csr *psi, asp_index *label);

/**
 * The strict domains (thesis eq. 2.5) as domain rows, in the layout of
 * asp_amg_domains: one row per basis function listing, in increasing order,
 * the points whose largest Psi is that function's (ties: the smaller index),
 * each with value 1 (hard membership: strict domains do not overlap, thesis
 * 2.5, so they are drawn without blending). Every point is in exactly one
 * row. The caller frees *out. Returns 0 or ASP_ENOMEM.
 */
int asp_amg_strict_domain_rows(const asp_amg_csr *psi, const asp_context *ctx, asp_amg_csr **out, asp_error *err);

/** Per-level figures for decompose --stats. */
typedef struct asp_amg_level_stats {
    size_t level;
    size_t unknowns;
    size_t domains;             /* non-empty thresholded domains */
    double mean_domain_size;    /* points */
    size_t max_domain_size;
    double mean_domains_per_point;
    double max_pou_error;       /* max |sum_i Psi_i(x) - 1| */
    double seconds;             /* time to get this level's basis and domains */
} asp_amg_level_stats;

/**
 * Fills stats[0 .. level_count-1] for every level with threshold tau, getting
 * each basis from the previous one (cost of one asp_amg_basis of the coarsest
 * level). Returns 0, ASP_EINVAL (tau outside [0,1)), ASP_ENOMEM.
 */
int asp_amg_level_stats_all(const asp_amg *amg, double tau, const asp_context *ctx, asp_amg_level_stats *stats,
                            asp_error *err);

/* ---- file ---- */

/**
 * Writes the decomposition to path (atomically) in the versioned binary .amg
 * format, version 3 (docs/cli/decompose.md): the source frame (asp_amg_frame),
 * the whole point set (positions, origin, normals, colours, radii, uvs, labels
 * as present), tangent normals, classifier and the prolongations, with a CRC-32. Returns 0, ASP_EIO,
 * ASP_EUNSUPPORTED (big-endian host).
 */
int asp_amg_save(const asp_amg *amg, const char *path, asp_error *err);

/**
 * Reads a .amg file (version 3; version 2, without the recorded frame, gets it
 * computed from the points as decompose does; version 1 files, which lack the
 * point attributes, are refused with a message to decompose again): reads the whole
 * file and parses it with asp_amg_load_memory. Returns 0, ASP_EINVAL (path or
 * out NULL), ASP_EIO (cannot open/read), ASP_EFORMAT (as
 * asp_amg_load_memory), ASP_EUNSUPPORTED (big-endian host), ASP_ENOMEM. The
 * caller frees *out with asp_amg_destroy; on failure *out is unchanged.
 * Thread-safe (no shared state).
 */
int asp_amg_load(const char *path, const asp_context *ctx, asp_amg **out, asp_error *err);

/**
 * Parses the bytes of a .amg file (size bytes at data, borrowed for the call;
 * data may be NULL when size is 0) into a new decomposition (*out, freed by the
 * caller with asp_amg_destroy). name is the file name used in messages (NULL =
 * "<memory>"). Every count and offset is checked against the bytes left before
 * it sizes an allocation, so a forged count costs no more memory than a few
 * times size. Returns 0, ASP_EINVAL (out NULL), ASP_EUNSUPPORTED (big-endian
 * host), ASP_ENOMEM, or ASP_EFORMAT for anything damaged (bad magic or
 * version, truncated or padded, checksum mismatch, a count the file cannot
 * hold, non-finite values, level sizes not decreasing, a prolongation row that
 * is empty, has columns out of order or out of range, or is not a partition of
 * unity), with a message naming the file, the byte offset or level and row,
 * the field and what was expected. On failure *out is unchanged and nothing
 * stays allocated. Thread-safe (no shared state).
 */
int asp_amg_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_amg **out,
                        asp_error *err);

/* ---- seeing it ---- */

typedef enum asp_amg_color_mode {
    ASP_AMG_COLOR_CLASSIFIER = 0, /* blue (creases, low C) to red (flat, high C), log scale (journal Fig. 1b) */
    ASP_AMG_COLOR_DOMAINS = 1,    /* a colour per basis function of the level, mixed by Psi (journal Fig. 5c-d) */
    ASP_AMG_COLOR_STRICT = 2      /* a colour per strict domain (thesis Fig. 2.7) */
} asp_amg_color_mode;

/**
 * Colours every point: writes 4 * count bytes RGBA (A = 255) to rgba. level is
 * used by the domain modes only. Returns 0, ASP_EINVAL, ASP_ENOMEM.
 */
int asp_amg_colorize(const asp_amg *amg, asp_amg_color_mode mode, size_t level, const asp_context *ctx,
                     uint8_t *rgba, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
