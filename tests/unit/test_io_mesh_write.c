/*
 * asp_mesh_save: OBJ+MTL+PNG and PLY (binary and ascii) read back through
 * asp_mesh_load with the same counts, positions, uvs, colours and texture;
 * several materials; unsupported extensions; no partial files on failure.
 */
#include <stdint.h>
#include <sys/stat.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "harness.h"

static char dir[64];

/*
 * A 3x3 grid of quads (16 vertices, 18 triangles) in the z = 0 plane with
 * uvs, colours and a 4x2 texture whose pixels all differ; triangles of the
 * right column use material 1 (blue, untextured) when two_materials.
 */
static asp_mesh *grid(int with_colors, int two_materials)
{
    asp_mesh *m = NULL;
    asp_error err = {0};
    if (asp_mesh_create(16, 18, ASP_MESH_UVS | (with_colors ? ASP_MESH_COLORS : 0), NULL, &m, &err))
        return NULL;
    m->origin[0] = 10.0, m->origin[1] = -2.0, m->origin[2] = 0.5;
    for (uint32_t y = 0; y < 4; y++)
        for (uint32_t x = 0; x < 4; x++) {
            size_t v = 4 * y + x;
            m->positions[3 * v] = (float)x * 0.5f, m->positions[3 * v + 1] = (float)y * 0.25f;
            m->positions[3 * v + 2] = 0.0f;
            m->normals[3 * v + 2] = 1.0f;
            m->uvs[2 * v] = (float)x / 3.0f, m->uvs[2 * v + 1] = (float)y / 3.0f;
            if (with_colors) {
                uint8_t c[4] = {(uint8_t)(x * 80), (uint8_t)(y * 80), 200, 255};
                memcpy(m->colors + 4 * v, c, 4);
            }
        }
    size_t t = 0;
    for (uint32_t y = 0; y < 3; y++)
        for (uint32_t x = 0; x < 3; x++) {
            uint32_t a = 4 * y + x, q[6] = {a, a + 1, a + 5, a, a + 5, a + 4};
            memcpy(m->triangles + 3 * t, q, sizeof q);
            m->material_ids[t] = m->material_ids[t + 1] = two_materials && x == 2;
            t += 2;
        }
    asp_material *mats = asp_calloc(NULL, 2, sizeof *mats);
    mats[0] = m->materials[0];
    snprintf(mats[0].name, sizeof mats[0].name, "skin tone");
    mats[0].diffuse[0] = 1.0f, mats[0].diffuse[1] = 0.5f, mats[0].diffuse[2] = 0.25f;
    asp_image_init(&mats[0].texture, 4, 2, &err);
    for (size_t i = 0; i < 4 * 2 * 4; i++)
        mats[0].texture.pixels[i] = (uint8_t)(i * 7 + 3);
    snprintf(mats[1].name, sizeof mats[1].name, "blue");
    mats[1].diffuse[2] = 1.0f, mats[1].diffuse[3] = 1.0f;
    asp_free(&m->ctx, m->materials);
    m->materials = mats;
    m->material_count = two_materials ? 2 : 1;
    return m;
}

/* Index of the vertex of b at a's vertex v's world position, or SIZE_MAX. */
static size_t find_vertex(const asp_mesh *a, size_t v, const asp_mesh *b)
{
    for (size_t w = 0; w < b->vertex_count; w++) {
        double d = 0.0;
        for (int c = 0; c < 3; c++) {
            double x = a->origin[c] + a->positions[3 * v + c] - (b->origin[c] + b->positions[3 * w + c]);
            d += x * x;
        }
        if (d < 1e-10)
            return w;
    }
    return SIZE_MAX;
}

/* Saves m to name in dir, loads it back and compares what asp_mesh_save promises. */
static void round_trip(const asp_mesh *m, const char *name, const asp_mesh_save_desc *desc, const char *texture_file)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    asp_error err = {0};
    CHECK_OK(asp_mesh_save(m, path, desc, &err), &err);
    asp_mesh *r = NULL;
    CHECK_OK(asp_mesh_load(path, NULL, NULL, &r, &err), &err);
    if (!r)
        return;
    CHECK_MSG(r->vertex_count == m->vertex_count && r->triangle_count == m->triangle_count,
              "%s: %zu vertices %zu triangles", name, r->vertex_count, r->triangle_count);
    CHECK(r->uvs != NULL);
    int pos_ok = 1, uv_ok = 1, col_ok = 1;
    for (size_t v = 0; v < m->vertex_count; v++) {
        size_t w = find_vertex(m, v, r);
        if (w == SIZE_MAX) {
            pos_ok = 0;
            continue;
        }
        if (r->uvs)
            uv_ok &= fabsf(r->uvs[2 * w] - m->uvs[2 * v]) < 1e-6f && fabsf(r->uvs[2 * w + 1] - m->uvs[2 * v + 1]) < 1e-6f;
        if (m->colors)
            for (int c = 0; c < 3; c++)
                col_ok &= r->colors && abs((int)r->colors[4 * w + c] - (int)m->colors[4 * v + c]) <= 1;
    }
    CHECK_MSG(pos_ok && uv_ok && col_ok, "%s: positions %d uvs %d colours %d", name, pos_ok, uv_ok, col_ok);
    /* the texture comes back pixel for pixel, from the file named after the output */
    const asp_image *t = NULL;
    for (size_t i = 0; i < r->material_count; i++)
        if (r->materials[i].texture.pixels)
            t = &r->materials[i].texture;
    CHECK_MSG(t && t->width == 4 && t->height == 2 &&
                  memcmp(t->pixels, m->materials[0].texture.pixels, 4 * 2 * 4) == 0,
              "%s: texture", name);
    char tex[256];
    snprintf(tex, sizeof tex, "%s/%s", dir, texture_file);
    CHECK_MSG(access(tex, R_OK) == 0, "%s missing", tex);
    CHECK(asp_mesh_area(r) > 1.124 && asp_mesh_area(r) < 1.126);
    asp_mesh_destroy(r);
}

