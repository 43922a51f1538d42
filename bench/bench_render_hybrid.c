/*
 * Frame time of the hybrid renderer (docs/hybrid.md, issue 18 item 3) against
 * the same level's primitives alone (normalized, the best pure-primitive
 * method in eval) on one .dps and its source points: 4 views (azimuth 0, 90,
 * 180, 270, elevation 20), frames of the two renderers interleaved so that
 * the load of a shared machine falls on both alike; per view the median of
 * each, and the median of the per-view ratios. asp_render_frame with
 * ASP_RENDER_WAIT, no read-back. Timings never fail anything.
 * usage: bench_render_hybrid X.dps [frames=9] [size=256] [tolerance=0]
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/render.h"
#include "amgsplat/scene.h"
#include "bench_common.h"

enum { VIEWS = 4, MAX_FRAMES = 101 };

static int frame(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, const asp_render_desc *d, double *ms,
                 asp_error *err)
{
    double t0 = asp_time_now();
    int rc = asp_render_frame(gl, r, cam, d, err);
    *ms = (asp_time_now() - t0) * 1e3;
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_render_hybrid X.dps [frames=9] [size=256] [tolerance=0]\n");
        return 2;
    }
    int frames = argc > 2 ? atoi(argv[2]) : 9;
    uint32_t size = argc > 3 ? (uint32_t)atoi(argv[3]) : 256;
    float tolerance = argc > 4 ? (float)atof(argv[4]) : 0.0f;
    if (frames < 1 || frames > MAX_FRAMES || size < 16 || size > 4096) {
        fprintf(stderr, "frames 1..%d, size 16..4096\n", MAX_FRAMES);
        return 2;
    }
    asp_error err = {0, ""};
    asp_scene s = {0};
    asp_gl_context *gl = NULL;
    asp_renderer *prim = NULL, *hybrid = NULL;
    int rc = asp_scene_load(argv[1], NULL, NULL, &s, &err);
    if (!rc)
        rc = asp_scene_load_source(&s, &err);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, NULL, &gl, &err);
    asp_render_source src;
    if (!rc) {
        asp_scene_render_source(&s, &src);
        rc = asp_prim_renderer_create(gl, src.level, &(asp_prim_renderer_desc){.origin = {src.origin[0],
                                      src.origin[1], src.origin[2]}}, &prim, &err);
    }
    asp_hybrid_desc hd = {.origin = {src.origin[0], src.origin[1], src.origin[2]}};
    if (!rc)
        rc = asp_hybrid_renderer_create(gl, src.level, src.cloud, &hd, NULL, &hybrid, &err);
    if (!rc)
        rc = asp_renderer_set_lod(hybrid, tolerance, 0, &err);
    asp_hybrid_counts hc = {0};
    if (!rc)
        rc = asp_hybrid_renderer_counts(hybrid, &hc, &err);
    if (!rc)
        printf("%s: %zu primitives, %zu kept; %zu of %zu points drawn (%.1f%%); %ux%u, %d frames per view, "
               "point tolerance %g px, %s\n",
               argv[1], src.level->prim_count, hc.prims_kept, hc.points_drawn, hc.points_total,
               100.0 * (double)hc.points_drawn / (double)hc.points_total, size, size, frames, (double)tolerance,
               asp_gl_context_renderer(gl));
    asp_render_desc d = {.width = size, .height = size, .flags = ASP_RENDER_WAIT};
    double ratios[VIEWS];
    for (int v = 0; v < VIEWS && !rc; v++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = 90.0f * (float)v;
        cam.elevation = 20.0f;
        asp_camera_frame(&cam, &s.frame, s.origin, 1.0f, 0.0f);
        double tp[MAX_FRAMES], th[MAX_FRAMES], warm;
        rc = frame(gl, prim, &cam, &d, &warm, &err);
        if (!rc)
            rc = frame(gl, hybrid, &cam, &d, &warm, &err);
        for (int f = 0; f < frames && !rc; f++) {
            rc = frame(gl, prim, &cam, &d, &tp[f], &err);
            if (!rc)
                rc = frame(gl, hybrid, &cam, &d, &th[f], &err);
        }
        if (rc)
            break;
        double mp = bench_median(tp, frames), mh = bench_median(th, frames);
        ratios[v] = mh / mp;
        printf("view %3d: normalized %8.2f ms  hybrid %8.2f ms (%zu primitives + splats)  ratio %.2f\n",
               (int)cam.azimuth, mp, mh, asp_renderer_count(hybrid), ratios[v]);
    }
    if (!rc)
        printf("median ratio hybrid / normalized: %.2f\n", bench_median(ratios, VIEWS));
    else
        fprintf(stderr, "bench_render_hybrid: %s\n", err.msg);
    asp_renderer_destroy(prim);
    asp_renderer_destroy(hybrid);
    asp_gl_context_destroy(gl);
    asp_scene_release(&s);
    return rc ? 1 : 0;
}
