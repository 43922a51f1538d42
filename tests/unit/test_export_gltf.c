/*
 * glTF export (issue 16): the Gaussian of a splat ellipse (KHR_gaussian_splatting), the GLB
 * container, quads that are the renderer's support rectangles with its texture coordinates, and
 * UTM-size coordinates kept exact through the node translation; the compact points (issue 32:
 * KHR_mesh_quantization + EXT_meshopt_compression) decoded with meshoptimizer's own decoder give
 * back the plain export's values within their quantisation steps.
 */
#include <errno.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>
#include <meshoptimizer.h>

#include "amgsplat/amgsplat.h"
#include "harness.h"

static char tmpdir[512];

static const char *tmp_path(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", tmpdir, name);
    return buf;
}

static uint32_t u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* A GLB read back: its JSON and its binary chunk. */
typedef struct glb {
    uint8_t *bytes;
    size_t size;
    cJSON *json;
    const uint8_t *bin;
    size_t bin_size;
} glb;

static int glb_read(const char *path, glb *g)
{
    memset(g, 0, sizeof *g);
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    g->size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    g->bytes = malloc(g->size + 1);
    size_t got = fread(g->bytes, 1, g->size, f);
    fclose(f);
    if (got != g->size || g->size < 28 || memcmp(g->bytes, "glTF", 4) != 0 || u32(g->bytes + 4) != 2 ||
        u32(g->bytes + 8) != g->size || u32(g->bytes + 16) != 0x4E4F534Au)
        return -1;
    size_t jlen = u32(g->bytes + 12);
    if (jlen % 4 || 20 + jlen + 8 > g->size)
        return -1;
    g->json = cJSON_ParseWithLength((const char *)g->bytes + 20, jlen);
    g->bin_size = u32(g->bytes + 20 + jlen);
    if (u32(g->bytes + 24 + jlen) != 0x004E4942u || 28 + jlen + g->bin_size != g->size)
        return -1;
    g->bin = g->bytes + 28 + jlen;
    return g->json ? 0 : -1;
}

static void glb_free(glb *g)
{
    cJSON_Delete(g->json);
    free(g->bytes);
}

static double num(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static const cJSON *at(const cJSON *root, const char *array, int index)
{
    return cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, array), index);
}

/* The float data of accessor index (tightly packed, as the export writes them). */
static const float *accessor_floats(const glb *g, int index, size_t *count)
{
    const cJSON *a = at(g->json, "accessors", index);
    const cJSON *v = at(g->json, "bufferViews", (int)num(a, "bufferView"));
    *count = (size_t)num(a, "count");
    size_t off = (size_t)num(v, "byteOffset");
    return off % 4 == 0 && off + (size_t)num(v, "byteLength") <= g->bin_size ? (const float *)(g->bin + off) : NULL;
}

static double srgb_to_linear_ref(uint8_t c)
{
    double x = c / 255.0;
    return x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
}

static void test_gaussian_axes(void)
{
    // u, v along x, y: no rotation; sigma = semi-axis / 2, the normal 1/100 of the minor one
    float q[4], s[3];
    asp_gltf_gaussian_from_ellipse((const float[]){1, 0, 0}, (const float[]){0, 1, 0}, 2.0f, 1.0f, q, s);
    CHECK_NEAR(q[0], 0, 1e-7);
    CHECK_NEAR(q[1], 0, 1e-7);
    CHECK_NEAR(q[2], 0, 1e-7);
    CHECK_NEAR(q[3], 1, 1e-7);
    CHECK_NEAR(s[0], log(1.0), 1e-6);
    CHECK_NEAR(s[1], log(0.5), 1e-6);
    CHECK_NEAR(s[2], log(0.005), 1e-6);
    // a tilted frame, and one with v pointing the other way (u x v = -normal): the quaternion's
    // rotation matrix (KHR_gaussian_splatting "3D Gaussian Representation") has columns u, v, u x v
    const double c = cos(0.7), sn = sin(0.7);
    float u[3] = {(float)c, (float)sn, 0}, v[3] = {(float)(-sn * 0.6), (float)(c * 0.6), 0.8f};
    for (int flip = 0; flip < 2; flip++) {
        float vv[3] = {flip ? -v[0] : v[0], flip ? -v[1] : v[1], flip ? -v[2] : v[2]};
        asp_gltf_gaussian_from_ellipse(u, vv, 0.3f, 0.1f, q, s);
        double x = q[0], y = q[1], z = q[2], w = q[3];
        CHECK_NEAR(x * x + y * y + z * z + w * w, 1, 1e-6);
        double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
        for (int r = 0; r < 3; r++) {
            CHECK_NEAR(R[r][0], u[r], 1e-5);
            CHECK_NEAR(R[r][1], vv[r], 1e-5);
        }
        CHECK_NEAR(exp(s[0]), 0.15, 1e-6);
        CHECK_NEAR(exp(s[1]), 0.05, 1e-6);
    }
    // a degenerate (b = 0) ellipse still has a finite log scale
    asp_gltf_gaussian_from_ellipse((const float[]){0, 0, 1}, (const float[]){1, 0, 0}, 1.0f, 0.0f, q, s);
    CHECK(isfinite(s[1]) && isfinite(s[2]) && s[1] < s[0] && s[2] < s[1]);
}

