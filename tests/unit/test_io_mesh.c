/*
 * Mesh input through assimp: each format from tiny files written here, node
 * transforms, textures (relative, embedded, missing, override), normals, and
 * the error cases; then the real models when ASP_TEST_DATA is present.
 */
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/amgsplat.h"
#include "harness.h"

static char dir[256];

static const char *path_in(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void write_file(const char *name, const char *text)
{
    FILE *fp = fopen(path_in(name), "wb");
    if (!fp)
        return;
    fputs(text, fp);
    fclose(fp);
}

static void write_texture(const char *name)
{
    asp_image img = {0};
    asp_image_init(&img, 4, 4, NULL);
    for (int i = 0; i < 16; i++) {
        uint8_t *p = img.pixels + 4 * i;
        p[0] = (i % 4) < 2 ? 255 : 0, p[1] = 0, p[2] = (i % 4) < 2 ? 0 : 255, p[3] = 255;
    }
    asp_image_save_png(&img, path_in(name), NULL);
    asp_image_release(&img);
}

static const char quad_obj[] = "mtllib quad.mtl\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                               "usemtl checker\nf 1/1 2/2 3/3 4/4\n";

static void test_obj_with_texture(void)
{
    asp_error err_ = {0}, *err = &err_;
    write_texture("quad.png");
    write_file("quad.mtl", "newmtl checker\nKd 0.8 0.8 0.8\nmap_Kd quad.png\n");
    write_file("quad.obj", quad_obj);
    asp_mesh *m = NULL;
    CHECK_OK(asp_mesh_load(path_in("quad.obj"), NULL, NULL, &m, err), err);
    if (!m)
        return;
    CHECK(m->vertex_count == 4);
    CHECK(m->triangle_count == 2);
    CHECK(m->uvs != NULL);
    CHECK_NEAR(asp_mesh_area(m), 1.0, 1e-6);
    const asp_material *mat = &m->materials[m->material_ids[0]];
    CHECK(strcmp(mat->name, "checker") == 0);
    CHECK(mat->texture.pixels && mat->texture.width == 4 && mat->texture.height == 4);
    CHECK(mat->has_color);
    /* computed normals face +z (counter-clockwise quad) */
    for (size_t v = 0; v < m->vertex_count; v++)
        CHECK(m->normals[3 * v + 2] == 1.0f);
    /* world positions: origin + relative */
    double lo = 1e9, hi = -1e9;
    for (size_t v = 0; v < m->vertex_count; v++) {
        double x = m->origin[0] + m->positions[3 * v];
        lo = fmin(lo, x), hi = fmax(hi, x);
    }
    CHECK_NEAR(lo, 0.0, 1e-7);
    CHECK_NEAR(hi, 1.0, 1e-7);
    /* sampled points take the texture's colour by half */
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(m, &(asp_sample_desc){.points = 4000}, NULL, &c, NULL, err), err);
    size_t bad = 0;
    for (size_t i = 0; c && c->colors && i < c->count; i++) {
        double x = m->origin[0] + c->positions[3 * i];
        const uint8_t *col = c->colors + 4 * i;
        if (x > 0.13 && x < 0.37)
            bad += col[0] != 255 || col[2] != 0;
        if (x > 0.63 && x < 0.87)
            bad += col[0] != 0 || col[2] != 255;
    }
    CHECK(c && c->colors && bad == 0);
    asp_cloud_destroy(c);
    asp_mesh_destroy(m);
}

static void test_missing_texture(void)
{
    asp_error err_ = {0}, *err = &err_;
    write_file("lost.mtl", "newmtl stone\nKd 0.5 0.5 0.5\nmap_Kd textures/gone.png\n");
    char obj[sizeof quad_obj + 16];
    snprintf(obj, sizeof obj, "mtllib lost.mtl\n%s", strchr(quad_obj, '\n') + 1);
    for (char *p = strstr(obj, "checker"); p; p = NULL)
        memcpy(p, "stone  ", 7);
    write_file("lost.obj", obj);
    asp_mesh *m = NULL;
    CHECK(asp_mesh_load(path_in("lost.obj"), NULL, NULL, &m, err) == ASP_EIO);
    CHECK_MSG(strstr(err->msg, "gone.png") && strstr(err->msg, "stone") && strstr(err->msg, "--texture"), "%s",
              err->msg);
    CHECK(m == NULL);
    /* an override stands in for the missing file */
    write_texture("other.png");
    CHECK_OK(asp_mesh_load(path_in("lost.obj"), &(asp_mesh_load_desc){.texture_override = path_in("other.png")},
                           NULL, &m, err),
             err);
    CHECK(m && m->materials[m->material_ids[0]].texture.width == 4);
    asp_mesh_destroy(m);
    m = NULL;
    /* an override that does not exist is reported by name */
    CHECK(asp_mesh_load(path_in("lost.obj"), &(asp_mesh_load_desc){.texture_override = path_in("nope.png")}, NULL,
                        &m, err) == ASP_EIO);
    CHECK(strstr(err->msg, "nope.png") != NULL);
}

