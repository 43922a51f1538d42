/*
 * k-NN benchmark: our kd-tree (build + asp_knn_all) against FLANN's exact
 * single kd-tree (KDTreeSingleIndex through the C API) on the same points:
 * a uniform cube, a sphere surface and the Stanford bunny surface.
 * usage: bench_knn [points=1000000] [k=64] [threads=0] [runs=3]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/geom.h"

#ifdef ASP_HAVE_FLANN
#include <flann/flann.h>
#endif

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
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

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof(double), cmp_double);
    return t[n / 2];
}

enum { MAX_RUNS = 9 };

static void bench_set(const char *name, const float *p, size_t n, size_t k, int threads, int runs)
{
    asp_context ctx = {.threads = threads};
    asp_index *idx = malloc(n * k * sizeof(asp_index));
    float *d2 = malloc(n * k * sizeof(float));
    double tb[MAX_RUNS], tq[MAX_RUNS];
    asp_error err;
    for (int r = 0; r < runs; r++) {
        asp_kdtree *t = NULL;
        double t0 = asp_time_now();
        if (asp_kdtree_create(p, n, 12, &ctx, &t, &err)) {
            fprintf(stderr, "bench_knn: %s\n", err.msg);
            exit(1);
        }
        double t1 = asp_time_now();
        if (asp_knn_all(t, k, idx, d2, &ctx, &err)) {
            fprintf(stderr, "bench_knn: %s\n", err.msg);
            exit(1);
        }
        double t2 = asp_time_now();
        tb[r] = t1 - t0;
        tq[r] = t2 - t1;
        asp_kdtree_destroy(t);
    }
    double ob = median(tb, runs), oq = median(tq, runs);
    printf("%-8s %9zu %4zu | ours  build %7.3f s  knn_all %7.3f s  total %7.3f s", name, n, k, ob, oq, ob + oq);
#ifdef ASP_HAVE_FLANN
    struct FLANNParameters fp = DEFAULT_FLANN_PARAMETERS;
    fp.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    fp.leaf_max_size = 10;
    fp.checks = FLANN_CHECKS_UNLIMITED;
    fp.eps = 0.0f;
    fp.cores = threads > 0 ? threads : asp_context_threads(NULL);
    fp.log_level = FLANN_LOG_NONE;
    size_t kf = k + 1; /* FLANN returns the query point itself first */
    int *fi = malloc(n * kf * sizeof(int));
    float *fd = malloc(n * kf * sizeof(float));
    float *pm = malloc(n * 3 * sizeof(float));
    memcpy(pm, p, n * 3 * sizeof(float));
    for (int r = 0; r < runs; r++) {
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
    double fb = median(tb, runs), fq = median(tq, runs);
    /* agreement: the sorted distance lists must match (indices may differ on ties) */
    size_t bad = 0;
    for (size_t i = 0; i < n; i += 97)
        for (size_t j = 0; j < k; j++)
            if (fabsf(fd[i * kf + j + 1] - d2[i * k + j]) > 1e-6f * (1.0f + d2[i * k + j]))
                bad++;
    printf(" | flann build %7.3f s  query %7.3f s  total %7.3f s | mismatching rows %zu\n", fb, fq, fb + fq,
           bad);
    free(fi);
    free(fd);
    free(pm);
#else
    printf(" | flann: not built\n");
#endif
    fflush(stdout);
    free(idx);
    free(d2);
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? strtoull(argv[1], NULL, 10) : 1000000;
    size_t k = argc > 2 ? strtoull(argv[2], NULL, 10) : 64;
    int threads = argc > 3 ? atoi(argv[3]) : 0;
    int runs = argc > 4 ? atoi(argv[4]) : 3;
    if (runs < 1 || runs > MAX_RUNS || n < 2 || k < 1 || k >= n) {
        fprintf(stderr, "usage: bench_knn [points>=2] [1<=k<points] [threads] [runs 1..%d]\n", MAX_RUNS);
        return 2;
    }
    printf("bench_knn: %zu points, k = %zu, %d threads, median of %d runs\n", n, k, asp_context_threads(&(asp_context){.threads = threads}), runs);
    float *p = malloc(3 * n * sizeof(float));
    make_cube(p, n);
    bench_set("cube", p, n, k, threads, runs);
    make_sphere(p, n);
    bench_set("sphere", p, n, k, threads, runs);
    if (make_obj_surface(ASP_TEST_DATA "/stanford-bunny.obj", p, n))
        bench_set("bunny", p, n, k, threads, runs);
    else
        printf("bunny: %s not found, skipped\n", ASP_TEST_DATA "/stanford-bunny.obj");
    free(p);
    return 0;
}
