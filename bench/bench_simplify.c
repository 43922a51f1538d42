/*
 * Simplification benchmark: meshoptimizer's edge collapse (asp_mesh_simplify)
 * on the Stanford bunny to 10000, 1000 and 100 triangles, then writing the
 * result as OBJ and PLY (asp_mesh_save). Prints the triangles reached, the
 * error and the GPU bytes of each level; medians of several runs, never a
 * pass/fail (STYLE.md 11).
 */
#include <stdio.h>
#include <unistd.h>

#include "amgsplat/amgsplat.h"
#include "bench_common.h"

enum { RUNS = 3 };

int main(int argc, char **argv)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", argc > 1 ? argv[1] : ASP_TEST_DATA "/stanford-bunny.obj");
    if (access(path, R_OK) != 0) {
        printf("bench_simplify: %s not found; pass a mesh path\n", path);
        return 0;
    }
    asp_error err = {0};
    asp_mesh *mesh = NULL;
    if (asp_mesh_load(path, NULL, NULL, &mesh, &err)) {
        fprintf(stderr, "bench_simplify: %s\n", err.msg);
        return 1;
    }
    char dir[] = "/tmp/asp_bench_simplify_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("bench_simplify: mkdtemp");
        asp_mesh_destroy(mesh);
        return 1;
    }
    printf("%s: %zu triangles, %zu vertices, %zu GPU bytes\n", path, mesh->triangle_count, mesh->vertex_count,
           asp_mesh_gpu_bytes(mesh, NULL));
    printf("%8s %9s %9s %10s %10s %10s %10s\n", "target", "reached", "vertices", "error", "simplify_s", "obj_s",
           "ply_s");
    static const size_t targets[] = {10000, 1000, 100};
    for (size_t k = 0; k < sizeof targets / sizeof targets[0]; k++) {
        double ts[RUNS], to[RUNS], tp[RUNS];
        asp_mesh_simplify_stats st = {0};
        for (int r = 0; r < RUNS; r++) {
            asp_mesh *s = NULL;
            char obj[96], ply[96];
            snprintf(obj, sizeof obj, "%s/s.obj", dir);
            snprintf(ply, sizeof ply, "%s/s.ply", dir);
            double t0 = asp_time_now();
            int rc = asp_mesh_simplify(mesh, &(asp_mesh_simplify_desc){.target_triangles = targets[k]}, NULL, &s, &st,
                                       &err);
            double t1 = asp_time_now();
            rc = rc ? rc : asp_mesh_save(s, obj, NULL, &err);
            double t2 = asp_time_now();
            rc = rc ? rc : asp_mesh_save(s, ply, NULL, &err);
            double t3 = asp_time_now();
            asp_mesh_destroy(s);
            if (rc) {
                fprintf(stderr, "bench_simplify: %s\n", err.msg);
                asp_mesh_destroy(mesh);
                return 1;
            }
            ts[r] = t1 - t0, to[r] = t2 - t1, tp[r] = t3 - t2;
        }
        printf("%8zu %9zu %9zu %10.3g %10.4f %10.4f %10.4f\n", targets[k], st.output_triangles, st.output_vertices,
               st.error, bench_median_upper(ts, RUNS), bench_median_upper(to, RUNS), bench_median_upper(tp, RUNS));
    }
    static const char *const names[] = {"s.obj", "s.mtl", "s.ply"};
    for (size_t i = 0; i < 3; i++) {
        char f[96];
        snprintf(f, sizeof f, "%s/%s", dir, names[i]);
        remove(f);
    }
    rmdir(dir);
    asp_mesh_destroy(mesh);
    return 0;
}
