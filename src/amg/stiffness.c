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

/* Row i of A~ into (col, val), merged and sorted by column; returns the entry count (<= 2 * ntri). */
static size_t tilde_row(const float *pos, const float *cls, const asp__amg_fans *f, size_t i, asp_index *col,
                        double *val)
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
        double wa = -ct * half_cot(x, pa, pb); /* edge i-a, opposite corner b */
        double wb = -ct * half_cot(x, pb, pa); /* edge i-b, opposite corner a */
        asp_index js[2] = {a, b};
        double ws[2] = {wa, wb};
        for (int e = 0; e < 2; e++) {
            size_t q = 0;
            while (q < cnt && col[q] != js[e])
                q++;
            if (q == cnt) {
                col[cnt] = js[e];
                val[cnt++] = 0;
            }
            val[q] += ws[e];
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
    }
    return cnt;
}

int asp__amg_assemble(const float *pos, const float *cls, const asp__amg_fans *f, const asp_context *ctx,
                      asp_amg_csr **out, size_t *positive, asp_error *err)
{
    const size_t n = f->n;
    const int threads = asp_context_threads(ctx);
    const size_t rowcap = 2 * f->stride;
    asp_amg_csr *at = NULL, *tt = NULL, *a = NULL;
    size_t *cnt = asp_calloc(ctx, n + 1, sizeof *cnt);
    size_t *pos_count = asp_calloc(ctx, (size_t)threads, sizeof *pos_count);
    int rc = 0;
    if (!cnt || !pos_count) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix");
        goto done;
    }
    /* A~ (journal eq. 5): rows are independent, so fill them in parallel into fixed-capacity slots */
    size_t nnz_t = 0;
    {
        asp_index *scol = asp_alloc(ctx, n * rowcap * sizeof *scol);
        double *sval = asp_alloc(ctx, n * rowcap * sizeof *sval);
        if (!scol || !sval) {
            asp_free(ctx, scol);
            asp_free(ctx, sval);
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix");
            goto done;
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long ii = 0; ii < (long long)n; ii++)
            cnt[ii] = tilde_row(pos, cls, f, (size_t)ii, scol + (size_t)ii * rowcap, sval + (size_t)ii * rowcap);
        for (size_t i = 0; i < n; i++)
            nnz_t += cnt[i];
        rc = asp_amg_csr_create(n, n, nnz_t, ctx, &at, err);
        if (!rc) {
            for (size_t i = 0; i < n; i++)
                at->row_ptr[i + 1] = at->row_ptr[i] + cnt[i];
#pragma omp parallel for schedule(static) num_threads(threads)
            for (long long ii = 0; ii < (long long)n; ii++) {
                size_t i = (size_t)ii, b = at->row_ptr[i];
                memcpy(at->col + b, scol + i * rowcap, cnt[i] * sizeof *scol);
                memcpy(at->val + b, sval + i * rowcap, cnt[i] * sizeof *sval);
            }
        }
        asp_free(ctx, scol);
        asp_free(ctx, sval);
        if (rc)
            goto done;
    }
    /* transpose by counting sort: sequential, so the column order is fixed */
    rc = asp_amg_csr_create(n, n, nnz_t, ctx, &tt, err);
    if (rc)
        goto done;
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
        }
    /*
     * A_ij = (A~_ij + A~_ji) / 2 (eq. 6). A positive result comes from obtuse
     * 3D angles (a non-Delaunay lifted fan); classical AMG interpolation needs
     * an M-matrix (non-positive off-diagonals) to give weights in [0,1], so
     * such entries are clamped to 0 and counted. Pass 1 counts, pass 2 fills.
     */
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
            if (rc)
                break;
            memcpy(a->row_ptr, cnt, (n + 1) * sizeof *cnt);
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long long ii = 0; ii < (long long)n; ii++) {
            size_t i = (size_t)ii;
            int t = 0;
#ifdef _OPENMP
            t = omp_get_thread_num();
#endif
            size_t p = at->row_ptr[i], pe = at->row_ptr[i + 1], q = tt->row_ptr[i], qe = tt->row_ptr[i + 1];
            size_t w = pass ? a->row_ptr[i] : 0, w0 = w, diag_slot = 0;
            double diag = 0;
            int diag_done = 0;
            size_t c = 0;
            while (p < pe || q < qe) {
                asp_index j;
                double v = 0;
                if (q >= qe || (p < pe && at->col[p] < tt->col[q])) {
                    j = at->col[p];
                    v = at->val[p++];
                } else if (p >= pe || tt->col[q] < at->col[p]) {
                    j = tt->col[q];
                    v = tt->val[q++];
                } else {
                    j = at->col[p];
                    v = at->val[p++] + tt->val[q++];
                }
                v *= 0.5;
                if (j == i)
                    continue;
                if (v > 0) {
                    if (pass == 0 && j > i)
                        pos_count[t]++;
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
            } else {
                cnt[i] = c;
            }
            (void)w0;
        }
    }
    if (!rc) {
        size_t total = 0;
        for (int t = 0; t < threads; t++)
            total += pos_count[t];
        *positive = total;
        *out = a;
        a = NULL;
    }
done:
    asp_amg_csr_destroy(at);
    asp_amg_csr_destroy(tt);
    asp_amg_csr_destroy(a);
    asp_free(ctx, cnt);
    asp_free(ctx, pos_count);
    return rc;
}
