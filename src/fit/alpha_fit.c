/*
 * Alpha texels for the silhouette (issue 27: ragged edges, thin parts). The
 * normalized method covers a pixel where the front-most fragment's bilinear
 * alpha exceeds alpha_ref (thesis 4.4.4, Fig. 4.13), a step function of
 * alpha with no useful gradient, so each round counts votes instead: a pixel
 * the reference covers but the level does not asks the nearest rectangle
 * hitting it to grow (raise its bilinear alpha taps); a pixel the level
 * covers over the reference's background asks every alpha-tested fragment
 * there to shrink; a pixel both cover holds its front fragment's taps. Each
 * texel moves by step * (grow - shrink) / (grow + shrink + hold), then the
 * views are rasterised again. Votes are summed per view and combined in view
 * order, so any thread count gives the same bytes. Alpha inside the surface
 * (no votes) keeps the basis function, so the blend weights there are the
 * unfitted partition of unity.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fit/internal.h"
#include "util/banned.h"

enum { GROW = 0, SHRINK = 1, HOLD = 2 };

#define GROW_MIN 0.02f

typedef struct vote {
    uint32_t texel;
    uint32_t kind;
    float w;
} vote;

typedef struct view_votes {
    vote *v;
    size_t n;
    size_t mismatch; /* pixels covered by exactly one of the level and the reference */
    int rc;
    asp_error err;
} view_votes;

static void add_taps(const asp_image *atlas, const asp__fit_frag *f, uint32_t kind, vote *out, size_t *n)
{
    uint32_t idx[4];
    float w[4];
    asp__fit_bilinear(atlas, f->tx, f->ty, idx, w);
    for (int k = 0; k < 4; k++)
        if (w[k] > 0)
            out[(*n)++] = (vote){idx[k], kind, w[k]};
}

static void view_vote(const asp_dps_level *lv, const double origin[3], const asp_fit_view *view,
                      const asp_image *ref, const asp_fit_draw *draw, const asp_context *ctx, view_votes *out)
{
    size_t *first = NULL;
    asp__fit_frag *frags = NULL;
    memset(out, 0, sizeof *out);
    out->rc = asp__fit_fragments(lv, origin, view, draw, 1, ctx, &first, &frags, &out->err);
    if (out->rc)
        return;
    size_t np = (size_t)view->width * view->height;
    out->v = asp_alloc(ctx, (4 * first[np] + 1) * sizeof *out->v);
    if (!out->v) {
        out->rc = asp_error_set(&out->err, ASP_ENOMEM, "out of memory for %zu alpha votes", 4 * first[np]);
        goto done;
    }
    for (size_t p = 0; p < np; p++) {
        const asp__fit_frag *f = frags + first[p];
        size_t nf = first[p + 1] - first[p];
        size_t front = SIZE_MAX, nearest = SIZE_MAX;
        for (size_t k = 0; k < nf; k++) {
            if (f[k].a > draw->alpha_ref && (front == SIZE_MAX || f[k].z < f[front].z))
                front = k;
            // growth only where the domain's basis function already reaches (alpha > 0): the empty
            // corners of a rectangle grown over a neighbour's pixels showed as dust in held-out views
            if (f[k].a > GROW_MIN && (nearest == SIZE_MAX || f[k].z < f[nearest].z))
                nearest = k;
        }
        int want = ref->pixels[4 * p + 3] != 0, have = front != SIZE_MAX;
        out->mismatch += want != have;
        if (want && have)
            add_taps(&lv->atlas, &f[front], HOLD, out->v, &out->n);
        else if (want && nearest != SIZE_MAX)
            add_taps(&lv->atlas, &f[nearest], GROW, out->v, &out->n);
        else if (!want && have)
            for (size_t k = 0; k < nf; k++)
                if (f[k].a > draw->alpha_ref)
                    add_taps(&lv->atlas, &f[k], SHRINK, out->v, &out->n);
    }
done:
    asp_free(ctx, first);
    asp_free(ctx, frags);
}

/*
 * Each texel's vote balance, then spread over its 3x3 neighbourhood (a tent, weights 4-2-1): one
 * texel's own balance alone raised isolated texels above alpha_ref, islands that showed as speckle
 * around the outline at twice the fitted size (bunny, 256 px: SSIM 0.895 -> 0.888).
 */