/* A level of 2 primitives on an 8x4 atlas, at UTM-size world coordinates. */
static void make_dps(asp_dps *d, asp_dps_level *lv, asp_prim p[2], uint8_t atlas[8 * 4 * 4])
{
    memset(d, 0, sizeof *d);
    memset(lv, 0, sizeof *lv);
    memset(p, 0, 2 * sizeof *p);
    for (int i = 0; i < 8 * 4 * 4; i++)
        atlas[i] = (uint8_t)(i * 7);
    for (int i = 0; i < 2; i++) {
        p[i].centre[0] = 500000.125 + i;
        p[i].centre[1] = 5000000.25;
        p[i].centre[2] = 312.5;
        p[i].axis_u[0] = 1;
        p[i].axis_v[1] = 1;
        p[i].normal[2] = 1;
        p[i].half_u = 0.5f;
        p[i].half_v = 0.25f;
        p[i].texel = 0.25f;
        p[i].tex_x = 4u * (uint32_t)i;
        p[i].tex_w = 4;
        p[i].tex_h = 2;
        p[i].tex_y = 1;
    }
    lv->level = 3;
    lv->prim_count = 2;
    lv->prims = p;
    lv->atlas = (asp_image){.width = 8, .height = 4, .pixels = atlas};
    d->level_count = 1;
    d->levels = lv;
    d->amg_levels = 5;
    d->frame = (asp_frame){.center = {500000.625, 5000000.25, 312.5}, .radius = 1.5};
    d->desc.padding = 2;
}

