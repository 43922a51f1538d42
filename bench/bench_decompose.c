/*
 * Benchmark of the AMG decomposition (journal 2, Table 1 "sd time"): samples
 * the bunny with N points (area method) and prints the median time of each
 * stage (neighbours, classifier, fans, assembly, AMG, basis of all levels) and
 * the peak memory. Usage: bench_decompose [N=1000000] [RUNS=3] [THREADS=0]
 * [STRONG=0 (default 0.9)] [CREASE_CUT=0 (default 0.25, -1 off)].
 */
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 1000000;
    int runs = argc > 2 ? atoi(argv[2]) : 3;
    asp_context ctx = {.threads = argc > 3 ? atoi(argv[3]) : 0};
    asp_amg_desc desc = {.strong_threshold = argc > 4 ? atof(argv[4]) : 0, .crease_cut = argc > 5 ? atof(argv[5]) : 0};
    if (runs < 1 || runs > 50)
        runs = 3;
    asp_error err;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    if (asp_mesh_load(ASP_TEST_DATA "/stanford-bunny.obj", NULL, &ctx, &mesh, &err) ||
        asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = n}, &ctx, &cloud, NULL, &err)) {
        fprintf(stderr, "bench_decompose: %s\n", err.msg);
        return 1;
    }
    asp_mesh_destroy(mesh);
    enum { STAGES = 7 };
    static const char *names[STAGES] = {"neighbours", "classifier", "fans", "assembly", "amg", "basis", "total"};
    double t[STAGES][50];
    size_t levels = 0, coarsest = 0;
    for (int r = 0; r < runs; r++) {
        asp_amg *amg = NULL;
        double t0 = asp_time_now();
        if (asp_amg_decompose(cloud, &desc, &ctx, &amg, &err)) {
            fprintf(stderr, "bench_decompose: %s\n", err.msg);
            return 1;
        }
        double t1 = asp_time_now();
        levels = asp_amg_level_count(amg);
        coarsest = asp_amg_level_size(amg, levels - 1);
        asp_amg_level_stats *st = calloc(levels, sizeof *st);
        if (!st || asp_amg_level_stats_all(amg, 0.05, &ctx, st, &err)) {
            fprintf(stderr, "bench_decompose: level statistics failed\n");
            return 1;
        }
        double t2 = asp_time_now();
        const asp_amg_info *in = asp_amg_get_info(amg);
        t[0][r] = in->t_neighbours;
        t[1][r] = in->t_classifier;
        t[2][r] = in->t_fans;
        t[3][r] = in->t_assembly;
        t[4][r] = in->t_amg;
        t[5][r] = t2 - t1;
        t[6][r] = t1 - t0;
        free(st);
        asp_amg_destroy(amg);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double load[3] = {0, 0, 0};
    FILE *fp = fopen("/proc/loadavg", "r");
    if (fp) {
        if (fscanf(fp, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3)
            load[0] = 0;
        fclose(fp);
    }
    printf("bench_decompose: bunny, %zu points, %d runs, %d threads, strength %g, crease cut %g, %zu levels (coarsest "
           "%zu unknowns), load average %.2f\n",
           cloud->count, runs, asp_context_threads(&ctx), desc.strong_threshold ? desc.strong_threshold : 0.9,
           desc.crease_cut ? desc.crease_cut : 0.25, levels, coarsest, load[0]);
    for (int s = 0; s < STAGES; s++)
        printf("  %-11s %8.3f s (median)\n", names[s], bench_median_upper(t[s], runs));
    printf("  peak memory %.0f MB (max RSS, includes sampling)\n", (double)ru.ru_maxrss / 1024.0);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
    return 0;
}
