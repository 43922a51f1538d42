/*
 * Colour texels by least squares (issue 27 item 1): with geometry and alpha
 * fixed the normalized blend (Pajarola et al. 2003 5.4) is linear in the
 * texels, pixel = sum coef * c (internal.h), so the texels that best match the
 * reference images solve regularised normal equations
 *   (R^T R + lambda I + smooth L) d = R^T (y - R c0),   c = c0 + d,
 * for the correction d of the unfitted texels c0 (L: the graph Laplacian of
 * 4-neighbouring texels of one primitive's texture, so a correction spreads
 * smoothly to texels few pixels see). Solved by Jacobi-preconditioned
 * conjugate gradients; every sum runs over fixed blocks combined in order, so
 * the result is the same for any thread count (STYLE.md 7).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "fit/internal.h"
#include "util/banned.h"

enum { BLOCK = 4096 };

/* The linear system over all atlas texels, 3 channels each. */
typedef struct color_system {
    size_t rows, texels;
    size_t *rfirst;      /* rows + 1 */
    uint32_t *rtex;
    float *rcoef;
    float *b;            /* 3 per row: y - R c0 */
    size_t *tfirst;      /* texels + 1: the transpose */
    uint32_t *trow;
    float *tcoef;
    uint32_t *owner;     /* primitive + 1 per texel inside a texture rectangle, 0 outside */
    double lambda, smooth;
    uint32_t width;      /* atlas width */
    int threads;
} color_system;

static double dot(const color_system *s, const double *a, const double *b, double *partial)
{
    size_t n = 3 * s->texels, nb = (n + BLOCK - 1) / BLOCK;
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t k = 0; k < nb; k++) {
        double sum = 0;
        size_t end = (k + 1) * BLOCK < n ? (k + 1) * BLOCK : n;
        for (size_t i = k * BLOCK; i < end; i++)
            sum += a[i] * b[i];
        partial[k] = sum;
    }
    double sum = 0;
    for (size_t k = 0; k < nb; k++)
        sum += partial[k];
    return sum;
}

/* z = R x (3 channels per row). */
static void apply_r(const color_system *s, const double *x, double *z)
{
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t r = 0; r < s->rows; r++) {
        double c[3] = {0, 0, 0};
        for (size_t k = s->rfirst[r]; k < s->rfirst[r + 1]; k++) {
            const double *xt = x + 3 * (size_t)s->rtex[k];
            for (int a = 0; a < 3; a++)
                c[a] += s->rcoef[k] * xt[a];
        }
        memcpy(z + 3 * r, c, sizeof c);
    }
}

/* y = (R^T R + lambda I + smooth L) x, with z = R x as scratch. */
static void apply_a(const color_system *s, const double *x, double *z, double *y)
{
    apply_r(s, x, z);
    uint32_t w = s->width;
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t t = 0; t < s->texels; t++) {
        double c[3];
        for (int a = 0; a < 3; a++)
            c[a] = s->lambda * x[3 * t + a];
        for (size_t k = s->tfirst[t]; k < s->tfirst[t + 1]; k++)
            for (int a = 0; a < 3; a++)
                c[a] += s->tcoef[k] * z[3 * (size_t)s->trow[k] + a];
        uint32_t o = s->owner[t];
        if (o && s->smooth > 0) {
            size_t x0 = t % w;
            size_t nb[4] = {x0 > 0 ? t - 1 : t, x0 + 1 < w ? t + 1 : t, t >= w ? t - w : t,
                            t + w < s->texels ? t + w : t};
            for (int k = 0; k < 4; k++)
                if (nb[k] != t && s->owner[nb[k]] == o)
                    for (int a = 0; a < 3; a++)
                        c[a] += s->smooth * (x[3 * t + a] - x[3 * nb[k] + a]);
        }
        memcpy(y + 3 * t, c, sizeof c);
    }
}

static size_t smooth_degree(const color_system *s, size_t t)
{
    uint32_t o = s->owner[t], w = s->width;
    if (!o)
        return 0;
    size_t x0 = t % w, d = 0;
    d += x0 > 0 && s->owner[t - 1] == o;
    d += x0 + 1 < w && s->owner[t + 1] == o;
    d += t >= w && s->owner[t - w] == o;
    d += t + w < s->texels && s->owner[t + w] == o;
    return d;
}

static void system_release(color_system *s, const asp_context *ctx)
{
    void *p[] = {s->rfirst, s->rtex, s->rcoef, s->b, s->tfirst, s->trow, s->tcoef, s->owner};
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++)
        asp_free(ctx, p[i]);
    memset(s, 0, sizeof *s);
}

