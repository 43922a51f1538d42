/*
 * Keeps the AMG hierarchy a partition of unity (journal 2.3, thesis 2.4):
 * every row of every P^l must hold non-negative weights summing to 1. hypre
 * leaves the rows of unknowns without strong connections empty (a point with
 * no fan neighbour, or a whole disconnected part that coarsened to a single
 * unknown); such an unknown becomes an "orphan" that is carried unchanged to
 * every coarser level, so a disconnected part stays its own domain. The row
 * kernels (repair, strongest coupling, crease test, filter) are level_rows.c's,
 * shared with the distributed hierarchy (distributed_hierarchy.c).
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
    const size_t rows = p->rows + carried, orphans = asp__amg_empty_rows(p);
    asp_amg_csr *q;
    int rc = asp_amg_csr_create(rows, p->cols + carried + orphans, p->row_ptr[p->rows] + carried + orphans, ctx,
                                &q, err);
    if (rc)
        return rc;
    /* the new orphans are numbered after hypre's unknowns and the carried ones */
    asp__amg_pou_rows(p, q, (asp_index)(p->cols + carried), NULL, NULL, repaired);
    size_t w = q->row_ptr[p->rows];
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

/*
 * Crease test on a coarse level (journal 2.3: "domains stop at creases").
 * a_IJ / f_IJ, the Galerkin coupling of the classifier-weighted matrix over
 * that of the unweighted one (same fans, C = 1), is the mean classifier along
 * the interface of unknowns I and J; cmean[I] is the mean classifier inside I.
 * An interface much less flat than both sides (ratio below `ratio` times the
 * smaller interior mean) is a crease between two quasi-flat parts: its
 * coupling is cut. On uniformly curved parts (a ball) interfaces and interiors
 * agree, so merging goes on there. The decision is taken once per pair (in the
 * row of the smaller index) so the matrix stays symmetric.
 */
static void crease_cuts(const asp_amg_csr *ac, const asp_amg_csr *fc, const double *cmean, double ratio,
                        double *dense, uint8_t *cut, size_t *ncut)
{
    /* dense (fc->cols zeros on entry and exit) holds row r of fc, whose columns are unsorted */
    for (size_t r = 0; r < ac->rows; r++) {
        for (size_t k = fc->row_ptr[r]; k < fc->row_ptr[r + 1]; k++)
            dense[fc->col[k]] = fc->val[k];
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
            asp_index c = ac->col[k];
            cut[k] = 0;
            if (c <= r || ac->val[k] >= 0)
                continue;
            if (asp__amg_crease(ac->val[k], dense[c], ratio, cmean[r], cmean[c])) {
                cut[k] = 1;
                (*ncut)++;
            }
        }
        for (size_t k = fc->row_ptr[r]; k < fc->row_ptr[r + 1]; k++)
            dense[fc->col[k]] = 0;
    }
    for (size_t r = 0; r < ac->rows; r++)
        for (size_t k = ac->row_ptr[r]; k < ac->row_ptr[r + 1]; k++) {
            asp_index c = ac->col[k];
            if (c >= r)
                continue;
            /* mirror the decision of (c, r) */
            const size_t m = asp__amg_csr_find(ac, c, (asp_index)r);
            cut[k] = m == SIZE_MAX ? 0 : cut[m];
        }
}

/*
 * Appends zero rows for the orphans, cuts the couplings flagged by the crease
 * test (cut, may be NULL) and those weaker than cut (absolute). BoomerAMG's strength test is relative to each row, so once a
 * flat part has become one unknown, its weak couplings across creases look
 * strong and AMG would merge parts the classifier separated (journal 2.3:
 * "domains stop at creases"). A small unknown (mass below a quarter of the
 * level's mean, e.g. a sliver along a crease) keeps its strongest coupling so
 * it joins a neighbour instead of surviving as a tiny domain. Rows keep zero
 * sums (eq. 7) and the matrix stays symmetric.
 */
