/*
 * The row kernels of one coarse level of the AMG hierarchy (journal 2.3,
 * thesis 2.4), shared by the serial hierarchy (hierarchy.c) and the
 * distributed one (distributed_hierarchy.c, issue 26): the repair of P's
 * rows into a partition of unity, the scale of a coupling, a small unknown's
 * strongest coupling, the crease test of one coupling and the filter that
 * makes the next level's matrix. Each works on rows with a first global row
 * row0 (0 in one process), so a rank runs it on its own rows; what the rows
 * need from other ranks the caller brings as per-entry arrays.
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

static double positive_sum(const asp_amg_csr *p, size_t r)
{
    double s = 0;
    for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
        if (p->val[k] > 0)
            s += p->val[k];
    return s;
}

size_t asp__amg_empty_rows(const asp_amg_csr *p)
{
    size_t n = 0;
    for (size_t r = 0; r < p->rows; r++)
        n += !(positive_sum(p, r) > 1e-12);
    return n;
}

size_t asp__amg_pou_rows(const asp_amg_csr *p, asp_amg_csr *q, asp_index first_orphan,
                         asp_index (*map)(asp_index c, const void *arg), const void *arg, size_t *repaired)
{
    size_t w = 0;
    asp_index next_orphan = first_orphan;
    for (size_t r = 0; r < p->rows; r++) {
        const double s = positive_sum(p, r);
        if (!(s > 1e-12)) {
            q->col[w] = next_orphan++;
            q->val[w++] = 1.0;
            (*repaired)++;
        } else {
            /*
             * Classical interpolation of a zero-row-sum M-matrix already sums
             * to 1; truncation or a clamped negative weight does not, so
             * renormalise (the correction is at rounding level otherwise).
             */
            if (fabs(s - 1.0) > 1e-9)
                (*repaired)++;
            for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
                if (p->val[k] > 0) {
                    q->col[w] = map ? map(p->col[k], arg) : p->col[k];
                    q->val[w++] = p->val[k] / s;
                }
        }
        q->row_ptr[r + 1] = w;
    }
    return next_orphan - first_orphan;
}

void asp__amg_coupling_hist(const asp_amg_csr *a, size_t row0, uint64_t hist[256])
{
    /* a histogram of log2 magnitudes is enough for a threshold scale and needs no sort */
    for (size_t r = 0; r < a->rows; r++)
        for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
            if (a->col[k] != row0 + r) {
                int e = 0;
                frexp(fabs(a->val[k]), &e);
                e += 128;
                hist[e < 0 ? 0 : e > 255 ? 255 : e]++;
            }
}

double asp__amg_hist_median(const uint64_t hist[256])
{
    uint64_t cnt = 0, acc = 0;
    for (int b = 0; b < 256; b++)
        cnt += hist[b];
    for (int b = 0; b < 256 && cnt; b++) {
        acc += hist[b];
        if (2 * acc >= cnt)
            return ldexp(0.75, b - 128); /* middle of the bin [2^(e-1), 2^e) */
    }
    return 0;
}

asp_index asp__amg_strongest(const asp_amg_csr *a, size_t r, size_t row0)
{
    asp_index best = UINT32_MAX;
    double v = 0;
    for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
        if (a->col[k] != row0 + r && a->val[k] < v) {
            v = a->val[k];
            best = a->col[k];
        }
    return best;
}

int asp__amg_crease(double a, double f, double ratio, double cmean_r, double cmean_c)
{
    /* no geometric coupling to compare with (f >= 0): keep, the test cannot tell */
    return f < 0 && a / f < ratio * fmin(cmean_r, cmean_c);
}

/* Whether entry k of local row r survives the filter (f->best_col: the column's choice, else best[col]). */
static int keep(const asp_amg_csr *ac, const asp__amg_filter *f, size_t r, size_t k)
{
    const asp_index c = ac->col[k], self = (asp_index)(f->row0 + r);
    const asp_index their = f->best_col ? f->best_col[k] : f->best[c];
    return c != self && ((-ac->val[k] >= f->cut && !(f->crease && f->crease[k])) || f->best[r] == c || their == self);
}

size_t asp__amg_filter_count(const asp_amg_csr *ac, const asp__amg_filter *f)
{
    size_t nnz = 0;
    for (size_t r = 0; r < ac->rows; r++)
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++)
            nnz += (size_t)keep(ac, f, r, k);
    return nnz;
}

size_t asp__amg_filter_rows(const asp_amg_csr *ac, const asp__amg_filter *f, asp_amg_csr *m)
{
    size_t w = 0;
    for (size_t r = 0; r < m->rows; r++) {
        size_t diag = SIZE_MAX;
        double sum = 0;
        if (r < ac->rows)
            for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
                /* a positive Galerkin entry is never kept: the matrix stays an M-matrix */
                if (!keep(ac, f, r, k) || ac->val[k] >= 0)
                    continue;
                if (diag == SIZE_MAX && ac->col[k] > f->row0 + r)
                    diag = w++;
                sum += ac->val[k];
                m->col[w] = ac->col[k];
                m->val[w++] = ac->val[k];
            }
        if (diag == SIZE_MAX)
            diag = w++;
        m->col[diag] = (asp_index)(f->row0 + r);
        m->val[diag] = -sum;
        m->row_ptr[r + 1] = w;
    }
    return w - m->rows;
}
