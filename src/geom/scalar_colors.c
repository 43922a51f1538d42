/*
 * Colour by a per-point scalar (issue 29): a scan's own fields (elevation, ASPRS classification,
 * intensity, return number, any PLY/LAS property) turned into point colours, so every renderer
 * shows them without knowing about them.
 *
 * Ramp: viridis (van der Walt and Smith 2015, matplotlib's default), sampled at nine stops and
 * interpolated linearly. It is perceptually uniform and ordered in lightness (dark purple = low,
 * yellow = high), so equal steps of elevation read as equal steps of colour and the picture stays
 * ordered in grey print and for the common colour-vision deficiencies, unlike a rainbow or turbo.
 * Classes: ASPRS LAS 1.4 R15 table 17 defines the codes (0 created never classified, 1 unclassified,
 * 2 ground, 3-5 low/medium/high vegetation, 6 building, 7 low point (noise), 9 water, 10 rail,
 * 11 road surface, 13-16 wires and towers, 17 bridge deck, 18 high noise); it defines no colours,
 * so those below follow the convention of common LiDAR viewers (ground brown, vegetation greens,
 * building orange-red, water blue). Reserved and user codes get a hashed hue.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "util/banned.h"

void asp_scalar_color_class(unsigned cls, uint8_t rgb[3])
{
    static const uint8_t palette[19][3] = {
        {160, 160, 160}, /* 0 created, never classified */
        {190, 190, 190}, /* 1 unclassified */
        {150, 100, 50},  /* 2 ground */
        {170, 220, 110}, /* 3 low vegetation */
        {80, 180, 60},   /* 4 medium vegetation */
        {20, 110, 30},   /* 5 high vegetation */
        {230, 80, 40},   /* 6 building */
        {255, 0, 255},   /* 7 low point (noise) */
        {120, 120, 120}, /* 8 reserved (model key-point in LAS 1.2) */
        {40, 90, 220},   /* 9 water */
        {110, 70, 140},  /* 10 rail */
        {60, 60, 60},    /* 11 road surface */
        {200, 200, 120}, /* 12 reserved (overlap in LAS 1.2) */
        {250, 220, 0},   /* 13 wire - guard (shield) */
        {255, 170, 0},   /* 14 wire - conductor (phase) */
        {200, 0, 0},     /* 15 transmission tower */
        {255, 120, 160}, /* 16 wire-structure connector */
        {130, 200, 220}, /* 17 bridge deck */
        {255, 60, 200},  /* 18 high noise */
    };
    if (cls < sizeof palette / sizeof palette[0]) {
        memcpy(rgb, palette[cls], 3);
        return;
    }
    // reserved (19-63) and user (64-255) codes: a hue per code, so neighbouring codes differ
    double h = fmod((double)cls * 0.618033988749895, 1.0) * 6.0, f = h - floor(h);
    double c[6][3] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
    for (int k = 0; k < 3; k++)
        rgb[k] = (uint8_t)(60.0 + 180.0 * c[(int)h % 6][k]);
}

void asp_scalar_color_ramp(double t, uint8_t rgb[3])
{
    // viridis at t = 0, 1/8, ..., 1 (matplotlib's _viridis_data, rounded to 8 bits)
    static const uint8_t stops[9][3] = {{68, 1, 84},    {71, 45, 123},  {59, 82, 139},  {44, 114, 142}, {33, 145, 140},
                                        {40, 174, 128}, {94, 201, 98},  {173, 220, 48}, {253, 231, 37}};
    if (!(t > 0))
        t = 0;
    if (t > 1)
        t = 1;
    double s = t * 8.0;
    int i = s >= 8.0 ? 7 : (int)s;
    double f = s - i;
    for (int k = 0; k < 3; k++)
        rgb[k] = (uint8_t)lround(stops[i][k] + f * (stops[i + 1][k] - stops[i][k]));
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int unknown(const asp_cloud *c, const char *what, asp_error *err)
{
    char list[512] = "";
    size_t n = 0;
    for (size_t i = 0; i < c->property_count && n + 2 < sizeof list; i++) {
        int w = snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", c->properties[i].name);
        n = w < 0 ? n : n + (size_t)w;
    }
    return asp_error_set(err, ASP_EINVAL,
                         "no such property '%s' (elevation or the file's: %s)", what,
                         c->property_count ? list : "none");
}

int asp_cloud_color_by(asp_cloud *cloud, const char *what, asp_up_axis up, asp_error *err)
{
    if (!cloud || !what)
        return asp_error_set(err, ASP_EINVAL, "cannot colour by a scalar: %s is NULL", cloud ? "what" : "cloud");
    const char *name = strncmp(what, "prop:", 5) == 0 ? what + 5 : what;
    int elevation = name == what && strcmp(name, "elevation") == 0;
    const asp_property *p = elevation ? NULL : asp_cloud_find_property(cloud, name);
    if (!elevation && !p)
        return unknown(cloud, what, err);
    size_t n = cloud->count;
    double *v = asp_alloc(&cloud->ctx, (n ? n : 1) * sizeof *v);
    if (!v)
        return asp_error_set(err, ASP_ENOMEM, "cannot colour by '%s': out of memory for %zu points", what, n);
    // the up axis as asp_up_axis numbers them: Y, Z, X, then the negative ones
    static const int axis[6] = {1, 2, 0, 1, 2, 0};
    for (size_t i = 0; i < n; i++)
        v[i] = elevation ? (up >= ASP_UP_NEG_Y ? -1.0 : 1.0) *
                               ((double)cloud->positions[3 * i + axis[up % 6]] + cloud->origin[axis[up % 6]])
                         : asp_property_value(p, i);
    int rc = cloud->colors ? 0 : asp_cloud_add_attrs(cloud, ASP_ATTR_COLORS, err);
    if (rc) {
        asp_free(&cloud->ctx, v);
        return rc;
    }
    int classes = !elevation && name == what && strcmp(name, "classification") == 0;
    int grey = !elevation && name == what && strcmp(name, "intensity") == 0;
    double lo = INFINITY, hi = -INFINITY;
    if (grey && n) { // 1st and 99th percentile: a few bright returns (retro-reflectors) would grey out the rest
        double *s = asp_alloc(&cloud->ctx, n * sizeof *s);
        if (!s) {
            asp_free(&cloud->ctx, v);
            return asp_error_set(err, ASP_ENOMEM, "cannot colour by '%s': out of memory for %zu points", what, n);
        }
        memcpy(s, v, n * sizeof *s);
        qsort(s, n, sizeof *s, cmp_double);
        lo = s[(size_t)(0.01 * (double)(n - 1))];
        hi = s[(size_t)(0.99 * (double)(n - 1) + 0.5)];
        asp_free(&cloud->ctx, s);
    } else {
        for (size_t i = 0; i < n; i++)
            if (isfinite(v[i])) {
                lo = v[i] < lo ? v[i] : lo;
                hi = v[i] > hi ? v[i] : hi;
            }
    }
    double span = hi > lo ? hi - lo : 1.0;
    for (size_t i = 0; i < n; i++) {
        uint8_t *c = cloud->colors + 4 * i;
        double t = (v[i] - lo) / span;
        if (classes) {
            asp_scalar_color_class(v[i] >= 0 && v[i] <= 255 ? (unsigned)v[i] : 1u, c);
        } else if (grey) {
            t = t > 0 ? (t < 1 ? t : 1) : 0;
            c[0] = c[1] = c[2] = (uint8_t)lround(255.0 * t);
        } else {
            asp_scalar_color_ramp(t, c);
        }
        c[3] = 255;
    }
    asp_free(&cloud->ctx, v);
    return 0;
}
