/*
 * CPU rasteriser of a level's support rectangles as the normalized method
 * draws them (Pajarola et al. 2003 5.3-5.4, thesis 5.3.1; src/render/
 * prim_shaders.c): a front layer of alpha-tested, front-facing fragments, the
 * sum of (shade(colour) alpha, alpha) of every fragment within the depth
 * window behind it, then the division. Written as linear rows over the atlas
 * texels (internal.h), so the same pass renders and builds the least squares.
 */
#include <math.h>
#include <string.h>

#include "fit/internal.h"
#include "util/banned.h"

/* One primitive in eye space. */
typedef struct eye_prim {
    double c[3], u[3], v[3], n[3]; /* centre, axis_u half_u, axis_v half_v, unit normal */
    double uu, vv;                 /* |u|^2, |v|^2 */
    double shade;                  /* 0.25 + 0.75 |n . l|, or 1 unlit */
    int x0, y0, x1, y1;            /* pixel box, inclusive; x1 < x0 when culled */
} eye_prim;

typedef asp__fit_frag frag;

float asp__fit_srgb_to_linear(uint8_t v)
{
    double c = v / 255.0;
    return (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
}

uint8_t asp__fit_linear_to_srgb(double v)
{
    double c = v <= 0 ? 0 : v >= 1 ? 1 : v;
    double s = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
    return (uint8_t)lround(s * 255.0);
}

float *asp__fit_atlas_linear(const asp_image *atlas, const asp_context *ctx)
{
    size_t n = (size_t)atlas->width * atlas->height;
    float *lin = asp_alloc(ctx, 3 * n * sizeof(float) + 1);
    if (!lin)
        return NULL;
    float table[256];
    for (int i = 0; i < 256; i++)
        table[i] = asp__fit_srgb_to_linear((uint8_t)i);
    for (size_t t = 0; t < n; t++)
        for (int c = 0; c < 3; c++)
            lin[3 * t + c] = table[atlas->pixels[4 * t + c]];
    return lin;
}

void asp__fit_rows_release(asp__fit_rows *rows, const asp_context *ctx)
{
    asp_free(ctx, rows->first);
    asp_free(ctx, rows->texel);
    asp_free(ctx, rows->coef);
    memset(rows, 0, sizeof *rows);
}

static void mat_apply(const float m[16], const double p[3], double w, double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * w;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The pixel box of the rectangle; the whole image when a corner is not in front of the eye. */
static void pixel_box(eye_prim *e, const asp_fit_view *v)
{
    double xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
    int whole = 0;
    for (int k = 0; k < 4; k++) {
        double su = k & 1 ? 1 : -1, sv = k & 2 ? 1 : -1, p[3];
        for (int a = 0; a < 3; a++)
            p[a] = e->c[a] + su * e->u[a] + sv * e->v[a];
        if (!(p[2] < -1e-9)) {
            whole = 1;
            break;
        }
        // ndc = P p / -z for a symmetric frustum; pixel x from the left, y from the top
        double nx = v->proj[0] * p[0] / -p[2], ny = v->proj[5] * p[1] / -p[2];
        double px = (nx + 1) * 0.5 * v->width, py = (1 - ny) * 0.5 * v->height;
        xmin = fmin(xmin, px), xmax = fmax(xmax, px), ymin = fmin(ymin, py), ymax = fmax(ymax, py);
    }
    if (whole) {
        e->x0 = e->y0 = 0, e->x1 = (int)v->width - 1, e->y1 = (int)v->height - 1;
        return;
    }
    // pixel i is covered when its centre i + 0.5 is inside
    double fx0 = floor(xmin - 0.5), fx1 = ceil(xmax - 0.5), fy0 = floor(ymin - 0.5), fy1 = ceil(ymax - 0.5);
    e->x0 = (int)fmax(fx0, 0), e->y0 = (int)fmax(fy0, 0);
    e->x1 = (int)fmin(fx1, (double)v->width - 1), e->y1 = (int)fmin(fy1, (double)v->height - 1);
}

static void eye_prims(const asp_dps_level *lv, const double origin[3], const asp_fit_view *v, int unlit,
                      eye_prim *e)
{
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        eye_prim *q = &e[i];
        double c[3], u[3], w[3], n[3];
        for (int a = 0; a < 3; a++) {
            c[a] = p->centre[a] - origin[a];
            u[a] = (double)p->axis_u[a] * p->half_u;
            w[a] = (double)p->axis_v[a] * p->half_v;
            n[a] = p->normal[a];
        }
        mat_apply(v->view, c, 1, q->c);
        mat_apply(v->view, u, 0, q->u);
        mat_apply(v->view, w, 0, q->v);
        mat_apply(v->view, n, 0, q->n);
        double nn = sqrt(dot3(q->n, q->n));
        for (int a = 0; a < 3 && nn > 0; a++)
            q->n[a] /= nn;
        q->uu = dot3(q->u, q->u), q->vv = dot3(q->v, q->v);
        double l[3] = {v->light[0], v->light[1], v->light[2]};
        q->shade = unlit || !(nn > 0) ? 1.0 : 0.25 + 0.75 * fabs(dot3(q->n, l));
        // back faces are culled in both passes (render-methods.md, normalized); the strip is
        // counter-clockwise seen from the normal side, so front-facing = the eye on that side
        q->x1 = -1, q->x0 = 0;
        if (!(dot3(q->n, q->c) < 0) || !(q->uu > 0) || !(q->vv > 0))
            continue;
        pixel_box(q, v);
    }
}

/* Bilinear lookup of channel ch (0..3) of an RGBA8 image as unorm, clamped to the edge. */
void asp__fit_bilinear(const asp_image *img, float tx, float ty, uint32_t idx[4], float wgt[4])
{
    float x = tx - 0.5f, y = ty - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    long ix = (long)fx, iy = (long)fy;
    long w = (long)img->width, h = (long)img->height;
    for (int k = 0; k < 4; k++) {
        long cx = ix + (k & 1), cy = iy + (k >> 1);
        cx = cx < 0 ? 0 : cx >= w ? w - 1 : cx;
        cy = cy < 0 ? 0 : cy >= h ? h - 1 : cy;
        idx[k] = (uint32_t)(cy * w + cx);
        wgt[k] = ((k & 1) ? ax : 1 - ax) * ((k >> 1) ? ay : 1 - ay);
    }
}

static float sample_alpha(const asp_image *img, float tx, float ty)
{
    uint32_t idx[4];
    float w[4], a = 0;
    asp__fit_bilinear(img, tx, ty, idx, w);
    for (int k = 0; k < 4; k++)
        a += w[k] * (float)img->pixels[4 * (size_t)idx[k] + 3] * (1.0f / 255.0f);
    return a;
}

/* Shade from the normal map (shader's shade(): the texel normal where it is not zero). */
static float normal_map_shade(const asp_dps_level *lv, const asp_fit_view *v, float tx, float ty, float fallback)
{
    uint32_t idx[4];
    float w[4], m[3] = {0, 0, 0};
    asp__fit_bilinear(&lv->normal_atlas, tx, ty, idx, w);
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++)
            m[a] += w[k] * (float)lv->normal_atlas.pixels[4 * (size_t)idx[k] + a] * (1.0f / 255.0f);
    double d[3] = {m[0] * 2.0 - 1.0, m[1] * 2.0 - 1.0, m[2] * 2.0 - 1.0}, e[3];
    if (!(dot3(d, d) > 1e-4))
        return fallback;
    mat_apply(v->view, d, 0, e);
    double l[3] = {v->light[0], v->light[1], v->light[2]};
    return (float)(0.25 + 0.75 * fabs(dot3(e, l)) / sqrt(dot3(e, e)));
}

