/*
 * Private to src/amg/distributed*.c: the decomposition on MPI ranks (issue 19).
 * Every rank owns a contiguous range of global point ids in space-filling-curve
 * order, and every distributed matrix a contiguous range of rows; rows are kept
 * as asp_amg_csr with local rows and GLOBAL column ids. Only built with hypre.
 */
#ifndef ASP_AMG_DISTRIBUTED_H
#define ASP_AMG_DISTRIBUTED_H

#include <mpi.h>

#include "amg/internal.h"
#include "amgsplat/amg_distributed.h"

typedef struct asp__dist {
    MPI_Comm comm;
    int rank, size;
    asp_context ctx;
} asp__dist;

/* The points of one rank: owned ones first (ids starts[rank] ..), then the halo copies (ghost_gid). */
typedef struct asp__dist_points {
    size_t n_global, n_own, n_ghost;
    size_t *starts;       /* size + 1: rank q owns global ids starts[q] .. starts[q+1]-1 */
    double origin[3];     /* as the serial PLY reader: wide (double) axes keep float offsets from it */
    float *pos;           /* 3 * (n_own + n_ghost) */
    float *normals;       /* 3 * n_own, or NULL: the input had none */
    uint8_t *colors;      /* 4 * n_own, or NULL */
    float *radii;         /* n_own, or NULL */
    uint32_t *labels;     /* n_own, or NULL */
    float *uvs;           /* 2 * n_own, or NULL */
    int has_alpha;
    asp_index *ghost_gid; /* n_ghost */
    float lo[3], hi[3];   /* bounding box of every rank's positions */
} asp__dist_points;

/*
 * Makes every rank return the same code: when any rank failed, the lowest
 * failing rank's code and message go to all. Collective.
 */
int asp__dist_agree(const asp__dist *d, int rc, asp_error *err);
/* The sum of every rank's v. Collective. */
unsigned long long asp__dist_sum(const asp__dist *d, unsigned long long v);
/* Owner rank of global id g in a partition starts[0..size]. */
int asp__dist_owner(const size_t *starts, int size, size_t g);
/* starts[0..size] of a partition where this rank holds local items. Collective. */
int asp__dist_partition(const asp__dist *d, size_t local, size_t *starts);

/*
 * out[i] = the elem-byte item of global id gids[i] from its owner's array
 * local (indexed by id - starts[owner]). Collective; m may be 0.
 */
int asp__dist_fetch(const asp__dist *d, const size_t *starts, const void *local, size_t elem, const asp_index *gids,
                    size_t m, void *out, asp_error *err);
/* local[g - starts[rank]] += vals[i] for every (gids[i], vals[i]) sent by any rank. Collective. */
int asp__dist_scatter_add(const asp__dist *d, const size_t *starts, const asp_index *gids, const double *vals,
                          size_t m, double *local, asp_error *err);
/* The rows gids[0..m-1] of a row-distributed matrix (rows partitioned by starts), in that order. Collective. */
int asp__dist_fetch_rows(const asp__dist *d, const size_t *starts, const asp_amg_csr *rows, const asp_index *gids,
                         size_t m, asp_amg_csr **out, asp_error *err);

/* ---- distributed_points.c ---- */

/* Reads this rank's share of a binary PLY, sorts all points along a Morton curve across ranks. Collective. */
int asp__dist_read_sorted(const asp__dist *d, const char *path, asp__dist_points *pts, asp_error *err);
/* Appends copies of the other ranks' points within radius[i] of an owned point i. Collective. */
int asp__dist_halo(const asp__dist *d, asp__dist_points *pts, const float *radius, asp_error *err);
void asp__dist_points_release(const asp_context *ctx, asp__dist_points *pts);

/* The global id of a rank's local point (owned, then halo). */
static inline asp_index asp__dist_gid(const asp__dist *d, const asp__dist_points *pts, size_t local)
{
    return (asp_index)(local < pts->n_own ? pts->starts[d->rank] + local : pts->ghost_gid[local - pts->n_own]);
}

/* ---- distributed_rows.c ---- */

/*
 * The global stiffness rows of the owned points (*ga, and *gf with the crease test's C = 1 matrix)
 * from the local assembly over points and halo (*take_a, *take_f: destroyed once their entries are
 * exchanged); *positive counts the positive off-diagonal couplings over every rank. Collective.
 */
int asp__dist_global_rows(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **take_a,
                          asp_amg_csr **take_f, asp_amg_stiffness form, asp_amg_csr **ga, asp_amg_csr **gf,
                          size_t *positive, asp_error *err);

/* ---- distributed_repair.c: one level's rows (P: local rows, global columns) ---- */

/* Rows of P left empty where a (the level's rows, or those hypre gave back) has couplings: their mean. */
int asp__dist_fill_empty_rows(const asp__dist *d, asp_amg_csr **pp, const asp_amg_csr *a, const size_t *st,
                              asp_error *err);