static void test_dps_quads(void)
{
    asp_dps d;
    asp_dps_level lv;
    asp_prim p[2];
    uint8_t atlas[8 * 4 * 4];
    make_dps(&d, &lv, p, atlas);
    char path[600];
    asp_error err = {0};
    asp_gltf_stats st = {0};
    CHECK_OK(asp_gltf_export_dps(&d, tmp_path(path, sizeof path, "q.glb"), NULL, &st, &err), &err);
    CHECK(st.primitives == 2 && st.nodes == 1 && st.images == 1 && st.files == 1);
    glb g;
    if (glb_read(path, &g)) {
        CHECK_MSG(0, "'%s' is not a GLB", path);
        glb_free(&g);
        return;
    }
    CHECK(st.file_bytes == g.size);
    // the origin is the frame centre, exact in the node translation
    const cJSON *node = at(g.json, "nodes", 0);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(node, "translation");
    CHECK(cJSON_GetArraySize(t) == 3);
    CHECK(cJSON_GetArrayItem(t, 0)->valuedouble == 500000.625);
    CHECK(cJSON_GetArrayItem(t, 1)->valuedouble == 5000000.25);
    CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(node, "name")->valuestring, "L-1 (2 primitives)") == 0);
    const cJSON *prim = at(at(g.json, "meshes", 0), "primitives", 0);
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    CHECK(num(prim, "mode") == 4);
    CHECK(cJSON_GetObjectItemCaseSensitive(attrs, "TANGENT") == NULL); // no normal map
    size_t n = 0, nuv = 0;
    const float *pos = accessor_floats(&g, (int)num(attrs, "POSITION"), &n);
    const float *uv = accessor_floats(&g, (int)num(attrs, "TEXCOORD_0"), &nuv);
    CHECK(n == 8 && nuv == 8 && pos && uv);
    if (pos && uv && n == 8) {
        // corner 0 of primitive 1: centre - half_u u - half_v v, minus the origin; its texture
        // coordinate the texture rectangle's left/top texel edge (build.md, prim_renderer.c)
        CHECK_NEAR(pos[12 + 0] + 500000.625, 500001.125 - 0.5, 1e-9);
        CHECK_NEAR(pos[12 + 1] + 5000000.25, 5000000.25 - 0.25, 1e-9);
        CHECK_NEAR(uv[8 + 0], 4.0 / 8, 1e-7);
        CHECK_NEAR(uv[8 + 1], 1.0 / 4, 1e-7);
        // corner 3: + half_u + half_v, the far texel edges
        CHECK_NEAR(pos[21 + 0] + 500000.625, 500001.125 + 0.5, 1e-9);
        CHECK_NEAR(uv[14 + 0], 8.0 / 8, 1e-7);
        CHECK_NEAR(uv[14 + 1], 3.0 / 4, 1e-7);
    }
    const cJSON *mat = at(g.json, "materials", 0);
    CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(mat, "alphaMode")->valuestring, "BLEND") == 0);
    CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(mat, "doubleSided")));
    CHECK(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(mat, "extensions"), "KHR_materials_unlit"));
    const cJSON *frame = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(at(g.json, "scenes", 0), "extras"),
                                         "amgsplat"),
        "frame");
    CHECK(num(frame, "radius") == 1.5);
    glb_free(&g);

    // MASK at a given cutoff, lit
    asp_gltf_desc desc = {.alpha_mode = ASP_GLTF_ALPHA_MASK, .alpha_cutoff = 0.25f, .flags = ASP_GLTF_LIT};
    CHECK_OK(asp_gltf_export_dps(&d, path, &desc, NULL, &err), &err);
    if (glb_read(path, &g) == 0) {
        mat = at(g.json, "materials", 0);
        CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(mat, "alphaMode")->valuestring, "MASK") == 0);
        CHECK_NEAR(num(mat, "alphaCutoff"), 0.25, 1e-7);
        CHECK(cJSON_GetObjectItemCaseSensitive(mat, "extensions") == NULL);
        CHECK(cJSON_GetObjectItemCaseSensitive(g.json, "extensionsUsed") == NULL);
    }
    glb_free(&g);
}

static void test_bad_arguments(void)
{
    asp_dps d;
    asp_dps_level lv;
    asp_prim p[2];
    uint8_t atlas[8 * 4 * 4];
    make_dps(&d, &lv, p, atlas);
    char path[600];
    asp_error err = {0};
    CHECK(asp_gltf_export_dps(&d, tmp_path(path, sizeof path, "x.obj"), NULL, NULL, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, ".glb or .gltf") != NULL);
    size_t bad_level = 1;
    asp_gltf_desc desc = {.levels = &bad_level, .level_count = 1};
    CHECK(asp_gltf_export_dps(&d, tmp_path(path, sizeof path, "y.glb"), &desc, NULL, &err) == ASP_EINVAL);
    desc = (asp_gltf_desc){.alpha_cutoff = 1.5f};
    CHECK(asp_gltf_export_dps(&d, path, &desc, NULL, &err) == ASP_EINVAL);
    struct stat sb;
    CHECK(stat(path, &sb) != 0); // a failed export leaves no file
    CHECK(asp_gltf_export_dps(&d, tmp_path(path, sizeof path, "nodir/z.glb"), NULL, NULL, &err) == ASP_EIO);
}

