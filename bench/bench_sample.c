/*
 * Sampling benchmark: load the Stanford bunny through assimp, area-sample it
 * to 1,000,000 points (placing vs. covering radii), vertex sampling, and the
 * voxel sampler of Schwarz 2004 3.1 at n = 512. Medians of several runs.
 */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "amgsplat/amgsplat.h"
#include "bench_common.h"

enum { RUNS = 3 };

static int run_method(const asp_mesh *mesh, asp_sample_desc desc, const char *label)
{
    double total[RUNS], sample[RUNS], radii[RUNS];
    size_t points = 0;
    double mean_r = 0;
    for (int r = 0; r < RUNS; r++) {
        asp_error err = {0};
        asp_cloud *c = NULL;
        asp_sample_stats st;
        double t0 = asp_time_now();
        if (asp_sample_mesh(mesh, &desc, NULL, &c, &st, &err)) {
            fprintf(stderr, "bench_sample: %s\n", err.msg);
            return 1;
        }
        total[r] = asp_time_now() - t0;
        sample[r] = st.sample_seconds;
        radii[r] = st.radii_seconds;
        points = st.points;
        mean_r = st.mean_radius;
        asp_cloud_destroy(c);
    }
    double t = bench_median_upper(total, RUNS);
    printf("%-22s %10zu %10.3f %10.3f %10.3f %12.2f %12.3g\n", label, points, bench_median_upper(sample, RUNS),
           bench_median_upper(radii, RUNS), t, (double)points / t / 1e6, mean_r);
    return 0;
}

int main(int argc, char **argv)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", argc > 1 ? argv[1] : ASP_TEST_DATA "/stanford-bunny.obj");
    if (access(path, R_OK) != 0) {
        printf("bench_sample: %s not found; pass a mesh path\n", path);
        return 0;
    }
    double load[RUNS];
    asp_mesh *mesh = NULL;
    for (int r = 0; r < RUNS; r++) {
        asp_error err = {0};
        asp_mesh_destroy(mesh);
        mesh = NULL;
        double t0 = asp_time_now();
        if (asp_mesh_load(path, NULL, NULL, &mesh, &err)) {
            fprintf(stderr, "bench_sample: %s\n", err.msg);
            return 1;
        }
        load[r] = asp_time_now() - t0;
    }
    printf("mesh %s: %zu vertices, %zu triangles, area %.6g; load (assimp + normals) %.3f s, median of %d, %d threads\n",
           path, mesh->vertex_count, mesh->triangle_count, asp_mesh_area(mesh), bench_median_upper(load, RUNS), RUNS,
           asp_context_threads(NULL));
    printf("%-22s %10s %10s %10s %10s %12s %12s\n", "method", "points", "sample s", "radii s", "total s", "Mpoints/s",
           "mean radius");
    int rc = run_method(mesh, (asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = 1000000}, "area 1M");
    rc |= run_method(mesh, (asp_sample_desc){.method = ASP_SAMPLE_VERTICES}, "vertices");
    rc |= run_method(mesh, (asp_sample_desc){.method = ASP_SAMPLE_VOXEL, .grid = 512}, "voxel n=512");
    rc |= run_method(mesh, (asp_sample_desc){.method = ASP_SAMPLE_VOXEL, .grid = 1024}, "voxel n=1024");
    asp_mesh_destroy(mesh);
    return rc;
}
