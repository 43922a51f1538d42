/*
 * Point sets and hierarchies as glTF POINTS (POSITION, NORMAL, COLOR_0) with the elliptical
 * splats of seed 001 (Pajarola, Sainz, Guidotti 2003, section 3.4: each point's tangent
 * ellipse) as 3D Gaussians of the KHR_gaussian_splatting extension (kernel "ellipse"), listed in
 * extensionsUsed only so that viewers without it still show the points.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <meshoptimizer.h>

#include "export/internal.h"
#include "util/banned.h"

void asp_gltf_gaussian_from_ellipse(const float u[3], const float v[3], float a, float b, float quat[4],
                                    float log_scale[3])
{
    ASP_ASSERT(a > 0);
    double n[3] = {(double)u[1] * v[2] - (double)u[2] * v[1], (double)u[2] * v[0] - (double)u[0] * v[2],
                   (double)u[0] * v[1] - (double)u[1] * v[0]};
    // rotation matrix with columns u, v, u x v (a proper rotation whichever way v pointed)
    double m[3][3];
    for (int r = 0; r < 3; r++) {
        m[r][0] = u[r];
        m[r][1] = v[r];
        m[r][2] = n[r];
    }
    double tr = m[0][0] + m[1][1] + m[2][2], q[4];
    // Shepperd's method: divide by the largest of the four candidates for stability
    if (tr > 0) {
        double s = 2.0 * sqrt(tr + 1.0);
        q[3] = 0.25 * s;
        q[0] = (m[2][1] - m[1][2]) / s;
        q[1] = (m[0][2] - m[2][0]) / s;
        q[2] = (m[1][0] - m[0][1]) / s;
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        double s = 2.0 * sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
        q[3] = (m[2][1] - m[1][2]) / s;
        q[0] = 0.25 * s;
        q[1] = (m[0][1] + m[1][0]) / s;
        q[2] = (m[0][2] + m[2][0]) / s;
    } else if (m[1][1] > m[2][2]) {
        double s = 2.0 * sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
        q[3] = (m[0][2] - m[2][0]) / s;
        q[0] = (m[0][1] + m[1][0]) / s;
        q[1] = 0.25 * s;
        q[2] = (m[1][2] + m[2][1]) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
        q[3] = (m[1][0] - m[0][1]) / s;
        q[0] = (m[0][2] + m[2][0]) / s;
        q[1] = (m[1][2] + m[2][1]) / s;
        q[2] = 0.25 * s;
    }
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++)
        quat[k] = (float)(q[k] / len);
    double bb = b > 0 ? (double)b : 1e-3 * a;
    // the rim at 2 sigma, the 3-sigma cut of the ellipse kernel at 1.5 semi-axes (export.h)
    double su = 0.5 * a, sv = 0.5 * bb, sn = 0.01 * sv;
    log_scale[0] = (float)log(su);
    log_scale[1] = (float)log(sv);
    log_scale[2] = (float)log(sn);
}

float asp__gltf_srgb_to_linear(uint8_t c)
{
    double x = c / 255.0;
    return (float)(x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4));
}

typedef struct point_arrays {
    float *pos, *nrm, *rot, *scale, *opacity, *sh0;
    uint16_t *color;
    float lo[3], hi[3];
} point_arrays;

/*
 * The splats ids (n indices into asp_hier_splats, a tile's cut), or with ids NULL every point in input
 * order, turned from the source's up axis to glTF's +y (asp__gltf_turn_up).
 */
