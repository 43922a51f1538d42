/*
 * Greedy domain merging (thesis 3.4): while some overlapping pair of domains
 * is flat (curvature l_min / sum l below a threshold, both and their union)
 * and faces the same way (normals within an angle), merge the pair with the
 * largest overlap (shared points); the merged basis is the sum of the two.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "prim/internal.h"
#include "util/banned.h"

typedef struct pair {
    uint32_t a, b;     /* a < b, live domains */
    uint32_t overlap;  /* shared points */
    int ok;            /* meets the flatness and angle criteria */
    int live;
} pair;

typedef struct dvec {
    size_t n;
    asp_index *col;
    double *val;
    int owned;
} dvec;

typedef struct merger {
    const float *pos, *normals;
    double flat, cos_angle;
    dvec *vec;
    asp__moments *mom;
    double *curv, (*nrm)[3];
    const asp_context *ctx;
} merger;

static uint32_t overlap(const dvec *x, const dvec *y)
{
    size_t i = 0, j = 0;
    uint32_t c = 0;
    while (i < x->n && j < y->n) {
        if (x->col[i] == y->col[j])
            c++, i++, j++;
        else if (x->col[i] < y->col[j])
            i++;
        else
            j++;
    }
    return c;
}

static int pair_ok(const merger *m, uint32_t a, uint32_t b)
{
    if (!(m->curv[a] < m->flat && m->curv[b] < m->flat))
        return 0;
    const double *na = m->nrm[a], *nb = m->nrm[b];
    if (!(na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2] > m->cos_angle))
        return 0;
    asp__moments u = m->mom[a];
    const asp__moments *v = &m->mom[b];
    u.w += v->w;
    for (int k = 0; k < 3; k++)
        u.s[k] += v->s[k], u.nrm[k] += v->nrm[k];
    for (int k = 0; k < 6; k++)
        u.ss[k] += v->ss[k];
    double n[3];
    return asp__moments_curvature(&u, n) < m->flat; /* the union must stay flat too, or merges chain around bends */
}

/* vec[a] += vec[b] (sorted union, values summed). */
static int merge_vec(merger *m, uint32_t a, uint32_t b)
{
    dvec *x = &m->vec[a], *y = &m->vec[b];
    size_t cap = x->n + y->n;
    asp_index *col = asp_alloc(m->ctx, cap * sizeof *col);
    double *val = asp_alloc(m->ctx, cap * sizeof *val);
    if (!col || !val) {
        asp_free(m->ctx, col);
        asp_free(m->ctx, val);
        return ASP_ENOMEM;
    }
    size_t i = 0, j = 0, k = 0;
    while (i < x->n || j < y->n) {
        if (j >= y->n || (i < x->n && x->col[i] < y->col[j]))
            col[k] = x->col[i], val[k++] = x->val[i++];
        else if (i >= x->n || y->col[j] < x->col[i])
            col[k] = y->col[j], val[k++] = y->val[j++];
        else
            col[k] = x->col[i], val[k++] = x->val[i++] + y->val[j++];
    }
    if (x->owned) {
        asp_free(m->ctx, x->col);
        asp_free(m->ctx, x->val);
    }
    *x = (dvec){k, col, val, 1};
    return 0;
}