/* The fragment of prim i at the pixel whose eye ray is d, if the rectangle covers it. */
static int hit(const asp_dps_level *lv, const asp_fit_view *v, const asp_fit_draw *draw, const eye_prim *e,
               uint32_t i, const double d[3], frag *f)
{
    double nd = dot3(e->n, d);
    if (!(fabs(nd) > 1e-12))
        return 0;
    double t = dot3(e->n, e->c) / nd;
    if (!(t > 0))
        return 0;
    double p[3] = {t * d[0], t * d[1], t * d[2]}, r[3] = {p[0] - e->c[0], p[1] - e->c[1], p[2] - e->c[2]};
    double ku = dot3(r, e->u) / e->uu, kv = dot3(r, e->v) / e->vv;
    if (!(fabs(ku) <= 1 && fabs(kv) <= 1))
        return 0;
    const asp_prim *q = &lv->prims[i];
    f->prim = i;
    f->tx = (float)(q->tex_x + (0.5 * ku + 0.5) * q->tex_w);
    f->ty = (float)(q->tex_y + (0.5 * kv + 0.5) * q->tex_h);
    f->a = sample_alpha(&lv->atlas, f->tx, f->ty);
    f->shade = (float)e->shade;
    if (!draw->unlit && lv->normal_atlas.width)
        f->shade = normal_map_shade(lv, v, f->tx, f->ty, (float)e->shade);
    f->z = -p[2];
    f->len = sqrt(dot3(p, p));
    return 1;
}