static void fill_points(const asp_hier *hier, const asp_index *ids, size_t n, point_arrays *a, int splats)
{
    const asp_up_axis up = asp_hier_frame(hier)->up;
    const asp_hier_splat *all = asp_hier_splats(hier);
    size_t nodes = asp_hier_node_count(hier);
    int colored = (asp_hier_flags(hier) & ASP_HIER_HAS_COLORS) != 0;
    // a splat without extent (a lone point) gets a tiny one: log(0) is not a number
    double tiny = asp_hier_frame(hier)->radius > 0 ? 1e-6 * asp_hier_frame(hier)->radius : 1e-6;
    for (int k = 0; k < 3; k++) {
        a->lo[k] = INFINITY;
        a->hi[k] = -INFINITY;
    }
    for (size_t j = 0; j < n; j++) {
        const asp_hier_splat *s = ids ? &all[ids[j]] : &all[nodes + j];
        size_t i = ids ? j : s->index < n ? s->index : j; // input order
        float c[3], nm[3], u[3], v[3];
        memcpy(c, s->center, sizeof c);
        memcpy(nm, s->normal, sizeof nm);
        memcpy(u, s->u, sizeof u);
        memcpy(v, s->v, sizeof v);
        asp__gltf_turn_up_f(up, c);
        asp__gltf_turn_up_f(up, nm);
        asp__gltf_turn_up_f(up, u);
        asp__gltf_turn_up_f(up, v);
        float nl = sqrtf(nm[0] * nm[0] + nm[1] * nm[1] + nm[2] * nm[2]);
        for (int k = 0; k < 3; k++) {
            a->pos[3 * i + k] = c[k];
            a->lo[k] = fminf(a->lo[k], c[k]);
            a->hi[k] = fmaxf(a->hi[k], c[k]);
            // glTF requires unit normals; a point without one faces +z
            a->nrm[3 * i + k] = nl > 0 ? nm[k] / nl : (k == 2 ? 1.0f : 0.0f);
        }
        // the renderers' light grey 200 for a set without colours (docs/cli/render.md)
        uint8_t rgba[4] = {200, 200, 200, 255};
        if (colored)
            memcpy(rgba, s->color, 4);
        for (int k = 0; k < 3; k++)
            a->color[4 * i + k] = (uint16_t)lrintf(asp__gltf_srgb_to_linear(rgba[k]) * 65535.0f); // glTF colours are linear
        a->color[4 * i + 3] = (uint16_t)(rgba[3] * 257u);
        if (!splats)
            continue;
        float ax = s->a > 0 ? s->a : (float)tiny, bx = s->a > 0 ? s->b : (float)tiny;
        asp_gltf_gaussian_from_ellipse(u, v, ax, bx, a->rot + 4 * i, a->scale + 3 * i);
        a->opacity[i] = rgba[3] / 255.0f;
        for (int k = 0; k < 3; k++) // colour = SH0 * Y00 + 0.5 (srgb_rec709_display: the stored sRGB values)
            a->sh0[3 * i + k] = (float)((rgba[k] / 255.0 - 0.5) / 0.2820947917738781);
    }
}

/* The primitive's KHR_gaussian_splatting object (seed 001's ellipses as Gaussians), for both codecs. */
static cJSON *gaussian_extension(cJSON *pr)
{
    cJSON *k = cJSON_AddObjectToObject(cJSON_AddObjectToObject(pr, "extensions"), "KHR_gaussian_splatting");
    cJSON_AddStringToObject(k, "kernel", "ellipse");
    cJSON_AddStringToObject(k, "colorSpace", "srgb_rec709_display");
    cJSON_AddStringToObject(k, "projection", "perspective");
    cJSON_AddStringToObject(k, "sortingMethod", "cameraDistance");
    return k;
}

static void splat_extension(asp__gltf *g, cJSON *attrs, cJSON *pr, const int acc[4])
{
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:ROTATION", acc[0]);
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:SCALE", acc[1]);
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:OPACITY", acc[2]);
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0", acc[3]);
    gaussian_extension(pr);
    asp__gltf_use_extension(g, "KHR_gaussian_splatting");
}

