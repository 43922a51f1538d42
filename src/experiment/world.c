/*
 * The navigation worlds of seed 004 2.3: a rocky terrain with a smooth path
 * (low-speed test) and a winding canyon (high-speed test), generated from a
 * seed as height-field meshes with vertex colours, and the path's centre
 * polyline the grading of 2.4 compares directions with.
 */
#include <math.h>
#include <string.h>

#include "experiment/internal.h"
#include "util/banned.h"

/* value noise on an integer lattice, hashed from the seed: same field on every machine */
static float lattice(uint64_t seed, int32_t i, int32_t j)
{
    uint64_t s = asp__exp_stream(seed, (uint64_t)(uint32_t)i, (uint64_t)(uint32_t)j);
    return (float)(asp__exp_next(&s) >> 40) * (1.0f / 16777216.0f) * 2.0f - 1.0f;
}

static float smooth01(float t)
{
    return t * t * (3.0f - 2.0f * t);
}

static float value_noise(uint64_t seed, float x, float z)
{
    float fx = floorf(x), fz = floorf(z);
    int32_t i = (int32_t)fx, j = (int32_t)fz;
    float u = smooth01(x - fx), v = smooth01(z - fz);
    float a = lattice(seed, i, j), b = lattice(seed, i + 1, j);
    float c = lattice(seed, i, j + 1), d = lattice(seed, i + 1, j + 1);
    return (a + (b - a) * u) * (1.0f - v) + (c + (d - c) * u) * v;
}

/* fractal sum of octaves (gain 1/2, lacunarity 2): rough at every scale, as rock is; about -1..1 */
static float fbm(uint64_t seed, float x, float z, int octaves)
{
    float sum = 0.0f, amp = 0.5f;
    for (int o = 0; o < octaves; o++) {
        sum += amp * value_noise(seed + (uint64_t)o * 7919u, x, z);
        x *= 2.0f;
        z *= 2.0f;
        amp *= 0.5f;
    }
    return sum * 1.0667f; // 1 / (1 - 2^-octaves) for 4-5 octaves, so the range stays about -1..1
}

static float smoothstep(float e0, float e1, float x)
{
    float t = (x - e0) / (e1 - e0);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return smooth01(t);
}

float asp_experiment_path_nearest(const float *path, size_t count, float x, float z, float *along, float dir[2])
{
    ASP_ASSERT(path && count >= 2);
    double total = 0.0, best = INFINITY, best_at = 0.0;
    float bd[2] = {0.0f, 1.0f};
    for (size_t i = 0; i + 1 < count; i++) {
        float ax = path[3 * i], az = path[3 * i + 2];
        float dx = path[3 * i + 3] - ax, dz = path[3 * i + 5] - az;
        float len2 = dx * dx + dz * dz, len = sqrtf(len2);
        float t = len2 > 0.0f ? ((x - ax) * dx + (z - az) * dz) / len2 : 0.0f;
        t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
        float px = ax + t * dx - x, pz = az + t * dz - z;
        double d = sqrt((double)px * px + (double)pz * pz);
        if (d < best) {
            best = d;
            best_at = total + t * len;
            if (len > 0.0f) {
                bd[0] = dx / len;
                bd[1] = dz / len;
            }
        }
        total += len;
    }
    if (along)
        *along = total > 0.0 ? (float)(best_at / total) : 0.0f;
    if (dir) {
        dir[0] = bd[0];
        dir[1] = bd[1];
    }
    return (float)best;
}

float asp_experiment_world_height(const asp_experiment_world *w, float x, float z)
{
    float cell = w->size / (float)(w->grid - 1);
    float fx = (x + 0.5f * w->size) / cell, fz = (z + 0.5f * w->size) / cell;
    float lim = (float)(w->grid - 1) - 1e-3f;
    fx = fx < 0.0f ? 0.0f : fx > lim ? lim : fx;
    fz = fz < 0.0f ? 0.0f : fz > lim ? lim : fz;
    uint32_t i = (uint32_t)fx, j = (uint32_t)fz;
    float u = fx - (float)i, v = fz - (float)j;
    const float *h = w->heights;
    uint32_t g = w->grid;
    float a = h[j * g + i], b = h[j * g + i + 1], c = h[(j + 1) * g + i], d = h[(j + 1) * g + i + 1];
    return (a + (b - a) * u) * (1.0f - v) + (c + (d - c) * u) * v;
}

