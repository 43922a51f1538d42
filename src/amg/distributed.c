/*
 * The decomposition on MPI ranks (issue 19; journal 2.1-2.3 as decompose.c):
 * Morton-ordered points with a halo, the serial kernels on each rank's points
 * and halo, the stiffness rows of owned points completed across rank borders,
 * the hierarchy level by level with hypre's distributed BoomerAMG and
 * hierarchy.c's repairs and cuts done on distributed rows, the basis
 * Psi^l = P^1 ... P^l as row-distributed products, and the .amg file.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg_distributed.h"
#include "util/banned.h"

int asp_amg_mpi_ranks(void)
{
    /* Open MPI, MPICH/Hydra and PMIx, Slurm's srun: the launcher's word, read before MPI starts */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        const char *v = getenv(vars[i]);
        if (v && *v) {
            long n = strtol(v, NULL, 10);
            if (n >= 1 && n < 1L << 24)
                return (int)n;
        }
    }
    return 1;
}

#ifndef ASP_HAVE_HYPRE
int asp_amg_decompose_distributed(const char *in_path, const char *out_path, const asp_amg_desc *desc, double tau,
                                  const asp_context *ctx, asp_amg_dist_info *info, asp_error *err)
{
    (void)in_path, (void)out_path, (void)desc, (void)tau, (void)ctx, (void)info;
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot decompose on MPI ranks: this build has no hypre");
}
void asp_amg_distributed_shutdown(void) {}
#else
#include <sys/resource.h>

#include "amgsplat/geom.h"

#include "amg/distributed.h"

/* ---- neighbourhood radius and halo ---- */

/* The global order statistic: the smallest v with at least want values <= v among every rank's vals[i * stride]. */
static float global_select(const asp__dist *d, const float *vals, size_t n, size_t stride, unsigned long long want)
{
    uint32_t lo = 0, hi = 0x7f800000u; /* non-negative floats order as their bits */
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        unsigned long long c = 0, all = 0;
        for (size_t i = 0; i < n; i++) {
            uint32_t b;
            memcpy(&b, &vals[i * stride], 4);
            c += b <= mid;
        }
        MPI_Allreduce(&c, &all, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (all >= want)
            hi = mid;
        else
            lo = mid + 1;
    }
    float v;
    memcpy(&v, &lo, 4);
    return v;
}

/* k nearest among the n points at pos (k < n): squared distances into a new array. */
static int knn_dist2(const asp__dist *d, const float *pos, size_t n, size_t k, float **out, asp_error *err)
{
    asp_kdtree *tree = NULL;
    asp_index *idx = NULL;
    float *d2 = NULL;
    int rc = asp_kdtree_create(pos, n, 3 * sizeof(float), &d->ctx, &tree, err);
    if (!rc) {
        idx = asp_alloc(&d->ctx, n * k * sizeof *idx);
        d2 = asp_alloc(&d->ctx, n * k * sizeof *d2);
        rc = idx && d2 ? asp_knn_all(tree, k, idx, d2, &d->ctx, err)
                       : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu x %zu neighbours", n, k);
    }
    asp_kdtree_destroy(tree);
    asp_free(&d->ctx, idx);
    if (rc)
        asp_free(&d->ctx, d2);
    else
        *out = d2;
    return rc;
}

/*
 * Each owned point's k_max-th neighbour distance among the rank's own points
 * bounds its true one from above; epsilon (journal 2.1) is the global median
 * k_min-th distance, found exactly by bisection on the float bits (the serial
 * select_kth). The halo radius is capped at twice the median k_max-th
 * distance: a few points of a rank's piece of the Morton curve lie apart from
 * the rest, and their uncapped balls spanned much of the model (246k halo
 * points for 1M on 2 ranks). halo_and_neighbourhoods checks the cap.
 */
