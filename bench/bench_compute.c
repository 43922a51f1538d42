/*
 * The compute-shader point renderer against the raster ones (issue 28): a Fibonacci sphere of N
 * points (normals, colours, radii; generated in memory) at SIZE x SIZE, drawn by compute opaque,
 * compute blended, disc and splat (every input point: tolerance 0), median frame time of FRAMES
 * frames each (glFinish-synchronised, the camera turning), points/s and the ratios compute
 * opaque / disc and compute blended / splat. Prints GL_VENDOR, GL_RENDERER and which atomics the
 * compute renderer used. Timings never fail anything.
 * Beside the wall time, the process's CPU time per frame (all threads): on a machine shared by
 * other jobs llvmpipe's wall time measures the contention, its CPU time the renderer.
 * usage: bench_compute [points=1e6,1e7] [size=1024] [frames=5] [splat_max=1e7] [which=co,cb,disc,splat]
 *   points: comma-separated sizes; splat_max: the largest N the splat renderer is run at (its
 *   hierarchy build dominates beyond), 0 = never; which: the renderers to run.
 */
#include <epoxy/gl.h>
#include <stdio.h>
#include <sys/resource.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/render.h"
#include "bench_common.h"

enum { MAX_SIZES = 8, MAX_FRAMES = 100 };
enum { R_COMPUTE_OPAQUE, R_COMPUTE_BLEND, R_DISC, R_SPLAT, R_COUNT };
static const char *names[R_COUNT] = {"compute opaque", "compute blended", "disc", "splat"};
static const char *keys[R_COUNT] = {"co", "cb", "disc", "splat"};

/* CPU seconds of the process so far, every thread (llvmpipe's too). */
static double cpu_seconds(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec + (double)u.ru_stime.tv_sec +
           1e-6 * (double)u.ru_stime.tv_usec;
}