void asp_experiment_world_release(asp_experiment_world *w)
{
    if (!w)
        return;
    asp_context ctx = w->mesh ? w->mesh->ctx : (asp_context){0};
    asp_free(&ctx, w->heights);
    asp_free(&ctx, w->path);
    asp_mesh_destroy(w->mesh);
    memset(w, 0, sizeof *w);
}

/* a seeded winding curve x(z) along the field, sampled about every world unit */
static int make_path(const asp_experiment_scene *s, const asp_context *ctx, asp_experiment_world *w, asp_error *err)
{
    uint64_t st = asp__exp_stream(s->seed, 0x50415448ull /* "PATH" */, (uint64_t)s->kind);
    float margin = 0.08f * s->size + s->half_width;
    float z0 = -0.5f * s->size + margin, z1 = 0.5f * s->size - margin;
    /* the canyon bends less sharply: a ship at speed turns wider than a walker */
    float amp1 = (s->kind == 2 ? 0.12f : 0.10f) * s->size, amp2 = (s->kind == 2 ? 0.012f : 0.04f) * s->size;
    float wav1 = (0.55f + 0.3f * (float)asp__exp_uniform(&st)) * s->size;
    float wav2 = (0.21f + 0.1f * (float)asp__exp_uniform(&st)) * s->size;
    float ph1 = 6.2831853f * (float)asp__exp_uniform(&st), ph2 = 6.2831853f * (float)asp__exp_uniform(&st);
    size_t n = (size_t)(z1 - z0) + 2;
    if (n < 16)
        n = 16;
    w->path = asp_calloc(ctx, 3 * n, sizeof(float));
    if (!w->path)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the path");
    for (size_t i = 0; i < n; i++) {
        float z = z0 + (z1 - z0) * (float)i / (float)(n - 1);
        float x = amp1 * sinf(6.2831853f * z / wav1 + ph1) + amp2 * sinf(6.2831853f * z / wav2 + ph2);
        x -= amp1 * sinf(6.2831853f * z0 / wav1 + ph1) + amp2 * sinf(6.2831853f * z0 / wav2 + ph2); // start at x 0
        w->path[3 * i] = x;
        w->path[3 * i + 2] = z;
    }
    w->path_count = n;
    return 0;
}

