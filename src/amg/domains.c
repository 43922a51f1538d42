/*
 * Domains of the basis functions: thresholded D = {x : Psi(x) > tau}
 * (journal eq. 8, tau = 0.05; thesis eq. 2.3 with K = 0.01), strict domains
 * by the largest Psi (thesis eq. 2.5), and the per-level statistics.
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

int asp_amg_domains(const asp_amg_csr *psi, double tau, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    if (!(tau >= 0 && tau < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid domain threshold %g: expected a value in [0, 1)", tau);
    size_t nnz = 0;
    for (size_t k = 0; k < psi->row_ptr[psi->rows]; k++)
        nnz += psi->val[k] > tau;
    asp_amg_csr *d;
    int rc = asp_amg_csr_create(psi->cols, psi->rows, nnz, ctx, &d, err);
    if (rc)
        return rc;
    for (size_t k = 0; k < psi->row_ptr[psi->rows]; k++)
        if (psi->val[k] > tau)
            d->row_ptr[psi->col[k] + 1]++;
    for (size_t i = 0; i < d->rows; i++)
        d->row_ptr[i + 1] += d->row_ptr[i];
    size_t *fill = asp_alloc(ctx, (d->rows + 1) * sizeof *fill);
    if (!fill) {
        asp_amg_csr_destroy(d);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the domains");
    }
    memcpy(fill, d->row_ptr, (d->rows + 1) * sizeof *fill);
    /* points in increasing order within each domain: scan the rows of psi in order */
    for (size_t x = 0; x < psi->rows; x++)
        for (size_t k = psi->row_ptr[x]; k < psi->row_ptr[x + 1]; k++)
            if (psi->val[k] > tau) {
                size_t w = fill[psi->col[k]]++;
                d->col[w] = (asp_index)x;
                d->val[w] = psi->val[k];
            }
    asp_free(ctx, fill);
    *out = d;
    return 0;
}

void asp_amg_strict_domains(const asp_amg_csr *psi, asp_index *label)
{
    for (size_t x = 0; x < psi->rows; x++) {
        double best = -1;
        asp_index arg = 0;
        for (size_t k = psi->row_ptr[x]; k < psi->row_ptr[x + 1]; k++)
            if (psi->val[k] > best) { /* strict >: ties keep the smaller column */
                best = psi->val[k];
                arg = psi->col[k];
            }
        label[x] = arg;
    }
}

int asp_amg_strict_domain_rows(const asp_amg_csr *psi, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    asp_index *label = asp_alloc(ctx, (psi->rows ? psi->rows : 1) * sizeof *label);
    if (!label)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the strict domains of %zu points", psi->rows);
    asp_amg_strict_domains(psi, label);
    asp_amg_csr *d;
    int rc = asp_amg_csr_create(psi->cols, psi->rows, psi->rows, ctx, &d, err);
    if (rc) {
        asp_free(ctx, label);
        return rc;
    }
    for (size_t x = 0; x < psi->rows; x++)
        d->row_ptr[label[x] + 1]++;
    for (size_t i = 0; i < d->rows; i++)
        d->row_ptr[i + 1] += d->row_ptr[i];
    /* counting sort by label, points in increasing order within a row */
    size_t *fill = asp_alloc(ctx, (d->rows + 1) * sizeof *fill);
    if (!fill) {
        asp_free(ctx, label);
        asp_amg_csr_destroy(d);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the strict domains");
    }
    memcpy(fill, d->row_ptr, (d->rows + 1) * sizeof *fill);
    for (size_t x = 0; x < psi->rows; x++) {
        size_t w = fill[label[x]]++;
        d->col[w] = (asp_index)x;
        d->val[w] = 1.0;
    }
    asp_free(ctx, fill);
    asp_free(ctx, label);
    *out = d;
    return 0;
}

static int fill_stats(const asp_amg_csr *psi, size_t level, double tau, const asp_context *ctx,
                      asp_amg_level_stats *s, asp_error *err)
{
    size_t *size = asp_calloc(ctx, psi->cols + 1, sizeof *size);
    if (!size)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the level statistics");
    memset(s, 0, sizeof *s);
    s->level = level;
    s->unknowns = psi->cols;
    size_t member = 0;
    for (size_t x = 0; x < psi->rows; x++) {
        double sum = 0;
        for (size_t k = psi->row_ptr[x]; k < psi->row_ptr[x + 1]; k++) {
            sum += psi->val[k];
            if (psi->val[k] > tau) {
                size[psi->col[k]]++;
                member++;
            }
        }
        if (fabs(sum - 1.0) > s->max_pou_error)
            s->max_pou_error = fabs(sum - 1.0);
    }
    for (size_t c = 0; c < psi->cols; c++)
        if (size[c]) {
            s->domains++;
            if (size[c] > s->max_domain_size)
                s->max_domain_size = size[c];
        }
    s->mean_domain_size = s->domains ? (double)member / (double)s->domains : 0;
    s->mean_domains_per_point = psi->rows ? (double)member / (double)psi->rows : 0;
    asp_free(ctx, size);
    return 0;
}

int asp_amg_level_stats_all(const asp_amg *amg, double tau, const asp_context *ctx, asp_amg_level_stats *stats,
                            asp_error *err)
{
    if (!(tau >= 0 && tau < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid domain threshold %g: expected a value in [0, 1)", tau);
    double t0 = asp_time_now();
    asp_amg_csr *psi;
    int rc = asp_amg_basis(amg, 0, ctx, &psi, err);
    if (rc)
        return rc;
    for (size_t l = 0; l < amg->nlevels; l++) {
        if (l > 0) {
            asp_amg_csr *next;
            rc = asp__amg_spgemm_pou(psi, amg->prolong[l], amg->desc.drop_tol, ctx, &next, err);
            asp_amg_csr_destroy(psi);
            if (rc)
                return rc;
            psi = next;
        }
        rc = fill_stats(psi, l, tau, ctx, &stats[l], err);
        if (rc)
            break;
        double t1 = asp_time_now();
        stats[l].seconds = t1 - t0;
        t0 = t1;
        if ((rc = asp_progress(ctx, "basis", (double)(l + 1) / (double)amg->nlevels)) != 0) {
            asp_error_set(err, rc, "decomposition statistics canceled");
            break;
        }
    }
    asp_amg_csr_destroy(psi);
    return rc;
}