static int radii_and_epsilon(const asp__dist *d, const asp__dist_points *pts, asp_amg_desc *desc, float *radius,
                             asp_error *err)
{
    const size_t n = pts->n_own, k = desc->k_max;
    float *d2 = NULL;
    int rc = 0;
    if (n <= k)
        rc = asp_error_set(err, ASP_EINVAL,
                           "rank %d holds %zu points, fewer than k_max + 1 = %zu: use fewer ranks for %zu points",
                           d->rank, n, k + 1, pts->n_global);
    if (!rc)
        rc = knn_dist2(d, pts->pos, n, k, &d2, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    const float cap = 2.0f * sqrtf(global_select(d, d2 + k - 1, n, k, pts->n_global / 2 + 1));
    for (size_t i = 0; i < n; i++)
        radius[i] = fminf(sqrtf(d2[i * k + k - 1]), cap) * (1.0f + 1e-5f) + 1e-30f;
    if (desc->epsilon == 0) {
        desc->epsilon = sqrt((double)global_select(d, d2 + desc->k_min - 1, n, k, pts->n_global / 2 + 1));
        if (!(desc->epsilon > 0))
            rc = asp_error_set(err, ASP_EDEGENERATE,
                               "cannot decompose: most points coincide with %zu others (no neighbourhood radius)",
                               desc->k_min);
    }
    asp_free(&d->ctx, d2);
    return rc;
}

static asp_index gid_of(const asp__dist *d, const asp__dist_points *pts, size_t local)
{
    return (asp_index)(local < pts->n_own ? pts->starts[d->rank] + local : pts->ghost_gid[local - pts->n_own]);
}

/* ---- stiffness rows across rank borders ---- */

typedef struct triple {
    asp_index row, col;
    double v, fv;
} triple;

static int cmp_triple(const void *a, const void *b)
{
    const triple *x = a, *y = b;
    if (x->row != y->row)
        return x->row < y->row ? -1 : 1;
    return x->col < y->col ? -1 : x->col > y->col;
}

/*
 * A = (A~ + A~^T) / 2 (journal eq. 6) for the owned rows. The local assembly
 * (ghosts without fans) already holds both halves between owned points and
 * A~_ij / 2 towards a ghost j; the other half, A~_ji / 2, is the value j's
 * owner has in row j, column i: each rank sends those to the owners. Then
 * stiffness.c's clamping and zero row sums (eq. 7) on the completed rows.
 */
static int global_rows(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **take_a, asp_amg_csr **take_f,
                       asp_amg_stiffness form, asp_amg_csr **ga, asp_amg_csr **gf, size_t *positive,
                       asp_error *err)
{
    const asp_amg_csr *a = *take_a, *f = *take_f;
    const int P = d->size, want_f = f != NULL;
    const size_t n = pts->n_own, start = pts->starts[d->rank];
    int *cnt = asp_calloc(&d->ctx, 4 * (size_t)P, sizeof *cnt);
    if (!cnt)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness exchange");
    int *dis = cnt + P, *rcnt = cnt + 2 * P, *rdis = cnt + 3 * P;
    size_t out_n = 0, own_n = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++) {
            if (a->col[k] >= n)
                cnt[asp__dist_owner(pts->starts, P, gid_of(d, pts, a->col[k]))]++, out_n++;
            if (a->col[k] != i)
                own_n++;
        }
    triple *snd = asp_alloc(&d->ctx, (out_n + 1) * sizeof *snd);
    int *fill = asp_calloc(&d->ctx, (size_t)P, sizeof *fill);
    for (int q = 1; q < P; q++)
        dis[q] = dis[q - 1] + cnt[q - 1];
    for (size_t i = 0; snd && fill && i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++)
            if (a->col[k] >= n) {
                asp_index g = gid_of(d, pts, a->col[k]);
                int o = asp__dist_owner(pts->starts, P, g);
                snd[dis[o] + fill[o]++] = (triple){g, (asp_index)(start + i), a->val[k], f ? f->val[k] : 0};
            }
    asp_free(&d->ctx, fill);
    MPI_Alltoall(cnt, 1, MPI_INT, rcnt, 1, MPI_INT, d->comm);
    size_t got = 0;
    for (int q = 0; q < P; q++) {
        rdis[q] = (int)got;
        got += (size_t)rcnt[q];
    }
    triple *all = asp_alloc(&d->ctx, (own_n + got + 1) * sizeof *all);
    int ok = snd && all, allok = 0, rc = 0;
    MPI_Allreduce(&ok, &allok, 1, MPI_INT, MPI_MIN, d->comm);
    if (!allok) {
        asp_free(&d->ctx, snd);
        asp_free(&d->ctx, all);
        asp_free(&d->ctx, cnt);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu stiffness entries", own_n + got);
    }
    MPI_Datatype t;
    MPI_Type_contiguous((int)sizeof(triple), MPI_BYTE, &t);
    MPI_Type_commit(&t);
    MPI_Alltoallv(snd, cnt, dis, t, all + own_n, rcnt, rdis, t, d->comm);
    MPI_Type_free(&t);
    asp_free(&d->ctx, snd);
    asp_free(&d->ctx, cnt);
    size_t w = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++)
            if (a->col[k] != i)
                all[w++] = (triple){(asp_index)(start + i), gid_of(d, pts, a->col[k]), a->val[k], f ? f->val[k] : 0};
    /* every entry is in the triples now: the local matrices go before the global ones are made (issue 19) */
    asp_amg_csr_destroy(*take_a);
    asp_amg_csr_destroy(*take_f);
    *take_a = *take_f = NULL;
    a = f = NULL;
    qsort(all, own_n + got, sizeof *all, cmp_triple);
    const size_t total = own_n + got;
    asp_amg_csr *A = NULL, *F = NULL;
    rc = asp_amg_csr_create(n, pts->n_global, total + n, &d->ctx, &A, err);
    if (!rc && want_f)
        rc = asp_amg_csr_create(n, pts->n_global, total + n, &d->ctx, &F, err);
    const int clamp = form != ASP_AMG_STIFFNESS_UNCLAMPED;
    size_t pos_count = 0, k = 0;
    w = 0;
    for (size_t i = 0; !rc && i < n; i++) {
        const asp_index gi = (asp_index)(start + i);
        size_t diag_slot = SIZE_MAX;
        double diag = 0, fdiag = 0;
        while (k < total && all[k].row == gi) {
            asp_index j = all[k].col;
            double v = 0, fv = 0;
            for (; k < total && all[k].row == gi && all[k].col == j; k++)
                v += all[k].v, fv += all[k].fv;
            if (v > 0) {
                pos_count += j > gi;
                if (clamp)
                    continue;
            }
            if (v == 0)
                continue;
            if (diag_slot == SIZE_MAX && j > gi)
                diag_slot = w++;
            A->col[w] = j;
            A->val[w] = v;
            diag -= v;
            if (F) {
                F->col[w] = j;
                F->val[w] = fv < 0 || !clamp ? fv : 0.0;
                fdiag -= F->val[w];
            }
            w++;
        }
        if (diag_slot == SIZE_MAX)
            diag_slot = w++;
        A->col[diag_slot] = gi;
        A->val[diag_slot] = diag;
        A->row_ptr[i + 1] = w;
        if (F) {
            F->col[diag_slot] = gi;
            F->val[diag_slot] = fdiag;
            F->row_ptr[i + 1] = w;
        }
    }
    asp_free(&d->ctx, all);
    if (rc) {
        asp_amg_csr_destroy(A);
        asp_amg_csr_destroy(F);
        return rc;
    }
    unsigned long long pc = pos_count, pall = 0;
    MPI_Allreduce(&pc, &pall, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
    *positive = (size_t)pall;
    *ga = A;
    *gf = F;
    return 0;
}

/* ---- the hierarchy (hierarchy.c on distributed rows) ---- */

typedef struct hier {
    size_t nlevels;
    size_t sizes[ASP_AMG_DIST_MAX_LEVELS];
    size_t *starts[ASP_AMG_DIST_MAX_LEVELS]; /* partition of each level's unknowns */
    asp_amg_csr *p[ASP_AMG_DIST_MAX_LEVELS]; /* [1..]: local rows (level l-1), global columns (level l) */
    size_t repaired;
} hier;

static void hier_release(const asp_context *ctx, hier *h)
{
    for (size_t l = 0; l < ASP_AMG_DIST_MAX_LEVELS; l++) {
        asp_free(ctx, h->starts[l]);
        asp_amg_csr_destroy(h->p[l]);
    }
    memset(h, 0, sizeof *h);
}