/* A 20 x 20 grid at x = 500000, y = 5000000 (UTM metres), 1 cm apart. */
static void test_points_utm(void)
{
    asp_cloud *c = NULL;
    asp_error err = {0};
    CHECK_OK(asp_cloud_create(400, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, &err), &err);
    if (!c)
        return;
    c->origin[0] = 500000.0;
    c->origin[1] = 5000000.0;
    c->origin[2] = 250.0;
    for (size_t i = 0; i < 400; i++) {
        c->positions[3 * i] = 0.01f * (float)(i % 20) + 0.003f;
        c->positions[3 * i + 1] = 0.01f * (float)(i / 20);
        c->positions[3 * i + 2] = 0.0f;
        c->normals[3 * i + 2] = 1.0f;
        uint8_t rgba[4] = {(uint8_t)(i % 256), 128, 255, 255};
        memcpy(c->colors + 4 * i, rgba, 4);
    }
    char path[600];
    asp_gltf_stats st = {0};
    const asp_gltf_desc plain = {.flags = ASP_GLTF_PLAIN}; // float offsets in input order: read directly
    CHECK_OK(asp_gltf_export_cloud(c, tmp_path(path, sizeof path, "utm.glb"), &plain, NULL, &st, &err), &err);
    CHECK(st.points == 400 && st.origin[0] == 500000.0 && st.origin[1] == 5000000.0);
    glb g;
    if (glb_read(path, &g)) {
        CHECK_MSG(0, "'%s' is not a GLB", path);
        glb_free(&g);
        asp_cloud_destroy(c);
        return;
    }
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(at(g.json, "nodes", 0), "translation");
    CHECK(cJSON_GetArrayItem(t, 0)->valuedouble == 500000.0 && cJSON_GetArrayItem(t, 1)->valuedouble == 5000000.0);
    const cJSON *prim = at(at(g.json, "meshes", 0), "primitives", 0);
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    CHECK(num(prim, "mode") == 0);
    size_t n = 0;
    const float *pos = accessor_floats(&g, (int)num(attrs, "POSITION"), &n);
    CHECK(n == 400 && pos);
    // world = translation + position, to float precision of the small offsets (not of 5e6)
    double worst = 0;
    for (size_t i = 0; pos && i < n; i++) {
        double wx = 500000.0 + pos[3 * i], want = 500000.0 + 0.01 * (double)(i % 20) + 0.003;
        worst = fmax(worst, fabs(wx - want));
    }
    CHECK_MSG(worst < 1e-6, "worst x error %g m", worst);
    // the splat attributes of KHR_gaussian_splatting, the extension used but not required
    CHECK(cJSON_GetObjectItemCaseSensitive(attrs, "KHR_gaussian_splatting:ROTATION"));
    CHECK(cJSON_GetObjectItemCaseSensitive(attrs, "KHR_gaussian_splatting:SCALE"));
    CHECK(cJSON_GetObjectItemCaseSensitive(attrs, "KHR_gaussian_splatting:OPACITY"));
    CHECK(cJSON_GetObjectItemCaseSensitive(attrs, "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0"));
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(prim, "extensions"), "KHR_gaussian_splatting");
    CHECK(ext && strcmp(cJSON_GetObjectItemCaseSensitive(ext, "kernel")->valuestring, "ellipse") == 0);
    CHECK(cJSON_GetObjectItemCaseSensitive(g.json, "extensionsRequired") == NULL);
    // the splats are about the point spacing: scale = ln(semi-axis / 2), semi-axes ~ 1 cm
    const float *scale = accessor_floats(&g, (int)num(attrs, "KHR_gaussian_splatting:SCALE"), &n);
    if (scale && n == 400) {
        double a = 2 * exp(scale[3 * 210]);
        CHECK_MSG(a > 0.004 && a < 0.05, "major semi-axis %g m", a);
    }
    // SH0 gives back the sRGB colour (colour = SH0 * 0.2820948 + 0.5)
    const float *sh = accessor_floats(&g, (int)num(attrs, "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0"), &n);
    if (sh && n == 400)
        CHECK_NEAR(sh[3 * 37 + 0] * 0.2820947917738781 + 0.5, 37 / 255.0, 1e-6);
    glb_free(&g);
    // without splats: plain points, no extension
    CHECK_OK(asp_gltf_export_cloud(c, path, &(asp_gltf_desc){.flags = ASP_GLTF_NO_SPLATS | ASP_GLTF_PLAIN}, NULL, &st,
                                   &err), &err);
    if (glb_read(path, &g) == 0)
        CHECK(cJSON_GetObjectItemCaseSensitive(g.json, "extensionsUsed") == NULL);
    glb_free(&g);
    asp_cloud_destroy(c);
}