/* P's rows as a partition of unity; the coarse partition cst becomes nst with each rank's orphans. */
int asp__dist_repair(const asp__dist *d, asp_amg_csr **pp, const size_t *cst, size_t *nst, size_t *repaired,
                     asp_error *err);
/* The coarse matrix in the repaired numbering nst, with an empty row per orphan. */
int asp__dist_renumber_coarse(const asp__dist *d, asp_amg_csr **pac, const size_t *cst, const size_t *nst,
                              asp_error *err);
/* dst[J] = sum_r P_rJ src[r] for this rank's coarse unknowns J (partition nst). Collective. */
int asp__dist_carry(const asp__dist *d, const asp_amg_csr *p, const size_t *nst, const double *src, double *dst,
                    asp_error *err);
/* The next level's matrix from the coarse one ac (and fc, the crease test's, or NULL). Collective. */
int asp__dist_filter(const asp__dist *d, const asp_amg_csr *ac, const asp_amg_csr *fc, const size_t *nst,
                     const double *mass, const double *cm, double cut, double ratio, double small, asp_amg_csr **out,
                     size_t *offdiag, asp_error *err);

/* ---- distributed_hierarchy.c ---- */

typedef struct asp__dist_hier {
    size_t nlevels;
    size_t sizes[ASP_AMG_DIST_MAX_LEVELS];
    size_t *starts[ASP_AMG_DIST_MAX_LEVELS]; /* partition of each level's unknowns */
    asp_amg_csr *p[ASP_AMG_DIST_MAX_LEVELS]; /* [1..]: local rows (level l-1), global columns (level l) */
    size_t repaired;
} asp__dist_hier;

/*
 * The hierarchy on the global rows *a0 (taken: destroyed once hypre holds its copy of the first
 * level) and f0 (the crease test's, or NULL), cls the owned points' classifier. Collective.
 */
int asp__dist_build_hierarchy(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **a0,
                              const asp_amg_csr *f0, const float *cls, const asp_amg_desc *desc, asp__dist_hier *h,
                              asp_error *err);
void asp__dist_hier_release(const asp_context *ctx, asp__dist_hier *h);

/* ---- distributed_basis.c ---- */

/* Each level's basis and its figures into info->level[] (tau: the domain threshold). Collective. */
int asp__dist_basis_figures(const asp__dist *d, const asp__dist_points *pts, const asp__dist_hier *h,
                            const asp_amg_desc *desc, double tau, asp_amg_dist_info *info, asp_error *err);

/* ---- hypre_distributed.c (hypre and MPI start-up) ---- */

int asp__dist_start(asp__dist *d, asp_error *err);
/*
 * One BoomerAMG setup level on the row-distributed a (rows starts): P (local
 * rows, global coarse columns), the coarse matrix's local rows and the coarse
 * partition cstarts[0..size]. *p = NULL on every rank when hypre did not coarsen.
 */
int asp__dist_coarsen(const asp__dist *d, const asp_amg_csr *a, const size_t *starts, const asp_amg_desc *desc,
                      asp_amg_csr **p, asp_amg_csr **ac, size_t *cstarts, asp_error *err);
/*
 * The same, taking *a: it is destroyed (*a = NULL) once hypre holds its copy, before the setup
 * (issue 19: A^0 is the largest array of the AMG stage's peak). *a_rows gets the rows of a that
 * P left empty (the others empty), read back from hypre's copy, for the rows filled at borders.
 */
int asp__dist_coarsen_take(const asp__dist *d, asp_amg_csr **a, const size_t *starts, const asp_amg_desc *desc,
                           asp_amg_csr **p, asp_amg_csr **ac, size_t *cstarts, asp_amg_csr **a_rows, asp_error *err);
/* Galerkin product P^T F P of row-distributed P (rows starts, columns cstarts) and F: local rows of cstarts. */
int asp__dist_galerkin(const asp__dist *d, const asp_amg_csr *p, const size_t *starts, const size_t *cstarts,
                       const asp_amg_csr *f, asp_amg_csr **out, asp_error *err);

/* ---- distributed_write.c ---- */

/* The decomposition of one rank as the writer needs it. */
typedef struct asp__dist_result {
    const asp__dist_points *pts;
    const float *tangent, *classifier; /* n_own each (tangent 3 *) */
    const asp_amg_desc *desc;
    size_t nlevels;
    const size_t *level_size;          /* global sizes */
    asp_amg_csr *const *prolong;       /* [1..nlevels-1]: local rows, global columns */
    asp_frame frame;                   /* asp_cloud_frame over every rank's points */
} asp__dist_result;

/* Writes the .amg (version 3) by rank 0 streaming every rank's part in order. Collective. */
int asp__dist_write_amg(const asp__dist *d, const asp__dist_result *res, const char *path, asp_error *err);

#endif