static unsigned long long sum_all(const asp__dist *d, unsigned long long v)
{
    unsigned long long s = 0;
    MPI_Allreduce(&v, &s, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
    return s;
}

/* Median |a_ij| of the off-diagonal entries over every rank (level_rows.c's histogram, summed). */
static double median_coupling(const asp__dist *d, const asp_amg_csr *a, size_t row0)
{
    uint64_t hist[256] = {0}, all[256];
    asp__amg_coupling_hist(a, row0, hist);
    MPI_Allreduce(hist, all, 256, MPI_UINT64_T, MPI_SUM, d->comm);
    return asp__amg_hist_median(all);
}

typedef struct wentry {
    asp_index c;
    double v;
} wentry;

static int cmp_wentry(const void *a, const void *b)
{
    const wentry *x = a, *y = b;
    return x->c < y->c ? -1 : x->c > y->c;
}

/*
 * Parallel RS coarsening leaves some rows of P empty at rank borders (an F
 * point whose strong couplings are all F points of another rank: 19 of 10005
 * rows on the second of 2 ranks, 20k bunny). Serially an empty row is a
 * disconnected point and becomes an orphan unknown (hierarchy.c), which never
 * merges again: these would stay separate domains up to L (45 unknowns at L
 * instead of 5). A row with couplings in a instead gets the mean of its
 * neighbours' P rows weighted by -a_ij, a convex combination of partitions of
 * unity, so the basis stays one; only rows without couplings become orphans.
 */
static int fill_empty_rows(const asp__dist *d, asp_amg_csr **pp, const asp_amg_csr *a, const size_t *st,
                           asp_error *err)
{
    asp_amg_csr *p = *pp;
    const size_t r0 = st[d->rank];
    size_t m = 0, extra = 0;
    for (size_t r = 0; r < p->rows; r++)
        if (p->row_ptr[r + 1] == p->row_ptr[r])
            m += a->row_ptr[r + 1] - a->row_ptr[r];
    asp_index *ids = asp_alloc(&d->ctx, (m + 1) * sizeof *ids);
    int rc = ids ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    size_t w = 0;
    for (size_t r = 0; !rc && r < p->rows; r++)
        if (p->row_ptr[r + 1] == p->row_ptr[r])
            for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
                ids[w++] = a->col[k];
    asp_amg_csr *nb = NULL, *q = NULL;
    if ((rc = asp__dist_agree(d, rc, err)) == 0)
        rc = asp__dist_fetch_rows(d, st, p, ids, m, &nb, err);
    asp_free(&d->ctx, ids);
    if (rc)
        return rc;
    if (sum_all(d, m) == 0) {
        asp_amg_csr_destroy(nb);
        return 0;
    }
    extra = nb->row_ptr[nb->rows];
    wentry *tmp = asp_alloc(&d->ctx, (extra + 1) * sizeof *tmp);
    rc = tmp ? asp_amg_csr_create(p->rows, p->cols, p->row_ptr[p->rows] + extra, &d->ctx, &q, err)
             : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    size_t at = 0, o = 0; /* at: next fetched row; o: output entries */
    for (size_t r = 0; !rc && r < p->rows; r++) {
        if (p->row_ptr[r + 1] > p->row_ptr[r]) {
            for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++) {
                q->col[o] = p->col[k];
                q->val[o++] = p->val[k];
            }
        } else {
            size_t t = 0;
            for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++, at++) {
                double wgt = a->col[k] != r0 + r && a->val[k] < 0 ? -a->val[k] : 0, s = 0;
                for (size_t e = nb->row_ptr[at]; e < nb->row_ptr[at + 1]; e++)
                    s += nb->val[e] > 0 ? nb->val[e] : 0;
                if (!(wgt > 0 && s > 1e-12))
                    continue;
                for (size_t e = nb->row_ptr[at]; e < nb->row_ptr[at + 1]; e++)
                    if (nb->val[e] > 0)
                        tmp[t++] = (wentry){nb->col[e], wgt * nb->val[e] / s};
            }
            qsort(tmp, t, sizeof *tmp, cmp_wentry);
            for (size_t e = 0; e < t; e++) {
                if (o > q->row_ptr[r] && q->col[o - 1] == tmp[e].c) {
                    q->val[o - 1] += tmp[e].v;
                } else {
                    q->col[o] = tmp[e].c;
                    q->val[o++] = tmp[e].v;
                }
            }
            /* renormalised with the rest in repair() */
        }
        q->row_ptr[r + 1] = o;
    }
    asp_free(&d->ctx, tmp);
    asp_amg_csr_destroy(nb);
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_amg_csr_destroy(q);
        return rc;
    }
    asp_amg_csr_destroy(p);
    *pp = q;
    return 0;
}

/* A coarse column in the repaired numbering: shifted by the orphans of the ranks before its owner. */
typedef struct {
    const size_t *cst, *ost;
    int P;
} orphan_shift;

static asp_index shift_column(asp_index c, const void *arg)
{
    const orphan_shift *s = arg;
    return (asp_index)(c + s->ost[asp__dist_owner(s->cst, s->P, c)]);
}

/*
 * hierarchy.c's repair on distributed rows (asp__amg_pou_rows): empty rows
 * become orphans, each a new coarse unknown numbered after its rank's hypre
 * unknowns, so the coarse partition becomes nst; columns are renumbered into
 * it (monotone, so rows stay sorted) and other rows renormalised.
 */
static int repair(const asp__dist *d, asp_amg_csr **pp, const size_t *cst, size_t *nst, size_t *repaired,
                  asp_error *err)
{
    const asp_amg_csr *p = *pp;
    const int P = d->size;
    const size_t orphans = asp__amg_empty_rows(p);
    size_t *ost = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *ost);
    if (!ost || asp__dist_partition(d, orphans, ost)) {
        asp_free(&d->ctx, ost);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    }
    for (int q = 0; q <= P; q++)
        nst[q] = cst[q] + ost[q];
    asp_amg_csr *qm;
    int rc = asp_amg_csr_create(p->rows, nst[P], p->row_ptr[p->rows] + orphans, &d->ctx, &qm, err);
    if (rc) {
        asp_free(&d->ctx, ost);
        return rc;
    }
    const orphan_shift shift = {cst, ost, P};
    asp__amg_pou_rows(p, qm, (asp_index)(nst[d->rank] + (cst[d->rank + 1] - cst[d->rank])), shift_column, &shift,
                      repaired);
    asp_free(&d->ctx, ost);
    asp_amg_csr_destroy(*pp);
    *pp = qm;
    return 0;
}

/* The coarse matrix in the repaired numbering, with an empty row per orphan. */
static int renumber_coarse(const asp__dist *d, asp_amg_csr **pac, const size_t *cst, const size_t *nst,
                           asp_error *err)
{
    const asp_amg_csr *ac = *pac;
    const size_t rows = nst[d->rank + 1] - nst[d->rank];
    asp_amg_csr *m;
    int rc = asp_amg_csr_create(rows, nst[d->size], ac->row_ptr[ac->rows], &d->ctx, &m, err);
    if (rc)
        return rc;
    for (size_t r = 0; r < ac->rows; r++) {
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
            int o = asp__dist_owner(cst, d->size, ac->col[k]);
            m->col[k] = (asp_index)(ac->col[k] - cst[o] + nst[o]);
            m->val[k] = ac->val[k];
        }
        m->row_ptr[r + 1] = ac->row_ptr[r + 1];
    }
    for (size_t r = ac->rows; r < rows; r++)
        m->row_ptr[r + 1] = m->row_ptr[r];
    asp_amg_csr_destroy(*pac);
    *pac = m;
    return 0;
}

/* dst[J] = sum_r P_rJ src[r] (hierarchy.c's carry) with J on any rank. */
static int carry(const asp__dist *d, const asp_amg_csr *p, const size_t *nst, const double *src, double *dst,
                 asp_error *err)
{
    const size_t nnz = p->row_ptr[p->rows];
    double *v = asp_alloc(&d->ctx, (nnz + 1) * sizeof *v);
    if (!v)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    for (size_t r = 0; r < p->rows; r++)
        for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
            v[k] = p->val[k] * src[r];
    memset(dst, 0, (nst[d->rank + 1] - nst[d->rank]) * sizeof *dst);
    int rc = asp__dist_scatter_add(d, nst, p->col, v, nnz, dst, err);
    asp_free(&d->ctx, v);
    return rc;
}

