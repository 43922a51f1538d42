/*
 * bench_fit (issue 27): fitted against unfitted domain primitives and against
 * the mesh simplified by meshoptimizer to the same triangle count, SSIM
 * against the mesh's own render on held-out views (eval's cameras: azimuth
 * 360 i / N, elevation alternating +-20, framed on the mesh's frame; none of
 * them is a fit view, which lie on a Fibonacci lattice). Also checks the fit's
 * CPU rasteriser against the GL prim renderer on the fitted level (crease
 * clipping off, as the rasteriser draws). The speed goal is timed by
 * bench_fit.sh around `amgsplat fit`.
 *
 *   bench_fit MESH UNFITTED.dps FITTED.dps [VIEWS] [PNG_DIR]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amgsplat.h"

enum { MAX_VIEWS = 64 };

static int fail(const char *what, const asp_error *err)
{
    fprintf(stderr, "bench_fit: %s: %s\n", what, err->msg);
    return 1;
}

static int make_renderer(asp_gl_context *gl, const char *kind_name, const asp_dps_level *lv, const asp_mesh *mesh,
                         const double origin[3], float crease, asp_renderer **out, asp_error *err)
{
    const asp_renderer_kind *kind = NULL;
    int rc = asp_renderer_kind_find(kind_name, 0, &kind, err);
    if (rc)
        return rc;
    asp_render_source src = {.level = lv};
    memcpy(src.origin, origin, sizeof src.origin);
    asp_render_material *mats = NULL;
    asp_render_mesh rm;
    if (mesh) {
        mats = calloc(mesh->material_count + 1, sizeof *mats);
        asp_scene_mesh_describe(mesh, mats, &rm);
        src.mesh = &rm;
    }
    asp_renderer_options o = {.prim = {.crease_angle = crease}};
    rc = kind->create(gl, &src, &o, NULL, out, err);
    free(mats);
    return rc;
}

static int render_ssim(asp_gl_context *gl, asp_renderer *r, const asp_camera *cams, const asp_image *refs, size_t n,
                       uint32_t size, double *ssim, const char *png, asp_error *err)
{
    for (size_t v = 0; v < n; v++) {
        asp_image img = {0};
        int rc = asp_render_to_image(gl, r, &cams[v], &(asp_render_desc){.width = size, .height = size}, &img, err);
        if (!rc)
            rc = asp_image_ssim(&img, &refs[v], &ssim[v], err);
        if (!rc && png && v < 4) {
            char path[512];
            snprintf(path, sizeof path, "%s-%u-v%zu.png", png, size, v);
            rc = asp_image_save_png(&img, path, err);
        }
        asp_image_release(&img);
        if (rc)
            return rc;
    }
    return 0;
}

static size_t wins(const double *a, const double *b, size_t n)
{
    size_t w = 0;
    for (size_t v = 0; v < n; v++)
        w += a[v] > b[v];
    return w;
}

static double mean(const double *a, size_t n)
{
    double s = 0;
    for (size_t v = 0; v < n; v++)
        s += a[v];
    return s / (double)n;
}

/* meshoptimizer at <= target triangles (the target lowered while it stops above it). */
static int simplify(const asp_mesh *m, size_t target, asp_mesh **out, asp_error *err)
{
    for (size_t t = target; t >= 4; t = t * 9 / 10) {
        asp_mesh *s = NULL;
        int rc = asp_mesh_simplify(
            m, &(asp_mesh_simplify_desc){.target_triangles = t, .flags = ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK}, NULL,
            &s, NULL, err);
        if (rc)
            return rc;
        if (s->triangle_count <= target) {
            *out = s;
            return 0;
        }
        asp_mesh_destroy(s);
    }
    return asp_error_set(err, ASP_EDEGENERATE, "cannot simplify to %zu triangles", target);
}