static int add_points_mesh(asp__gltf *g, const point_arrays *a, size_t n, int splats)
{
    int pos = asp__gltf_accessor(g, asp__gltf_view(g, a->pos, n * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                 "VEC3", 0, a->lo, a->hi);
    int nrm = asp__gltf_accessor(g, asp__gltf_view(g, a->nrm, n * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                 "VEC3", 0, NULL, NULL);
    int col = asp__gltf_accessor(g, asp__gltf_view(g, a->color, n * 8, ASP__GL_ARRAY_BUFFER),
                                 ASP__GL_UNSIGNED_SHORT, n, "VEC4", 1, NULL, NULL);
    cJSON *attrs = cJSON_CreateObject();
    cJSON_AddNumberToObject(attrs, "POSITION", pos);
    cJSON_AddNumberToObject(attrs, "NORMAL", nrm);
    cJSON_AddNumberToObject(attrs, "COLOR_0", col);
    int ok = pos >= 0 && nrm >= 0 && col >= 0;
    cJSON *pr = cJSON_CreateObject();
    if (splats) {
        int rot = asp__gltf_accessor(g, asp__gltf_view(g, a->rot, n * 16, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                     "VEC4", 0, NULL, NULL);
        int sc = asp__gltf_accessor(g, asp__gltf_view(g, a->scale, n * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                    "VEC3", 0, NULL, NULL);
        int op = asp__gltf_accessor(g, asp__gltf_view(g, a->opacity, n * 4, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                    "SCALAR", 0, NULL, NULL);
        int sh = asp__gltf_accessor(g, asp__gltf_view(g, a->sh0, n * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                    "VEC3", 0, NULL, NULL);
        ok = ok && rot >= 0 && sc >= 0 && op >= 0 && sh >= 0;
        splat_extension(g, attrs, pr, (const int[4]){rot, sc, op, sh});
    }
    cJSON_AddItemToObject(pr, "attributes", attrs);
    cJSON_AddNumberToObject(pr, "mode", 0); // POINTS
    cJSON *mesh = cJSON_CreateObject();
    cJSON_AddItemToArray(cJSON_AddArrayToObject(mesh, "primitives"), pr);
    cJSON_AddStringToObject(mesh, "name", "points");
    int m = asp__gltf_append(g, g->meshes, mesh);
    return ok && m >= 0 ? m : -1;
}

int asp__gltf_compact_positions(asp__gltf *g, const float *pos, size_t n, const float lo[3], const float hi[3],
                                const unsigned *remap, int normalized, uint8_t *buf, double translation[3],
                                double *scale)
{
    double side = 0;
    for (int k = 0; k < 3; k++) {
        side = fmax(side, (double)hi[k] - lo[k]);
        translation[k] = lo[k];
    }
    side = side > 0 ? side : 1.0;
    // normalized: the node's scale is the side (stored q / 65535); else one 16-bit step (stored q)
    *scale = normalized ? side : side / 65535.0;
    uint16_t *q = (uint16_t *)buf;
    float qmin[3] = {65535, 65535, 65535}, qmax[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        uint16_t *o = q + 4 * (size_t)remap[i];
        for (int k = 0; k < 3; k++) {
            double v = fmin(fmax(rint(((double)pos[3 * i + k] - lo[k]) / side * 65535.0), 0.0), 65535.0);
            o[k] = (uint16_t)v;
            qmin[k] = fminf(qmin[k], (float)v); // bounds in the stored integers (glTF 3.6.2.5)
            qmax[k] = fmaxf(qmax[k], (float)v);
        }
        o[3] = 0;
    }
    return asp__gltf_accessor(g, asp__gltf_view_meshopt(g, q, n, 8, "NONE"), ASP__GL_UNSIGNED_SHORT, n, "VEC3",
                              normalized, qmin, qmax);
}

/* The compact points' node transform: world offset = translation + scale * q / 65535 (q: 16-bit position). */
typedef struct compact_node {
    double translation[3], scale;
} compact_node;

/*
 * The compact form (issue 32, the encodings of gltfpack): points in meshopt_spatialSortRemap order
 * (neighbours next to each other is what the vertex codec's byte deltas compress), then
 *  POSITION  VEC3 unsigned short normalized (stride 8): q = round((p - lo) / s * 65535), s = the box's
 *            longest side, the node's scale: the same s on all axes so that it leaves normals and
 *            splat shapes unskewed, and the box's side so that the splats' local sizes do not
 *            depend on the model's units (SCALE below);
 *  NORMAL    VEC3 byte normalized (stride 4) through the OCTAHEDRAL filter (8 bits): three.js's
 *            MeshoptDecoder undoes the filter, so the page sees plain int8 xyz (KHR_mesh_quantization);
 *  COLOR_0   VEC4 unsigned byte normalized, linear (8 bits, gltfpack's choice);
 *  ROTATION  VEC4 short normalized (stride 8) through the QUATERNION filter (12 bits);
 *  SCALE     VEC3 float, EXPONENTIAL filter (12-bit mantissa: ln sigma to ~0.1 %), ln(sigma / s): in the
 *            node's local units like the positions, so the node's scale gives world sigma back;
 *  OPACITY   unsigned byte normalized (stride 4: vertex attributes are 4-byte aligned);
 *  SH0       VEC3 float, EXPONENTIAL filter (10-bit mantissa: below half an 8-bit colour step).
 * Each view is one vertex stream of EXT_meshopt_compression (mode ATTRIBUTES).
 */
static int add_points_compact(asp__gltf *g, const point_arrays *a, size_t n, int splats, const double origin[3],
                              compact_node *node)
{
    unsigned *remap = asp_alloc(NULL, n * sizeof *remap);
    uint8_t *buf = asp_alloc(NULL, n * 16);
    float *tmp = asp_alloc(NULL, n * 16);
    int mesh = -1;
    if (!remap || !buf || !tmp) {
        g->failed = 1;
        goto done;
    }
    meshopt_spatialSortRemap(remap, a->pos, n, 12); // remap[input index] = output index
    double s;
    int pos = asp__gltf_compact_positions(g, a->pos, n, a->lo, a->hi, remap, 1, buf, node->translation, &s);
    for (int k = 0; k < 3; k++)
        node->translation[k] += origin[k];
    node->scale = s;
    for (size_t i = 0; i < n; i++) {
        float *o = tmp + 4 * (size_t)remap[i];
        memcpy(o, a->nrm + 3 * i, 12);
        o[3] = 0;
    }
    meshopt_encodeFilterOct(buf, n, 4, 8, tmp);
    int nrm = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 4, "OCTAHEDRAL"), ASP__GL_BYTE, n, "VEC3", 1,
                                 NULL, NULL);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 4; k++) // 16-bit linear to 8-bit linear
            buf[4 * (size_t)remap[i] + k] = (uint8_t)((a->color[4 * i + k] * 255u + 32767u) / 65535u);
    int col = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 4, "NONE"), ASP__GL_UNSIGNED_BYTE, n, "VEC4",
                                 1, NULL, NULL);
    cJSON *attrs = cJSON_CreateObject(), *pr = cJSON_CreateObject();
    cJSON_AddNumberToObject(attrs, "POSITION", pos);
    cJSON_AddNumberToObject(attrs, "NORMAL", nrm);
    cJSON_AddNumberToObject(attrs, "COLOR_0", col);
    int ok = pos >= 0 && nrm >= 0 && col >= 0;
    if (splats) {
        int acc[4];
        for (size_t i = 0; i < n; i++)
            memcpy(tmp + 4 * (size_t)remap[i], a->rot + 4 * i, 16);
        meshopt_encodeFilterQuat(buf, n, 8, 12, tmp);
        acc[0] = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 8, "QUATERNION"), ASP__GL_SHORT, n, "VEC4",
                                    1, NULL, NULL);
        // glTF attributes live in the node's local space, which the node's scale s takes to the
        // world (and viewers apply it to the Gaussian, as KHR_gaussian_splatting says): ln(sigma / s).
        // With s the box's side, ln(sigma / s) lies near -7 (tangent) and -12 (normal) for
        // 10^3..10^8 points of any unit: the filter's shared exponent (of the largest) stays put,
        // which the codec's byte deltas need (s = side / 65535 put it on 4 for the 1M bunny: +1.5 B)
        const float log_s = (float)log(s);
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++)
                tmp[3 * (size_t)remap[i] + k] = a->scale[3 * i + k] - log_s;
        meshopt_encodeFilterExp(buf, n, 12, 12, tmp);
        acc[1] = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 12, "EXPONENTIAL"), ASP__GL_FLOAT, n,
                                    "VEC3", 0, NULL, NULL);
        memset(buf, 0, n * 4);
        for (size_t i = 0; i < n; i++)
            buf[4 * (size_t)remap[i]] = (uint8_t)lrintf(a->opacity[i] * 255.0f);
        acc[2] = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 4, "NONE"), ASP__GL_UNSIGNED_BYTE, n,
                                    "SCALAR", 1, NULL, NULL);
        for (size_t i = 0; i < n; i++)
            memcpy(tmp + 3 * (size_t)remap[i], a->sh0 + 3 * i, 12);
        meshopt_encodeFilterExp(buf, n, 12, 10, tmp);
        acc[3] = asp__gltf_accessor(g, asp__gltf_view_meshopt(g, buf, n, 12, "EXPONENTIAL"), ASP__GL_FLOAT, n,
                                    "VEC3", 0, NULL, NULL);
        ok = ok && acc[0] >= 0 && acc[1] >= 0 && acc[2] >= 0 && acc[3] >= 0;
        splat_extension(g, attrs, pr, acc);
    }
    asp__gltf_require_extension(g, "KHR_mesh_quantization");
    cJSON_AddItemToObject(pr, "attributes", attrs);
    cJSON_AddNumberToObject(pr, "mode", 0); // POINTS
    cJSON *m = cJSON_CreateObject();
    cJSON_AddItemToArray(cJSON_AddArrayToObject(m, "primitives"), pr);
    cJSON_AddStringToObject(m, "name", "points");
    mesh = asp__gltf_append(g, g->meshes, m);
    if (!ok)
        mesh = -1;