/* Decodes the EXT_meshopt_compression view of accessor index into out (count x stride bytes). */
static int decode_view(const glb *g, int index, void *out, size_t count, size_t stride)
{
    const cJSON *a = at(g->json, "accessors", index);
    const cJSON *v = at(g->json, "bufferViews", (int)num(a, "bufferView"));
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(v, "extensions"),
                                                      "EXT_meshopt_compression");
    if (!e || num(e, "count") != (double)count || num(e, "byteStride") != (double)stride || num(v, "buffer") != 1)
        return -1;
    size_t off = (size_t)num(e, "byteOffset"), len = (size_t)num(e, "byteLength");
    if (off + len > g->bin_size || meshopt_decodeVertexBuffer(out, count, stride, g->bin + off, len) != 0)
        return -1;
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(e, "filter");
    const char *filter = cJSON_IsString(f) ? f->valuestring : "NONE";
    if (strcmp(filter, "OCTAHEDRAL") == 0)
        meshopt_decodeFilterOct(out, count, stride);
    else if (strcmp(filter, "QUATERNION") == 0)
        meshopt_decodeFilterQuat(out, count, stride);
    else if (strcmp(filter, "EXPONENTIAL") == 0)
        meshopt_decodeFilterExp(out, count, stride);
    return 0;
}

