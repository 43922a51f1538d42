/*
 * k-NN benchmark: our kd-tree (build + asp_knn_all) against FLANN's exact
 * single kd-tree (KDTreeSingleIndex through the C API) on the same points:
 * a uniform cube, a sphere surface and the Stanford bunny surface, printed as
 * one table (build, query, total seconds, each total relative to ours).
 * --per-query also times our per-query tree search (the fallback path of
 * asp_knn_all) and checks it gives the same bits; --group=N sets the group size.
 * usage: bench_knn [points=1000000] [k=64] [threads=0] [runs=3] [--no-flann]
 *        [--per-query] [--sets=cube,sphere,bunny] [--group=N]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "bench_common.h"
#include "geom/kdtree_internal.h"

#ifdef ASP_HAVE_FLANN
#include <flann/flann.h>
#endif

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    return bench_urand(&rng_state);
}

static void make_cube(float *p, size_t n)
{
    for (size_t i = 0; i < 3 * n; i++)
        p[i] = (float)urand();
}

static void make_sphere(float *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double z = 2 * urand() - 1, phi = 6.283185307179586 * urand(), r = sqrt(1 - z * z);
        p[3 * i] = (float)(r * cos(phi));
        p[3 * i + 1] = (float)(r * sin(phi));
        p[3 * i + 2] = (float)z;
    }
}

/* Area-uniform random points on the triangles of an OBJ file; returns 0 when it cannot be read. */
static int make_obj_surface(const char *path, float *p, size_t n)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return 0;
    size_t nv = 0, nf = 0, cv = 1024, cf = 1024;
    float *v = malloc(cv * 3 * sizeof(float));
    unsigned *f = malloc(cf * 3 * sizeof(unsigned));
    char line[512];
    while (fgets(line, sizeof line, fp)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (nv == cv)
                v = realloc(v, (cv *= 2) * 3 * sizeof(float));
            if (sscanf(line + 2, "%f %f %f", &v[3 * nv], &v[3 * nv + 1], &v[3 * nv + 2]) == 3)
                nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            unsigned a, b, c;
            if (sscanf(line + 2, "%u%*[^ ] %u%*[^ ] %u", &a, &b, &c) == 3 ||
                sscanf(line + 2, "%u %u %u", &a, &b, &c) == 3) {
                if (nf == cf)
                    f = realloc(f, (cf *= 2) * 3 * sizeof(unsigned));
                f[3 * nf] = a - 1, f[3 * nf + 1] = b - 1, f[3 * nf + 2] = c - 1;
                nf++;
            }
        }
    }
    fclose(fp);
    int ok = nv > 0 && nf > 0;
    double *cum = ok ? malloc(nf * sizeof(double)) : NULL;
    double total = 0;
    for (size_t t = 0; ok && t < nf; t++) {
        const float *a = v + 3 * f[3 * t], *b = v + 3 * f[3 * t + 1], *c = v + 3 * f[3 * t + 2];
        if (f[3 * t] >= nv || f[3 * t + 1] >= nv || f[3 * t + 2] >= nv) {
            ok = 0;
            break;
        }
        double e1[3], e2[3];
        for (int i = 0; i < 3; i++)
            e1[i] = b[i] - a[i], e2[i] = c[i] - a[i];
        double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
               cz = e1[0] * e2[1] - e1[1] * e2[0];
        total += 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
        cum[t] = total;
    }
    for (size_t i = 0; ok && i < n; i++) {
        double x = urand() * total;
        size_t lo = 0, hi = nf - 1;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (cum[mid] < x)
                lo = mid + 1;
            else
                hi = mid;
        }
        const float *a = v + 3 * f[3 * lo], *b = v + 3 * f[3 * lo + 1], *c = v + 3 * f[3 * lo + 2];
        double u = urand(), w = urand();
        if (u + w > 1)
            u = 1 - u, w = 1 - w;
        for (int j = 0; j < 3; j++)
            p[3 * i + j] = (float)(a[j] + u * (b[j] - a[j]) + w * (c[j] - a[j]));
    }
    free(cum);
    free(v);
    free(f);
    return ok;
}

