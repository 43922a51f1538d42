/*
 * Classifier-weighted stiffness matrix on the local fans (journal 2.2,
 * eq. 5-7): A~_ij sums C(T) grad(Phi_i).grad(Phi_j) |T| over i's 3D fan
 * triangles, A_ij = (A~_ij + A~_ji) / 2 off the diagonal, A_ii = -sum_j A_ij.
 */
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amg/internal.h"
#include "util/banned.h"

/*
 * grad(Phi_a).grad(Phi_b) |T| = -cot(angle at the third corner c) / 2 for the
 * linear hat functions of triangle (a, b, c). Computed in 3D, not on the
 * projection: the journal integrates on the 3D fan so creases weaken coupling.
 */
static double half_cot(const double *a, const double *b, const double *c)
{
    double u[3] = {a[0] - c[0], a[1] - c[1], a[2] - c[2]};
    double v[3] = {b[0] - c[0], b[1] - c[1], b[2] - c[2]};
    double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
    double cr = sqrt(cx * cx + cy * cy + cz * cz);
    /* a sliver has no meaningful gradient: it couples nothing */
    if (!(cr > 1e-12 * (dot > 0 ? dot : -dot)) || cr == 0)
        return 0.0;
    return 0.5 * dot / cr;
}

/*
 * Row i of A~ into (col, val), merged and sorted by column; returns the entry
 * count (<= 2 * ntri). fval (may be NULL) receives the same row with C = 1.
 */
static size_t tilde_row(const float *pos, const float *cls, const asp__amg_fans *f, size_t i, asp_index *col,
                        double *val, double *fval)
{
    size_t nt = f->ntri[i], cnt = 0;
    const asp_index *tri = f->tri + 2 * i * f->stride;
    double x[3] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
    for (size_t t = 0; t < nt; t++) {
        asp_index a = tri[2 * t], b = tri[2 * t + 1];
        double pa[3] = {pos[3 * (size_t)a], pos[3 * (size_t)a + 1], pos[3 * (size_t)a + 2]};
        double pb[3] = {pos[3 * (size_t)b], pos[3 * (size_t)b + 1], pos[3 * (size_t)b + 2]};
        /* C(T): mean of the nodal classifier values (journal eq. 5) */
        double ct = ((double)cls[i] + cls[a] + cls[b]) / 3.0;
        double ga = -half_cot(x, pa, pb); /* edge i-a, opposite corner b */
        double gb = -half_cot(x, pb, pa); /* edge i-b, opposite corner a */
        asp_index js[2] = {a, b};
        double gs[2] = {ga, gb};
        for (int e = 0; e < 2; e++) {
            size_t q = 0;
            while (q < cnt && col[q] != js[e])
                q++;
            if (q == cnt) {
                col[cnt] = js[e];
                val[cnt] = 0;
                if (fval)
                    fval[cnt] = 0;
                cnt++;
            }
            val[q] += ct * gs[e];
            if (fval)
                fval[q] += gs[e];
        }
    }
    /* insertion sort by column: rows hold a handful of entries */
    for (size_t q = 1; q < cnt; q++) {
        asp_index c = col[q];
        double v = val[q];
        size_t r = q;
        while (r > 0 && col[r - 1] > c) {
            col[r] = col[r - 1];
            val[r] = val[r - 1];
            r--;
        }
        col[r] = c;
        val[r] = v;
        if (fval) {
            double fv = fval[q];
            size_t u = q;
            while (u > r) {
                fval[u] = fval[u - 1];
                u--;
            }
            fval[r] = fv;
        }
    }
    return cnt;
}