/*
 * hierarchy.c's crease test and filter_coarse on the local rows of ac: the
 * crease decision for (r, c) is taken in both rows from the same symmetric
 * quantities (it was mirrored from the smaller index serially); the strongest
 * couplings of small unknowns come from their owners.
 */
static int filter(const asp__dist *d, const asp_amg_csr *ac, const asp_amg_csr *fc, const size_t *nst,
                  const double *mass, const double *cm, double cut, double ratio, double small, asp_amg_csr **out,
                  size_t *offdiag, asp_error *err)
{
    const size_t rows = ac->rows, nnz = ac->row_ptr[rows], r0 = nst[d->rank];
    double *cmean = asp_alloc(&d->ctx, (rows + 1) * sizeof *cmean), *ccol = NULL;
    asp_index *best = asp_alloc(&d->ctx, (rows + 1) * sizeof *best), *bcol = NULL;
    uint8_t *crease = NULL;
    asp_amg_csr *m = NULL;
    int rc = cmean && best ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    if (!rc) {
        ccol = asp_alloc(&d->ctx, (nnz + 1) * sizeof *ccol);
        bcol = asp_alloc(&d->ctx, (nnz + 1) * sizeof *bcol);
        crease = asp_calloc(&d->ctx, nnz + 1, 1);
        if (!ccol || !bcol || !crease)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    }
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    for (size_t r = 0; r < rows; r++) {
        cmean[r] = mass[r] > 0 ? cm[r] / mass[r] : 0;
        best[r] = mass[r] < small ? asp__amg_strongest(ac, r, r0) : UINT32_MAX;
    }
    if ((rc = asp__dist_fetch(d, nst, best, sizeof *best, ac->col, nnz, bcol, err)) != 0)
        goto done;
    if (fc && (rc = asp__dist_fetch(d, nst, cmean, sizeof *cmean, ac->col, nnz, ccol, err)) != 0)
        goto done;
    for (size_t r = 0; fc && r < rows; r++)
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
            if (ac->col[k] == r0 + r || ac->val[k] >= 0)
                continue;
            crease[k] = (uint8_t)asp__amg_crease(ac->val[k], asp__amg_csr_entry(fc, r, ac->col[k]), ratio, cmean[r],
                                                 ccol[k]);
        }
    const asp__amg_filter keep = {.cut = cut, .crease = crease, .best = best, .best_col = bcol, .row0 = r0};
    rc = asp_amg_csr_create(rows, ac->cols, asp__amg_filter_count(ac, &keep) + rows, &d->ctx, &m, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    const size_t w = asp__amg_filter_rows(ac, &keep, m);
    *offdiag = (size_t)sum_all(d, w);
    *out = m;
    m = NULL;
done:
    asp_amg_csr_destroy(m);
    asp_free(&d->ctx, cmean);
    asp_free(&d->ctx, ccol);
    asp_free(&d->ctx, best);
    asp_free(&d->ctx, bcol);
    asp_free(&d->ctx, crease);
    return rc;
}

/*
 * A level moves to rank 0 and is coarsened there as in one process (hypre's
 * own answer is BoomerAMGSetSeqThreshold) below 2048 unknowns per rank, and on
 * a few ranks below 65,536 unknowns in all. Measured on a 20k bunny, parallel
 * RS coarsening of a level with a few hundred unknowns per rank keeps nearly
 * every unknown at a rank border, so the coarse levels stopped shrinking (58
 * unknowns at L on 2 ranks, 5 serially). Above that, each border still adds
 * its own C points, and the coarse levels amplify any difference (RS is
 * greedy): on a 4M-point bunny with the per-rank rule alone, 4 ranks ended
 * with 58 unknowns on level 14 against 50 in one process; gathering below
 * 65,536 (level 6 on) gave 53, and 49 on 2 ranks. A level of 65,536 unknowns
 * costs rank 0 a few megabytes and well under a second. The global ids stay;
 * only the partition changes, to [0, N, N, ...].
 */
enum { GATHER_BELOW_PER_RANK = 2048, GATHER_BELOW = 65536 };

static size_t gather_below(int P)
{
    const size_t g = GATHER_BELOW_PER_RANK * (size_t)P;
    return g > GATHER_BELOW ? g : GATHER_BELOW;
}

static int gather_level(const asp__dist *d, size_t *starts, asp_amg_csr **a, asp_amg_csr **f, double **mass,
                        double **cm, asp_error *err)
{
    const size_t N = starts[d->size], m = d->rank == 0 ? N : 0;
    asp_index *ids = asp_alloc(&d->ctx, (m + 1) * sizeof *ids);
    double *m2 = asp_alloc(&d->ctx, (m + 1) * sizeof *m2), *c2 = asp_alloc(&d->ctx, (m + 1) * sizeof *c2);
    asp_amg_csr *a2 = NULL, *f2 = NULL;
    int rc = ids && m2 && c2 ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory gathering a level of %zu unknowns", N);
    for (size_t i = 0; !rc && i < m; i++)
        ids[i] = (asp_index)i;
    if ((rc = asp__dist_agree(d, rc, err)) == 0)
        rc = asp__dist_fetch_rows(d, starts, *a, ids, m, &a2, err);
    if (!rc && *f)
        rc = asp__dist_fetch_rows(d, starts, *f, ids, m, &f2, err);
    if (!rc)
        rc = asp__dist_fetch(d, starts, *mass, sizeof **mass, ids, m, m2, err);
    if (!rc)
        rc = asp__dist_fetch(d, starts, *cm, sizeof **cm, ids, m, c2, err);
    asp_free(&d->ctx, ids);
    if (rc) {
        asp_free(&d->ctx, m2);
        asp_free(&d->ctx, c2);
        asp_amg_csr_destroy(a2);
        asp_amg_csr_destroy(f2);
        return rc;
    }
    asp_free(&d->ctx, *mass);
    asp_free(&d->ctx, *cm);
    *mass = m2;
    *cm = c2;
    *a = a2;
    *f = f2;
    for (int q = 1; q <= d->size; q++)
        starts[q] = N;
    return 0;
}

