/*
 * Domain-primitive construction for whole levels (journal section 3, thesis
 * chapter 3 and Table 5.2): basis and thresholded domains of a level, optional
 * merging (3.4), one support plane and texture per domain (3.1-3.3), the
 * level's atlas and the neighbour lists (journal section 4).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amgsplat/geom.h"
#include "prim/internal.h"
#include "util/banned.h"

enum { ATLAS_MAX = 16384 };

/* Per-point inputs shared by all levels. */
typedef struct build_src {
    const asp_cloud *cloud;   /* positions, normals, origin */
    const uint8_t *colors;    /* 4n, or NULL (grey) */
    const float *radii;       /* n */
    double mean_radius;
} build_src;

/* Per-primitive layout decided in pass 1. */
typedef struct layout {
    asp__plane pl;
    size_t row;           /* domain row */
    double texel, s0, t0; /* texel size and the texture grid's origin in plane coordinates */
    double foot;          /* footprint factor: 1 (affine) or w (radial) */
    uint32_t w, h;
    int capped;
} layout;

static void resolve_desc(const asp_prim_desc *in, asp_prim_desc *d)
{
    *d = in ? *in : (asp_prim_desc){0};
    if (d->tau == 0)
        d->tau = 0.05;
    if (d->texel_size == 0)
        d->texel_size = 1;
    if (d->max_texture == 0)
        d->max_texture = 512;
    if (d->width == 0)
        d->width = 1;
    if (d->neighbour_fraction == 0)
        d->neighbour_fraction = 0.05;
    if (d->merge_flatness == 0)
        d->merge_flatness = 0.01;
    if (d->merge_angle == 0)
        d->merge_angle = 15;
    if (d->padding == 0)
        d->padding = 2;
}

static int check_desc(const asp_prim_desc *d, asp_error *err)
{
    if (!(d->tau >= 0 && d->tau < 1))
        return asp_error_set(err, ASP_EINVAL, "domain threshold tau must be in [0, 1), got %g", d->tau);
    if (!(d->texel_size > 0 && d->texel_size < 1e6))
        return asp_error_set(err, ASP_EINVAL, "texel size must be positive, got %g", d->texel_size);
    if (d->max_texture > ATLAS_MAX / 2)
        return asp_error_set(err, ASP_EINVAL, "texture cap must be at most %d texels, got %u", ATLAS_MAX / 2,
                             d->max_texture);
    if (!(d->width > 0 && d->width <= 16))
        return asp_error_set(err, ASP_EINVAL, "radial width factor must be in (0, 16], got %g", d->width);
    if (!(d->neighbour_fraction > 0 && d->neighbour_fraction < 1))
        return asp_error_set(err, ASP_EINVAL, "neighbour fraction must be in (0, 1), got %g", d->neighbour_fraction);
    if (!(d->merge_flatness > 0 && d->merge_flatness <= 1.0 / 3))
        return asp_error_set(err, ASP_EINVAL, "merge flatness must be in (0, 1/3], got %g", d->merge_flatness);
    if (!(d->merge_angle > 0 && d->merge_angle <= 180))
        return asp_error_set(err, ASP_EINVAL, "merge angle must be in (0, 180] degrees, got %g", d->merge_angle);
    if (!(d->brightness >= -1 && d->brightness <= 1))
        return asp_error_set(err, ASP_EINVAL, "brightness must be in [-1, 1], got %g", d->brightness);
    if (!(d->enlarge >= 0 && d->enlarge <= 1000))
        return asp_error_set(err, ASP_EINVAL, "rectangle enlargement must be in [0, 1000] percent, got %g",
                             d->enlarge);
    if (d->padding > 64)
        return asp_error_set(err, ASP_EINVAL, "atlas padding must be at most 64 texels, got %u", d->padding);
    if (d->fill && d->normal_map)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the texture fill of desc.fill (GPU) makes no normal maps; "
                             "build the normal maps on the CPU");
    if ((unsigned)d->strict > ASP_PRIM_DOMAINS_BOTH)
        return asp_error_set(err, ASP_EINVAL, "unknown domain set %d (expected 0 thresholded, 1 strict, 2 both)",
                             d->strict);
    if ((unsigned)d->method > ASP_PRIM_RADIAL || (unsigned)d->shape > ASP_PRIM_GAUSSIAN ||
        (unsigned)d->normalise > ASP_PRIM_NORM_GE1)
        return asp_error_set(err, ASP_EINVAL, "unknown texture method, shape or normalisation");
    return 0;
}