/* Rows of every covered pixel the reference sees, with b = y - R c0; then the transpose. */
static int system_build(color_system *s, const asp_dps_level *lv, const asp__fit_rows *vr, const asp_image *refs,
                        size_t nviews, const float *c0, const asp_context *ctx, asp_error *err)
{
    size_t rows = 0, total = 0;
    for (size_t v = 0; v < nviews; v++) {
        size_t np = (size_t)vr[v].width * vr[v].height;
        for (size_t p = 0; p < np; p++)
            if (vr[v].first[p + 1] > vr[v].first[p] && refs[v].pixels[4 * p + 3]) {
                rows++;
                total += vr[v].first[p + 1] - vr[v].first[p];
            }
    }
    s->rows = rows;
    s->texels = (size_t)lv->atlas.width * lv->atlas.height;
    s->width = lv->atlas.width;
    s->rfirst = asp_alloc(ctx, (rows + 1) * sizeof *s->rfirst);
    s->rtex = asp_alloc(ctx, (total + 1) * sizeof *s->rtex);
    s->rcoef = asp_alloc(ctx, (total + 1) * sizeof *s->rcoef);
    s->b = asp_alloc(ctx, (3 * rows + 1) * sizeof *s->b);
    s->tfirst = asp_calloc(ctx, s->texels + 1, sizeof *s->tfirst);
    s->trow = asp_alloc(ctx, (total + 1) * sizeof *s->trow);
    s->tcoef = asp_alloc(ctx, (total + 1) * sizeof *s->tcoef);
    s->owner = asp_calloc(ctx, s->texels, sizeof *s->owner);
    if (!s->rfirst || !s->rtex || !s->rcoef || !s->b || !s->tfirst || !s->trow || !s->tcoef || !s->owner)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a fit of %zu pixels and %zu texels", rows,
                             s->texels);
    size_t r = 0, e = 0;
    for (size_t v = 0; v < nviews; v++) {
        size_t np = (size_t)vr[v].width * vr[v].height;
        for (size_t p = 0; p < np; p++) {
            if (!(vr[v].first[p + 1] > vr[v].first[p] && refs[v].pixels[4 * p + 3]))
                continue;
            s->rfirst[r] = e;
            double c[3] = {0, 0, 0};
            for (size_t k = vr[v].first[p]; k < vr[v].first[p + 1]; k++, e++) {
                s->rtex[e] = vr[v].texel[k];
                s->rcoef[e] = vr[v].coef[k];
                for (int a = 0; a < 3; a++)
                    c[a] += (double)vr[v].coef[k] * c0[3 * (size_t)vr[v].texel[k] + a];
                s->tfirst[vr[v].texel[k] + 1]++;
            }
            for (int a = 0; a < 3; a++)
                s->b[3 * r + a] = (float)(asp__fit_srgb_to_linear(refs[v].pixels[4 * p + a]) - c[a]);
            r++;
        }
    }
    s->rfirst[rows] = e;
    for (size_t t = 0; t < s->texels; t++)
        s->tfirst[t + 1] += s->tfirst[t];
    // counting sort by texel, rows in increasing order within each texel: a fixed summation order
    size_t *fill = asp_alloc(ctx, (s->texels + 1) * sizeof *fill);
    if (!fill)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the transpose of %zu entries", total);
    memcpy(fill, s->tfirst, (s->texels + 1) * sizeof *fill);
    for (size_t row = 0; row < rows; row++)
        for (size_t k = s->rfirst[row]; k < s->rfirst[row + 1]; k++) {
            size_t q = fill[s->rtex[k]]++;
            s->trow[q] = (uint32_t)row;
            s->tcoef[q] = s->rcoef[k];
        }
    asp_free(ctx, fill);
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *q = &lv->prims[i];
        for (uint32_t y = q->tex_y; y < q->tex_y + q->tex_h; y++)
            for (uint32_t x = q->tex_x; x < q->tex_x + q->tex_w; x++)
                s->owner[(size_t)y * s->width + x] = (uint32_t)i + 1;
    }
    return 0;
}

static void log_line(const asp_fit_desc *d, const char *fmt, double a, double b)
{
    if (!d->log)
        return;
    char line[160];
    snprintf(line, sizeof line, fmt, a, b);
    d->log(d->log_user, line);
}

/* Data loss of the correction d: mean over rows and channels of |R d - b|^2. */
static double data_loss(const color_system *s, const double *d, double *z)
{
    apply_r(s, d, z);
    double sum = 0;
    for (size_t i = 0; i < 3 * s->rows; i++) {
        double e = z[i] - s->b[i];
        sum += e * e;
    }
    return s->rows ? sum / (3.0 * (double)s->rows) : 0.0;
}