/* Takes *a0: destroyed (*a0 = NULL) once hypre holds its copy of the first level (the AMG stage's peak). */
static int build_hierarchy(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **a0,
                           const asp_amg_csr *f0, const float *cls, const asp_amg_desc *desc, hier *h, asp_error *err)
{
    const int P = d->size;
    const size_t maxl = desc->max_levels < ASP_AMG_DIST_MAX_LEVELS ? desc->max_levels : ASP_AMG_DIST_MAX_LEVELS;
    const int crease = desc->crease_cut > 0 && f0;
    const asp_amg_csr *cur = *a0, *fcur = f0;
    asp_amg_csr *owned = NULL, *fowned = NULL;
    size_t n = pts->n_own, *cst = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *cst);
    double *mass = asp_alloc(&d->ctx, (n + 1) * sizeof *mass), *cm = asp_alloc(&d->ctx, (n + 1) * sizeof *cm);
    int rc = cst && mass && cm ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    h->nlevels = 1;
    h->sizes[0] = pts->n_global;
    h->starts[0] = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *h->starts[0]);
    if (!h->starts[0])
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    else
        memcpy(h->starts[0], pts->starts, ((size_t)P + 1) * sizeof *pts->starts);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    for (size_t i = 0; i < n; i++) {
        mass[i] = 1.0;
        cm[i] = cls[i];
    }
    const double cut = desc->weak_coupling > 0 ? desc->weak_coupling * median_coupling(d, *a0, pts->starts[d->rank]) : 0;
    while (h->nlevels < maxl && h->sizes[h->nlevels - 1] > desc->max_coarse) {
        const size_t l = h->nlevels;
        size_t *st = h->starts[l - 1];
        if (P > 1 && l >= 2 && h->sizes[l - 1] < gather_below(P) && st[1] < st[P]) {
            asp_amg_csr *ga = (asp_amg_csr *)cur, *gf = (asp_amg_csr *)fcur;
            if ((rc = gather_level(d, st, &ga, &gf, &mass, &cm, err)) != 0)
                break;
            asp_amg_csr_destroy(owned);
            asp_amg_csr_destroy(fowned);
            owned = ga;
            cur = ga;
            fowned = gf;
            fcur = gf;
        }
        asp_amg_csr *p = NULL, *ac = NULL, *next = NULL, *fnext = NULL;
        size_t *nst = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *nst), offdiag = 0;
        /* the first level: A^0 goes as soon as hypre has it; the rows P leaves empty come back for the fill */
        asp_amg_csr *a_rows = NULL;
        const int first = *a0 && cur == *a0;
        rc = first ? asp__dist_coarsen_take(d, a0, st, desc, &p, &ac, cst, &a_rows, err)
                   : asp__dist_coarsen(d, cur, st, desc, &p, &ac, cst, err);
        if (first && !*a0)
            cur = NULL; /* taken */
        if (rc || !p) {
            asp_amg_csr_destroy(a_rows);
            asp_free(&d->ctx, nst);
            break;
        }
        if (!nst)
            rc = ASP_ENOMEM;
        if ((rc = asp__dist_agree(d, rc ? asp_error_set(err, rc, "out of memory for the AMG hierarchy") : 0, err)))
            goto level_fail;
        rc = fill_empty_rows(d, &p, a_rows ? a_rows : cur, st, err);
        asp_amg_csr_destroy(a_rows);
        a_rows = NULL;
        if (rc)
            goto level_fail;
        if ((rc = asp__dist_agree(d, repair(d, &p, cst, nst, &h->repaired, err), err)) != 0)
            goto level_fail;
        if ((rc = asp__dist_agree(d, renumber_coarse(d, &ac, cst, nst, err), err)) != 0)
            goto level_fail;
        const size_t nc = nst[d->rank + 1] - nst[d->rank];
        double *m2 = asp_alloc(&d->ctx, (nc + 1) * sizeof *m2), *c2 = asp_alloc(&d->ctx, (nc + 1) * sizeof *c2);
        rc = m2 && c2 ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        if ((rc = asp__dist_agree(d, rc, err)) == 0)
            rc = carry(d, p, nst, mass, m2, err);
        if (!rc)
            rc = carry(d, p, nst, cm, c2, err);
        if (!rc) {
            asp_free(&d->ctx, mass);
            asp_free(&d->ctx, cm);
            mass = m2;
            cm = c2;
        } else {
            asp_free(&d->ctx, m2);
            asp_free(&d->ctx, c2);
            goto level_fail;
        }
        if (crease && (rc = asp__dist_galerkin(d, p, st, nst, fcur, &fnext, err)) != 0)
            goto level_fail;
        rc = filter(d, ac, fnext, nst, mass, cm, cut, desc->crease_cut, 0.25 * (double)pts->n_global / (double)nst[P],
                    &next, &offdiag, err);
        if (rc)
            goto level_fail;
        asp_amg_csr_destroy(ac);
        ac = NULL;
        if (nst[P] >= h->sizes[l - 1]) { /* nothing left to merge */
            asp_amg_csr_destroy(p);
            asp_amg_csr_destroy(next);
            asp_amg_csr_destroy(fnext);
            asp_free(&d->ctx, nst);
            break;
        }
        h->p[l] = p;
        h->starts[l] = nst;
        h->sizes[l] = nst[P];
        h->nlevels++;
        asp_amg_csr_destroy(owned);
        owned = next;
        cur = next;
        if (fnext) {
            asp_amg_csr_destroy(fowned);
            fowned = fnext;
            fcur = fnext;
        }
        if (offdiag == 0)
            break;
        continue;
    level_fail:
        asp_amg_csr_destroy(a_rows);
        asp_amg_csr_destroy(p);
        asp_amg_csr_destroy(ac);
        asp_amg_csr_destroy(next);
        asp_amg_csr_destroy(fnext);
        asp_free(&d->ctx, nst);
        break;
    }
    h->repaired = (size_t)sum_all(d, h->repaired);
done:
    asp_amg_csr_destroy(owned);
    asp_amg_csr_destroy(fowned);
    asp_free(&d->ctx, cst);
    asp_free(&d->ctx, mass);
    asp_free(&d->ctx, cm);
    return rc;
}

/* ---- the basis and its domains, level by level ---- */

static int cmp_index(const void *a, const void *b)
{
    asp_index x = *(const asp_index *)a, y = *(const asp_index *)b;
    return x < y ? -1 : x > y;
}

/*
 * Psi^l = Psi^(l-1) P^l (journal 2.3). The rows of P^l for this rank's own
 * columns are at hand (Morton order keeps most columns local); the others
 * are fetched from their owners, sorted and deduplicated first.
 */
