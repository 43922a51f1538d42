/*
 * PLY reader and writer: positions of every scalar type in every encoding
 * (files built here by an independent test-side encoder), byte-exact round
 * trips of extra properties of every type, double origins, faces, lists,
 * comments, CRLF headers, and files larger than the read window.
 */
#include <float.h>
#include <stdarg.h>
#include <stdint.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

enum { ENC_ASCII, ENC_LE, ENC_BE };
static const char *const enc_names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
static const asp_ply_encoding enc_desc[] = {ASP_PLY_ASCII, ASP_PLY_BINARY_LE, ASP_PLY_BINARY_BE};

/* ---------- a test-side PLY encoder, independent of the library writer ---------- */

typedef struct sbuf {
    char *p;
    size_t len, cap;
} sbuf;

static void sb_put(sbuf *b, const void *d, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        b->cap = (b->len + n + 1) * 2;
        b->p = realloc(b->p, b->cap);
    }
    memcpy(b->p + b->len, d, n);
    b->len += n;
    b->p[b->len] = '\0';
}

static void sb_printf(sbuf *b, const char *fmt, ...)
{
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    sb_put(b, tmp, (size_t)n);
}

static int host_be(void)
{
    uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 0;
}

/* Appends v as type t; v must be representable in t. */
static void put_value(sbuf *b, int enc, asp_scalar_type t, double v, int last)
{
    if (enc == ENC_ASCII) {
        if (t == ASP_SCALAR_FLOAT32)
            sb_printf(b, "%.9g", (double)(float)v);
        else if (t == ASP_SCALAR_FLOAT64)
            sb_printf(b, "%.17g", v);
        else
            sb_printf(b, "%.0f", v);
        sb_put(b, last ? "\n" : " ", 1);
        return;
    }
    uint8_t raw[8] = {0}; // every byte is written below; gcc -O3 cannot see it through the switch
    size_t n = asp_scalar_size(t);
    switch (t) {
    case ASP_SCALAR_INT8: { int8_t x = (int8_t)v; memcpy(raw, &x, 1); break; }
    case ASP_SCALAR_UINT8: { uint8_t x = (uint8_t)v; memcpy(raw, &x, 1); break; }
    case ASP_SCALAR_INT16: { int16_t x = (int16_t)v; memcpy(raw, &x, 2); break; }
    case ASP_SCALAR_UINT16: { uint16_t x = (uint16_t)v; memcpy(raw, &x, 2); break; }
    case ASP_SCALAR_INT32: { int32_t x = (int32_t)v; memcpy(raw, &x, 4); break; }
    case ASP_SCALAR_UINT32: { uint32_t x = (uint32_t)v; memcpy(raw, &x, 4); break; }
    case ASP_SCALAR_FLOAT32: { float x = (float)v; memcpy(raw, &x, 4); break; }
    default: memcpy(raw, &v, 8); break;
    }
    if ((enc == ENC_BE) != host_be())
        for (size_t i = 0; i < n / 2; i++) {
            uint8_t s = raw[i];
            raw[i] = raw[n - 1 - i];
            raw[n - 1 - i] = s;
        }
    sb_put(b, raw, n);
}

static const asp_scalar_type all_types[] = {ASP_SCALAR_INT8,  ASP_SCALAR_UINT8,  ASP_SCALAR_INT16,
                                            ASP_SCALAR_UINT16, ASP_SCALAR_INT32, ASP_SCALAR_UINT32,
                                            ASP_SCALAR_FLOAT32, ASP_SCALAR_FLOAT64};
/* both the classic names and the sized aliases must be accepted */
static const char *const alias_names[] = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};

static void tmp_path(char *out, size_t n, const char *name)
{
    snprintf(out, n, "/tmp/asp_test_io_ply_%ld_%s", (long)getpid(), name);
}

/* ---------- tests ---------- */