static void test_simple_formats(void)
{
    asp_error err_ = {0}, *err = &err_;
    /* a unit cube in OFF: 6 quads -> 12 triangles, area 6, outward normals */
    write_file("cube.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                           "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n");
    write_file("tri.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 2 0 0\nvertex 0 2 0\n"
                          "endloop\nendfacet\nendsolid t\n");
    write_file("quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                           "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0 255 0 0\n3 0 0 255 0 0\n3 1 0 255 0 0\n0 1 0 255 0 0\n4 0 1 2 3\n");
    struct {
        const char *name;
        size_t tris;
        double area;
    } cases[] = {{"cube.off", 12, 6.0}, {"tri.stl", 1, 2.0}, {"quad.ply", 2, 3.0}};
    for (size_t i = 0; i < 3; i++) {
        asp_mesh *m = NULL;
        CHECK_OK(asp_mesh_load(path_in(cases[i].name), NULL, NULL, &m, err), err);
        if (!m)
            continue;
        CHECK_MSG(m->triangle_count == cases[i].tris, "%s: %zu triangles", cases[i].name, m->triangle_count);
        CHECK_NEAR(asp_mesh_area(m), cases[i].area, 1e-5);
        if (i == 0) {
            /* outward: the normal points away from the centre (0.5,0.5,0.5) */
            int out = 1;
            for (size_t v = 0; v < m->vertex_count; v++) {
                double d = 0;
                for (int k = 0; k < 3; k++)
                    d += (m->origin[k] + m->positions[3 * v + k] - 0.5) * m->normals[3 * v + k];
                out &= d > 0;
            }
            CHECK(out);
        }
        if (i == 2) {
            CHECK(m->colors && m->colors[0] == 255 && m->colors[1] == 0);
            asp_cloud *c = NULL;
            CHECK_OK(asp_sample_mesh(m, &(asp_sample_desc){.points = 100}, NULL, &c, NULL, err), err);
            CHECK(c && c->colors && c->colors[0] == 255 && c->colors[2] == 0);
            asp_cloud_destroy(c);
        }
        asp_mesh_destroy(m);
    }
}

static void b64(const uint8_t *in, size_t n, char *out)
{
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = t[v >> 18 & 63], out[o++] = t[v >> 12 & 63];
        out[o++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? t[v & 63] : '=';
    }
    out[o] = '\0';
}

/* glTF with a node hierarchy (translate 10 then scale 2) and a data-URI PNG texture (assimp: embedded "*0"). */
static void test_gltf_transform_embedded(void)
{
    asp_error err_ = {0}, *err = &err_;
    write_texture("emb.png");
    FILE *fp = fopen(path_in("emb.png"), "rb");
    uint8_t png[4096];
    size_t npng = fp ? fread(png, 1, sizeof png, fp) : 0;
    if (fp)
        fclose(fp);
    uint8_t buf[68] = {0};
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, uv[6] = {0, 0, 1, 0, 0, 1};
    uint16_t idx[3] = {0, 1, 2};
    memcpy(buf, pos, 36), memcpy(buf + 36, uv, 24), memcpy(buf + 60, idx, 6);
    static char b_png[8192], b_buf[256], json[16384];
    b64(png, npng, b_png);
    b64(buf, sizeof buf, b_buf);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"children\":[1],\"translation\":[10,0,0]},{\"mesh\":0,\"scale\":[2,2,2]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,"
             "\"material\":0}]}],"
             "\"materials\":[{\"name\":\"emb\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
             "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],"
             "\"buffers\":[{\"byteLength\":68,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
             "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":60,\"byteLength\":6}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}",
             b_png, b_buf);
    write_file("tri.gltf", json);
    asp_mesh *m = NULL;
    CHECK_OK(asp_mesh_load(path_in("tri.gltf"), NULL, NULL, &m, err), err);
    if (!m)
        return;
    CHECK(m->triangle_count == 1);
    CHECK_NEAR(asp_mesh_area(m), 2.0, 1e-5);
    double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            double x = m->origin[k] + m->positions[3 * v + k];
            lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x);
        }
    CHECK_NEAR(lo[0], 10.0, 1e-5);
    CHECK_NEAR(hi[0], 12.0, 1e-5);
    CHECK_NEAR(hi[1], 2.0, 1e-5);
    const asp_material *mat = &m->materials[m->material_ids[0]];
    CHECK_MSG(mat->texture.pixels && mat->texture.width == 4, "texture '%s'", mat->texture_path);
    CHECK(mat->texture.pixels && mat->texture.pixels[0] == 255 && mat->texture.pixels[4 * 3 + 2] == 255);
    asp_mesh_destroy(m);
}

