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
    const asp_index *tri = asp__amg_fan_row(f, i);
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

/*
 * A~_oc alone: the terms of column c in owner o's fan, added in tilde_row's
 * order from 0, so the value is bit-identical to tilde_row's entry.
 */
static void tilde_entry(const float *pos, const float *cls, const asp__amg_fans *f, size_t o, asp_index c,
                        double *val, double *fval)
{
    size_t nt = f->ntri[o];
    const asp_index *tri = asp__amg_fan_row(f, o);
    double x[3] = {pos[3 * o], pos[3 * o + 1], pos[3 * o + 2]};
    double v = 0, fv = 0;
    for (size_t t = 0; t < nt; t++) {
        asp_index a = tri[2 * t], b = tri[2 * t + 1];
        if (a != c && b != c)
            continue;
        double pa[3] = {pos[3 * (size_t)a], pos[3 * (size_t)a + 1], pos[3 * (size_t)a + 2]};
        double pb[3] = {pos[3 * (size_t)b], pos[3 * (size_t)b + 1], pos[3 * (size_t)b + 2]};
        double ct = ((double)cls[o] + cls[a] + cls[b]) / 3.0;
        if (a == c) {
            double ga = -half_cot(x, pa, pb);
            v += ct * ga;
            fv += ga;
        }
        if (b == c) {
            double gb = -half_cot(x, pb, pa);
            v += ct * gb;
            fv += gb;
        }
    }
    *val = v;
    *fval = fv;
}

/* The distinct vertices of i's fan other than i, sorted; returns their count (<= 2 * ntri). */
static size_t fan_columns(const asp__amg_fans *f, size_t i, asp_index *col)
{
    size_t nt = f->ntri[i], cnt = 0;
    const asp_index *tri = asp__amg_fan_row(f, i);
    for (size_t e = 0; e < 2 * nt; e++) {
        asp_index c = tri[e];
        size_t r = cnt;
        if (c == i)
            continue;
        while (r > 0 && col[r - 1] > c)
            r--;
        if (r > 0 && col[r - 1] == c)
            continue;
        memmove(col + r + 1, col + r, (cnt - r) * sizeof *col);
        col[r] = c;
        cnt++;
    }
    return cnt;
}

/* Sorts a short index list (a reverse-fan row: a handful of entries). */
static void sort_indices(asp_index *v, size_t n)
{
    for (size_t q = 1; q < n; q++) {
        asp_index c = v[q];
        size_t r = q;
        while (r > 0 && v[r - 1] > c) {
            v[r] = v[r - 1];
            r--;
        }
        v[r] = c;
    }
}

/* Per-thread scratch of one row: A~ row i (col, val, fval) and the reverse entries (val, fval). */
typedef struct row_scratch {
    asp_index *col;
    double *val, *fval, *rval, *rfval;
} row_scratch;

/*
 * Row i of A (eq. 6-7) and of the flat matrix into (col, val, fval), sorted
 * with the diagonal in place; returns its length. rev (nrev entries, sorted)
 * lists the points whose fans hold i: their A~_ji come from their own fans.
 * A positive A_ij comes from obtuse 3D angles (a non-Delaunay lifted fan);
 * classical AMG interpolation needs an M-matrix (non-positive off-diagonals)
 * to give weights in [0,1], so such entries are clamped to 0 (counted in
 * *positive when j > i). The seeds keep them (journal eq. 5-7, thesis 2.4):
 * ASP_AMG_STIFFNESS_UNCLAMPED. The flat matrix (C = 1, the crease test's
 * reference) takes A's pattern, its positive entries clamped as A's are,
 * with zero row sums.
 */
