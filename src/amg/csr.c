/*
 * Compressed sparse row matrices for the AMG hierarchy (journal 2.2-2.3): the
 * stiffness-matrix invariant check of journal eq. 6-7, and the Galerkin
 * product P^T F P (journal 2.3) for matrices hypre does not coarsen itself.
 */
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amg/internal.h"
#include "util/banned.h"

int asp_amg_csr_create(size_t rows, size_t cols, size_t nnz, const asp_context *ctx, asp_amg_csr **out,
                       asp_error *err)
{
    if (rows > UINT32_MAX || cols > UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "matrix of %zu x %zu exceeds 2^32-1 rows or columns", rows, cols);
    asp_amg_csr *m = asp_calloc(ctx, 1, sizeof *m);
    if (!m)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a sparse matrix");
    if (ctx)
        m->ctx = *ctx;
    m->rows = rows;
    m->cols = cols;
    m->row_ptr = asp_calloc(ctx, rows + 1, sizeof *m->row_ptr);
    m->col = asp_calloc(ctx, nnz ? nnz : 1, sizeof *m->col);
    m->val = asp_calloc(ctx, nnz ? nnz : 1, sizeof *m->val);
    if (!m->row_ptr || !m->col || !m->val) {
        asp_amg_csr_destroy(m);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a sparse matrix of %zu non-zeros", nnz);
    }
    *out = m;
    return 0;
}

void asp_amg_csr_destroy(asp_amg_csr *m)
{
    if (!m)
        return;
    asp_context ctx = m->ctx;
    asp_free(&ctx, m->row_ptr);
    asp_free(&ctx, m->col);
    asp_free(&ctx, m->val);
    asp_free(&ctx, m);
}

size_t asp__amg_csr_find(const asp_amg_csr *m, size_t r, asp_index c)
{
    size_t lo = m->row_ptr[r], hi = m->row_ptr[r + 1];
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (m->col[mid] < c)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < m->row_ptr[r + 1] && m->col[lo] == c ? lo : SIZE_MAX;
}

void asp_amg_csr_check_stiffness(const asp_amg_csr *a, asp_amg_matrix_check *out)
{
    memset(out, 0, sizeof *out);
    out->max_offdiag = -INFINITY;
    out->min_diag = INFINITY;
    for (size_t r = 0; r < a->rows; r++) {
        double sum = 0.0;
        int offdiag = 0;
        for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++) {
            asp_index c = a->col[k];
            sum += a->val[k];
            if (c == r) {
                if (a->val[k] < out->min_diag)
                    out->min_diag = a->val[k];
                continue;
            }
            offdiag = 1;
            if (a->val[k] > out->max_offdiag)
                out->max_offdiag = a->val[k];
            double asym = fabs(a->val[k] - asp__amg_csr_entry(a, c, (asp_index)r));
            if (asym > out->max_asymmetry)
                out->max_asymmetry = asym;
        }
        if (!offdiag)
            out->empty_rows++;
        if (fabs(sum) > out->max_row_sum)
            out->max_row_sum = fabs(sum);
        if (asp__amg_csr_entry(a, r, (asp_index)r) == 0.0 && 0.0 < out->min_diag)
            out->min_diag = 0.0;
    }
    if (out->max_offdiag == -INFINITY)
        out->max_offdiag = 0.0;
    if (out->min_diag == INFINITY)
        out->min_diag = 0.0;
}

/* Transpose of p (cols x rows), rows sorted by column because the scan is in row order. */
static int transpose(const asp_amg_csr *p, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    const size_t nnz = p->row_ptr[p->rows];
    asp_amg_csr *t;
    int rc = asp_amg_csr_create(p->cols, p->rows, nnz, ctx, &t, err);
    if (rc)
        return rc;
    size_t *fill = asp_alloc(ctx, (p->cols + 1) * sizeof *fill);
    if (!fill) {
        asp_amg_csr_destroy(t);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a sparse transpose");
    }
    for (size_t k = 0; k < nnz; k++)
        t->row_ptr[p->col[k] + 1]++;
    for (size_t c = 0; c < p->cols; c++)
        t->row_ptr[c + 1] += t->row_ptr[c];
    memcpy(fill, t->row_ptr, (p->cols + 1) * sizeof *fill);
    for (size_t r = 0; r < p->rows; r++)
        for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++) {
            size_t w = fill[p->col[k]]++;
            t->col[w] = (asp_index)r;
            t->val[w] = p->val[k];
        }
    asp_free(ctx, fill);
    *out = t;
    return 0;
}

/*
 * Row I of P^T F P into (col, val), columns in the order first reached (not
 * sorted); returns its length. acc
 * and mark are the thread's dense accumulator over the coarse columns (zero on
 * entry and exit), list (capacity listcap) the touched columns.
 */
