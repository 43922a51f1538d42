/*
 * Plain-text point files: every column layout (3, 4, 6 as normals or
 * colours, 7, 9), count lines, comments, commas and CRLF, far coordinates
 * with an origin, write-read round trips, load/save by extension.
 */
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

static asp_cloud *parse(const char *text)
{
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_xyz_read_memory(text, strlen(text), "t.xyz", NULL, &c, err), err);
    return c;
}

static void test_three_columns_comments_count_crlf(void)
{
    asp_cloud *c = parse("# header comment\r\n3\r\n1 2 3\r\n\r\n// other comment\r\n4.5\t5 6\r\n-7,8;9\r\n");
    CHECK(c && c->count == 3 && !c->normals && !c->colors && c->property_count == 0);
    if (c && c->count == 3) {
        CHECK(c->positions[0] == 1.0f && c->positions[3] == 4.5f && c->positions[6] == -7.0f &&
              c->positions[8] == 9.0f);
        CHECK(c->origin[0] == 0.0);
    }
    asp_cloud_destroy(c);
}

static void test_six_columns_normals_or_colours(void)
{
    /* integer triples of unit length are normals */
    asp_cloud *c = parse("0 0 0 0 0 1\n1 0 0 1 0 0\n");
    CHECK(c && c->normals && !c->colors);
    if (c && c->normals)
        CHECK(c->normals[2] == 1.0f && c->normals[3] == 1.0f);
    asp_cloud_destroy(c);
    /* non-integers are normals */
    c = parse("0 0 0 0.6 0.8 0\n1 0 0 1 0 0\n");
    CHECK(c && c->normals && !c->colors);
    asp_cloud_destroy(c);
    /* integers 0..255, not all unit triples, are colours */
    c = parse("0 0 0 255 128 0\n1 0 0 0 0 1\n");
    CHECK(c && c->colors && !c->normals);
    if (c && c->colors) {
        CHECK(c->colors[0] == 255 && c->colors[1] == 128 && c->colors[2] == 0 && c->colors[3] == 255);
        CHECK(c->colors[6] == 1 && c->color_type == ASP_SCALAR_UINT8);
    }
    asp_cloud_destroy(c);
    /* a negative component anywhere means normals */
    c = parse("0 0 0 255 128 0\n1 0 0 0 -1 0\n");
    CHECK(c && c->normals && !c->colors);
    asp_cloud_destroy(c);
}

static void test_pts_intensity_and_nine_columns(void)
{
    asp_cloud *c = parse("2\n1 2 3 -1200 10 20 30\n4 5 6 7 40 50 60\n");
    CHECK(c && c->colors && !c->normals && c->property_count == 1);
    asp_property *p = c ? asp_cloud_find_property(c, "intensity") : NULL;
    CHECK(p && p->type == ASP_SCALAR_FLOAT32 && ((float *)p->data)[0] == -1200.0f);
    if (c && c->colors)
        CHECK(c->colors[4] == 40 && c->colors[6] == 60);
    asp_cloud_destroy(c);
    c = parse("1 2 3 42\n");
    CHECK(c && c->property_count == 1 && !c->colors);
    asp_cloud_destroy(c);
    c = parse("1 2 3 0 1 0 0.5 1 0\n");
    CHECK(c && c->normals && c->colors && c->color_type == ASP_SCALAR_FLOAT32);
    if (c && c->colors)
        CHECK(c->normals[1] == 1.0f && c->colors[0] == 128 && c->colors[1] == 255 && c->colors[2] == 0);
    asp_cloud_destroy(c);
}

static void test_far_coordinates_get_an_origin(void)
{
    asp_cloud *c = parse("500000.25 4200000.5 12.125\n500010.75 4200001.5 13\n");
    CHECK(c != NULL);
    if (!c)
        return;
    CHECK(c->origin[0] == 500006.0 && c->origin[1] == 4200001.0 && c->origin[2] == 13.0);
    double w[3];
    asp_cloud_world_position(c, 0, w);
    CHECK(w[0] == 500000.25 && w[1] == 4200000.5 && w[2] == 12.125);
    /* the text writer prints world coordinates; they read back exactly */
    char path[128];
    snprintf(path, sizeof path, "/tmp/asp_test_xyz_%ld.xyz", (long)getpid());
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_xyz_write(c, path, NULL, err), err);
    asp_cloud *back = NULL;
    CHECK_OK(asp_xyz_read(path, NULL, &back, err), err);
    if (back) {
        CHECK(memcmp(back->origin, c->origin, sizeof c->origin) == 0);
        CHECK(memcmp(back->positions, c->positions, 6 * sizeof(float)) == 0);
    }
    asp_cloud_destroy(back);
    asp_cloud_destroy(c);
    remove(path);
}

