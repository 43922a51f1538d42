/*
 * PLY throughput: writes and reads a synthetic cloud (xyz float, normals,
 * rgb uchar, radius; 31-byte records) in binary little endian (5M points)
 * and ascii (smaller), and prints MB/s, the median of 5 runs. Timings never
 * fail anything (STYLE.md section 11). Usage: bench_ply [points] [dir]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "bench_common.h"

enum { RUNS = 5 };

static asp_cloud *synthetic(size_t n)
{
    asp_cloud *c = NULL;
    asp_error err;
    if (asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err)) {
        fprintf(stderr, "bench_ply: %s\n", err.msg);
        exit(1);
    }
    uint32_t s = 1;
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            s = s * 1664525u + 1013904223u;
            c->positions[3 * i + k] = (float)(s >> 8) / 16777216.0f;
            c->normals[3 * i + k] = k == 2 ? 1.0f : 0.0f;
            c->colors[4 * i + k] = (uint8_t)(s >> 24);
        }
        c->colors[4 * i + 3] = 255;
        c->radii[i] = 0.001f;
    }
    return c;
}

static void run(const char *label, asp_cloud *c, const char *path, asp_ply_encoding enc)
{
    double tw[RUNS], tr[RUNS];
    asp_error err;
    for (int r = 0; r < RUNS; r++) {
        double t0 = asp_time_now();
        if (asp_ply_write(c, path, &(asp_save_desc){.encoding = enc}, &err)) {
            fprintf(stderr, "bench_ply: %s\n", err.msg);
            exit(1);
        }
        double t1 = asp_time_now();
        asp_cloud *back = NULL;
        if (asp_ply_read(path, NULL, &back, &err)) {
            fprintf(stderr, "bench_ply: %s\n", err.msg);
            exit(1);
        }
        double t2 = asp_time_now();
        asp_cloud_destroy(back);
        tw[r] = t1 - t0;
        tr[r] = t2 - t1;
    }
    struct stat st;
    double mb = stat(path, &st) == 0 ? (double)st.st_size / 1e6 : 0.0;
    double w = bench_median_upper(tw, RUNS), rd = bench_median_upper(tr, RUNS);
    printf("%-22s %10zu %9.1f %9.3f %9.1f %9.3f %9.1f\n", label, c->count, mb, w, mb / w, rd, mb / rd);
    remove(path);
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 5000000;
    const char *dir = argc > 2 ? argv[2] : "/tmp";
    char path[512];
    snprintf(path, sizeof path, "%s/bench_ply_%ld.ply", dir, (long)getpid());
    printf("%-22s %10s %9s %9s %9s %9s %9s\n", "encoding", "points", "MB", "write s", "MB/s", "read s", "MB/s");
    asp_cloud *c = synthetic(n);
    run("binary_little_endian", c, path, ASP_PLY_BINARY_LE);
    run("binary_big_endian", c, path, ASP_PLY_BINARY_BE);
    asp_cloud_destroy(c);
    c = synthetic(n / 25 > 0 ? n / 25 : 1);
    run("ascii", c, path, ASP_PLY_ASCII);
    asp_cloud_destroy(c);
    return 0;
}
