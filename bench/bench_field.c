/*
 * Field of instances (issue 18, first "Done when" line; seed 004's closing
 * question of distance-dependent detail, journal section 6): N instances of a
 * multi-level .dps of the bunny on a ground plane receding to the horizon,
 * the camera at ground level, drawn by the cut renderer at full detail
 * (tolerance 0: the finest stored level everywhere) and at several screen
 * tolerances. Prints per tolerance the median frame times of `frames` renders
 * of each (asp_render_frame with glFinish; full and cut frames alternate), the
 * primitives drawn and the SSIM against full detail (eval's asp_image_ssim),
 * and the fastest tolerance with SSIM >= 0.97; writes full.png, cut.png (that tolerance) and cut_<tolerance>.png to DIR. Timings never fail.
 * usage: bench_field [MODEL.obj|.dps] [--points N=150000] [--instances N=1000] [--frames N=5]
 *                    [--finest N=2000] [--size-weight X=0 (renderer default)] [--out DIR=.]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/eval.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

enum { SIZE = 512, MAX_LEVELS = 64 };

static const char *prog = "bench_field";

static int fail(const asp_error *err)
{
    fprintf(stderr, "%s: %s\n", prog, err->msg);
    return 1;
}

/* The finest level with at most finest basis functions and every coarser one, linked (asp_prim_build). */
static int build_dps(const char *model, size_t points, size_t finest, asp_dps **dps, asp_error *err)
{
    size_t n = strlen(model);
    if (n > 4 && strcmp(model + n - 4, ".dps") == 0)
        return asp_dps_load(model, NULL, dps, err);
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    double t0 = asp_time_now();
    int rc = asp_mesh_load(model, NULL, NULL, &mesh, err);
    if (!rc)
        rc = asp_sample_mesh(mesh, &(asp_sample_desc){.points = points, .seed = 1}, NULL, &cloud, NULL, err);
    asp_mesh_destroy(mesh);
    if (!rc)
        rc = asp_amg_decompose(cloud, NULL, NULL, &amg, err);
    size_t first = 0, levels[MAX_LEVELS], nl = 0;
    if (!rc)
        rc = asp_prim_level_for_budget(amg, finest, &first, err);
    if (!rc) {
        for (size_t l = first; l < asp_amg_level_count(amg) && nl < MAX_LEVELS; l++)
            levels[nl++] = l;
        rc = asp_prim_build(amg, NULL, levels, nl, NULL, model, NULL, dps, err);
    }
    if (!rc) {
        printf("model %s: %zu points, %zu levels stored (", model, cloud->count, (*dps)->level_count);
        for (size_t i = 0; i < (*dps)->level_count; i++)
            printf("%s%zu", i ? ", " : "", (*dps)->levels[i].prim_count);
        printf(" primitives), built in %.1f s\n", asp_time_now() - t0);
    }
    asp_cloud_destroy(cloud);
    asp_amg_destroy(amg);
    return rc;
}

/*
 * cols x rows instances on the plane y = ground, spaced 2.4 radii, each turned about y by a seeded
 * angle; rows recede along -z from just in front of the camera.
 */
static void field_models(float *models, size_t count, float radius, float ground)
{
    size_t cols = 20;
    uint64_t seed = 0x9e3779b97f4a7c15ull;
    float step = 2.4f * radius;
    for (size_t i = 0; i < count; i++) {
        size_t row = i / cols, col = i % cols;
        double a = 2 * 3.14159265358979 * bench_urand(&seed);
        float c = (float)cos(a), s = (float)sin(a), *m = models + 16 * i;
        memset(m, 0, 16 * sizeof *m);
        m[0] = c, m[2] = -s, m[5] = 1, m[8] = s, m[10] = c, m[15] = 1;
        m[12] = ((float)col - 0.5f * (float)(cols - 1)) * step;
        m[13] = ground;
        m[14] = -(float)(row + 2) * step;
    }
}

typedef struct timing {
    double ms, cut_ms; /* frame; the CPU cuts and item list of the last frame */
    size_t drawn;
} timing;

