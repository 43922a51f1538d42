/*
 * Domain-primitive rendering benchmark (journal Table 2, thesis Table 5.3:
 * domain primitives 3-16x faster than the model's points): median frame time
 * of every AMG level's primitives (normalized and overlap methods) against the
 * full point set drawn as opaque discs, at 128x128, 256x256 and 512x512
 * (asp_render_frame with glFinish, no read-back). With --quality DIR it also
 * renders 16 views at 256x256 of the level nearest 400 primitives with every
 * method and prints the SSIM of each view against the full point render
 * (issue 5), writing one contact sheet per method to DIR. Timings never fail
 * anything.
 * usage: bench_prim_render [MODEL.obj|.ply|.amg] [frames=7] [--quality DIR]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/eval.h"
#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

enum { VIEWS = 16, QSIZE = 256, MAX_LEVELS = 64 };

static int ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), m = strlen(ext);
    return n >= m && strcmp(s + n - m, ext) == 0;
}

/* The decomposition of path: loaded (.amg), or sampled (mesh, 100k points) / read (points) and decomposed. */
static int load_amg(const char *path, asp_amg **amg, asp_error *err)
{
    if (ends_with(path, ".amg"))
        return asp_amg_load(path, NULL, amg, err);
    asp_cloud *cloud = NULL;
    int rc;
    if (ends_with(path, ".ply") || ends_with(path, ".xyz")) {
        rc = asp_cloud_load(path, NULL, &cloud, err);
    } else {
        asp_mesh *mesh = NULL;
        rc = asp_mesh_load(path, NULL, NULL, &mesh, err);
        if (!rc)
            rc = asp_sample_mesh(mesh, NULL, NULL, &cloud, NULL, err);
        asp_mesh_destroy(mesh);
    }
    if (!rc)
        rc = asp_amg_decompose(cloud, NULL, NULL, amg, err);
    asp_cloud_destroy(cloud);
    return rc;
}

static void view_camera(asp_camera *cam, size_t i, size_t n, const float c[3], float r)
{
    asp_camera_init(cam);
    cam->azimuth = 30.0f + 360.0f * (float)i / (float)n;
    cam->elevation = i % 2 ? -20.0f : 20.0f;
    asp_camera_fit(cam, c, r, 1.0f);
}

static double frame_ms(asp_gl_context *gl, asp_renderer *r, const float c[3], float radius, uint32_t size,
                       int frames)
{
    double t[64];
    asp_camera cam;
    view_camera(&cam, 0, 1, c, radius);
    asp_render_desc d = {.width = size, .height = size, .background = {255, 255, 255, 255}, .flags = ASP_RENDER_WAIT};
    asp_error err;
    if (asp_render_frame(gl, r, &cam, &d, &err)) { // warm-up: shader JIT, target allocation
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        return NAN;
    }
    for (int f = 0; f < frames; f++) {
        double t0 = asp_time_now();
        asp_render_frame(gl, r, &cam, &d, &err);
        t[f] = 1e3 * (asp_time_now() - t0);
    }
    return bench_median(t, frames);
}

