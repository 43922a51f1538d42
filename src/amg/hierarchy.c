/*
 * Keeps the AMG hierarchy a partition of unity (journal 2.3, thesis 2.4):
 * every row of every P^l must hold non-negative weights summing to 1. hypre
 * leaves the rows of unknowns without strong connections empty (a point with
 * no fan neighbour, or a whole disconnected part that coarsened to a single
 * unknown); such an unknown becomes an "orphan" that is carried unchanged to
 * every coarser level, so a disconnected part stays its own domain.
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

/* Rebuilds p (hypre rows x hypre cols) with carried orphans (carried) and new ones; returns the new count. */
static int repair_level(asp_amg_csr **pp, size_t carried, const asp_context *ctx, size_t *new_orphans,
                        size_t *repaired, asp_error *err)
{
    const asp_amg_csr *p = *pp;
    size_t rows = p->rows + carried, orphans = 0;
    for (size_t r = 0; r < p->rows; r++) {
        double s = 0;
        for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
            if (p->val[k] > 0)
                s += p->val[k];
        if (!(s > 1e-12))
            orphans++;
    }
    size_t cols = p->cols + carried + orphans;
    asp_amg_csr *q;
    int rc = asp_amg_csr_create(rows, cols, p->row_ptr[p->rows] + carried + orphans, ctx, &q, err);
    if (rc)
        return rc;
    size_t w = 0, next_orphan = p->cols + carried;
    for (size_t r = 0; r < p->rows; r++) {
        double s = 0;
        for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
            if (p->val[k] > 0)
                s += p->val[k];
        if (!(s > 1e-12)) {
            q->col[w] = (asp_index)next_orphan++;
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
                    q->col[w] = p->col[k];
                    q->val[w++] = p->val[k] / s;
                }
        }
        q->row_ptr[r + 1] = w;
    }
    for (size_t o = 0; o < carried; o++) {
        q->col[w] = (asp_index)(p->cols + o);
        q->val[w++] = 1.0;
        q->row_ptr[p->rows + o + 1] = w;
    }
    asp_amg_csr_destroy(*pp);
    *pp = q;
    *new_orphans = orphans;
    return 0;
}

/* Column of the most negative off-diagonal entry of row r of a, or UINT32_MAX. */
static asp_index strongest(const asp_amg_csr *a, size_t r)
{
    asp_index best = UINT32_MAX;
    double v = 0;
    for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
        if (a->col[k] != r && a->val[k] < v) {
            v = a->val[k];
            best = a->col[k];
        }
    return best;
}

/*
 * Appends zero rows for the orphans and cuts couplings weaker than cut
 * (absolute). BoomerAMG's strength test is relative to each row, so once a
 * flat part has become one unknown, its weak couplings across creases look
 * strong and AMG would merge parts the classifier separated (journal 2.3:
 * "domains stop at creases"). A small unknown (mass below a quarter of the
 * level's mean, e.g. a sliver along a crease) keeps its strongest coupling so
 * it joins a neighbour instead of surviving as a tiny domain. Rows keep zero
 * sums (eq. 7) and the matrix stays symmetric.
 */
static int filter_coarse(const asp_amg_csr *ac, size_t size, double cut, const double *mass, double small,
                         const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    asp_index *best = asp_alloc(ctx, (ac->rows + 1) * sizeof *best);
    if (!best)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    for (size_t r = 0; r < ac->rows; r++)
        best[r] = mass[r] < small ? strongest(ac, r) : UINT32_MAX;
#define KEEP(r, k) (ac->col[k] != (r) && (-ac->val[k] >= cut || best[r] == ac->col[k] || best[ac->col[k]] == (r)))
    size_t nnz = 0;
    for (size_t r = 0; r < ac->rows; r++)
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++)
            nnz += KEEP(r, k);
    asp_amg_csr *m;
    int rc = asp_amg_csr_create(size, size, nnz + size, ctx, &m, err);
    if (rc) {
        asp_free(ctx, best);
        return rc;
    }
    size_t w = 0;
    for (size_t r = 0; r < size; r++) {
        size_t diag = SIZE_MAX;
        double sum = 0;
        if (r < ac->rows)
            for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
                /* a positive Galerkin entry is never kept: the matrix stays an M-matrix */
                if (!KEEP(r, k) || ac->val[k] >= 0)
                    continue;
                if (diag == SIZE_MAX && ac->col[k] > r)
                    diag = w++;
                sum += ac->val[k];
                m->col[w] = ac->col[k];
                m->val[w++] = ac->val[k];
            }
        if (diag == SIZE_MAX)
            diag = w++;
        m->col[diag] = (asp_index)r;
        m->val[diag] = -sum;
        m->row_ptr[r + 1] = w;
    }
