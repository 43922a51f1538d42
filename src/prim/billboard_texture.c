/*
 * Textures of a billboard cloud (Decoret, Durand, Sillion and Dorsey 2003,
 * section 5): each plane's texture is the orthographic projection of the faces
 * (or discs) it took, over the tight rectangle of their projection oriented by
 * its 2D principal axes, at one texel size; alpha is binary (255 where an
 * element projects, else 0) and the element farthest along the plane normal
 * (its front) wins a texel. The planes become the primitives of one .dps
 * level flagged billboards, so every renderer draws them alpha-tested.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prim/billboard_internal.h"
#include "prim/internal.h"
#include "util/banned.h"

enum { MAX_SIDE = 4096, ATLAS_SIDE = 16384, PAD = 2, DILATE = 4 };

/* Where colours come from: the mesh (texture, vertex colours, material) or the cloud. */
typedef struct colour_src {
    const asp_mesh *mesh;
    const asp_cloud *cloud;
} colour_src;

/* Colour (0..255 floats) and normal of element i at barycentric weights w (discs: w ignored). */
static void elem_sample(const colour_src *cs, size_t i, const float w[3], float rgb[3], float nrm[3])
{
    if (cs->cloud) {
        const asp_cloud *c = cs->cloud;
        for (int k = 0; k < 3; k++) {
            rgb[k] = c->colors ? c->colors[4 * i + (size_t)k] : 200.0f;
            nrm[k] = c->normals ? c->normals[3 * i + (size_t)k] : 0.0f;
        }
        return;
    }
    const asp_mesh *m = cs->mesh;
    const uint32_t *v = m->triangles + 3 * i;
    for (int k = 0; k < 3; k++)
        nrm[k] = w[0] * m->normals[3 * (size_t)v[0] + k] + w[1] * m->normals[3 * (size_t)v[1] + k] +
                 w[2] * m->normals[3 * (size_t)v[2] + k];
    const asp_material *mat = &m->materials[m->material_ids[i] < m->material_count ? m->material_ids[i] : 0];
    if (m->uvs && mat->texture.pixels) {
        /* the texture replaces the diffuse colour, as the sampler and the mesh renderer read OBJ files */
        float uv[2], out[4];
        for (int k = 0; k < 2; k++)
            uv[k] = w[0] * m->uvs[2 * (size_t)v[0] + k] + w[1] * m->uvs[2 * (size_t)v[1] + k] +
                    w[2] * m->uvs[2 * (size_t)v[2] + k];
        asp_image_sample_bilinear(&mat->texture, uv[0], uv[1], out);
        memcpy(rgb, out, 3 * sizeof *rgb);
    } else if (m->colors) {
        for (int k = 0; k < 3; k++)
            rgb[k] = w[0] * m->colors[4 * (size_t)v[0] + k] + w[1] * m->colors[4 * (size_t)v[1] + k] +
                     w[2] * m->colors[4 * (size_t)v[2] + k];
    } else {
        for (int k = 0; k < 3; k++)
            rgb[k] = mat->has_color ? 255.0f * fminf(1.0f, fmaxf(0.0f, mat->diffuse[k])) : 200.0f;
    }
}

/* One plane's frame and extent in its own (s, t) coordinates (local frame of the input). */
typedef struct frame2 {
    double n[3], u[3], v[3], rho;
    double s0, s1, t0, t1;
} frame2;

/* One plane's texture while it is drawn. */
typedef struct tex {
    uint32_t w, h;
    double texel, s_lo, t_lo; /* texel (i, j) centre at (s_lo + (i + 0.5) texel, t_lo + (j + 0.5) texel) */
    uint8_t *rgba, *nrm;
    float *depth;
} tex;