int asp__prim_merge(const asp_amg_csr *dom, const float *pos, const float *normals, double flatness,
                    double angle_deg, const asp_context *ctx, asp_amg_csr **out, uint32_t **first, uint32_t **count,
                    uint32_t *merges, asp_error *err)
{
    const size_t rows = dom->rows;
    merger m = {.pos = pos, .normals = normals, .flat = flatness, .cos_angle = cos(angle_deg * 3.14159265358979323846 / 180.0),
                .ctx = ctx};
    m.vec = asp_calloc(ctx, rows, sizeof *m.vec);
    m.mom = asp_calloc(ctx, rows, sizeof *m.mom);
    m.curv = asp_calloc(ctx, rows, sizeof *m.curv);
    m.nrm = asp_calloc(ctx, rows, sizeof *m.nrm);
    uint32_t *bfirst = asp_calloc(ctx, rows, sizeof *bfirst), *bcount = asp_calloc(ctx, rows, sizeof *bcount);
    uint32_t *stamp = asp_calloc(ctx, rows, sizeof *stamp);
    size_t *pfirst = NULL, pair_cap = 0, np = 0;
    uint32_t *plist = NULL;
    pair *pairs = NULL;
    asp_amg_csr *res = NULL;
    int rc = 0;
    if (!m.vec || !m.mom || !m.curv || !m.nrm || !bfirst || !bcount || !stamp)
        goto oom;
    for (size_t r = 0; r < rows; r++) {
        size_t a = dom->row_ptr[r], n = dom->row_ptr[r + 1] - a;
        m.vec[r] = (dvec){n, &dom->col[a], &dom->val[a], 0};
        asp__moments_add_points(&m.mom[r], pos, normals, &dom->col[a], &dom->val[a], n);
        m.curv[r] = asp__moments_curvature(&m.mom[r], m.nrm[r]);
        bfirst[r] = (uint32_t)r;
        bcount[r] = 1;
    }
    /* candidate pairs: every overlapping pair (a fraction just above 0 in the neighbour kernel) */
    pfirst = asp_calloc(ctx, rows + 1, sizeof *pfirst);
    if (!pfirst)
        goto oom;
    size_t total = 0;
    if ((rc = asp_prim_neighbours(dom, 1e-12, ctx, pfirst, &plist, &total, err)))
        goto done;
    pair_cap = total / 2 + 1;
    pairs = asp_alloc(ctx, pair_cap * sizeof *pairs);
    if (!pairs)
        goto oom;
    for (size_t a = 0; a < rows; a++)
        for (size_t q = pfirst[a]; q < pfirst[a + 1]; q++)
            if (plist[q] > a) {
                uint32_t b = plist[q];
                pairs[np++] = (pair){(uint32_t)a, b, overlap(&m.vec[a], &m.vec[b]), pair_ok(&m, (uint32_t)a, b), 1};
            }
    uint32_t done_merges = 0;
    for (uint32_t iter = 1;; iter++) {
        size_t best = SIZE_MAX;
        for (size_t k = 0; k < np; k++)
            if (pairs[k].live && pairs[k].ok &&
                (best == SIZE_MAX || pairs[k].overlap > pairs[best].overlap))
                best = k; /* ties: the earlier pair, so the result is deterministic */
        if (best == SIZE_MAX)
            break;
        uint32_t a = pairs[best].a, b = pairs[best].b;
        if (merge_vec(&m, a, b))
            goto oom;
        if (m.vec[b].owned) {
            asp_free(ctx, m.vec[b].col);
            asp_free(ctx, m.vec[b].val);
        }
        m.vec[b] = (dvec){0, NULL, NULL, 0};
        asp__moments *ma = &m.mom[a], *mb = &m.mom[b];
        ma->w += mb->w;
        for (int k = 0; k < 3; k++)
            ma->s[k] += mb->s[k], ma->nrm[k] += mb->nrm[k];
        for (int k = 0; k < 6; k++)
            ma->ss[k] += mb->ss[k];
        m.curv[a] = asp__moments_curvature(ma, m.nrm[a]);
        bcount[a] += bcount[b];
        bcount[b] = 0;
        done_merges++;
        /* pairs of b become pairs of a; drop duplicates and the merged pair; re-score every pair of a */
        stamp[a] = iter;
        for (size_t k = 0; k < np; k++) {
            pair *p = &pairs[k];
            if (!p->live || (p->a != a && p->b != a && p->a != b && p->b != b))
                continue;
            uint32_t other = p->a == a || p->a == b ? p->b : p->a;
            if (other == a || other == b || stamp[other] == iter) {
                p->live = 0;
                continue;
            }
            stamp[other] = iter;
            p->a = a < other ? a : other;
            p->b = a < other ? other : a;
            p->overlap = overlap(&m.vec[p->a], &m.vec[p->b]);
            p->ok = p->overlap > 0 && pair_ok(&m, p->a, p->b);
        }
    }
    size_t live = 0, nnz = 0;
    for (size_t r = 0; r < rows; r++)
        if (bcount[r]) {
            live++;
            nnz += m.vec[r].n;
        }
    if ((rc = asp_amg_csr_create(live, dom->cols, nnz, ctx, &res, err)))
        goto done;
    size_t o = 0, k = 0;
    for (size_t r = 0; r < rows; r++) {
        if (!bcount[r])
            continue;
        memcpy(&res->col[o], m.vec[r].col, m.vec[r].n * sizeof *res->col);
        memcpy(&res->val[o], m.vec[r].val, m.vec[r].n * sizeof *res->val);
        o += m.vec[r].n;
        res->row_ptr[k + 1] = o;
        bfirst[k] = bfirst[r];
        bcount[k] = bcount[r];
        k++;
    }
    *out = res;
    *first = bfirst;
    *count = bcount;
    *merges = done_merges;
    bfirst = bcount = NULL;
    res = NULL;
    goto done;
oom:
    rc = asp_error_set(err, ASP_ENOMEM, "out of memory while merging %zu domains", rows);
done:
    for (size_t r = 0; m.vec && r < rows; r++)
        if (m.vec[r].owned) {
            asp_free(ctx, m.vec[r].col);
            asp_free(ctx, m.vec[r].val);
        }
    asp_free(ctx, m.vec);
    asp_free(ctx, m.mom);
    asp_free(ctx, m.curv);
    asp_free(ctx, m.nrm);
    asp_free(ctx, bfirst);
    asp_free(ctx, bcount);
    asp_free(ctx, stamp);
    asp_free(ctx, pfirst);
    asp_free(ctx, plist);
    asp_free(ctx, pairs);
    asp_amg_csr_destroy(res);
    return rc;
}