/* meshoptimizer at <= limit GPU bytes (asp_mesh_gpu_bytes, as eval's mesh-bytes row): the triangle target bisected. */
static int simplify_bytes(const asp_mesh *m, size_t limit, asp_mesh **out, asp_error *err)
{
    size_t lo = 0, hi = m->triangle_count;
    asp_mesh *best = NULL;
    while (lo + 1 < hi && !(lo && hi - lo <= lo / 100)) {
        size_t t = lo + (hi - lo) / 2;
        asp_mesh *s = NULL;
        int rc = asp_mesh_simplify(
            m, &(asp_mesh_simplify_desc){.target_triangles = t, .flags = ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK}, NULL,
            &s, NULL, err);
        if (rc) {
            asp_mesh_destroy(best);
            return rc;
        }
        if (asp_mesh_gpu_bytes(s, NULL) <= limit) {
            asp_mesh_destroy(best);
            best = s;
            lo = t;
        } else {
            asp_mesh_destroy(s);
            hi = t;
        }
    }
    if (!best)
        return asp_error_set(err, ASP_EDEGENERATE, "no simplification within %zu bytes", limit);
    *out = best;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: bench_fit MESH UNFITTED.dps FITTED.dps [VIEWS] [PNG_DIR]\n");
        return 2;
    }
    size_t nviews = argc > 4 ? (size_t)atoi(argv[4]) : 16;
    const char *png_dir = argc > 5 ? argv[5] : NULL;
    if (nviews < 1 || nviews > MAX_VIEWS)
        nviews = 16;
    asp_error err = {0};
    asp_mesh *mesh = NULL;
    asp_dps *unfit = NULL, *fit = NULL;
    asp_gl_context *gl = NULL;
    if (asp_mesh_load(argv[1], NULL, NULL, &mesh, &err))
        return fail(argv[1], &err);
    if (asp_dps_load(argv[2], NULL, &unfit, &err) || asp_dps_load(argv[3], NULL, &fit, &err))
        return fail("dps", &err);
    if (unfit->level_count != fit->level_count)
        return fprintf(stderr, "bench_fit: the two files hold different levels\n"), 1;
    if (asp_gl_context_create_headless(NULL, NULL, &gl, &err))
        return fail("GL", &err);
    asp_frame frame;
    if (asp_scene_mesh_frame(mesh, &frame, &err))
        return fail("mesh frame", &err);
    const double *origin = frame.center;
    asp_camera cams[MAX_VIEWS];
    for (size_t v = 0; v < nviews; v++) {
        asp_camera_init(&cams[v]);
        cams[v].azimuth = (float)(360.0 * (double)v / (double)nviews);
        cams[v].elevation = v % 2 ? -20.0f : 20.0f;
        asp_camera_frame(&cams[v], &frame, origin, 1.0f, 0.0f);
    }
    const char *model = strrchr(argv[1], '/') ? strrchr(argv[1], '/') + 1 : argv[1];
    printf("model,level,primitives,triangles,size,ssim_unfitted,ssim_fitted,ssim_mesh,fitted_beats_mesh,"
           "unfitted_beats_mesh,fitted_beats_unfitted,views,cpu_gl_ssim_min,fitted_bytes,bytes_triangles,"
           "ssim_mesh_bytes,fitted_beats_mesh_bytes\n");
    static const uint32_t sizes[2] = {128, 256};
    for (size_t l = 0; l < fit->level_count; l++) {
        const asp_dps_level *lu = &unfit->levels[l], *lf = &fit->levels[l];
        asp_mesh *simple = NULL;
        if (simplify(mesh, lf->prim_count, &simple, &err))
            return fail("simplify", &err);
        size_t fbytes = asp_dps_level_gpu_bytes(lf, NULL);
        asp_mesh *eqb = NULL;
        if (simplify_bytes(mesh, fbytes, &eqb, &err))
            return fail("simplify to bytes", &err);
        char name[16];
        asp_dps_level_name(fit, l, name);
        // the CPU rasteriser the fit solves with against GL, crease clipping off
        double cpu_gl = 1;
        asp_renderer *plain = NULL;
        if (make_renderer(gl, "prim", lf, NULL, origin, -1.0f, &plain, &err))
            return fail("prim renderer", &err);
        for (size_t v = 0; v < 4 && v < nviews; v++) {
            asp_fit_view fv = {.width = 128, .height = 128, .light = {0, 0, 1}};
            asp_camera_view_matrix(&cams[v], fv.view);
            asp_camera_projection_matrix(&cams[v], fv.proj);
            asp_image a = {0}, b = {0};
            double s = 0;
            if (asp_render_to_image(gl, plain, &cams[v], &(asp_render_desc){.width = 128, .height = 128}, &a,
                                    &err) ||
                asp_fit_render_cpu(lf, origin, &fv, NULL, &b, &err) || asp_image_ssim(&a, &b, &s, &err))
                return fail("CPU vs GL", &err);
            cpu_gl = fmin(cpu_gl, s);
            asp_image_release(&a), asp_image_release(&b);
        }
        asp_renderer_destroy(plain);
        for (int si = 0; si < 2; si++) {
            uint32_t size = sizes[si];
            asp_image refs[MAX_VIEWS];
            double su[MAX_VIEWS], sf[MAX_VIEWS], sm[MAX_VIEWS], sb[MAX_VIEWS];
            asp_renderer *rm = NULL, *ru = NULL, *rf = NULL, *rs = NULL, *rb = NULL;
            char pu[512], pf[512], ps[512], pr[512];
            snprintf(pu, sizeof pu, "%s/%s-%s-unfitted", png_dir ? png_dir : ".", model, name);
            snprintf(pf, sizeof pf, "%s/%s-%s-fitted", png_dir ? png_dir : ".", model, name);
            snprintf(ps, sizeof ps, "%s/%s-%s-mesh%zu", png_dir ? png_dir : ".", model, name, simple->triangle_count);
            snprintf(pr, sizeof pr, "%s/%s-reference", png_dir ? png_dir : ".", model);
            int rc = make_renderer(gl, "mesh", NULL, mesh, origin, 0, &rm, &err);
            for (size_t v = 0; v < nviews && !rc; v++) {
                memset(&refs[v], 0, sizeof refs[v]);
                rc = asp_render_to_image(gl, rm, &cams[v], &(asp_render_desc){.width = size, .height = size},
                                         &refs[v], &err);
                if (!rc && png_dir && v < 4) {
                    char path[600];
                    snprintf(path, sizeof path, "%s-%u-v%zu.png", pr, size, v);
                    rc = asp_image_save_png(&refs[v], path, &err);
                }
            }
            if (!rc)
                rc = make_renderer(gl, "prim", lu, NULL, origin, 0, &ru, &err);
            if (!rc)
                rc = make_renderer(gl, "prim", lf, NULL, origin, 0, &rf, &err);
            if (!rc)
                rc = make_renderer(gl, "mesh", NULL, simple, origin, 0, &rs, &err);
            if (!rc)
                rc = render_ssim(gl, ru, cams, refs, nviews, size, su, png_dir ? pu : NULL, &err);
            if (!rc)
                rc = render_ssim(gl, rf, cams, refs, nviews, size, sf, png_dir ? pf : NULL, &err);
            if (!rc)
                rc = render_ssim(gl, rs, cams, refs, nviews, size, sm, png_dir ? ps : NULL, &err);
            if (!rc)
                rc = make_renderer(gl, "mesh", NULL, eqb, origin, 0, &rb, &err);
            if (!rc)
                rc = render_ssim(gl, rb, cams, refs, nviews, size, sb, NULL, &err);
            if (rc)
                return fail("render", &err);
            printf("%s,%s,%zu,%zu,%u,%.4f,%.4f,%.4f,%zu,%zu,%zu,%zu,%.4f,%zu,%zu,%.4f,%zu\n", model, name,
                   lf->prim_count, simple->triangle_count, size, mean(su, nviews), mean(sf, nviews), mean(sm, nviews),
                   wins(sf, sm, nviews), wins(su, sm, nviews), wins(sf, su, nviews), nviews, cpu_gl, fbytes,
                   eqb->triangle_count, mean(sb, nviews), wins(sf, sb, nviews));
            fflush(stdout);
            asp_renderer_destroy(rm), asp_renderer_destroy(ru), asp_renderer_destroy(rf), asp_renderer_destroy(rs);
            asp_renderer_destroy(rb);
            for (size_t v = 0; v < nviews; v++)
                asp_image_release(&refs[v]);
        }
        asp_mesh_destroy(simple);
        asp_mesh_destroy(eqb);
    }
    asp_gl_context_destroy(gl);
    asp_dps_destroy(unfit), asp_dps_destroy(fit);
    asp_mesh_destroy(mesh);
    return 0;
}
