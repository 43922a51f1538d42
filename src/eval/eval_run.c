/*
 * The measuring stick of the evaluation: render the reference (all points as
 * blended, normalised splats, seed 001 section 5, tolerance 0; or, given the
 * mesh the points were sampled from, the mesh itself: issue 14, seed 004
 * 2.2-2.3) and every representation from the same cameras, and compare images
 * (journal section 6 asks for an image difference metric). The point-hierarchy
 * cut to a level's primitive count is the comparison of thesis Fig. 1.1; the
 * mesh simplified to the level's count and bytes is what users ship today.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/geom.h"
#include "amgsplat/hier.h"
#include "amgsplat/render.h"
#include "amgsplat/scene.h"
#include "eval/internal.h"
#include "util/banned.h"

void asp_eval_result_destroy(asp_eval_result *res)
{
    if (!res)
        return;
    asp_context ctx = res->ctx;
    asp_free(&ctx, res->rows);
    asp_free(&ctx, res->ssim);
    asp_free(&ctx, res->psnr);
    asp_image_release(&res->sheet);
    asp_free(&ctx, res);
}

size_t asp_eval_ssim_wins(const asp_eval_result *res, size_t a, size_t b)
{
    size_t wins = 0;
    for (size_t v = 0; v < res->views; v++)
        wins += res->ssim[a * res->views + v] > res->ssim[b * res->views + v];
    return wins;
}

#ifndef ASP_HAVE_GL

int asp_eval_run(const asp_cloud *cloud, const asp_eval_desc *desc, const asp_context *ctx, asp_eval_result **out,
                 asp_error *err)
{
    (void)cloud;
    (void)desc;
    (void)ctx;
    (void)out;
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot evaluate: this build has no OpenGL renderer (ASP_WITH_GL)");
}

#else

enum { MAX_SIZES = 8, MAX_VIEWS = 256, MAX_FRAMES = 1000, MAX_REPS = 21, MAX_LEVELS = 64 };

/* asp_eval_row.bytes of a point: 12 position + 12 normal + 4 RGBA8 + 4 radius, as asp_cloud holds it */
#define POINT_BYTES 32

/* Identical images have infinite PSNR; a finite stand-in keeps means and CSV numbers usable. */
#define PSNR_IDENTICAL 99.0

/*
 * A representation: the point hierarchy cut per view to the level's primitive
 * count (prim = 0, drawn by the shared splat renderer), or the level's domain
 * primitives drawn with one method (journal section 4, thesis 4.4).
 */
enum rep_kind { REP_CUT, REP_PRIM, REP_MESH_TRIS, REP_MESH_BYTES, REP_FULL_DISCS, REP_FULL_SPLATS, REP_HYBRID,
                REP_BILLBOARDS };

struct rep {
    char name[32];
    enum rep_kind kind;
    int prim;
    asp_prim_render_method method;
};


struct eval_state {
    const asp_context *ctx;
    const asp_cloud *cloud;
    asp_gl_context *gl;
    asp_hier *hier;
    asp_renderer *splat; /* the reference at tolerance 0; the point cut with a splat budget */
    asp_renderer *disc;  /* with a mesh: the full point set as discs */
    asp_dps *dps;
    asp_frame frame;     /* the one camera framing (asp_camera_frame): the cloud's, or the mesh's with one */
    const asp_mesh *mesh;            /* the true surface (asp_eval_desc.mesh) or NULL */
    asp_mesh *tris[MAX_LEVELS];      /* per level of dps: the mesh at <= the level's primitive count */
    asp_mesh *bytes[MAX_LEVELS];     /* per level: the mesh at <= the level's GPU bytes */
    char tris_note[MAX_LEVELS][96];  /* why tris[l] is NULL */
    char bytes_note[MAX_LEVELS][96]; /* why bytes[l] is NULL */
    asp_dps *bb[MAX_LEVELS];         /* per level: the billboard cloud matched to it (issue 30), or NULL */
    double bb_seconds[MAX_LEVELS], bb_error[MAX_LEVELS];
    float elevation;
    float crease_angle;  /* resolved: degrees, or -1 for none */
    size_t views, frames;
    struct rep reps[MAX_REPS];
    size_t nreps;
};

