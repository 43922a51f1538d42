/*
 * Synthetic point models with known ground truth: the 8-colour octahedron of
 * Reniers & Telea 2006 Fig. 1 (journal section 5: 16,000 points, one domain per
 * face), a 6-face cube, a sphere, a torus, and the checkerboard plane used by
 * Pajarola et al. 2003 to show splat blending. Labels hold the face id.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/sample.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

static const char *const shape_names[] = {"octahedron", "cube", "sphere", "torus", "checker-plane"};
enum { N_SHAPES = sizeof shape_names / sizeof shape_names[0] };

static const double torus_major = 1.0, torus_minor = 0.35;

const char *asp_synth_shape_name(asp_synth_shape shape)
{
    return (unsigned)shape < N_SHAPES ? shape_names[shape] : "unknown";
}

int asp_synth_shape_parse(const char *name, asp_synth_shape *out, asp_error *err)
{
    for (unsigned i = 0; i < N_SHAPES; i++)
        if (strcmp(name, shape_names[i]) == 0) {
            *out = (asp_synth_shape)i;
            return 0;
        }
    return asp_error_set(err, ASP_EINVAL,
                         "unknown shape '%s'; expected octahedron, cube, sphere, torus or checker-plane", name);
}

/* Eight well-separated face colours, so a render shows the ground-truth domains. */
static const uint8_t face_palette[8][3] = {
    {230, 25, 75}, {60, 180, 75}, {255, 225, 25}, {0, 130, 200},
    {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230},
};

static void put_color(uint8_t *c, uint8_t r, uint8_t g, uint8_t b)
{
    c[0] = r;
    c[1] = g;
    c[2] = b;
    c[3] = 255;
}

/* Points of face f: the count is split as evenly as possible, the first (n % faces) faces get one more. */
static size_t face_begin(size_t n, size_t faces, size_t f)
{
    return f * (n / faces) + (f < n % faces ? f : n % faces);
}

static void face_offsets(uint64_t seed, size_t f, double *ou, double *ov)
{
    uint64_t h = asp__mix64(seed ^ asp__mix64(f + 1));
    *ou = asp__unit(h);
    *ov = asp__unit(asp__mix64(h));
}

static void make_octahedron(asp_cloud *c, uint64_t seed)
{
    const double inv_sqrt3 = 0.57735026918962576451;
    for (size_t f = 0; f < 8; f++) {
        double s[3] = {(f & 1) ? -1.0 : 1.0, (f & 2) ? -1.0 : 1.0, (f & 4) ? -1.0 : 1.0};
        size_t b = face_begin(c->count, 8, f), e = face_begin(c->count, 8, f + 1);
        double ou, ov;
        face_offsets(seed, f, &ou, &ov);
        for (size_t i = b; i < e; i++) {
            double u, v, b1, b2;
            asp__r2(i - b, ou, ov, &u, &v);
            asp__square_to_triangle(u, v, &b1, &b2);
            /* vertex 0 = s_x e_x, vertex 1 = s_y e_y, vertex 2 = s_z e_z */
            double w[3] = {1.0 - b1 - b2, b1, b2};
            for (int a = 0; a < 3; a++) {
                c->positions[3 * i + a] = (float)(s[a] * w[a]);
                c->normals[3 * i + a] = (float)(s[a] * inv_sqrt3);
            }
            put_color(c->colors + 4 * i, face_palette[f][0], face_palette[f][1], face_palette[f][2]);
            c->labels[i] = (uint32_t)f;
        }
    }
}

static void make_cube(asp_cloud *c, uint64_t seed)
{
    for (size_t f = 0; f < 6; f++) {
        int axis = (int)(f / 2);
        double sign = (f & 1) ? -1.0 : 1.0;
        size_t b = face_begin(c->count, 6, f), e = face_begin(c->count, 6, f + 1);
        double ou, ov;
        face_offsets(seed, f, &ou, &ov);
        for (size_t i = b; i < e; i++) {
            double u, v;
            asp__r2(i - b, ou, ov, &u, &v);
            float *p = c->positions + 3 * i, *n = c->normals + 3 * i;
            p[axis] = (float)sign;
            p[(axis + 1) % 3] = (float)(2.0 * u - 1.0);
            p[(axis + 2) % 3] = (float)(2.0 * v - 1.0);
            n[0] = n[1] = n[2] = 0.0f;
            n[axis] = (float)sign;
            put_color(c->colors + 4 * i, face_palette[f][0], face_palette[f][1], face_palette[f][2]);
            c->labels[i] = (uint32_t)f;
        }
    }
}

