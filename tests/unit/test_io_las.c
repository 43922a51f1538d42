/*
 * LAS: write-read round trips of every written point format with UTM-size
 * coordinates (every point within half a scale step, every field equal,
 * LAS -> LAS byte for byte), files built here byte by byte from the LAS 1.4
 * R15 tables (origin for |X| >= 2^23, the colour rule, typed and raw extra
 * bytes), and malformed headers that must fail with a clear message.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

static void put(uint8_t *p, uint64_t v, int bytes)
{
    for (int k = 0; k < bytes; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

static void put_f64(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    put(p, u, 8);
}

/*
 * A LAS 1.<minor> file of format fmt with n records of reclen bytes, all
 * zero but X = x0 + 1000 i, scale s, offset off (LAS 1.4 R15 Table 3).
 * Returns its size; buf must hold 375 + vlr_size + n * reclen bytes.
 */
static size_t make_las(uint8_t *buf, int minor, int fmt, size_t reclen, size_t n, double s, double off, int64_t x0,
                       const uint8_t *vlr, size_t vlr_size)
{
    size_t hs = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
    memset(buf, 0, hs + vlr_size + n * reclen);
    memcpy(buf, "LASF", 4);
    buf[24] = 1;
    buf[25] = (uint8_t)minor;
    put(buf + 94, hs, 2);
    put(buf + 96, hs + vlr_size, 4);
    put(buf + 100, vlr_size ? 1 : 0, 4);
    buf[104] = (uint8_t)fmt;
    put(buf + 105, reclen, 2);
    put(buf + 107, fmt < 6 ? n : 0, 4);
    for (int k = 0; k < 3; k++) {
        put_f64(buf + 131 + 8 * k, s);
        put_f64(buf + 155 + 8 * k, off);
    }
    if (minor >= 4)
        put(buf + 247, n, 8);
    if (vlr_size)
        memcpy(buf + hs, vlr, vlr_size); // memcpy from NULL is undefined even for 0 bytes
    for (size_t i = 0; i < n; i++)
        put(buf + hs + vlr_size + i * reclen, (uint64_t)(x0 + 1000 * (int64_t)i), 4);
    return hs + vlr_size + n * reclen;
}

static asp_cloud *read_mem(const uint8_t *b, size_t size, asp_error *err)
{
    asp_cloud *c = NULL;
    int rc = asp_las_read_memory(b, size, "t.las", NULL, &c, err);
    if (rc)
        return NULL;
    return c;
}

/* A cloud with UTM-size coordinates and every field a LAS file can carry, plus normals and a custom property. */
static asp_cloud *make_cloud(size_t n)
{
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_COLORS | ASP_ATTR_NORMALS, NULL, &c, err), err);
    if (!c)
        return NULL;
    c->origin[0] = 500000.0, c->origin[1] = 5000000.0, c->origin[2] = 300.0;
    static const struct { const char *name; asp_scalar_type type; } props[] = {
        {"intensity", ASP_SCALAR_UINT16},       {"return_number", ASP_SCALAR_UINT8},
        {"number_of_returns", ASP_SCALAR_UINT8}, {"classification", ASP_SCALAR_UINT8},
        {"user_data", ASP_SCALAR_UINT8},         {"point_source_id", ASP_SCALAR_UINT16},
        {"gps_time", ASP_SCALAR_FLOAT64},        {"scan_angle_rank", ASP_SCALAR_INT8},
        {"nir", ASP_SCALAR_UINT16},              {"height", ASP_SCALAR_FLOAT32}};
    asp_property *p[10];
    for (int k = 0; k < 10; k++)
        CHECK_OK(asp_cloud_add_property(c, props[k].name, props[k].type, &p[k], err), err);
    // each add may move the property table: look the entries up once all are added (ASan: use after free)
    for (int k = 0; k < 10; k++)
        p[k] = asp_cloud_find_property(c, props[k].name);
    for (size_t i = 0; i < n; i++) {
        // positions on the 0.001 grid give exact integers; others test the rounding
        c->positions[3 * i] = (float)(-600.0 + 1200.0 * (double)i / (double)n + 0.0004 * (double)(i % 3));
        c->positions[3 * i + 1] = (float)(400.0 * sin((double)i));
        c->positions[3 * i + 2] = (float)(0.001 * (double)(i % 90000) - 45.0);
        for (int k = 0; k < 3; k++)
            c->colors[4 * i + (size_t)k] = (uint8_t)(i * (size_t)(k + 3) % 256);
        c->colors[4 * i + 3] = 255;
        double t = 0.1 * (double)i;
        c->normals[3 * i] = (float)(cos(t) * 0.6), c->normals[3 * i + 1] = (float)(sin(t) * 0.6);
        c->normals[3 * i + 2] = 0.8f;
        ((uint16_t *)p[0]->data)[i] = (uint16_t)(i * 37);
        ((uint8_t *)p[1]->data)[i] = (uint8_t)(1 + i % 5);
        ((uint8_t *)p[2]->data)[i] = 5;
        ((uint8_t *)p[3]->data)[i] = (uint8_t)(i % 32);
        ((uint8_t *)p[4]->data)[i] = (uint8_t)(i * 7);
        ((uint16_t *)p[5]->data)[i] = (uint16_t)(i * 3);
        ((double *)p[6]->data)[i] = 2.5e8 + 0.000123 * (double)i;
        ((int8_t *)p[7]->data)[i] = (int8_t)((int)(i % 181) - 90);
        ((uint16_t *)p[8]->data)[i] = (uint16_t)(65535 - i);
        ((float *)p[9]->data)[i] = 0.25f * (float)i;
    }
    return c;
}