#undef KEEP
    m->row_ptr[size] = w;
    asp_free(ctx, best);
    *out = m;
    return 0;
}

/* Median |a_ij| over the off-diagonal entries: the scale of a coupling on this model. */
static double median_coupling(const asp_amg_csr *a, const asp_context *ctx)
{
    size_t cnt = 0;
    for (size_t r = 0; r < a->rows; r++)
        for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
            cnt += a->col[k] != r;
    if (cnt == 0)
        return 0;
    /* a histogram of log2 magnitudes is enough for a threshold scale and needs no sort */
    size_t hist[256] = {0};
    for (size_t r = 0; r < a->rows; r++)
        for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
            if (a->col[k] != r) {
                int e = 0;
                frexp(fabs(a->val[k]), &e);
                e += 128;
                hist[e < 0 ? 0 : e > 255 ? 255 : e]++;
            }
    (void)ctx;
    size_t acc = 0;
    for (int b = 0; b < 256; b++) {
        acc += hist[b];
        if (2 * acc >= cnt)
            return ldexp(0.75, b - 128); /* middle of the bin [2^(e-1), 2^e) */
    }
    return 0;
}

int asp__amg_build_hierarchy(const asp_amg_csr *a0, const asp_amg_desc *desc, const asp_context *ctx,
                             size_t *nlevels, asp_amg_csr ***p_out, size_t **sizes_out, size_t *repaired,
                             asp_error *err)
{
    const size_t maxl = desc->max_levels;
    asp_amg_csr **p = asp_calloc(ctx, maxl, sizeof *p);
    size_t *sizes = asp_calloc(ctx, maxl, sizeof *sizes);
    const asp_amg_csr *cur = a0;
    asp_amg_csr *owned = NULL;
    size_t levels = 1;
    double *mass = NULL, *nmass = NULL;
    int rc = 0;
    if (!p || !sizes) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        goto done;
    }
    sizes[0] = a0->rows;
    mass = asp_alloc(ctx, a0->rows * sizeof *mass);
    nmass = asp_alloc(ctx, a0->rows * sizeof *nmass);
    if (!mass || !nmass) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        goto done;
    }
    for (size_t i = 0; i < a0->rows; i++)
        mass[i] = 1.0;
    const double cut = desc->weak_coupling > 0 ? desc->weak_coupling * median_coupling(a0, ctx) : 0;
    while (levels < maxl && cur->rows > desc->max_coarse) {
        asp_amg_csr *praw = NULL, *araw = NULL, *next = NULL;
        rc = asp__amg_hypre_coarsen(cur, desc, ctx, &praw, &araw, err);
        if (rc)
            goto done;
        if (!praw) {
            asp_amg_csr_destroy(araw);
            break;
        }
        size_t fresh = 0;
        rc = repair_level(&praw, 0, ctx, &fresh, repaired, err);
        if (!rc) {
            /* mass of a coarse unknown: how many points its basis function covers */
            memset(nmass, 0, praw->cols * sizeof *nmass);
            for (size_t r = 0; r < praw->rows; r++)
                for (size_t k = praw->row_ptr[r]; k < praw->row_ptr[r + 1]; k++)
                    nmass[praw->col[k]] += praw->val[k] * mass[r];
            double *t = mass;
            mass = nmass;
            nmass = t;
            rc = filter_coarse(araw, praw->cols, cut, mass, 0.25 * (double)a0->rows / (double)praw->cols, ctx, &next,
                               err);
        }
        asp_amg_csr_destroy(araw);
        if (rc) {
            asp_amg_csr_destroy(praw);
            goto done;
        }
        if (praw->cols >= cur->rows) {
            /* nothing left to merge: every unknown is its own part of the surface */
            asp_amg_csr_destroy(praw);
            asp_amg_csr_destroy(next);
            break;
        }
        p[levels] = praw;
        sizes[levels] = praw->cols;
        levels++;
        asp_amg_csr_destroy(owned);
        owned = next;
        cur = next;
        if ((rc = asp_progress(ctx, "amg", (double)levels / (double)maxl)) != 0) {
            asp_error_set(err, rc, "decomposition canceled during amg");
            goto done;
        }
    }
done:
    asp_amg_csr_destroy(owned);
    asp_free(ctx, mass);
    asp_free(ctx, nmass);
    if (rc) {
        if (p)
            for (size_t l = 0; l < maxl; l++)
                asp_amg_csr_destroy(p[l]);
        asp_free(ctx, p);
        asp_free(ctx, sizes);
        return rc;
    }
    *nlevels = levels;
    *p_out = p;
    *sizes_out = sizes;
    return 0;
}