static double dot3(const double *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Frame of plane P over its elements: principal axes of the projected points, tight extent. */
static void plan_frame(const asp__bb_input *in, const asp_billboard_plane *P, const double centre_off,
                       const uint32_t *idx, size_t m, frame2 *f)
{
    memcpy(f->n, P->normal, sizeof f->n);
    f->rho = P->offset - centre_off;
    /* any in-plane basis first: the world axis least aligned with n, made perpendicular */
    double a[3] = {0, 0, 0};
    int ax = fabs(f->n[0]) <= fabs(f->n[1]) && fabs(f->n[0]) <= fabs(f->n[2]) ? 0 : fabs(f->n[1]) <= fabs(f->n[2]) ? 1 : 2;
    a[ax] = 1;
    double u0[3] = {f->n[1] * a[2] - f->n[2] * a[1], f->n[2] * a[0] - f->n[0] * a[2], f->n[0] * a[1] - f->n[1] * a[0]};
    double l = sqrt(u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2]);
    for (int k = 0; k < 3; k++)
        u0[k] /= l;
    double v0[3] = {f->n[1] * u0[2] - f->n[2] * u0[1], f->n[2] * u0[0] - f->n[0] * u0[2], f->n[0] * u0[1] - f->n[1] * u0[0]};
    /* 2D covariance in double (sums of many squares) for the rectangle's orientation */
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, cnt = 0;
    for (size_t q = 0; q < m; q++) {
        const asp__bb_elem *e = &in->elems[idx[q]];
        int nv = e->r > 0 ? 1 : 3;
        for (int j = 0; j < nv; j++) {
            double x = dot3(u0, e->p + 3 * j), y = dot3(v0, e->p + 3 * j);
            sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, cnt += 1;
        }
    }
    double mx = sx / cnt, my = sy / cnt, cxx = sxx / cnt - mx * mx, cyy = syy / cnt - my * my, cxy = sxy / cnt - mx * my;
    double ang = 0.5 * atan2(2 * cxy, cxx - cyy);
    double ca = cos(ang), sa = sin(ang);
    for (int k = 0; k < 3; k++) {
        f->u[k] = ca * u0[k] + sa * v0[k];
        f->v[k] = -sa * u0[k] + ca * v0[k];
    }
    /* u x v = n holds: a rotation of (u0, v0) with u0 x v0 = n */
    f->s0 = f->t0 = DBL_MAX;
    f->s1 = f->t1 = -DBL_MAX;
    for (size_t q = 0; q < m; q++) {
        const asp__bb_elem *e = &in->elems[idx[q]];
        int nv = e->r > 0 ? 1 : 3;
        for (int j = 0; j < nv; j++) {
            double s = dot3(f->u, e->p + 3 * j), t = dot3(f->v, e->p + 3 * j);
            f->s0 = fmin(f->s0, s - e->r), f->s1 = fmax(f->s1, s + e->r);
            f->t0 = fmin(f->t0, t - e->r), f->t1 = fmax(f->t1, t + e->r);
        }
    }
}

static uint32_t side(double extent, double texel)
{
    double c = ceil(extent / texel - 1e-9);
    return c < 1 ? 1 : c > MAX_SIDE ? MAX_SIDE : (uint32_t)c;
}

static void put_texel(tex *T, long i, long j, float depth, const float rgb[3], const float nrm[3])
{
    if (i < 0 || j < 0 || i >= (long)T->w || j >= (long)T->h)
        return;
    size_t o = (size_t)j * T->w + (size_t)i;
    if (T->rgba[4 * o + 3] && T->depth[o] >= depth)
        return;
    T->depth[o] = depth;
    for (int k = 0; k < 3; k++)
        T->rgba[4 * o + k] = (uint8_t)lrintf(fminf(255.0f, fmaxf(0.0f, rgb[k])));
    T->rgba[4 * o + 3] = 255;
    if (T->nrm) {
        float l = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        for (int k = 0; k < 3; k++)
            T->nrm[4 * o + k] = (uint8_t)lrintf(127.5f + 127.5f * (l > 0 ? nrm[k] / l : 0.0f));
        T->nrm[4 * o + 3] = 255;
    }
}

/*
 * Conservative rasterisation of one triangle: a texel is drawn when its square meets the triangle
 * (each edge's half plane pushed out by half the texel's extent along the edge normal), so faces
 * seen nearly edge-on leave no cracks; colour and depth at the texel centre's clamped barycentrics.
 */