done:
    asp_free(NULL, remap);
    asp_free(NULL, buf);
    asp_free(NULL, tmp);
    return mesh;
}

/* An accessor without a bufferView: an extension supplies its data (count and type say what decodes). */
static int accessor_no_view(asp__gltf *g, int component_type, size_t n, const char *type, int normalized,
                            const double *min, const double *max)
{
    cJSON *acc = cJSON_CreateObject();
    cJSON_AddNumberToObject(acc, "componentType", component_type);
    cJSON_AddNumberToObject(acc, "count", (double)n);
    cJSON_AddStringToObject(acc, "type", type);
    if (normalized)
        cJSON_AddBoolToObject(acc, "normalized", 1);
    if (min && max) {
        cJSON_AddItemToObject(acc, "min", asp__gltf_numbers(min, 3));
        cJSON_AddItemToObject(acc, "max", asp__gltf_numbers(max, 3));
    }
    return asp__gltf_append(g, g->accessors, acc);
}

/* SPZ's local frame: the box's longest side spans this many units (see add_points_spz) */
#define SPZ_SIDE 256.0
/* fractional bits of SPZ's 24-bit positions: 1/256 of a unit, 1/65536 of the side (the meshopt form's 16 bits) */
#define SPZ_FRACTION_BITS 8

