/*
 * Sharp creases between domain primitives (beyond the seeds; see
 * docs/render-methods.md "Crease clipping"). Each primitive is a quasi-flat
 * domain on its support plane (journal section 3); where two of them meet at a
 * sharp crease the surface is the line where their planes cross, but each
 * rectangle's texture reaches past it (the domain's basis function overlaps
 * the next face), and the overhang covers the other face in a band of mixed
 * colour (the too-wide transitions of thesis 5.3.1). Splatting fixes the same
 * defect by clipping splats at feature lines (Pauly et al. 2003, Zwicker et
 * al. 2004); here every primitive is clipped by the support plane of each
 * primitive it crosses at an angle. This file finds those pairs on upload.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/prim_internal.h"
#include "util/banned.h"

/* Pairs at less than this angle are never clipped, so their lists stay short (the shader tests the
   current crease angle, which may be anything above it). */
#define MIN_ANGLE_COS 0.9396926207859084 /* cos 20 degrees */

typedef struct rect {
    double c[3], u[3], v[3], n[3]; /* centre (frame of origin), unit axes, unit normal */
    double hu, hv;                 /* half extents */
    double lo[3], hi[3];           /* bounding box of the corners */
    const asp_prim *prim;          /* for its texture rectangle */
} rect;

/*
 * Only quasi-flat primitives meet at creases: l_min / (l0 + l1 + l2) below the
 * flatness that merging uses (thesis 3.4, `build --merge-flatness`, 0.01).
 * Between curved domains the plane intersection is no feature of the surface,
 * and cutting there opens slivers where the basis functions' overlap would
 * have blended the two smoothly.
 */
#define FLAT_MAX 0.01

/*
 * At a true crease only the basis function's tail reaches across: the
 * partition-of-unity overlap, where Psi falls from about 0.5 to 0 within a
 * point spacing or two. So the alpha-weighted area a cut removes may be at
 * most that of a band BAND_TEXELS texels (texel = about a point radius, build
 * --texel-size) wide along the cut inside the rectangle. More, and the planes
 * meet somewhere the domains do not (a fillet between two flat faces, say):
 * the pair is left alone. Measured with eval (128 px, 16 views): 1 texel keeps
 * every octahedron level at SSIM >= 0.975 and the fandisk within 0.003 of or
 * above a 5%-of-alpha rule at every level; 2-4 texels cut fandisk fillets
 * (-0.01 to -0.03), a fixed share of alpha cut too little of the octahedron's
 * small domains (0.879 at 683 primitives).
 */
#define BAND_TEXELS 1.0

/* Samples along a crossing line, and how many must lie where both basis functions are above ALPHA_MIN. */
enum { LINE_SAMPLES = 33, SAMPLES_NEEDED = 2 };
#define ALPHA_MIN 0.1 /* the default alpha reference (thesis Fig. 4.13) */