static void draw_triangle(const colour_src *cs, const asp__bb_elem *e, size_t ei, const frame2 *f, tex *T)
{
    double x[3], y[3], z[3];
    for (int j = 0; j < 3; j++) {
        x[j] = (dot3(f->u, e->p + 3 * j) - T->s_lo) / T->texel;
        y[j] = (dot3(f->v, e->p + 3 * j) - T->t_lo) / T->texel;
        z[j] = dot3(f->n, e->p + 3 * j) - f->rho;
    }
    double area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    long i0 = (long)floor(fmin(x[0], fmin(x[1], x[2]))) - 1, i1 = (long)ceil(fmax(x[0], fmax(x[1], x[2]))) + 1;
    long j0 = (long)floor(fmin(y[0], fmin(y[1], y[2]))) - 1, j1 = (long)ceil(fmax(y[0], fmax(y[1], y[2]))) + 1;
    /* edge k runs from vertex k+1 to k+2; its function is positive inside for either winding */
    double ea[3], eb[3], ec[3], slack[3];
    const double sg = area2 < 0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; k++) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        ea[k] = sg * (y[a] - y[b]);
        eb[k] = sg * (x[b] - x[a]);
        ec[k] = -(ea[k] * x[a] + eb[k] * y[a]);
        slack[k] = 0.5 * (fabs(ea[k]) + fabs(eb[k]));
    }
    const double aa = fabs(area2);
    for (long j = j0; j <= j1; j++)
        for (long i = i0; i <= i1; i++) {
            double px = i + 0.5, py = j + 0.5;
            int inside = 1;
            double w[3];
            for (int k = 0; k < 3 && inside; k++) {
                w[k] = ea[k] * px + eb[k] * py + ec[k];
                inside = w[k] >= -slack[k];
            }
            if (!inside)
                continue;
            float wf[3];
            if (aa > 1e-12) {
                double s = 0;
                for (int k = 0; k < 3; k++)
                    w[k] = fmax(0.0, w[k] / aa), s += w[k];
                for (int k = 0; k < 3; k++)
                    wf[k] = s > 0 ? (float)(w[k] / s) : 1.0f / 3;
            } else { /* edge-on: a segment; its middle's colour */
                wf[0] = wf[1] = wf[2] = 1.0f / 3;
            }
            float rgb[3], nrm[3];
            elem_sample(cs, ei, wf, rgb, nrm);
            put_texel(T, i, j, (float)(wf[0] * z[0] + wf[1] * z[1] + wf[2] * z[2]), rgb, nrm);
        }
}

static void draw_disc(const colour_src *cs, const asp__bb_elem *e, size_t ei, const frame2 *f, tex *T)
{
    double cx = (dot3(f->u, e->p) - T->s_lo) / T->texel, cy = (dot3(f->v, e->p) - T->t_lo) / T->texel;
    double r = fmax(e->r / T->texel, 0.71); /* at least the texel it falls in */
    float z = (float)(dot3(f->n, e->p) - f->rho);
    float rgb[3], nrm[3];
    static const float w[3] = {1, 0, 0};
    elem_sample(cs, ei, w, rgb, nrm);
    for (long j = (long)floor(cy - r); j <= (long)ceil(cy + r); j++)
        for (long i = (long)floor(cx - r); i <= (long)ceil(cx + r); i++) {
            double dx = i + 0.5 - cx, dy = j + 0.5 - cy;
            if (dx * dx + dy * dy <= r * r)
                put_texel(T, i, j, z, rgb, nrm);
        }
}

/* Texels without coverage take the mean colour of covered neighbours (a few rings), so that linear
 * filtering at the mask's edge mixes in the surface's colour, not black. Alpha stays 0. */
static void dilate(tex *T, uint8_t *mark)
{
    const long W = T->w, H = T->h;
    for (long o = 0; o < W * H; o++)
        mark[o] = T->rgba[4 * o + 3] ? 1 : 0;
    for (int ring = 1; ring <= DILATE; ring++) {
        int any = 0;
        for (long j = 0; j < H; j++)
            for (long i = 0; i < W; i++) {
                long o = j * W + i;
                if (mark[o])
                    continue;
                float s[3] = {0, 0, 0}, ns[3] = {0, 0, 0};
                int c = 0;
                static const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
                for (int k = 0; k < 4; k++) {
                    long ii = i + di[k], jj = j + dj[k];
                    if (ii < 0 || jj < 0 || ii >= W || jj >= H)
                        continue;
                    long q = jj * W + ii;
                    if (!mark[q] || mark[q] > ring)
                        continue;
                    for (int ch = 0; ch < 3; ch++) {
                        s[ch] += T->rgba[4 * q + ch];
                        if (T->nrm)
                            ns[ch] += T->nrm[4 * q + ch];
                    }
                    c++;
                }
                if (!c)
                    continue;
                for (int ch = 0; ch < 3; ch++) {
                    T->rgba[4 * o + ch] = (uint8_t)lrintf(s[ch] / c);
                    if (T->nrm)
                        T->nrm[4 * o + ch] = (uint8_t)lrintf(ns[ch] / c);
                }
                mark[o] = (uint8_t)(ring + 1);
                any = 1;
            }
        if (!any)
            break;
    }
}

