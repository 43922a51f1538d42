/*
 * Which domain primitives of a level a hybrid render keeps and which points
 * it draws instead (issue 18 item 3; the hybrid of points and primitives the
 * journal (section 6) and the thesis (2.6.3, future work) propose, with the
 * points drawn as the splats of seed 001). No GL: a pure function of the
 * level, its source points and the thresholds of asp_hybrid_split_desc, so it
 * lives below render (prim.h) and the no-GL build has it too.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "util/banned.h"

/*
 * The domain threshold tau of journal eq. 8 as `amgsplat build` uses it: the
 * texture alpha holds the basis function Psi, so a point belongs to a
 * primitive's domain where the texel under its projection has alpha > tau.
 */
#define DOMAIN_TAU 0.05f

/* cos 45 degrees: a domain point whose normal turns further from the primitive's is badly represented */
#define TURNED_COS 0.70710678f

/* cos 60 degrees: a primitive covers a point for drawing only if their normals agree this well */
#define COVER_COS 0.5f

/* One primitive in the points' local frame, with what the membership test needs. */
typedef struct frame_prim {
    float c[3], u[3], v[3], n[3];
    float hu, hv, bound2, slab, cover_slab, radius;
} frame_prim;

static float dot3(const float *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/*
 * Psi_i at local point x with normal nrm (NULL = any), or 0 when x is not in
 * the domain: projected outside the rectangle or onto a texel of alpha <=
 * tau, further than the slab from the plane, or turned away from it. *dist
 * gets the signed plane distance.
 */
static float membership(const asp_dps_level *lv, const asp_prim *p, const frame_prim *fp, const float *x,
                        const float *nrm, float *dist)
{
    float d[3] = {x[0] - fp->c[0], x[1] - fp->c[1], x[2] - fp->c[2]};
    if (dot3(d, d) > fp->bound2)
        return 0;
    float h = dot3(d, fp->n);
    if (fabsf(h) > fp->slab)
        return 0;
    // the other side of a thin part lies close to the plane but faces away: not this domain
    if (nrm && dot3(nrm, fp->n) < -0.1f)
        return 0;
    float s = dot3(d, fp->u) / fp->hu, t = dot3(d, fp->v) / fp->hv;
    if (!(s >= -1 && s <= 1 && t >= -1 && t <= 1))
        return 0;
    // the rectangle's edges are the texture rectangle's texel edges (build.md); rows top first as uploaded
    uint32_t tx = p->tex_x + (uint32_t)fminf((0.5f * s + 0.5f) * (float)p->tex_w, (float)p->tex_w - 1);
    uint32_t ty = p->tex_y + (uint32_t)fminf((0.5f * t + 0.5f) * (float)p->tex_h, (float)p->tex_h - 1);
    float a = lv->atlas.pixels[4 * ((size_t)ty * lv->atlas.width + tx) + 3] / 255.0f;
    if (!(a > DOMAIN_TAU))
        return 0;
    *dist = h;
    return a;
}

int asp_hybrid_split(const asp_dps_level *level, const asp_cloud *points, const asp_hybrid_split_desc *desc,
                     const asp_context *ctx, uint8_t *restrict prim_replaced, uint32_t *restrict point_cover,
                     float *restrict prim_score, asp_hybrid_counts *counts, asp_error *err)
{
    ASP_ASSERT(level && points && prim_replaced && point_cover);
    static const asp_hybrid_split_desc zero_desc;
    const asp_hybrid_split_desc *d = desc ? desc : &zero_desc;
    float error_limit = d->error_limit > 0 ? d->error_limit : ASP_HYBRID_ERROR_LIMIT;
    float turned_limit = d->turned_limit > 0 ? d->turned_limit : ASP_HYBRID_TURNED_LIMIT;
    float coverage_min = d->coverage_min > 0 ? d->coverage_min : ASP_HYBRID_COVERAGE_MIN;
    // 0 means the default; a negative or non-finite threshold is a caller's mistake, not a default
    if (!(d->error_limit >= 0) || !(d->turned_limit >= 0) || !(d->coverage_min >= 0) || !isfinite(error_limit) ||
        !isfinite(turned_limit) || !isfinite(coverage_min))
        return asp_error_set(err, ASP_EINVAL,
                             "hybrid thresholds must be finite and >= 0 (error %g, turned %g, coverage %g)",
                             (double)d->error_limit, (double)d->turned_limit, (double)d->coverage_min);
    size_t np = level->prim_count, n = points->count;
    if (np == 0 || n == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot split level %u (%zu primitives) over %zu points",
                             level->level, np, n);
    if (!level->atlas.pixels)
        return asp_error_set(err, ASP_EFORMAT, "cannot split level %u: it has no atlas", level->level);
    for (size_t i = 0; i < np; i++) {
        const asp_prim *p = &level->prims[i];
        if (p->tex_w == 0 || p->tex_h == 0 || p->tex_x + p->tex_w > level->atlas.width ||
            p->tex_y + p->tex_h > level->atlas.height || !(p->half_u > 0) || !(p->half_v > 0))
            return asp_error_set(err, ASP_EFORMAT, "cannot split level %u: primitive %zu has an empty rectangle or "
                                 "a texture outside the %ux%u atlas", level->level, i, level->atlas.width,
                                 level->atlas.height);
    }
    frame_prim *fps = asp_calloc(ctx, np, sizeof *fps);
    double *sums = asp_calloc(ctx, 3 * np, sizeof *sums);
    if (!fps || !sums) {
        asp_free(ctx, fps);
        asp_free(ctx, sums);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the hybrid split of %zu primitives", np);
    }
    // mean point spacing: the points' radii, or the disc renderer's default (asp_render_default_radius)
    double spacing = 0;
    if (points->radii) {
        for (size_t j = 0; j < n; j++)
            spacing += points->radii[j];
        spacing /= (double)n;
    } else {
        spacing = asp_cloud_default_radius(points) * 0.5;
    }
    for (size_t i = 0; i < np; i++) {
        const asp_prim *p = &level->prims[i];
        frame_prim *f = &fps[i];
        for (int k = 0; k < 3; k++) {
            f->c[k] = (float)(p->centre[k] - points->origin[k]);
            f->u[k] = p->axis_u[k];
            f->v[k] = p->axis_v[k];
            f->n[k] = p->normal[k];
        }
        f->hu = p->half_u;
        f->hv = p->half_v;
        f->radius = sqrtf(p->half_u * p->half_v);
        // the domain of the statistics: anything within half the primitive's size of its plane
        f->slab = 0.5f * f->radius;
        // drawing: the rectangle stands in for a point only if it passes within a few spacings of it
        f->cover_slab = 2.0f * p->error + 2.0f * (float)spacing;
        f->bound2 = p->half_u * p->half_u + p->half_v * p->half_v + f->slab * f->slab;
    }
    const float *nrm = points->normals;

    /*
     * Per primitive, Psi-weighted over its domain: the mean squared plane
     * distance (error relative to size) and the share of points whose normal
     * turns more than 45 degrees from the plane's (creases, thin parts, a
     * rectangle bridging a concavity). Each primitive writes its own slots.
     */
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 4) num_threads(asp_context_threads(ctx))
#endif
    for (long long ii = 0; ii < (long long)np; ii++) {
        size_t i = (size_t)ii;
        double w = 0, e2 = 0, turned = 0;
        for (size_t j = 0; j < n; j++) {
            float h = 0;
            float a = membership(level, &level->prims[i], &fps[i], points->positions + 3 * j, nrm ? nrm + 3 * j : NULL,
                                 &h);
            if (a <= 0)
                continue;
            w += a;
            e2 += a * (double)h * h;
            if (nrm && dot3(nrm + 3 * j, fps[i].n) < TURNED_COS)
                turned += a;
        }
        sums[3 * i] = w;
        sums[3 * i + 1] = w > 0 ? sqrt(e2 / w) / fps[i].radius : 0;
        sums[3 * i + 2] = w > 0 ? turned / w : 0;
    }
    size_t replaced = 0;
    for (size_t i = 0; i < np; i++) {
        float score = fmaxf((float)sums[3 * i + 1] / error_limit, (float)sums[3 * i + 2] / turned_limit);
        // a primitive without any point of its own represents nothing it was built from
        if (!(sums[3 * i] > 0))
            score = INFINITY;
        prim_replaced[i] = score > 1;
        replaced += prim_replaced[i];
        if (prim_score)
            prim_score[i] = score;
    }

    /*
     * Per point: the kept primitive of largest Psi that lies close to it and
     * faces its way stands for it, unless the kept primitives' Psi there sums
     * below coverage_min (a gap between domains, a thin tip the rectangles
     * miss) or the point is in the domain of a replaced primitive: then it is
     * drawn as a point. Every point is thus kept or drawn (coverage).
     */
    size_t drawn = 0;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) reduction(+ : drawn) num_threads(asp_context_threads(ctx))
