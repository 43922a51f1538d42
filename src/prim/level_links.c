/*
 * Links between the stored levels of a .dps (issue 18 item 1; journal section
 * 6 and thesis 2.6.3, combining levels): a fine primitive's share of each
 * coarse primitive, from the AMG relation Psi^b = Psi^a P^{a+1} ... P^b
 * (journal 2.3), so a coarse primitive can be replaced by its children.
 */
#include <stdlib.h>
#include <string.h>

#include "prim/internal.h"
#include "util/banned.h"

/* Shares below this are left out: they change sum_j w Psi_j by less than the 0.05 of the test. */
#define LINK_DROP 1e-4

void asp__level_links_release(const asp_context *ctx, asp_dps_level *lv)
{
    asp_free(ctx, lv->link_first);
    asp_free(ctx, lv->link_parent);
    asp_free(ctx, lv->link_weight);
    lv->link_first = lv->link_parent = NULL;
    lv->link_weight = NULL;
    lv->link_total = 0;
}

int asp_dps_has_links(const asp_dps *dps)
{
    if (!dps || dps->level_count < 2)
        return 0;
    for (size_t i = 0; i + 1 < dps->level_count; i++)
        if (!dps->levels[i].link_first)
            return 0;
    return 1;
}

/* Sparse row vector with a dense accumulator (cap = the largest level size). */
typedef struct spvec {
    size_t n;
    asp_index *col;
    double *val;
} spvec;

/* y = x P: x indexes P's rows; acc (zero on entry and exit) and mark are dense over P's columns. */
static void row_times(const spvec *x, const asp_amg_csr *P, double *acc, uint8_t *mark, spvec *y)
{
    y->n = 0;
    for (size_t q = 0; q < x->n; q++) {
        size_t r = x->col[q];
        for (size_t e = P->row_ptr[r]; e < P->row_ptr[r + 1]; e++) {
            asp_index c = P->col[e];
            if (!mark[c]) {
                mark[c] = 1;
                y->col[y->n++] = c;
            }
            acc[c] += x->val[q] * P->val[e];
        }
    }
    for (size_t q = 0; q < y->n; q++) {
        y->val[q] = acc[y->col[q]];
        acc[y->col[q]] = 0;
        mark[y->col[q]] = 0;
    }
}

typedef struct link_pair {
    uint32_t parent;
    float w;
} link_pair;

static int cmp_pair(const void *a, const void *b)
{
    const link_pair *x = a, *y = b;
    return x->parent < y->parent ? -1 : x->parent > y->parent;
}