static double point_radius(const build_src *src, const asp__plane *pl, const asp_prim_desc *d, size_t p)
{
    double r = src->radii[p];
    if (d->project_radii && src->cloud->normals) {
        const float *n = &src->cloud->normals[3 * p];
        /* thesis 3.1: r |n_p . n|; a floor keeps edge-on points from vanishing entirely */
        r *= fmax(fabs(n[0] * pl->n[0] + n[1] * pl->n[1] + n[2] * pl->n[2]), 0.05);
    }
    return r;
}

/*
 * The colour a point gives the texture: the model's or grey (thesis appendix C "Use Model Colors"),
 * its HSV value shifted by desc->brightness ("Adjust Brightness"): scaling RGB by V' / V keeps hue
 * and saturation.
 */
static void point_color(const build_src *src, const asp_prim_desc *d, size_t p, float out[3])
{
    for (int j = 0; j < 3; j++)
        out[j] = src->colors && !d->no_model_colors ? src->colors[4 * p + (size_t)j] : 200.0f;
    if (d->brightness == 0)
        return;
    float v = fmaxf(out[0], fmaxf(out[1], out[2]));
    float nv = fminf(255.0f, fmaxf(0.0f, v + (float)d->brightness * 255.0f));
    for (int j = 0; j < 3; j++)
        out[j] = v > 0 ? out[j] * (nv / v) : nv;
}

/* Pass 1 for one domain: plane, rectangle with margin, texel grid. */
static void plan_one(const build_src *src, const asp_amg_csr *dom, const asp_prim_desc *d, layout *L)
{
    size_t a = dom->row_ptr[L->row], n = dom->row_ptr[L->row + 1] - a;
    const asp_cloud *c = src->cloud;
    asp__prim_plane(c->positions, c->normals, &dom->col[a], &dom->val[a], n, d->unweighted, &L->pl);
    L->foot = d->method == ASP_PRIM_RADIAL ? d->width : 1.0;
    double rmax = 0, rsum = 0;
    for (size_t k = 0; k < n; k++) {
        double r = point_radius(src, &L->pl, d, dom->col[a + k]);
        rmax = fmax(rmax, r);
        rsum += r;
    }
    /* margin: the largest footprint, but at most 3x the domain's mean, so one outlier radius cannot bloat it */
    double margin = L->foot * fmin(rmax, 3 * rsum / (double)n);
    double ew = L->pl.smax - L->pl.smin + 2 * margin, eh = L->pl.tmax - L->pl.tmin + 2 * margin;
    if (d->enlarge > 0) {
        /* thesis appendix C: the sides grown by a percentage so the point samples fall inside */
        ew = (L->pl.smax - L->pl.smin) * (1 + d->enlarge / 100);
        eh = (L->pl.tmax - L->pl.tmin) * (1 + d->enlarge / 100);
    }
    double T = d->texel_size * src->mean_radius;
    double wf = ceil(ew / T), hf = ceil(eh / T);
    L->capped = 0;
    if (wf > d->max_texture || hf > d->max_texture) {
        T = fmax(ew, eh) / d->max_texture * (1 + 1e-9);
        wf = ceil(ew / T), hf = ceil(eh / T);
        L->capped = 1;
    }
    L->w = (uint32_t)fmax(1, fmin(wf, d->max_texture));
    L->h = (uint32_t)fmax(1, fmin(hf, d->max_texture));
    L->texel = T;
    double ms = 0.5 * (L->pl.smin + L->pl.smax), mt = 0.5 * (L->pl.tmin + L->pl.tmax);
    L->s0 = ms - 0.5 * L->w * T;
    L->t0 = mt - 0.5 * L->h * T;
}

/* One domain's samples in texel units: x, y, footprint r and C attributes each (thesis 3.3). */
static void project_samples(const build_src *src, const asp_amg_csr *dom, const asp_prim_desc *d, const layout *L,
                            int C, float *x, float *y, float *r, float *attr)
{
    size_t a = dom->row_ptr[L->row], n = dom->row_ptr[L->row + 1] - a;
    const asp_cloud *c = src->cloud;
    for (size_t k = 0; k < n; k++) {
        size_t p = dom->col[a + k];
        const float *q = &c->positions[3 * p];
        double dv[3] = {q[0] - L->pl.c[0], q[1] - L->pl.c[1], q[2] - L->pl.c[2]};
        double s = dv[0] * L->pl.u[0] + dv[1] * L->pl.u[1] + dv[2] * L->pl.u[2];
        double t = dv[0] * L->pl.v[0] + dv[1] * L->pl.v[1] + dv[2] * L->pl.v[2];
        x[k] = (float)((s - L->s0) / L->texel);
        y[k] = (float)((t - L->t0) / L->texel);
        r[k] = (float)(L->foot * point_radius(src, &L->pl, d, p) / L->texel);
        float *o = &attr[(size_t)C * k];
        point_color(src, d, p, o);
        o[3] = (float)dom->val[a + k];
        if (C == 7)
            for (int j = 0; j < 3; j++)
                o[4 + j] = c->normals ? c->normals[3 * p + (size_t)j] : (float)L->pl.n[j];
    }
}

