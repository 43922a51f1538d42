/*
 * Private to src/amg: the decomposition object and the stages of the
 * pipeline (journal 2.1-2.3), each in its own file. Not public API.
 */
#ifndef ASP_AMG_INTERNAL_H
#define ASP_AMG_INTERNAL_H

#include <stdint.h>

#include "amgsplat/amg.h"

struct asp_amg {
    asp_context ctx;
    asp_cloud *cloud;      /* the input points: positions, origin, normals (input's, else tangent), colors, radii, uvs, labels */
    float *tangent;        /* 3 * count tangent-plane normals (journal 2.1, Fig. 3a) */
    int input_normals;     /* cloud->normals came from the input (else they alias the tangent normals' values) */
    float *classifier;     /* count */
    asp_amg_csr *matrix;   /* A^0; NULL after load */
    size_t nlevels;        /* L + 1 */
    size_t *level_size;    /* nlevels */
    asp_amg_csr **prolong; /* nlevels entries; [0] is NULL */
    asp_amg_desc desc;     /* resolved options */
    asp_amg_info info;
    asp_frame frame;       /* the source points' frame (asp_cloud_frame) */
};

/*
 * Neighbourhoods N(x) of journal 2.1: row i (asp__amg_nbhd_row) holds nn[i]
 * indices, nearest first, and at least the fan_k nearest. Rows start at
 * first[i] (compact, issue 19), or at i * kmax when first is NULL.
 */
typedef struct asp__amg_nbhd {
    size_t n, kmax;
    asp_index *nbr; /* first[n] (or n * kmax) */
    uint16_t *nn;   /* n */
    size_t *first;  /* n + 1, or NULL */
} asp__amg_nbhd;

static inline const asp_index *asp__amg_nbhd_row(const asp__amg_nbhd *nb, size_t i)
{
    return nb->nbr + (nb->first ? nb->first[i] : i * nb->kmax);
}

/*
 * Local triangle fans (journal 2.2): point i's triangles are (i, r[2t],
 * r[2t+1]), t < ntri[i], r = asp__amg_fan_row. Rows start at pair first[i]
 * (compact, issue 19), or at pair i * stride when first is NULL.
 */
typedef struct asp__amg_fans {
    size_t n, stride;
    asp_index *tri;  /* 2 * first[n] (or 2 * n * stride) */
    uint16_t *ntri;  /* n */
    size_t *first;   /* n + 1, or NULL */
} asp__amg_fans;

static inline const asp_index *asp__amg_fan_row(const asp__amg_fans *f, size_t i)
{
    return f->tri + 2 * (f->first ? f->first[i] : i * f->stride);
}

int asp__amg_resolve_desc(const asp_amg_desc *in, size_t count, asp_amg_desc *out, asp_error *err);

int asp__amg_neighbourhoods(const float *pos, size_t n, asp_amg_desc *desc, const asp_context *ctx,
                            asp__amg_nbhd *out, double *mean_size, asp_error *err);
void asp__amg_nbhd_release(const asp_context *ctx, asp__amg_nbhd *nb);
/*
 * Moves the stride-layout rows (what asp__amg_neighbourhoods gives) into a
 * block of their lengths, max(nn[i], fan_k) (first[] offsets): about half the
 * bytes on a scan (issue 19). Left as is when out of memory. After it nn[i]
 * may not grow (the distributed run re-derives nn on the stride layout).
 */
void asp__amg_nbhd_compact(const asp_context *ctx, asp__amg_nbhd *nb, size_t fan_k);

int asp__amg_classify(const float *pos, const asp__amg_nbhd *nb, const asp_amg_desc *desc, const asp_context *ctx,
                      float *classifier, float *normals, asp_error *err);

int asp__amg_build_fans(const float *pos, const float *normals, const asp__amg_nbhd *nb, size_t fan_k,
                        const asp_context *ctx, asp__amg_fans *out, asp_error *err);
void asp__amg_fans_release(const asp_context *ctx, asp__amg_fans *f);
/* Moves stride-layout rows together (first[] offsets) and shrinks tri; left as is when out of memory. */
void asp__amg_fans_compact(const asp_context *ctx, asp__amg_fans *f);
/* Fans of the mesh triangles incident to each of n vertices (mesh_fans.c, journal eq. 4). */
int asp__amg_mesh_fans(size_t n, const uint32_t *triangles, size_t ntris, const asp_context *ctx,
                       asp__amg_fans *out, asp_error *err);