static double prop(const asp_cloud *c, const char *name, size_t i)
{
    const asp_property *p = asp_cloud_find_property(c, name);
    if (!p)
        return NAN;
    switch (p->type) {
    case ASP_SCALAR_INT8: return ((const int8_t *)p->data)[i];
    case ASP_SCALAR_UINT8: return ((const uint8_t *)p->data)[i];
    case ASP_SCALAR_INT16: return ((const int16_t *)p->data)[i];
    case ASP_SCALAR_UINT16: return ((const uint16_t *)p->data)[i];
    case ASP_SCALAR_UINT32: return ((const uint32_t *)p->data)[i];
    case ASP_SCALAR_FLOAT32: return ((const float *)p->data)[i];
    case ASP_SCALAR_FLOAT64: return ((const double *)p->data)[i];
    default: return NAN;
    }
}

static int same_file(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int x = fgetc(fa), y = fgetc(fb);
        same = x == y;
        if (x == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

static void test_round_trip_every_format(void)
{
    const size_t n = 3000;
    asp_cloud *src = make_cloud(n);
    if (!src)
        return;
    static const int formats[] = {0, 1, 2, 3, 6, 7, 8};
    char path[64], path2[64];
    snprintf(path, sizeof path, "/tmp/asp_test_las_%d.las", (int)getpid());
    snprintf(path2, sizeof path2, "/tmp/asp_test_las_%d_b.las", (int)getpid());
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; f++) {
        int fmt = formats[f];
        asp_error e = {0}, *err = &e;
        asp_save_desc d = {.las_format = ASP_LAS_FORMAT(fmt), .las_scale = 0.001};
        CHECK_OK(asp_las_write(src, path, &d, err), err);
        asp_cloud *c = NULL;
        CHECK_OK(asp_las_read(path, NULL, &c, err), err);
        CHECK_MSG(c && c->count == n && c->las && c->las->point_format == fmt &&
                      c->las->version_minor == (fmt >= 6 ? 4 : 2),
                  "format %d", fmt);
        if (!c || c->count != n)
            continue;
        double worst = 0;
        size_t bad_fields = 0, bad_colors = 0, bad_normals = 0;
        for (size_t i = 0; i < n; i++) {
            for (int k = 0; k < 3; k++) {
                double want = src->origin[k] + (double)src->positions[3 * i + (size_t)k];
                want = 0.001 * nearbyint(want / 0.001); // the grid point the writer rounds to
                double got = c->origin[k] + (double)c->positions[3 * i + (size_t)k];
                worst = fmax(worst, fabs(got - want));
            }
            static const char *const common[] = {"intensity", "return_number", "number_of_returns",
                                                 "classification", "user_data", "point_source_id", "height"};
            for (int k = 0; k < 7; k++)
                bad_fields += prop(c, common[k], i) != prop(src, common[k], i);
            if (fmt == 1 || fmt == 3 || fmt >= 6)
                bad_fields += prop(c, "gps_time", i) != prop(src, "gps_time", i);
            // formats 6-8 store the angle in 0.006 degree steps: whole degrees come back within half a step
            double angle = fmt >= 6 ? prop(c, "scan_angle", i) * 0.006 : prop(c, "scan_angle_rank", i);
            bad_fields += fabs(angle - prop(src, "scan_angle_rank", i)) > (fmt >= 6 ? 0.003 + 1e-9 : 0.0);
            if (fmt == 8)
                bad_fields += prop(c, "nir", i) != prop(src, "nir", i);
            if (fmt == 2 || fmt == 3 || fmt >= 7)
                bad_colors += memcmp(c->colors + 4 * i, src->colors + 4 * i, 4) != 0;
            bad_normals += !c->normals || memcmp(c->normals + 3 * i, src->normals + 3 * i, 12) != 0;
        }
        CHECK_MSG(worst <= 0.0005 * 0.25, "format %d: worst coordinate error %.3g (half step 0.0005)", fmt, worst);
        CHECK_MSG(bad_fields == 0 && bad_colors == 0 && bad_normals == 0,
                  "format %d: %zu fields, %zu colours, %zu normals differ", fmt, bad_fields, bad_colors, bad_normals);
        CHECK_MSG((fmt == 2 || fmt == 3 || fmt >= 7) == (c->colors != NULL), "format %d colours", fmt);
        fprintf(stderr, "format %d: worst coordinate error %.3g m\n", fmt, worst);
        /* LAS -> LAS: the same bytes */
        CHECK_OK(asp_las_write(c, path2, NULL, err), err);
        CHECK_MSG(same_file(path, path2), "format %d: rewriting the read file changed it", fmt);
        asp_cloud_destroy(c);
    }
    /* classification 40 does not fit format 3 (5 bits); format 7 holds it */
    ((uint8_t *)asp_cloud_find_property(src, "classification")->data)[5] = 40;
    asp_error e = {0};
    CHECK(asp_las_write(src, path, &(asp_save_desc){.las_format = ASP_LAS_FORMAT(3)}, &e) == ASP_EINVAL);
    CHECK_MSG(strstr(e.msg, "point 6: classification 40 does not fit point format 3"), "%s", e.msg);
    CHECK(asp_las_write(src, path, &(asp_save_desc){.las_format = ASP_LAS_FORMAT(5)}, &e) == ASP_EINVAL);
    /* a 1 m scale cannot hold 0.3 m steps exactly, but every point is within half a step */
    asp_cloud *c = NULL;
    CHECK_OK(asp_las_write(src, path, &(asp_save_desc){.las_scale = 1.0}, &e), &e);
    CHECK_OK(asp_las_read(path, NULL, &c, &e), &e);
    for (size_t i = 0; c && i < n; i++)
        for (int k = 0; k < 3; k++) {
            double want = src->origin[k] + (double)src->positions[3 * i + (size_t)k];
            double got = c->origin[k] + (double)c->positions[3 * i + (size_t)k];
            if (fabs(got - want) > 0.5 + 1e-6) {
                CHECK_MSG(0, "scale 1: point %zu axis %d off by %g", i, k, got - want);
                i = n;
                break;
            }
        }
    CHECK(c && c->las && c->las->point_format == 8 && c->las->scale[0] == 1.0); // colours and "nir": format 8
    asp_cloud_destroy(c);
    remove(path);
    remove(path2);
    asp_cloud_destroy(src);
}

/* X far from the offset (|X| >= 2^23): the origin moves to the data, every point stays within half a step. */
static void test_far_integers_move_the_origin(void)
{
    static uint8_t buf[375 + 20 * 100];
    // offset 0, X around 5e8 (500 km at 1 mm): float offsets from 0 would be off by up to 16 m
    size_t size = make_las(buf, 2, 0, 20, 100, 0.001, 0.0, 500000123, NULL, 0);
    asp_error e = {0};
    asp_cloud *c = read_mem(buf, size, &e);
    CHECK_MSG(c != NULL, "%s", e.msg);
    if (!c)
        return;
    CHECK(c->origin[0] != 0.0);
    double worst = 0;
    for (size_t i = 0; i < 100; i++) {
        double want = 0.001 * (double)(500000123 + 1000 * (int64_t)i);
        worst = fmax(worst, fabs(c->origin[0] + (double)c->positions[3 * i] - want));
    }
    CHECK_MSG(worst <= 0.0005, "worst %.3g", worst);
    asp_cloud_destroy(c);
}

static void test_colour_rule(void)
{
    static uint8_t buf[227 + 26 * 2];
    size_t size = make_las(buf, 2, 2, 26, 2, 0.01, 0, 0, NULL, 0);
    uint8_t *rec = buf + 227;
    put(rec + 20, 200, 2), put(rec + 22, 100, 2), put(rec + 24, 7, 2); // all <= 255: taken as they are
    put(rec + 26 + 20, 255, 2);
    asp_error e = {0};
    asp_cloud *c = read_mem(buf, size, &e);
    CHECK(c && c->colors && c->colors[0] == 200 && c->colors[1] == 100 && c->colors[2] == 7 && c->colors[3] == 255);
    asp_cloud_destroy(c);
    put(rec + 26 + 20, 0xab00 + 0x77, 2); // one value > 255: the high byte of every value
    c = read_mem(buf, size, &e);
    CHECK(c && c->colors && c->colors[0] == 0 && c->colors[4] == 0xab);
    CHECK(c && prop(c, "red16", 1) == 0xab77 && prop(c, "red16", 0) == 200);
    asp_cloud_destroy(c);
}

static void test_extra_bytes_typed_and_raw(void)
{
    /* one descriptor: int16 "h" with scale 0.01 and offset 5, then 2 bytes nothing describes */
    uint8_t vlr[54 + 192] = {0};
    memcpy(vlr + 2, "LASF_Spec", 9);
    put(vlr + 18, 4, 2);
    put(vlr + 20, 192, 2);
    uint8_t *d = vlr + 54;
    d[2] = 4;           // int16
    d[3] = 0x08 | 0x10; // scale and offset
    memcpy(d + 4, "h", 1);
    put_f64(d + 112, 0.01);
    put_f64(d + 136, 5.0);
    enum { RECLEN = 30 + 4 }; // format 6 (30 bytes) and 4 extra bytes
    static uint8_t buf[375 + sizeof vlr + RECLEN * 3];
    size_t reclen = RECLEN;
    size_t size = make_las(buf, 4, 6, reclen, 3, 0.001, 0, 0, vlr, sizeof vlr);
    uint8_t *rec = buf + 375 + sizeof vlr;
    put(rec + 30, (uint16_t)-250, 2);
    rec[32] = 0xaa, rec[33] = 0xbb;
    asp_error e = {0};
    asp_cloud *c = read_mem(buf, size, &e);
    CHECK_MSG(c != NULL, "%s", e.msg);
    if (!c)
        return;
    CHECK_NEAR(prop(c, "h", 0), -250 * 0.01 + 5.0, 1e-12);
    CHECK(prop(c, "extra_byte_2", 0) == 0xaa && prop(c, "extra_byte_3", 0) == 0xbb);
    CHECK(c->las && c->las->version_minor == 4 && c->las->point_format == 6 && c->las->vlr_count == 0);
    asp_cloud_destroy(c);
}

/* Each malformed file fails with its code and a message naming the file and what was expected. */
static void test_malformed_headers(void)
{
    static uint8_t good[375 + 30 * 4], buf[sizeof good];
    size_t size = make_las(good, 4, 6, 30, 4, 0.001, 0, 0, NULL, 0);
    struct {
        size_t at;
        int bytes;
        uint64_t value;
        size_t cut; /* file size, 0 = whole */
        int code;
        const char *text;
    } cases[] = {
        {0, 1, 'X', 0, ASP_EFORMAT, "not a LAS file"},
        {0, 0, 0, 100, ASP_EFORMAT, "truncated header: 100 bytes"},
        {24, 1, 2, 0, ASP_EUNSUPPORTED, "LAS version 2.4 (expected 1.0 to 1.4)"},
        {94, 2, 300, 0, ASP_EFORMAT, "header size 300 is less than the 375 bytes of a LAS 1.4 header"},
        {105, 2, 20, 0, ASP_EFORMAT, "point record length 20 is less than the 30 bytes of point format 6"},
        {104, 1, 11, 0, ASP_EFORMAT, "point data record format 11 (expected 0 to 10)"},
        {104, 1, 0x86, 0, ASP_EUNSUPPORTED, "compressed LAS (LASzip) needs a decompressor"},
        {247, 8, 5, 0, ASP_EFORMAT, "declares 5 points of 30 bytes from byte 375, but the file holds only 4"},
        {247, 8, UINT64_MAX, 0, ASP_EFORMAT, "the file holds only 4 whole records"},
        {0, 0, 0, 375 + 30 * 4 - 1, ASP_EFORMAT, "the file holds only 3 whole records"},
        {107, 4, 3, 0, ASP_EFORMAT, "legacy point count 3 disagrees with the 64-bit point count 4"},
        {131, 8, 0, 0, ASP_EFORMAT, "X scale factor 0 (expected a finite non-zero number)"},
        {147, 8, 0x7ff8000000000000ull, 0, ASP_EFORMAT, "Z scale factor nan"},
        {163, 8, 0x7ff0000000000000ull, 0, ASP_EFORMAT, "Y offset inf (expected a finite number)"},
        {96, 4, 10, 0, ASP_EFORMAT, "offset to point data 10 is outside the file"},
        {100, 4, 1, 0, ASP_EFORMAT, "1 VLRs do not fit between the header"},
        {243, 4, 1, 0, ASP_EFORMAT, "the first EVLR starts at byte 0"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memcpy(buf, good, size);
        put(buf + cases[k].at, cases[k].value, cases[k].bytes);
        asp_error e = {0};
        asp_cloud *c = NULL;
        int rc = asp_las_read_memory(buf, cases[k].cut ? cases[k].cut : size, "t.las", NULL, &c, &e);
        CHECK_MSG(rc == cases[k].code && c == NULL && strstr(e.msg, cases[k].text) &&
                      strncmp(e.msg, "cannot read 't.las': ", 21) == 0,
                  "case %zu: rc %d, message '%s'", k, rc, e.msg);
    }
    /* a LASzip VLR in an otherwise plain header */
    uint8_t vlr[54] = {0};
    memcpy(vlr + 2, "laszip encoded", 14);
    put(vlr + 18, 22204, 2);
    static uint8_t z[227 + 54 + 20];
    size_t zs = make_las(z, 2, 0, 20, 1, 0.01, 0, 0, vlr, sizeof vlr);
    asp_error e = {0};
    asp_cloud *c = NULL;
    CHECK(asp_las_read_memory(z, zs, "x.laz", NULL, &c, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "`laszip -i x.laz -o x.las`"), "%s", e.msg);
    asp_file_type t;
    CHECK(asp_file_recognise_memory(z, zs, "x.las", &t, NULL) == 0 && strcmp(t.format, "laz") == 0 &&
          t.kind == ASP_FILE_POINTS && t.by_magic);
    CHECK(asp_file_recognise_memory(good, size, "x.bin", &t, NULL) == 0 && strcmp(t.format, "las") == 0);
    CHECK(asp_file_recognise_memory(NULL, 0, "X.LAZ", &t, NULL) == 0 && strcmp(t.format, "laz") == 0);
}

TEST_MAIN(TEST_CASE(test_round_trip_every_format), TEST_CASE(test_far_integers_move_the_origin),
          TEST_CASE(test_colour_rule), TEST_CASE(test_extra_bytes_typed_and_raw), TEST_CASE(test_malformed_headers))
