/*
 * Billboard-cloud plane search (issue 30; Decoret et al. 2003 section 4): the
 * greedy search over the discretised plane space on the Stanford bunny (69,451
 * triangles, the size of the thesis's madcat row: 59,855 triangles at 6%, 171
 * planes, 529 s in 2003) at error bounds of 2, 4, 6 and 8% of the diagonal, on
 * one thread and on all; then the whole build (textures and atlas) at 6%.
 * Prints planes, fallbacks and median seconds of RUNS runs, wall-clock and
 * process CPU (clock(): on a shared, loaded machine the CPU seconds of the
 * one-thread runs are the figure that compares); never a pass/fail (STYLE.md 11).
 */
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "amgsplat/amgsplat.h"
#include "bench_common.h"

enum { RUNS = 3 };

int main(int argc, char **argv)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", argc > 1 ? argv[1] : ASP_TEST_DATA "/stanford-bunny.obj");
    if (access(path, R_OK) != 0) {
        printf("bench_billboard: %s not found; pass a mesh path\n", path);
        return 0;
    }
    asp_error err = {0};
    asp_mesh *mesh = NULL;
    if (asp_mesh_load(path, NULL, NULL, &mesh, &err)) {
        fprintf(stderr, "bench_billboard: %s\n", err.msg);
        return 1;
    }
    uint32_t *assign = malloc(mesh->triangle_count * sizeof *assign);
    if (!assign) {
        asp_mesh_destroy(mesh);
        return 1;
    }
    printf("%s: %zu triangles\n", path, mesh->triangle_count);
    printf("%7s %8s %7s %10s %12s %10s %12s\n", "error", "threads", "planes", "fallbacks", "search_s", "cpu_s",
           "speedup");
    static const double bounds[] = {0.02, 0.04, 0.06, 0.08};
    for (size_t b = 0; b < sizeof bounds / sizeof bounds[0]; b++) {
        double one = 0;
        for (int threads = 1; threads >= 0; threads--) { /* 1, then 0 = all */
            asp_context ctx = {0};
            ctx.threads = threads;
            double t[RUNS], cpu[RUNS];
            asp_billboard_stats st = {0};
            for (int r = 0; r < RUNS; r++) {
                asp_billboard_plane *planes = NULL;
                size_t np = 0;
                clock_t c0 = clock();
                double t0 = asp_time_now();
                if (asp_billboard_search_mesh(mesh, &(asp_billboard_desc){.error = bounds[b]}, &ctx, &planes, &np,
                                              assign, &st, &err)) {
                    fprintf(stderr, "bench_billboard: %s\n", err.msg);
                    free(assign);
                    asp_mesh_destroy(mesh);
                    return 1;
                }
                t[r] = asp_time_now() - t0;
                cpu[r] = (double)(clock() - c0) / CLOCKS_PER_SEC;
                asp_free(&ctx, planes);
            }
            double med = bench_median(t, RUNS);
            if (threads == 1)
                one = med;
            printf("%6.0f%% %8s %7zu %10zu %12.3f %10.3f %11.2fx\n", 100 * bounds[b], threads ? "1" : "all",
                   st.planes, st.fallbacks, med, bench_median(cpu, RUNS), one / med);
        }
    }
    double t[RUNS];
    asp_billboard_stats st = {0};
    for (int r = 0; r < RUNS; r++) {
        asp_dps *dps = NULL;
        double t0 = asp_time_now();
        if (asp_billboard_mesh(mesh, &(asp_billboard_desc){.error = 0.06}, path, NULL, &dps, &st, &err)) {
            fprintf(stderr, "bench_billboard: %s\n", err.msg);
            break;
        }
        t[r] = asp_time_now() - t0;
        asp_dps_destroy(dps);
    }
    printf("build at 6%%, all threads: %zu planes, %llu texels, median %.3f s (search %.3f s, textures %.3f s)\n",
           st.planes, (unsigned long long)st.texels, bench_median(t, RUNS), st.t_search, st.t_texture);
    free(assign);
    asp_mesh_destroy(mesh);
    return 0;
}