static void test_positions_every_type_and_encoding(void)
{
    for (int enc = 0; enc < 3; enc++)
        for (size_t ti = 0; ti < 8; ti++) {
            asp_scalar_type t = all_types[ti];
            int is_signed = t == ASP_SCALAR_INT8 || t == ASP_SCALAR_INT16 || t == ASP_SCALAR_INT32 ||
                            t >= ASP_SCALAR_FLOAT32;
            sbuf b = {0};
            const char *tn = (ti & 1) ? alias_names[ti] : asp_scalar_name(t);
            sb_printf(&b, "ply\nformat %s 1.0\nelement vertex 6\nproperty %s x\nproperty %s y\nproperty %s z\n"
                          "end_header\n", enc_names[enc], tn, tn, tn);
            double want[6][3];
            for (int i = 0; i < 6; i++) {
                want[i][0] = is_signed ? i * 7 - 20 : i * 7;
                want[i][1] = 100 - i;
                want[i][2] = t >= ASP_SCALAR_FLOAT32 ? 0.25 * i : i;
                for (int k = 0; k < 3; k++)
                    put_value(&b, enc, t, want[i][k], k == 2);
            }
            asp_cloud *c = NULL;
            asp_error err_ = {0}, *err = &err_;
            CHECK_OK(asp_ply_read_memory(b.p, b.len, "pos.ply", NULL, &c, err), err);
            if (c) {
                CHECK(c->count == 6);
                int wide = t == ASP_SCALAR_INT32 || t == ASP_SCALAR_UINT32 || t == ASP_SCALAR_FLOAT64;
                CHECK(c->position_type == (wide ? ASP_SCALAR_FLOAT64 : ASP_SCALAR_FLOAT32));
                /* wide types take the first point (rounded) as origin */
                CHECK(c->origin[0] == (wide ? want[0][0] : 0.0));
                for (int i = 0; i < 6; i++) {
                    double w[3];
                    asp_cloud_world_position(c, (size_t)i, w);
                    for (int k = 0; k < 3; k++)
                        CHECK_MSG(w[k] == want[i][k], "enc %d type %s point %d axis %d: %g != %g", enc, tn, i, k,
                                  w[k], want[i][k]);
                }
                CHECK(c->property_count == 0 && c->normals == NULL && c->colors == NULL);
            }
            asp_cloud_destroy(c);
            free(b.p);
        }
}

/* Cloud with every standard attribute and one extra property per scalar type, holding extreme values. */
static asp_cloud *make_rich_cloud(size_t n)
{
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII | ASP_ATTR_UVS | ASP_ATTR_LABELS,
                              NULL, &c, err),
             err);
    static const double extremes[8][4] = {
        {-128, 127, 0, -1},
        {0, 255, 1, 128},
        {-32768, 32767, 0, -300},
        {0, 65535, 1, 40000},
        {-2147483648.0, 2147483647.0, 0, -123456789},
        {0, 4294967295.0, 1, 3000000000.0},
        {FLT_MAX, -FLT_MIN, 1e-40, -0.0},
        {DBL_MAX, -DBL_MIN, 4.9e-324, 0.1},
    };
    char name[32];
    uint32_t s = 12345;
    for (size_t ti = 0; ti < 8; ti++) {
        asp_property *p;
        snprintf(name, sizeof name, "extra_%s", asp_scalar_name(all_types[ti]));
        CHECK_OK(asp_cloud_add_property(c, name, all_types[ti], &p, err), err);
    }
    for (size_t ti = 0; ti < 8; ti++) {
        asp_property *p = &c->properties[ti];
        size_t sz = asp_scalar_size(p->type);
        for (size_t i = 0; i < n; i++) {
            s = s * 1664525u + 1013904223u;
            double v = i < 4 ? extremes[ti][i] : (double)(s >> 8) / 65536.0 - 100.0;
            if (all_types[ti] < ASP_SCALAR_FLOAT32)
                v = i < 4 ? v : (double)(s % 100);
            uint8_t raw[8];
            switch (p->type) {
            case ASP_SCALAR_INT8: { int8_t x = (int8_t)v; memcpy(raw, &x, 1); break; }
            case ASP_SCALAR_UINT8: { uint8_t x = (uint8_t)v; memcpy(raw, &x, 1); break; }
            case ASP_SCALAR_INT16: { int16_t x = (int16_t)v; memcpy(raw, &x, 2); break; }
            case ASP_SCALAR_UINT16: { uint16_t x = (uint16_t)v; memcpy(raw, &x, 2); break; }
            case ASP_SCALAR_INT32: { int32_t x = (int32_t)v; memcpy(raw, &x, 4); break; }
            case ASP_SCALAR_UINT32: { uint32_t x = (uint32_t)v; memcpy(raw, &x, 4); break; }
            case ASP_SCALAR_FLOAT32: { float x = (float)v; memcpy(raw, &x, 4); break; }
            default: memcpy(raw, &v, 8); break;
            }
            memcpy((uint8_t *)p->data + i * sz, raw, sz);
        }
    }
    for (size_t i = 0; i < n; i++) {
        s = s * 1664525u + 1013904223u;
        for (int k = 0; k < 3; k++) {
            c->positions[3 * i + k] = (float)((double)((s >> (k * 5)) & 0xffff) / 777.0 - 40.0);
            c->normals[3 * i + k] = k == 2 ? 1.0f / 3.0f : -0.1f * (float)k;
            c->colors[4 * i + k] = (uint8_t)(s >> (8 * k));
        }
        c->colors[4 * i + 3] = (uint8_t)(i % 3 ? 255 : i);
        c->radii[i] = 0.001f * (float)(i + 1);
        c->uvs[2 * i] = (float)i / 7.0f;
        c->uvs[2 * i + 1] = 1.0f - (float)i / 9.0f;
        c->labels[i] = (uint32_t)(i * 2654435761u);
    }
    CHECK_OK(asp_cloud_add_comment(c, "made by test_io_ply  (two spaces kept)", err), err);
    CHECK_OK(asp_cloud_add_comment(c, "", err), err);
    CHECK_OK(asp_cloud_add_obj_info(c, "scanner: none", err), err);
    return c;
}