static size_t stiffness_row(const float *pos, const float *cls, const asp__amg_fans *f, size_t i,
                            const asp_index *rev, size_t nrev, int clamp, row_scratch *s, asp_index *col, double *val,
                            double *fval, size_t *positive)
{
    size_t pe = tilde_row(pos, cls, f, i, s->col, s->val, fval ? s->fval : NULL);
    for (size_t q = 0; q < nrev; q++)
        tilde_entry(pos, cls, f, rev[q], (asp_index)i, &s->rval[q], &s->rfval[q]);
    size_t p = 0, q = 0, w = 0, diag_slot = 0;
    double diag = 0, fdiag = 0;
    int diag_done = 0;
    while (p < pe || q < nrev) {
        asp_index j;
        double v = 0, fv = 0;
        if (q >= nrev || (p < pe && s->col[p] < rev[q])) {
            j = s->col[p];
            fv = fval ? s->fval[p] : 0;
            v = s->val[p++];
        } else if (p >= pe || rev[q] < s->col[p]) {
            j = rev[q];
            fv = fval ? s->rfval[q] : 0;
            v = s->rval[q++];
        } else {
            j = s->col[p];
            fv = fval ? s->fval[p] + s->rfval[q] : 0;
            v = s->val[p++] + s->rval[q++];
        }
        v *= 0.5; /* A_ij = (A~_ij + A~_ji) / 2 (eq. 6) */
        fv *= 0.5;
        if (j == i)
            continue;
        if (v > 0) {
            if (j > i)
                (*positive)++;
            if (clamp)
                continue;
        }
        if (v == 0)
            continue;
        if (!diag_done && j > i) {
            /* keep columns sorted: the diagonal goes before the first larger column */
            diag_slot = w++;
            diag_done = 1;
        }
        col[w] = j;
        val[w] = v;
        if (fval) {
            fval[w] = fv < 0 || !clamp ? fv : 0.0;
            fdiag -= fval[w];
        }
        w++;
        diag -= v;
    }
    if (!diag_done)
        diag_slot = w++;
    col[diag_slot] = (asp_index)i;
    val[diag_slot] = diag; /* eq. 7: zero row sum */
    if (fval)
        fval[diag_slot] = fdiag;
    return w;
}

/*
 * Who holds whom in a fan: row j of the result lists, sorted, every i whose
 * fan has vertex j (the pattern of A~ transposed, without values). Built in
 * parallel with atomic cursors; the sort makes it independent of the order.
 */
static int reverse_fans(const asp__amg_fans *f, const asp_context *ctx, size_t **first_out, asp_index **rev_out,
                        size_t *widest, asp_error *err)
{
    const size_t n = f->n;
    const int threads = asp_context_threads(ctx);
    size_t cap = 1;
    for (size_t i = 0; i < n; i++)
        if (2 * (size_t)f->ntri[i] > cap)
            cap = 2 * (size_t)f->ntri[i];
    size_t *first = asp_calloc(ctx, n + 1, sizeof *first);
    size_t *fill = asp_alloc(ctx, (n + 1) * sizeof *fill);
    asp_index *cols = asp_alloc(ctx, (size_t)threads * cap * sizeof *cols);
    asp_index *rev = NULL;
    if (!first || !fill || !cols)
        goto oom;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        asp_index *c = cols + (size_t)t * cap;
        size_t m = fan_columns(f, (size_t)ii, c);
        for (size_t e = 0; e < m; e++) {
#pragma omp atomic
            first[c[e] + 1]++;
        }
    }
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
        if (first[i + 1] > w)
            w = first[i + 1];
        first[i + 1] += first[i];
    }
    memcpy(fill, first, (n + 1) * sizeof *fill);
    rev = asp_alloc(ctx, (first[n] + 1) * sizeof *rev);
    if (!rev)
        goto oom;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        asp_index *c = cols + (size_t)t * cap;
        size_t m = fan_columns(f, (size_t)ii, c);
        for (size_t e = 0; e < m; e++) {
            size_t at;
#pragma omp atomic capture
            at = fill[c[e]]++;
            rev[at] = (asp_index)ii;
        }
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++)
        sort_indices(rev + first[ii], first[ii + 1] - first[ii]);
    asp_free(ctx, fill);
    asp_free(ctx, cols);
    *first_out = first;
    *rev_out = rev;
    *widest = w;
    return 0;
oom:
    asp_free(ctx, first);
    asp_free(ctx, fill);
    asp_free(ctx, cols);
    asp_free(ctx, rev);
    return asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix of %zu points", n);
}

/*
 * A is assembled row by row, each row from the fans alone (issue 19): its
 * A~_ij from i's fan, its A~_ji from the fans of the points that hold i
 * (reverse_fans), so no transposed copy of A~ with values is ever built and
 * every step runs in parallel. Rows are written into slots of their pattern
 * size (the union of both column sets plus the diagonal); the few entries a
 * row drops (clamped or zero) are closed up afterwards.
 */