static int create_prim(struct eval_state *s, const struct rep *rep, const asp_dps_level *lv, asp_renderer **out,
                       asp_error *err)
{
    // the one renderer table, in the cloud's frame so the camera is the points' camera
    const asp_renderer_kind *prim = NULL;
    int rc = asp_renderer_kind_find("prim", 0, &prim, err);
    if (rc)
        return rc;
    asp_render_source src = {.level = lv};
    memcpy(src.origin, s->cloud->origin, sizeof src.origin);
    asp_renderer_options o = {.prim = {.method = rep->method, .crease_angle = s->crease_angle}};
    return prim->create(s->gl, &src, &o, s->ctx, out, err);
}

/* issue 18 item 3: the level's primitives where they hold, the cloud's points where they fail */
static int create_hybrid(struct eval_state *s, const asp_dps_level *lv, asp_renderer **out, asp_error *err)
{
    const asp_renderer_kind *kind = NULL;
    int rc = asp_renderer_kind_find("hybrid", 0, &kind, err);
    if (rc)
        return rc;
    asp_render_source src = {.level = lv, .cloud = s->cloud};
    memcpy(src.origin, s->cloud->origin, sizeof src.origin);
    asp_renderer_options o = {.prim = {.crease_angle = s->crease_angle}};
    return kind->create(s->gl, &src, &o, s->ctx, out, err);
}

static int create_mesh(struct eval_state *s, const asp_mesh *m, asp_renderer **out, asp_error *err)
{
    const asp_renderer_kind *kind = NULL;
    int rc = asp_renderer_kind_find("mesh", 0, &kind, err);
    if (rc)
        return rc;
    asp_render_material *mats = asp_calloc(s->ctx, m->material_count, sizeof *mats);
    if (!mats)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu materials", m->material_count);
    asp_render_mesh rm;
    asp_scene_mesh_describe(m, mats, &rm);
    // drawn in the cloud's frame, so the camera is the points' camera
    asp_render_source src = {.mesh = &rm};
    memcpy(src.origin, s->cloud->origin, sizeof src.origin);
    rc = kind->create(s->gl, &src, NULL, s->ctx, out, err);
    asp_free(s->ctx, mats);
    return rc;
}

static uint64_t mesh_texels(const asp_mesh *m)
{
    uint64_t t = 0;
    for (size_t i = 0; i < m->material_count; i++)
        if (m->materials[i].texture.pixels)
            t += (uint64_t)m->materials[i].texture.width * m->materials[i].texture.height;
    return t;
}