static int next_basis(const asp__dist *d, const asp_amg_csr *psi, const asp_amg_csr *p, const size_t *pst,
                      double drop, asp_amg_csr **out, asp_error *err)
{
    const size_t nnz = psi->row_ptr[psi->rows], lo = pst[d->rank], nloc = pst[d->rank + 1] - lo;
    asp_index *cols = asp_alloc(&d->ctx, (nnz + 1) * sizeof *cols);
    asp_amg_csr *fetched = NULL, *b = NULL, *a = NULL;
    size_t m = 0;
    int rc = cols ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the basis");
    for (size_t k = 0; cols && k < nnz; k++)
        if (psi->col[k] < lo || psi->col[k] >= lo + nloc)
            cols[m++] = psi->col[k];
    if (cols) {
        qsort(cols, m, sizeof *cols, cmp_index);
        size_t u = 0;
        for (size_t k = 0; k < m; k++)
            if (u == 0 || cols[k] != cols[u - 1])
                cols[u++] = cols[k];
        m = u;
    }
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_free(&d->ctx, cols);
        return rc;
    }
    rc = asp__dist_fetch_rows(d, pst, p, cols, m, &fetched, err);
    /* b: the local rows of P^l, then the fetched ones */
    if (!rc)
        rc = asp_amg_csr_create(nloc + m, p->cols, p->row_ptr[nloc] + fetched->row_ptr[m], &d->ctx, &b, err);
    if (!rc) {
        const size_t pn = p->row_ptr[nloc];
        memcpy(b->row_ptr, p->row_ptr, (nloc + 1) * sizeof *b->row_ptr);
        memcpy(b->col, p->col, pn * sizeof *b->col);
        memcpy(b->val, p->val, pn * sizeof *b->val);
        for (size_t r = 0; r < m; r++)
            b->row_ptr[nloc + r + 1] = pn + fetched->row_ptr[r + 1];
        memcpy(b->col + pn, fetched->col, fetched->row_ptr[m] * sizeof *b->col);
        memcpy(b->val + pn, fetched->val, fetched->row_ptr[m] * sizeof *b->val);
        rc = asp_amg_csr_create(psi->rows, nloc + m, nnz, &d->ctx, &a, err);
    }
    if (!rc) {
        memcpy(a->row_ptr, psi->row_ptr, (psi->rows + 1) * sizeof *a->row_ptr);
        memcpy(a->val, psi->val, nnz * sizeof *a->val);
        for (size_t k = 0; k < nnz; k++) {
            asp_index c = psi->col[k];
            a->col[k] = c >= lo && c < lo + nloc
                            ? (asp_index)(c - lo)
                            : (asp_index)(nloc + (size_t)((asp_index *)bsearch(&c, cols, m, sizeof *cols, cmp_index) - cols));
        }
        rc = asp__amg_spgemm_pou(a, b, drop, &d->ctx, out, err);
    }
    asp_amg_csr_destroy(a);
    asp_amg_csr_destroy(b);
    asp_amg_csr_destroy(fetched);
    asp_free(&d->ctx, cols);
    return asp__dist_agree(d, rc, err);
}

/* A level's agreement figures (journal eq. 8, thesis eq. 2.5) over every rank. */
static int level_figures(const asp__dist *d, const asp_amg_csr *psi, const size_t *cst, double tau,
                         asp_amg_dist_level *lv, asp_error *err)
{
    const size_t nnz = psi->row_ptr[psi->rows], nc = cst[d->rank + 1] - cst[d->rank];
    double *one = asp_alloc(&d->ctx, (nnz + psi->rows + 1) * sizeof *one), *inside = asp_calloc(&d->ctx, nc + 1, sizeof *inside);
    double *strict = asp_calloc(&d->ctx, nc + 1, sizeof *strict);
    asp_index *arg = asp_alloc(&d->ctx, (psi->rows + 1) * sizeof *arg);
    int rc = one && inside && strict && arg ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for level figures");
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    unsigned long long member = 0, outside = 0;
    double pou = 0;
    for (size_t x = 0; x < psi->rows; x++) {
        double sum = 0, bv = -1;
        int any = 0;
        arg[x] = 0;
        for (size_t k = psi->row_ptr[x]; k < psi->row_ptr[x + 1]; k++) {
            sum += psi->val[k];
            one[k] = psi->val[k] > tau;
            member += psi->val[k] > tau;
            any |= psi->val[k] > tau;
            if (psi->val[k] > bv) { /* columns increase: ties keep the smaller index */
                bv = psi->val[k];
                arg[x] = psi->col[k];
            }
        }
        outside += !any;
        pou = fmax(pou, fabs(sum - 1.0));
    }
    if ((rc = asp__dist_scatter_add(d, cst, psi->col, one, nnz, inside, err)) != 0)
        goto done;
    for (size_t x = 0; x < psi->rows; x++)
        one[x] = 1.0;
    if ((rc = asp__dist_scatter_add(d, cst, arg, one, psi->rows, strict, err)) != 0)
        goto done;
    unsigned long long dom = 0, sdom = 0;
    for (size_t c = 0; c < nc; c++) {
        dom += inside[c] > 0;
        sdom += strict[c] > 0;
    }
    unsigned long long points = sum_all(d, psi->rows);
    lv->unknowns = cst[d->size];
    lv->domains = (size_t)sum_all(d, dom);
    lv->strict_domains = (size_t)sum_all(d, sdom);
    lv->points_outside = (size_t)sum_all(d, outside);
    lv->mean_domains_per_point = points ? (double)sum_all(d, member) / (double)points : 0;
    MPI_Allreduce(&pou, &lv->max_pou_error, 1, MPI_DOUBLE, MPI_MAX, d->comm);
done:
    asp_free(&d->ctx, one);
    asp_free(&d->ctx, inside);
    asp_free(&d->ctx, strict);
    asp_free(&d->ctx, arg);
    return rc;
}

static int basis_figures(const asp__dist *d, const asp__dist_points *pts, const hier *h, const asp_amg_desc *desc,
                         double tau, asp_amg_dist_info *info, asp_error *err)
{
    asp_amg_csr *psi = NULL;
    const size_t n = pts->n_own;
    int rc = asp_amg_csr_create(n, pts->n_global, n, &d->ctx, &psi, err);
    for (size_t i = 0; !rc && i < n; i++) {
        psi->col[i] = (asp_index)(pts->starts[d->rank] + i);
        psi->val[i] = 1.0;
        psi->row_ptr[i + 1] = i + 1;
    }
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    for (size_t l = 0; l < h->nlevels && !rc; l++) {
        if (l > 0) {
            asp_amg_csr *next = NULL;
            rc = next_basis(d, psi, h->p[l], h->starts[l - 1], desc->drop_tol, &next, err);
            if (rc)
                break;
            asp_amg_csr_destroy(psi);
            psi = next;
        }
        rc = level_figures(d, psi, h->starts[l], tau, &info->level[l], err);
    }
    asp_amg_csr_destroy(psi);
    return rc;
}

/* ---- the pipeline ---- */

static double peak_rss_mb(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? (double)ru.ru_maxrss / 1024.0 : 0;
}