static int filter_coarse(const asp_amg_csr *ac, size_t size, double cut, const uint8_t *crease, const double *mass,
                         double small, const asp_context *ctx, asp_amg_csr **out, size_t *offdiag, asp_error *err)
{
    asp_index *best = asp_alloc(ctx, (ac->rows + 1) * sizeof *best);
    if (!best)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    for (size_t r = 0; r < ac->rows; r++)
        best[r] = mass[r] < small ? asp__amg_strongest(ac, r, 0) : UINT32_MAX;
    const asp__amg_filter keep = {.cut = cut, .crease = crease, .best = best};
    asp_amg_csr *m;
    int rc = asp_amg_csr_create(size, size, asp__amg_filter_count(ac, &keep) + size, ctx, &m, err);
    if (rc) {
        asp_free(ctx, best);
        return rc;
    }
    *offdiag = asp__amg_filter_rows(ac, &keep, m);
    asp_free(ctx, best);
    *out = m;
    return 0;
}

/* Median |a_ij| over the off-diagonal entries: the scale of a coupling on this model. */
static double median_coupling(const asp_amg_csr *a)
{
    uint64_t hist[256] = {0};
    asp__amg_coupling_hist(a, 0, hist);
    return asp__amg_hist_median(hist);
}

/* Carries a per-unknown sum through P: dst[J] = sum_r P_rJ src[r] (mass, classifier mass). */
static void carry(const asp_amg_csr *p, const double *src, double *dst)
{
    memset(dst, 0, p->cols * sizeof *dst);
    for (size_t r = 0; r < p->rows; r++)
        for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++)
            dst[p->col[k]] += p->val[k] * src[r];
}