static void view_camera(const struct eval_state *s, size_t v, asp_camera *cam)
{
    asp_camera_init(cam);
    cam->up = s->frame.up; // the source's up axis: a LAS scan stands upright as in render and view
    cam->azimuth = (float)(360.0 * (double)v / (double)s->views);
    cam->elevation = v % 2 ? -s->elevation : s->elevation;
    asp_camera_frame(cam, &s->frame, s->cloud->origin, 1.0f, 0.0f);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median time of s->frames finished frames (one untimed warm-up frame first). */
static int frame_time(struct eval_state *s, asp_renderer *r, const asp_camera *cam, const asp_render_desc *rd,
                      double *ms, asp_error *err)
{
    asp_render_desc d = *rd;
    d.flags |= ASP_RENDER_WAIT;
    double t[MAX_FRAMES];
    int rc = asp_render_frame(s->gl, r, cam, &d, err);
    for (size_t i = 0; !rc && i < s->frames; i++) {
        double t0 = asp_time_now();
        rc = asp_render_frame(s->gl, r, cam, &d, err);
        t[i] = (asp_time_now() - t0) * 1e3;
    }
    if (rc)
        return rc;
    qsort(t, s->frames, sizeof *t, cmp_double);
    *ms = s->frames % 2 ? t[s->frames / 2] : 0.5 * (t[s->frames / 2 - 1] + t[s->frames / 2]);
    return 0;
}

static int compare(const asp_image *img, const asp_image *ref, double *psnr, double *ssim, double *iou,
                   asp_error *err)
{
    int rc = asp_image_psnr(img, ref, psnr, err);
    if (!rc)
        rc = asp_image_ssim(img, ref, ssim, err);
    if (!rc)
        rc = asp_image_silhouette_iou(img, ref, NULL, iou, err);
    if (!rc && !isfinite(*psnr))
        *psnr = PSNR_IDENTICAL;
    return rc;
}

struct sheet {
    asp_image *tiles; /* rows x cols; NULL when no sheet is made */
    size_t cols, rows;
};

static int keep_tile(const struct eval_state *s, struct sheet *sh, size_t row, size_t col, asp_image *img)
{
    if (!sh->tiles)
        return 0;
    (void)s;
    asp_image *t = &sh->tiles[row * sh->cols + col];
    asp_image_release(t);
    *t = *img; // takes the pixels
    memset(img, 0, sizeof *img);
    return 0;
}

/*
 * One row: every view of representation rep at level lv (rep NULL: the
 * reference; lv NULL: the whole model), drawing mesh instead when it is given
 * (the mesh reference and the simplified meshes), figures into row.
 */
static int measure(struct eval_state *s, const struct rep *rep, const asp_dps_level *lv, const asp_mesh *mesh,
                   uint32_t size, const asp_image *refs, asp_image *ref_out, struct sheet *sh, size_t sheet_row,
                   size_t sheet_col, asp_eval_row *row, double *ssim_views, double *psnr_views, asp_error *err)
{
    asp_renderer *r = s->splat;
    int rc = 0;
    if (mesh)
        rc = create_mesh(s, mesh, &r, err);
    else if (rep && rep->prim)
        rc = create_prim(s, rep, lv, &r, err);
    else if (rep && rep->kind == REP_FULL_DISCS)
        r = s->disc;
    else if (rep && rep->kind == REP_HYBRID)
        rc = create_hybrid(s, lv, &r, err);
    if (rc)
        return rc;
    asp_hybrid_counts hc = {0};
    if (rep && rep->kind == REP_HYBRID)
        (void)asp_hybrid_renderer_counts(r, &hc, NULL);
    int cut = r == s->splat;
    size_t target = lv ? lv->prim_count : mesh ? mesh->triangle_count : s->cloud->count;
    asp_render_desc rd = {.width = size, .height = size};
    double drawn = 0, psnr_sum = 0, ssim_sum = 0, iou_sum = 0;
    row->psnr_min = row->ssim_min = row->iou_min = INFINITY;
    for (size_t v = 0; v < s->views && !rc; v++) {
        asp_camera cam;
        view_camera(s, v, &cam);
        // thesis Fig. 1.1: the point hierarchy cut to as many splats as the level has primitives
        if (cut)
            rc = asp_renderer_set_budget(r, lv ? target : 0, err);
        if (!rc && cut)
            rc = asp_renderer_set_lod(r, 0, 0, err);
        asp_image img = {0};
        if (!rc)
            rc = asp_render_to_image(s->gl, r, &cam, &rd, &img, err);
        if (!rc && v == 0)
            rc = frame_time(s, r, &cam, &rd, &row->frame_ms, err);
        drawn += (double)asp_renderer_count(r);
        double psnr = PSNR_IDENTICAL, ssim = 1, iou = 1;
        if (!rc && refs)
            rc = compare(&img, &refs[v], &psnr, &ssim, &iou, err);
        if (!rc) {
            psnr_views[v] = psnr;
            ssim_views[v] = ssim;
            psnr_sum += psnr;
            ssim_sum += ssim;
            iou_sum += iou;
            row->psnr_min = psnr < row->psnr_min ? psnr : row->psnr_min;
            row->ssim_min = ssim < row->ssim_min ? ssim : row->ssim_min;
            row->iou_min = iou < row->iou_min ? iou : row->iou_min;
        }
        if (!rc && v == 0 && sh && sh->tiles && size == sh->tiles[0].width) {
            asp_image copy = {0};
            rc = asp_image_init(&copy, img.width, img.height, err);
            if (!rc) {
                memcpy(copy.pixels, img.pixels, (size_t)img.width * img.height * 4);
                rc = keep_tile(s, sh, sheet_row, sheet_col, &copy);
            }
            asp_image_release(&copy);
        }
        if (!rc && ref_out)
            ref_out[v] = img; // the caller keeps the reference images
        else
            asp_image_release(&img);
    }
    if (r != s->splat && r != s->disc)
        asp_renderer_destroy(r);
    if (rc)
        return rc;
    snprintf(row->representation, sizeof row->representation, "%s", rep ? rep->name : "reference");
    row->size = size;
    row->primitives = target;
    row->drawn = drawn / (double)s->views;
    // splats have no texture
    row->texels = mesh ? mesh_texels(mesh) : rep && (rep->prim || rep->kind == REP_HYBRID) ? lv->texels : 0;
    if (mesh)
        row->bytes = asp_mesh_gpu_bytes(mesh, NULL);
    else if (rep && rep->prim)
        row->bytes = asp_dps_level_gpu_bytes(lv, NULL);
    else if (rep && rep->kind == REP_HYBRID)
        // the whole level stays uploaded (its atlas is shared) plus every point drawn
        row->bytes = asp_dps_level_gpu_bytes(lv, NULL) + (uint64_t)hc.points_drawn * POINT_BYTES;
    else
        row->bytes = (uint64_t)llround(row->drawn) * POINT_BYTES;
    row->psnr_mean = psnr_sum / (double)s->views;
    row->ssim_mean = ssim_sum / (double)s->views;
    row->iou_mean = iou_sum / (double)s->views;
    return 0;
}

/* A row that could not be made honestly (e.g. no mesh fits the bytes): NaN figures and the reason. */
static void row_without_figures(const struct eval_state *s, const struct rep *rep, const asp_dps_level *lv,
                                uint32_t size, const char *note, asp_eval_row *row, double *ssim_views,
                                double *psnr_views)
{
    snprintf(row->representation, sizeof row->representation, "%s", rep->name);
    snprintf(row->note, sizeof row->note, "%s", note);
    row->size = size;
    row->primitives = lv->prim_count;
    row->psnr_mean = row->psnr_min = row->ssim_mean = row->ssim_min = NAN;
    row->iou_mean = row->iou_min = row->frame_ms = NAN;
    for (size_t v = 0; v < s->views; v++)
        ssim_views[v] = psnr_views[v] = NAN;
}

static int check_desc(const asp_eval_desc *d, const uint32_t *sizes, size_t nsizes, asp_error *err)
{
    if (d->views > MAX_VIEWS)
        return asp_error_set(err, ASP_EINVAL, "views must be 1..%d, got %zu", MAX_VIEWS, d->views);
    if (nsizes == 0 || nsizes > MAX_SIZES)
        return asp_error_set(err, ASP_EINVAL, "expected 1..%d image sizes, got %zu", MAX_SIZES, nsizes);
    for (size_t i = 0; i < nsizes; i++)
        if (sizes[i] < 16 || sizes[i] > 2048)
            return asp_error_set(err, ASP_EINVAL, "image size %u is outside 16..2048", sizes[i]);
    // the reps: the point cut, the methods, and the two simplified meshes
    if (d->methods && d->method_count > MAX_REPS - 4)
        return asp_error_set(err, ASP_EINVAL, "at most %d rendering methods, got %zu", MAX_REPS - 4, d->method_count);
    for (size_t i = 0; d->methods && i < d->method_count; i++)
        if (!asp_prim_render_method_name(d->methods[i]))
            return asp_error_set(err, ASP_EINVAL, "unknown rendering method %d", (int)d->methods[i]);
    if (d->frames > MAX_FRAMES)
        return asp_error_set(err, ASP_EINVAL, "frames must be at most %d, got %zu", MAX_FRAMES, d->frames);
    if (isnan(d->crease_angle) || d->crease_angle >= 90)
        return asp_error_set(err, ASP_EINVAL, "crease angle must be below 90 degrees (or < 0 for none), got %g",
                             (double)d->crease_angle);
    if (!(d->elevation >= -90 && d->elevation <= 90))
        return asp_error_set(err, ASP_EINVAL, "elevation must be in -90..90 degrees, got %g", (double)d->elevation);
    return 0;
}

/* Levels 1 .. L with at most max primitives (level 0 is the points themselves); at least the coarsest. */
static size_t pick_levels(const asp_amg *amg, size_t max, size_t *levels)
{
    size_t n = 0, count = asp_amg_level_count(amg);
    for (size_t l = 1; l < count && n < 64; l++)
        if (asp_amg_level_size(amg, l) <= max)
            levels[n++] = l;
    if (n == 0)
        levels[n++] = count - 1;
    return n;
}

static size_t mesh_measure(const asp_mesh *m, int by_bytes)
{
    return by_bytes ? asp_mesh_gpu_bytes(m, NULL) : m->triangle_count;
}

/*
 * The simplified mesh with the most triangles whose triangle count (or GPU
 * bytes, by_bytes) is at most limit: asp_mesh_simplify at a target found by
 * bisection, since meshoptimizer may stop above a target (seams, sloppy
 * fallback) and bytes are known only after simplifying. Neither measure is
 * strictly monotone in the target, but every result kept was checked against
 * limit. Stops once the bracket is within 1% of the target. *out NULL with
 * note filled when no simplification fits.
 */
static int simplify_fit(struct eval_state *s, size_t limit, int by_bytes, asp_mesh **out, char note[96],
                        asp_error *err)
{
    const asp_mesh *m = s->mesh;
    size_t full = m->triangle_count, lo = 0, hi = full + 1, guess = by_bytes ? 0 : limit;
    size_t fail_tris = 0, fail_measure = 0;
    asp_mesh *best = NULL;
    *out = NULL;
    if (by_bytes) {
        asp_mesh_bytes b;
        asp_mesh_gpu_bytes(m, &b);
        // the texture is not simplified: when it alone is over the budget no triangle count helps
        if (b.texture >= limit) {
            snprintf(note, 96, "texture alone %zu bytes exceeds %zu", b.texture, limit);
            return 0;
        }
        // bytes per triangle of the full mesh, for a first guess near the answer
        double per = (double)(b.vertex + b.index) / (double)full;
        guess = (size_t)((double)(limit - b.texture) / per);
    }
    guess = guess < 1 ? 1 : guess > full ? full : guess;
    int rc = 0;
    for (size_t t = guess; !rc && lo + 1 < hi && !(lo && hi - lo <= lo / 100); t = lo + (hi - lo) / 2) {
        asp_mesh *cand = NULL;
        rc = asp_mesh_simplify(m,
                               &(asp_mesh_simplify_desc){.target_triangles = t,
                                                         .flags = ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK},
                               s->ctx, &cand, NULL, err);
        if (rc)
            break;
        if (mesh_measure(cand, by_bytes) <= limit) {
            asp_mesh_destroy(best);
            best = cand;
            lo = t;
        } else {
            fail_tris = cand->triangle_count;
            fail_measure = mesh_measure(cand, by_bytes);
            asp_mesh_destroy(cand);
            hi = t;
        }
    }
    if (rc) {
        asp_mesh_destroy(best);
        return rc;
    }
    if (!best) {
        if (by_bytes)
            snprintf(note, 96, "smallest simplification %zu triangles %zu bytes exceeds %zu", fail_tris, fail_measure,
                     limit);
        else
            snprintf(note, 96, "smallest simplification %zu triangles exceeds %zu", fail_tris, limit);
    }
    *out = best;
    return 0;
}

/* The two simplified meshes of every level (issue 14): at its primitive count and at its GPU bytes. */
static int simplify_levels(struct eval_state *s, asp_eval_result *res, asp_error *err)
{
    double t0 = asp_time_now();
    int rc = 0;
    for (size_t l = 0; l < s->dps->level_count && !rc; l++) {
        const asp_dps_level *lv = &s->dps->levels[l];
        rc = simplify_fit(s, lv->prim_count, 0, &s->tris[l], s->tris_note[l], err);
        if (!rc)
            rc = simplify_fit(s, asp_dps_level_gpu_bytes(lv, NULL), 1, &s->bytes[l], s->bytes_note[l], err);
        if (!rc)
            rc = asp_progress(s->ctx, "simplify", (double)(l + 1) / (double)s->dps->level_count);
    }
    res->t_simplify = asp_time_now() - t0;
    return rc;
}

static int prepare(struct eval_state *s, const asp_eval_desc *d, asp_eval_result *res, asp_error *err)
{
    double t0 = asp_time_now();
    asp_amg *amg = NULL;
    int rc = asp_amg_decompose(s->cloud, d->amg, s->ctx, &amg, err);
    res->t_decompose = asp_time_now() - t0;
    size_t levels[64], n = 0;
    if (!rc) {
        n = pick_levels(amg, d->max_primitives ? d->max_primitives : 2000, levels);
        t0 = asp_time_now();
        rc = asp_prim_build(amg, s->cloud, levels, n, d->prim, NULL, s->ctx, &s->dps, err);
        res->t_build = asp_time_now() - t0;
    }
    asp_amg_destroy(amg);
    if (!rc)
        rc = asp_hier_build(s->cloud, NULL, s->ctx, &s->hier, err);
    if (!rc && s->mesh)
        rc = simplify_levels(s, res, err);
    for (size_t l = 0; !rc && d->billboards && l < s->dps->level_count; l++) {
        const asp_dps_level *lv = &s->dps->levels[l];
        asp_billboard_stats st = {0};
        rc = asp__eval_billboards(s->mesh, s->cloud, lv->prim_count, lv->texels, s->ctx, &s->bb[l], &st,
                                  &s->bb_error[l], err);
        s->bb_seconds[l] = st.t_search + st.t_texture;
        if (!rc)
            rc = asp_progress(s->ctx, "billboards", (double)(l + 1) / (double)s->dps->level_count);
    }
    // with a mesh, every picture is framed as `render MESH` frames it
    if (!rc)
        rc = s->mesh ? asp_scene_mesh_frame(s->mesh, &s->frame, err) : asp_cloud_frame(s->cloud, &s->frame, err);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, s->ctx, &s->gl, err);
    // the reference's splats cut at creases, so its sharp edges are the surface's, not the sampling's
    float *planes = NULL;
    if (!rc && s->crease_angle > 0 && s->cloud->normals) {
        planes = asp_alloc(s->ctx, 8 * s->cloud->count * sizeof(float));
        if (!planes)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the crease planes of %zu points", s->cloud->count);
        if (!rc)
            rc = asp_crease_clip_planes(s->cloud, &(asp_crease_desc){.angle_deg = s->crease_angle}, s->ctx,
                                        planes, &res->clipped_points, err);
    }
    if (!rc)
        rc = asp_renderer_kind_at(1)->create(s->gl, &(asp_render_source){.hier = s->hier, .clip_planes = planes},
                                             NULL, s->ctx, &s->splat, err); // row 1: "splat"
    if (!rc && s->mesh)
        rc = asp_renderer_kind_at(0)->create(s->gl, &(asp_render_source){.cloud = s->cloud, .clip_planes = planes},
                                             NULL, s->ctx, &s->disc, err); // row 0: "disc"
    asp_free(s->ctx, planes);
    if (!rc)
        snprintf(res->gl_renderer, sizeof res->gl_renderer, "%s", asp_gl_context_renderer(s->gl));
    return rc;
}

