/*
 * Helpers the benchmarks share: medians of run times, a seeded uniform random
 * number, and the Fibonacci-sphere cloud, headless context and camera that
 * bench_render and bench_splat draw with. Header only (static inline), so each
 * bench stays one .c file; the name does not match CMake's bench/bench_*.c glob.
 */
#ifndef BENCH_COMMON_H
#define BENCH_COMMON_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/render.h"

static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v[0..n) and returns its median, the mean of the two middle values when n is even. */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/*
 * Sorts v[0..n) and returns v[n / 2]: the median for odd n, the upper middle value for even n.
 * The benches that quoted their figures with this one keep it, so new runs compare with the old.
 */
static inline double bench_median_upper(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return v[n / 2];
}

/* Uniform in [0, 1) from a xorshift64 state (nonzero), 53 random bits; each bench keeps its own seed. */
static inline double bench_urand(uint64_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    return (double)(*state >> 11) / 9007199254740992.0;
}

/*
 * n points on the unit sphere along a Fibonacci spiral, with normals, colours (the normal mapped to
 * 0..255) and radii sized so the discs cover the sphere; NULL after printing "prog: message" on failure.
 */
static inline asp_cloud *bench_fibonacci_sphere(size_t n, const char *prog)
{
    asp_cloud *c = NULL;
    asp_error err;
    if (asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err)) {
        fprintf(stderr, "%s: %s\n", prog, err.msg);
        return NULL;
    }
    float r = (float)sqrt(4.0 * 3.14159265358979323846 / (double)n);
    for (size_t i = 0; i < n; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / (double)n, rho = sqrt(1.0 - y * y), phi = (double)i * 2.399963229728653;
        float nrm[3] = {(float)(rho * cos(phi)), (float)y, (float)(rho * sin(phi))};
        for (int k = 0; k < 3; k++) {
            c->positions[3 * i + k] = nrm[k];
            c->normals[3 * i + k] = nrm[k];
            c->colors[4 * i + k] = (uint8_t)(127.5f + 127.5f * nrm[k]);
        }
        c->colors[4 * i + 3] = 255;
        c->radii[i] = r;
    }
    return c;
}

/* The headless GL context; NULL after printing "prog: message" on failure. */
static inline asp_gl_context *bench_gl_headless(const char *prog)
{
    asp_gl_context *gl = NULL;
    asp_error err;
    if (asp_gl_context_create_headless(NULL, NULL, &gl, &err)) {
        fprintf(stderr, "%s: %s\n", prog, err.msg);
        return NULL;
    }
    return gl;
}

/* A square view from azimuth 30, elevation 20 (degrees) of the sphere of the given radius about the origin. */
static inline void bench_sphere_camera(asp_camera *cam, float radius)
{
    asp_camera_init(cam);
    cam->azimuth = 30.0f;
    cam->elevation = 20.0f;
    const float center[3] = {0, 0, 0};
    asp_camera_fit(cam, center, radius, 1.0f);
}

#endif