/* Spherical Fibonacci lattice: equal-area rings with golden-angle turns, the most even simple sphere set. */
static void make_sphere(asp_cloud *c, uint64_t seed)
{
    const double golden = 0.61803398874989484820;
    double off = asp__unit(asp__mix64(seed));
    size_t n = c->count;
    for (size_t i = 0; i < n; i++) {
        double z = 1.0 - (2.0 * (double)i + 1.0) / (double)n;
        double t = off + golden * (double)i;
        double phi = 2.0 * M_PI * (t - floor(t));
        double rho = sqrt(fmax(0.0, 1.0 - z * z));
        double p[3] = {rho * cos(phi), rho * sin(phi), z};
        for (int a = 0; a < 3; a++) {
            c->positions[3 * i + a] = (float)p[a];
            c->normals[3 * i + a] = (float)p[a];
        }
        put_color(c->colors + 4 * i, (uint8_t)lrint(127.5 * (p[0] + 1.0)), (uint8_t)lrint(127.5 * (p[1] + 1.0)),
                  (uint8_t)lrint(127.5 * (p[2] + 1.0)));
    }
}

/*
 * Torus: a Fibonacci lattice in (u, v), with u mapped to the tube angle
 * through the inverse of the area CDF F(t) = (R t + r sin t) / (2 pi R), since
 * the area element is r (R + r cos t) dt dphi: even density everywhere.
 */
static void make_torus(asp_cloud *c, uint64_t seed)
{
    const double golden = 0.61803398874989484820, R = torus_major, r = torus_minor;
    double off = asp__unit(asp__mix64(seed));
    size_t n = c->count;
    for (size_t i = 0; i < n; i++) {
        double u = ((double)i + 0.5) / (double)n;
        double t = 2.0 * M_PI * u;
        for (int it = 0; it < 30; it++) {
            /* Newton on R t + r sin t = 2 pi R u; derivative R + r cos t >= R - r > 0 */
            double step = (R * t + r * sin(t) - 2.0 * M_PI * R * u) / (R + r * cos(t));
            t -= step;
            if (fabs(step) < 1e-14)
                break;
        }
        double s = off + golden * (double)i;
        double phi = 2.0 * M_PI * (s - floor(s));
        double ring = R + r * cos(t);
        double p[3] = {ring * cos(phi), ring * sin(phi), r * sin(t)};
        double nn[3] = {cos(t) * cos(phi), cos(t) * sin(phi), sin(t)};
        for (int a = 0; a < 3; a++) {
            c->positions[3 * i + a] = (float)p[a];
            c->normals[3 * i + a] = (float)nn[a];
        }
        /* hue from the ring angle, brightness from the tube angle: both angles visible at once */
        double h = phi / (2.0 * M_PI) * 6.0, k = 0.55 + 0.45 * (0.5 + 0.5 * cos(t));
        double fr = fmin(1.0, fmax(0.0, fabs(h - 3.0) - 1.0));
        double fg = fmin(1.0, fmax(0.0, 2.0 - fabs(h - 2.0)));
        double fb = fmin(1.0, fmax(0.0, 2.0 - fabs(h - 4.0)));
        put_color(c->colors + 4 * i, (uint8_t)lrint(255.0 * k * fr), (uint8_t)lrint(255.0 * k * fg),
                  (uint8_t)lrint(255.0 * k * fb));
    }
}