static void test_errors(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *m = NULL;
    CHECK(asp_mesh_load(path_in("absent.obj"), NULL, NULL, &m, err) == ASP_EIO);
    CHECK(strstr(err->msg, "absent.obj") != NULL);
    write_file("flat.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n");
    CHECK(asp_mesh_load(path_in("flat.obj"), NULL, NULL, &m, err) == ASP_EDEGENERATE);
    CHECK_MSG(strstr(err->msg, "zero surface area") && strstr(err->msg, "flat.obj"), "%s", err->msg);
    write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n");
    CHECK(asp_mesh_load(path_in("points.obj"), NULL, NULL, &m, err) < 0);
    CHECK_MSG(strstr(err->msg, "points.obj") != NULL, "%s", err->msg);
    write_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(asp_mesh_load(path_in("nan.obj"), NULL, NULL, &m, err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err->msg, "nan.obj") != NULL, "%s", err->msg);
    write_file("junk.stl", "\x01\x02 this is not a mesh");
    CHECK(asp_mesh_load(path_in("junk.stl"), NULL, NULL, &m, err) < 0);
    CHECK(strstr(err->msg, "junk.stl") != NULL);
    /* a texture override needs UVs */
    write_texture("t.png");
    write_file("nouv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(asp_mesh_load(path_in("nouv.obj"), &(asp_mesh_load_desc){.texture_override = path_in("t.png")}, NULL, &m,
                        err) == ASP_EINVAL);
    CHECK(strstr(err->msg, "texture coordinates") != NULL);
    CHECK(m == NULL);
}

static void test_real_models(void)
{
    char pbuf[1024], tbuf[1024], bbuf[1024];
    const char *p = asp_test_data(pbuf, sizeof pbuf, "spot_triangulated.obj");
    const char *t = asp_test_data(tbuf, sizeof tbuf, "spot_texture.png");
    const char *bunny = asp_test_data(bbuf, sizeof bbuf, "stanford-bunny.obj");
    if (!p || !t || !bunny)
        return;
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *m = NULL;
    CHECK_OK(asp_mesh_load(p, &(asp_mesh_load_desc){.texture_override = t}, NULL, &m, err), err);
    if (m) {
        CHECK(m->triangle_count == 5856);
        asp_cloud *c = NULL;
        CHECK_OK(asp_sample_mesh(m, &(asp_sample_desc){.points = 200000}, NULL, &c, NULL, err), err);
        /* Spot's texture: pale pink skin (red above blue) with dark patches; a grey fallback has neither */
        size_t pink = 0, dark = 0;
        for (size_t i = 0; c && c->colors && i < c->count; i++) {
            const uint8_t *q = c->colors + 4 * i;
            pink += q[0] > q[2] + 15;
            dark += q[0] < 110 && q[1] < 110 && q[2] < 110;
        }
        CHECK_MSG(c && c->count == 200000 && pink > c->count / 2 && dark > c->count / 50,
                  "%zu pink and %zu dark of 200000 points", pink, dark);
        asp_cloud_destroy(c);
        asp_mesh_destroy(m);
    }
    m = NULL;
    CHECK_OK(asp_mesh_load(bunny, NULL, NULL, &m, err), err);
    if (m) {
        CHECK(m->triangle_count == 69451);
        CHECK(m->vertex_count >= 34000 && m->vertex_count <= 35947);
        CHECK(m->uvs == NULL && m->colors == NULL);
    }
    asp_mesh_destroy(m);
}