/* The basis function (texture alpha, 0..1) of r at the world point x, nearest texel; 0 outside. */
static double alpha_at(const rect *r, const asp_image *atlas, const double x[3])
{
    double rel[3] = {x[0] - r->c[0], x[1] - r->c[1], x[2] - r->c[2]};
    double s = (rel[0] * r->u[0] + rel[1] * r->u[1] + rel[2] * r->u[2]) / r->hu;
    double t = (rel[0] * r->v[0] + rel[1] * r->v[1] + rel[2] * r->v[2]) / r->hv;
    if (!(r->hu > 0 && r->hv > 0) || !(fabs(s) <= 1 && fabs(t) <= 1))
        return 0;
    const asp_prim *p = r->prim;
    // column i covers s in [-1 + 2 i / tex_w, -1 + 2 (i + 1) / tex_w] (prim.h)
    uint32_t i = (uint32_t)fmin((0.5 * s + 0.5) * p->tex_w, p->tex_w - 1.0);
    uint32_t j = (uint32_t)fmin((0.5 * t + 0.5) * p->tex_h, p->tex_h - 1.0);
    size_t at = ((size_t)(p->tex_y + j) * atlas->width + p->tex_x + i) * 4 + 3;
    return atlas->pixels[at] / 255.0;
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The alpha-weighted area of r's texture (alpha 0..1 at texel centres) on the negative side of plane. */
static double cut_area(const rect *r, const asp_image *atlas, const float plane[4])
{
    const asp_prim *p = r->prim;
    double cut = 0;
    for (uint32_t j = 0; j < p->tex_h; j++) {
        double t = r->hv * (-1.0 + (2.0 * j + 1.0) / p->tex_h);
        const uint8_t *row = atlas->pixels + ((size_t)(p->tex_y + j) * atlas->width + p->tex_x) * 4;
        for (uint32_t i = 0; i < p->tex_w; i++) {
            double a = row[4 * i + 3];
            if (a == 0)
                continue;
            double s = r->hu * (-1.0 + (2.0 * i + 1.0) / p->tex_w), side = plane[3];
            for (int k = 0; k < 3; k++)
                side += plane[k] * (r->c[k] + s * r->u[k] + t * r->v[k]);
            cut += side < 0 ? a : 0;
        }
    }
    return cut / 255.0 * (2.0 * r->hu / p->tex_w) * (2.0 * r->hv / p->tex_h);
}

/*
 * Clips the line p + s d to the rectangle r (|(x - c) . u| <= hu, same for v),
 * narrowing [*s0, *s1]; returns 0 when nothing is left.
 */
static int clip_line(const rect *r, const double p[3], const double d[3], double *s0, double *s1)
{
    const double *axis[2] = {r->u, r->v};
    double half[2] = {r->hu, r->hv};
    double rel[3] = {p[0] - r->c[0], p[1] - r->c[1], p[2] - r->c[2]};
    for (int k = 0; k < 2; k++) {
        double a = dot3(rel, axis[k]), b = dot3(d, axis[k]);
        if (fabs(b) < 1e-12) {
            if (fabs(a) > half[k])
                return 0;
            continue;
        }
        double t0 = (-half[k] - a) / b, t1 = (half[k] - a) / b;
        if (t0 > t1) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
        *s0 = fmax(*s0, t0);
        *s1 = fmin(*s1, t1);
    }
    return *s0 <= *s1;
}

/*
 * Whether a must be clipped by b's plane: their planes meet at more than
 * 20 degrees along a line crossing both rectangles, and the pair is
 * consistent (each centre on the same side of the other's plane as the other
 * way round: both inside for a convex crease, both outside for a concave one;
 * a saddle-like pair or a centre on a plane is left alone). Writes b's plane,
 * oriented so a's centre is on the kept (>= 0) side, and cos(angle).
 */
static int crease_of(const rect *a, const rect *b, const asp_image *atlas, float plane[4], float *cosine)
{
    double c = dot3(a->n, b->n);
    if (!(c < MIN_ANGLE_COS) || !(a->prim->curvature < FLAT_MAX) || !(b->prim->curvature < FLAT_MAX))
        return 0;
    double d[3] = {a->n[1] * b->n[2] - a->n[2] * b->n[1], a->n[2] * b->n[0] - a->n[0] * b->n[2],
                   a->n[0] * b->n[1] - a->n[1] * b->n[0]};
    double dd = dot3(d, d);
    if (!(dd > 1e-12)) // parallel planes (opposite faces) never cross
        return 0;
    // the point of the line closest to the origin: ((h_a n_b - h_b n_a) x d) ... written out below
    double ha = dot3(a->n, a->c), hb = dot3(b->n, b->c);
    double w[3] = {ha * b->n[0] - hb * a->n[0], ha * b->n[1] - hb * a->n[1], ha * b->n[2] - hb * a->n[2]};
    double p[3] = {(w[1] * d[2] - w[2] * d[1]) / dd, (w[2] * d[0] - w[0] * d[2]) / dd,
                   (w[0] * d[1] - w[1] * d[0]) / dd};
    double s0 = -INFINITY, s1 = INFINITY;
    if (!clip_line(a, p, d, &s0, &s1) || !clip_line(b, p, d, &s0, &s1))
        return 0;
    /* rectangles reach well past their domains (bounding rectangles, a margin): the line must also
       cross where both domains are, or unrelated primitives would cut holes into each other */
    int both = 0;
    for (int k = 0; k < LINE_SAMPLES && both < SAMPLES_NEEDED; k++) {
        double f = s0 + (s1 - s0) * (k + 0.5) / LINE_SAMPLES, x[3];
        for (int q = 0; q < 3; q++)
            x[q] = p[q] + f * d[q];
        both += alpha_at(a, atlas, x) > ALPHA_MIN && alpha_at(b, atlas, x) > ALPHA_MIN;
    }
    if (both < SAMPLES_NEEDED)
        return 0;
    double s = dot3(b->n, a->c) - hb, t = dot3(a->n, b->c) - ha;
    double size_a = sqrt(a->hu * a->hv), size_b = sqrt(b->hu * b->hv);
    if (!(s * t > 0) || fabs(s) < 1e-3 * size_a || fabs(t) < 1e-3 * size_b)
        return 0;
    double sign = s > 0 ? 1.0 : -1.0;
    for (int k = 0; k < 3; k++)
        plane[k] = (float)(sign * b->n[k]);
    plane[3] = (float)(-sign * hb);
    double a0 = -INFINITY, a1 = INFINITY; // the line's length inside a's rectangle
    clip_line(a, p, d, &a0, &a1);
    double band = (a1 - a0) * sqrt(dd) * BAND_TEXELS * a->prim->texel;
    if (!(cut_area(a, atlas, plane) <= band))
        return 0;
    *cosine = (float)c;
    return 1;
}

static int cmp_lo_x(const void *x, const void *y, const rect *rs)
{
    double a = rs[*(const uint32_t *)x].lo[0], b = rs[*(const uint32_t *)y].lo[0];
    return a < b ? -1 : a > b;
}

/* qsort has no context argument; the sort is small (one per upload), so an insertion-friendly merge sort. */
static void sort_by_lo_x(uint32_t *idx, uint32_t *tmp, size_t n, const rect *rs)
{
    if (n < 2)
        return;
    size_t h = n / 2;
    sort_by_lo_x(idx, tmp, h, rs);
    sort_by_lo_x(idx + h, tmp, n - h, rs);
    size_t i = 0, j = h, k = 0;
    while (i < h && j < n)
        tmp[k++] = cmp_lo_x(&idx[j], &idx[i], rs) < 0 ? idx[j++] : idx[i++];
    while (i < h)
        tmp[k++] = idx[i++];
    while (j < n)
        tmp[k++] = idx[j++];
    memcpy(idx, tmp, n * sizeof *idx);
}

static int boxes_overlap(const rect *a, const rect *b)
{
    for (int k = 0; k < 3; k++)
        if (a->hi[k] < b->lo[k] || b->hi[k] < a->lo[k])
            return 0;
    return 1;
}

/*
 * Sweep and prune along x over the rectangles' bounding boxes; for every
 * crossing pair calls crease_of both ways. pass 0 counts per primitive into
 * count; pass 1 writes at first[i] + fill[i]++.
 */
static void sweep(const rect *rs, const asp_image *atlas, const uint32_t *order, size_t n, int pass, uint32_t *count, const uint32_t *first,
                  uint32_t *fill, float *entries)
{
    for (size_t x = 0; x < n; x++) {
        const rect *a = &rs[order[x]];
        for (size_t y = x + 1; y < n && rs[order[y]].lo[0] <= a->hi[0]; y++) {
            const rect *b = &rs[order[y]];
            if (!boxes_overlap(a, b))
                continue;
            uint32_t ia = order[x], ib = order[y];
            const rect *pair[2][2] = {{a, b}, {b, a}};
            uint32_t ids[2][2] = {{ia, ib}, {ib, ia}};
            for (int w = 0; w < 2; w++) {
                float plane[4], cosine;
                if (!crease_of(pair[w][0], pair[w][1], atlas, plane, &cosine))
                    continue;
                uint32_t i = ids[w][0];
                if (pass == 0) {
                    count[i]++;
                    continue;
                }
                float *e = entries + 8 * ((size_t)first[i] + fill[i]++);
                memcpy(e, plane, sizeof plane);
                e[4] = cosine;
                e[5] = (float)ids[w][1];
                e[6] = e[7] = 0.0f;
            }
        }
    }
}

int asp__prim_creases(const asp_dps_level *lv, const double origin[3], const asp_context *ctx, uint32_t *first,
                      uint32_t *count, float **entries, size_t *total, asp_error *err)
{
    size_t n = lv->prim_count;
    rect *rs = asp_alloc(ctx, n * sizeof *rs);
    uint32_t *order = asp_alloc(ctx, 2 * n * sizeof *order), *fill = asp_calloc(ctx, n, sizeof *fill);
    if (!rs || !order || !fill) {
        asp_free(ctx, rs);
        asp_free(ctx, order);
        asp_free(ctx, fill);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the crease search of %zu primitives", n);
    }
    for (size_t i = 0; i < n; i++) {
        const asp_prim *p = &lv->prims[i];
        rect *r = &rs[i];
        for (int k = 0; k < 3; k++) {
            r->c[k] = p->centre[k] - origin[k];
            r->u[k] = p->axis_u[k];
            r->v[k] = p->axis_v[k];
            r->n[k] = p->normal[k];
        }
        r->hu = p->half_u;
        r->hv = p->half_v;
        r->prim = p;
        for (int k = 0; k < 3; k++) {
            double ext = fabs(r->u[k]) * r->hu + fabs(r->v[k]) * r->hv;
            r->lo[k] = r->c[k] - ext;
            r->hi[k] = r->c[k] + ext;
        }
        order[i] = (uint32_t)i;
        count[i] = 0;
    }
    sort_by_lo_x(order, order + n, n, rs);
    sweep(rs, &lv->atlas, order, n, 0, count, NULL, NULL, NULL);
    size_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        first[i] = (uint32_t)sum;
        sum += count[i];
    }
    // one unused entry keeps the storage buffer bindable when there is no crease
    float *e = asp_calloc(ctx, 8 * (sum ? sum : 1), sizeof(float));
    if (!e) {
        asp_free(ctx, rs);
        asp_free(ctx, order);
        asp_free(ctx, fill);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu crease planes", sum);
    }
    sweep(rs, &lv->atlas, order, n, 1, count, first, fill, e);
    asp_free(ctx, rs);
    asp_free(ctx, order);
    asp_free(ctx, fill);
    *entries = e;
    *total = sum;
    return 0;
}