static void timing_table(asp_gl_context *gl, const asp_cloud *cloud, const asp_dps *dps, int frames)
{
    static const uint32_t sizes[3] = {128, 256, 512};
    float c[3], radius;
    asp_error err;
    if (asp_render_bounding_sphere(cloud, c, &radius, &err))
        return;
    asp_renderer *disc = NULL;
    if (asp_disc_renderer_create(gl, cloud, NULL, &disc, &err)) {
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        return;
    }
    double disc_ms[3];
    for (int s = 0; s < 3; s++)
        disc_ms[s] = frame_ms(gl, disc, c, radius, sizes[s], frames);
    asp_renderer_destroy(disc);
    printf("\nframe time, median of %d frames (ms), and speed-up over %zu points as discs\n", frames, cloud->count);
    printf("%-6s %7s | %-24s | %-24s | %-24s\n", "level", "prims", "128x128 norm / overlap", "256x256 norm / overlap",
           "512x512 norm / overlap");
    printf("%-6s %7zu | %10.2f %13s | %10.2f %13s | %10.2f %13s\n", "points", cloud->count, disc_ms[0], "(discs)",
           disc_ms[1], "(discs)", disc_ms[2], "(discs)");
    asp_dps_summary rows[MAX_LEVELS];
    asp_dps_summarize(dps, rows, MAX_LEVELS);
    for (size_t l = 0; l < dps->level_count && l < MAX_LEVELS; l++) {
        asp_renderer *r = NULL;
        asp_prim_renderer_desc pd = {.origin = {cloud->origin[0], cloud->origin[1], cloud->origin[2]}};
        if (asp_prim_renderer_create(gl, &dps->levels[l], &pd, &r, &err)) {
            fprintf(stderr, "bench_prim_render: level %s: %s\n", rows[l].name, err.msg);
            continue;
        }
        printf("%-6s %7zu |", rows[l].name, dps->levels[l].prim_count);
        for (int s = 0; s < 3; s++) {
            double ms[2];
            for (int m = 0; m < 2; m++) {
                asp_prim_render_options o = {.method = m ? ASP_PRIM_RENDER_OVERLAP : ASP_PRIM_RENDER_NORMALIZED};
                asp_prim_renderer_set_options(r, &o, NULL);
                ms[m] = frame_ms(gl, r, c, radius, sizes[s], frames);
            }
            printf(" %5.2f/%5.2f %4.1fx/%4.1fx |", ms[0], ms[1], disc_ms[s] / ms[0], disc_ms[s] / ms[1]);
        }
        printf("\n");
        fflush(stdout);
        asp_renderer_destroy(r);
    }
}

static void save_sheet(const asp_image *tiles, const char *dir, const char *name)
{
    asp_image sheet = {0, 0, NULL};
    asp_error err;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    if (asp_image_contact_sheet(tiles, VIEWS, 0, &sheet, &err) || asp_image_save_png(&sheet, path, &err))
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
    asp_image_release(&sheet);
}

/* Issue 5: 16 views at 256x256 of the level nearest 400 primitives against the full point render. */
static void quality(asp_gl_context *gl, const asp_cloud *cloud, const asp_dps *dps, size_t level, const char *dir)
{
    float c[3], radius;
    asp_error err;
    static asp_image ref[VIEWS], img[VIEWS];
    static double ssim[16][VIEWS];
    asp_render_desc rd = {.width = QSIZE, .height = QSIZE, .background = {255, 255, 255, 255}};
    asp_renderer *disc = NULL, *r = NULL;
    if (asp_render_bounding_sphere(cloud, c, &radius, &err) || asp_disc_renderer_create(gl, cloud, NULL, &disc, &err)) {
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        return;
    }
    for (size_t v = 0; v < VIEWS; v++) {
        asp_camera cam;
        view_camera(&cam, v, VIEWS, c, radius);
        asp_render_to_image(gl, disc, &cam, &rd, &ref[v], &err);
    }
    asp_renderer_destroy(disc);
    save_sheet(ref, dir, "points");
    asp_prim_renderer_desc pd = {.origin = {cloud->origin[0], cloud->origin[1], cloud->origin[2]}};
    if (asp_prim_renderer_create(gl, &dps->levels[level], &pd, &r, &err)) {
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        return;
    }
    printf("\nSSIM against the %zu points as discs, %u views at %ux%u, %zu primitives (level %u)\n", cloud->count,
           VIEWS, QSIZE, QSIZE, dps->levels[level].prim_count, dps->levels[level].level);
    size_t nm = 0;
    for (unsigned m = 0; asp_prim_render_method_name(m) && m < 16; m++, nm++) {
        asp_prim_render_options o = {.method = (asp_prim_render_method)m};
        asp_prim_renderer_set_options(r, &o, NULL);
        double mean = 0;
        for (size_t v = 0; v < VIEWS; v++) {
            asp_camera cam;
            view_camera(&cam, v, VIEWS, c, radius);
            ssim[m][v] = 0;
            if (!asp_render_to_image(gl, r, &cam, &rd, &img[v], &err))
                asp_image_ssim(&ref[v], &img[v], &ssim[m][v], &err);
            mean += ssim[m][v] / VIEWS;
        }
        save_sheet(img, dir, asp_prim_render_method_name(m));
        for (size_t v = 0; v < VIEWS; v++)
            asp_image_release(&img[v]);
        printf("%-19s mean %.4f\n", asp_prim_render_method_name(m), mean);
    }
    printf("\nper view: normalized, prefix, overlap (wins = better than overlap)\n");
    int wins_n = 0, wins_p = 0;
    for (size_t v = 0; v < VIEWS; v++) {
        double n = ssim[ASP_PRIM_RENDER_NORMALIZED][v], p = ssim[ASP_PRIM_RENDER_PREFIX][v];
        double ov = ssim[ASP_PRIM_RENDER_OVERLAP][v];
        wins_n += n > ov;
        wins_p += p > ov;
        printf("view %2zu (az %5.1f, el %+3.0f): %.4f %.4f %.4f\n", v, 30.0 + 360.0 * (double)v / VIEWS,
               v % 2 ? -20.0 : 20.0, n, p, ov);
    }
    printf("normalized beats overlap on %d of %d views, prefix on %d of %d\n", wins_n, VIEWS, wins_p, VIEWS);
    asp_renderer_destroy(r);
    for (size_t v = 0; v < VIEWS; v++)
        asp_image_release(&ref[v]);
}