static asp__tex_input tex_input(const asp_prim_desc *d, const layout *L, size_t n, int C, const float *x,
                                const float *y, const float *r, const float *attr)
{
    return (asp__tex_input){.n = n, .x = x, .y = y, .r = r, .attr = attr, .channels = C, .w = L->w, .h = L->h,
                            .method = d->method, .shape = d->shape, .normalise = d->normalise,
                            .normalise_color = d->normalise_color, .extend_color = !d->no_extend_color};
}

/* Pass 2 for one domain: samples in texel units, then the texture into the atlas. */
static void texture_one(const build_src *src, const asp_amg_csr *dom, const asp_prim_desc *d, const layout *L,
                        const asp_prim *P, asp_image *atlas, asp_image *natlas, void *scratch)
{
    size_t n = dom->row_ptr[L->row + 1] - dom->row_ptr[L->row];
    int C = d->normal_map ? 7 : 4;
    float *x = scratch, *y = x + n, *r = y + n, *attr = r + n;
    size_t head = ((size_t)(3 + C) * n * sizeof(float) + 63) & ~(size_t)63;
    project_samples(src, dom, d, L, C, x, y, r, attr);
    asp__tex_input in = tex_input(d, L, n, C, x, y, r, attr);
    size_t off = 4 * ((size_t)P->tex_y * atlas->width + P->tex_x);
    asp__prim_texture(&in, (uint8_t *)scratch + head, atlas->pixels + off, natlas ? natlas->pixels + off : NULL,
                      atlas->width);
}

/*
 * Thesis 3.6: one batch of texture fills by an external builder (desc->fill, the GPU). The samples and
 * the affine triangulation are made here as on the CPU path, the fill (the per-texel sums and the
 * barycentric interpolation) there, and the normalisation, extend colour and encoding here again
 * (asp__prim_texture_finish), so the two paths differ only in the fill.
 */