static void state_release(struct eval_state *s)
{
    asp_renderer_destroy(s->splat);
    asp_renderer_destroy(s->disc);
    for (size_t l = 0; l < MAX_LEVELS; l++) {
        asp_mesh_destroy(s->tris[l]);
        asp_mesh_destroy(s->bytes[l]);
        asp_dps_destroy(s->bb[l]);
    }
    asp_gl_context_destroy(s->gl);
    asp_hier_destroy(s->hier);
    asp_dps_destroy(s->dps);
}

static void name_level(const struct eval_state *s, const asp_dps_level *lv, asp_eval_row *row)
{
    row->level = lv->level;
    uint32_t coarse = s->dps->amg_levels - 1 - lv->level;
    if (coarse)
        snprintf(row->level_name, sizeof row->level_name, "L-%u", coarse);
    else
        snprintf(row->level_name, sizeof row->level_name, "L");
}

static int run_size(struct eval_state *s, uint32_t size, asp_eval_result *res, size_t *row, struct sheet *sh,
                    asp_error *err)
{
    asp_image *refs = asp_calloc(s->ctx, s->views, sizeof *refs);
    if (!refs)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu reference images", s->views);
    size_t r0 = *row;
    int rc = measure(s, NULL, NULL, s->mesh, size, NULL, refs, sh, 0, 0, &res->rows[r0], res->ssim + r0 * s->views,
                     res->psnr + r0 * s->views, err);
    if (!rc) {
        snprintf(res->rows[r0].level_name, sizeof res->rows[r0].level_name, "%s", s->mesh ? "mesh" : "points");
        (*row)++;
    }
    // against the true surface the full point set is a representation too, as discs and as splats
    static const struct rep full[2] = {{.name = "full-discs", .kind = REP_FULL_DISCS},
                                       {.name = "full-splats", .kind = REP_FULL_SPLATS}};
    for (int k = 0; k < 2 && s->mesh && !rc; k++) {
        size_t r = *row;
        rc = measure(s, &full[k], NULL, NULL, size, refs, NULL, NULL, 0, 0, &res->rows[r], res->ssim + r * s->views,
                     res->psnr + r * s->views, err);
        if (!rc) {
            snprintf(res->rows[r].level_name, sizeof res->rows[r].level_name, "points");
            (*row)++;
        }
    }
    for (size_t k = 0; k < s->nreps && !rc; k++)
        for (size_t l = 0; l < s->dps->level_count && !rc; l++) {
            const asp_dps_level *lv = &s->dps->levels[l];
            const struct rep *rp = &s->reps[k];
            size_t r = *row;
            const asp_mesh *mesh = rp->kind == REP_MESH_TRIS    ? s->tris[l]
                                   : rp->kind == REP_MESH_BYTES ? s->bytes[l]
                                                                : NULL;
            // a billboard cloud is drawn in its level's place: its own planes, texels and bytes
            const asp_dps_level *draw = rp->kind == REP_BILLBOARDS ? &s->bb[l]->levels[0] : lv;
            if ((rp->kind == REP_MESH_TRIS || rp->kind == REP_MESH_BYTES) && !mesh)
                row_without_figures(s, rp, lv, size, rp->kind == REP_MESH_TRIS ? s->tris_note[l] : s->bytes_note[l],
                                    &res->rows[r], res->ssim + r * s->views, res->psnr + r * s->views);
            else
                rc = measure(s, rp, draw, mesh, size, refs, NULL, sh, k, l + 1, &res->rows[r],
                             res->ssim + r * s->views, res->psnr + r * s->views, err);
            if (rc)
                break;
            name_level(s, lv, &res->rows[r]);
            if (rp->kind == REP_BILLBOARDS)
                res->rows[r].build_seconds = s->bb_seconds[l], res->rows[r].error_bound = s->bb_error[l];
            else if (rp->kind == REP_PRIM)
                res->rows[r].build_seconds = lv->t_basis + lv->t_construct;
            (*row)++;
            rc = asp_progress(s->ctx, "render", (double)*row / (double)res->row_count);
        }
    for (size_t v = 0; v < s->views; v++)
        asp_image_release(&refs[v]);
    asp_free(s->ctx, refs);
    return rc;
}

