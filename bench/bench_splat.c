/*
 * Splat renderer benchmark (seed 001 Table 2 reports about 600,000 blended
 * splats/s on a GeForce4 Ti 4600): splats per second drawing a 1M-point
 * Fibonacci sphere (normals, colours, radii) with the blended splat renderer
 * (three passes), its opaque mode, the square renderer and, for reference, the
 * disc renderer, at 256x256 and 512x512 and screen tolerances 0 and 1 px;
 * median of several frames (asp_render_frame with glFinish: cut, upload and
 * drawing, no read-back). Timings never fail anything.
 * usage: bench_splat [points=1000000] [frames=5]
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/render.h"
#include "bench_common.h"

/* Median frame time of r at size x size, and the splats of the last frame. */
static int time_frames(asp_gl_context *gl, asp_renderer *r, uint32_t size, int frames, double *seconds,
                       size_t *count, double *select)
{
    asp_camera cam;
    bench_sphere_camera(&cam, 1.01f);
    asp_render_desc desc = {.width = size, .height = size, .flags = ASP_RENDER_WAIT};
    double t[64], sel[64];
    asp_error err;
    // one frame first: shader compilation and target allocation are not part of a frame
    if (asp_render_frame(gl, r, &cam, &desc, &err)) {
        fprintf(stderr, "bench_splat: %s\n", err.msg);
        return 1;
    }
    for (int f = 0; f < frames; f++) {
        cam.azimuth += 0.5f; // a slightly different view each frame, as when orbiting
        double t0 = asp_time_now();
        if (asp_render_frame(gl, r, &cam, &desc, &err)) {
            fprintf(stderr, "bench_splat: %s\n", err.msg);
            return 1;
        }
        t[f] = asp_time_now() - t0;
        asp_renderer_stats st;
        asp_renderer_stats_get(r, &st);
        sel[f] = st.select_seconds;
    }
    *seconds = bench_median(t, frames);
    *select = bench_median(sel, frames);
    *count = asp_renderer_count(r);
    return 0;
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 1000000;
    int frames = argc > 2 ? atoi(argv[2]) : 5;
    if (n == 0 || frames < 1 || frames > 64) {
        fprintf(stderr, "usage: bench_splat [points=1000000] [frames=5 (1..64)]\n");
        return 2;
    }
    asp_error err;
    asp_gl_context *gl = bench_gl_headless("bench_splat");
    if (!gl)
        return 1;
    asp_cloud *c = bench_fibonacci_sphere(n, "bench_splat");
    asp_hier *h = NULL;
    double t0 = asp_time_now();
    if (!c || asp_hier_build(c, NULL, NULL, &h, &err)) {
        fprintf(stderr, "bench_splat: %s\n", c ? err.msg : "no cloud");
        asp_cloud_destroy(c);
        asp_gl_context_destroy(gl);
        return 1;
    }
    double t_build = asp_time_now() - t0;
    printf("bench_splat: %zu points, %s (%s), median of %d frames (cut + upload + draw, glFinish)\n", n,
           asp_gl_context_renderer(gl), asp_gl_context_backend(gl), frames);
    printf("hierarchy build %.2f s (%zu nodes)\n", t_build, asp_hier_node_count(h));
    printf("%-14s %5s %4s %9s %9s %9s %12s\n", "renderer", "size", "tau", "splats", "frame ms", "cut ms",
           "splats/s");

    static const struct {
        const char *name;
        int kind; /* 0 splat blend, 1 splat opaque, 2 square, 3 disc */
    } kinds[] = {{"splat", 0}, {"splat-opaque", 1}, {"square", 2}, {"disc", 3}};
    static const uint32_t sizes[] = {256, 512};
    static const float taus[] = {0, 4};
    int status = 0;
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0] && !status; k++) {
        asp_renderer *r = NULL;
        double tc = asp_time_now();
        int rc;
        if (kinds[k].kind <= 1)
            rc = asp_splat_renderer_create_hier(
                gl, h, &(asp_splat_renderer_desc){.mode = kinds[k].kind ? ASP_SPLAT_OPAQUE : ASP_SPLAT_BLEND}, &r,
                &err);
        else if (kinds[k].kind == 2)
            rc = asp_square_renderer_create_hier(gl, h, NULL, &r, &err);
        else
            rc = asp_disc_renderer_create(gl, c, NULL, &r, &err);
        if (rc) {
            fprintf(stderr, "bench_splat: %s\n", err.msg);
            status = 1;
            break;
        }
        printf("%-14s upload %.2f s\n", kinds[k].name, asp_time_now() - tc);
        for (size_t s = 0; s < 2 && !status; s++)
            for (size_t t = 0; t < 2 && !status; t++) {
                if (kinds[k].kind == 3 && t > 0)
                    continue; // the disc renderer has no tolerance
                if (kinds[k].kind != 3)
                    asp_renderer_set_lod(r, taus[t], 0, NULL);
                double sec = 0, sel = 0;
                size_t count = 0;
                status = time_frames(gl, r, sizes[s], frames, &sec, &count, &sel);
                if (!status)
                    printf("%-14s %5u %4g %9zu %9.1f %9.1f %12.0f\n", kinds[k].name, sizes[s],
                           kinds[k].kind == 3 ? 0.0 : (double)taus[t], count, 1e3 * sec, 1e3 * sel,
                           (double)count / sec);
            }
        asp_renderer_destroy(r);
    }
    asp_hier_destroy(h);
    asp_cloud_destroy(c);
    asp_gl_context_destroy(gl);
    return status;
}