/* Little-endian writers for the hand-made 3DS file below. */
static size_t put16(unsigned char *b, size_t o, unsigned v)
{
    b[o] = (unsigned char)(v & 0xff), b[o + 1] = (unsigned char)(v >> 8);
    return o + 2;
}

static size_t put32(unsigned char *b, size_t o, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[o + (size_t)i] = (unsigned char)(v >> (8 * i));
    return o + 4;
}

static size_t putf(unsigned char *b, size_t o, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return put32(b, o, u);
}

/*
 * A 3DS file (chunks 0x4D4D main / 0x0002 version / 0x3D3D editor / 0x4000
 * object / 0x4100 trimesh / 0x4110 vertices / 0x4120 faces) holding a tall
 * tetrahedron whose apex is at y = 10 in the file: data that is y-up, as in
 * glmark2's cat.3ds and horse.3ds. Returns the byte count.
 */
static size_t make_tall_3ds(unsigned char *b)
{
    static const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 10, 0}};
    static const unsigned f[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    const size_t vert = 6 + 2 + 4 * 12, face = 6 + 2 + 4 * 8, mesh = 6 + vert + face, obj = 6 + 5 + mesh;
    const size_t ver = 10, edit = 6 + obj, main_len = 6 + ver + edit;
    size_t o = 0;
    o = put16(b, o, 0x4D4D), o = put32(b, o, (uint32_t)main_len);
    o = put16(b, o, 0x0002), o = put32(b, o, 10), o = put32(b, o, 3);
    o = put16(b, o, 0x3D3D), o = put32(b, o, (uint32_t)edit);
    o = put16(b, o, 0x4000), o = put32(b, o, (uint32_t)obj);
    memcpy(b + o, "tall", 5), o += 5;
    o = put16(b, o, 0x4100), o = put32(b, o, (uint32_t)mesh);
    o = put16(b, o, 0x4110), o = put32(b, o, (uint32_t)vert), o = put16(b, o, 4);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            o = putf(b, o, v[i][k]);
    o = put16(b, o, 0x4120), o = put32(b, o, (uint32_t)face), o = put16(b, o, 4);
    for (int i = 0; i < 4; i++)
        o = put16(b, o, f[i][0]), o = put16(b, o, f[i][1]), o = put16(b, o, f[i][2]), o = put16(b, o, 0);
    return o;
}

