/*
 * The stiffness rows of a distributed decomposition (issue 19, journal eq.
 * 5-7): each rank assembles A~ on its own points and halo with stiffness.c,
 * then the halves of the couplings across rank borders travel to the owners
 * of the rows, which complete, clamp and sum them as one process would.
 */
#ifdef ASP_HAVE_HYPRE
#include <stdlib.h>

#include "amg/distributed.h"
#include "util/banned.h"

typedef struct triple {
    asp_index row, col;
    double v, fv;
} triple;

static int cmp_triple(const void *a, const void *b)
{
    const triple *x = a, *y = b;
    if (x->row != y->row)
        return x->row < y->row ? -1 : 1;
    return x->col < y->col ? -1 : x->col > y->col;
}

/*
 * A = (A~ + A~^T) / 2 (journal eq. 6) for the owned rows. The local assembly
 * (ghosts without fans) already holds both halves between owned points and
 * A~_ij / 2 towards a ghost j; the other half, A~_ji / 2, is the value j's
 * owner has in row j, column i: each rank sends those to the owners. Then
 * stiffness.c's clamping and zero row sums (eq. 7) on the completed rows.
 */
int asp__dist_global_rows(const asp__dist *d, const asp__dist_points *pts, asp_amg_csr **take_a,
                          asp_amg_csr **take_f, asp_amg_stiffness form, asp_amg_csr **ga, asp_amg_csr **gf,
                          size_t *positive, asp_error *err)
{
    const asp_amg_csr *a = *take_a, *f = *take_f;
    const int P = d->size, want_f = f != NULL;
    const size_t n = pts->n_own, start = pts->starts[d->rank];
    int *cnt = asp_calloc(&d->ctx, 4 * (size_t)P, sizeof *cnt);
    if (!cnt)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness exchange");
    int *dis = cnt + P, *rcnt = cnt + 2 * P, *rdis = cnt + 3 * P;
    size_t out_n = 0, own_n = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++) {
            if (a->col[k] >= n)
                cnt[asp__dist_owner(pts->starts, P, asp__dist_gid(d, pts, a->col[k]))]++, out_n++;
            if (a->col[k] != i)
                own_n++;
        }
    triple *snd = asp_alloc(&d->ctx, (out_n + 1) * sizeof *snd);
    int *fill = asp_calloc(&d->ctx, (size_t)P, sizeof *fill);
    for (int q = 1; q < P; q++)
        dis[q] = dis[q - 1] + cnt[q - 1];
    for (size_t i = 0; snd && fill && i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++)
            if (a->col[k] >= n) {
                asp_index g = asp__dist_gid(d, pts, a->col[k]);
                int o = asp__dist_owner(pts->starts, P, g);
                snd[dis[o] + fill[o]++] = (triple){g, (asp_index)(start + i), a->val[k], f ? f->val[k] : 0};
            }
    asp_free(&d->ctx, fill);
    MPI_Alltoall(cnt, 1, MPI_INT, rcnt, 1, MPI_INT, d->comm);
    size_t got = 0;
    for (int q = 0; q < P; q++) {
        rdis[q] = (int)got;
        got += (size_t)rcnt[q];
    }
    triple *all = asp_alloc(&d->ctx, (own_n + got + 1) * sizeof *all);
    int ok = snd && all, allok = 0, rc = 0;
    MPI_Allreduce(&ok, &allok, 1, MPI_INT, MPI_MIN, d->comm);
    if (!allok) {
        asp_free(&d->ctx, snd);
        asp_free(&d->ctx, all);
        asp_free(&d->ctx, cnt);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu stiffness entries", own_n + got);
    }
    MPI_Datatype t;
    MPI_Type_contiguous((int)sizeof(triple), MPI_BYTE, &t);
    MPI_Type_commit(&t);
    MPI_Alltoallv(snd, cnt, dis, t, all + own_n, rcnt, rdis, t, d->comm);
    MPI_Type_free(&t);
    asp_free(&d->ctx, snd);
    asp_free(&d->ctx, cnt);
    size_t w = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = a->row_ptr[i]; k < a->row_ptr[i + 1]; k++)
            if (a->col[k] != i)
                all[w++] = (triple){(asp_index)(start + i), asp__dist_gid(d, pts, a->col[k]), a->val[k],
                                    f ? f->val[k] : 0};
    /* every entry is in the triples now: the local matrices go before the global ones are made (issue 19) */
    asp_amg_csr_destroy(*take_a);
    asp_amg_csr_destroy(*take_f);
    *take_a = *take_f = NULL;
    a = f = NULL;
    qsort(all, own_n + got, sizeof *all, cmp_triple);
    const size_t total = own_n + got;
    asp_amg_csr *A = NULL, *F = NULL;
    rc = asp_amg_csr_create(n, pts->n_global, total + n, &d->ctx, &A, err);
    if (!rc && want_f)
        rc = asp_amg_csr_create(n, pts->n_global, total + n, &d->ctx, &F, err);
    const int clamp = form != ASP_AMG_STIFFNESS_UNCLAMPED;
    size_t pos_count = 0, k = 0;
    w = 0;
    for (size_t i = 0; !rc && i < n; i++) {
        const asp_index gi = (asp_index)(start + i);
        size_t diag_slot = SIZE_MAX;
        double diag = 0, fdiag = 0;
        while (k < total && all[k].row == gi) {
            asp_index j = all[k].col;
            double v = 0, fv = 0;
            for (; k < total && all[k].row == gi && all[k].col == j; k++)
                v += all[k].v, fv += all[k].fv;
            if (v > 0) {
                pos_count += j > gi;
                if (clamp)
                    continue;
            }
            if (v == 0)
                continue;
            if (diag_slot == SIZE_MAX && j > gi)
                diag_slot = w++;
            A->col[w] = j;
            A->val[w] = v;
            diag -= v;
            if (F) {
                F->col[w] = j;
                F->val[w] = fv < 0 || !clamp ? fv : 0.0;
                fdiag -= F->val[w];
            }
            w++;
        }
        if (diag_slot == SIZE_MAX)
            diag_slot = w++;
        A->col[diag_slot] = gi;
        A->val[diag_slot] = diag;
        A->row_ptr[i + 1] = w;
        if (F) {
            F->col[diag_slot] = gi;
            F->val[diag_slot] = fdiag;
            F->row_ptr[i + 1] = w;
        }
    }
    asp_free(&d->ctx, all);
    if (rc) {
        asp_amg_csr_destroy(A);
        asp_amg_csr_destroy(F);
        return rc;
    }
    unsigned long long pc = pos_count, pall = 0;
    MPI_Allreduce(&pc, &pall, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
    *positive = (size_t)pall;
    *ga = A;
    *gf = F;
    return 0;
}
#else
typedef int asp__dist_rows_unused;
#endif
