/*
 * The basis Psi^l = P^1 ... P^l of a distributed decomposition as
 * row-distributed products (journal 2.3), and each level's domain figures
 * (journal eq. 8) over every rank, for decompose --stats.
 */
#ifdef ASP_HAVE_HYPRE
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amg/distributed.h"
#include "util/banned.h"

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
    unsigned long long points = asp__dist_sum(d, psi->rows);
    lv->unknowns = cst[d->size];
    lv->domains = (size_t)asp__dist_sum(d, dom);
    lv->strict_domains = (size_t)asp__dist_sum(d, sdom);
    lv->points_outside = (size_t)asp__dist_sum(d, outside);
    lv->mean_domains_per_point = points ? (double)asp__dist_sum(d, member) / (double)points : 0;
    MPI_Allreduce(&pou, &lv->max_pou_error, 1, MPI_DOUBLE, MPI_MAX, d->comm);
done:
    asp_free(&d->ctx, one);
    asp_free(&d->ctx, inside);
    asp_free(&d->ctx, strict);
    asp_free(&d->ctx, arg);
    return rc;
}

int asp__dist_basis_figures(const asp__dist *d, const asp__dist_points *pts, const asp__dist_hier *h,
                            const asp_amg_desc *desc, double tau, asp_amg_dist_info *info, asp_error *err)
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
#else
typedef int asp__dist_basis_unused;
#endif