static void check_same_cloud(const asp_cloud *a, const asp_cloud *b)
{
    CHECK(a->count == b->count);
    if (a->count != b->count)
        return;
    size_t n = a->count;
    CHECK(memcmp(a->origin, b->origin, sizeof a->origin) == 0);
    CHECK(memcmp(a->positions, b->positions, 3 * n * sizeof(float)) == 0);
    CHECK(!a->normals == !b->normals && (!a->normals || memcmp(a->normals, b->normals, 3 * n * sizeof(float)) == 0));
    CHECK(!a->colors == !b->colors && (!a->colors || memcmp(a->colors, b->colors, 4 * n) == 0));
    CHECK(!a->radii == !b->radii && (!a->radii || memcmp(a->radii, b->radii, n * sizeof(float)) == 0));
    CHECK(!a->uvs == !b->uvs && (!a->uvs || memcmp(a->uvs, b->uvs, 2 * n * sizeof(float)) == 0));
    CHECK(!a->labels == !b->labels && (!a->labels || memcmp(a->labels, b->labels, n * sizeof(uint32_t)) == 0));
    CHECK(a->property_count == b->property_count);
    for (size_t i = 0; i < a->property_count && i < b->property_count; i++) {
        const asp_property *p = &a->properties[i], *q = &b->properties[i];
        CHECK_MSG(strcmp(p->name, q->name) == 0 && p->type == q->type, "property %zu: %s/%d vs %s/%d", i, p->name,
                  (int)p->type, q->name, (int)q->type);
        if (p->type == q->type)
            CHECK_MSG(memcmp(p->data, q->data, n * asp_scalar_size(p->type)) == 0, "property '%s' bytes differ",
                      p->name);
    }
    CHECK(a->comment_count == b->comment_count && a->obj_info_count == b->obj_info_count);
    for (size_t i = 0; i < a->comment_count && i < b->comment_count; i++)
        CHECK_MSG(strcmp(a->comments[i], b->comments[i]) == 0, "comment '%s' vs '%s'", a->comments[i],
                  b->comments[i]);
    for (size_t i = 0; i < a->obj_info_count && i < b->obj_info_count; i++)
        CHECK(strcmp(a->obj_info[i], b->obj_info[i]) == 0);
    CHECK(a->face_count == b->face_count);
    if (a->face_count == b->face_count && a->face_count)
        CHECK(memcmp(a->faces, b->faces, 3 * a->face_count * sizeof(uint32_t)) == 0);
}