static void test_round_trip_through_every_extension(void)
{
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    size_t n = 50;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, err), err);
    if (!c)
        return;
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            c->positions[3 * i + k] = (float)i / 3.0f - (float)k * 1e-3f;
            c->colors[4 * i + k] = (uint8_t)(i * 5 + (size_t)k);
        }
        c->normals[3 * i] = 0.6f;
        c->normals[3 * i + 1] = -0.8f;
        c->normals[3 * i + 2] = 0.0f;
        c->colors[4 * i + 3] = 255;
    }
    static const char *const exts[] = {"xyz", "pts", "txt", "PLY", "ply"};
    for (int x = 0; x < 5; x++) {
        char path[128];
        snprintf(path, sizeof path, "/tmp/asp_test_xyz_rt_%ld.%s", (long)getpid(), exts[x]);
        CHECK_OK(asp_cloud_save(c, path, NULL, err), err);
        asp_cloud *back = NULL;
        CHECK_OK(asp_cloud_load(path, NULL, &back, err), err);
        if (back) {
            CHECK(back->count == n && back->normals && back->colors);
            if (back->normals && back->colors && back->count == n) {
                CHECK_MSG(memcmp(back->positions, c->positions, 3 * n * sizeof(float)) == 0, "%s", exts[x]);
                CHECK(memcmp(back->normals, c->normals, 3 * n * sizeof(float)) == 0);
                CHECK(memcmp(back->colors, c->colors, 4 * n) == 0);
            }
        }
        if (x == 1) {
            FILE *f = fopen(path, "r");
            char first[32] = {0};
            CHECK(f && fgets(first, sizeof first, f) && strcmp(first, "50\n") == 0);
            if (f)
                fclose(f);
        }
        asp_cloud_destroy(back);
        remove(path);
    }
    asp_cloud_destroy(c);
}

static void test_errors_name_the_line(void)
{
    static const struct {
        const char *text, *want;
    } cases[] = {
        {"1 2 3\n4 5 6\n7 8 9 10\n", "line 3: expected 3 values, got 4"},
        {"1 2 3 4 5\n", "line 1: expected 3, 4, 6, 7 or 9 values per line, got 5"},
        {"1 2 3 4 5 6 7 8 9 10 11\n", "got more than 9"},
        {"# c\n1 2 x3\n", "line 2: value 'x3' is not a number"},
        {"1 2 3\n1 inf 3\n", "line 2: coordinate y is infinite"},
        {"0 0 0 1 2 3 0.5 0.5 2\n", "line 1: colour values must be integers 0..255 or all in 0..1, got 0.5"},
        {"", "no points in the file"},
        {"12\n", "line 1 declares 12 points, but 0 follow"},
        {"1 1 1\n0 1 1\n1 1 1.7e74\n", "line 3: coordinate z 1.7e+74 is outside the float range"},
        {"10\n0 0 0\n1 0 0\n0 1 0\n", "line 1 declares 10 points, but 3 follow"},
        {"1000000000000\n0 0 0\n1 0 0\n0 1 0\n", "line 1 declares 1000000000000 points, but 3 follow"},
        {"# c\n\n2\n0 0 0\n", "line 3 declares 2 points, but 1 follow"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        asp_cloud *c = NULL;
        asp_error err = {0};
        int rc = asp_xyz_read_memory(cases[i].text, strlen(cases[i].text), "e.xyz", NULL, &c, &err);
        CHECK_MSG(rc == ASP_EFORMAT && c == NULL && strstr(err.msg, cases[i].want) &&
                      strncmp(err.msg, "cannot read 'e.xyz': ", 21) == 0,
                  "case %zu: rc %d '%s'", i, rc, err.msg);
        asp_cloud_destroy(c);
    }
}

/*
 * CR-only (old Mac), LF and CRLF line ends, alone and mixed, from memory and
 * from a file long enough that a CRLF falls across the reader's 64 KB window
 * (issue #13: a CR-only file loaded as one point).
 */
static void test_cr_lf_crlf_line_ends(void)
{
    static const char *const eols[] = {"\r", "\n", "\r\n"};
    for (int k = 0; k < 3; k++) {
        char text[128];
        snprintf(text, sizeof text, "3%s1 2 3%s4 5 6%s7 8 9%s", eols[k], eols[k], eols[k], eols[k]);
        asp_cloud *c = parse(text);
        CHECK_MSG(c && c->count == 3 && c->positions[8] == 9.0f, "line end %d: %zu points", k, c ? c->count : 0);
        asp_cloud_destroy(c);
    }
    asp_cloud *c = parse("1 2 3\r4 5 6\n7 8 9\r\n10 11 12");
    CHECK(c && c->count == 4 && c->positions[11] == 12.0f);
    asp_cloud_destroy(c);
    char path[64];
    snprintf(path, sizeof path, "/tmp/asp_test_cr_%d.xyz", (int)getpid());
    for (int k = 0; k < 3; k++) {
        FILE *f = fopen(path, "wb");
        CHECK(f != NULL);
        if (!f)
            return;
        const size_t n = 50000; // about 1 MB: many window refills, some splitting a CRLF
        for (size_t i = 0; i < n; i++)
            fprintf(f, "%zu 0.125 %zu%s", i, i % 7, eols[k]);
        fclose(f);
        asp_cloud *d = NULL;
        asp_error e = {0}, *err = &e;
        CHECK_OK(asp_xyz_read(path, NULL, &d, err), err);
        CHECK_MSG(d && d->count == n && d->positions[3 * (n - 1)] == (float)(n - 1) - (float)d->origin[0],
                  "line end %d: %zu points", k, d ? d->count : 0);
        asp_cloud_destroy(d);
    }
    remove(path);
}

TEST_MAIN(TEST_CASE(test_cr_lf_crlf_line_ends), TEST_CASE(test_three_columns_comments_count_crlf), TEST_CASE(test_six_columns_normals_or_colours),
          TEST_CASE(test_pts_intensity_and_nine_columns), TEST_CASE(test_far_coordinates_get_an_origin),
          TEST_CASE(test_round_trip_through_every_extension), TEST_CASE(test_errors_name_the_line))