/* One timed frame at tolerance (asp_render_frame with glFinish); fills drawn and cut_ms. */
static int time_one(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, float tolerance, double *ms,
                    timing *out, asp_error *err)
{
    asp_render_desc d = {.width = SIZE, .height = SIZE, .background = {190, 205, 225, 255}, .flags = ASP_RENDER_WAIT};
    int rc = asp_renderer_set_lod(r, tolerance, 0, err);
    double t0 = asp_time_now();
    if (!rc)
        rc = asp_render_frame(gl, r, cam, &d, err);
    *ms = 1e3 * (asp_time_now() - t0);
    if (!rc && out) {
        asp_renderer_stats st;
        asp_renderer_stats_get(r, &st);
        out->drawn = st.count;
        out->cut_ms = 1e3 * st.select_seconds;
    }
    return rc;
}

/*
 * Full detail and the cut at tolerance, frame for frame alternately, so both medians see the same load
 * of this shared machine (the ratio is the claim, not the milliseconds). The first pair warms up.
 */
static int time_pair(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, float tolerance, int frames,
                     timing *full, timing *cut, asp_error *err)
{
    double *tf = calloc((size_t)frames, sizeof *tf), *tc = calloc((size_t)frames, sizeof *tc), w;
    int rc = time_one(gl, r, cam, 0, &w, NULL, err);
    if (!rc)
        rc = time_one(gl, r, cam, tolerance, &w, NULL, err);
    for (int f = 0; !rc && f < frames; f++) {
        rc = time_one(gl, r, cam, 0, &tf[f], full, err);
        if (!rc)
            rc = time_one(gl, r, cam, tolerance, &tc[f], cut, err);
    }
    if (!rc) {
        full->ms = bench_median(tf, frames);
        cut->ms = bench_median(tc, frames);
    }
    free(tf);
    free(tc);
    return rc;
}

static int snapshot(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, float tolerance, asp_image *img,
                    asp_error *err)
{
    asp_render_desc d = {.width = SIZE, .height = SIZE, .background = {190, 205, 225, 255}};
    int rc = asp_renderer_set_lod(r, tolerance, 0, err);
    return rc ? rc : asp_render_to_image(gl, r, cam, &d, img, err);
}

/*
 * SSIM of rows [y0, y1) only: the band where the field lies. The sky above and the empty plane below
 * are background in both images and lift the whole-image SSIM; this shows the models' own share.
 */
static int band_ssim(const asp_image *a, const asp_image *b, uint32_t y0, uint32_t y1, double *out, asp_error *err)
{
    asp_image ca = {0, 0, NULL}, cb = {0, 0, NULL};
    int rc = asp_image_init(&ca, a->width, y1 - y0, err);
    if (!rc)
        rc = asp_image_init(&cb, b->width, y1 - y0, err);
    if (!rc) {
        size_t row = 4 * (size_t)a->width;
        memcpy(ca.pixels, a->pixels + y0 * row, (y1 - y0) * row);
        memcpy(cb.pixels, b->pixels + y0 * row, (y1 - y0) * row);
        rc = asp_image_ssim(&ca, &cb, out, err);
    }
    asp_image_release(&ca);
    asp_image_release(&cb);
    return rc;
}