static void test_round_trip_every_type_every_encoding(void)
{
    asp_cloud *src = make_rich_cloud(41);
    uint32_t faces[] = {0, 1, 2, 2, 3, 40};
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_cloud_set_faces(src, faces, 2, err), err);
    for (int enc = 0; enc < 3; enc++) {
        char path[256];
        tmp_path(path, sizeof path, "rt.ply");
        CHECK_OK(asp_ply_write(src, path, &(asp_save_desc){.encoding = enc_desc[enc]}, err), err);
        asp_cloud *back = NULL;
        CHECK_OK(asp_ply_read(path, NULL, &back, err), err);
        if (back) {
            check_same_cloud(src, back);
            CHECK(back->color_type == ASP_SCALAR_UINT8 && back->position_type == ASP_SCALAR_FLOAT32);
            /* writing the read cloud again gives the same bytes: nothing is lost or reordered */
            char path2[256];
            tmp_path(path2, sizeof path2, "rt2.ply");
            CHECK_OK(asp_ply_write(back, path2, &(asp_save_desc){.encoding = enc_desc[enc]}, err), err);
            FILE *f1 = fopen(path, "rb"), *f2 = fopen(path2, "rb");
            int same = f1 && f2;
            while (same) {
                int a = fgetc(f1), b = fgetc(f2);
                same = a == b;
                if (a == EOF)
                    break;
            }
            CHECK_MSG(same, "second write differs (encoding %d)", enc);
            if (f1) fclose(f1);
            if (f2) fclose(f2);
            remove(path2);
        }
        asp_cloud_destroy(back);
        remove(path);
    }
    asp_cloud_destroy(src);
}

static void test_big_endian_matches_little_endian_bytes(void)
{
    asp_cloud *src = make_rich_cloud(9);
    char le[256], be[256];
    tmp_path(le, sizeof le, "le.ply");
    tmp_path(be, sizeof be, "be.ply");
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_ply_write(src, le, NULL, err), err);
    CHECK_OK(asp_ply_write(src, be, &(asp_save_desc){.encoding = ASP_PLY_BINARY_BE}, err), err);
    FILE *f = fopen(le, "rb");
    char head[64] = {0};
    CHECK(f && fread(head, 1, 40, f) == 40);
    if (f) fclose(f);
    CHECK(strstr(head, "binary_little_endian") != NULL); /* the default */
    f = fopen(be, "rb");
    CHECK(f && fread(head, 1, 40, f) == 40);
    if (f) fclose(f);
    CHECK(strstr(head, "binary_big_endian") != NULL);
    asp_cloud *a = NULL, *b = NULL;
    CHECK_OK(asp_ply_read(le, NULL, &a, err), err);
    CHECK_OK(asp_ply_read(be, NULL, &b, err), err);
    if (a && b)
        check_same_cloud(a, b);
    asp_cloud_destroy(a);
    asp_cloud_destroy(b);
    asp_cloud_destroy(src);
    remove(le);
    remove(be);
}