static int fill_batch(const build_src *src, const asp_amg_csr *dom, const asp_prim_desc *d, const layout *L,
                      const asp_prim *P, size_t m, asp_image *atlas, const asp_context *ctx, asp_error *err)
{
    int threads = asp_context_threads(ctx), rc = 0;
    size_t *sf = asp_calloc(ctx, 3 * (m + 1), sizeof *sf), *tf = sf ? sf + m + 1 : NULL, *trf = sf ? tf + m + 1 : NULL;
    uint32_t *wh = asp_alloc(ctx, 2 * m * sizeof *wh);
    if (!sf || !wh) {
        asp_free(ctx, sf);
        asp_free(ctx, wh);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a texture batch of %zu primitives", m);
    }
    size_t max_n = 0;
    for (size_t k = 0; k < m; k++) {
        size_t n = dom->row_ptr[L[k].row + 1] - dom->row_ptr[L[k].row];
        max_n = n > max_n ? n : max_n;
        sf[k + 1] = sf[k] + n;
        tf[k + 1] = tf[k] + (size_t)L[k].w * L[k].h;
        wh[k] = L[k].w, wh[m + k] = L[k].h;
    }
    const size_t S = sf[m], T = tf[m];
    size_t dscratch = (2 * max_n * sizeof(double) + (6 * max_n + 2) * sizeof(uint32_t) +
                       asp_delaunay2d_scratch_size(max_n) + 63) & ~(size_t)63;
    float *xyr = asp_alloc(ctx, 7 * S * sizeof *xyr), *acc = asp_calloc(ctx, 5 * T, sizeof *acc);
    uint32_t *tri = d->method == ASP_PRIM_AFFINE ? asp_alloc(ctx, (6 * S + 1) * sizeof *tri) : NULL;
    uint8_t *covered = asp_calloc(ctx, T, 1);
    int32_t *seed = asp_alloc(ctx, T * sizeof *seed);
    uint8_t *ds = d->method == ASP_PRIM_AFFINE ? asp_alloc(ctx, (size_t)threads * dscratch) : NULL;
    if (!xyr || !acc || !covered || !seed || (d->method == ASP_PRIM_AFFINE && (!tri || !ds))) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a texture batch of %zu texels", T);
        goto done;
    }
    float *x = xyr, *y = x + S, *r = y + S, *attr = r + S, *f = acc + 4 * T;
    long lm = (long)m;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long k = 0; k < lm; k++) {
        size_t a = sf[k], n = sf[k + 1] - a;
        project_samples(src, dom, d, &L[k], 4, x + a, y + a, r + a, attr + 4 * a);
        if (d->method != ASP_PRIM_AFFINE)
            continue;
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        asp__tex_input in = tex_input(d, &L[k], n, 4, x + a, y + a, r + a, attr + 4 * a);
        uint32_t *kept = NULL;
        size_t nt = asp__prim_affine_triangles(&in, ds + (size_t)tid * dscratch, &kept);
        for (size_t q = 0; q < 3 * nt; q++)
            tri[6 * a + q] = kept[q] + (uint32_t)a; // global sample indices
        trf[k + 1] = nt;
    }
    if (d->method == ASP_PRIM_AFFINE)
        for (size_t k = 0; k < m; k++) { // compact: each primitive's triangles start at 6 sf[k] >= 3 trf[k]
            size_t nt = trf[k + 1];
            trf[k + 1] = trf[k] + nt;
            memmove(&tri[3 * trf[k]], &tri[6 * sf[k]], 3 * nt * sizeof *tri);
        }
    asp_prim_fill_batch b = {.prim_count = m, .sample_first = sf, .texel_first = tf, .tri_first = trf, .w = wh,
                             .h = wh + m, .x = x, .y = y, .r = r, .attr = attr, .tri = tri, .method = (int)d->method,
                             .shape = (int)d->shape};
    if ((rc = d->fill(d->fill_user, &b, acc, f, covered, err)) != 0)
        goto done;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long k = 0; k < lm; k++) {
        size_t a = sf[k], t = tf[k];
        asp__tex_input in = tex_input(d, &L[k], sf[k + 1] - a, 4, x + a, y + a, r + a, attr + 4 * a);
        asp__prim_texture_finish(&in, acc + 4 * t, f + t, covered + t, seed + t,
                                 atlas->pixels + 4 * ((size_t)P[k].tex_y * atlas->width + P[k].tex_x), NULL,
                                 atlas->width);
    }
done:
    asp_free(ctx, sf);
    asp_free(ctx, wh);
    asp_free(ctx, xyr);
    asp_free(ctx, acc);
    asp_free(ctx, tri);
    asp_free(ctx, covered);
    asp_free(ctx, seed);
    asp_free(ctx, ds);
    return rc;
}

/* The level's textures through desc->fill, in batches of about 4 M texels (a primitive larger than that
 * alone), which bounds the batch's buffers here and on the device. */
static int fill_external(const build_src *src, const asp_amg_csr *dom, const asp_prim_desc *d, const layout *L,
                         asp_dps_level *lv, size_t np, const asp_context *ctx, asp_error *err)
{
    enum { BATCH_TEXELS = 1 << 22 };
    int rc = 0;
    for (size_t k0 = 0, k1; k0 < np && !rc; k0 = k1) {
        size_t texels = 0;
        for (k1 = k0; k1 < np && (k1 == k0 || texels + (size_t)L[k1].w * L[k1].h <= BATCH_TEXELS); k1++)
            texels += (size_t)L[k1].w * L[k1].h;
        rc = fill_batch(src, dom, d, L + k0, lv->prims + k0, k1 - k0, &lv->atlas, ctx, err);
    }
    return rc;
}

static size_t scratch_bytes(size_t n, size_t texels, int C)
{
    return (((size_t)(3 + C) * n * sizeof(float) + 63) & ~(size_t)63) + asp__prim_texture_scratch(n, texels, C);
}

static void release_level(const asp_context *ctx, asp_dps_level *lv)
{
    asp_free(ctx, lv->prims);
    asp_free(ctx, lv->neighbours);
    asp_image_release(&lv->atlas);
    asp_image_release(&lv->normal_atlas);
    asp_free(ctx, lv->atlas_bc3);
    asp_free(ctx, lv->normal_bc3);
    asp__level_links_release(ctx, lv);
    memset(lv, 0, sizeof *lv);
}