static double default_window(const asp_dps_level *lv)
{
    double sum = 0;
    for (size_t i = 0; i < lv->prim_count; i++)
        sum += sqrt((double)lv->prims[i].half_u * lv->prims[i].half_v);
    return 0.5 * sum / (double)lv->prim_count;
}

/* Fragments per pixel, as CSR: ff[p] .. ff[p + 1] - 1 in frags, in primitive order. */
static int gather(const asp_dps_level *lv, const asp_fit_view *v, const asp_fit_draw *draw, const eye_prim *e,
                  int all, const asp_context *ctx, size_t **first_out, frag **frags_out, asp_error *err)
{
    size_t np = (size_t)v->width * v->height;
    size_t *first = asp_calloc(ctx, np + 1, sizeof *first);
    if (!first)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %ux%u fit view", v->width, v->height);
    frag *frags = NULL;
    // two sweeps: count, then fill; the fragment tests are cheap next to the solve
    for (int sweep = 0; sweep < 2; sweep++) {
        for (uint32_t i = 0; i < lv->prim_count; i++) {
            const eye_prim *q = &e[i];
            for (int y = q->y0; y <= q->y1 && q->x1 >= q->x0; y++) {
                double ny = 1 - 2 * (y + 0.5) / v->height;
                for (int x = q->x0; x <= q->x1; x++) {
                    double nx = 2 * (x + 0.5) / v->width - 1;
                    double d[3] = {nx / v->proj[0], ny / v->proj[5], -1};
                    frag f;
                    if (!hit(lv, v, draw, q, i, d, &f) || !(all || f.a > 0))
                        continue;
                    size_t p = (size_t)y * v->width + (size_t)x;
                    if (sweep == 0)
                        first[p + 1]++;
                    else
                        frags[first[p]++] = f;
                }
            }
        }
        if (sweep == 0) {
            for (size_t p = 0; p < np; p++)
                first[p + 1] += first[p];
            frags = asp_alloc(ctx, (first[np] + 1) * sizeof *frags);
            if (!frags) {
                asp_free(ctx, first);
                return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu fragments", first[np]);
            }
        } else {
            // the fill advanced each start to the next pixel's start; shift back
            memmove(first + 1, first, np * sizeof *first);
            first[0] = 0;
        }
    }
    *first_out = first;
    *frags_out = frags;
    return 0;
}

void asp__fit_draw_resolve(const asp_dps_level *lv, const asp_fit_draw *in, asp_fit_draw *out, double *window)
{
    *out = in ? *in : (asp_fit_draw){0};
    if (!(out->alpha_ref > 0))
        out->alpha_ref = out->alpha_ref < 0 ? 0.0f : 0.1f;
    *window = out->depth_window > 0 ? out->depth_window : out->depth_window < 0 ? 0 : default_window(lv);
}

int asp__fit_fragments(const asp_dps_level *lv, const double origin[3], const asp_fit_view *v,
                       const asp_fit_draw *draw, int all, const asp_context *ctx, size_t **first,
                       asp__fit_frag **frags, asp_error *err)
{
    if (!lv->prim_count || !v->width || !v->height || !lv->atlas.width)
        return asp_error_set(err, ASP_EINVAL, "cannot rasterise: empty level or zero image size");
    eye_prim *e = asp_alloc(ctx, lv->prim_count * sizeof *e);
    if (!e)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu primitives", lv->prim_count);
    eye_prims(lv, origin, v, draw->unlit, e);
    int rc = gather(lv, v, draw, e, all, ctx, first, frags, err);
    asp_free(ctx, e);
    return rc;
}