int asp_experiment_world_generate(const asp_experiment_scene *s, const asp_context *ctx, asp_experiment_world *out,
                                  asp_error *err)
{
    ASP_ASSERT(s && out);
    memset(out, 0, sizeof *out);
    if (s->kind != 1 && s->kind != 2)
        return asp_error_set(err, ASP_EINVAL, "scene kind %d is not a terrain (1) or canyon (2)", s->kind);
    if (s->grid < 8 || s->grid > 2048 || !(s->size > 0.0f) || !(s->half_width > 0.0f) ||
        !(s->half_width < 0.25f * s->size) || !(s->relief >= 0.0f))
        return asp_error_set(err, ASP_EINVAL,
                             "world needs grid 8..2048, size > 0, 0 < half_width < size/4 and relief >= 0 "
                             "(got %u, %g, %g, %g)",
                             s->grid, s->size, s->half_width, s->relief);
    asp_experiment_world w = {.grid = s->grid, .size = s->size, .half_width = s->half_width};
    int rc = make_path(s, ctx, &w, err);
    uint32_t g = s->grid;
    size_t nv = (size_t)g * g, nt = 2 * (size_t)(g - 1) * (g - 1);
    if (!rc)
        rc = asp_mesh_create(nv, nt, ASP_MESH_COLORS, ctx, &w.mesh, err);
    if (!rc && !(w.heights = asp_calloc(ctx, nv, sizeof(float))))
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the height field");
    if (rc) {
        asp_experiment_world_release(&w);
        return rc;
    }
    float cell = s->size / (float)(g - 1), hw = s->half_width;
    /* rock detail about 3 path widths across, so the path stays the smoothest feature */
    float feature = 6.0f * hw;
    for (uint32_t j = 0; j < g; j++)
        for (uint32_t i = 0; i < g; i++) {
            size_t v = (size_t)j * g + i;
            float x = -0.5f * s->size + cell * (float)i, z = -0.5f * s->size + cell * (float)j;
            float d = asp_experiment_path_nearest(w.path, w.path_count, x, z, NULL, NULL);
            float rock = fbm(s->seed, x / feature, z / feature, 5);
            float h;
            uint8_t *c = &w.mesh->colors[4 * v];
            float grain = value_noise(s->seed ^ 0x5a5aull, x * 1.7f, z * 1.7f); // colour grain, -1..1
            if (s->kind == 1) {
                /* the path follows the large-scale ground (1 octave); rocks rise beside it */
                float ground = 0.25f * s->relief * value_noise(s->seed + 11u, x / (4.0f * feature), z / (4.0f * feature));
                float off = smoothstep(hw, 2.2f * hw, d);
                h = ground + off * s->relief * (0.3f + 0.7f * (0.5f + 0.5f * rock));
            } else {
                float wall = smoothstep(hw, 1.7f * hw, d);
                h = 0.02f * s->relief * rock + wall * s->relief * (0.85f + 0.3f * rock);
            }
            /*
             * The path must stand out from the ground it runs through (seed 004 2.3: the subject is to
             * stay on it): light sand on the path, on the terrain a dark green verge at least one grid
             * cell wide just outside it (vertex colours blend over a cell, so a narrower verge would be lost), and
             * cool grey rock beyond. Only the path is "sandy" to the observer (observer.c: red well
             * above blue); the verge and the rock have red at most a little above blue.
             */
            float verge = s->kind == 1 ? fmaxf(0.45f * hw, 1.05f * cell) : 0.0f; // the canyon's walls stand out
            if (d < hw) {
                c[0] = (uint8_t)(236 + 8 * grain);
                c[1] = (uint8_t)(204 + 8 * grain);
                c[2] = (uint8_t)(136 + 8 * grain);
            } else if (d < hw + verge) {
                c[0] = (uint8_t)(58 + 8 * grain);
                c[1] = (uint8_t)(92 + 10 * grain);
                c[2] = (uint8_t)(54 + 6 * grain);
            } else {
                float grey = (s->kind == 1 ? 112.0f : 92.0f) + 26.0f * grain + 30.0f * rock;
                grey = grey < 30.0f ? 30.0f : grey > 190.0f ? 190.0f : grey;
                c[0] = (uint8_t)(grey - 4.0f);
                c[1] = (uint8_t)grey;
                c[2] = (uint8_t)(grey + 8.0f);
            }
            c[3] = 255;
            w.heights[v] = h;
            float *p = &w.mesh->positions[3 * v];
            p[0] = x;
            p[1] = h;
            p[2] = z;
        }
    size_t t = 0;
    for (uint32_t j = 0; j + 1 < g; j++)
        for (uint32_t i = 0; i + 1 < g; i++) {
            uint32_t v00 = j * g + i, v10 = v00 + 1, v01 = v00 + g, v11 = v01 + 1;
            uint32_t *tri = &w.mesh->triangles[3 * t];
            // counter-clockwise seen from +y (above)
            tri[0] = v00, tri[1] = v01, tri[2] = v10;
            tri[3] = v10, tri[4] = v01, tri[5] = v11;
            t += 2;
        }
    for (size_t i = 0; i < w.path_count; i++)
        w.path[3 * i + 1] = asp_experiment_world_height(&w, w.path[3 * i], w.path[3 * i + 2]);
    rc = asp_mesh_compute_normals(w.mesh, err);
    if (rc) {
        asp_experiment_world_release(&w);
        return rc;
    }
    *out = w;
    return 0;
}
