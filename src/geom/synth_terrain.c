/*
 * A synthetic terrain of any size streamed to disk (issue 28: test sets of
 * 10^9 points for the out-of-core hierarchy). Fractal value noise (sums of
 * octaves of smoothly interpolated lattice hashes) in a 4096^2 heightfield
 * plus a tiled detail texture, so close-ups show structure below the
 * heightfield's 49 cm spacing; points are drawn tile by tile, so the working
 * set does not grow with the point count.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/point_stream.h"
#include "amgsplat/sample.h"
#include "util/banned.h"

enum { MAP = 2048, DETAIL = 256, TILE_POINTS = 1 << 20 };
#define SIDE 1000.0      /* metres */
#define HEIGHT 180.0     /* metres, highest peak */
#define DETAIL_PERIOD 4.0 /* metres per detail tile */
#define DETAIL_AMP 0.25  /* metres */

static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double lattice(uint64_t seed, int64_t i, int64_t j)
{
    uint64_t h = mix64(seed ^ mix64((uint64_t)i * 0x632be59bd9b4e019ull + (uint64_t)j));
    return (double)(h >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
}

/* Value noise at (x, y) in lattice units; period > 0 wraps the lattice (tiling detail). */
static double value_noise(uint64_t seed, double x, double y, int64_t period)
{
    double fx = floor(x), fy = floor(y);
    int64_t i = (int64_t)fx, j = (int64_t)fy;
    double u = x - fx, v = y - fy;
    u = u * u * (3 - 2 * u);
    v = v * v * (3 - 2 * v);
    int64_t i1 = i + 1, j1 = j + 1;
    if (period > 0) {
        i = ((i % period) + period) % period, j = ((j % period) + period) % period;
        i1 = (i + 1) % period, j1 = (j + 1) % period;
    }
    double a = lattice(seed, i, j), b = lattice(seed, i1, j), c = lattice(seed, i, j1), d = lattice(seed, i1, j1);
    return (a + (b - a) * u) + ((c + (d - c) * u) - (a + (b - a) * u)) * v;
}

/* Fractal sum of octaves, about [-1, 1]; ridged octaves make mountain crests. */
static double fbm(uint64_t seed, double x, double y, int octaves, int64_t period)
{
    double sum = 0, amp = 0.5, norm = 0; // gain 0.45: rough but not a cliff at every texel
    for (int o = 0; o < octaves; o++) {
        double n = value_noise(seed + (uint64_t)o * 7919u, x, y, period);
        if (o >= 1 && o <= 3 && period == 0)
            n = 1.0 - 2.0 * fabs(n); // ridges
        sum += amp * n;
        norm += amp;
        amp *= 0.45;
        x *= 2.0, y *= 2.0;
        if (period > 0)
            period *= 2;
    }
    return sum / norm;
}

typedef struct terrain {
    float *height; /* MAP^2, metres */
    uint8_t *color; /* MAP^2 * 3 */
    float *detail; /* DETAIL^2, [-1, 1] */
} terrain;

static void ramp(double t, double slope, uint8_t out[3])
{
    static const double stops[][4] = {{0.00, 40, 90, 140},   {0.06, 194, 178, 128}, {0.10, 70, 130, 50},
                                      {0.40, 40, 95, 35},    {0.62, 120, 100, 70},  {0.80, 130, 125, 120},
                                      {0.90, 240, 240, 245}, {1.00, 255, 255, 255}};
    size_t k = 0;
    while (k + 2 < sizeof stops / sizeof stops[0] && t > stops[k + 1][0])
        k++;
    double f = (t - stops[k][0]) / (stops[k + 1][0] - stops[k][0]);
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    double rock = slope > 1.2 ? 1.0 : slope < 0.7 ? 0.0 : (slope - 0.7) / 0.5;
    for (int c = 0; c < 3; c++) {
        double v = stops[k][c + 1] + (stops[k + 1][c + 1] - stops[k][c + 1]) * f;
        v = v * (1 - rock) + (105.0 + 10.0 * c) * rock;
        out[c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
    }
}

static int terrain_make(terrain *t, uint64_t seed, int threads)
{
    t->height = malloc(sizeof(float) * MAP * MAP);
    t->color = malloc((size_t)3 * MAP * MAP);
    t->detail = malloc(sizeof(float) * DETAIL * DETAIL);
    if (!t->height || !t->color || !t->detail)
        return ASP_ENOMEM;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int j = 0; j < MAP; j++)
        for (int i = 0; i < MAP; i++) {
            double x = 6.0 * i / MAP, y = 6.0 * j / MAP; // six base features across
            double h = 0.5 + 0.5 * fbm(seed, x, y, 10, 0);
            h = h < 0 ? 0 : h;
            t->height[(size_t)j * MAP + i] = (float)(HEIGHT * pow(h, 1.7));
        }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int j = 0; j < MAP; j++)
        for (int i = 0; i < MAP; i++) {
            // slope over +-4 texels (about 4 m): rock shows on cliffs, not on the fine relief
            int i0 = i >= 4 ? i - 4 : 0, i1 = i + 4 < MAP ? i + 4 : MAP - 1, j0 = j >= 4 ? j - 4 : 0,
                j1 = j + 4 < MAP ? j + 4 : MAP - 1;
            double cell = SIDE / (MAP - 1);
            double gx = (t->height[(size_t)j * MAP + i1] - t->height[(size_t)j * MAP + i0]) / ((i1 - i0) * cell);
            double gy = (t->height[(size_t)j1 * MAP + i] - t->height[(size_t)j0 * MAP + i]) / ((j1 - j0) * cell);
            ramp(t->height[(size_t)j * MAP + i] / HEIGHT, sqrt(gx * gx + gy * gy), t->color + 3 * ((size_t)j * MAP + i));
        }
    for (int j = 0; j < DETAIL; j++)
        for (int i = 0; i < DETAIL; i++)
            t->detail[j * DETAIL + i] = (float)fbm(seed ^ 0xde7a11ull, 8.0 * i / DETAIL, 8.0 * j / DETAIL, 5, 8);
    return 0;
}