int main(int argc, char **argv)
{
    const char *model = ASP_TEST_DATA "/stanford-bunny.obj", *qdir = NULL;
    int frames = 7, npos = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quality") == 0 && i + 1 < argc)
            qdir = argv[++i];
        else if (npos++ == 0)
            model = argv[i];
        else
            frames = atoi(argv[i]);
    }
    if (frames < 1 || frames > 64)
        frames = 7;
    asp_error err = {0, ""};
    asp_amg *amg = NULL;
    asp_dps *dps = NULL;
    asp_gl_context *gl = NULL;
    double t0 = asp_time_now();
    if (load_amg(model, &amg, &err)) {
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        return 1;
    }
    const asp_cloud *cloud = asp_amg_cloud(amg);
    // every level from the one with about 20 points per primitive (thesis Table 5.2 starts near there) to L
    size_t nl = asp_amg_level_count(amg), levels[MAX_LEVELS], n = 0, q = 0;
    for (size_t l = 0; l < nl && n < MAX_LEVELS; l++)
        if (asp_amg_level_size(amg, l) * 20 <= cloud->count)
            levels[n++] = l;
    for (size_t l = 0; l < nl; l++) // the level nearest 400 primitives (issue 5)
        if (fabs(log((double)asp_amg_level_size(amg, l) / 400.0)) < fabs(log((double)asp_amg_level_size(amg, q) / 400.0)))
            q = l;
    int rc = asp_prim_build(amg, NULL, levels, n, NULL, model, NULL, &dps, &err);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, NULL, &gl, &err);
    if (rc) {
        fprintf(stderr, "bench_prim_render: %s\n", err.msg);
        asp_dps_destroy(dps);
        asp_amg_destroy(amg);
        asp_amg_shutdown();
        return 1;
    }
    printf("%s: %zu points, %zu levels built in %.1f s; GL: %s\n", model, cloud->count, dps->level_count,
           asp_time_now() - t0, asp_gl_context_renderer(gl));
    timing_table(gl, cloud, dps, frames);
    if (qdir) {
        size_t ql = SIZE_MAX;
        for (size_t l = 0; l < dps->level_count; l++)
            if (dps->levels[l].level == q)
                ql = l;
        if (ql != SIZE_MAX)
            quality(gl, cloud, dps, ql, qdir);
    }
    asp_gl_context_destroy(gl);
    asp_dps_destroy(dps);
    asp_amg_destroy(amg);
    asp_amg_shutdown();
    return 0;
}
