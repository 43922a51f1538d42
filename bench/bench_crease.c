/*
 * Crease clip planes (docs/render-methods.md "Crease clipping"; Pauly et al.
 * 2003, Zwicker et al. 2004): the cost of asp_crease_clip_planes, one
 * k-nearest-neighbour pass plus a per-point clustering, on the synthetic
 * octahedron (sharp: about 18% of the points get a plane) and cube, scaled
 * to 1M points. Usage: bench_crease [points] [runs]. Prints medians; never
 * fails on timings.
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/geom.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

static void run(asp_synth_shape shape, const char *name, size_t n, int runs)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    if (asp_synth(shape, &(asp_synth_desc){.points = n}, NULL, &c, &err) != 0) {
        fprintf(stderr, "%s: %s\n", name, err.msg);
        return;
    }
    float *planes = malloc(8 * c->count * sizeof *planes);
    double t[16];
    size_t clipped = 0;
    for (int r = 0; planes && r < runs; r++) {
        double t0 = asp_time_now();
        if (asp_crease_clip_planes(c, NULL, NULL, planes, &clipped, &err) != 0) {
            fprintf(stderr, "%s: %s\n", name, err.msg);
            break;
        }
        t[r] = asp_time_now() - t0;
    }
    double med = bench_median_upper(t, runs);
    printf("%-11s %9zu points  %8zu clipped (%4.1f%%)  median %7.3f s  %6.2f M points/s\n", name, c->count,
           clipped, 100.0 * (double)clipped / (double)c->count, med, (double)c->count / med / 1e6);
    free(planes);
    asp_cloud_destroy(c);
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 1000000;
    int runs = argc > 2 ? atoi(argv[2]) : 3;
    if (runs < 1 || runs > 16)
        runs = 3;
    printf("asp_crease_clip_planes, defaults (60 degrees, k = 16), %d runs, %d threads\n", runs,
           asp_context_threads(NULL));
    run(ASP_SYNTH_OCTAHEDRON, "octahedron", 16000, runs);
    run(ASP_SYNTH_OCTAHEDRON, "octahedron", n, runs);
    run(ASP_SYNTH_CUBE, "cube", n, runs);
    run(ASP_SYNTH_SPHERE, "sphere", n, runs);
    return 0;
}