/*
 * The splats as KHR_gaussian_splatting_compression_spz_2 (issue 32; what CesiumJS draws): one
 * gzipped SPZ version 2 stream (gltf_spz.c) in a buffer view named by the extension, and the
 * accessors the extension maps it to (POSITION, COLOR_0 = colour and opacity,
 * KHR_gaussian_splatting:SCALE and :ROTATION) without views of their own. No NORMAL (the normal
 * is the rotation's third axis) and no OPACITY / SH_DEGREE_0 attributes: SPZ's colours and alphas
 * are COLOR_0 (the extension's attribute mapping).
 * The frame: points in meshopt_spatialSortRemap order (gzip finds the like bytes of neighbours);
 * the node's translation (origin + the box centre) and uniform scale s = side / 256 take SPZ's
 * coordinates to the world, so that SPZ's fixed ranges fit any model's units: positions within
 * +-128 in 24-bit fixed point with 8 fractional bits, ln sigma - ln s within SPZ's [-10, 5.9]
 * (sigma from 2e-7 to 1.5 times the side). The coordinates are glTF's own, not converted to SPZ's
 * RUB: CesiumJS unpacks the stream unconverted (coordinateSystem UNSPECIFIED) and puts the splats
 * where glTF's axes say.
 */
static int add_points_spz(asp__gltf *g, const point_arrays *a, size_t n, const double origin[3], compact_node *node)
{
    unsigned *remap = asp_alloc(NULL, n * sizeof *remap);
    float *f = asp_alloc(NULL, n * 14 * sizeof *f);
    uint8_t *spz = NULL;
    size_t spz_size = 0;
    int mesh = -1;
    if (!remap || !f) {
        g->failed = 1;
        goto done;
    }
    meshopt_spatialSortRemap(remap, a->pos, n, 12); // remap[input index] = output index
    double side = 0, centre[3];
    for (int k = 0; k < 3; k++) {
        side = fmax(side, (double)a->hi[k] - a->lo[k]);
        centre[k] = 0.5 * ((double)a->lo[k] + a->hi[k]);
        node->translation[k] = origin[k] + centre[k];
    }
    double s = side > 0 ? side / SPZ_SIDE : 1.0, log_s = log(s);
    node->scale = s;
    float *pos = f, *rot = pos + 3 * n, *ls = rot + 4 * n, *op = ls + 3 * n, *sh = op + n;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++) {
        size_t o = remap[i];
        for (int k = 0; k < 3; k++) {
            // the decoded position (what the POSITION bounds must hold): SPZ's fixed point
            double x = rint(((double)a->pos[3 * i + k] - centre[k]) / s * (1 << SPZ_FRACTION_BITS));
            x /= (1 << SPZ_FRACTION_BITS);
            pos[3 * o + k] = (float)x;
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
            ls[3 * o + k] = (float)(a->scale[3 * i + k] - log_s);
            sh[3 * o + k] = a->sh0[3 * i + k];
        }
        memcpy(rot + 4 * o, a->rot + 4 * i, 16);
        op[o] = a->opacity[i];
    }
    asp__spz_splats in = {pos, rot, ls, op, sh, SPZ_FRACTION_BITS};
    if (asp__spz_encode(&in, n, &spz, &spz_size, NULL)) {
        g->failed = 1;
        goto done;
    }
    int view = asp__gltf_view(g, spz, spz_size, 0);
    int acc[4] = {accessor_no_view(g, ASP__GL_FLOAT, n, "VEC3", 0, lo, hi),
                  accessor_no_view(g, ASP__GL_UNSIGNED_BYTE, n, "VEC4", 1, NULL, NULL),
                  accessor_no_view(g, ASP__GL_FLOAT, n, "VEC3", 0, NULL, NULL),
                  accessor_no_view(g, ASP__GL_FLOAT, n, "VEC4", 0, NULL, NULL)};
    cJSON *attrs = cJSON_CreateObject(), *pr = cJSON_CreateObject();
    cJSON_AddNumberToObject(attrs, "POSITION", acc[0]);
    cJSON_AddNumberToObject(attrs, "COLOR_0", acc[1]);
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:SCALE", acc[2]);
    cJSON_AddNumberToObject(attrs, "KHR_gaussian_splatting:ROTATION", acc[3]);
    cJSON_AddItemToObject(pr, "attributes", attrs);
    cJSON_AddNumberToObject(pr, "mode", 0); // POINTS
    cJSON *k = gaussian_extension(pr);
    cJSON *kx = cJSON_AddObjectToObject(cJSON_AddObjectToObject(k, "extensions"), "KHR_gaussian_splatting_compression_spz_2");
    cJSON_AddNumberToObject(kx, "bufferView", view);
    // the accessors have no data without the SPZ stream: a viewer must decode it
    asp__gltf_require_extension(g, "KHR_gaussian_splatting");
    asp__gltf_require_extension(g, "KHR_gaussian_splatting_compression_spz_2");
    cJSON *m = cJSON_CreateObject();
    cJSON_AddItemToArray(cJSON_AddArrayToObject(m, "primitives"), pr);
    cJSON_AddStringToObject(m, "name", "points");
    mesh = asp__gltf_append(g, g->meshes, m);
    if (view < 0 || acc[0] < 0 || acc[1] < 0 || acc[2] < 0 || acc[3] < 0)
        mesh = -1;