/* Preconditioned CG from d = 0; returns the iterations run or a negative ASP_E* code. */
static int solve(const color_system *s, const asp_fit_desc *desc, uint32_t iterations, const asp_context *ctx, double *d,
                 asp_error *err)
{
    size_t n = 3 * s->texels, nb = (n + BLOCK - 1) / BLOCK;
    double *r = asp_calloc(ctx, n + 1, sizeof *r), *z = asp_calloc(ctx, n + 1, sizeof *z);
    double *p = asp_calloc(ctx, n + 1, sizeof *p), *q = asp_calloc(ctx, n + 1, sizeof *q);
    double *m = asp_calloc(ctx, n + 1, sizeof *m), *zr = asp_calloc(ctx, 3 * s->rows + 1, sizeof *zr);
    double *partial = asp_calloc(ctx, nb + 1, sizeof *partial);
    int rc = 0;
    if (!r || !z || !p || !q || !m || !zr || !partial) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for conjugate gradients on %zu unknowns", n);
        goto done;
    }
    // r = R^T b (d = 0); Jacobi preconditioner from the diagonal
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t t = 0; t < s->texels; t++) {
        double c[3] = {0, 0, 0}, diag = s->lambda + s->smooth * (double)smooth_degree(s, t);
        for (size_t k = s->tfirst[t]; k < s->tfirst[t + 1]; k++) {
            for (int a = 0; a < 3; a++)
                c[a] += s->tcoef[k] * (double)s->b[3 * (size_t)s->trow[k] + a];
            diag += (double)s->tcoef[k] * s->tcoef[k];
        }
        for (int a = 0; a < 3; a++) {
            r[3 * t + a] = c[a];
            m[3 * t + a] = diag > 0 ? 1.0 / diag : 0.0;
            d[3 * t + a] = 0;
        }
    }
    for (size_t i = 0; i < n; i++)
        z[i] = m[i] * r[i], p[i] = z[i];
    double rz = dot(s, r, z, partial), rz0 = rz;
    log_line(desc, "fit: iteration %.0f: training loss %.6g (mean squared error of linear RGB)", 0.0,
             data_loss(s, d, zr));
    uint32_t it = 0;
    for (; it < iterations && rz > 1e-14 * rz0 && rz > 0; it++) {
        apply_a(s, p, zr, q);
        double pq = dot(s, p, q, partial);
        if (!(pq > 0))
            break;
        double alpha = rz / pq;
        for (size_t i = 0; i < n; i++)
            d[i] += alpha * p[i], r[i] -= alpha * q[i], z[i] = m[i] * r[i];
        double rz1 = dot(s, r, z, partial);
        for (size_t i = 0; i < n; i++)
            p[i] = z[i] + rz1 / rz * p[i];
        rz = rz1;
        if (desc->log && ((it + 1) % 10 == 0 || it + 1 == iterations))
            log_line(desc, "fit: iteration %.0f: training loss %.6g", (double)(it + 1), data_loss(s, d, zr));
        if (asp_progress(ctx, "fit", (double)(it + 1) / iterations)) {
            rc = asp_error_set(err, ASP_ECANCELED, "fit canceled");
            goto done;
        }
    }
    rc = (int)it;
done:
    asp_free(ctx, r), asp_free(ctx, z), asp_free(ctx, p), asp_free(ctx, q), asp_free(ctx, m), asp_free(ctx, zr);
    asp_free(ctx, partial);
    return rc;
}