static void test_double_origin_far_from_zero(void)
{
    for (int enc = 0; enc < 3; enc++) {
        sbuf b = {0};
        sb_printf(&b, "ply\nformat %s 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                      "property float z\nend_header\n", enc_names[enc]);
        /* UTM-like coordinates: in float they would be quantised to 0.5 m; offsets keep 1/1024 */
        double xs[4] = {4500000.7, 4500001.0 + 1.0 / 1024, 4499990.5, 4500010.25};
        double ys[4] = {-612345.4, -612345.0, -612340.125, -612350.0};
        for (int i = 0; i < 4; i++) {
            put_value(&b, enc, ASP_SCALAR_FLOAT64, xs[i], 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT64, ys[i], 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT32, 0.5 * i, 1);
        }
        asp_cloud *c = NULL;
        asp_error err_ = {0}, *err = &err_;
        CHECK_OK(asp_ply_read_memory(b.p, b.len, "utm.ply", NULL, &c, err), err);
        if (c) {
            CHECK(c->origin[0] == 4500001.0 && c->origin[1] == -612345.0 && c->origin[2] == 0.0);
            CHECK(c->position_type == ASP_SCALAR_FLOAT64);
            for (int i = 0; i < 4; i++) {
                double w[3];
                asp_cloud_world_position(c, (size_t)i, w);
                /* offsets below 16 m are float-exact to 2^-20 m */
                CHECK_NEAR(w[0], xs[i], 1e-6);
                CHECK_NEAR(w[1], ys[i], 1e-6);
                CHECK(w[2] == 0.5 * i);
            }
            CHECK(c->positions[3] == (float)(1.0 / 1024)); /* point 1: x offset exactly */
            char path[256];
            tmp_path(path, sizeof path, "utm_out.ply");
            CHECK_OK(asp_ply_write(c, path, NULL, err), err);
            asp_cloud *back = NULL;
            CHECK_OK(asp_ply_read(path, NULL, &back, err), err);
            if (back)
                check_same_cloud(c, back);
            FILE *f = fopen(path, "rb");
            char head[256] = {0};
            CHECK(f && fread(head, 1, 120, f) > 0);
            if (f) fclose(f);
            CHECK(strstr(head, "property double x") != NULL);
            asp_cloud_destroy(back);
            remove(path);
        }
        asp_cloud_destroy(c);
        free(b.p);
    }
}

/* Faces before vertices, quads and a pentagon, a tristrips element and an unknown element with lists. */
static void test_faces_and_skipped_lists(void)
{
    for (int enc = 0; enc < 3; enc++) {
        sbuf b = {0};
        sb_printf(&b, "ply\r\nformat %s 1.0\r\ncomment faces first\r\n"
                      "element face 3\r\nproperty uchar flags\r\nproperty list uchar int vertex_indices\r\n"
                      "property list ushort float texcoord\r\n"
                      "element thing 2\r\nproperty list int double values\r\nproperty short tag\r\n"
                      "element vertex 6\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
                      "property list uchar uint neighbours\r\nproperty uchar red\r\nproperty uchar green\r\n"
                      "property uchar blue\r\n"
                      "element tristrips 1\r\nproperty list int int vertex_indices\r\nend_header\r\n",
                  enc_names[enc]);
        static const int polys[3][6] = {{3, 0, 1, 2}, {4, 1, 2, 3, 4}, {5, 5, 4, 3, 2, 1}};
        for (int f = 0; f < 3; f++) {
            put_value(&b, enc, ASP_SCALAR_UINT8, 7, 0);
            put_value(&b, enc, ASP_SCALAR_UINT8, polys[f][0], 0);
            for (int k = 1; k <= polys[f][0]; k++)
                put_value(&b, enc, ASP_SCALAR_INT32, polys[f][k], 0);
            put_value(&b, enc, ASP_SCALAR_UINT16, 2, 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT32, 0.5, 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT32, 0.25, 1);
        }
        for (int t = 0; t < 2; t++) {
            put_value(&b, enc, ASP_SCALAR_INT32, t, 0);
            if (t)
                put_value(&b, enc, ASP_SCALAR_FLOAT64, 3.5, 0);
            put_value(&b, enc, ASP_SCALAR_INT16, -t, 1);
        }
        for (int i = 0; i < 6; i++) {
            put_value(&b, enc, ASP_SCALAR_FLOAT32, i, 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT32, -i, 0);
            put_value(&b, enc, ASP_SCALAR_FLOAT32, 2 * i, 0);
            put_value(&b, enc, ASP_SCALAR_UINT8, i % 3, 0);
            for (int k = 0; k < i % 3; k++)
                put_value(&b, enc, ASP_SCALAR_UINT32, k, 0);
            put_value(&b, enc, ASP_SCALAR_UINT8, 10 * i, 0);
            put_value(&b, enc, ASP_SCALAR_UINT8, 10 * i + 1, 0);
            put_value(&b, enc, ASP_SCALAR_UINT8, 10 * i + 2, 1);
        }
        put_value(&b, enc, ASP_SCALAR_INT32, 4, 0);
        for (int k = 0; k < 4; k++)
            put_value(&b, enc, ASP_SCALAR_INT32, k, k == 3);
        asp_cloud *c = NULL;
        asp_error err_ = {0}, *err = &err_;
        CHECK_OK(asp_ply_read_memory(b.p, b.len, "faces.ply", NULL, &c, err), err);
        if (c) {
            /* the three polygons fanned, then the strip 0 1 2 3 as (0 1 2) and (2 1 3), the winding kept */
            static const uint32_t want[] = {0, 1, 2, 1, 2, 3, 1, 3, 4, 5, 4, 3, 5, 3, 2, 5, 2, 1, 0, 1, 2, 2, 1, 3};
            CHECK_MSG(c->face_count == 8, "encoding %d: %zu faces", enc, c->face_count);
            if (c->face_count == 8)
                CHECK(memcmp(c->faces, want, sizeof want) == 0);
            CHECK(c->count == 6 && c->colors && c->comment_count == 1);
            if (c->colors && c->count == 6)
                for (int i = 0; i < 6; i++) {
                    CHECK(c->positions[3 * i] == (float)i && c->positions[3 * i + 2] == (float)(2 * i));
                    CHECK(c->colors[4 * i] == 10 * i && c->colors[4 * i + 2] == 10 * i + 2 &&
                          c->colors[4 * i + 3] == 255);
                }
            CHECK(c->property_count == 0); /* the vertex list is skipped, not kept */
            CHECK(c->comment_count == 1 && strcmp(c->comments[0], "faces first") == 0);
        }
        asp_cloud_destroy(c);
        free(b.p);
    }
}

static void test_face_index_out_of_range(void)
{
    const char *ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    CHECK(asp_ply_read_memory(ply, strlen(ply), "f.ply", NULL, &c, err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err->msg, "line 13") && strstr(err->msg, "vertex index 3"), "%s", err->msg);
    CHECK(c == NULL);
}

/* Binary files several times the 4 MiB read window: chunk and window boundaries inside records. */
static void test_large_file_streams(void)
{
    size_t n = 350000; /* 31-byte records: 10.8 MB */
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, err), err);
    if (!c)
        return;
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            c->positions[3 * i + k] = (float)i * 0.001f + (float)k;
            c->normals[3 * i + k] = k == 1 ? 1.0f : 0.0f;
            c->colors[4 * i + k] = (uint8_t)(i + (size_t)k);
        }
        c->colors[4 * i + 3] = 255;
        c->radii[i] = (float)(i % 1000) * 1e-4f;
    }
    for (int enc = 1; enc < 3; enc++) {
        char path[256];
        tmp_path(path, sizeof path, "big.ply");
        CHECK_OK(asp_ply_write(c, path, &(asp_save_desc){.encoding = enc_desc[enc]}, err), err);
        asp_cloud *back = NULL;
        CHECK_OK(asp_ply_read(path, NULL, &back, err), err);
        if (back)
            check_same_cloud(c, back);
        asp_cloud_destroy(back);
        remove(path);
    }
    asp_cloud_destroy(c);

    /* a list inside the vertex element forces the record-by-record path across windows */
    char path[256];
    tmp_path(path, sizeof path, "biglist.ply");
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    size_t m = 400000;
    fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\nproperty float y\n"
               "property list uchar ushort misc\nproperty float z\nproperty int id\nend_header\n", m);
    for (size_t i = 0; i < m; i++) {
        sbuf b = {0};
        put_value(&b, ENC_LE, ASP_SCALAR_FLOAT32, (double)i, 0);
        put_value(&b, ENC_LE, ASP_SCALAR_FLOAT32, -(double)i, 0);
        put_value(&b, ENC_LE, ASP_SCALAR_UINT8, (double)(i % 5), 0);
        for (size_t k = 0; k < i % 5; k++)
            put_value(&b, ENC_LE, ASP_SCALAR_UINT16, 9, 0);
        put_value(&b, ENC_LE, ASP_SCALAR_FLOAT32, 0.5, 0);
        put_value(&b, ENC_LE, ASP_SCALAR_INT32, (double)i, 0);
        fwrite(b.p, 1, b.len, f);
        free(b.p);
    }
    fclose(f);
    asp_cloud *d = NULL;
    CHECK_OK(asp_ply_read(path, NULL, &d, err), err);
    if (d) {
        asp_property *id = asp_cloud_find_property(d, "id");
        CHECK(d->count == m && id && id->type == ASP_SCALAR_INT32);
        int ok = 1;
        for (size_t i = 0; i < m && id; i++) {
            int32_t v;
            memcpy(&v, (int32_t *)id->data + i, 4);
            ok &= v == (int32_t)i && d->positions[3 * i] == (float)i && d->positions[3 * i + 2] == 0.5f;
        }
        CHECK(ok);
    }
    asp_cloud_destroy(d);
    remove(path);
}