enum { MAX_RUNS = 9 };

typedef struct bench_opts {
    size_t k, group;
    int threads, runs, flann, baseline;
} bench_opts;

/* Median build and knn_all times of our tree; tuning NULL is the library default (asp_knn_all). */
static void time_ours(const float *p, size_t n, const bench_opts *o, const asp__knn_tuning *tuning, asp_index *idx,
                      float *d2, double *build_s, double *query_s)
{
    asp_context ctx = {.threads = o->threads};
    double tb[MAX_RUNS], tq[MAX_RUNS];
    asp_error err;
    for (int r = 0; r < o->runs; r++) {
        asp_kdtree *t = NULL;
        double t0 = asp_time_now();
        if (asp_kdtree_create(p, n, 12, &ctx, &t, &err)) {
            fprintf(stderr, "bench_knn: %s\n", err.msg);
            exit(1);
        }
        double t1 = asp_time_now();
        int rc = tuning ? asp__knn_all_tuned(t, o->k, idx, d2, tuning, &ctx, &err)
                        : asp_knn_all(t, o->k, idx, d2, &ctx, &err);
        if (rc) {
            fprintf(stderr, "bench_knn: %s\n", err.msg);
            exit(1);
        }
        double t2 = asp_time_now();
        tb[r] = t1 - t0;
        tq[r] = t2 - t1;
        asp_kdtree_destroy(t);
    }
    *build_s = bench_median_upper(tb, o->runs);
    *query_s = bench_median_upper(tq, o->runs);
}

/* One table row; the last column is this row's total time over ours (2.00x: twice as slow as ours). */
static void print_row(const char *set, const char *impl, double b, double q, double ours_total, const char *note)
{
    printf("%-7s %-22s %8.3f %8.3f %8.3f %7.2fx  %s\n", set, impl, b, q, b + q,
           ours_total > 0 ? (b + q) / ours_total : 1.0, note);
}

static void bench_set(const char *name, const float *p, size_t n, const bench_opts *o)
{
    const size_t k = o->k;
    asp_index *idx = malloc(n * k * sizeof(asp_index));
    float *d2 = malloc(n * k * sizeof(float));
    double ob, oq;
    time_ours(p, n, o, o->group ? &(asp__knn_tuning){.group_max = o->group} : NULL, idx, d2, &ob, &oq);
    print_row(name, "ours", ob, oq, 0, "");
    if (o->baseline) {
        /* the per-query tree search alone: the previous algorithm, kept as the fallback path */
        asp_index *bi = malloc(n * k * sizeof(asp_index));
        float *bd = malloc(n * k * sizeof(float));
        double bb, bq;
        time_ours(p, n, o, &(asp__knn_tuning){.tree_only = 1}, bi, bd, &bb, &bq);
        int same = memcmp(bi, idx, n * k * sizeof(asp_index)) == 0 && memcmp(bd, d2, n * k * sizeof(float)) == 0;
        print_row(name, "ours, per-query search", bb, bq, ob + oq, same ? "identical output" : "OUTPUT DIFFERS");
        free(bi);
        free(bd);
    }
#ifdef ASP_HAVE_FLANN
    if (o->flann) {
        double tb[MAX_RUNS], tq[MAX_RUNS];
        struct FLANNParameters fp = DEFAULT_FLANN_PARAMETERS;
        fp.algorithm = FLANN_INDEX_KDTREE_SINGLE;
        fp.leaf_max_size = 10;
        fp.checks = FLANN_CHECKS_UNLIMITED;
        fp.eps = 0.0f;
        fp.cores = asp_context_threads(&(asp_context){.threads = o->threads});
        fp.log_level = FLANN_LOG_NONE;
        size_t kf = k + 1; /* FLANN returns the query point itself first */
        int *fi = malloc(n * kf * sizeof(int));
        float *fd = malloc(n * kf * sizeof(float));
        float *pm = malloc(n * 3 * sizeof(float));
        memcpy(pm, p, n * 3 * sizeof(float));
        for (int r = 0; r < o->runs; r++) {
            float speedup = 0;
            double t0 = asp_time_now();
            flann_index_t fx = flann_build_index(pm, (int)n, 3, &speedup, &fp);
            double t1 = asp_time_now();
            flann_find_nearest_neighbors_index(fx, pm, (int)n, fi, fd, (int)kf, &fp);
            double t2 = asp_time_now();
            tb[r] = t1 - t0;
            tq[r] = t2 - t1;
            flann_free_index(fx, &fp);
        }
        double fb = bench_median_upper(tb, o->runs), fq = bench_median_upper(tq, o->runs);
        /* agreement: the sorted distance lists must match (indices may differ on ties) */
        size_t bad = 0;
        for (size_t i = 0; i < n; i += 97)
            for (size_t j = 0; j < k; j++)
                if (fabsf(fd[i * kf + j + 1] - d2[i * k + j]) > 1e-6f * (1.0f + d2[i * k + j]))
                    bad++;
        char note[64];
        snprintf(note, sizeof note, "%zu sampled distances differ from ours", bad);
        print_row(name, "FLANN kdtree_single", fb, fq, ob + oq, note);
        free(fi);
        free(fd);
        free(pm);
    }
#endif
    fflush(stdout);
    free(idx);
    free(d2);
}