static int make_sheet(struct eval_state *s, struct sheet *sh, asp_eval_result *res, asp_error *err)
{
    // every row starts with the reference; tiles never rendered stay transparent
    const asp_image *ref = &sh->tiles[0];
    for (size_t i = 1; i < sh->rows * sh->cols; i++) {
        if (sh->tiles[i].pixels)
            continue;
        int rc = asp_image_init(&sh->tiles[i], ref->width, ref->height, err);
        if (rc)
            return rc;
        if (i % sh->cols == 0)
            memcpy(sh->tiles[i].pixels, ref->pixels, (size_t)ref->width * ref->height * 4);
    }
    res->sheet_cols = (uint32_t)sh->cols;
    res->sheet_rows = (uint32_t)sh->rows;
    asp_image grid = {0};
    int rc = asp_image_contact_sheet(sh->tiles, sh->rows * sh->cols, (uint32_t)sh->cols, &grid, err);
    if (rc)
        return rc;
    // the sheet says what it shows (issue 29): each row's representation, each column's level
    enum { LABEL = 48 };
    char *text = asp_calloc(s->ctx, sh->rows + sh->cols, LABEL);
    const char **labels = asp_calloc(s->ctx, sh->rows + sh->cols, sizeof *labels);
    if (!text || !labels)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the sheet's labels");
    for (size_t i = 0; !rc && i < sh->rows + sh->cols; i++) {
        char *t = text + i * LABEL;
        size_t c = i - sh->rows, lv = c - 1;
        if (i < sh->rows)
            snprintf(t, LABEL, "%s", s->reps[i].name);
        else if (c == 0)
            snprintf(t, LABEL, "reference\n%s", s->mesh ? "mesh" : "all points");
        else if (s->dps->amg_levels - 1 - s->dps->levels[lv].level)
            snprintf(t, LABEL, "level L-%u\n%zu primitives", s->dps->amg_levels - 1 - s->dps->levels[lv].level,
                     s->dps->levels[lv].prim_count);
        else
            snprintf(t, LABEL, "level L\n%zu primitives", s->dps->levels[lv].prim_count);
        labels[i] = t;
    }
    char title[96];
    snprintf(title, sizeof title, "view 0 at %ux%u: rows are representations, columns levels", ref->width,
             ref->height);
    if (!rc)
        rc = asp_chart_label_sheet(&grid,
                                   &(asp_chart_sheet_desc){.title = title,
                                                           .row_count = sh->rows,
                                                           .col_count = sh->cols,
                                                           .row_labels = labels,
                                                           .col_labels = labels + sh->rows},
                                   &res->sheet, err);
    asp_free(s->ctx, text);
    asp_free(s->ctx, labels);
    asp_image_release(&grid);
    return rc;
}

