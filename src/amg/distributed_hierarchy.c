/*
 * The hierarchy of a distributed decomposition level by level (issue 19;
 * journal 2.3 as hierarchy.c): hypre's distributed BoomerAMG coarsens each
 * level, distributed_repair.c repairs and filters its rows, and the small
 * coarse levels move to rank 0.
 */
#ifdef ASP_HAVE_HYPRE
#include <string.h>

#include "amg/distributed.h"
#include "util/banned.h"

void asp__dist_hier_release(const asp_context *ctx, asp__dist_hier *h)
{
    for (size_t l = 0; l < ASP_AMG_DIST_MAX_LEVELS; l++) {
        asp_free(ctx, h->starts[l]);
        asp_amg_csr_destroy(h->p[l]);
    }
    memset(h, 0, sizeof *h);
}

/* Median |a_ij| of the off-diagonal entries over every rank (level_rows.c's histogram, summed). */
static double median_coupling(const asp__dist *d, const asp_amg_csr *a, size_t row0)
{
    uint64_t hist[256] = {0}, all[256];
    asp__amg_coupling_hist(a, row0, hist);
    MPI_Allreduce(hist, all, 256, MPI_UINT64_T, MPI_SUM, d->comm);
    return asp__amg_hist_median(all);
}

/*
 * A level moves to rank 0 and is coarsened there as in one process (hypre's
 * own answer is BoomerAMGSetSeqThreshold) below 2048 unknowns per rank, and on
 * a few ranks below 65,536 unknowns in all. Measured on a 20k bunny, parallel
 * RS coarsening of a level with a few hundred unknowns per rank keeps nearly
 * every unknown at a rank border, so the coarse levels stopped shrinking (58
 * unknowns at L on 2 ranks, 5 serially). Above that, each border still adds
 * its own C points, and the coarse levels amplify any difference (RS is
 * greedy): on a 4M-point bunny with the per-rank rule alone, 4 ranks ended
 * with 58 unknowns on level 14 against 50 in one process; gathering below
 * 65,536 (level 6 on) gave 53, and 49 on 2 ranks. A level of 65,536 unknowns
 * costs rank 0 a few megabytes and well under a second. The global ids stay;
 * only the partition changes, to [0, N, N, ...].
 */
enum { GATHER_BELOW_PER_RANK = 2048, GATHER_BELOW = 65536 };

static size_t gather_below(int P)
{
    const size_t g = GATHER_BELOW_PER_RANK * (size_t)P;
    return g > GATHER_BELOW ? g : GATHER_BELOW;
}

static int gather_level(const asp__dist *d, size_t *starts, asp_amg_csr **a, asp_amg_csr **f, double **mass,
                        double **cm, asp_error *err)
{
    const size_t N = starts[d->size], m = d->rank == 0 ? N : 0;
    asp_index *ids = asp_alloc(&d->ctx, (m + 1) * sizeof *ids);
    double *m2 = asp_alloc(&d->ctx, (m + 1) * sizeof *m2), *c2 = asp_alloc(&d->ctx, (m + 1) * sizeof *c2);
    asp_amg_csr *a2 = NULL, *f2 = NULL;
    int rc = ids && m2 && c2 ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory gathering a level of %zu unknowns", N);
    for (size_t i = 0; !rc && i < m; i++)
        ids[i] = (asp_index)i;
    if ((rc = asp__dist_agree(d, rc, err)) == 0)
        rc = asp__dist_fetch_rows(d, starts, *a, ids, m, &a2, err);
    if (!rc && *f)
        rc = asp__dist_fetch_rows(d, starts, *f, ids, m, &f2, err);
    if (!rc)
        rc = asp__dist_fetch(d, starts, *mass, sizeof **mass, ids, m, m2, err);
    if (!rc)
        rc = asp__dist_fetch(d, starts, *cm, sizeof **cm, ids, m, c2, err);
    asp_free(&d->ctx, ids);
    if (rc) {
        asp_free(&d->ctx, m2);
        asp_free(&d->ctx, c2);
        asp_amg_csr_destroy(a2);
        asp_amg_csr_destroy(f2);
        return rc;
    }
    asp_free(&d->ctx, *mass);
    asp_free(&d->ctx, *cm);
    *mass = m2;
    *cm = c2;
    *a = a2;
    *f = f2;
    for (int q = 1; q <= d->size; q++)
        starts[q] = N;
    return 0;
}