int asp__amg_assemble(const float *pos, const float *cls, const asp__amg_fans *f, asp_amg_stiffness form,
                      const asp_context *ctx, asp_amg_csr **out, asp_amg_csr **flat_out, size_t *positive,
                      asp_error *err)
{
    const size_t n = f->n;
    const int threads = asp_context_threads(ctx);
    const int want_flat = flat_out != NULL, clamp = form != ASP_AMG_STIFFNESS_UNCLAMPED;
    asp_amg_csr *a = NULL, *fl = NULL;
    size_t *rfirst = NULL, *slot = NULL, *pos_count = NULL, widest = 0, fan_cap = 1;
    asp_index *rev = NULL;
    char *scratch = NULL;
    int rc = reverse_fans(f, ctx, &rfirst, &rev, &widest, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++)
        if (2 * (size_t)f->ntri[i] > fan_cap)
            fan_cap = 2 * (size_t)f->ntri[i];
    /* per thread: A~ row (fan_cap columns and values) and the reverse values (widest) */
    const size_t row_bytes = (fan_cap * (sizeof(asp_index) + 2 * sizeof(double)) + widest * 2 * sizeof(double) + 127) / 64 * 64;
    slot = asp_alloc(ctx, (n + 1) * sizeof *slot);
    pos_count = asp_calloc(ctx, (size_t)threads, sizeof *pos_count);
    scratch = asp_alloc(ctx, (size_t)threads * row_bytes);
    if (!slot || !pos_count || !scratch) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the stiffness matrix of %zu points", n);
        goto done;
    }
    /* pattern sizes: |fan columns U reverse row| + the diagonal */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        asp_index *c = (asp_index *)(void *)(scratch + (size_t)t * row_bytes);
        size_t m = fan_columns(f, i, c), p = 0, q = rfirst[i], qe = rfirst[i + 1], u = 1;
        while (p < m || q < qe) {
            if (q >= qe || (p < m && c[p] < rev[q]))
                p++;
            else if (p >= m || rev[q] < c[p])
                q++;
            else
                p++, q++;
            u++;
        }
        slot[i + 1] = u;
    }
    slot[0] = 0;
    for (size_t i = 0; i < n; i++)
        slot[i + 1] += slot[i];
    if ((rc = asp_amg_csr_create(n, n, slot[n], ctx, &a, err)) != 0 ||
        (want_flat && (rc = asp_amg_csr_create(n, n, slot[n], ctx, &fl, err)) != 0))
        goto done;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        char *base = scratch + (size_t)t * row_bytes;
        row_scratch s;
        s.val = (double *)(void *)base;
        s.fval = s.val + fan_cap;
        s.rval = s.fval + fan_cap;
        s.rfval = s.rval + widest;
        s.col = (asp_index *)(void *)(s.rfval + widest);
        size_t b = slot[i];
        a->row_ptr[i + 1] = stiffness_row(pos, cls, f, i, rev + rfirst[i], rfirst[i + 1] - rfirst[i], clamp, &s,
                                          a->col + b, a->val + b, fl ? fl->val + b : NULL, &pos_count[t]);
    }
    /* close the gaps of dropped entries, in order (rows only move down) */
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
        size_t len = a->row_ptr[i + 1], b = slot[i];
        if (w != b) {
            memmove(a->col + w, a->col + b, len * sizeof *a->col);
            memmove(a->val + w, a->val + b, len * sizeof *a->val);
            if (fl)
                memmove(fl->val + w, fl->val + b, len * sizeof *fl->val);
        }
        a->row_ptr[i] = w;
        w += len;
    }
    a->row_ptr[n] = w;
    if (fl) {
        memcpy(fl->row_ptr, a->row_ptr, (n + 1) * sizeof *a->row_ptr);
        memcpy(fl->col, a->col, w * sizeof *a->col);
    }
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
done:
    asp_amg_csr_destroy(a);
    asp_amg_csr_destroy(fl);
    asp_free(ctx, rfirst);
    asp_free(ctx, rev);
    asp_free(ctx, slot);
    asp_free(ctx, pos_count);
    asp_free(ctx, scratch);
    return rc;
}
