/*
 * Domain neighbours for rendering (journal section 4, Fig. 11): two domains
 * are neighbours when their common points exceed a fraction (0.05 in the
 * journal) of either domain's points, so that slightly overlapping domains
 * are not blended together.
 */
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "prim/internal.h"
#include "util/banned.h"

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* Neighbours of row a into out (capacity rows); returns how many. count/touched: per-thread scratch. */
static size_t row_neighbours(const asp_amg_csr *dom, const size_t *pt_first, const uint32_t *pt_dom, double fraction,
                             size_t a, uint32_t *count, uint32_t *touched, uint32_t *out)
{
    size_t nt = 0, m = 0;
    for (size_t k = dom->row_ptr[a]; k < dom->row_ptr[a + 1]; k++) {
        size_t p = dom->col[k];
        for (size_t q = pt_first[p]; q < pt_first[p + 1]; q++) {
            uint32_t b = pt_dom[q];
            if (b == a)
                continue;
            if (count[b]++ == 0)
                touched[nt++] = b;
        }
    }
    double na = (double)(dom->row_ptr[a + 1] - dom->row_ptr[a]);
    for (size_t k = 0; k < nt; k++) {
        uint32_t b = touched[k];
        double nb = (double)(dom->row_ptr[b + 1] - dom->row_ptr[b]), common = count[b];
        if (common > fraction * na || common > fraction * nb)
            out[m++] = b;
        count[b] = 0;
    }
    qsort(out, m, sizeof *out, cmp_u32);
    return m;
}

int asp_prim_neighbours(const asp_amg_csr *dom, double fraction, const asp_context *ctx, size_t *first,
                        uint32_t **list, size_t *total, asp_error *err)
{
    if (!dom || !first || !list || !total || !(fraction > 0 && fraction < 1))
        return asp_error_set(err, ASP_EINVAL, "neighbour fraction must be in (0, 1), got %g", fraction);
    const size_t rows = dom->rows, pts = dom->cols, nnz = dom->row_ptr[rows];
    int threads = asp_context_threads(ctx);
    size_t *pt_first = asp_calloc(ctx, pts + 1, sizeof *pt_first);
    uint32_t *pt_dom = asp_alloc(ctx, (nnz ? nnz : 1) * sizeof *pt_dom);
    uint32_t *scratch = asp_calloc(ctx, (size_t)threads * 3 * (rows ? rows : 1), sizeof *scratch);
    size_t *cnt = asp_calloc(ctx, rows + 1, sizeof *cnt);
    uint32_t *out = NULL;
    int rc = 0;
    if (!pt_first || !pt_dom || !scratch || !cnt) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the neighbours of %zu domains", rows);
        goto done;
    }
    /* transpose: the domains of each point, in increasing domain order */
    for (size_t k = 0; k < nnz; k++)
        pt_first[dom->col[k] + 1]++;
    for (size_t p = 0; p < pts; p++)
        pt_first[p + 1] += pt_first[p];
    for (size_t a = 0; a < rows; a++)
        for (size_t k = dom->row_ptr[a]; k < dom->row_ptr[a + 1]; k++)
            pt_dom[pt_first[dom->col[k]]++] = (uint32_t)a;
    for (size_t p = pts; p > 0; p--)
        pt_first[p] = pt_first[p - 1];
    pt_first[0] = 0;

    long nrows = (long)rows;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long a = 0; a < nrows; a++) {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        uint32_t *s = scratch + (size_t)tid * 3 * rows;
        cnt[a + 1] = row_neighbours(dom, pt_first, pt_dom, fraction, (size_t)a, s, s + rows, s + 2 * rows);
    }
    for (size_t a = 0; a < rows; a++)
        cnt[a + 1] += cnt[a];
    out = asp_alloc(ctx, (cnt[rows] ? cnt[rows] : 1) * sizeof *out);
    if (!out) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu neighbour entries", cnt[rows]);
        goto done;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long a = 0; a < nrows; a++) {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        uint32_t *s = scratch + (size_t)tid * 3 * rows;
        size_t m = row_neighbours(dom, pt_first, pt_dom, fraction, (size_t)a, s, s + rows, s + 2 * rows);
        memcpy(out + cnt[a], s + 2 * rows, m * sizeof *out);
    }
    memcpy(first, cnt, (rows + 1) * sizeof *first);
    *list = out;
    *total = cnt[rows];
    out = NULL;
done:
    asp_free(ctx, out);
    asp_free(ctx, pt_first);
    asp_free(ctx, pt_dom);
    asp_free(ctx, scratch);
    asp_free(ctx, cnt);
    return rc;
}