int main(int argc, char **argv)
{
    bench_opts o = {64, 0, 0, 3, 1, 0};
    size_t n = 1000000;
    const char *sets = "cube,sphere,bunny";
    int pos = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--no-flann") == 0)
            o.flann = 0;
        else if (strcmp(argv[i], "--per-query") == 0)
            o.baseline = 1;
        else if (strncmp(argv[i], "--group=", 8) == 0)
            o.group = strtoull(argv[i] + 8, NULL, 10);
        else if (strncmp(argv[i], "--sets=", 7) == 0)
            sets = argv[i] + 7;
        else if (pos == 0 && ++pos)
            n = strtoull(argv[i], NULL, 10);
        else if (pos == 1 && ++pos)
            o.k = strtoull(argv[i], NULL, 10);
        else if (pos == 2 && ++pos)
            o.threads = atoi(argv[i]);
        else if (pos == 3 && ++pos)
            o.runs = atoi(argv[i]);
        else
            o.runs = 0;
    }
    if (o.runs < 1 || o.runs > MAX_RUNS || n < 2 || o.k < 1 || o.k >= n) {
        fprintf(stderr,
                "usage: bench_knn [points>=2] [1<=k<points] [threads] [runs 1..%d] [--no-flann] [--per-query] "
                "[--sets=cube,sphere,bunny] [--group=N]\n",
                MAX_RUNS);
        return 2;
    }
    printf("bench_knn: %zu points, k = %zu, %d threads, median of %d runs; seconds; 'x ours' = row total / our "
           "total\n",
           n, o.k, asp_context_threads(&(asp_context){.threads = o.threads}), o.runs);
#ifndef ASP_HAVE_FLANN
    printf("FLANN: not found at build time, comparison skipped\n");
#endif
    printf("%-7s %-22s %8s %8s %8s %8s\n", "set", "implementation", "build", "query", "total", "x ours");
    float *p = malloc(3 * n * sizeof(float));
    if (strstr(sets, "cube")) {
        make_cube(p, n);
        bench_set("cube", p, n, &o);
    }
    if (strstr(sets, "sphere")) {
        make_sphere(p, n);
        bench_set("sphere", p, n, &o);
    }
    if (strstr(sets, "bunny")) {
        if (make_obj_surface(ASP_TEST_DATA "/stanford-bunny.obj", p, n))
            bench_set("bunny", p, n, &o);
        else
            printf("bunny: %s not found, skipped\n", ASP_TEST_DATA "/stanford-bunny.obj");
    }
    free(p);
    return 0;
}