/* Whether key is an entry of the comma-separated list. */
static int listed(const char *list, const char *key)
{
    size_t n = strlen(key);
    for (const char *p = list; (p = strstr(p, key)) != NULL; p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0'))
            return 1;
    return 0;
}

static int make(asp_gl_context *gl, int which, const asp_cloud *cloud, asp_renderer **r, asp_error *err)
{
    if (which == R_DISC)
        return asp_disc_renderer_create(gl, cloud, NULL, r, err);
    if (which == R_SPLAT)
        return asp_splat_renderer_create(gl, cloud, NULL, NULL, r, err);
    const asp_renderer_kind *kind = NULL;
    int rc = asp_renderer_kind_find("compute", 0, &kind, err);
    if (rc)
        return rc;
    asp_render_source src = {.cloud = cloud};
    asp_renderer_options o;
    memset(&o, 0, sizeof o);
    o.splat.mode = which == R_COMPUTE_OPAQUE ? ASP_SPLAT_OPAQUE : ASP_SPLAT_BLEND;
    return kind->create(gl, &src, &o, NULL, r, err);
}

/* Median seconds per frame of r and the mean CPU seconds per frame (*cpu), or a negative value after printing the error. */
static double time_frames(asp_gl_context *gl, asp_renderer *r, uint32_t size, int frames, double *cpu)
{
    asp_error err;
    asp_camera cam;
    bench_sphere_camera(&cam, 1.0f);
    asp_render_desc desc = {.width = size, .height = size, .background = {255, 255, 255, 255},
                            .flags = ASP_RENDER_WAIT};
    double t[MAX_FRAMES];
    // one warm-up frame: shader compilation and target allocation happen on first use
    int rc = asp_render_frame(gl, r, &cam, &desc, &err);
    double c0 = cpu_seconds();
    for (int f = 0; f < frames && !rc; f++) {
        cam.azimuth += 360.0f / (float)frames;
        double a = asp_time_now();
        rc = asp_render_frame(gl, r, &cam, &desc, &err);
        t[f] = asp_time_now() - a;
    }
    if (rc) {
        fprintf(stderr, "bench_compute: %s\n", err.msg);
        return -1;
    }
    *cpu = (cpu_seconds() - c0) / frames;
    return bench_median(t, frames);
}

static int parse_sizes(const char *s, size_t *out, int *count)
{
    *count = 0;
    while (*s && *count < MAX_SIZES) {
        char *end;
        double v = strtod(s, &end);
        if (end == s || !(v >= 1) || v > 4e9)
            return 1;
        out[(*count)++] = (size_t)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return 1;
    }
    return *count == 0;
}

int main(int argc, char **argv)
{
    size_t sizes[MAX_SIZES];
    int nsizes = 0;
    uint32_t size = argc > 2 ? (uint32_t)atoi(argv[2]) : 1024;
    int frames = argc > 3 ? atoi(argv[3]) : 5;
    double splat_max = argc > 4 ? atof(argv[4]) : 1e7;
    const char *which = argc > 5 ? argv[5] : "co,cb,disc,splat";
    if (parse_sizes(argc > 1 ? argv[1] : "1e6,1e7", sizes, &nsizes) || size < 16 || size > 8192 || frames < 1 ||
        frames > MAX_FRAMES || argc > 6) {
        fprintf(stderr, "usage: bench_compute [points=1e6,1e7] [size=1024] [frames=5] [splat_max=1e7] "
                        "[which=co,cb,disc,splat]\n");
        return 2;
    }
    asp_gl_context *gl = bench_gl_headless("bench_compute");
    if (!gl)
        return 1;
    printf("bench_compute: GL_VENDOR %s | GL_RENDERER %s | GL_VERSION %s | %s\n", (const char *)glGetString(GL_VENDOR),
           (const char *)glGetString(GL_RENDERER), (const char *)glGetString(GL_VERSION), asp_gl_context_backend(gl));
    printf("bench_compute: %ux%u, median of %d frames (glFinish), Fibonacci sphere filling the view\n", size, size,
           frames);
    int status = 0;
    for (int s = 0; s < nsizes && !status; s++) {
        size_t n = sizes[s];
        double t0 = asp_time_now();
        asp_cloud *cloud = bench_fibonacci_sphere(n, "bench_compute");
        if (!cloud) {
            status = 1;
            break;
        }
        printf("%zu points (generated in %.1f s)\n", n, asp_time_now() - t0);
        double rate[R_COUNT] = {0};
        for (int w = 0; w < R_COUNT; w++) {
            if (!listed(which, keys[w]))
                continue;
            if (w == R_SPLAT && (double)n > splat_max) {
                printf("  %-16s skipped (N > splat_max %.3g: the hierarchy build dominates)\n", names[w], splat_max);
                continue;
            }
            asp_error err;
            asp_renderer *r = NULL;
            double c0 = asp_time_now();
            if (make(gl, w, cloud, &r, &err)) {
                fprintf(stderr, "bench_compute: %s: %s\n", names[w], err.msg);
                status = 1;
                break;
            }
            double create = asp_time_now() - c0;
            double cpu = 0;
            double t = time_frames(gl, r, size, frames, &cpu);
            const char *path = asp_compute_renderer_path(r);
            size_t drawn = asp_renderer_count(r);
            asp_renderer_destroy(r);
            if (t < 0) {
                status = 1;
                break;
            }
            rate[w] = (double)n / t;
            printf("  %-16s %9.2f ms  %9.2f M points/s  cpu %9.2f ms/frame  (%zu drawn, create %.1f s%s%s)\n",
                   names[w], 1e3 * t, rate[w] * 1e-6, 1e3 * cpu, drawn, create, path ? ", path " : "",
                   path ? path : "");
        }
        if (rate[R_DISC] > 0 && rate[R_COMPUTE_OPAQUE] > 0)
            printf("  ratio compute opaque / disc    %.2f\n", rate[R_COMPUTE_OPAQUE] / rate[R_DISC]);
        if (rate[R_SPLAT] > 0 && rate[R_COMPUTE_BLEND] > 0)
            printf("  ratio compute blended / splat  %.2f\n", rate[R_COMPUTE_BLEND] / rate[R_SPLAT]);
        fflush(stdout);
        asp_cloud_destroy(cloud);
    }
    asp_gl_context_destroy(gl);
    return status;
}
