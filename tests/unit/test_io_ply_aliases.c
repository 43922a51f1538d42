/*
 * PLY property aliases: every spelling of colours, normals, radius, uvs and
 * labels that asp_ply_read maps onto the cloud, as uchar and float colours,
 * and the cases that must stay extra properties (incomplete or mixed sets).
 */
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

/* An ascii PLY with x y z plus the given property lines and one value line tail per point (2 points). */
static asp_cloud *read_with(const char *props, const char *tail0, const char *tail1)
{
    char buf[2048];
    snprintf(buf, sizeof buf,
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n%s"
             "end_header\n0 0 0 %s\n1 2 3 %s\n",
             props, tail0, tail1);
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_ply_read_memory(buf, strlen(buf), "alias.ply", NULL, &c, err), err);
    return c;
}

static void test_colour_aliases_uchar(void)
{
    static const char *const sets[][4] = {{"red", "green", "blue", "alpha"},
                                          {"r", "g", "b", "a"},
                                          {"diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"}};
    for (int s = 0; s < 3; s++)
        for (int with_alpha = 0; with_alpha < 2; with_alpha++) {
            char props[512];
            int n = snprintf(props, sizeof props, "property uchar %s\nproperty uchar %s\nproperty uchar %s\n",
                             sets[s][0], sets[s][1], sets[s][2]);
            if (with_alpha)
                snprintf(props + n, sizeof props - (size_t)n, "property uchar %s\n", sets[s][3]);
            asp_cloud *c = read_with(props, with_alpha ? "10 20 30 40" : "10 20 30", with_alpha ? "255 0 7 128" : "255 0 7");
            CHECK(c && c->colors && c->property_count == 0 && c->color_type == ASP_SCALAR_UINT8);
            if (c && c->colors) {
                CHECK(c->colors[0] == 10 && c->colors[1] == 20 && c->colors[2] == 30);
                CHECK(c->colors[3] == (with_alpha ? 40 : 255));
                CHECK(c->colors[4] == 255 && c->colors[5] == 0 && c->colors[6] == 7);
                CHECK(c->colors[7] == (with_alpha ? 128 : 255));
            }
            asp_cloud_destroy(c);
        }
}

static void test_colour_float_zero_to_one(void)
{
    for (int dbl = 0; dbl < 2; dbl++) {
        const char *t = dbl ? "double" : "float";
        char props[256];
        snprintf(props, sizeof props, "property %s red\nproperty %s green\nproperty %s blue\n", t, t, t);
        asp_cloud *c = read_with(props, "0 0.5 1", "0.2 1.5 -1");
        CHECK(c && c->colors && c->color_type == ASP_SCALAR_FLOAT32);
        if (c && c->colors) {
            CHECK(c->colors[0] == 0 && c->colors[1] == 128 && c->colors[2] == 255 && c->colors[3] == 255);
            CHECK(c->colors[4] == 51 && c->colors[5] == 255 && c->colors[6] == 0); /* clamped */
        }
        asp_cloud_destroy(c);
    }
}

static void test_normal_radius_uv_label_aliases(void)
{
    static const char *const normals[][3] = {{"nx", "ny", "nz"}, {"normal_x", "normal_y", "normal_z"}};
    static const char *const radii[] = {"radius", "psz", "point_size"};
    static const char *const uvs[][2] = {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}};
    for (int a = 0; a < 2; a++)
        for (int r = 0; r < 3; r++)
            for (int u = 0; u < 3; u++) {
                char props[512];
                snprintf(props, sizeof props,
                         "property double %s\nproperty double %s\nproperty double %s\nproperty float %s\n"
                         "property float %s\nproperty float %s\nproperty uint label\n",
                         normals[a][0], normals[a][1], normals[a][2], radii[r], uvs[u][0], uvs[u][1]);
                asp_cloud *c = read_with(props, "0 0 1 0.25 0.5 0.75 7", "0.6 0.8 0 2 1 0 4000000000");
                CHECK(c && c->normals && c->radii && c->uvs && c->labels && c->property_count == 0);
                if (c && c->normals && c->radii && c->uvs && c->labels) {
                    CHECK(c->normals[2] == 1.0f && c->normals[3] == 0.6f && c->normals[4] == 0.8f);
                    CHECK(c->radii[0] == 0.25f && c->radii[1] == 2.0f);
                    CHECK(c->uvs[0] == 0.5f && c->uvs[1] == 0.75f && c->uvs[2] == 1.0f && c->uvs[3] == 0.0f);
                    CHECK(c->labels[0] == 7 && c->labels[1] == 4000000000u);
                }
                asp_cloud_destroy(c);
            }
}