/* Extent of a cloud along each axis. */
static void cloud_extent(const asp_cloud *c, double ext[3], double lo_out[3])
{
    double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
    for (size_t i = 0; i < c->count; i++)
        for (int k = 0; k < 3; k++) {
            double x = c->positions[3 * i + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
    for (int k = 0; k < 3; k++)
        ext[k] = hi[k] - lo[k], lo_out[k] = lo[k] + c->origin[k];
}

/*
 * The issue: "a 3DS model whose data is y-up lies on its side by default".
 * assimp's 3DS importer turns the scene (x,y,z) -> (x,z,-y); the loader undoes
 * it, so the sampled points stand upright along +y, the renderer's default
 * up, and the mesh records the assumption. Upper-case names load too.
 */
static void test_3ds_y_up(void)
{
    unsigned char buf[512];
    size_t n = make_tall_3ds(buf);
    FILE *fp = fopen(path_in("TALL.3DS"), "wb");
    CHECK(fp != NULL);
    if (!fp)
        return;
    fwrite(buf, 1, n, fp);
    fclose(fp);
    asp_mesh *m = NULL;
    asp_error *err = &(asp_error){0};
    CHECK_OK(asp_mesh_load(path_in("TALL.3DS"), NULL, NULL, &m, err), err);
    if (!m)
        return;
    CHECK(m->up == ASP_UP_Y);
    CHECK_MSG(strstr(m->up_rule, "3DS") != NULL, "%s", m->up_rule);
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(m, &(asp_sample_desc){.points = 3000}, NULL, &c, NULL, err), err);
    asp_mesh_destroy(m);
    if (!c)
        return;
    double ext[3], lo[3];
    cloud_extent(c, ext, lo);
    /* tallest along y, by the file's factor of 10, and standing on y = 0 (apex up, not down) */
    CHECK_MSG(ext[1] > 8.0 && ext[0] < 1.5 && ext[2] < 1.5, "extent %g %g %g", ext[0], ext[1], ext[2]);
    CHECK_NEAR(lo[1], 0.0, 0.05);
    asp_cloud_destroy(c);

    /* --up z: the same file read as z-up turns its y (the tall axis) to -z */
    m = NULL;
    CHECK_OK(asp_mesh_load(path_in("TALL.3DS"), &(asp_mesh_load_desc){.up = ASP_UP_Z}, NULL, &m, err), err);
    if (!m)
        return;
    CHECK(m->up == ASP_UP_Z);
    double zlo = 1e30, zhi = -1e30, ylo = 1e30, yhi = -1e30;
    for (size_t v = 0; v < m->vertex_count; v++) {
        double y = m->origin[1] + m->positions[3 * v + 1], z = m->origin[2] + m->positions[3 * v + 2];
        ylo = y < ylo ? y : ylo, yhi = y > yhi ? y : yhi, zlo = z < zlo ? z : zlo, zhi = z > zhi ? z : zhi;
    }
    CHECK_NEAR(zlo, -10.0, 1e-5);
    CHECK_NEAR(zhi, 0.0, 1e-5);
    CHECK_NEAR(yhi - ylo, 1.0, 1e-5); /* the file's z (depth 1) is now up */
    asp_mesh_destroy(m);
}

/* OBJ is y-up by convention and kept as it is; an upper-case .OBJ loads; a missing texture can be tolerated. */
static void test_obj_upper_case_and_missing_texture(void)
{
    write_file("UP.OBJ", "mtllib up.mtl\nv 0 0 0\nv 1 0 0\nv 0 5 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\n"
                         "f 1/1 2/2 3/3\n");
    write_file("up.mtl", "newmtl skin\nKd 0.5 0.25 1\nmap_Kd textures/absent.png\n");
    asp_mesh *m = NULL;
    asp_error *err = &(asp_error){0};
    CHECK(asp_mesh_load(path_in("UP.OBJ"), NULL, NULL, &m, err) == ASP_EIO && m == NULL);
    CHECK_MSG(strstr(err->msg, "absent.png") != NULL, "%s", err->msg);
    CHECK_OK(asp_mesh_load(path_in("UP.OBJ"), &(asp_mesh_load_desc){.allow_missing_textures = 1}, NULL, &m, err),
             err);
    if (!m)
        return;
    CHECK(m->up == ASP_UP_Y && m->uv_set_count == 1);
    CHECK(m->material_count >= 1);
    const asp_material *mt = &m->materials[m->material_ids[0]];
    CHECK(mt->texture_missing == 1 && mt->texture.pixels == NULL);
    CHECK_MSG(strstr(mt->texture_path, "absent.png") != NULL, "%s", mt->texture_path);
    CHECK_NEAR(mt->diffuse[2], 1.0, 1e-6);
    double top = m->origin[1];
    for (size_t v = 0; v < m->vertex_count; v++)
        top = fmax(top, m->origin[1] + m->positions[3 * v + 1]);
    CHECK_NEAR(top, 5.0, 1e-6);
    asp_mesh_destroy(m);
    /* a point file is not a mesh: the message says so instead of "no triangles" */
    write_file("pts.PLY", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 0 0\n");
    m = NULL;
    CHECK(asp_mesh_load(path_in("pts.PLY"), NULL, NULL, &m, err) == ASP_EUNSUPPORTED && m == NULL);
    CHECK_MSG(strstr(err->msg, "point file") && strstr(err->msg, "pts.PLY"), "%s", err->msg);
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/asp_test_mesh_XXXXXX");
    if (!mkdtemp(dir))
        snprintf(dir, sizeof dir, "/tmp");
}

static void teardown(void)
{
    const char *names[] = {"quad.png", "quad.mtl", "quad.obj", "lost.mtl", "lost.obj", "other.png", "cube.off",
                           "tri.stl", "quad.ply", "emb.png", "tri.gltf", "flat.obj", "points.obj", "nan.obj",
                           "junk.stl", "t.png", "nouv.obj", "TALL.3DS", "UP.OBJ", "up.mtl", "pts.PLY"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        remove(path_in(names[i]));
    rmdir(dir);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_obj_with_texture), TEST_CASE(test_missing_texture),
          TEST_CASE(test_simple_formats), TEST_CASE(test_gltf_transform_embedded), TEST_CASE(test_errors),
          TEST_CASE(test_3ds_y_up), TEST_CASE(test_obj_upper_case_and_missing_texture), TEST_CASE(test_real_models),
          TEST_FIXTURE(teardown))