static void test_obj_round_trip(void)
{
    asp_mesh *m = grid(1, 0);
    round_trip(m, "grid.obj", NULL, "grid.png");
    char mtl[256];
    snprintf(mtl, sizeof mtl, "%s/grid.mtl", dir);
    FILE *fp = fopen(mtl, "r");
    char text[512] = "";
    if (fp) {
        size_t n = fread(text, 1, sizeof text - 1, fp);
        text[n] = '\0';
        fclose(fp);
    }
    CHECK(strstr(text, "newmtl skin_tone") && strstr(text, "map_Kd grid.png") && strstr(text, "Kd 1 0.5 0.25"));
    asp_mesh_destroy(m);
}

static void test_ply_round_trip(void)
{
    asp_mesh *m = grid(1, 0);
    round_trip(m, "grid.ply", NULL, "grid.png");
    round_trip(m, "ascii.PLY", &(asp_mesh_save_desc){.ply_ascii = 1}, "ascii.png");
    asp_file_type ft;
    char path[256];
    snprintf(path, sizeof path, "%s/grid.ply", dir);
    CHECK(asp_file_recognise(path, &ft, NULL) == 0 && ft.kind == ASP_FILE_MESH);
    asp_mesh_destroy(m);
    m = grid(0, 0);
    round_trip(m, "nocolor.ply", NULL, "nocolor.png");
    asp_mesh_destroy(m);
}

static void test_obj_two_materials(void)
{
    asp_mesh *m = grid(0, 1);
    char path[256];
    snprintf(path, sizeof path, "%s/two.obj", dir);
    asp_error err = {0};
    CHECK_OK(asp_mesh_save(m, path, NULL, &err), &err);
    asp_mesh *r = NULL;
    CHECK_OK(asp_mesh_load(path, NULL, NULL, &r, &err), &err);
    if (r) {
        CHECK(r->triangle_count == 18);
        /* the blue material holds the right column's 6 triangles, the textured one the other 12 */
        size_t blue = 0, textured = 0;
        for (size_t t = 0; t < r->triangle_count; t++) {
            const asp_material *mat = &r->materials[r->material_ids[t]];
            blue += strcmp(mat->name, "blue") == 0 && mat->diffuse[2] > 0.99f && !mat->texture.pixels;
            textured += strcmp(mat->name, "skin_tone") == 0 && mat->texture.pixels != NULL;
        }
        CHECK_MSG(blue == 6 && textured == 12, "blue %zu textured %zu", blue, textured);
        asp_mesh_destroy(r);
    }
    asp_mesh_destroy(m);
}

static void test_bad_outputs(void)
{
    asp_mesh *m = grid(0, 0);
    asp_error err = {0};
    char path[256];
    snprintf(path, sizeof path, "%s/x.stl", dir);
    CHECK(asp_mesh_save(m, path, NULL, &err) == ASP_EUNSUPPORTED && strstr(err.msg, "mesh output is .obj or .ply"));
    snprintf(path, sizeof path, "%s/x.abc", dir);
    CHECK(asp_mesh_save(m, path, NULL, &err) == ASP_EUNSUPPORTED && strstr(err.msg, "unknown file type '.abc'"));
    snprintf(path, sizeof path, "%s/no/such/dir/x.obj", dir);
    CHECK(asp_mesh_save(m, path, NULL, &err) == ASP_EIO);
    struct stat sb;
    snprintf(path, sizeof path, "%s/x.stl", dir);
    CHECK(stat(path, &sb) != 0);
    asp_mesh_destroy(m);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/asp_test_mesh_write_XXXXXX");
    if (!mkdtemp(dir))
        snprintf(dir, sizeof dir, "/tmp");
    static const asp_test_case cases[] = {
        TEST_CASE(test_obj_round_trip),
        TEST_CASE(test_ply_round_trip),
        TEST_CASE(test_obj_two_materials),
        TEST_CASE(test_bad_outputs),
    };
    return asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
}