done:
    asp_free(NULL, remap);
    asp_free(NULL, f);
    asp_free(NULL, spz);
    return mesh;
}

void asp__gltf_tileset_extensions(cJSON *tileset, unsigned flags)
{
    if (!(flags & ASP_GLTF_SPZ) || (flags & ASP_GLTF_NO_SPLATS))
        return;
    // 3D Tiles 1.1 reads glTF content without it; CesiumJS asks it which glTF extensions the tiles
    // require (Cesium3DTileset.isGltfExtensionRequired) and draws splats only where both are
    cJSON_AddItemToArray(cJSON_AddArrayToObject(tileset, "extensionsUsed"), cJSON_CreateString("3DTILES_content_gltf"));
    cJSON *c = cJSON_AddObjectToObject(cJSON_AddObjectToObject(tileset, "extensions"), "3DTILES_content_gltf");
    const char *names[2] = {"KHR_gaussian_splatting", "KHR_gaussian_splatting_compression_spz_2"};
    cJSON_AddItemToObject(c, "extensionsUsed", cJSON_CreateStringArray(names, 2));
    cJSON_AddItemToObject(c, "extensionsRequired", cJSON_CreateStringArray(names, 2));
}

int asp__gltf_points_write(const asp_hier *hier, const asp_index *ids, size_t n, const double origin[3], cJSON *crs,
                           const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats, asp_error *err)
{
    static const asp_gltf_desc zero;
    const asp_gltf_desc *d = desc ? desc : &zero;
    int splats = !(d->flags & ASP_GLTF_NO_SPLATS), spz = (d->flags & ASP_GLTF_SPZ) != 0;
    if (spz && (d->flags & (ASP_GLTF_NO_SPLATS | ASP_GLTF_PLAIN))) {
        cJSON_Delete(crs);
        return asp_error_set(err, ASP_EINVAL, "SPZ holds Gaussian splats, compressed: not with %s",
                             (d->flags & ASP_GLTF_PLAIN) ? "plain (float) attributes" : "no splats");
    }
    if (n == 0) {
        cJSON_Delete(crs);
        return asp_error_set(err, ASP_EDEGENERATE, "no points to export");
    }
    asp_gltf_stats st = {0};
    asp__gltf_turn_up(asp_hier_frame(hier)->up, origin, st.origin); // the node translation, y-up
    asp__gltf g;
    int rc = asp__gltf_init(&g, path, spz      ? "(points, KHR_gaussian_splatting, SPZ)"
                               : splats ? "(points, KHR_gaussian_splatting)"
                                        : "(points)", NULL, err);
    if (rc) {
        cJSON_Delete(crs);
        return rc;
    }
    if (crs) { // glTF has no CRS: the source's words, for a GIS that reads the file (asp__gltf_crs)
        cJSON *asset = cJSON_GetObjectItem(g.root, "asset");
        cJSON *ex = asset ? cJSON_AddObjectToObject(asset, "extras") : NULL;
        cJSON *am = ex ? cJSON_AddObjectToObject(ex, "amgsplat") : NULL;
        if (!am || !cJSON_AddItemToObject(am, "crs", crs))
            cJSON_Delete(crs);
    }
    point_arrays a = {0};
    a.pos = asp_alloc(NULL, n * 12);
    a.nrm = asp_alloc(NULL, n * 12);
    a.color = asp_alloc(NULL, n * 8);
    if (splats) {
        a.rot = asp_alloc(NULL, n * 16);
        a.scale = asp_alloc(NULL, n * 12);
        a.opacity = asp_alloc(NULL, n * 4);
        a.sh0 = asp_alloc(NULL, n * 12);
    }
    if (!a.pos || !a.nrm || !a.color || (splats && (!a.rot || !a.scale || !a.opacity || !a.sh0))) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the glTF arrays of %zu points", n);
        goto done;
    }
    fill_points(hier, ids, n, &a, splats);
    int plain = (d->flags & ASP_GLTF_PLAIN) != 0;
    compact_node cn = {{0, 0, 0}, 1};
    int mesh = plain ? add_points_mesh(&g, &a, n, splats)
               : spz ? add_points_spz(&g, &a, n, st.origin, &cn)
                     : add_points_compact(&g, &a, n, splats, st.origin, &cn);
    char name[64];
    snprintf(name, sizeof name, "points (%zu)", n);
    cJSON *node = cJSON_CreateObject();
    cJSON_AddStringToObject(node, "name", name);
    cJSON_AddNumberToObject(node, "mesh", mesh);
    if (spz) {
        // as a matrix, not TRS: CesiumJS's splat tiles take the node's transform from node.matrix
        // only (GaussianSplat3DTileContent: scene.nodes[0].matrix), undefined for TRS nodes
        double m[16] = {cn.scale, 0, 0, 0, 0, cn.scale, 0, 0, 0, 0, cn.scale, 0, 0, 0, 0, 1};
        memcpy(m + 12, cn.translation, sizeof cn.translation);
        cJSON_AddItemToObject(node, "matrix", asp__gltf_numbers(m, 16));
    } else
        cJSON_AddItemToObject(node, "translation", asp__gltf_numbers(plain ? st.origin : cn.translation, 3));
    if (!plain && !spz) {
        double sc[3] = {cn.scale, cn.scale, cn.scale};
        cJSON_AddItemToObject(node, "scale", asp__gltf_numbers(sc, 3));
    }
    if (mesh < 0 || asp__gltf_append(&g, g.nodes, node) < 0) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the glTF document of '%s'", path);
        goto done;
    }
    cJSON *scenes = cJSON_AddArrayToObject(g.root, "scenes"), *s = cJSON_CreateObject();
    double zero_node = 0;
    cJSON_AddStringToObject(s, "name", "points");
    cJSON_AddItemToObject(s, "nodes", asp__gltf_numbers(&zero_node, 1));
    cJSON_AddItemToObject(s, "extras", asp__gltf_extras("points", NULL, st.origin, asp_hier_frame(hier)));
    asp__gltf_append(&g, scenes, s);
    cJSON_AddNumberToObject(g.root, "scene", 0);
    st.points = n;
    st.nodes = 1;
    rc = asp__gltf_write(&g, path, &st, err);
