/*
 * Disc renderer benchmark: frame time of drawing a 1M-point Fibonacci sphere
 * (normals, colours, radii) at 256x256 and 512x512 on the headless context,
 * median of 10 frames each, drawing alone (glFinish) and with read-back into
 * an asp_image, plus the upload time. Timings never fail anything.
 * usage: bench_render [points=1000000] [frames=10] [samples=1]
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/render.h"
#include "bench_common.h"

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 1000000;
    int frames = argc > 2 ? atoi(argv[2]) : 10;
    uint32_t samples = argc > 3 ? (uint32_t)atoi(argv[3]) : 1;
    if (n == 0 || frames < 1 || frames > 1000) {
        fprintf(stderr, "usage: bench_render [points=1000000] [frames=10] [samples=1]\n");
        return 2;
    }
    asp_error err;
    asp_gl_context *gl = bench_gl_headless("bench_render");
    if (!gl)
        return 1;
    asp_cloud *cloud = bench_fibonacci_sphere(n, "bench_render");
    if (!cloud) {
        asp_gl_context_destroy(gl);
        return 1;
    }
    printf("bench_render: %zu points, %s (%s), %u sample%s, median of %d frames\n", n, asp_gl_context_renderer(gl),
           asp_gl_context_backend(gl), samples, samples == 1 ? "" : "s", frames);
    double t0 = asp_time_now();
    asp_renderer *r = NULL;
    if (asp_disc_renderer_create(gl, cloud, NULL, &r, &err)) {
        fprintf(stderr, "bench_render: %s\n", err.msg);
        asp_cloud_destroy(cloud);
        asp_gl_context_destroy(gl);
        return 1;
    }
    printf("  upload                 %8.1f ms\n", 1e3 * (asp_time_now() - t0));
    static const uint32_t sizes[] = {256, 512};
    double *t = malloc(sizeof *t * (size_t)frames);
    int status = 0;
    for (size_t s = 0; s < 2 && t && !status; s++) {
        asp_camera cam;
        bench_sphere_camera(&cam, 1.0f);
        asp_render_desc desc = {.width = sizes[s], .height = sizes[s], .samples = samples,
                                .background = {255, 255, 255, 255}, .flags = ASP_RENDER_WAIT};
        // one warm-up frame: shader compilation and target allocation happen on first use
        status = asp_render_frame(gl, r, &cam, &desc, &err);
        for (int f = 0; f < frames && !status; f++) {
            cam.azimuth += 360.0f / (float)frames;
            double a = asp_time_now();
            status = asp_render_frame(gl, r, &cam, &desc, &err);
            t[f] = asp_time_now() - a;
        }
        if (status)
            break;
        double draw = bench_median(t, frames);
        for (int f = 0; f < frames && !status; f++) {
            asp_image img = {0, 0, NULL};
            double a = asp_time_now();
            status = asp_render_to_image(gl, r, &cam, &desc, &img, &err);
            t[f] = asp_time_now() - a;
            asp_image_release(&img);
        }
        if (status)
            break;
        double full = bench_median(t, frames);
        printf("  %4ux%-4u draw         %8.1f ms   %7.1f M splats/s\n", sizes[s], sizes[s], 1e3 * draw,
               (double)n / draw * 1e-6);
        printf("  %4ux%-4u draw + read  %8.1f ms   %7.1f M splats/s\n", sizes[s], sizes[s], 1e3 * full,
               (double)n / full * 1e-6);
    }
    if (status)
        fprintf(stderr, "bench_render: %s\n", err.msg);
    free(t);
    asp_renderer_destroy(r);
    asp_cloud_destroy(cloud);
    asp_gl_context_destroy(gl);
    return status ? 1 : 0;
}