/* The whole build on elements in: search, frames, texel size, textures, atlas, the .dps. */
static int build(const asp__bb_input *in, const colour_src *cs, const asp_billboard_desc *d, const char *source,
                 const double origin[3], const asp_frame *frame, double mean_radius, const asp_context *ctx,
                 asp_dps **out, asp_billboard_stats *st_out, asp_error *err)
{
    if (d->texels && d->texel_size > 0)
        return asp_error_set(err, ASP_EINVAL, "give a texel size or a texel count for billboards, not both");
    if (!(d->texel_size >= 0 && d->texel_size <= 1))
        return asp_error_set(err, ASP_EINVAL, "billboard texel size %g, expected a fraction of the diagonal in (0, 1]",
                             d->texel_size);
    asp_billboard_plane *planes = NULL;
    size_t np = 0, n = in->count;
    asp_billboard_stats st = {0};
    uint32_t *assign = asp_alloc(ctx, n * sizeof *assign);
    if (!assign)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboard elements", n);
    int rc = asp__bb_search(in, d, ctx, &planes, &np, assign, &st, err);
    if (rc) {
        asp_free(ctx, assign);
        return rc;
    }
    const double t0 = asp_time_now();
    size_t *first = asp_calloc(ctx, np + 2, sizeof *first);
    uint32_t *order = asp_alloc(ctx, (n ? n : 1) * sizeof *order);
    frame2 *fr = asp_calloc(ctx, np ? np : 1, sizeof *fr);
    tex *tx = asp_calloc(ctx, np ? np : 1, sizeof *tx);
    uint32_t *w = asp_alloc(ctx, 4 * (np ? np : 1) * sizeof *w), *h = w ? w + np : NULL, *x = w ? h + np : NULL,
             *y = w ? x + np : NULL;
    asp_dps *dps = asp_calloc(ctx, 1, sizeof *dps);
    asp_dps_level *lv = dps ? asp_calloc(ctx, 1, sizeof *lv) : NULL;
    if (!first || !order || !fr || !tx || !w || !dps || !lv) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the textures of %zu billboards", np);
        goto done;
    }
    if (!np) {
        rc = asp_error_set(err, ASP_EDEGENERATE, "the billboard search made no plane");
        goto done;
    }
    /* elements grouped by plane, in index order (counting sort: deterministic) */
    for (size_t i = 0; i < n; i++)
        if (assign[i] != UINT32_MAX)
            first[assign[i] + 2]++;
    for (size_t k = 0; k < np; k++)
        first[k + 2] += first[k + 1];
    for (size_t i = 0; i < n; i++)
        if (assign[i] != UINT32_MAX)
            order[first[assign[i] + 1]++] = (uint32_t)i;
    const double coff = 0; /* planes are in the input's local frame relative to in->centre already */
    const int nth = asp_context_threads(ctx);
    (void)nth;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nth)
    for (long k = 0; k < (long)np; k++)
        plan_frame(in, &planes[k], coff, order + first[k], first[k + 1] - first[k], &fr[k]);
    /* the texel: given, or chosen for the texel count (the rounding up of the sides, iterated out) */
    double area = 0;
    for (size_t k = 0; k < np; k++)
        area += (fr[k].s1 - fr[k].s0) * (fr[k].t1 - fr[k].t0);
    double T = d->texel_size > 0 ? d->texel_size * in->diagonal : in->diagonal / 512.0;
    if (d->texels) {
        T = sqrt(fmax(area, 1e-300) / (double)d->texels);
        for (int it = 0; it < 8; it++) {
            double got = 0;
            for (size_t k = 0; k < np; k++)
                got += (double)side(fr[k].s1 - fr[k].s0, T) * side(fr[k].t1 - fr[k].t0, T);
            T *= sqrt(got / (double)d->texels);
        }
    }
    int capped = 0;
    for (int attempt = 0;; attempt++) {
        for (size_t k = 0; k < np; k++) {
            double es = fr[k].s1 - fr[k].s0, et = fr[k].t1 - fr[k].t0, Tk = T;
            if (es / Tk > MAX_SIDE || et / Tk > MAX_SIDE)
                Tk = fmax(es, et) / MAX_SIDE, capped++;
            tx[k].texel = Tk;
            tx[k].w = side(es, Tk), tx[k].h = side(et, Tk);
            /* the rectangle grows to whole texels around the extent's middle */
            tx[k].s_lo = 0.5 * (fr[k].s0 + fr[k].s1) - 0.5 * tx[k].w * Tk;
            tx[k].t_lo = 0.5 * (fr[k].t0 + fr[k].t1) - 0.5 * tx[k].h * Tk;
            w[k] = tx[k].w, h[k] = tx[k].h;
        }
        uint32_t aw = 0, ah = 0;
        int pk = asp__atlas_pack(w, h, np, PAD, ATLAS_SIDE, x, y, &aw, &ah, ctx);
        if (pk == -2) {
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the billboard atlas layout");
            goto done;
        }
        if (pk == 0) {
            rc = asp_image_init(&lv->atlas, aw, ah, err);
            if (!rc && d->normal_map)
                rc = asp_image_init(&lv->normal_atlas, aw, ah, err);
            if (rc)
                goto done;
            break;
        }
        if (attempt == 2) {
            rc = asp_error_set(err, ASP_EUNSUPPORTED, "the textures of %zu billboards do not fit a %dx%d atlas even "
                               "at a texel of %g; raise the texel size", np, ATLAS_SIDE, ATLAS_SIDE, T);
            goto done;
        }
        T *= 2;
        capped = 0;
    }
    lv->prims = asp_calloc(ctx, np, sizeof *lv->prims);
    if (!lv->prims) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboards", np);
        goto done;
    }
    int failed = 0;
    double err_sum = 0, err_n = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nth) reduction(| : failed)
    for (long k = 0; k < (long)np; k++) {
        tex *t = &tx[k];
        size_t texels = (size_t)t->w * t->h;
        t->rgba = asp_calloc(ctx, texels, 4);
        t->nrm = d->normal_map ? asp_calloc(ctx, texels, 4) : NULL;
        t->depth = asp_alloc(ctx, texels * sizeof *t->depth);
        uint8_t *mark = asp_alloc(ctx, texels);
        if (!t->rgba || (d->normal_map && !t->nrm) || !t->depth || !mark) {
            failed |= 1;
            asp_free(ctx, mark);
            continue;
        }
        for (size_t q = first[k]; q < first[k + 1]; q++) {
            const asp__bb_elem *e = &in->elems[order[q]];
            if (e->r > 0)
                draw_disc(cs, e, order[q], &fr[k], t);
            else
                draw_triangle(cs, e, order[q], &fr[k], t);
        }
        dilate(t, mark);
        asp_free(ctx, mark);
    }
    if (failed) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the billboard textures");
        goto done;
    }
    uint64_t texels = 0;
    for (size_t k = 0; k < np; k++) {
        asp_prim *P = &lv->prims[k];
        const frame2 *f = &fr[k];
        const tex *t = &tx[k];
        double sc = t->s_lo + 0.5 * t->w * t->texel, tc = t->t_lo + 0.5 * t->h * t->texel;
        double perr = 0, pn = 0;
        for (size_t q = first[k]; q < first[k + 1]; q++) {
            const asp__bb_elem *e = &in->elems[order[q]];
            int nv = e->r > 0 ? 1 : 3;
            for (int j = 0; j < nv; j++)
                perr += fabs(dot3(f->n, e->p + 3 * j) - f->rho), pn += 1;
        }
        err_sum += perr, err_n += pn;
        for (int c = 0; c < 3; c++) {
            P->centre[c] = origin[c] + in->centre[c] + f->n[c] * f->rho + f->u[c] * sc + f->v[c] * tc;
            P->axis_u[c] = (float)f->u[c];
            P->axis_v[c] = (float)f->v[c];
            P->normal[c] = (float)f->n[c];
        }
        P->half_u = (float)(0.5 * t->w * t->texel);
        P->half_v = (float)(0.5 * t->h * t->texel);
        P->texel = (float)t->texel;
        P->error = (float)(pn > 0 ? perr / pn : 0);
        P->error_norm = (float)(P->error / mean_radius);
        P->points = (uint32_t)(first[k + 1] - first[k]);
        P->basis = (uint32_t)k;
        P->merged = 1;
        P->flags = t->texel > T * (1 + 1e-9) ? ASP_PRIM_FLAG_CAPPED : 0;
        P->tex_x = x[k], P->tex_y = y[k], P->tex_w = t->w, P->tex_h = t->h;
        texels += (uint64_t)t->w * t->h;
        for (uint32_t j = 0; j < t->h; j++) {
            size_t dst = 4 * ((size_t)(y[k] + j) * lv->atlas.width + x[k]);
            memcpy(lv->atlas.pixels + dst, t->rgba + 4 * (size_t)j * t->w, 4 * (size_t)t->w);
            if (t->nrm)
                memcpy(lv->normal_atlas.pixels + dst, t->nrm + 4 * (size_t)j * t->w, 4 * (size_t)t->w);
        }
        if (P->flags & ASP_PRIM_FLAG_CAPPED)
            lv->capped++;
    }
    asp__atlas_pad(&lv->atlas, lv->prims, np, PAD);
    if (d->normal_map)
        asp__atlas_pad(&lv->normal_atlas, lv->prims, np, PAD);
    lv->level = 0;
    lv->basis_count = (uint32_t)np;
    lv->prim_count = np;
    lv->texels = texels;
    lv->error = err_n > 0 ? err_sum / err_n : 0;
    lv->error_norm = lv->error / mean_radius;
    lv->t_basis = st.t_search;
    lv->t_construct = asp_time_now() - t0;
    lv->billboards = 1;
    dps->level_count = 1;
    dps->levels = lv;
    lv = NULL;
    dps->amg_levels = 1;
    dps->source_points = n;
    dps->mean_radius = mean_radius;
    dps->desc.texel_size = T / mean_radius;
    dps->desc.normal_map = d->normal_map;
    dps->desc.padding = PAD;
    dps->desc.max_texture = MAX_SIDE;
    snprintf(dps->source, sizeof dps->source, "%s", source ? source : "");
    dps->frame = *frame;
    dps->ctx = ctx ? *ctx : (asp_context){0};
    st.texel = T;
    st.texels = texels;
    st.t_texture = dps->levels[0].t_construct;
    if (st_out)
        *st_out = st;
    *out = dps;
    dps = NULL;
