/*
 * The one numbering of points for the decomposition (issue 19): Morton
 * (Z-curve) order of the coordinates quantised to 2^21 steps per axis over
 * the bounding box of the float positions, ties in input order.
 *
 * Why one order: RS coarsening (journal 2.3) takes its C points greedily and
 * breaks ties by the number of the unknown, so two numberings of the same
 * matrix give different hierarchies, and the differences grow down the
 * levels (on a 4M-point bunny the input order and the Morton order of the
 * same points gave 104 and 114 unknowns on level 13). The distributed
 * decomposition must number points along a space-filling curve to give each
 * rank a compact piece of the surface; numbering the serial decomposition the
 * same way makes one rank give exactly the serial hierarchy and P ranks differ
 * only by where the rank borders cut. The curve also keeps neighbours close in
 * memory for the kNN search, the fans, the assembly and hypre.
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

/* 21 bits spread to every third bit. */
static uint64_t spread(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

double asp__amg_morton_scale(const float lo[3], const float hi[3])
{
    double ext = 0;
    for (int k = 0; k < 3; k++)
        ext = fmax(ext, (double)hi[k] - lo[k]);
    return ext > 0 ? 2097151.0 / ext : 0;
}

uint64_t asp__amg_morton_key(const float p[3], const float lo[3], double scale)
{
    uint64_t q[3];
    for (int k = 0; k < 3; k++)
        q[k] = (uint64_t)(((double)p[k] - lo[k]) * scale);
    return spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2;
}

typedef struct keyed {
    uint64_t key;
    asp_index index;
} keyed;

int asp__amg_morton_order(const float *pos, size_t n, const asp_context *ctx, asp_index **out, asp_error *err)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], pos[3 * i + k]);
            hi[k] = fmaxf(hi[k], pos[3 * i + k]);
        }
    const double scale = asp__amg_morton_scale(lo, hi);
    keyed *a = asp_alloc(ctx, (n + 1) * sizeof *a), *b = asp_alloc(ctx, (n + 1) * sizeof *b);
    size_t *count = asp_alloc(ctx, 65536 * sizeof *count);
    asp_index *order = asp_alloc(ctx, (n + 1) * sizeof *order);
    if (!a || !b || !count || !order) {
        asp_free(ctx, a);
        asp_free(ctx, b);
        asp_free(ctx, count);
        asp_free(ctx, order);
        return asp_error_set(err, ASP_ENOMEM, "out of memory ordering %zu points along the Morton curve", n);
    }
    for (size_t i = 0; i < n; i++) {
        a[i].key = asp__amg_morton_key(pos + 3 * i, lo, scale);
        a[i].index = (asp_index)i;
    }
    /* LSD radix sort by 16-bit digits: stable, so equal keys keep the input order (the distributed tie rule) */
    for (int shift = 0; shift < 64; shift += 16) {
        memset(count, 0, 65536 * sizeof *count);
        for (size_t i = 0; i < n; i++)
            count[(a[i].key >> shift) & 0xffff]++;
        if (n && count[(a[0].key >> shift) & 0xffff] == n)
            continue; /* every key has this digit: the pass would not move anything */
        size_t at = 0;
        for (size_t d = 0; d < 65536; d++) {
            size_t c = count[d];
            count[d] = at;
            at += c;
        }
        for (size_t i = 0; i < n; i++)
            b[count[(a[i].key >> shift) & 0xffff]++] = a[i];
        keyed *t = a;
        a = b;
        b = t;
    }
    for (size_t i = 0; i < n; i++)
        order[i] = a[i].index;
    asp_free(ctx, a);
    asp_free(ctx, b);
    asp_free(ctx, count);
    *out = order;
    return 0;
}

int asp__amg_unpermute(void *data, size_t n, size_t elem, const asp_index *order, const asp_context *ctx,
                       asp_error *err)
{
    unsigned char *tmp = asp_alloc(ctx, n * elem + 1), *d = data;
    if (!tmp)
        return asp_error_set(err, ASP_ENOMEM, "out of memory returning %zu points to the input order", n);
    for (size_t m = 0; m < n; m++)
        memcpy(tmp + (size_t)order[m] * elem, d + m * elem, elem);
    memcpy(d, tmp, n * elem);
    asp_free(ctx, tmp);
    return 0;
}

int asp__amg_csr_unpermute(asp_amg_csr **pm, const asp_index *order, int columns_too, const asp_context *ctx,
                           asp_error *err)
{
    const asp_amg_csr *m = *pm;
    const size_t rows = m->rows;
    asp_amg_csr *q;
    int rc = asp_amg_csr_create(rows, m->cols, m->row_ptr[rows], ctx, &q, err);
    if (rc)
        return rc;
    for (size_t r = 0; r < rows; r++)
        q->row_ptr[(size_t)order[r] + 1] = m->row_ptr[r + 1] - m->row_ptr[r];
    for (size_t r = 0; r < rows; r++)
        q->row_ptr[r + 1] += q->row_ptr[r];
    for (size_t r = 0; r < rows; r++) {
        const size_t b = q->row_ptr[order[r]];
        size_t w = b;
        for (size_t k = m->row_ptr[r]; k < m->row_ptr[r + 1]; k++, w++) {
            asp_index c = columns_too ? order[m->col[k]] : m->col[k];
            double v = m->val[k];
            size_t p = w;
            /* keep the columns of a row increasing: rows hold a handful of entries */
            while (columns_too && p > b && q->col[p - 1] > c) {
                q->col[p] = q->col[p - 1];
                q->val[p] = q->val[p - 1];
                p--;
            }
            q->col[p] = c;
            q->val[p] = v;
        }
    }
    asp_amg_csr_destroy(*pm);
    *pm = q;
    return 0;
}