static void test_points_compact(void)
{
    enum { N = 400 };
    asp_cloud *c = NULL;
    asp_error err = {0};
    CHECK_OK(asp_cloud_create(N, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, &err), &err);
    if (!c)
        return;
    c->origin[0] = 500000.0;
    c->origin[1] = 5000000.0;
    for (size_t i = 0; i < N; i++) {
        // a wavy 20 x 20 grid: normals, colours and splat shapes all vary
        double x = 0.01 * (double)(i % 20), y = 0.01 * (double)(i / 20), z = 0.004 * sin(40 * x) * cos(30 * y);
        c->positions[3 * i] = (float)x;
        c->positions[3 * i + 1] = (float)y;
        c->positions[3 * i + 2] = (float)z;
        double nx = -0.16 * cos(40 * x) * cos(30 * y), ny = 0.12 * sin(40 * x) * sin(30 * y);
        double nl = sqrt(nx * nx + ny * ny + 1);
        c->normals[3 * i] = (float)(nx / nl);
        c->normals[3 * i + 1] = (float)(ny / nl);
        c->normals[3 * i + 2] = (float)(1 / nl);
        uint8_t rgba[4] = {(uint8_t)(i % 256), (uint8_t)(7 * i % 256), 200, 255};
        memcpy(c->colors + 4 * i, rgba, 4);
    }
    char pp[600], cp[600];
    asp_gltf_stats sp = {0}, sc = {0};
    CHECK_OK(asp_gltf_export_cloud(c, tmp_path(pp, sizeof pp, "plain.glb"), &(asp_gltf_desc){.flags = ASP_GLTF_PLAIN},
                                   NULL, &sp, &err), &err);
    CHECK_OK(asp_gltf_export_cloud(c, tmp_path(cp, sizeof cp, "compact.glb"), NULL, NULL, &sc, &err), &err);
    CHECK_MSG(sc.file_bytes * 2 < sp.file_bytes, "compact %zu bytes, plain %zu", sc.file_bytes, sp.file_bytes);
    glb gp, gc;
    int bad = glb_read(pp, &gp) | glb_read(cp, &gc);
    CHECK(!bad);
    const cJSON *ap = cJSON_GetObjectItemCaseSensitive(at(at(gp.json, "meshes", 0), "primitives", 0), "attributes");
    const cJSON *ac = cJSON_GetObjectItemCaseSensitive(at(at(gc.json, "meshes", 0), "primitives", 0), "attributes");
    static const char *names[5] = {"NORMAL", "KHR_gaussian_splatting:ROTATION", "KHR_gaussian_splatting:SCALE",
                                   "KHR_gaussian_splatting:OPACITY", "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0"};
    const float *plain[6] = {NULL};
    size_t n = 0;
    for (int k = 0; !bad && k < 5; k++)
        plain[k] = accessor_floats(&gp, (int)num(ap, names[k]), &n);
    const float *ppos = bad ? NULL : accessor_floats(&gp, (int)num(ap, "POSITION"), &n);
    uint16_t q[4 * N];
    int8_t nrm[4 * N];
    uint8_t col[4 * N], op[4 * N];
    int16_t rot[4 * N];
    float scale[3 * N], sh[3 * N];
    bad = bad || !ppos || decode_view(&gc, (int)num(ac, "POSITION"), q, N, 8) ||
          decode_view(&gc, (int)num(ac, "NORMAL"), nrm, N, 4) || decode_view(&gc, (int)num(ac, "COLOR_0"), col, N, 4) ||
          decode_view(&gc, (int)num(ac, names[1]), rot, N, 8) ||
          decode_view(&gc, (int)num(ac, names[2]), scale, N, 12) ||
          decode_view(&gc, (int)num(ac, names[3]), op, N, 4) || decode_view(&gc, (int)num(ac, names[4]), sh, N, 12);
    CHECK_MSG(!bad, "compact views do not decode");
    const cJSON *node = at(gc.json, "nodes", 0);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(node, "translation");
    double s = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(node, "scale"), 0)->valuedouble;
    double worst_pos = 0, worst_nrm = 0, worst_rot = 0, worst_scale = 0, worst_sh = 0;
    int worst_col = 0, seen[N] = {0}, matched = 0;
    for (size_t j = 0; !bad && j < N; j++) {
        double w[3];
        for (int k = 0; k < 3; k++)
            w[k] = cJSON_GetArrayItem(t, k)->valuedouble + s * (q[4 * j + k] / 65535.0) - c->origin[k];
        // which input point: the grid cell (positions are exact to s / 2 = 2 micrometres)
        long ix = lround(w[0] / 0.01), iy = lround(w[1] / 0.01);
        if (ix < 0 || ix >= 20 || iy < 0 || iy >= 20 || seen[iy * 20 + ix]++)
            continue;
        size_t i = (size_t)(iy * 20 + ix);
        matched++;
        double dot = 0, ql = 0;
        for (int k = 0; k < 3; k++) {
            worst_pos = fmax(worst_pos, fabs(w[k] - ppos[3 * i + k]));
            worst_nrm = fmax(worst_nrm, fabs(fmax(nrm[4 * j + k] / 127.0, -1.0) - plain[0][3 * i + k]));
            // SCALE is in the node's units (ln(sigma / s)): the node's scale gives world sigma back
            worst_scale = fmax(worst_scale, fabs(scale[3 * j + k] + log(s) - plain[2][3 * i + k]));
            worst_sh = fmax(worst_sh, fabs(sh[3 * j + k] - plain[4][3 * i + k]));
            // linear colour: 8 bits of the 16-bit plain value
            int want = (int)lrint(srgb_to_linear_ref(c->colors[4 * i + k]) * 255.0);
            worst_col = abs(col[4 * j + k] - want) > worst_col ? abs(col[4 * j + k] - want) : worst_col;
        }
        for (int k = 0; k < 4; k++) {
            dot += rot[4 * j + k] / 32767.0 * plain[1][4 * i + k];
            ql += (rot[4 * j + k] / 32767.0) * (rot[4 * j + k] / 32767.0);
        }
        worst_rot = fmax(worst_rot, 1 - fabs(dot) / sqrt(ql)); // q and -q are one rotation
        CHECK(fabs(op[4 * j] / 255.0 - plain[3][i]) < 1e-6);
    }
    CHECK_MSG(matched == N, "%d of %d compact points matched a grid point", matched, N);
    CHECK_MSG(worst_pos <= 0.51 * s / 65535 + 1e-9, "position error %g (step %g)", worst_pos, s / 65535);
    CHECK_MSG(worst_nrm < 0.02, "normal error %g (8-bit octahedral)", worst_nrm);
    CHECK_MSG(worst_col <= 1, "colour error %d of 255", worst_col);
    CHECK_MSG(worst_rot < 1e-5, "rotation 1 - |q.q'| = %g (12-bit quaternion)", worst_rot);
    CHECK_MSG(worst_scale < 0.01, "ln sigma error %g (12-bit exponential)", worst_scale);
    CHECK_MSG(worst_sh < 0.01, "SH0 error %g (10-bit exponential; an sRGB step is 0.014)", worst_sh);
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(gc.json, "extensionsRequired");
    CHECK(cJSON_GetArraySize(req) == 2);
    glb_free(&gp);
    glb_free(&gc);
    asp_cloud_destroy(c);
}

static void setup(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/asp_export_gltf_%ld", base ? base : "/tmp", (long)getpid());
    CHECK_MSG(mkdir(tmpdir, 0700) == 0 || errno == EEXIST, "cannot create '%s': %s", tmpdir, strerror(errno));
}

static void cleanup(void)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_gaussian_axes), TEST_CASE(test_dps_quads),
          TEST_CASE(test_bad_arguments), TEST_CASE(test_points_utm), TEST_CASE(test_points_compact),
          TEST_FIXTURE(cleanup))