int asp_eval_run(const asp_cloud *cloud, const asp_eval_desc *desc, const asp_context *ctx, asp_eval_result **out,
                 asp_error *err)
{
    static const uint32_t default_sizes[3] = {128, 256, 512};
    asp_eval_desc d = desc ? *desc : (asp_eval_desc){0};
    const uint32_t *sizes = d.sizes ? d.sizes : default_sizes;
    size_t nsizes = d.sizes ? d.size_count : 3;
    int rc = check_desc(&d, sizes, nsizes, err);
    if (rc)
        return rc;
    if (!cloud || cloud->count < 3)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot evaluate a model of %zu points (at least 3)",
                             cloud ? cloud->count : (size_t)0);
    struct eval_state s = {.ctx = ctx, .cloud = cloud, .elevation = d.elevation ? d.elevation : 20.0f,
                           .views = d.views ? d.views : 16, .frames = d.frames ? d.frames : 5,
                           .crease_angle = d.crease_angle == 0 ? 60.0f : d.crease_angle < 0 ? -1.0f : d.crease_angle,
                           .mesh = d.mesh};
    asp_eval_result *res = asp_calloc(ctx, 1, sizeof *res);
    if (!res)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the evaluation result");
    if (ctx)
        res->ctx = *ctx;
    res->views = s.views;
    res->points = cloud->count;
    res->crease_angle = s.crease_angle;
    res->mesh_triangles = d.mesh ? d.mesh->triangle_count : 0;
    struct sheet sh = {0};
    static const asp_prim_render_method default_methods[4] = {ASP_PRIM_RENDER_NORMALIZED, ASP_PRIM_RENDER_PREFIX,
                                                              ASP_PRIM_RENDER_OVERLAP, ASP_PRIM_RENDER_TWO_PASS};
    const asp_prim_render_method *methods = d.methods ? d.methods : default_methods;
    size_t nmethods = d.methods ? d.method_count : 4;
    snprintf(s.reps[0].name, sizeof s.reps[0].name, "points");
    s.nreps = 1;
    for (size_t i = 0; i < nmethods; i++, s.nreps++) {
        s.reps[s.nreps].prim = 1;
        s.reps[s.nreps].method = methods[i];
        s.reps[s.nreps].kind = REP_PRIM;
        snprintf(s.reps[s.nreps].name, sizeof s.reps[s.nreps].name, "dp-%s", asp_prim_render_method_name(methods[i]));
    }
    if (d.hybrid)
        s.reps[s.nreps++] = (struct rep){.name = "hybrid", .kind = REP_HYBRID};
    if (d.billboards) // drawn by the prim renderer, which draws a billboard level alpha-tested whatever the method
        s.reps[s.nreps++] = (struct rep){.name = "billboards", .kind = REP_BILLBOARDS, .prim = 1};
    if (d.mesh) {
        s.reps[s.nreps++] = (struct rep){.name = "mesh-tris", .kind = REP_MESH_TRIS};
        s.reps[s.nreps++] = (struct rep){.name = "mesh-bytes", .kind = REP_MESH_BYTES};
    }
    rc = prepare(&s, &d, res, err);
    if (!rc) {
        res->level_count = s.dps->level_count;
        res->row_count = nsizes * (1 + (d.mesh ? 2 : 0) + s.nreps * s.dps->level_count);
        res->rows = asp_calloc(ctx, res->row_count, sizeof *res->rows);
        res->ssim = asp_calloc(ctx, res->row_count * s.views, sizeof *res->ssim);
        res->psnr = asp_calloc(ctx, res->row_count * s.views, sizeof *res->psnr);
        sh.cols = 1 + s.dps->level_count;
        sh.rows = s.nreps;
        sh.tiles = asp_calloc(ctx, sh.cols * sh.rows, sizeof *sh.tiles);
        if (!res->rows || !res->ssim || !res->psnr || !sh.tiles)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu result rows", res->row_count);
    }
    uint32_t sheet_size = d.sheet_size;
    if (!sheet_size)
        for (size_t i = 0; i < nsizes; i++)
            sheet_size = !sheet_size || sizes[i] < sheet_size ? sizes[i] : sheet_size;
    double t_render = asp_time_now();
    size_t row = 0;
    for (size_t i = 0; i < nsizes && !rc; i++) {
        // the sheet is made at sheet_size only; tiles[0].width tells measure() which size that is
        if (sh.tiles && sizes[i] == sheet_size && !sh.tiles[0].pixels)
            rc = asp_image_init(&sh.tiles[0], sheet_size, sheet_size, err);
        if (!rc)
            rc = run_size(&s, sizes[i], res, &row, &sh, err);
    }
    res->t_render = asp_time_now() - t_render;
    if (!rc && sh.tiles && sh.tiles[0].pixels)
        rc = make_sheet(&s, &sh, res, err);
    if (sh.tiles) {
        for (size_t i = 0; i < sh.rows * sh.cols; i++)
            asp_image_release(&sh.tiles[i]);
        asp_free(ctx, sh.tiles);
    }
    state_release(&s);
    if (rc) {
        asp_eval_result_destroy(res);
        return rc;
    }
    res->row_count = row;
    *out = res;
    return 0;
}

#endif