int asp__amg_assemble(const float *pos, const float *cls, const asp__amg_fans *f, asp_amg_stiffness form,
                      const asp_context *ctx, asp_amg_csr **out, asp_amg_csr **flat_out, size_t *positive,
                      asp_error *err)
{
    const size_t n = f->n;
    const int threads = asp_context_threads(ctx);
    const int want_flat = flat_out != NULL;
    asp_amg_csr *at = NULL, *tt = NULL, *a = NULL, *fl = NULL;
    double *atf = NULL, *ttf = NULL;
    size_t *cnt = asp_calloc(ctx, n + 1, sizeof *cnt);
    size_t *slot = asp_alloc(ctx, (n + 1) * sizeof *slot);
    size_t *pos_count = asp_calloc(ctx, (size_t)threads, sizeof *pos_count);
    int rc = 0;
    if (!cnt || !slot || !pos_count) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix");
        goto done;
    }
    /*
     * A~ (journal eq. 5): rows are independent, so fill them in parallel, each
     * into a slot of 2 * (its triangle count) entries (the row's upper bound),
     * then close the gaps in order.
     */
    slot[0] = 0;
    for (size_t i = 0; i < n; i++)
        slot[i + 1] = slot[i] + 2 * (size_t)f->ntri[i];
    if ((rc = asp_amg_csr_create(n, n, slot[n], ctx, &at, err)) != 0)
        goto done;
    if (want_flat && !(atf = asp_alloc(ctx, (slot[n] + 1) * sizeof *atf))) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix");
        goto done;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        cnt[i] = tilde_row(pos, cls, f, i, at->col + slot[i], at->val + slot[i], atf ? atf + slot[i] : NULL);
    }
    for (size_t i = 0; i < n; i++) {
        size_t b = at->row_ptr[i];
        if (b != slot[i]) {
            memmove(at->col + b, at->col + slot[i], cnt[i] * sizeof *at->col);
            memmove(at->val + b, at->val + slot[i], cnt[i] * sizeof *at->val);
            if (atf)
                memmove(atf + b, atf + slot[i], cnt[i] * sizeof *atf);
        }
        at->row_ptr[i + 1] = b + cnt[i];
    }
    const size_t nnz_t = at->row_ptr[n];
    /* transpose by counting sort: sequential, so the column order is fixed */
    rc = asp_amg_csr_create(n, n, nnz_t, ctx, &tt, err);
    if (rc)
        goto done;
    if (want_flat && !(ttf = asp_alloc(ctx, (nnz_t + 1) * sizeof *ttf))) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix");
        goto done;
    }
    for (size_t k = 0; k < nnz_t; k++)
        tt->row_ptr[at->col[k] + 1]++;
    for (size_t i = 0; i < n; i++)
        tt->row_ptr[i + 1] += tt->row_ptr[i];
    memcpy(cnt, tt->row_ptr, (n + 1) * sizeof *cnt);
    for (size_t i = 0; i < n; i++)
        for (size_t k = at->row_ptr[i]; k < at->row_ptr[i + 1]; k++) {
            size_t d = cnt[at->col[k]]++;
            tt->col[d] = (asp_index)i;
            tt->val[d] = at->val[k];
            if (ttf)
                ttf[d] = atf[k];
        }
    /*
     * A_ij = (A~_ij + A~_ji) / 2 (eq. 6). A positive result comes from obtuse
     * 3D angles (a non-Delaunay lifted fan); classical AMG interpolation needs
     * an M-matrix (non-positive off-diagonals) to give weights in [0,1], so
     * such entries are clamped to 0 and counted. The seeds keep them (journal
     * eq. 5-7, thesis 2.4): ASP_AMG_STIFFNESS_UNCLAMPED. Pass 1 counts, pass 2
     * fills. The flat matrix (C = 1, the crease test's reference) takes A's
     * pattern, its positive entries clamped as A's are, with zero row sums.
     */
    const int clamp = form != ASP_AMG_STIFFNESS_UNCLAMPED;
    for (int pass = 0; pass < 2 && !rc; pass++) {
        if (pass == 1) {
            size_t total = 0;
            for (size_t i = 0; i < n; i++) {
                size_t c = cnt[i];
                cnt[i] = total;
                total += c;
            }
            cnt[n] = total;
            rc = asp_amg_csr_create(n, n, total, ctx, &a, err);
            if (!rc && want_flat)
                rc = asp_amg_csr_create(n, n, total, ctx, &fl, err);
            if (rc)
                break;
            memcpy(a->row_ptr, cnt, (n + 1) * sizeof *cnt);
            if (fl)
                memcpy(fl->row_ptr, cnt, (n + 1) * sizeof *cnt);
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long ii = 0; ii < (long long)n; ii++) {
            size_t i = (size_t)ii;
            int t = 0;
#ifdef _OPENMP
            t = omp_get_thread_num();
#endif
            size_t p = at->row_ptr[i], pe = at->row_ptr[i + 1], q = tt->row_ptr[i], qe = tt->row_ptr[i + 1];
            size_t w = pass ? a->row_ptr[i] : 0, diag_slot = 0;
            double diag = 0, fdiag = 0;
            int diag_done = 0;
            size_t c = 0;
            while (p < pe || q < qe) {
                asp_index j;
                double v = 0, fv = 0;
                if (q >= qe || (p < pe && at->col[p] < tt->col[q])) {
                    j = at->col[p];
                    fv = atf ? atf[p] : 0;
                    v = at->val[p++];
                } else if (p >= pe || tt->col[q] < at->col[p]) {
                    j = tt->col[q];
                    fv = ttf ? ttf[q] : 0;
                    v = tt->val[q++];
                } else {
                    j = at->col[p];
                    fv = atf ? atf[p] + ttf[q] : 0;
                    v = at->val[p++] + tt->val[q++];
                }
                v *= 0.5;
                fv *= 0.5;
                if (j == i)
                    continue;
                if (v > 0) {
                    if (pass == 0 && j > i)
                        pos_count[t]++;
                    if (clamp)
                        continue;
                }
                if (v == 0)
                    continue;
                if (!diag_done && j > i) {
                    /* keep columns sorted: the diagonal goes before the first larger column */
                    diag_slot = w++;
                    c++;
                    diag_done = 1;
                }
                if (pass) {
                    a->col[w] = j;
                    a->val[w] = v;
                    if (fl) {
                        fl->col[w] = j;
                        fl->val[w] = fv < 0 || !clamp ? fv : 0.0;
                        fdiag -= fl->val[w];
                    }
                }
                w++;
                c++;
                diag -= v;
            }
            if (!diag_done) {
                diag_slot = w++;
                c++;
            }
            if (pass) {
                a->col[diag_slot] = (asp_index)i;
                a->val[diag_slot] = diag; /* eq. 7: zero row sum */
                if (fl) {
                    fl->col[diag_slot] = (asp_index)i;
                    fl->val[diag_slot] = fdiag;
                }
            } else {
                cnt[i] = c;
            }
        }
    }
    if (!rc) {
        size_t total = 0;
        for (int t = 0; t < threads; t++)
            total += pos_count[t];
        *positive = total;
        *out = a;
        a = NULL;
        if (flat_out) {
            *flat_out = fl;
            fl = NULL;
        }
    }
done:
    asp_amg_csr_destroy(at);
    asp_amg_csr_destroy(tt);
    asp_amg_csr_destroy(a);
    asp_amg_csr_destroy(fl);
    asp_free(ctx, atf);
    asp_free(ctx, ttf);
    asp_free(ctx, cnt);
    asp_free(ctx, slot);
    asp_free(ctx, pos_count);
    return rc;
}