static void terrain_release(terrain *t)
{
    free(t->height);
    free(t->color);
    free(t->detail);
}

static double bilinear(const float *m, int size, double x, double y, int wrap)
{
    double fx = floor(x), fy = floor(y);
    int i = (int)fx, j = (int)fy, i1, j1;
    double u = x - fx, v = y - fy;
    if (wrap) {
        i = ((i % size) + size) % size, j = ((j % size) + size) % size;
        i1 = (i + 1) % size, j1 = (j + 1) % size;
    } else {
        i = i < 0 ? 0 : i >= size - 1 ? size - 2 : i;
        j = j < 0 ? 0 : j >= size - 1 ? size - 2 : j;
        u = x - i, v = y - j;
        u = u < 0 ? 0 : u > 1 ? 1 : u;
        v = v < 0 ? 0 : v > 1 ? 1 : v;
        i1 = i + 1, j1 = j + 1;
    }
    double a = m[(size_t)j * size + i], b = m[(size_t)j * size + i1], c = m[(size_t)j1 * size + i],
           d = m[(size_t)j1 * size + i1];
    return (a + (b - a) * u) + ((c + (d - c) * u) - (a + (b - a) * u)) * v;
}

/* Points [first, first + n) of tile (tx, ty) of a g x g grid. */
static void make_tile(const terrain *t, uint64_t seed, uint64_t first, size_t n, uint64_t tx, uint64_t ty, uint64_t g,
                      float *xyz, uint8_t *rgb)
{
    double side = SIDE / (double)g;
    for (size_t k = 0; k < n; k++) {
        uint64_t r = mix64(seed * 0x9e3779b97f4a7c15ull ^ mix64(first + k));
        double x = ((double)tx + (double)(r >> 40) / 16777216.0) * side;
        double y = ((double)ty + (double)((r >> 16) & 0xffffff) / 16777216.0) * side;
        double hx = x / SIDE * (MAP - 1), hy = y / SIDE * (MAP - 1);
        double d = bilinear(t->detail, DETAIL, x / DETAIL_PERIOD * DETAIL, y / DETAIL_PERIOD * DETAIL, 1);
        double z = bilinear(t->height, MAP, hx, hy, 0) + DETAIL_AMP * d;
        xyz[3 * k] = (float)x, xyz[3 * k + 1] = (float)y, xyz[3 * k + 2] = (float)z;
        size_t ci = 3 * ((size_t)(hy + 0.5) * MAP + (size_t)(hx + 0.5));
        double shade = 1.0 + 0.2 * d; // coherent in space: shading by the detail relief, no per-point noise
        for (int c = 0; c < 3; c++) {
            double v = t->color[ci + (size_t)c] * shade;
            rgb[3 * k + (size_t)c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
    }
}

int asp_synth_terrain_stream(const char *path, uint64_t points, uint64_t seed, const asp_context *ctx,
                             asp_error *err)
{
    ASP_ASSERT(path);
    if (points == 0)
        return asp_error_set(err, ASP_EINVAL, "terrain: expected at least 1 point");
    int threads = asp_context_threads(ctx);
    uint64_t g = (uint64_t)ceil(sqrt((double)points / TILE_POINTS));
    g = g < 1 ? 1 : g;
    uint64_t tiles = g * g;
    size_t most = (size_t)((points + tiles - 1) / tiles);
    terrain t = {0};
    float *xyz = malloc(sizeof(float) * 3 * most * (size_t)threads);
    uint8_t *rgb = malloc((size_t)3 * most * (size_t)threads);
    asp_point_writer *w = NULL;
    int rc = !xyz || !rgb ? ASP_ENOMEM : terrain_make(&t, seed, threads);
    if (rc)
        asp_error_set(err, rc, "out of memory for a terrain of %llu points", (unsigned long long)points);
    if (!rc)
        rc = asp_point_writer_open(path, points, 1, ctx, &w, err);
    for (uint64_t t0 = 0; !rc && t0 < tiles; t0 += (uint64_t)threads) {
        int batch = (int)(tiles - t0 < (uint64_t)threads ? tiles - t0 : (uint64_t)threads);
#pragma omp parallel for schedule(static, 1) num_threads(threads)
        for (int b = 0; b < batch; b++) {
            uint64_t tile = t0 + (uint64_t)b, first = tile * points / tiles, end = (tile + 1) * points / tiles;
            make_tile(&t, seed, first, (size_t)(end - first), tile % g, tile / g, g, xyz + 3 * most * (size_t)b,
                      rgb + 3 * most * (size_t)b);
        }
        for (int b = 0; b < batch && !rc; b++) {
            uint64_t tile = t0 + (uint64_t)b, first = tile * points / tiles, end = (tile + 1) * points / tiles;
            rc = asp_point_writer_write(w, xyz + 3 * most * (size_t)b, rgb + 3 * most * (size_t)b,
                                        (size_t)(end - first), err);
        }
        if (!rc && (rc = asp_progress(ctx, "synth", (double)(t0 + (uint64_t)batch) / (double)tiles)) != 0)
            asp_error_set(err, rc, "synth canceled");
    }
    if (w)
        rc = rc ? (asp_point_writer_abort(w), rc) : asp_point_writer_finish(w, err);
    terrain_release(&t);
    free(xyz);
    free(rgb);
    return rc;
}