/* A (journal eq. 5-7) and, when flat is not NULL, the same fans' matrix with C = 1 on A's pattern. */
int asp__amg_assemble(const float *pos, const float *classifier, const asp__amg_fans *fans, asp_amg_stiffness form,
                      const asp_context *ctx, asp_amg_csr **out, asp_amg_csr **flat, size_t *positive,
                      asp_error *err);

/* Starts MPI (a singleton when no launcher did) and hypre once per process; asp_amg_shutdown ends what it started. */
int asp__amg_hypre_start(asp_error *err);
/*
 * Starts MPI on a thread of its own when this process will need it and nobody started it, so the
 * start overlaps the stages before the AMG (hypre_bridge.c); asp__amg_hypre_start waits for it.
 */
void asp__amg_hypre_prestart(void);
/* One BoomerAMG setup level on a: copies P (a->rows x nc) and A^1 = P^T a P; *p = NULL when hypre did not coarsen. */
int asp__amg_hypre_coarsen(const asp_amg_csr *a, const asp_amg_desc *desc, const asp_context *ctx,
                           asp_amg_csr **p, asp_amg_csr **ac, asp_error *err);
/* The same, taking *a: it is destroyed (*a = NULL) as soon as hypre holds its own copy, before the setup. */
int asp__amg_hypre_coarsen_take(asp_amg_csr **a, const asp_amg_desc *desc, const asp_context *ctx,
                                asp_amg_csr **p, asp_amg_csr **ac, asp_error *err);

/* The hierarchy level by level (hierarchy.c): p[1..nlevels-1], sizes[0..nlevels-1]; arrays sized max_levels. */
/*
 * f0 (may be NULL) is the stiffness matrix of the same fans with C = 1 and cls the classifier: with
 * desc->crease_cut > 0 they drive the crease test that keeps coarse unknowns from merging across creases.
 */
int asp__amg_build_hierarchy(const asp_amg_csr *a0, const asp_amg_csr *f0, const float *cls,
                             const asp_amg_desc *desc, const asp_context *ctx, size_t *nlevels, asp_amg_csr ***p,
                             size_t **sizes, size_t *repaired, asp_error *err);
/*
 * The same, taking *a0 and *f0 (either may point to NULL): each is destroyed
 * and set to NULL once the hierarchy no longer needs it (A^0 inside the first
 * hypre call, F^0 after the first Galerkin product), on failure too (issue 19).
 */
int asp__amg_build_hierarchy_take(asp_amg_csr **a0, asp_amg_csr **f0, const float *cls, const asp_amg_desc *desc,
                                  const asp_context *ctx, size_t *nlevels, asp_amg_csr ***p, size_t **sizes,
                                  size_t *repaired, asp_error *err);

/*
 * ---- level_rows.c: the row kernels of a coarse level, for the serial and the distributed hierarchy ----
 * Rows are a matrix's local rows whose first global row is row0 (0 in one process); columns global.
 */

/*
 * P^l's rows as a partition of unity (journal 2.3): each row of p keeps its positive
 * weights over their sum; a row without any (sum <= 1e-12: a point hypre left without interpolation)
 * gets weight 1 on a new orphan unknown, numbered from first_orphan in row order. Columns go through
 * map (NULL: unchanged; it must be increasing, so rows stay sorted). q has p->rows rows or more and
 * room for p's entries plus one per orphan; rows from p->rows on are the caller's. Counts the rows it
 * changed into *repaired; returns the orphans.
 */
size_t asp__amg_pou_rows(const asp_amg_csr *p, asp_amg_csr *q, asp_index first_orphan,
                         asp_index (*map)(asp_index c, const void *arg), const void *arg, size_t *repaired);
/* The rows of p that asp__amg_pou_rows turns into orphans. */
size_t asp__amg_empty_rows(const asp_amg_csr *p);