/* Incomplete or mixed-type sets are not guessed at: they stay extra properties, in file order. */
static void test_incomplete_sets_stay_extra(void)
{
    asp_cloud *c = read_with("property uchar red\nproperty uchar green\nproperty float nx\nproperty float ny\n"
                             "property int label\nproperty ushort blue\nproperty uchar alpha\n",
                             "1 2 0.5 0.5 -3 65535 9", "3 4 0 1 5 0 8");
    CHECK(c && !c->colors && !c->normals && !c->labels && c->property_count == 7);
    if (c && c->property_count == 7) {
        CHECK(strcmp(c->properties[0].name, "red") == 0 && c->properties[0].type == ASP_SCALAR_UINT8);
        CHECK(strcmp(c->properties[4].name, "label") == 0 && c->properties[4].type == ASP_SCALAR_INT32);
        CHECK(strcmp(c->properties[5].name, "blue") == 0 && c->properties[5].type == ASP_SCALAR_UINT16);
        CHECK(((uint16_t *)c->properties[5].data)[0] == 65535);
        CHECK(((int32_t *)c->properties[4].data)[0] == -3 && ((int32_t *)c->properties[4].data)[1] == 5);
    }
    asp_cloud_destroy(c);
    /* two complete colour sets: the first spelling wins, the other is kept */
    c = read_with("property uchar r\nproperty uchar g\nproperty uchar b\n"
                  "property uchar red\nproperty uchar green\nproperty uchar blue\n",
                  "1 2 3 4 5 6", "7 8 9 10 11 12");
    CHECK(c && c->colors && c->property_count == 3);
    if (c && c->colors && c->property_count == 3) {
        CHECK(c->colors[0] == 4 && c->colors[4] == 10);
        CHECK(strcmp(c->properties[0].name, "r") == 0 && ((uint8_t *)c->properties[0].data)[1] == 7);
    }
    asp_cloud_destroy(c);
}

/* Aliased input is written back with the canonical names and reads back to the same values. */
static void test_aliases_write_canonical_names(void)
{
    asp_cloud *c = read_with("property float normal_x\nproperty float normal_y\nproperty float normal_z\n"
                             "property float diffuse_red\nproperty float diffuse_green\nproperty float diffuse_blue\n"
                             "property float psz\nproperty float s\nproperty float t\n",
                             "0 0 1 0.2 0.4 0.6 0.5 0.1 0.2", "1 0 0 1 1 1 0.25 0.3 0.4");
    CHECK(c != NULL);
    if (!c)
        return;
    char path[128];
    snprintf(path, sizeof path, "/tmp/asp_test_alias_%ld.ply", (long)getpid());
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_ply_write(c, path, &(asp_save_desc){.encoding = ASP_PLY_ASCII}, err), err);
    FILE *f = fopen(path, "rb");
    char text[2048] = {0};
    CHECK(f && fread(text, 1, sizeof text - 1, f) > 0);
    if (f)
        fclose(f);
    CHECK(strstr(text, "property float nx\n") && strstr(text, "property float red\n") &&
          strstr(text, "property float radius\n") && strstr(text, "property float texture_u\n"));
    asp_cloud *back = NULL;
    CHECK_OK(asp_ply_read(path, NULL, &back, err), err);
    if (back) {
        CHECK(memcmp(back->colors, c->colors, 8) == 0 && back->color_type == ASP_SCALAR_FLOAT32);
        CHECK(memcmp(back->normals, c->normals, 6 * sizeof(float)) == 0);
        CHECK(memcmp(back->uvs, c->uvs, 4 * sizeof(float)) == 0 && back->radii[1] == 0.25f);
    }
    asp_cloud_destroy(back);
    asp_cloud_destroy(c);
    remove(path);
}

TEST_MAIN(TEST_CASE(test_colour_aliases_uchar), TEST_CASE(test_colour_float_zero_to_one),
          TEST_CASE(test_normal_radius_uv_label_aliases), TEST_CASE(test_incomplete_sets_stay_extra),
          TEST_CASE(test_aliases_write_canonical_names))
