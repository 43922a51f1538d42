/*
 * Benchmark of domain-primitive construction (thesis Tables 5.2 and 5.4):
 * samples the bunny with N points, decomposes it once, then prints the median
 * whole-build time (basis, planes, textures, atlas, .dps file) at the level
 * nearest TARGET primitives for every texture method, and the Table 5.2
 * columns of levels L-6 .. L. Usage: bench_prim [N=35000] [TARGET=400] [RUNS=3] [THREADS=0].
 */
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

/* Whole build of one level and its file; returns seconds, or -1. */
static double build_once(const asp_amg *amg, const asp_cloud *cloud, size_t level, const asp_prim_desc *d,
                         const asp_context *ctx, asp_dps_summary *row)
{
    asp_error err;
    asp_dps *dps = NULL;
    double t0 = asp_time_now();
    if (asp_prim_build(amg, cloud, &level, 1, d, "bunny", ctx, &dps, &err) ||
        asp_dps_save(dps, "/tmp/bench_prim.dps", &err)) {
        fprintf(stderr, "bench_prim: %s\n", err.msg);
        asp_dps_destroy(dps);
        return -1;
    }
    double t = asp_time_now() - t0;
    asp_dps_summarize(dps, row, 1);
    asp_dps_destroy(dps);
    return t;
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 35000;
    size_t target = argc > 2 ? (size_t)atof(argv[2]) : 400;
    int runs = argc > 3 ? atoi(argv[3]) : 3;
    asp_context ctx = {.threads = argc > 4 ? atoi(argv[4]) : 0};
    if (runs < 1 || runs > 50)
        runs = 3;
    asp_error err;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    if (asp_mesh_load(ASP_TEST_DATA "/stanford-bunny.obj", NULL, &ctx, &mesh, &err) ||
        asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = n}, &ctx, &cloud, NULL, &err)) {
        fprintf(stderr, "bench_prim: %s\n", err.msg);
        return 1;
    }
    double t0 = asp_time_now();
    if (asp_amg_decompose(cloud, NULL, &ctx, &amg, &err)) {
        fprintf(stderr, "bench_prim: %s\n", err.msg);
        return 1;
    }
    double t_dec = asp_time_now() - t0;
    size_t nl = asp_amg_level_count(amg), level = 0, best = SIZE_MAX;
    for (size_t l = 0; l < nl; l++) {
        size_t s = asp_amg_level_size(amg, l), dist = s > target ? s - target : target - s;
        if (dist < best)
            best = dist, level = l;
    }
    printf("bunny, %zu points, decomposition %.2f s, %zu levels; level L-%zu has %zu basis functions (nearest %zu)\n",
           cloud->count, t_dec, nl, nl - 1 - level, asp_amg_level_size(amg, level), target);
    struct {
        const char *name;
        asp_prim_desc d;
    } methods[] = {
        {"affine", {.method = ASP_PRIM_AFFINE}},
        {"radial constant", {.method = ASP_PRIM_RADIAL, .shape = ASP_PRIM_CONSTANT}},
        {"radial linear", {.method = ASP_PRIM_RADIAL, .shape = ASP_PRIM_LINEAR}},
        {"radial gaussian w=2", {.method = ASP_PRIM_RADIAL, .shape = ASP_PRIM_GAUSSIAN, .width = 2}},
        {"affine + normal map", {.method = ASP_PRIM_AFFINE, .normal_map = 1}},
        {"affine, texel 0.5", {.method = ASP_PRIM_AFFINE, .texel_size = 0.5}},
        {"affine, texel 2", {.method = ASP_PRIM_AFFINE, .texel_size = 2}},
    };
    printf("\n| method | primitives | texels | cb (s) | dpc (s) | whole build (s, median of %d) |\n|---|---|---|---|---|---|\n",
           runs);
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; m++) {
        double t[50];
        asp_dps_summary row;
        for (int r = 0; r < runs; r++)
            if ((t[r] = build_once(amg, cloud, level, &methods[m].d, &ctx, &row)) < 0)
                return 1;
        printf("| %s | %zu | %llu | %.3f | %.3f | %.3f |\n", methods[m].name, row.primitives,
               (unsigned long long)row.texels, row.t_basis, row.t_construct, bench_median_upper(t, runs));
    }
    printf("\n| level | primitives | texels | error | normalised | cb (s) | dpc (s) |\n|---|---|---|---|---|---|---|\n");
    for (size_t l = nl >= 7 ? nl - 7 : 0; l < nl; l++) {
        asp_dps_summary row;
        if (build_once(amg, cloud, l, NULL, &ctx, &row) < 0)
            return 1;
        printf("| %s | %zu | %llu | %.6g | %.3f | %.3f | %.3f |\n", row.name, row.primitives,
               (unsigned long long)row.texels, row.error, row.error_norm, row.t_basis, row.t_construct);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("\npeak memory %.0f MB\n", (double)ru.ru_maxrss / 1024.0);
    remove("/tmp/bench_prim.dps");
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    asp_amg_shutdown();
    return 0;
}
