/*
 * Compressed sparse row matrices for the AMG hierarchy (journal 2.2-2.3) and
 * the stiffness-matrix invariant check of journal eq. 6-7.
 */
#include <math.h>
#include <string.h>

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

/* Value of a(r, c) by binary search in the sorted row; 0 when absent. */
static double entry(const asp_amg_csr *a, size_t r, asp_index c)
{
    size_t lo = a->row_ptr[r], hi = a->row_ptr[r + 1];
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (a->col[mid] < c)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < a->row_ptr[r + 1] && a->col[lo] == c ? a->val[lo] : 0.0;
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
            double asym = fabs(a->val[k] - entry(a, c, (asp_index)r));
            if (asym > out->max_asymmetry)
                out->max_asymmetry = asym;
        }
        if (!offdiag)
            out->empty_rows++;
        if (fabs(sum) > out->max_row_sum)
            out->max_row_sum = fabs(sum);
        if (entry(a, r, (asp_index)r) == 0.0 && 0.0 < out->min_diag)
            out->min_diag = 0.0;
    }
    if (out->max_offdiag == -INFINITY)
        out->max_offdiag = 0.0;
    if (out->min_diag == INFINITY)
        out->min_diag = 0.0;
}