static int cancel_cb(void *user, const char *stage, double fraction)
{
    (void)stage;
    (void)fraction;
    return ++*(int *)user >= 1;
}

static void test_progress_can_cancel_and_outputs_stay(void)
{
    asp_cloud *c = make_rich_cloud(5);
    char path[256];
    tmp_path(path, sizeof path, "cancel.ply");
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_ply_write(c, path, NULL, err), err);
    int calls = 0;
    asp_context ctx = {.progress = cancel_cb, .progress_user = &calls};
    asp_cloud *sentinel = (asp_cloud *)&calls, *out = sentinel;
    CHECK(asp_ply_read(path, &ctx, &out, err) == ASP_ECANCELED);
    CHECK(out == sentinel && calls >= 1);
    out = sentinel;
    CHECK(asp_ply_read("/nonexistent/dir/x.ply", NULL, &out, err) == ASP_EIO);
    CHECK(out == sentinel && strstr(err->msg, "cannot open '/nonexistent/dir/x.ply'"));
    asp_cloud_destroy(c);
    remove(path);
}

static void test_write_rejects_clashing_names_and_leaves_no_file(void)
{
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_cloud_create(3, ASP_ATTR_COLORS, NULL, &c, err), err);
    CHECK_OK(asp_cloud_add_property(c, "red", ASP_SCALAR_UINT16, NULL, err), err);
    char path[256];
    tmp_path(path, sizeof path, "clash.ply");
    remove(path);
    CHECK(asp_ply_write(c, path, NULL, err) == ASP_EINVAL);
    CHECK(strstr(err->msg, "'red'") != NULL);
    CHECK(access(path, F_OK) != 0);
    c->property_count = 0; /* hide the clashing property (still freed by destroy below) */
    CHECK(asp_ply_write(c, "/nonexistent/dir/x.ply", NULL, err) == ASP_EIO);
    CHECK_MSG(strstr(err->msg, "/nonexistent/dir/x.ply") != NULL, "%s", err->msg);
    c->property_count = 1;
    asp_cloud_destroy(c);
}