static void level_name(const asp_amg *amg, size_t level, char *buf, size_t cap)
{
    size_t top = asp_amg_level_count(amg) - 1;
    if (level == top)
        snprintf(buf, cap, "L");
    else
        snprintf(buf, cap, "L-%zu", top - level);
}

/* Fills the primitive records, atlas and neighbours of one level from its (possibly merged) domains. */
static int construct(const build_src *src, const asp_amg_csr *dom, const uint32_t *basis_first,
                     const uint32_t *basis_count, const asp_prim_desc *d, const char *name, const asp_context *ctx,
                     asp_dps_level *lv, asp_error *err)
{
    size_t rows = dom->rows, np = 0;
    for (size_t r = 0; r < rows; r++)
        np += dom->row_ptr[r + 1] > dom->row_ptr[r];
    lv->skipped = (uint32_t)(rows - np);
    if (np == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "level %s: no domain has a point with Psi > %g", name, d->tau);
    int threads = asp_context_threads(ctx), C = d->normal_map ? 7 : 4, rc = 0;
    layout *L = asp_calloc(ctx, np, sizeof *L);
    uint32_t *ws = asp_alloc(ctx, 4 * np * sizeof *ws);
    size_t *first = asp_calloc(ctx, rows + 1, sizeof *first);
    uint32_t *nbr = NULL, *row_to_prim = NULL;
    uint8_t *scratch = NULL;
    lv->prims = asp_calloc(ctx, np, sizeof *lv->prims);
    if (!L || !ws || !first || !lv->prims) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu primitives of level %s", np, name);
        goto done;
    }
    lv->prim_count = np;
    for (size_t r = 0, k = 0; r < rows; r++)
        if (dom->row_ptr[r + 1] > dom->row_ptr[r])
            L[k++].row = r;
    long lnp = (long)np;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long k = 0; k < lnp; k++)
        plan_one(src, dom, d, &L[k]);

    uint32_t *w = ws, *h = ws + np, *x = ws + 2 * np, *y = ws + 3 * np;
    size_t max_n = 0, max_t = 0;
    for (size_t k = 0; k < np; k++) {
        w[k] = L[k].w, h[k] = L[k].h;
        size_t n = dom->row_ptr[L[k].row + 1] - dom->row_ptr[L[k].row];
        size_t need = scratch_bytes(n, (size_t)L[k].w * L[k].h, C);
        max_t = need > max_t ? need : max_t;
        max_n = n > max_n ? n : max_n;
    }
    uint32_t aw = 0, ah = 0;
    int pk = asp__atlas_pack(w, h, np, d->padding, ATLAS_MAX, x, y, &aw, &ah, ctx);
    if (pk == -2) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the atlas layout of level %s", name);
        goto done;
    }
    if (pk) {
        rc = asp_error_set(err, ASP_EUNSUPPORTED,
                           "level %s: the textures of %zu primitives do not fit a %dx%d atlas; raise --texel-size",
                           name, np, ATLAS_MAX, ATLAS_MAX);
        goto done;
    }
    if ((rc = asp_image_init(&lv->atlas, aw, ah, err)) ||
        (d->normal_map && (rc = asp_image_init(&lv->normal_atlas, aw, ah, err))))
        goto done;
    scratch = asp_alloc(ctx, (size_t)threads * max_t);
    if (!scratch) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %d texture scratch buffers of %zu bytes", threads,
                           max_t);
        goto done;
    }
    const asp_cloud *c = src->cloud;
    for (size_t k = 0; k < np; k++) {
        asp_prim *P = &lv->prims[k];
        const layout *l = &L[k];
        double ms = l->s0 + 0.5 * l->w * l->texel, mt = l->t0 + 0.5 * l->h * l->texel;
        for (int j = 0; j < 3; j++) {
            P->centre[j] = c->origin[j] + l->pl.c[j] + ms * l->pl.u[j] + mt * l->pl.v[j];
            P->axis_u[j] = (float)l->pl.u[j];
            P->axis_v[j] = (float)l->pl.v[j];
            P->normal[j] = (float)l->pl.n[j];
        }
        P->half_u = (float)(0.5 * l->w * l->texel);
        P->half_v = (float)(0.5 * l->h * l->texel);
        P->texel = (float)l->texel;
        P->error = (float)l->pl.error;
        P->error_norm = (float)(l->pl.error / src->mean_radius);
        P->curvature = (float)l->pl.curvature;
        P->points = (uint32_t)(dom->row_ptr[l->row + 1] - dom->row_ptr[l->row]);
        P->basis = basis_first ? basis_first[l->row] : (uint32_t)l->row;
        P->merged = basis_count ? basis_count[l->row] : 1;
        P->flags = (l->pl.degenerate ? ASP_PRIM_FLAG_DEGENERATE : 0u) | (l->capped ? ASP_PRIM_FLAG_CAPPED : 0u);
        P->tex_x = x[k], P->tex_y = y[k], P->tex_w = l->w, P->tex_h = l->h;
    }
    asp_image *natlas = d->normal_map ? &lv->normal_atlas : NULL;
    if (d->fill) {
        if ((rc = fill_external(src, dom, d, L, lv, np, ctx, err)) != 0)
            goto done;
    } else {
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long k = 0; k < lnp; k++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            texture_one(src, dom, d, &L[k], &lv->prims[k], &lv->atlas, natlas, scratch + (size_t)tid * max_t);
        }
    }
    asp__atlas_pad(&lv->atlas, lv->prims, np, d->padding);
    if (natlas)
        asp__atlas_pad(natlas, lv->prims, np, d->padding);

    /* neighbours per domain row, renumbered to primitive indices (empty rows have none) */
    size_t total = 0;
    if ((rc = asp_prim_neighbours(dom, d->neighbour_fraction, ctx, first, &nbr, &total, err)))
        goto done;
    row_to_prim = asp_alloc(ctx, rows * sizeof *row_to_prim);
    if (!row_to_prim) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu domain indices", rows);
        goto done;
    }
    for (size_t k = 0; k < np; k++)
        row_to_prim[L[k].row] = (uint32_t)k;
    lv->neighbours = asp_alloc(ctx, (total ? total : 1) * sizeof *lv->neighbours);
    if (!lv->neighbours) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu neighbour entries", total);
        goto done;
    }
    lv->neighbour_total = total;
    double esum = 0, pts = 0;
    for (size_t k = 0; k < np; k++) {
        asp_prim *P = &lv->prims[k];
        size_t r = L[k].row;
        P->neighbour_first = (uint32_t)first[r];
        P->neighbour_count = (uint32_t)(first[r + 1] - first[r]);
        for (size_t q = first[r]; q < first[r + 1]; q++)
            lv->neighbours[q] = row_to_prim[nbr[q]]; /* rows increase with k, so lists stay sorted */
        lv->texels += (uint64_t)P->tex_w * P->tex_h;
        esum += (double)P->error * P->points;
        pts += P->points;
        lv->degenerate += (P->flags & ASP_PRIM_FLAG_DEGENERATE) != 0;
        lv->capped += (P->flags & ASP_PRIM_FLAG_CAPPED) != 0;
    }
    lv->error = esum / pts;
    lv->error_norm = lv->error / src->mean_radius;