#endif
    for (long long jj = 0; jj < (long long)n; jj++) {
        size_t j = (size_t)jj;
        const float *x = points->positions + 3 * j, *nj = nrm ? nrm + 3 * j : NULL;
        float cover = 0, best = 0;
        uint32_t best_i = ASP_HYBRID_DRAWN;
        int in_replaced = 0;
        for (size_t i = 0; i < np && !in_replaced; i++) {
            float h = 0;
            float a = membership(level, &level->prims[i], &fps[i], x, nj, &h);
            if (a <= 0)
                continue;
            if (prim_replaced[i]) {
                in_replaced = 1;
                break;
            }
            if (fabsf(h) > fps[i].cover_slab || (nj && dot3(nj, fps[i].n) < COVER_COS))
                continue;
            cover += a;
            if (a > best) {
                best = a;
                best_i = (uint32_t)i;
            }
        }
        if (in_replaced || cover < coverage_min)
            best_i = ASP_HYBRID_DRAWN;
        point_cover[j] = best_i;
        drawn += best_i == ASP_HYBRID_DRAWN;
    }
    asp_free(ctx, fps);
    asp_free(ctx, sums);
    if (counts) {
        counts->prims_kept = np - replaced;
        counts->prims_replaced = replaced;
        counts->points_drawn = drawn;
        counts->points_total = n;
    }
    return 0;
}

float asp_hybrid_domain_weight(const asp_dps_level *level, size_t prim, const double origin[3], const float x[3],
                               const float normal[3])
{
    ASP_ASSERT(level && prim < level->prim_count && x);
    const asp_prim *p = &level->prims[prim];
    frame_prim f = {0};
    for (int k = 0; k < 3; k++) {
        f.c[k] = (float)(p->centre[k] - (origin ? origin[k] : 0.0));
        f.u[k] = p->axis_u[k];
        f.v[k] = p->axis_v[k];
        f.n[k] = p->normal[k];
    }
    f.hu = p->half_u;
    f.hv = p->half_v;
    f.radius = sqrtf(p->half_u * p->half_v);
    f.slab = 0.5f * f.radius;
    f.bound2 = p->half_u * p->half_u + p->half_v * p->half_v + f.slab * f.slab;
    float h = 0;
    return membership(level, p, &f, x, normal, &h);
}
