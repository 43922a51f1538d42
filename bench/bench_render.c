/*
 * Disc renderer benchmark: frame time of drawing a 1M-point Fibonacci sphere
 * (normals, colours, radii) at 256x256 and 512x512 on the headless context,
 * median of 10 frames each, drawing alone (glFinish) and with read-back into
 * an asp_image, plus the upload time. Timings never fail anything.
 * usage: bench_render [points=1000000] [frames=10] [samples=1]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/render.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static asp_cloud *make_sphere(size_t n)
{
    asp_cloud *c = NULL;
    asp_error err;
    if (asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err)) {
        fprintf(stderr, "bench_render: %s\n", err.msg);
        return NULL;
    }
    float r = (float)sqrt(4.0 * 3.14159265358979323846 / (double)n);
    for (size_t i = 0; i < n; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / (double)n, rho = sqrt(1.0 - y * y), phi = (double)i * 2.399963229728653;
        float nrm[3] = {(float)(rho * cos(phi)), (float)y, (float)(rho * sin(phi))};
        for (int k = 0; k < 3; k++) {
            c->positions[3 * i + k] = nrm[k];
            c->normals[3 * i + k] = nrm[k];
            c->colors[4 * i + k] = (uint8_t)(127.5f + 127.5f * nrm[k]);
        }
        c->colors[4 * i + 3] = 255;
        c->radii[i] = r;
    }
    return c;
}

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
    asp_gl_context *gl = NULL;
    if (asp_gl_context_create_headless(NULL, &gl, &err)) {
        fprintf(stderr, "bench_render: %s\n", err.msg);
        return 1;
    }
    asp_cloud *cloud = make_sphere(n);
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
        asp_camera_init(&cam);
        cam.azimuth = 30.0f;
        cam.elevation = 20.0f;
        const float center[3] = {0, 0, 0};
        asp_camera_fit(&cam, center, 1.0f, 1.0f);
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
        double draw = median(t, frames);
        for (int f = 0; f < frames && !status; f++) {
            asp_image img = {0, 0, NULL};
            double a = asp_time_now();
            status = asp_render_to_image(gl, r, &cam, &desc, &img, &err);
            t[f] = asp_time_now() - a;
            asp_image_release(&img);
        }
        if (status)
            break;
        double full = median(t, frames);
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