done:
    asp_free(ctx, L);
    asp_free(ctx, ws);
    asp_free(ctx, first);
    asp_free(ctx, nbr);
    asp_free(ctx, row_to_prim);
    asp_free(ctx, scratch);
    return rc;
}

static int build_level(const asp_amg *amg, const build_src *src, size_t level, const asp_prim_desc *d,
                       const asp_context *ctx, asp_dps_level *lv, asp_error *err)
{
    char name[32];
    level_name(amg, level, name, sizeof name);
    double t0 = asp_time_now();
    asp_amg_csr *psi = NULL, *dom = NULL, *merged = NULL;
    uint32_t *bfirst = NULL, *bcount = NULL;
    int rc = asp_amg_basis(amg, level, ctx, &psi, err);
    if (!rc)
        rc = d->strict == ASP_PRIM_DOMAINS_STRICT ? asp_amg_strict_domain_rows(psi, ctx, &dom, err) : asp_amg_domains(psi, d->tau, ctx, &dom, err);
    asp_amg_csr_destroy(psi);
    if (rc)
        return rc;
    lv->level = (uint32_t)level;
    lv->strict = d->strict == ASP_PRIM_DOMAINS_STRICT;
    lv->basis_count = (uint32_t)dom->rows;
    lv->t_basis = asp_time_now() - t0;
    double t1 = asp_time_now();
    if (d->merge) {
        rc = asp__prim_merge(dom, src->cloud->positions, src->cloud->normals, d->merge_flatness, d->merge_angle, ctx,
                             &merged, &bfirst, &bcount, &lv->merges, err);
        if (rc) {
            asp_amg_csr_destroy(dom);
            return rc;
        }
    }
    rc = construct(src, merged ? merged : dom, bfirst, bcount, d, name, ctx, lv, err);
    lv->t_construct = asp_time_now() - t1;
    asp_amg_csr_destroy(dom);
    asp_amg_csr_destroy(merged);
    asp_free(ctx, bfirst);
    asp_free(ctx, bcount);
    if (rc)
        release_level(ctx, lv);
    return rc;
}