/* Links of fine level lv to coarse level up through P^{lv->level + 1} ... P^{up->level}. */
static int link_pair_levels(const asp_amg *amg, asp_dps_level *lv, const asp_dps_level *up, const asp_context *ctx,
                            asp_error *err)
{
    size_t cap = 0;
    for (size_t l = lv->level; l <= up->level; l++)
        if (asp_amg_level_size(amg, l) > cap)
            cap = asp_amg_level_size(amg, l);
    size_t ncoarse = asp_amg_level_size(amg, up->level);
    int rc = 0;
    double *acc = asp_calloc(ctx, cap, sizeof *acc);
    uint8_t *mark = asp_calloc(ctx, cap, 1);
    asp_index *cols = asp_alloc(ctx, 2 * cap * sizeof *cols);
    double *vals = asp_alloc(ctx, 2 * cap * sizeof *vals);
    uint32_t *to_prim = asp_alloc(ctx, ncoarse * sizeof *to_prim);
    link_pair *pairs = NULL;
    size_t pcap = 0, ptotal = 0;
    lv->link_first = asp_calloc(ctx, lv->prim_count + 1, sizeof *lv->link_first);
    if (!acc || !mark || !cols || !vals || !to_prim || !lv->link_first) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the links of level %u", lv->level);
        goto done;
    }
    for (size_t c = 0; c < ncoarse; c++)
        to_prim[c] = UINT32_MAX; /* skipped basis functions have no primitive */
    for (size_t k = 0; k < up->prim_count; k++)
        to_prim[up->prims[k].basis] = (uint32_t)k;
    for (size_t j = 0; j < lv->prim_count; j++) {
        spvec a = {1, cols, vals}, b = {0, cols + cap, vals + cap};
        a.col[0] = lv->prims[j].basis;
        a.val[0] = 1;
        for (size_t l = lv->level + 1; l <= up->level; l++) {
            row_times(&a, asp_amg_prolongation(amg, l), acc, mark, &b);
            spvec t = a;
            a = b;
            b = t;
        }
        if (pcap - ptotal < a.n) {
            size_t ncap = 2 * (pcap + a.n);
            link_pair *np = asp_alloc(ctx, ncap * sizeof *np);
            if (!np) {
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the links of level %u", lv->level);
                goto done;
            }
            if (ptotal)
                memcpy(np, pairs, ptotal * sizeof *np);
            asp_free(ctx, pairs);
            pairs = np, pcap = ncap;
        }
        size_t start = ptotal;
        for (size_t q = 0; q < a.n; q++)
            if (a.val[q] >= LINK_DROP && to_prim[a.col[q]] != UINT32_MAX)
                pairs[ptotal++] = (link_pair){to_prim[a.col[q]], (float)(a.val[q] > 1 ? 1 : a.val[q])};
        qsort(pairs + start, ptotal - start, sizeof *pairs, cmp_pair);
        lv->link_first[j + 1] = (uint32_t)ptotal;
    }
    lv->link_parent = asp_alloc(ctx, (ptotal ? ptotal : 1) * sizeof *lv->link_parent);
    lv->link_weight = asp_alloc(ctx, (ptotal ? ptotal : 1) * sizeof *lv->link_weight);
    if (!lv->link_parent || !lv->link_weight) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu links of level %u", ptotal, lv->level);
        goto done;
    }
    for (size_t q = 0; q < ptotal; q++)
        lv->link_parent[q] = pairs[q].parent, lv->link_weight[q] = pairs[q].w;
    lv->link_total = ptotal;
done:
    if (rc)
        asp__level_links_release(ctx, lv);
    asp_free(ctx, acc);
    asp_free(ctx, mark);
    asp_free(ctx, cols);
    asp_free(ctx, vals);
    asp_free(ctx, to_prim);
    asp_free(ctx, pairs);
    return rc;
}

int asp_prim_links(const asp_amg *amg, asp_dps *dps, const asp_context *ctx, asp_error *err)
{
    if (!amg || !dps)
        return asp_error_set(err, ASP_EINVAL, "asp_prim_links needs a decomposition and a dps");
    size_t nl = asp_amg_level_count(amg);
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        if (lv->level >= nl || lv->basis_count != asp_amg_level_size(amg, lv->level))
            return asp_error_set(err, ASP_EINVAL, "level %zu (AMG level %u, %u basis functions) does not belong to "
                                 "the %zu-level decomposition", i, lv->level, lv->basis_count, nl);
        for (size_t k = 0; k < lv->prim_count; k++)
            if (lv->prims[k].basis >= lv->basis_count)
                return asp_error_set(err, ASP_EINVAL, "level %zu, primitive %zu: basis %u out of range", i, k,
                                     lv->prims[k].basis);
    }
    for (size_t i = 0; i < dps->level_count; i++)
        asp__level_links_release(ctx, &dps->levels[i]);
    for (size_t i = 0; i + 1 < dps->level_count; i++) {
        asp_dps_level *lv = &dps->levels[i];
        const asp_dps_level *up = &dps->levels[i + 1];
        if (lv->merges || up->merges)
            continue; /* NEEDSWORK: a merged primitive's member basis functions are not kept */
        /* a file of both domain sets (each AMG level twice) has no single chain of coarser levels */
        if (up->level <= lv->level || up->strict != lv->strict)
            continue;
        int rc = link_pair_levels(amg, lv, up, ctx, err);
        if (rc) {
            for (size_t q = 0; q < dps->level_count; q++)
                asp__level_links_release(ctx, &dps->levels[q]);
            return rc;
        }
    }
    return 0;
}