/*
 * A pipe is refused by name before it is read (issue #13): a named FIFO would
 * block the open until a writer came, and one check for every reader keeps
 * them alike, so an anonymous pipe (/dev/fd/N) is refused the same way.
 */
static void test_refuses_a_pipe(void)
{
    int fds[2];
    CHECK(pipe(fds) == 0);
    const char *ply = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n0 0 0\n";
    CHECK(write(fds[1], ply, strlen(ply)) == (ssize_t)strlen(ply));
    close(fds[1]);
    char path[64];
    snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    int rc = asp_ply_read(path, NULL, &c, err);
    CHECK_MSG(rc == ASP_EIO && c == NULL && strstr(err->msg, path) && strstr(err->msg, "not a regular file (a FIFO)"),
              "%s", err->msg);
    close(fds[0]);
}

struct warnings {
    int count;
    char last[256];
};

static void collect_warning(void *user, const char *message)
{
    struct warnings *w = user;
    w->count++;
    snprintf(w->last, sizeof w->last, "%s", message);
}

/*
 * Blender 2.4x writes "Created by Blender ..." without 'comment': before the
 * first element it is kept as a comment with one warning; after an element
 * an unknown word (a misspelt 'property') is still an error.
 */
static void test_header_line_without_comment_keyword(void)
{
    const char *ply = "ply\nformat ascii 1.0\nCreated by Blender 2.49b - www.blender.org\nelement vertex 2\n"
                      "property float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 2 3\n";
    struct warnings w = {0};
    asp_context ctx = {.warning = collect_warning, .warning_user = &w};
    asp_cloud *c = NULL;
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_ply_read_memory(ply, strlen(ply), "blender.ply", &ctx, &c, err), err);
    CHECK(c && c->count == 2 && c->positions[5] == 3.0f);
    CHECK(c && c->comment_count == 1 && strcmp(c->comments[0], "Created by Blender 2.49b - www.blender.org") == 0);
    CHECK_MSG(w.count == 1 && strstr(w.last, "'blender.ply': line 3: header line starting 'Created' has no 'comment' "
                                             "keyword; kept as a comment"),
              "%d warnings, last '%s'", w.count, w.last);
    asp_cloud_destroy(c);
    c = NULL;
    const char *typo = "ply\nformat ascii 1.0\nelement vertex 1\nCreated by Blender\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n0 0 0\n";
    CHECK(asp_ply_read_memory(typo, strlen(typo), "typo.ply", &ctx, &c, err) == ASP_EFORMAT && c == NULL);
    CHECK_MSG(strstr(err->msg, "line 4: unknown header keyword 'Created'"), "%s", err->msg);
    CHECK(w.count == 1);
}

TEST_MAIN(TEST_CASE(test_header_line_without_comment_keyword), TEST_CASE(test_refuses_a_pipe), TEST_CASE(test_positions_every_type_and_encoding), TEST_CASE(test_round_trip_every_type_every_encoding),
          TEST_CASE(test_big_endian_matches_little_endian_bytes), TEST_CASE(test_double_origin_far_from_zero),
          TEST_CASE(test_faces_and_skipped_lists), TEST_CASE(test_face_index_out_of_range),
          TEST_CASE(test_large_file_streams), TEST_CASE(test_progress_can_cancel_and_outputs_stay),
          TEST_CASE(test_write_rejects_clashing_names_and_leaves_no_file))