/* own_a0, own_f0: NULL, or a0's and f0's owners (asp__amg_build_hierarchy_take) */
static int build(const asp_amg_csr *a0, asp_amg_csr **own_a0, const asp_amg_csr *f0, asp_amg_csr **own_f0,
                 const float *cls, const asp_amg_desc *desc, const asp_context *ctx, size_t *nlevels,
                 asp_amg_csr ***p_out, size_t **sizes_out, size_t *repaired, asp_error *err)
{
    const size_t maxl = desc->max_levels, n = a0->rows;
    const int crease = desc->crease_cut > 0 && f0 && cls;
    asp_amg_csr **p = asp_calloc(ctx, maxl, sizeof *p);
    size_t *sizes = asp_calloc(ctx, maxl, sizeof *sizes);
    const asp_amg_csr *cur = a0, *fcur = f0;
    asp_amg_csr *owned = NULL, *fowned = NULL;
    size_t levels = 1;
    double *mass = NULL, *cm = NULL, *tmp = NULL, *dense = NULL;
    uint8_t *cutflag = NULL;
    int rc = 0;
    if (!p || !sizes) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        goto done;
    }
    sizes[0] = n;
    mass = asp_alloc(ctx, n * sizeof *mass);
    cm = asp_alloc(ctx, n * sizeof *cm);
    tmp = asp_alloc(ctx, n * sizeof *tmp);
    dense = crease ? asp_calloc(ctx, n, sizeof *dense) : NULL;
    if (!mass || !cm || !tmp || (crease && !dense)) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        goto done;
    }
    /* mass of an unknown: how many points its basis function covers; cm: the classifier summed over them */
    for (size_t i = 0; i < n; i++) {
        mass[i] = 1.0;
        cm[i] = cls ? cls[i] : 1.0;
    }
    const double cut = desc->weak_coupling > 0 ? desc->weak_coupling * median_coupling(a0) : 0;
    size_t cur_rows = n;
    while (levels < maxl && cur_rows > desc->max_coarse) {
        asp_amg_csr *praw = NULL, *araw = NULL, *next = NULL, *fnext = NULL;
        size_t fresh = 0, offdiag = 0, ncut = 0;
        if (own_a0 && *own_a0 && cur == *own_a0) {
            cur = NULL; /* freed inside, once hypre has its copy */
            rc = asp__amg_hypre_coarsen_take(own_a0, desc, ctx, &praw, &araw, err);
        } else {
            rc = asp__amg_hypre_coarsen(cur, desc, ctx, &praw, &araw, err);
        }
        if (rc)
            goto done;
        if (!praw) {
            asp_amg_csr_destroy(araw);
            break;
        }
        rc = repair_level(&praw, 0, ctx, &fresh, repaired, err);
        if (!rc) {
            carry(praw, mass, tmp);
            memcpy(mass, tmp, praw->cols * sizeof *mass);
            carry(praw, cm, tmp);
            memcpy(cm, tmp, praw->cols * sizeof *cm);
        }
        if (!rc && crease) {
            rc = asp__amg_galerkin(praw, fcur, ctx, &fnext, err);
            if (!rc && own_f0 && *own_f0 == fcur) {
                asp_amg_csr_destroy(*own_f0); /* only the first Galerkin product reads F^0 */
                *own_f0 = NULL;
                fcur = NULL;
            }
            asp_free(ctx, cutflag);
            cutflag = rc ? NULL : asp_alloc(ctx, (araw->row_ptr[araw->rows] + 1) * sizeof *cutflag);
            if (!rc && !cutflag)
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
            if (!rc) {
                /* cmean = cm / mass, kept in tmp for the crease test */
                for (size_t j = 0; j < araw->rows; j++)
                    tmp[j] = mass[j] > 0 ? cm[j] / mass[j] : 0;
                crease_cuts(araw, fnext, tmp, desc->crease_cut, dense, cutflag, &ncut);
            }
        }
        if (!rc)
            rc = filter_coarse(araw, praw->cols, cut, crease ? cutflag : NULL, mass,
                               0.25 * (double)n / (double)praw->cols, ctx, &next, &offdiag, err);
        asp_amg_csr_destroy(araw);
        if (rc) {
            asp_amg_csr_destroy(praw);
            asp_amg_csr_destroy(fnext);
            goto done;
        }
        if (praw->cols >= cur_rows) {
            /* nothing left to merge: every unknown is its own part of the surface */
            asp_amg_csr_destroy(praw);
            asp_amg_csr_destroy(next);
            asp_amg_csr_destroy(fnext);
            break;
        }
        p[levels] = praw;
        sizes[levels] = praw->cols;
        levels++;
        asp_amg_csr_destroy(owned);
        owned = next;
        cur = next;
        cur_rows = next->rows;
        if (fnext) {
            asp_amg_csr_destroy(fowned);
            fowned = fnext;
            fcur = fnext;
        }
        if ((rc = asp_progress(ctx, "amg", (double)levels / (double)maxl)) != 0) {
            asp_error_set(err, rc, "decomposition canceled during amg");
            goto done;
        }
        /* every coupling left is a crease: each unknown is a quasi-flat part of its own (journal 2.3) */
        if (offdiag == 0)
            break;
    }
done:
    asp_amg_csr_destroy(owned);
    asp_amg_csr_destroy(fowned);
    asp_free(ctx, mass);
    asp_free(ctx, cm);
    asp_free(ctx, tmp);
    asp_free(ctx, dense);
    asp_free(ctx, cutflag);
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

int asp__amg_build_hierarchy(const asp_amg_csr *a0, const asp_amg_csr *f0, const float *cls,
                             const asp_amg_desc *desc, const asp_context *ctx, size_t *nlevels, asp_amg_csr ***p_out,
                             size_t **sizes_out, size_t *repaired, asp_error *err)
{
    return build(a0, NULL, f0, NULL, cls, desc, ctx, nlevels, p_out, sizes_out, repaired, err);
}

int asp__amg_build_hierarchy_take(asp_amg_csr **a0, asp_amg_csr **f0, const float *cls, const asp_amg_desc *desc,
                                  const asp_context *ctx, size_t *nlevels, asp_amg_csr ***p_out, size_t **sizes_out,
                                  size_t *repaired, asp_error *err)
{
    int rc = build(*a0, a0, *f0, f0, cls, desc, ctx, nlevels, p_out, sizes_out, repaired, err);
    asp_amg_csr_destroy(*a0);
    asp_amg_csr_destroy(*f0);
    *a0 = NULL;
    *f0 = NULL;
    return rc;
}