int asp_prim_level_for_budget(const asp_amg *amg, size_t max_prims, size_t *level, asp_error *err)
{
    if (!amg || !level || max_prims == 0)
        return asp_error_set(err, ASP_EINVAL, "primitive budget must be at least 1");
    size_t nl = asp_amg_level_count(amg);
    for (size_t l = 0; l < nl; l++)
        if (asp_amg_level_size(amg, l) <= max_prims) {
            *level = l;
            return 0;
        }
    *level = nl - 1;
    return 0;
}

int asp_prim_level_nearest(const asp_amg *amg, size_t prims, size_t *level, asp_error *err)
{
    if (!amg || !level || prims == 0)
        return asp_error_set(err, ASP_EINVAL, "primitive count must be at least 1");
    size_t nl = asp_amg_level_count(amg), best = 0, best_d = SIZE_MAX;
    for (size_t l = 0; l < nl; l++) { // finest first: a tie keeps the finer level (more detail for the same distance)
        size_t n = asp_amg_level_size(amg, l), d = n > prims ? n - prims : prims - n;
        if (d < best_d) {
            best = l;
            best_d = d;
        }
    }
    *level = best;
    return 0;
}

/* Estimates radii when there are none (16th neighbour) and takes their mean. */
static int prepare_src(build_src *src, const asp_context *ctx, float **own, asp_error *err)
{
    size_t n = src->cloud->count;
    if (!src->radii) {
        *own = asp_alloc(ctx, n * sizeof **own);
        if (!*own)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu radii", n);
        int rc = asp_estimate_radii(src->cloud->positions, n, 12, NULL, *own, ctx, err);
        if (rc)
            return rc;
        src->radii = *own;
    }
    double rs = 0; /* double: a float sum of 10^6 radii would lose digits */
    for (size_t i = 0; i < n; i++)
        rs += src->radii[i];
    src->mean_radius = rs / (double)n;
    if (!(src->mean_radius > 0) || !isfinite(src->mean_radius))
        return asp_error_set(err, ASP_EDEGENERATE, "mean point radius is %g; expected a positive radius",
                             src->mean_radius);
    return 0;
}

int asp_prim_build_level(const asp_cloud *cloud, const asp_amg_csr *dom, const asp_prim_desc *desc,
                         const asp_context *ctx, asp_dps_level *out, asp_error *err)
{
    if (!cloud || !dom || !out || cloud->count == 0 || dom->cols != cloud->count)
        return asp_error_set(err, ASP_EINVAL, "domains over %zu points do not match the cloud's %zu",
                             dom ? dom->cols : 0, cloud ? cloud->count : 0);
    asp_prim_desc d;
    resolve_desc(desc, &d);
    int rc = check_desc(&d, err);
    if (rc)
        return rc;
    for (size_t k = 0; k < dom->row_ptr[dom->rows]; k++)
        if (dom->col[k] >= cloud->count || !(dom->val[k] >= 0 && dom->val[k] <= 1.000001))
            return asp_error_set(err, ASP_EINVAL, "domain entry %zu: point %u, Psi %g; expected a point below %zu and "
                                 "Psi in [0, 1]", k, dom->col[k], dom->val[k], cloud->count);
    build_src src = {.cloud = cloud, .colors = cloud->colors, .radii = cloud->radii};
    float *own = NULL;
    asp_dps_level lv;
    memset(&lv, 0, sizeof lv);
    double t0 = asp_time_now();
    rc = prepare_src(&src, ctx, &own, err);
    if (!rc) {
        lv.basis_count = (uint32_t)dom->rows;
        lv.strict = d.strict == ASP_PRIM_DOMAINS_STRICT;
        rc = construct(&src, dom, NULL, NULL, &d, "of explicit domains", ctx, &lv, err);
        lv.t_construct = asp_time_now() - t0;
    }
    asp_free(ctx, own);
    memset(out, 0, sizeof *out);
    if (rc) {
        release_level(ctx, &lv);
        return rc;
    }
    *out = lv;
    return 0;
}

void asp_dps_level_release(asp_dps_level *lv, const asp_context *ctx)
{
    if (lv)
        release_level(ctx, lv);
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return x < y ? -1 : x > y;
}