static void apply_votes(asp_dps_level *lv, const double *acc, double *delta, double step)
{
    size_t w = lv->atlas.width, h = lv->atlas.height, texels = w * h;
    for (size_t t = 0; t < texels; t++) {
        double g = acc[3 * t + GROW], s = acc[3 * t + SHRINK], k = acc[3 * t + HOLD];
        delta[t] = g == 0 && s == 0 ? 0.0 : step * (g - s) / (g + s + k);
    }
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
            double sum = 0, wsum = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    if ((dx < 0 && x == 0) || (dy < 0 && y == 0) || (dx > 0 && x + 1 == w) || (dy > 0 && y + 1 == h))
                        continue;
                    double wt = (dx ? 1.0 : 2.0) * (dy ? 1.0 : 2.0);
                    sum += wt * delta[(y + (size_t)dy) * w + x + (size_t)dx];
                    wsum += wt;
                }
            double d = sum / wsum;
            if (d == 0)
                continue;
            uint8_t *px = lv->atlas.pixels + 4 * (y * w + x) + 3;
            double a = *px / 255.0 + d;
            *px = (uint8_t)lround((a < 0 ? 0 : a > 1 ? 1 : a) * 255.0);
        }
}

int asp_fit_alpha(asp_dps_level *lv, const double origin[3], const asp_fit_view *views, const asp_image *refs,
                  size_t nviews, const asp_fit_desc *desc_in, const asp_context *ctx, size_t *mismatch_before,
                  size_t *mismatch_after, asp_error *err)
{
    asp_fit_desc desc = desc_in ? *desc_in : (asp_fit_desc){0};
    int rounds = desc.alpha_rounds ? desc.alpha_rounds : 8;
    double step = desc.alpha_step > 0 ? desc.alpha_step : 0.08;
    if (!lv || !views || !refs || nviews == 0 || !lv->prim_count)
        return asp_error_set(err, ASP_EINVAL, "cannot fit alpha: no views or an empty level");
    for (size_t v = 0; v < nviews; v++)
        if (!refs[v].pixels || refs[v].width != views[v].width || refs[v].height != views[v].height)
            return asp_error_set(err, ASP_EINVAL, "training reference %zu is %ux%u, expected %ux%u", v,
                                 refs[v].width, refs[v].height, views[v].width, views[v].height);
    asp__fit_drop_blocks(lv, ctx);
    asp_fit_draw draw;
    double window;
    asp__fit_draw_resolve(lv, &desc.draw, &draw, &window);
    size_t texels = (size_t)lv->atlas.width * lv->atlas.height;
    view_votes *vv = asp_calloc(ctx, nviews, sizeof *vv);
    double *acc = asp_calloc(ctx, 4 * texels + 1, sizeof *acc), *delta = acc + 3 * texels;
    if (!vv || !acc) {
        asp_free(ctx, vv), asp_free(ctx, acc);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for alpha votes of %zu texels", texels);
    }
    uint8_t *saved = asp_alloc(ctx, texels + 1);
    if (!saved) {
        asp_free(ctx, vv), asp_free(ctx, acc);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for alpha votes of %zu texels", texels);
    }
    for (size_t t = 0; t < texels; t++)
        saved[t] = lv->atlas.pixels[4 * t + 3];
    int rc = 0;
    // rounds + 1 rasterisations: the last only measures
    for (int round = 0; round <= (rounds > 0 ? rounds : 0) && !rc; round++) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(asp_context_threads(ctx))
        for (size_t v = 0; v < nviews; v++)
            view_vote(lv, origin, &views[v], &refs[v], &draw, ctx, &vv[v]);
        size_t mismatch = 0;
        memset(acc, 0, 3 * texels * sizeof *acc);
        for (size_t v = 0; v < nviews; v++) {
            if (vv[v].rc && !rc) {
                rc = vv[v].rc;
                if (err)
                    *err = vv[v].err;
            }
            mismatch += vv[v].mismatch;
            for (size_t k = 0; k < vv[v].n; k++)
                acc[3 * (size_t)vv[v].v[k].texel + vv[v].v[k].kind] += vv[v].v[k].w;
            asp_free(ctx, vv[v].v);
            vv[v].v = NULL;
        }
        if (rc)
            break;
        if (round == 0 && mismatch_before)
            *mismatch_before = mismatch;
        if (mismatch_after)
            *mismatch_after = mismatch;
        if (desc.log) {
            char line[128];
            snprintf(line, sizeof line, "fit: alpha round %d: %zu silhouette pixels differ over %zu views", round,
                     mismatch, nviews);
            desc.log(desc.log_user, line);
        }
        if (round == rounds || rounds <= 0)
            break;
        apply_votes(lv, acc, delta, step);
        if (asp_progress(ctx, "fit alpha", (double)(round + 1) / rounds))
            rc = asp_error_set(err, ASP_ECANCELED, "fit canceled");
    }
    for (size_t t = 0; rc && t < texels; t++)
        lv->atlas.pixels[4 * t + 3] = saved[t]; // on failure the level is as it was
    asp_free(ctx, saved);
    asp_free(ctx, vv);
    asp_free(ctx, acc);
    return rc;
}