done:
    asp__gltf_release(&g);
    void *blocks[] = {a.pos, a.nrm, a.color, a.rot, a.scale, a.opacity, a.sh0};
    for (size_t i = 0; i < sizeof blocks / sizeof blocks[0]; i++)
        asp_free(NULL, blocks[i]);
    if (!rc && stats)
        *stats = st;
    return rc;
}

int asp_gltf_export_hier(const asp_hier *hier, const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats,
                         asp_error *err)
{
    ASP_ASSERT(hier && path);
    double origin[3];
    asp_hier_origin(hier, origin);
    return asp__gltf_points_write(hier, NULL, asp_hier_point_count(hier), origin, NULL, path, desc, stats, err);
}

int asp_gltf_export_cloud(const asp_cloud *cloud, const char *path, const asp_gltf_desc *desc,
                          const asp_context *ctx, asp_gltf_stats *stats, asp_error *err)
{
    ASP_ASSERT(cloud && path);
    asp_hier *hier = NULL;
    int rc = asp_hier_build(cloud, NULL, ctx, &hier, err);
    if (!rc) {
        double origin[3];
        asp_hier_origin(hier, origin);
        rc = asp__gltf_points_write(hier, NULL, asp_hier_point_count(hier), origin, asp__gltf_crs(cloud->las), path,
                                    desc, stats, err);
    }
    asp_hier_destroy(hier);
    return rc;
}