/* Adds the log2 magnitudes of the off-diagonal entries of a (rows from row0) to hist. */
void asp__amg_coupling_hist(const asp_amg_csr *a, size_t row0, uint64_t hist[256]);
/* The median magnitude of such a histogram (the middle of its bin), 0 when empty: the scale of a coupling. */
double asp__amg_hist_median(const uint64_t hist[256]);
/* Column of the most negative off-diagonal entry of local row r (global row row0 + r), or UINT32_MAX. */
asp_index asp__amg_strongest(const asp_amg_csr *a, size_t r, size_t row0);
/*
 * The crease test of one coupling a (Galerkin product of the classifier-weighted matrix) against f
 * (the same with C = 1): a / f is the mean classifier along the interface of unknowns I and J, cut
 * when below ratio times the smaller of their interior means cmean_r, cmean_c (hierarchy.c).
 */
int asp__amg_crease(double a, double f, double ratio, double cmean_r, double cmean_c);

/* What asp__amg_filter_rows keeps of a coarse matrix's rows (hierarchy.c's filter_coarse says why). */
typedef struct asp__amg_filter {
    double cut;                /* couplings weaker than this (absolute) go */
    const uint8_t *crease;     /* per entry: cut by the crease test; NULL: none */
    const asp_index *best;     /* per local row: asp__amg_strongest for a small unknown, else UINT32_MAX */
    const asp_index *best_col; /* per entry: best of the column's unknown; NULL: best[col] (all rows local) */
    size_t row0;
} asp__amg_filter;
/* The entries asp__amg_filter_rows keeps, diagonals aside. */
size_t asp__amg_filter_count(const asp_amg_csr *ac, const asp__amg_filter *f);
/*
 * The next level's matrix: m's rows are ac's kept negative couplings plus a diagonal that makes
 * each row sum to zero (eq. 7); rows of m past ac->rows hold the diagonal alone. m needs room for
 * asp__amg_filter_count plus m->rows entries. Returns the off-diagonal entries written.
 */
size_t asp__amg_filter_rows(const asp_amg_csr *ac, const asp__amg_filter *f, asp_amg_csr *m);

/*
 * The position of column c in row r of m, whose columns increase within each row (binary search;
 * csr.c), or SIZE_MAX when the row has no such column. The one entry lookup of src/amg.
 */
size_t asp__amg_csr_find(const asp_amg_csr *m, size_t r, asp_index c);

/* m(r, c): 0 where the pattern has no entry. */
static inline double asp__amg_csr_entry(const asp_amg_csr *m, size_t r, asp_index c)
{
    const size_t k = asp__amg_csr_find(m, r, c);
    return k == SIZE_MAX ? 0.0 : m->val[k];
}

/* Galerkin product P^T F P (p: n x nc, f: n x n); columns within a row are not sorted. */
int asp__amg_galerkin(const asp_amg_csr *p, const asp_amg_csr *f, const asp_context *ctx, asp_amg_csr **out,
                      asp_error *err);

/* Sparse product c = a * b with entries < drop dropped and rows renormalised to sum 1. */
int asp__amg_spgemm_pou(const asp_amg_csr *a, const asp_amg_csr *b, double drop, const asp_context *ctx,
                        asp_amg_csr **out, asp_error *err);

/*
 * The decomposition's numbering of points (morton.c): *order (n entries) lists the input indices
 * along the Morton curve of the positions quantised over their bounding box, ties in input order.
 * The key alone, for the distributed reader: scale from the global box (asp__amg_morton_scale).
 */
int asp__amg_morton_order(const float *pos, size_t n, const asp_context *ctx, asp_index **order, asp_error *err);
double asp__amg_morton_scale(const float lo[3], const float hi[3]);
uint64_t asp__amg_morton_key(const float p[3], const float lo[3], double scale);

/* Back to the input order: element m of data (n elements of elem bytes) moves to order[m]. */
int asp__amg_unpermute(void *data, size_t n, size_t elem, const asp_index *order, const asp_context *ctx,
                       asp_error *err);
/* The same for the rows of *m (and its columns, with columns_too: a square point-by-point matrix). */
int asp__amg_csr_unpermute(asp_amg_csr **m, const asp_index *order, int columns_too, const asp_context *ctx,
                           asp_error *err);

/* Allocates an empty asp_amg owning nothing yet. */
int asp__amg_alloc(const asp_context *ctx, asp_amg **out, asp_error *err);

#endif
