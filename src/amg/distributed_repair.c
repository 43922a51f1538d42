/*
 * The repairs of one level of the distributed hierarchy (issue 19): the rows
 * of P that parallel coarsening leaves empty at rank borders, the partition
 * of unity with orphans numbered per rank, the coarse matrix renumbered
 * around them, the masses carried to the coarse unknowns, and the filter of
 * the next level's matrix. The row kernels are level_rows.c's, those of the
 * serial hierarchy (hierarchy.c); what they need of other ranks' rows is
 * fetched here first.
 */
#ifdef ASP_HAVE_HYPRE
#include <stdlib.h>
#include <string.h>

#include "amg/distributed.h"
#include "util/banned.h"

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
int asp__dist_fill_empty_rows(const asp__dist *d, asp_amg_csr **pp, const asp_amg_csr *a, const size_t *st,
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
    if (asp__dist_sum(d, m) == 0) {
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
            /* renormalised with the rest in asp__dist_repair */
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
int asp__dist_repair(const asp__dist *d, asp_amg_csr **pp, const size_t *cst, size_t *nst, size_t *repaired,
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
int asp__dist_renumber_coarse(const asp__dist *d, asp_amg_csr **pac, const size_t *cst, const size_t *nst,
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
int asp__dist_carry(const asp__dist *d, const asp_amg_csr *p, const size_t *nst, const double *src, double *dst,
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
 * level_rows.c's crease test and filter (hierarchy.c's filter_coarse) on the
 * local rows of ac: the crease decision for (r, c) is taken in both rows from
 * the same symmetric quantities (it was mirrored from the smaller index
 * serially); the strongest couplings of small unknowns come from their owners.
 */
int asp__dist_filter(const asp__dist *d, const asp_amg_csr *ac, const asp_amg_csr *fc, const size_t *nst,
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
    *offdiag = (size_t)asp__dist_sum(d, w);
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
#else
typedef int asp__dist_repair_unused;
#endif