/* Takes *a0: destroyed (*a0 = NULL) once hypre holds its copy of the first level (the AMG stage's peak). */
int asp__dist_build_hierarchy(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **a0,
                              const asp_amg_csr *f0, const float *cls, const asp_amg_desc *desc, asp__dist_hier *h,
                              asp_error *err)
{
    const int P = d->size;
    const size_t maxl = desc->max_levels < ASP_AMG_DIST_MAX_LEVELS ? desc->max_levels : ASP_AMG_DIST_MAX_LEVELS;
    const int crease = desc->crease_cut > 0 && f0;
    const asp_amg_csr *cur = *a0, *fcur = f0;
    asp_amg_csr *owned = NULL, *fowned = NULL;
    size_t n = pts->n_own, *cst = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *cst);
    double *mass = asp_alloc(&d->ctx, (n + 1) * sizeof *mass), *cm = asp_alloc(&d->ctx, (n + 1) * sizeof *cm);
    int rc = cst && mass && cm ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    h->nlevels = 1;
    h->sizes[0] = pts->n_global;
    h->starts[0] = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *h->starts[0]);
    if (!h->starts[0])
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
    else
        memcpy(h->starts[0], pts->starts, ((size_t)P + 1) * sizeof *pts->starts);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    for (size_t i = 0; i < n; i++) {
        mass[i] = 1.0;
        cm[i] = cls[i];
    }
    const double cut = desc->weak_coupling > 0 ? desc->weak_coupling * median_coupling(d, *a0, pts->starts[d->rank]) : 0;
    while (h->nlevels < maxl && h->sizes[h->nlevels - 1] > desc->max_coarse) {
        const size_t l = h->nlevels;
        size_t *st = h->starts[l - 1];
        if (P > 1 && l >= 2 && h->sizes[l - 1] < gather_below(P) && st[1] < st[P]) {
            asp_amg_csr *ga = (asp_amg_csr *)cur, *gf = (asp_amg_csr *)fcur;
            if ((rc = gather_level(d, st, &ga, &gf, &mass, &cm, err)) != 0)
                break;
            asp_amg_csr_destroy(owned);
            asp_amg_csr_destroy(fowned);
            owned = ga;
            cur = ga;
            fowned = gf;
            fcur = gf;
        }
        asp_amg_csr *p = NULL, *ac = NULL, *next = NULL, *fnext = NULL;
        size_t *nst = asp_alloc(&d->ctx, ((size_t)P + 1) * sizeof *nst), offdiag = 0;
        /* the first level: A^0 goes as soon as hypre has it; the rows P leaves empty come back for the fill */
        asp_amg_csr *a_rows = NULL;
        const int first = *a0 && cur == *a0;
        rc = first ? asp__dist_coarsen_take(d, a0, st, desc, &p, &ac, cst, &a_rows, err)
                   : asp__dist_coarsen(d, cur, st, desc, &p, &ac, cst, err);
        if (first && !*a0)
            cur = NULL; /* taken */
        if (rc || !p) {
            asp_amg_csr_destroy(a_rows);
            asp_free(&d->ctx, nst);
            break;
        }
        if (!nst)
            rc = ASP_ENOMEM;
        if ((rc = asp__dist_agree(d, rc ? asp_error_set(err, rc, "out of memory for the AMG hierarchy") : 0, err)))
            goto level_fail;
        rc = asp__dist_fill_empty_rows(d, &p, a_rows ? a_rows : cur, st, err);
        asp_amg_csr_destroy(a_rows);
        a_rows = NULL;
        if (rc)
            goto level_fail;
        if ((rc = asp__dist_agree(d, asp__dist_repair(d, &p, cst, nst, &h->repaired, err), err)) != 0)
            goto level_fail;
        if ((rc = asp__dist_agree(d, asp__dist_renumber_coarse(d, &ac, cst, nst, err), err)) != 0)
            goto level_fail;
        const size_t nc = nst[d->rank + 1] - nst[d->rank];
        double *m2 = asp_alloc(&d->ctx, (nc + 1) * sizeof *m2), *c2 = asp_alloc(&d->ctx, (nc + 1) * sizeof *c2);
        rc = m2 && c2 ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
        if ((rc = asp__dist_agree(d, rc, err)) == 0)
            rc = asp__dist_carry(d, p, nst, mass, m2, err);
        if (!rc)
            rc = asp__dist_carry(d, p, nst, cm, c2, err);
        if (!rc) {
            asp_free(&d->ctx, mass);
            asp_free(&d->ctx, cm);
            mass = m2;
            cm = c2;
        } else {
            asp_free(&d->ctx, m2);
            asp_free(&d->ctx, c2);
            goto level_fail;
        }
        if (crease && (rc = asp__dist_galerkin(d, p, st, nst, fcur, &fnext, err)) != 0)
            goto level_fail;
        rc = asp__dist_filter(d, ac, fnext, nst, mass, cm, cut, desc->crease_cut,
                              0.25 * (double)pts->n_global / (double)nst[P], &next, &offdiag, err);
        if (rc)
            goto level_fail;
        asp_amg_csr_destroy(ac);
        ac = NULL;
        if (nst[P] >= h->sizes[l - 1]) { /* nothing left to merge */
            asp_amg_csr_destroy(p);
            asp_amg_csr_destroy(next);
            asp_amg_csr_destroy(fnext);
            asp_free(&d->ctx, nst);
            break;
        }
        h->p[l] = p;
        h->starts[l] = nst;
        h->sizes[l] = nst[P];
        h->nlevels++;
        asp_amg_csr_destroy(owned);
        owned = next;
        cur = next;
        if (fnext) {
            asp_amg_csr_destroy(fowned);
            fowned = fnext;
            fcur = fnext;
        }
        if (offdiag == 0)
            break;
        continue;
    level_fail:
        asp_amg_csr_destroy(a_rows);
        asp_amg_csr_destroy(p);
        asp_amg_csr_destroy(ac);
        asp_amg_csr_destroy(next);
        asp_amg_csr_destroy(fnext);
        asp_free(&d->ctx, nst);
        break;
    }
    h->repaired = (size_t)asp__dist_sum(d, h->repaired);
done:
    asp_amg_csr_destroy(owned);
    asp_amg_csr_destroy(fowned);
    asp_free(&d->ctx, cst);
    asp_free(&d->ctx, mass);
    asp_free(&d->ctx, cm);
    return rc;
}
#else
typedef int asp__dist_hierarchy_unused;
#endif
