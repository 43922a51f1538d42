/*
 * Basis functions per level (journal 2.3): Psi^l = P^1 P^2 ... P^l evaluated at
 * the points. Entries below a tolerance are dropped after each product and the
 * row renormalised, so Psi stays sparse and remains a partition of unity.
 */
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amg/internal.h"
#include "util/banned.h"

/*
 * Row r of a*b into (col, val) sorted by column, dropped and renormalised.
 * acc (b->cols doubles, zero on entry and exit) and mark (b->cols bytes) are
 * the thread's dense accumulator; list receives the touched columns.
 */
static size_t product_row(const asp_amg_csr *a, const asp_amg_csr *b, size_t r, double drop, double *acc,
                          uint8_t *mark, asp_index *list, size_t listcap, asp_index *col, double *val)
{
    size_t cnt = 0;
    for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++) {
        double w = a->val[k];
        size_t br = a->col[k];
        for (size_t q = b->row_ptr[br]; q < b->row_ptr[br + 1]; q++) {
            asp_index c = b->col[q];
            if (!mark[c]) {
                mark[c] = 1;
                if (cnt < listcap)
                    list[cnt] = c;
                cnt++;
            }
            acc[c] += w * b->val[q];
        }
    }
    if (cnt > listcap)
        cnt = listcap; /* cannot happen: listcap bounds the product's row length */
    /* sort the touched columns: the accumulation order is fixed, so is the result */
    for (size_t q = 1; q < cnt; q++) {
        asp_index c = list[q];
        size_t s = q;
        while (s > 0 && list[s - 1] > c) {
            list[s] = list[s - 1];
            s--;
        }
        list[s] = c;
    }
    double kept = 0, best = -1;
    size_t best_at = 0;
    for (size_t q = 0; q < cnt; q++) {
        double v = acc[list[q]];
        if (v >= drop)
            kept += v;
        if (v > best) {
            best = v;
            best_at = q;
        }
    }
    size_t w = 0;
    for (size_t q = 0; q < cnt; q++) {
        asp_index c = list[q];
        double v = acc[c];
        /* never drop everything: a row's largest entry always survives */
        if (v >= drop || (kept == 0 && q == best_at)) {
            if (col) {
                col[w] = c;
                val[w] = v / (kept > 0 ? kept : v);
            }
            w++;
        }
        acc[c] = 0;
        mark[c] = 0;
    }
    return w;
}

static size_t max_row(const asp_amg_csr *m)
{
    size_t best = 0;
    for (size_t r = 0; r < m->rows; r++)
        if (m->row_ptr[r + 1] - m->row_ptr[r] > best)
            best = m->row_ptr[r + 1] - m->row_ptr[r];
    return best;
}

int asp__amg_spgemm_pou(const asp_amg_csr *a, const asp_amg_csr *b, double drop, const asp_context *ctx,
                        asp_amg_csr **out, asp_error *err)
{
    const int threads = asp_context_threads(ctx);
    const size_t n = a->rows, nc = b->cols;
    const size_t listcap = max_row(a) * max_row(b) + 1;
    double *acc = asp_calloc(ctx, (size_t)threads * nc, sizeof *acc);
    uint8_t *mark = asp_calloc(ctx, (size_t)threads * nc, 1);
    asp_index *list = asp_alloc(ctx, (size_t)threads * listcap * sizeof *list);
    size_t *cnt = asp_calloc(ctx, n + 1, sizeof *cnt);
    asp_amg_csr *c = NULL;
    int rc = 0;
    if (!acc || !mark || !list || !cnt) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the basis functions of %zu points", n);
        goto done;
    }
    if (drop < 0)
        drop = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            size_t total = 0;
            for (size_t i = 0; i < n; i++)
                total += cnt[i];
            rc = asp_amg_csr_create(n, nc, total, ctx, &c, err);
            if (rc)
                goto done;
            for (size_t i = 0; i < n; i++)
                c->row_ptr[i + 1] = c->row_ptr[i] + cnt[i];
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long ii = 0; ii < (long long)n; ii++) {
            size_t i = (size_t)ii;
            int t = 0;
#ifdef _OPENMP
            t = omp_get_thread_num();
#endif
            double *ac = acc + (size_t)t * nc;
            uint8_t *mk = mark + (size_t)t * nc;
            asp_index *ls = list + (size_t)t * listcap;
            if (pass == 0)
                cnt[i] = product_row(a, b, i, drop, ac, mk, ls, listcap, NULL, NULL);
            else
                product_row(a, b, i, drop, ac, mk, ls, listcap, c->col + c->row_ptr[i], c->val + c->row_ptr[i]);
        }
    }
    *out = c;
    c = NULL;
done:
    asp_amg_csr_destroy(c);
    asp_free(ctx, acc);
    asp_free(ctx, mark);
    asp_free(ctx, list);
    asp_free(ctx, cnt);
    return rc;
}

int asp_amg_basis(const asp_amg *amg, size_t level, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    if (level >= amg->nlevels)
        return asp_error_set(err, ASP_EINVAL, "no level %zu: the decomposition has levels 0..%zu", level,
                             amg->nlevels - 1);
    const size_t n = amg->cloud->count;
    asp_amg_csr *psi;
    /* Psi^0 is the identity: every point is its own basis function */
    int rc = asp_amg_csr_create(n, n, n, ctx, &psi, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++) {
        psi->row_ptr[i + 1] = i + 1;
        psi->col[i] = (asp_index)i;
        psi->val[i] = 1.0;
    }
    for (size_t l = 1; l <= level; l++) {
        asp_amg_csr *next;
        rc = asp__amg_spgemm_pou(psi, amg->prolong[l], amg->desc.drop_tol, ctx, &next, err);
        asp_amg_csr_destroy(psi);
        if (rc)
            return rc;
        psi = next;
    }
    *out = psi;
    return 0;
}