int asp__fit_raster(const asp_dps_level *lv, const double origin[3], const asp_fit_view *v,
                    const asp_fit_draw *draw_in, const asp_context *ctx, asp__fit_rows *rows, asp_error *err)
{
    asp_fit_draw draw;
    double window;
    asp__fit_draw_resolve(lv, draw_in, &draw, &window);
    size_t *ff = NULL;
    frag *frags = NULL;
    int rc = asp__fit_fragments(lv, origin, v, &draw, 0, ctx, &ff, &frags, err);
    if (rc)
        return rc;
    size_t np = (size_t)v->width * v->height;
    memset(rows, 0, sizeof *rows);
    rows->width = v->width, rows->height = v->height;
    rows->first = asp_calloc(ctx, np + 1, sizeof *rows->first);
    rows->texel = asp_alloc(ctx, (4 * ff[np] + 1) * sizeof *rows->texel);
    rows->coef = asp_alloc(ctx, (4 * ff[np] + 1) * sizeof *rows->coef);
    if (!rows->first || !rows->texel || !rows->coef) {
        asp__fit_rows_release(rows, ctx);
        asp_free(ctx, ff);
        asp_free(ctx, frags);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu fragments", ff[np]);
    }
    size_t out = 0;
    for (size_t p = 0; p < np; p++) {
        rows->first[p] = out;
        const frag *fp = frags + ff[p];
        size_t nf = ff[p + 1] - ff[p];
        // pass 1: the front-most alpha-tested fragment
        double front = INFINITY;
        for (size_t k = 0; k < nf; k++)
            if (fp[k].a > draw.alpha_ref && fp[k].z < front)
                front = fp[k].z;
        if (!isfinite(front))
            continue;
        // pass 2: fragments within the window behind it along their eye ray (the shader's selected())
        double sum = 0;
        for (size_t k = 0; k < nf; k++)
            if ((fp[k].z - front) * fp[k].len / fp[k].z <= window + 1e-5 * fp[k].len)
                sum += fp[k].a;
        for (size_t k = 0; k < nf && sum > 0; k++) {
            if (!((fp[k].z - front) * fp[k].len / fp[k].z <= window + 1e-5 * fp[k].len))
                continue;
            uint32_t idx[4];
            float w[4];
            asp__fit_bilinear(&lv->atlas, fp[k].tx, fp[k].ty, idx, w);
            double s = fp[k].a * fp[k].shade / sum;
            for (int j = 0; j < 4; j++) {
                if (w[j] == 0)
                    continue;
                rows->texel[out] = idx[j];
                rows->coef[out] = (float)(s * w[j]);
                out++;
            }
        }
    }
    rows->first[np] = out;
    rows->total = out;
    asp_free(ctx, ff);
    asp_free(ctx, frags);
    return 0;
}

double asp__fit_rows_loss(const asp__fit_rows *rows, const float *lin, const asp_image *ref, size_t *count)
{
    double sum = 0;
    size_t n = 0, np = (size_t)rows->width * rows->height;
    for (size_t p = 0; p < np; p++) {
        if (rows->first[p + 1] == rows->first[p] || ref->pixels[4 * p + 3] == 0)
            continue;
        double c[3] = {0, 0, 0};
        for (size_t k = rows->first[p]; k < rows->first[p + 1]; k++)
            for (int a = 0; a < 3; a++)
                c[a] += (double)rows->coef[k] * lin[3 * (size_t)rows->texel[k] + a];
        for (int a = 0; a < 3; a++) {
            double d = c[a] - asp__fit_srgb_to_linear(ref->pixels[4 * p + a]);
            sum += d * d;
        }
        n++;
    }
    if (count)
        *count = n;
    return n ? sum / (3.0 * (double)n) : 0.0;
}

int asp_fit_render_cpu(const asp_dps_level *lv, const double origin[3], const asp_fit_view *view,
                       const asp_fit_draw *draw, asp_image *out, asp_error *err)
{
    asp_context ctx = {0};
    asp__fit_rows rows;
    asp_fit_draw d = draw ? *draw : (asp_fit_draw){0};
    int rc = asp__fit_raster(lv, origin, view, &d, &ctx, &rows, err);
    if (rc)
        return rc;
    float *lin = asp__fit_atlas_linear(&lv->atlas, &ctx);
    asp_image img = {0};
    if (!lin || asp_image_init(&img, view->width, view->height, err)) {
        asp_free(&ctx, lin);
        asp__fit_rows_release(&rows, &ctx);
        return lin ? (err ? err->code : ASP_ENOMEM) : asp_error_set(err, ASP_ENOMEM, "out of memory for the atlas");
    }
    size_t np = (size_t)view->width * view->height;
    for (size_t p = 0; p < np; p++) {
        if (rows.first[p + 1] == rows.first[p])
            continue;
        double c[3] = {0, 0, 0};
        for (size_t k = rows.first[p]; k < rows.first[p + 1]; k++)
            for (int a = 0; a < 3; a++)
                c[a] += (double)rows.coef[k] * lin[3 * (size_t)rows.texel[k] + a];
        for (int a = 0; a < 3; a++)
            img.pixels[4 * p + a] = asp__fit_linear_to_srgb(c[a]);
        img.pixels[4 * p + 3] = 255;
    }
    asp_free(&ctx, lin);
    asp__fit_rows_release(&rows, &ctx);
    *out = img;
    return 0;
}