/* Rasterises n views in parallel, each into its own rows; the first error (in view order) wins. */
static int raster_all(const asp_dps_level *lv, const double origin[3], const asp_fit_view *views, size_t n,
                      const asp_fit_draw *draw, const asp_context *ctx, asp__fit_rows *rows, asp_error *err)
{
    int *codes = asp_calloc(ctx, n + 1, sizeof *codes);
    asp_error *errs = asp_calloc(ctx, n + 1, sizeof *errs);
    if (!codes || !errs) {
        asp_free(ctx, codes), asp_free(ctx, errs);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu views", n);
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(asp_context_threads(ctx))
    for (size_t v = 0; v < n; v++)
        codes[v] = asp__fit_raster(lv, origin, &views[v], draw, ctx, &rows[v], &errs[v]);
    int rc = 0;
    for (size_t v = 0; v < n && !rc; v++)
        if (codes[v]) {
            rc = codes[v];
            if (err)
                *err = errs[v];
        }
    asp_free(ctx, codes), asp_free(ctx, errs);
    return rc;
}

static double views_loss(const asp__fit_rows *rows, const float *lin, const asp_image *refs, size_t n,
                         size_t *pixels)
{
    double sum = 0;
    size_t total = 0;
    for (size_t v = 0; v < n; v++) {
        size_t c = 0;
        double l = asp__fit_rows_loss(&rows[v], lin, &refs[v], &c);
        sum += l * (double)c;
        total += c;
    }
    if (pixels)
        *pixels = total;
    return total ? sum / (double)total : 0.0;
}

static int check_refs(const asp_fit_view *views, const asp_image *refs, size_t n, const char *what, asp_error *err)
{
    for (size_t v = 0; v < n; v++)
        if (!refs[v].pixels || refs[v].width != views[v].width || refs[v].height != views[v].height)
            return asp_error_set(err, ASP_EINVAL, "%s reference %zu is %ux%u, expected %ux%u", what, v,
                                 refs[v].width, refs[v].height, views[v].width, views[v].height);
    return 0;
}

int asp_fit_color(asp_dps_level *lv, const double origin[3], const asp_fit_view *views, const asp_image *refs,
                  size_t nviews, const asp_fit_view *holdout, const asp_image *href, size_t nholdout,
                  const asp_fit_desc *desc_in, const asp_context *ctx, asp_fit_stats *stats, asp_error *err)
{
    double t0 = asp_time_now();
    asp_fit_desc desc = desc_in ? *desc_in : (asp_fit_desc){0};
    uint32_t iterations = desc.iterations ? desc.iterations : 60;
    double lambda = desc.lambda > 0 ? desc.lambda : 0.1;
    double smooth = desc.smooth > 0 ? desc.smooth : desc.smooth < 0 ? 0.0 : 4.0;
    if (!lv || !views || !refs || nviews == 0 || !lv->prim_count)
        return asp_error_set(err, ASP_EINVAL, "cannot fit: no views or an empty level");
    int rc = check_refs(views, refs, nviews, "training", err);
    if (!rc && nholdout)
        rc = check_refs(holdout, href, nholdout, "held-out", err);
    if (rc)
        return rc;
    asp__fit_drop_blocks(lv, ctx);
    size_t nall = nviews + nholdout;
    asp__fit_rows *rows = asp_calloc(ctx, nall, sizeof *rows);
    float *c0 = asp__fit_atlas_linear(&lv->atlas, ctx);
    double *d = asp_calloc(ctx, 3 * (size_t)lv->atlas.width * lv->atlas.height + 1, sizeof *d);
    color_system s = {0};
    s.threads = asp_context_threads(ctx);
    if (!rows || !c0 || !d) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a fit of %zu views", nall);
        goto done;
    }
    rc = raster_all(lv, origin, views, nviews, &desc.draw, ctx, rows, err);
    if (!rc && nholdout)
        rc = raster_all(lv, origin, holdout, nholdout, &desc.draw, ctx, rows + nviews, err);
    if (!rc)
        rc = system_build(&s, lv, rows, refs, nviews, c0, ctx, err);
    if (rc)
        goto done;
    // lambda and smooth are relative to the mean data weight (diagonal of R^T R) of a seen texel,
    // so they mean the same at any image size, view count and texel density
    double diag_sum = 0;
    size_t seen = 0;
    for (size_t t = 0; t < s.texels; t++) {
        double dg = 0;
        for (size_t k = s.tfirst[t]; k < s.tfirst[t + 1]; k++)
            dg += (double)s.tcoef[k] * s.tcoef[k];
        if (dg > 0)
            diag_sum += dg, seen++;
    }
    double mean_diag = seen ? diag_sum / (double)seen : 1.0;
    s.lambda = lambda * mean_diag;
    s.smooth = smooth * mean_diag;
    asp_fit_stats st = {0};
    st.texels_seen = seen;
    st.pixels = s.rows;
    st.train_before = views_loss(rows, c0, refs, nviews, NULL);
    st.holdout_before = nholdout ? views_loss(rows + nviews, c0, href, nholdout, NULL) : 0.0;
    int it = solve(&s, &desc, iterations, ctx, d, err);
    if (it < 0) {
        rc = it;
        goto done;
    }
    st.iterations = (uint32_t)it;
    // the new texels, stored as the atlas stores them (sRGB bytes); alpha untouched
    for (size_t t = 0; t < s.texels; t++)
        for (int a = 0; a < 3; a++) {
            uint8_t v = asp__fit_linear_to_srgb((double)c0[3 * t + a] + d[3 * t + a]);
            lv->atlas.pixels[4 * t + a] = v;
            c0[3 * t + a] = asp__fit_srgb_to_linear(v);
        }
    st.train_after = views_loss(rows, c0, refs, nviews, NULL);
    st.holdout_after = nholdout ? views_loss(rows + nviews, c0, href, nholdout, NULL) : 0.0;
    st.seconds = asp_time_now() - t0;
    log_line(&desc, "fit: training loss %.6g -> %.6g (after 8-bit rounding)", st.train_before, st.train_after);
    if (nholdout)
        log_line(&desc, "fit: held-out loss %.6g -> %.6g", st.holdout_before, st.holdout_after);
    if (stats)
        *stats = st;
done:
    for (size_t v = 0; rows && v < nall; v++)
        asp__fit_rows_release(&rows[v], ctx);
    asp_free(ctx, rows);
    asp_free(ctx, c0);
    asp_free(ctx, d);
    system_release(&s, ctx);
    return rc;
}