/* The frame of asp_cloud_frame over every rank: box centre, farthest point plus the largest disc radius. */
static void frame_of(const asp__dist *d, const asp__dist_points *pts, asp_frame *frame)
{
    double far2 = 0, all2 = 0, rmax = 0, rall = 0;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = 0.5 * ((double)pts->lo[k] + pts->hi[k]);
    for (size_t i = 0; i < pts->n_own; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++)
            s += ((double)pts->pos[3 * i + k] - c[k]) * ((double)pts->pos[3 * i + k] - c[k]);
        far2 = fmax(far2, s);
        if (pts->radii)
            rmax = fmax(rmax, pts->radii[i]);
    }
    MPI_Allreduce(&far2, &all2, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    MPI_Allreduce(&rmax, &rall, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    if (!pts->radii) {
        /* asp_cloud_default_radius: discs twice the size that would cover half the box's surface */
        double e[3] = {(double)pts->hi[0] - pts->lo[0], (double)pts->hi[1] - pts->lo[1],
                       (double)pts->hi[2] - pts->lo[2]};
        double area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        rall = area > 0 ? 2 * sqrt(area / (3.14159265358979323846 * (double)pts->n_global))
                        : fmax(e[0], fmax(e[1], e[2])) / (double)pts->n_global;
    }
    for (int k = 0; k < 3; k++)
        frame->center[k] = c[k] + pts->origin[k];
    frame->radius = sqrt(all2) + rall;
}

typedef struct run {
    asp__dist d;
    asp_amg_desc desc;
    int auto_epsilon; /* desc.epsilon was not given: the median k_min-th distance */
    asp__dist_points pts;
    float *radius, *cls, *tangent;
    asp__amg_nbhd nb;
    asp__amg_fans fans;
    asp_amg_csr *la, *lf, *a, *f;
    hier h;
} run;

static void run_release(run *r)
{
    const asp_context *ctx = &r->d.ctx;
    asp__dist_points_release(ctx, &r->pts);
    asp_free(ctx, r->radius);
    asp_free(ctx, r->cls);
    asp_free(ctx, r->tangent);
    asp__amg_nbhd_release(ctx, &r->nb);
    asp__amg_fans_release(ctx, &r->fans);
    asp_amg_csr_destroy(r->la);
    asp_amg_csr_destroy(r->lf);
    asp_amg_csr_destroy(r->a);
    asp_amg_csr_destroy(r->f);
    hier_release(ctx, &r->h);
}

/* Neighbourhoods, classifier, fans and stiffness rows of the owned points (journal 2.1-2.2). */
static float dist2(const float *x, const float *y)
{
    return (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2]);
}

/*
 * Epsilon of one process (the median k_min-th neighbour distance, journal
 * 2.1): the estimate from each rank's own points is a little high at rank
 * borders (0.6% on a 20k bunny on 2 ranks); with the halo the owned points'
 * k_min-th neighbours are exact, so the median is taken again and the
 * neighbourhood sizes follow it.
 */
static int exact_epsilon(run *r, asp_error *err)
{
    const asp__dist_points *pts = &r->pts;
    const size_t n = pts->n_own, kmin = r->desc.k_min, kmax = r->desc.k_max;
    float *kth = asp_alloc(&r->d.ctx, (n + 1) * sizeof *kth);
    int rc = asp__dist_agree(&r->d, kth ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu distances", n), err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++)
        kth[i] = dist2(pts->pos + 3 * i, pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + kmin - 1]);
    r->desc.epsilon = sqrt((double)global_select(&r->d, kth, n, 1, pts->n_global / 2 + 1));
    asp_free(&r->d.ctx, kth);
    const float eps2 = (float)(r->desc.epsilon * r->desc.epsilon);
    for (size_t i = 0; i < n; i++) {
        size_t m = kmin;
        while (m < kmax && dist2(pts->pos + 3 * i, pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + m]) <= eps2)
            m++;
        r->nb.nn[i] = (uint16_t)m;
    }
    return 0;
}

/*
 * The halo, then the neighbourhoods N(x) of journal 2.1 on the rank's points
 * and halo. N(x_i) is the one of a single process when everything within its
 * farthest member, and within epsilon when it stopped short of k_max, lay
 * within radius[i] (all of that was sent). Otherwise that distance becomes
 * radius[i] and the halo is made again (none was needed on the bunny).
 */