static void make_checker(asp_cloud *c, uint32_t grid, uint32_t squares)
{
    double spacing = 2.0 / (double)(grid - 1);
    /* the farthest point of a grid cell from its corners is the centre, spacing * sqrt(2) / 2 away */
    float radius = (float)(spacing * 0.70710678118654752440 * 1.02);
    for (uint32_t j = 0; j < grid; j++)
        for (uint32_t i = 0; i < grid; i++) {
            size_t k = (size_t)j * grid + i;
            c->positions[3 * k + 0] = (float)(-1.0 + spacing * i);
            c->positions[3 * k + 1] = (float)(-1.0 + spacing * j);
            c->positions[3 * k + 2] = 0.0f;
            c->normals[3 * k + 0] = 0.0f;
            c->normals[3 * k + 1] = 0.0f;
            c->normals[3 * k + 2] = 1.0f;
            uint32_t parity = (uint32_t)(((uint64_t)i * squares / grid + (uint64_t)j * squares / grid) & 1);
            if (parity)
                put_color(c->colors + 4 * k, 30, 30, 30);
            else
                put_color(c->colors + 4 * k, 235, 235, 235);
            c->labels[k] = parity;
            c->radii[k] = radius;
        }
}

int asp_synth(asp_synth_shape shape, const asp_synth_desc *desc, const asp_context *ctx, asp_cloud **out,
              asp_error *err)
{
    static const size_t default_points[] = {16000, 24000, 20000, 30000, 0};
    static const size_t faces[] = {8, 6, 1, 1, 1};
    asp_synth_desc d = desc ? *desc : (asp_synth_desc){0};
    if ((unsigned)shape >= N_SHAPES)
        return asp_error_set(err, ASP_EINVAL, "unknown synthetic shape %d", (int)shape);
    size_t n = d.points ? d.points : default_points[shape];
    uint32_t grid = d.grid ? d.grid : 512, squares = d.squares ? d.squares : 8;
    if (shape == ASP_SYNTH_CHECKER_PLANE) {
        if (grid < 2 || (uint64_t)grid * grid >= UINT32_MAX)
            return asp_error_set(err, ASP_EINVAL, "checker-plane grid %u is outside 2..65535", grid);
        if (squares > grid)
            return asp_error_set(err, ASP_EINVAL, "checker-plane has %u squares per side but only %u points",
                                 squares, grid);
        n = (size_t)grid * grid;
    } else if (n < 4 * faces[shape] || n >= UINT32_MAX) {
        return asp_error_set(err, ASP_EINVAL, "%s needs 4 to 4294967294 points per face, got %zu in all",
                             shape_names[shape], n);
    }
    unsigned attrs = ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII;
    if (shape == ASP_SYNTH_OCTAHEDRON || shape == ASP_SYNTH_CUBE || shape == ASP_SYNTH_CHECKER_PLANE)
        attrs |= ASP_ATTR_LABELS;
    asp_cloud *c = NULL;
    int rc = asp_cloud_create(n, attrs, ctx, &c, err);
    if (rc)
        return rc;
    switch (shape) {
    case ASP_SYNTH_OCTAHEDRON: make_octahedron(c, d.seed); break;
    case ASP_SYNTH_CUBE: make_cube(c, d.seed); break;
    case ASP_SYNTH_SPHERE: make_sphere(c, d.seed); break;
    case ASP_SYNTH_TORUS: make_torus(c, d.seed); break;
    case ASP_SYNTH_CHECKER_PLANE: make_checker(c, grid, squares); break;
    }
    if (shape != ASP_SYNTH_CHECKER_PLANE) {
        rc = asp__covering_radii(c->positions, c->normals, c->count, 12, ASP__COVER_MARGIN, 0.0f, ctx, c->radii,
                                 err);
        if (rc) {
            asp_cloud_destroy(c);
            return rc;
        }
    }
    char comment[96];
    snprintf(comment, sizeof comment, "amgsplat synth %s, %zu points, seed %llu", shape_names[shape], n,
             (unsigned long long)d.seed);
    asp_cloud_add_comment(c, comment, NULL); /* provenance only: losing it to ENOMEM is harmless */
    *out = c;
    return 0;
}
