/*
 * Batched point I/O for sets larger than memory (issue 28): binary PLY and
 * LAS records decoded a window at a time (positions and colours only), and a
 * binary PLY writer. The whole-file readers (ply_read.c, las_read.c) keep
 * every property; these keep a bounded working set instead.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/point_stream.h"
#include "util/atomic_file.h"
#include "util/regular_file.h"
#include "util/banned.h"

enum { WINDOW = 1 << 23 };

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } num_type;

struct asp_point_reader {
    FILE *fp;
    const asp_context *ctx;
    char name[256];
    uint64_t count, next;
    uint64_t data_at;  /* byte offset of the first record */
    size_t record;     /* bytes per record */
    int big_endian;
    int colors;
    int las;           /* LAS: int32 X Y Z at 0, 4, 8 scaled */
    double scale[3], offset[3];
    size_t pos_at[3];
    num_type pos_type[3];
    size_t col_at[4];  /* rgb(a); alpha SIZE_MAX when absent */
    int col16;         /* LAS: 16-bit colours */
    uint8_t *buf;
};

static int host_le(void)
{
    const uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void load_bytes(uint8_t *dst, const uint8_t *src, size_t n, int swap)
{
    for (size_t i = 0; i < n; i++)
        dst[i] = swap ? src[n - 1 - i] : src[i];
}

static size_t type_size(num_type t)
{
    static const size_t s[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return s[t];
}

static double read_num(const uint8_t *p, num_type t, int swap)
{
    uint8_t b[8];
    load_bytes(b, p, type_size(t), swap);
    switch (t) {
    case T_I8: return (double)(int8_t)b[0];
    case T_U8: return (double)b[0];
    case T_I16: { int16_t v; memcpy(&v, b, 2); return v; }
    case T_U16: { uint16_t v; memcpy(&v, b, 2); return v; }
    case T_I32: { int32_t v; memcpy(&v, b, 4); return v; }
    case T_U32: { uint32_t v; memcpy(&v, b, 4); return v; }
    case T_F32: { float v; memcpy(&v, b, 4); return v; }
    case T_F64: { double v; memcpy(&v, b, 8); return v; }
    default: return 0;
    }
}

static num_type ply_type(const char *s)
{
    static const struct { const char *n; num_type t; } names[] = {
        {"char", T_I8},   {"int8", T_I8},     {"uchar", T_U8},  {"uint8", T_U8},    {"short", T_I16},
        {"int16", T_I16}, {"ushort", T_U16},  {"uint16", T_U16}, {"int", T_I32},    {"int32", T_I32},
        {"uint", T_U32},  {"uint32", T_U32},  {"float", T_F32}, {"float32", T_F32}, {"double", T_F64},
        {"float64", T_F64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(s, names[i].n) == 0)
            return names[i].t;
    return T_NONE;
}

static int open_ply(asp_point_reader *r, asp_error *err)
{
    char line[1024];
    int in_vertex = 0, seen_vertex = 0, format = 0;
    size_t at = 0;
    int have[7] = {0};
    r->col_at[3] = SIZE_MAX;
    while (fgets(line, sizeof line, r->fp)) {
        char a[64] = "", b[64] = "", c[64] = "";
        int n = sscanf(line, "%63s %63s %63s", a, b, c);
        if (n <= 0)
            continue;
        if (strcmp(a, "end_header") == 0) {
            long off = ftell(r->fp);
            if (off < 0)
                return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", r->name, strerror(errno));
            r->data_at = (uint64_t)off;
            break;
        }
        if (strcmp(a, "format") == 0) {
            if (strcmp(b, "binary_little_endian") == 0)
                format = 1;
            else if (strcmp(b, "binary_big_endian") == 0)
                format = 2;
            else
                return asp_error_set(err, ASP_EUNSUPPORTED,
                                     "'%s': PLY format '%s' is not read in batches; convert it to binary PLY first "
                                     "(amgsplat convert IN OUT.ply)", r->name, b);
        } else if (strcmp(a, "element") == 0) {
            unsigned long long cnt = strtoull(c, NULL, 10);
            if (seen_vertex && in_vertex) {
                in_vertex = 0; // elements after the vertices (faces) are never read
            } else if (strcmp(b, "vertex") == 0) {
                in_vertex = seen_vertex = 1;
                r->count = cnt;
            } else if (!seen_vertex && cnt) {
                return asp_error_set(err, ASP_EUNSUPPORTED, "'%s': element '%s' comes before 'vertex'", r->name, b);
            }
        } else if (strcmp(a, "property") == 0 && in_vertex) {
            if (strcmp(b, "list") == 0)
                return asp_error_set(err, ASP_EUNSUPPORTED, "'%s': a list property in 'vertex'", r->name);
            num_type t = ply_type(b);
            if (t == T_NONE)
                return asp_error_set(err, ASP_EFORMAT, "'%s': property '%s' has unknown type '%s'", r->name, c, b);
            static const char *want[] = {"x", "y", "z", "red", "green", "blue", "alpha"};
            for (int k = 0; k < 7; k++)
                if (strcmp(c, want[k]) == 0) {
                    if (k < 3) {
                        r->pos_at[k] = at;
                        r->pos_type[k] = t;
                    } else if (t == T_U8) {
                        r->col_at[k - 3] = at;
                    } else {
                        break;
                    }
                    have[k] = 1;
                }
            at += type_size(t);
        }
    }
    if (!format || !seen_vertex || !r->data_at)
        return asp_error_set(err, ASP_EFORMAT, "'%s': expected a binary PLY header with a 'vertex' element", r->name);
    if (!have[0] || !have[1] || !have[2])
        return asp_error_set(err, ASP_EFORMAT, "'%s': vertex has no x, y, z", r->name);
    r->colors = have[3] && have[4] && have[5];
    if (!have[6])
        r->col_at[3] = SIZE_MAX;
    r->record = at;
    r->big_endian = format == 2;
    for (int k = 0; k < 3; k++)
        r->scale[k] = 1, r->offset[k] = 0;
    return 0;
}

static uint64_t le(const uint8_t *p, int n)
{
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

static int open_las(asp_point_reader *r, asp_error *err)
{
    uint8_t h[375];
    memset(h, 0, sizeof h);
    size_t got = fread(h, 1, sizeof h, r->fp);
    if (got < 227)
        return asp_error_set(err, ASP_EFORMAT, "'%s': LAS header shorter than 227 bytes", r->name);
    unsigned minor = h[25], format = h[104] & 0x3f;
    r->data_at = le(h + 96, 4);
    r->record = (size_t)le(h + 105, 2);
    r->count = le(h + 107, 4);
    if (minor >= 4 && got >= 255 && le(h + 247, 8))
        r->count = le(h + 247, 8);
    for (int k = 0; k < 3; k++) {
        uint64_t s = le(h + 131 + 8 * k, 8), o = le(h + 155 + 8 * k, 8);
        memcpy(&r->scale[k], &s, 8);
        memcpy(&r->offset[k], &o, 8);
        r->pos_at[k] = 4 * (size_t)k;
        r->pos_type[k] = T_I32;
    }
    static const size_t color_at[11] = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 0};
    static const size_t min_record[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    if (format > 10 || r->record < min_record[format])
        return asp_error_set(err, ASP_EFORMAT, "'%s': LAS point format %u with %zu-byte records", r->name, format,
                             r->record);
    r->colors = color_at[format] != 0;
    for (int k = 0; k < 3; k++)
        r->col_at[k] = color_at[format] + 2 * (size_t)k;
    r->col_at[3] = SIZE_MAX;
    r->col16 = 1;
    r->las = 1;
    return 0;
}

int asp_point_reader_open(const char *path, const asp_context *ctx, asp_point_reader **out, asp_error *err)
{
    ASP_ASSERT(path && out);
    asp_point_reader *r = calloc(1, sizeof *r);
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    r->ctx = ctx;
    snprintf(r->name, sizeof r->name, "%s", path);
    asp_error open_err = {0, ""};
    r->fp = asp__regular_file_open(path, &open_err); // a FIFO or directory is refused, never waited on
    int rc = 0;
    if (!r->fp) {
        rc = asp_error_set(err, open_err.code, "%s", open_err.msg);
    } else {
        char magic[4] = {0};
        size_t got = fread(magic, 1, 4, r->fp);
        rewind(r->fp);
        if (got == 4 && memcmp(magic, "ply", 3) == 0)
            rc = open_ply(r, err);
        else if (got == 4 && memcmp(magic, "LASF", 4) == 0)
            rc = open_las(r, err);
        else
            rc = asp_error_set(err, ASP_EUNSUPPORTED,
                               "'%s': not binary PLY or LAS; convert it first (amgsplat convert IN OUT.ply)", path);
    }
    if (!rc) {
        if (fseeko(r->fp, 0, SEEK_END) != 0)
            rc = asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(errno));
        off_t size = ftello(r->fp);
        if (!rc && (r->record == 0 || r->count > ((uint64_t)size - r->data_at) / r->record || (uint64_t)size < r->data_at))
            rc = asp_error_set(err, ASP_EFORMAT, "'%s': %llu points of %zu bytes from byte %llu do not fit in %lld bytes",
                               path, (unsigned long long)r->count, r->record, (unsigned long long)r->data_at,
                               (long long)size);
    }
    // a batch holds at least one record: a wider one would read as the end of the points
    if (!rc && r->record > WINDOW)
        rc = asp_error_set(err, ASP_EUNSUPPORTED, "'%s': %zu-byte point records; at most %d bytes are read in batches",
                           path, r->record, (int)WINDOW);
    if (!rc && !(r->buf = malloc(WINDOW)))
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
    if (!rc)
        rc = asp_point_reader_rewind(r, err);
    if (rc) {
        asp_point_reader_close(r);
        return rc;
    }
    *out = r;
    return 0;
}

uint64_t asp_point_reader_count(const asp_point_reader *r) { return r->count; }
int asp_point_reader_has_colors(const asp_point_reader *r) { return r->colors; }

int asp_point_reader_rewind(asp_point_reader *r, asp_error *err)
{
    if (fseeko(r->fp, (off_t)r->data_at, SEEK_SET) != 0)
        return asp_error_set(err, ASP_EIO, "cannot seek '%s': %s", r->name, strerror(errno));
    r->next = 0;
    return 0;
}

int asp_point_reader_read(asp_point_reader *r, double *xyz, uint8_t *rgba, size_t cap, size_t *got, asp_error *err)
{
    size_t per = WINDOW / r->record;
    uint64_t left = r->count - r->next;
    size_t n = cap < per ? cap : per;
    if (n > left)
        n = (size_t)left;
    *got = 0;
    if (n == 0)
        return 0;
    if (fread(r->buf, r->record, n, r->fp) != n)
        return ferror(r->fp) ? asp_error_set(err, ASP_EIO, "cannot read '%s': %s", r->name, strerror(errno))
                             : asp_error_set(err, ASP_EFORMAT, "'%s': ends before point %llu", r->name,
                                             (unsigned long long)r->next);
    int swap = r->las ? !host_le() : r->big_endian == host_le();
    // the common layouts (float xyz first, native order) skip the generic decoder: it is most of the time
    int fast = !swap && !r->las && r->pos_type[0] == T_F32 && r->pos_type[1] == T_F32 && r->pos_type[2] == T_F32;
    // decoding is most of a pass's time once the file is cached: both cores share it (each point its own slots)
    int threads = asp_context_threads(r->ctx);
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= 65536)
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = r->buf + i * r->record;
        for (int k = 0; k < 3; k++) {
            if (fast) {
                float f;
                memcpy(&f, p + r->pos_at[k], 4);
                xyz[3 * i + (size_t)k] = f;
            } else {
                xyz[3 * i + (size_t)k] = read_num(p + r->pos_at[k], r->pos_type[k], swap) * r->scale[k] + r->offset[k];
            }
        }
        if (rgba) {
            uint8_t *c = rgba + 4 * i;
            if (!r->colors) {
                memset(c, 255, 4);
            } else {
                for (int k = 0; k < 3; k++)
                    c[k] = r->col16 ? (uint8_t)(le(p + r->col_at[k], 2) >> 8) : p[r->col_at[k]];
                c[3] = r->col_at[3] == SIZE_MAX ? 255 : p[r->col_at[3]];
            }
        }
    }
    r->next += n;
    *got = n;
    return 0;
}

void asp_point_reader_close(asp_point_reader *r)
{
    if (!r)
        return;
    if (r->fp)
        fclose(r->fp);
    free(r->buf);
    free(r);
}

struct asp_point_writer {
    asp__atomic_file f;
    uint64_t count, written;
    int colors;
    uint8_t *buf;
};

int asp_point_writer_open(const char *path, uint64_t count, int colors, const asp_context *ctx,
                          asp_point_writer **out, asp_error *err)
{
    (void)ctx;
    ASP_ASSERT(path && out);
    asp_point_writer *w = calloc(1, sizeof *w);
    if (!w || !(w->buf = malloc(WINDOW))) {
        free(w);
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    }
    w->count = count;
    w->colors = colors;
    int rc = asp__atomic_open(&w->f, path, err);
    if (rc) {
        free(w->buf);
        free(w);
        return rc;
    }
    fprintf(w->f.fp, "ply\nformat binary_little_endian 1.0\ncomment amgsplat point stream\nelement vertex %llu\n"
                     "property float x\nproperty float y\nproperty float z\n%send_header\n",
            (unsigned long long)count,
            colors ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "");
    *out = w;
    return 0;
}

int asp_point_writer_write(asp_point_writer *w, const float *xyz, const uint8_t *rgb, size_t n, asp_error *err)
{
    size_t rec = w->colors ? 15 : 12, per = WINDOW / rec;
    int swap = !host_le();
    for (size_t s = 0; s < n; s += per) {
        size_t m = n - s < per ? n - s : per;
        uint8_t *p = w->buf;
        for (size_t i = s; i < s + m; i++, p += rec) {
            for (int k = 0; k < 3; k++)
                load_bytes(p + 4 * k, (const uint8_t *)(xyz + 3 * i + k), 4, swap);
            if (w->colors)
                memcpy(p + 12, rgb + 3 * i, 3);
        }
        if (fwrite(w->buf, rec, m, w->f.fp) != m)
            return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", w->f.tmp, strerror(errno));
    }
    w->written += n;
    return 0;
}

void asp_point_writer_abort(asp_point_writer *w)
{
    if (!w)
        return;
    asp__atomic_abort(&w->f);
    free(w->buf);
    free(w);
}

int asp_point_writer_finish(asp_point_writer *w, asp_error *err)
{
    int rc = 0;
    if (w->written != w->count) {
        rc = asp_error_set(err, ASP_EINVAL, "'%s': %llu points written, the header says %llu", w->f.path,
                           (unsigned long long)w->written, (unsigned long long)w->count);
        asp__atomic_abort(&w->f);
    } else {
        rc = asp__atomic_commit(&w->f, err);
    }
    free(w->buf);
    free(w);
    return rc;
}