static size_t rap_row(const asp_amg_csr *pt, const asp_amg_csr *f, const asp_amg_csr *p, size_t row, double *acc,
                      uint8_t *mark, asp_index *list, size_t listcap, asp_index *col, double *val)
{
    size_t cnt = 0;
    for (size_t a = pt->row_ptr[row]; a < pt->row_ptr[row + 1]; a++) {
        const size_t i = pt->col[a];
        const double wi = pt->val[a];
        for (size_t b = f->row_ptr[i]; b < f->row_ptr[i + 1]; b++) {
            const size_t k = f->col[b];
            const double wik = wi * f->val[b];
            for (size_t c = p->row_ptr[k]; c < p->row_ptr[k + 1]; c++) {
                asp_index j = p->col[c];
                if (!mark[j]) {
                    mark[j] = 1;
                    if (cnt < listcap)
                        list[cnt] = j;
                    cnt++;
                }
                acc[j] += wik * p->val[c];
            }
        }
    }
    if (cnt > listcap)
        cnt = listcap; /* cannot happen: listcap is the number of coarse columns */
    /* columns stay in the order first touched: fixed by the input, so any thread count gives the same row */
    for (size_t q = 0; q < cnt; q++) {
        if (col) {
            col[q] = list[q];
            val[q] = acc[list[q]];
        }
        acc[list[q]] = 0;
        mark[list[q]] = 0;
    }
    return cnt;
}

/* Length of row I of P^T F P: the columns rap_row would write, counted without the products. */
static size_t rap_count(const asp_amg_csr *pt, const asp_amg_csr *f, const asp_amg_csr *p, size_t row, uint8_t *mark,
                        asp_index *list)
{
    size_t cnt = 0;
    for (size_t a = pt->row_ptr[row]; a < pt->row_ptr[row + 1]; a++) {
        const size_t i = pt->col[a];
        for (size_t b = f->row_ptr[i]; b < f->row_ptr[i + 1]; b++) {
            const size_t k = f->col[b];
            for (size_t c = p->row_ptr[k]; c < p->row_ptr[k + 1]; c++) {
                asp_index j = p->col[c];
                if (!mark[j]) {
                    mark[j] = 1;
                    list[cnt++] = j;
                }
            }
        }
    }
    for (size_t q = 0; q < cnt; q++)
        mark[list[q]] = 0;
    return cnt;
}

int asp__amg_galerkin(const asp_amg_csr *p, const asp_amg_csr *f, const asp_context *ctx, asp_amg_csr **out,
                      asp_error *err)
{
    const int threads = asp_context_threads(ctx);
    const size_t nc = p->cols;
    asp_amg_csr *pt = NULL, *c = NULL;
    double *acc = asp_calloc(ctx, (size_t)threads * nc, sizeof *acc);
    uint8_t *mark = asp_calloc(ctx, (size_t)threads * nc, 1);
    asp_index *list = asp_alloc(ctx, (size_t)threads * nc * sizeof *list);
    size_t *cnt = asp_calloc(ctx, nc + 1, sizeof *cnt);
    int rc = 0;
    if (!acc || !mark || !list || !cnt) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a coarse matrix of %zu rows", nc);
        goto done;
    }
    if ((rc = transpose(p, ctx, &pt, err)) != 0)
        goto done;
    /*
     * A counting pass, then the filling pass straight into the result: twice
     * the products, but no slots of a per-row upper bound, which at the first
     * level held several times the result (issue 19: the AMG stage's peak).
     */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long rr = 0; rr < (long long)nc; rr++) {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        cnt[rr] = rap_count(pt, f, p, (size_t)rr, mark + (size_t)t * nc, list + (size_t)t * nc);
    }
    size_t total = 0;
    for (size_t r = 0; r < nc; r++)
        total += cnt[r];
    if ((rc = asp_amg_csr_create(nc, nc, total, ctx, &c, err)) != 0)
        goto done;
    for (size_t r = 0; r < nc; r++)
        c->row_ptr[r + 1] = c->row_ptr[r] + cnt[r];
    /* each row is summed in the same fixed order, so any thread count gives the same bits */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long rr = 0; rr < (long long)nc; rr++) {
        size_t r = (size_t)rr;
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        rap_row(pt, f, p, r, acc + (size_t)t * nc, mark + (size_t)t * nc, list + (size_t)t * nc, nc,
                c->col + c->row_ptr[r], c->val + c->row_ptr[r]);
    }
    *out = c;
    c = NULL;
done:
    asp_amg_csr_destroy(pt);
    asp_amg_csr_destroy(c);
    asp_free(ctx, acc);
    asp_free(ctx, mark);
    asp_free(ctx, list);
    asp_free(ctx, cnt);
    return rc;
}