int asp_prim_build(const asp_amg *amg, const asp_cloud *attrs, const size_t *levels, size_t nlevels,
                   const asp_prim_desc *desc, const char *source, const asp_context *ctx, asp_dps **out,
                   asp_error *err)
{
    if (!amg || !levels || !out || nlevels == 0)
        return asp_error_set(err, ASP_EINVAL, "asp_prim_build needs a decomposition and at least one level");
    asp_prim_desc d;
    resolve_desc(desc, &d);
    int rc = check_desc(&d, err);
    if (rc)
        return rc;
    const asp_cloud *cloud = asp_amg_cloud(amg);
    size_t n = cloud->count, nl = asp_amg_level_count(amg);
    if (attrs && attrs->count != n)
        return asp_error_set(err, ASP_EINVAL, "attribute cloud has %zu points, the decomposition %zu", attrs->count, n);
    for (size_t i = 0; i < nlevels; i++)
        if (levels[i] >= nl)
            return asp_error_set(err, ASP_EINVAL, "level %zu out of range: the decomposition has levels 0..%zu",
                                 levels[i], nl - 1);
    size_t *lv_sorted = asp_alloc(ctx, nlevels * sizeof *lv_sorted);
    float *own_radii = NULL;
    asp_dps *dps = asp_calloc(ctx, 1, sizeof *dps);
    if (!lv_sorted || !dps) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
        goto fail;
    }
    dps->ctx = ctx ? *ctx : (asp_context){0};
    memcpy(lv_sorted, levels, nlevels * sizeof *lv_sorted);
    qsort(lv_sorted, nlevels, sizeof *lv_sorted, cmp_size);
    size_t nu = 0;
    for (size_t i = 0; i < nlevels; i++)
        if (nu == 0 || lv_sorted[i] != lv_sorted[nu - 1])
            lv_sorted[nu++] = lv_sorted[i];

    build_src src = {.cloud = cloud};
    src.colors = attrs && attrs->colors ? attrs->colors : cloud->colors;
    src.radii = attrs && attrs->radii ? attrs->radii : cloud->radii;
    if ((rc = prepare_src(&src, ctx, &own_radii, err)))
        goto fail;
    // Domain Set both (thesis appendix C): each level twice, thresholded then strict
    const size_t sets = d.strict == ASP_PRIM_DOMAINS_BOTH ? 2 : 1;
    dps->levels = asp_calloc(ctx, nu * sets, sizeof *dps->levels);
    if (!dps->levels) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < nu * sets; i++) {
        if ((rc = asp_progress(ctx, "primitives", (double)i / (double)(nu * sets)))) {
            asp_error_set(err, rc, "primitive construction canceled");
            goto fail;
        }
        asp_prim_desc di = d;
        if (sets == 2)
            di.strict = (int)(i % 2);
        rc = build_level(amg, &src, lv_sorted[i / sets], &di, ctx, &dps->levels[dps->level_count], err);
        if (rc == ASP_EDEGENERATE) {
            dps->skipped_levels++;
            continue;
        }
        if (rc)
            goto fail;
        dps->level_count++;
    }
    if (dps->level_count == 0) {
        rc = asp_error_set(err, ASP_EDEGENERATE, "no requested level has a domain with a point above tau = %g", d.tau);
        goto fail;
    }
    /* links between the stored levels, for the cut across levels (issue 18, level_links.c) */
    if ((rc = asp_prim_links(amg, dps, ctx, err)))
        goto fail;
    asp_progress(ctx, "primitives", 1.0);
    dps->amg_levels = (uint32_t)nl;
    dps->source_points = n;
    dps->mean_radius = src.mean_radius;
    dps->desc = d;
    dps->desc.fill = NULL, dps->desc.fill_user = NULL; // the builder is the caller's, not a parameter of the file
    snprintf(dps->source, sizeof dps->source, "%s", source ? source : "");
    dps->frame = *asp_amg_frame(amg);
    *out = dps;
    asp_free(ctx, lv_sorted);
    asp_free(ctx, own_radii);
    return 0;
fail:
    asp_dps_destroy(dps);
    asp_free(ctx, lv_sorted);
    asp_free(ctx, own_radii);
    return rc;
}

void asp_dps_destroy(asp_dps *dps)
{
    if (!dps)
        return;
    asp_context ctx = dps->ctx;
    for (size_t i = 0; i < dps->level_count; i++)
        release_level(&ctx, &dps->levels[i]);
    asp_free(&ctx, dps->levels);
    asp_free(&ctx, dps);
}