static int halo_and_neighbourhoods(run *r, asp_amg_dist_info *info, asp_error *err)
{
    asp__dist *d = &r->d;
    asp__dist_points *pts = &r->pts;
    const size_t kmax = r->desc.k_max;
    for (int round = 0;; round++) {
        double t = asp_time_now(), mean = 0;
        int rc = d->size > 1 ? asp__dist_halo(d, pts, r->radius, err) : 0;
        info->t_halo += asp_time_now() - t;
        t = asp_time_now();
        if (!rc)
            rc = asp__amg_neighbourhoods(pts->pos, pts->n_own + pts->n_ghost, &r->desc, &d->ctx, &r->nb, &mean, err);
        info->amg.t_neighbours += asp_time_now() - t;
        if ((rc = asp__dist_agree(d, rc, err)) != 0)
            return rc;
        if (r->auto_epsilon && d->size > 1 && (rc = exact_epsilon(r, err)) != 0)
            return rc;
        unsigned long long short_ = 0, all = 0;
        for (size_t i = 0; d->size > 1 && i < pts->n_own; i++) {
            const size_t m = r->nb.nn[i];
            const float *x = pts->pos + 3 * i, *y = pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + m - 1];
            float far = sqrtf((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                              (x[2] - y[2]) * (x[2] - y[2]));
            if (m < kmax)
                far = fmaxf(far, (float)r->desc.epsilon);
            if (far > r->radius[i]) {
                r->radius[i] = far * (1.0f + 1e-5f) + 1e-30f;
                short_++;
            }
        }
        MPI_Allreduce(&short_, &all, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (all == 0)
            return 0;
        asp__amg_nbhd_release(&d->ctx, &r->nb);
        if (round == 8)
            return asp_error_set(err, ASP_ESOLVER, "the halo did not close after 8 rounds (%llu points short)", all);
    }
}

/* Classifier, fans and stiffness rows of the owned points (journal 2.1-2.2). */
static int local_stages(run *r, asp_amg_dist_info *info, asp_error *err)
{
    asp__dist *d = &r->d;
    asp__dist_points *pts = &r->pts;
    const size_t n = pts->n_own, nl = pts->n_own + pts->n_ghost;
    int rc = 0;
    unsigned long long nn = 0;
    for (size_t i = 0; i < n; i++)
        nn += r->nb.nn[i];
    info->amg.mean_neighbourhood = (double)sum_all(d, nn) / (double)pts->n_global;
    double t = asp_time_now();
    r->cls = asp_alloc(&d->ctx, (nl + 1) * sizeof *r->cls);
    r->tangent = asp_alloc(&d->ctx, (3 * nl + 3) * sizeof *r->tangent);
    rc = r->cls && r->tangent ? asp__amg_classify(pts->pos, &r->nb, &r->desc, &d->ctx, r->cls, r->tangent, err)
                              : asp_error_set(err, ASP_ENOMEM, "out of memory for the classifier of %zu points", nl);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    /* a halo point's own neighbourhood is cut at the halo's edge: its owner's values are the right ones */
    rc = asp__dist_fetch(d, pts->starts, r->cls, sizeof *r->cls, pts->ghost_gid, pts->n_ghost, r->cls + n, err);
    if (!rc)
        rc = asp__dist_fetch(d, pts->starts, r->tangent, 3 * sizeof *r->tangent, pts->ghost_gid, pts->n_ghost,
                             r->tangent + 3 * n, err);
    if (rc)
        return rc;
    info->amg.t_classifier = asp_time_now() - t;
    t = asp_time_now();
    rc = asp__amg_build_fans(pts->pos, r->tangent, &r->nb, r->desc.fan_k, &d->ctx, &r->fans, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp__amg_nbhd_release(&d->ctx, &r->nb);
    unsigned long long tri = 0;
    for (size_t i = 0; i < nl; i++) {
        if (i >= n)
            r->fans.ntri[i] = 0; /* a halo point's row belongs to its owner */
        tri += r->fans.ntri[i];
    }
    info->amg.mean_fan = (double)sum_all(d, tri) / (double)pts->n_global;
    info->amg.t_fans = asp_time_now() - t;
    t = asp_time_now();
    const int crease = r->desc.crease_cut > 0;
    size_t positive = 0;
    rc = asp__amg_assemble(pts->pos, r->cls, &r->fans, ASP_AMG_STIFFNESS_UNCLAMPED, &d->ctx, &r->la,
                           crease ? &r->lf : NULL, &positive, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp__amg_fans_release(&d->ctx, &r->fans);
    rc = global_rows(d, pts, &r->la, &r->lf, r->desc.stiffness, &r->a, &r->f, &info->amg.positive_offdiag, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp_amg_csr_destroy(r->la);
    asp_amg_csr_destroy(r->lf);
    r->la = r->lf = NULL;
    unsigned long long isolated = 0;
    for (size_t i = 0; i < n; i++)
        isolated += r->a->row_ptr[i + 1] - r->a->row_ptr[i] == 1;
    info->amg.isolated_points = (size_t)sum_all(d, isolated);
    info->amg.matrix_nnz = (size_t)sum_all(d, r->a->row_ptr[n]);
    if (info->amg.isolated_points == pts->n_global)
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot decompose %zu points: no point has a triangle fan (colinear or too sparse points)",
                             pts->n_global);
    info->amg.t_assembly = asp_time_now() - t;
    return 0;
}

int asp_amg_decompose_distributed(const char *in_path, const char *out_path, const asp_amg_desc *desc, double tau,
                                  const asp_context *ctx, asp_amg_dist_info *info, asp_error *err)
{
    run r;
    memset(&r, 0, sizeof r);
    if (ctx)
        r.d.ctx = *ctx;
    asp__dist *d = &r.d;
    asp_amg_dist_info inf;
    memset(&inf, 0, sizeof inf);
    if (info)
        memset(info, 0, sizeof *info);
    int rc = asp__dist_start(d, err);
    if (rc)
        return rc;
    const double t0 = asp_time_now();
    inf.rank = d->rank;
    inf.ranks = d->size;
    const int figures = tau != ASP_AMG_DIST_NO_FIGURES;
    if (figures && !(tau >= 0 && tau < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid domain threshold %g: expected a value in [0, 1)", tau);
    rc = asp__dist_read_sorted(d, in_path, &r.pts, err);
    if (!rc)
        rc = asp__dist_agree(d, asp__amg_resolve_desc(desc, r.pts.n_global, &r.desc, err), err);
    if (rc)
        goto done;
    r.auto_epsilon = r.desc.epsilon == 0;
    inf.points = r.pts.n_global;
    inf.own_points_min = SIZE_MAX;
    for (int q = 0; q < d->size; q++) {
        size_t c = r.pts.starts[q + 1] - r.pts.starts[q];
        inf.own_points_min = c < inf.own_points_min ? c : inf.own_points_min;
        inf.own_points_max = c > inf.own_points_max ? c : inf.own_points_max;
    }
    inf.t_read = asp_time_now() - t0;
    double t = asp_time_now();
    r.radius = asp_alloc(&d->ctx, (r.pts.n_own + 1) * sizeof *r.radius);
    /* on one rank there is no halo: the neighbourhoods find epsilon themselves, as in one process */
    rc = !r.radius ? asp_error_set(err, ASP_ENOMEM, "out of memory for %zu radii", r.pts.n_own)
         : d->size > 1 ? radii_and_epsilon(d, &r.pts, &r.desc, r.radius, err)
                       : 0;
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    inf.t_halo = asp_time_now() - t; /* the radii; the exchange is added to it */
    if ((rc = halo_and_neighbourhoods(&r, &inf, err)) != 0)
        goto done;
    asp_free(&d->ctx, r.radius); /* the halo is closed */
    r.radius = NULL;
    inf.halo_points = (size_t)sum_all(d, r.pts.n_ghost);
    if ((rc = local_stages(&r, &inf, err)) != 0)
        goto done;
    t = asp_time_now();
    rc = build_hierarchy(d, &r.pts, &r.a, r.f, r.cls, &r.desc, &r.h, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    asp_amg_csr_destroy(r.f);
    r.f = NULL;
    inf.amg.t_amg = asp_time_now() - t;
    inf.amg.repaired_rows = r.h.repaired;
    inf.amg.epsilon = r.desc.epsilon;
    inf.amg.k_min = r.desc.k_min;
    inf.amg.k_max = r.desc.k_max;
    inf.amg.fan_k = r.desc.fan_k;
    inf.nlevels = r.h.nlevels;
    t = asp_time_now();
    if (figures && (rc = basis_figures(d, &r.pts, &r.h, &r.desc, tau, &inf, err)) != 0)
        goto done;
    for (size_t l = 0; !figures && l < r.h.nlevels; l++)
        inf.level[l].unknowns = r.h.sizes[l];
    inf.t_stats = asp_time_now() - t;
    t = asp_time_now();
    if (out_path) {
        asp__dist_result res = {.pts = &r.pts, .tangent = r.tangent, .classifier = r.cls, .desc = &r.desc,
                                .nlevels = r.h.nlevels, .level_size = r.h.sizes, .prolong = r.h.p};
        frame_of(d, &r.pts, &res.frame);
        if ((rc = asp__dist_write_amg(d, &res, out_path, err)) != 0)
            goto done;
    }
    inf.t_write = asp_time_now() - t;
    inf.t_total = asp_time_now() - t0;
    double rss = peak_rss_mb();
    MPI_Allreduce(&rss, &inf.peak_rss_max_mb, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    MPI_Allreduce(&rss, &inf.peak_rss_mean_mb, 1, MPI_DOUBLE, MPI_SUM, d->comm);
    inf.peak_rss_mean_mb /= d->size;
    /* every rank reports rank 0's stage times */
    MPI_Bcast(&inf.amg, (int)sizeof inf.amg, MPI_BYTE, 0, d->comm);
    if (info)
        *info = inf;
done:
    if (rc && info) {
        memset(info, 0, sizeof *info);
        info->rank = inf.rank;
        info->ranks = inf.ranks;
    }
    run_release(&r);
    return rc;
}
#endif