done:
    for (size_t k = 0; tx && k < np; k++) {
        asp_free(ctx, tx[k].rgba);
        asp_free(ctx, tx[k].nrm);
        asp_free(ctx, tx[k].depth);
    }
    if (lv) {
        asp_image_release(&lv->atlas);
        asp_image_release(&lv->normal_atlas);
        asp_free(ctx, lv->prims);
        asp_free(ctx, lv);
    }
    asp_free(ctx, dps);
    asp_free(ctx, tx);
    asp_free(ctx, fr);
    asp_free(ctx, w);
    asp_free(ctx, order);
    asp_free(ctx, first);
    asp_free(ctx, planes);
    asp_free(ctx, assign);
    return rc;
}

int asp_billboard_mesh(const asp_mesh *mesh, const asp_billboard_desc *desc, const char *source,
                       const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, asp_error *err)
{
    ASP_ASSERT(mesh && desc && out);
    asp__bb_input in;
    int rc = asp__bb_input_mesh(mesh, ctx, &in, err);
    if (rc)
        return rc;
    asp_frame frame;
    rc = asp_positions_frame(mesh->positions, mesh->vertex_count, mesh->origin, 0.0, &frame, err);
    if (!rc) {
        colour_src cs = {mesh, NULL};
        double T = desc->texel_size > 0 ? desc->texel_size * in.diagonal : in.diagonal / 512.0;
        /* a mesh has no point radius: the .dps's radius unit is the texel asked for */
        rc = build(&in, &cs, desc, source, mesh->origin, &frame, T, ctx, out, stats, err);
    }
    asp__bb_input_release(&in, ctx);
    return rc;
}

int asp_billboard_cloud(const asp_cloud *cloud, const asp_billboard_desc *desc, const char *source,
                        const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, asp_error *err)
{
    ASP_ASSERT(cloud && desc && out);
    asp__bb_input in;
    int rc = asp__bb_input_cloud(cloud, ctx, &in, err);
    if (rc)
        return rc;
    asp_frame frame;
    rc = asp_cloud_frame(cloud, &frame, err);
    if (!rc) {
        double rs = 0;
        for (size_t i = 0; i < in.count; i++)
            rs += in.elems[i].r;
        colour_src cs = {NULL, cloud};
        rc = build(&in, &cs, desc, source, cloud->origin, &frame, rs / (double)in.count, ctx, out, stats, err);
    }
    asp__bb_input_release(&in, ctx);
    return rc;
}
