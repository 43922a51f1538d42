/*
 * GPU texture construction against the CPU (thesis 3.6, issue 17): samples
 * the bunny with N points, decomposes it once, and prints for the affine and
 * the radial method the median construction time (dpc: planes, textures,
 * atlas, neighbours) of the level nearest TARGET primitives built on the CPU
 * (THREADS threads) and with asp_prim_gpu_fill_set, their ratio, and the largest
 * per-texel difference of the atlases. Timings never decide pass or fail.
 * Usage: bench_texture_gpu [N=100000] [TARGET=400] [RUNS=5] [THREADS=0].
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

#if defined(ASP_HAVE_GL)
/* Median dpc over runs builds; *out keeps the last build. */
static double median_dpc(const asp_amg *amg, size_t level, const asp_prim_desc *d, const asp_context *ctx, int runs,
                         asp_dps **out)
{
    double t[50];
    for (int i = 0; i < runs; i++) {
        asp_error err;
        asp_dps *dps = NULL;
        if (asp_prim_build(amg, NULL, &level, 1, d, "bunny", ctx, &dps, &err)) {
            fprintf(stderr, "bench_texture_gpu: %s\n", err.msg);
            return -1;
        }
        t[i] = dps->levels[0].t_construct;
        asp_dps_destroy(*out);
        *out = dps;
    }
    return bench_median(t, runs);
}

static int max_diff(const asp_dps *a, const asp_dps *b)
{
    const asp_image *x = &a->levels[0].atlas, *y = &b->levels[0].atlas;
    if (x->width != y->width || x->height != y->height)
        return 256;
    int m = 0;
    for (size_t k = 0; k < 4 * (size_t)x->width * x->height; k++) {
        int d = abs((int)x->pixels[k] - (int)y->pixels[k]);
        m = d > m ? d : m;
    }
    return m;
}
#endif

int main(int argc, char **argv)
{
#if !defined(ASP_HAVE_GL)
    (void)argc, (void)argv;
    fprintf(stderr, "bench_texture_gpu: this build has no OpenGL (ASP_WITH_GL=OFF)\n");
    return 0;
#else
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 100000;
    size_t target = argc > 2 ? (size_t)atof(argv[2]) : 400;
    int runs = argc > 3 ? atoi(argv[3]) : 5;
    asp_context ctx = {.threads = argc > 4 ? atoi(argv[4]) : 0};
    if (runs < 1 || runs > 50)
        runs = 5;
    asp_error err;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    asp_gl_context *gl = NULL;
    if (asp_mesh_load(ASP_TEST_DATA "/stanford-bunny.obj", NULL, &ctx, &mesh, &err) ||
        asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = n}, &ctx, &cloud, NULL, &err) ||
        asp_amg_decompose(cloud, NULL, &ctx, &amg, &err) || asp_gl_context_create_headless(NULL, &ctx, &gl, &err)) {
        fprintf(stderr, "bench_texture_gpu: %s\n", err.msg);
        return 1;
    }
    size_t nl = asp_amg_level_count(amg), level = 0, best = SIZE_MAX;
    for (size_t l = 0; l < nl; l++) {
        size_t s = asp_amg_level_size(amg, l), dist = s > target ? s - target : target - s;
        if (dist < best)
            best = dist, level = l;
    }
    printf("bunny, %zu points, level L-%zu (%zu basis functions), GL: %s, CPU threads %d\n", cloud->count,
           nl - 1 - level, asp_amg_level_size(amg, level), asp_gl_context_renderer(gl), asp_context_threads(&ctx));
    printf("\n| method | texels | CPU dpc (s) | GPU dpc (s) | GPU / CPU | max texel diff (of 255) |\n"
           "|---|---|---|---|---|---|\n");
    static const struct {
        const char *name;
        asp_prim_method method;
    } methods[] = {{"affine", ASP_PRIM_AFFINE}, {"radial linear", ASP_PRIM_RADIAL}};
    for (size_t m = 0; m < 2; m++) {
        asp_prim_desc cpu = {.method = methods[m].method}, gpu = cpu;
        asp_prim_gpu_fill_set(&gpu, gl);
        asp_dps *a = NULL, *b = NULL;
        double tc = median_dpc(amg, level, &cpu, &ctx, runs, &a), tg = median_dpc(amg, level, &gpu, &ctx, runs, &b);
        if (a && b)
            printf("| %s | %llu | %.3f | %.3f | %.2f | %d |\n", methods[m].name,
                   (unsigned long long)a->levels[0].texels, tc, tg, tg / tc, max_diff(a, b));
        asp_dps_destroy(a);
        asp_dps_destroy(b);
    }
    asp_gl_context_destroy(gl);
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    asp_amg_shutdown();
    return 0;
#endif
}