int main(int argc, char **argv)
{
    char model_buf[512];
    const char *model = NULL, *dir = ".";
    size_t points = 150000, instances = 1000, finest = 2000;
    int frames = 5;
    double size_weight = 0; // the renderer's default
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--points") == 0 && i + 1 < argc)
            points = strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--instances") == 0 && i + 1 < argc)
            instances = strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (strcmp(argv[i], "--finest") == 0 && i + 1 < argc)
            finest = strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--size-weight") == 0 && i + 1 < argc)
            size_weight = atof(argv[++i]);
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            dir = argv[++i];
        else
            model = argv[i];
    }
    if (!model) {
        snprintf(model_buf, sizeof model_buf, "%s/stanford-bunny.obj", ASP_TEST_DATA);
        model = model_buf;
    }
    if (frames < 1 || instances < 1 || points < 100) {
        fprintf(stderr, "usage: %s [MODEL.obj|.dps] [--points N] [--instances N] [--frames N] [--finest N] "
                "[--out DIR]\n", prog);
        return 2;
    }
    asp_error err = {0, ""};
    asp_dps *dps = NULL;
    if (build_dps(model, points, finest, &dps, &err))
        return fail(&err);
    asp_gl_context *gl = NULL;
    asp_renderer *r = NULL;
    float *models = malloc(16 * instances * sizeof *models);
    const asp_frame *fr = &dps->frame;
    double lo = INFINITY; // the model's lowest point along y: it stands on the plane
    for (size_t i = 0; i < dps->levels[0].prim_count; i++)
        lo = fmin(lo, dps->levels[0].prims[i].centre[1] - dps->levels[0].prims[i].half_v);
    float radius = (float)fr->radius, ground = (float)(fr->center[1] - lo);
    field_models(models, instances, radius, ground);
    asp_cut_renderer_desc cd = {.fade_seconds = -1, .size_weight = (float)size_weight};
    memcpy(cd.origin, fr->center, sizeof cd.origin);
    if (asp_gl_context_create_headless(NULL, NULL, &gl, &err) || asp_cut_renderer_create(gl, dps, &cd, &r, &err) ||
        asp_cut_renderer_set_instances(r, models, instances, &err))
        return fail(&err);
    // ground level: the eye about a model's height above the plane, looking down the rows to the horizon
    asp_camera cam;
    asp_camera_init(&cam);
    cam.distance = 10 * radius;
    cam.elevation = 4; // the eye above the target: looking down
    cam.target[0] = 0.5f * radius, cam.target[1] = 1.2f * radius - cam.distance * sinf(4 * 3.14159265f / 180);
    cam.target[2] = -cam.distance * cosf(4 * 3.14159265f / 180);
    cam.fov_y = 45, cam.aspect = 1, cam.z_near = 0.02f * radius, cam.z_far = 1000 * radius;
    printf("%zu instances, %d frames per figure, %dx%d, %s\n", instances, frames, SIZE, SIZE,
           asp_gl_context_renderer(gl));

    asp_image ref = {0, 0, NULL}, best_img = {0, 0, NULL};
    if (snapshot(gl, r, &cam, 0, &ref, &err))
        return fail(&err);
    printf("tolerance_px  drawn (full)        full_ms  cut_ms  cpu_cut_ms  speedup  ssim    ssim_band(rows 160-383)\n");
    static const float tols[] = {1, 2, 2.5f, 3, 3.5f, 4, 6};
    float best = -1;
    timing best_t = {0, 0, 0}, best_full = {0, 0, 0};
    double best_ssim = 0;
    for (size_t k = 0; k < sizeof tols / sizeof tols[0]; k++) {
        timing t = {0, 0, 0}, full = {0, 0, 0};
        asp_image img = {0, 0, NULL};
        double ssim = 0, band = 0;
        if (time_pair(gl, r, &cam, tols[k], frames, &full, &t, &err) || snapshot(gl, r, &cam, tols[k], &img, &err) ||
            asp_image_ssim(&ref, &img, &ssim, &err) || band_ssim(&ref, &img, 160, 384, &band, &err))
            return fail(&err);
        printf("%-12g  %-6zu (%-9zu)  %-7.1f  %-6.1f  %-10.1f  %-7.1f  %.4f  %.4f\n", (double)tols[k], t.drawn,
               full.drawn, full.ms, t.ms, t.cut_ms, full.ms / t.ms, ssim, band);
        char name[600];
        snprintf(name, sizeof name, "%s/cut_%g.png", dir, (double)tols[k]);
        if (asp_image_save_png(&img, name, &err))
            return fail(&err);
        if (ssim >= 0.97) {
            best = tols[k], best_t = t, best_full = full, best_ssim = ssim;
            asp_image_release(&best_img);
            best_img = img;
        } else {
            asp_image_release(&img);
        }
    }
    char path[600];
    snprintf(path, sizeof path, "%s/full.png", dir);
    if (asp_image_save_png(&ref, path, &err))
        return fail(&err);
    if (best >= 0) {
        snprintf(path, sizeof path, "%s/cut.png", dir);
        if (asp_image_save_png(&best_img, path, &err))
            return fail(&err);
        printf("chosen: tolerance %g px, %zu primitives, %.1f ms against %.1f ms full detail (%zu primitives): "
               "%.1fx less frame time, SSIM %.4f\n", (double)best, best_t.drawn, best_t.ms, best_full.ms,
               best_full.drawn, best_full.ms / best_t.ms, best_ssim);
    } else {
        printf("no tolerance kept SSIM >= 0.97\n");
    }
    asp_image_release(&ref);
    asp_image_release(&best_img);
    asp_renderer_destroy(r);
    asp_gl_context_destroy(gl);
    asp_dps_destroy(dps);
    free(models);
    return 0;
}
