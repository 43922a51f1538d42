/*
 * LAS reader (ASPRS LAS 1.0-1.4, point data record formats 0-10, LAS 1.4 R15):
 * header, VLRs, EVLRs, legacy and 64-bit point counts, every record field as a
 * named property, Extra Bytes (typed by the Extra Bytes VLR, else raw), and
 * the integer coordinates put back as world = offset + scale * X with the
 * double part in asp_cloud.origin, so UTM-size scans keep every scale step.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/io.h"
#include "io/las_internal.h"
#include "util/regular_file.h"
#include "util/banned.h"

/* One destination of record bytes: a property, or a standard array (normals, radii, labels). */
typedef struct column {
    size_t offset;      /* in the record */
    unsigned bytes;     /* 1, 2, 4 or 8 */
    char kind;          /* 'u', 's', 'f' */
    unsigned shift, mask;
    int scaled;         /* Extra Bytes with scale/offset: value = raw * scale + add */
    double scale, add;
    char name[64];
    asp_scalar_type type;
    void *dst;          /* set once the cloud exists */
    size_t stride, k;   /* dst element index = i * stride + k */
} column;

typedef struct reader {
    const uint8_t *b; /* the whole file (asp_las_read_memory), or NULL: */
    FILE *fp;         /* the file, read a piece at a time (asp_las_read) */
    uint8_t *scratch; /* what fetch() read from fp */
    size_t scratch_cap;
    size_t size;      /* of the file */
    const char *name;
    const asp_context *ctx;
    asp_error *err;
    asp_las_meta *meta;
    unsigned fmt;
    size_t reclen, point_offset;
    uint64_t count;
    uint8_t *extra_vlr; /* Extra Bytes descriptors (a copy), or NULL */
    size_t extra_vlr_size;
    size_t vlr_cap;
    column cols[LAS_MAX_FIELDS + 256 + 32];
    size_t ncols;
} reader;

static int bad(reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int bad(reader *r, const char *fmt, ...)
{
    char what[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': %s", r->name, what);
}

static void copy_text(char *dst, const uint8_t *src, size_t n)
{
    size_t k = 0;
    for (; k < n && src[k]; k++)
        dst[k] = (src[k] >= 0x20 && src[k] < 0x7f) ? (char)src[k] : '?';
    dst[k] = '\0';
}

/*
 * The len bytes at file offset at (the caller has checked that they lie in
 * the file) in *out: a pointer into the memory image, or into the scratch
 * buffer, valid until the next fetch. Reading a file a piece at a time keeps
 * a scan of billions of bytes from being held twice (file and cloud).
 */
static int fetch(reader *r, uint64_t at, size_t len, const uint8_t **out)
{
    if (r->b) {
        *out = r->b + at;
        return 0;
    }
    if (len > r->scratch_cap) {
        uint8_t *grown = asp_realloc(r->ctx, r->scratch, r->scratch_cap, len);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for %zu bytes", r->name, len);
        r->scratch = grown;
        r->scratch_cap = len;
    }
    if (fseeko(r->fp, (off_t)at, SEEK_SET) != 0 || fread(r->scratch, 1, len, r->fp) != len)
        return asp_error_set(r->err, ferror(r->fp) ? ASP_EIO : ASP_EFORMAT, "cannot read '%s': byte %llu: %s", r->name,
                             (unsigned long long)at, ferror(r->fp) ? strerror(errno) : "unexpected end of file");
    *out = r->scratch;
    return 0;
}

static double get_f64(const uint8_t *p)
{
    uint64_t u = las_get(p, 8);
    double d;
    memcpy(&d, &u, 8);
    return d;
}

static int keep_vlr(reader *r, const uint8_t *h, size_t size, const uint8_t *data, int extended)
{
    asp_las_meta *m = r->meta;
    if (m->vlr_count == r->vlr_cap) {
        size_t cap = r->vlr_cap ? 2 * r->vlr_cap : 8; // doubling: a file of many small VLRs stays linear
        asp_las_vlr *grown = asp_realloc(r->ctx, m->vlrs, r->vlr_cap * sizeof *grown, cap * sizeof *grown);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        m->vlrs = grown;
        r->vlr_cap = cap;
    }
    asp_las_vlr *v = &m->vlrs[m->vlr_count];
    memset(v, 0, sizeof *v);
    copy_text(v->user_id, h + 2, 16);
    v->record_id = (uint16_t)las_get(h + 18, 2);
    copy_text(v->description, h + (extended ? 28 : 22), 32);
    v->extended = extended;
    v->size = size;
    v->data = asp_alloc(r->ctx, size ? size : 1);
    if (!v->data)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
    memcpy(v->data, data, size);
    m->vlr_count++;
    return 0;
}

/* A VLR or EVLR: the LASzip one means a compressed file, Extra Bytes describe the record tail, others are kept. */
static int take_vlr(reader *r, const uint8_t *h, size_t size, const uint8_t *data, int extended)
{
    char user[17];
    copy_text(user, h + 2, 16);
    unsigned id = (unsigned)las_get(h + 18, 2);
    if (strcmp(user, "laszip encoded") == 0)
        return asp__las_laz_error(r->name, r->err);
    if (strcmp(user, "LASF_Spec") == 0 && id == 4) {
        uint8_t *copy = asp_alloc(r->ctx, size ? size : 1);
        if (!copy)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        memcpy(copy, data, size);
        asp_free(r->ctx, r->extra_vlr); // a second one replaces the first
        r->extra_vlr = copy;
        r->extra_vlr_size = size;
        return 0;
    }
    if (strcmp(user, "LASF_Spec") == 0 && id == 65535)
        return 0; // waveform data packets: their byte offsets mean nothing once the points are written elsewhere
    return keep_vlr(r, h, size, data, extended);
}

static int read_vlrs(reader *r, size_t header_size, uint32_t nvlr)
{
    size_t at = header_size, end = r->point_offset;
    for (uint32_t i = 0; i < nvlr; i++) {
        if (end - at < LAS_VLR_HEADER)
            return bad(r, "VLR %u of %u at byte %zu: its 54-byte header runs past the point data offset %zu", i + 1,
                       nvlr, at, end);
        const uint8_t *h;
        int rc = fetch(r, at, LAS_VLR_HEADER, &h);
        if (rc)
            return rc;
        size_t len = (size_t)las_get(h + 20, 2);
        if (end - at - LAS_VLR_HEADER < len)
            return bad(r, "VLR %u of %u at byte %zu: its %zu data bytes run past the point data offset %zu", i + 1,
                       nvlr, at, len, end);
        if ((rc = fetch(r, at, LAS_VLR_HEADER + len, &h)) == 0)
            rc = take_vlr(r, h, len, h + LAS_VLR_HEADER, 0);
        if (rc)
            return rc;
        at += LAS_VLR_HEADER + len;
    }
    return 0;
}

static int read_evlrs(reader *r, uint64_t start, uint32_t n)
{
    uint64_t points_end = r->point_offset + r->count * r->reclen; // both checked against the file size
    if (n == 0)
        return 0;
    if (start < points_end || start > r->size)
        return bad(r, "the first EVLR starts at byte %llu, expected between the end of the points (%llu) and the end "
                   "of the file (%zu)",
                   (unsigned long long)start, (unsigned long long)points_end, r->size);
    size_t at = (size_t)start;
    for (uint32_t i = 0; i < n; i++) {
        if (r->size - at < LAS_EVLR_HEADER)
            return bad(r, "EVLR %u of %u at byte %zu: truncated header (60 bytes needed, %zu left)", i + 1, n, at,
                       r->size - at);
        const uint8_t *h;
        int rc = fetch(r, at, LAS_EVLR_HEADER, &h);
        if (rc)
            return rc;
        uint64_t len = las_get(h + 20, 8);
        if (len > r->size - at - LAS_EVLR_HEADER)
            return bad(r, "EVLR %u of %u at byte %zu: %llu data bytes, but only %zu are left in the file", i + 1, n,
                       at, (unsigned long long)len, r->size - at - LAS_EVLR_HEADER);
        if (las_get(h + 18, 2) == 65535 && memcmp(h + 2, "LASF_Spec", 10) == 0) {
            at += LAS_EVLR_HEADER + (size_t)len; // waveform data, dropped by take_vlr: not worth reading
            continue;
        }
        if ((rc = fetch(r, at, LAS_EVLR_HEADER + (size_t)len, &h)) == 0)
            rc = take_vlr(r, h, (size_t)len, h + LAS_EVLR_HEADER, 1);
        if (rc)
            return rc;
        at += LAS_EVLR_HEADER + (size_t)len;
    }
    return 0;
}

static column *add_column(reader *r, const char *name, asp_scalar_type type, size_t offset, unsigned bytes, char kind)
{
    if (r->ncols == sizeof r->cols / sizeof r->cols[0])
        return NULL;
    column *c = &r->cols[r->ncols++];
    memset(c, 0, sizeof *c);
    snprintf(c->name, sizeof c->name, "%s", name);
    c->type = type;
    c->offset = offset;
    c->bytes = bytes;
    c->kind = kind;
    return c;
}

/* name, made unique among the columns so far ("height", "height_2", ...). */
static void unique_name(reader *r, char *name, size_t cap)
{
    char base[64];
    snprintf(base, sizeof base, "%s", name);
    for (unsigned n = 2;; n++) {
        int clash = 0;
        for (size_t i = 0; i < r->ncols && !clash; i++)
            clash = strcmp(r->cols[i].name, name) == 0;
        if (!clash)
            return;
        snprintf(name, cap, "%.50s_%u", base, n);
    }
}

/*
 * The Extra Bytes after the format's fields: typed and named by the Extra
 * Bytes descriptors (LAS 1.4 R15 Table 24-25) where the file has them, then
 * one uint8 property "extra_byte_K" per byte nothing describes.
 */
static int plan_extra_bytes(reader *r)
{
    static const unsigned size_of[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    static const char kind_of[11] = {0, 'u', 's', 'u', 's', 'u', 's', 'u', 's', 'f', 'f'};
    static const asp_scalar_type type_of[11] = {
        ASP_SCALAR_NONE,   ASP_SCALAR_UINT8,   ASP_SCALAR_INT8,    ASP_SCALAR_UINT16,  ASP_SCALAR_INT16,  ASP_SCALAR_UINT32,
        ASP_SCALAR_INT32,  ASP_SCALAR_FLOAT64, ASP_SCALAR_FLOAT64, ASP_SCALAR_FLOAT32, ASP_SCALAR_FLOAT64};
    size_t base = asp__las_format_size(r->fmt), at = base, end = r->reclen;
    size_t ndesc = r->extra_vlr ? r->extra_vlr_size / LAS_EXTRA_DESCRIPTOR : 0;
    if (r->extra_vlr && r->extra_vlr_size % LAS_EXTRA_DESCRIPTOR)
        return bad(r, "the Extra Bytes VLR holds %zu bytes, not a multiple of the 192-byte descriptor",
                   r->extra_vlr_size);
    for (size_t d = 0; d < ndesc; d++) {
        const uint8_t *e = r->extra_vlr + d * LAS_EXTRA_DESCRIPTOR;
        unsigned type = e[2], options = e[3];
        char name[64];
        copy_text(name, e + 4, 32);
        for (char *p = name; *p; p++)
            if (*p == ' ' || *p == '?')
                *p = '_';
        if (!name[0])
            snprintf(name, sizeof name, "extra_%zu", d + 1);
        /* deprecated 11-30: arrays of 2 or 3 of the types 1-10 */
        unsigned elems = 1, t = type;
        if (type >= 11 && type <= 30) {
            elems = type <= 20 ? 2 : 3;
            t = (type - 11) % 10 + 1;
        } else if (type > 30) {
            return bad(r, "Extra Bytes descriptor %zu ('%s'): data type %u (expected 0 to 30)", d + 1, name, type);
        }
        size_t bytes = t == 0 ? options : (size_t)size_of[t] * elems;
        if (bytes == 0)
            return bad(r, "Extra Bytes descriptor %zu ('%s'): undocumented bytes with a byte count of 0", d + 1,
                       name);
        if (bytes > end - at)
            return bad(r, "Extra Bytes descriptor %zu ('%s') needs %zu bytes at record byte %zu, but records are %zu "
                       "bytes long",
                       d + 1, name, bytes, at, end);
        if (t == 0)
            elems = (unsigned)bytes;
        for (unsigned k = 0; k < elems; k++) {
            char nm[64];
            if (elems == 1)
                snprintf(nm, sizeof nm, "%s", name);
            else
                snprintf(nm, sizeof nm, "%.50s_%u", name, k);
            unique_name(r, nm, sizeof nm);
            column *c = t == 0 ? add_column(r, nm, ASP_SCALAR_UINT8, at + k, 1, 'u')
                               : add_column(r, nm, type_of[t], at + k * size_of[t], size_of[t], kind_of[t]);
            if (!c)
                return bad(r, "too many Extra Bytes fields (more than 256)");
            // options bits 3 and 4: scale and offset (LAS 1.4 R15 Table 25); the scaled value is what the field means
            if (t != 0 && (options & 0x18)) {
                c->scaled = 1;
                c->scale = options & 0x08 ? get_f64(e + 112 + 8 * (k < 3 ? k : 2)) : 1.0;
                c->add = options & 0x10 ? get_f64(e + 136 + 8 * (k < 3 ? k : 2)) : 0.0;
                c->type = ASP_SCALAR_FLOAT64;
                if (!isfinite(c->scale) || !isfinite(c->add))
                    return bad(r, "Extra Bytes descriptor %zu ('%s'): scale or offset is not finite", d + 1, name);
            }
        }
        at += bytes;
    }
    for (size_t k = at; k < end; k++) {
        char nm[64];
        snprintf(nm, sizeof nm, "extra_byte_%zu", k - base);
        unique_name(r, nm, sizeof nm);
        if (!add_column(r, nm, ASP_SCALAR_UINT8, k, 1, 'u'))
            return bad(r, "too many undescribed extra bytes per record (%zu)", end - base);
    }
    return 0;
}

static column *find_column(reader *r, const char *name, asp_scalar_type type)
{
    for (size_t i = 0; i < r->ncols; i++)
        if (strcmp(r->cols[i].name, name) == 0 && r->cols[i].type == type && !r->cols[i].scaled)
            return &r->cols[i];
    return NULL;
}

/*
 * Extra bytes named as asp_las_write names normals ("nx", "ny", "nz" float),
 * splat radii ("radius" float) and labels ("label" uint32) go back into those
 * arrays, so amgsplat's own attributes survive a LAS round trip.
 */
static int route_columns(reader *r, asp_cloud *c)
{
    column *n[3] = {find_column(r, "nx", ASP_SCALAR_FLOAT32), find_column(r, "ny", ASP_SCALAR_FLOAT32),
                    find_column(r, "nz", ASP_SCALAR_FLOAT32)};
    column *rad = find_column(r, "radius", ASP_SCALAR_FLOAT32), *lab = find_column(r, "label", ASP_SCALAR_UINT32);
    asp_error e2;
    unsigned attrs = (n[0] && n[1] && n[2] ? ASP_ATTR_NORMALS : 0) | (rad ? ASP_ATTR_RADII : 0) |
                     (lab ? ASP_ATTR_LABELS : 0);
    if (asp_cloud_add_attrs(c, attrs, &e2))
        return asp_error_set(r->err, e2.code, "cannot read '%s': %s", r->name, e2.msg);
    for (int k = 0; k < 3 && (attrs & ASP_ATTR_NORMALS); k++)
        n[k]->dst = c->normals, n[k]->stride = 3, n[k]->k = (size_t)k;
    if (rad)
        rad->dst = c->radii, rad->stride = 1;
    if (lab)
        lab->dst = c->labels, lab->stride = 1;
    for (size_t i = 0; i < r->ncols; i++) {
        column *col = &r->cols[i];
        if (col->dst)
            continue;
        asp_property *p;
        if (asp_cloud_add_property(c, col->name, col->type, &p, &e2))
            return asp_error_set(r->err, e2.code, "cannot read '%s': %s", r->name, e2.msg);
        col->stride = 1;
    }
    /* properties may move while they are added: take the data pointers afterwards */
    for (size_t i = 0; i < r->ncols; i++)
        if (!r->cols[i].dst)
            r->cols[i].dst = asp_cloud_find_property(c, r->cols[i].name)->data;
    return 0;
}

static double field_value(const column *c, const uint8_t *rec)
{
    uint64_t u = las_get(rec + c->offset, c->bytes);
    double v;
    if (c->kind == 'f') {
        if (c->bytes == 4) {
            uint32_t u32 = (uint32_t)u;
            float f;
            memcpy(&f, &u32, 4);
            v = f;
        } else {
            memcpy(&v, &u, 8);
        }
    } else if (c->kind == 's') {
        unsigned bits = 8 * c->bytes;
        int64_t s = bits == 64 ? (int64_t)u : (int64_t)(u ^ (1ull << (bits - 1))) - (int64_t)(1ull << (bits - 1));
        v = (double)s;
    } else {
        if (c->mask)
            u = (u >> c->shift) & c->mask;
        v = (double)u;
    }
    return c->scaled ? v * c->scale + c->add : v;
}

static void store(const column *c, size_t i, double v)
{
    size_t at = i * c->stride + c->k;
    switch (c->type) {
    case ASP_SCALAR_INT8: ((int8_t *)c->dst)[at] = (int8_t)v; break;
    case ASP_SCALAR_UINT8: ((uint8_t *)c->dst)[at] = (uint8_t)v; break;
    case ASP_SCALAR_INT16: ((int16_t *)c->dst)[at] = (int16_t)v; break;
    case ASP_SCALAR_UINT16: ((uint16_t *)c->dst)[at] = (uint16_t)v; break;
    case ASP_SCALAR_INT32: ((int32_t *)c->dst)[at] = (int32_t)v; break;
    case ASP_SCALAR_UINT32: ((uint32_t *)c->dst)[at] = (uint32_t)v; break;
    case ASP_SCALAR_FLOAT32: ((float *)c->dst)[at] = (float)v; break;
    case ASP_SCALAR_FLOAT64: ((double *)c->dst)[at] = v; break;
    default: break;
    }
}

/*
 * Every record, a chunk at a time: the fields into their columns, the
 * integer coordinates into the position array as int32 bit patterns (the
 * same 4 bytes a float takes), for fill_positions to turn into floats once
 * the range is known.
 */
static int decode_records(reader *r, asp_cloud *c)
{
    enum { CHUNK_RECORDS = 1 << 14 };
    for (size_t first = 0; first < c->count; first += CHUNK_RECORDS) {
        size_t n = c->count - first < CHUNK_RECORDS ? c->count - first : CHUNK_RECORDS;
        const uint8_t *rec;
        int rc = fetch(r, r->point_offset + (uint64_t)first * r->reclen, n * r->reclen, &rec);
        if (rc)
            return rc;
        for (size_t j = 0; j < n; j++, rec += r->reclen) {
            memcpy(&c->positions[3 * (first + j)], rec, 12);
            for (size_t col = 0; col < r->ncols; col++)
                store(&r->cols[col], first + j, field_value(&r->cols[col], rec));
        }
        if ((rc = asp_progress(r->ctx, "read LAS", (double)(first + n) / (double)c->count)))
            return asp_error_set(r->err, rc, "cannot read '%s': canceled", r->name);
    }
    return 0;
}

/* The int32 a record's coordinate k of point i is (decode_records left it in the position array). */
static int64_t stored_int(const asp_cloud *c, size_t i, int k)
{
    uint8_t b[4];
    memcpy(b, &c->positions[3 * i + (size_t)k], 4);
    return (int32_t)(uint32_t)las_get(b, 4);
}

/*
 * world = offset + scale * X. Where every |X| < 2^23 the offset is the
 * origin and the float X * scale is within half a scale step (24-bit
 * significand); otherwise the origin moves to the middle integer of the
 * data so that spans up to 2^24 steps keep that bound.
 */
static int fill_positions(reader *r, asp_cloud *c)
{
    const asp_las_meta *m = r->meta;
    for (int k = 0; k < 3; k++) {
        int64_t lo = INT32_MAX, hi = INT32_MIN;
        for (size_t i = 0; i < c->count; i++) {
            int64_t x = stored_int(c, i, k);
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
        int64_t mid = 0;
        if (c->count && (lo <= -(1 << 23) || hi >= (1 << 23)))
            mid = lo + (hi - lo) / 2;
        c->origin[k] = m->offset[k] + (double)mid * m->scale[k];
        if (!isfinite(c->origin[k]))
            return bad(r, "%c offset %g plus the coordinates at scale %g is not a finite number", "XYZ"[k],
                       m->offset[k], m->scale[k]);
        for (size_t i = 0; i < c->count; i++) {
            int64_t x = stored_int(c, i, k);
            double v = (double)(x - mid) * m->scale[k];
            if (!(fabs(v) <= 3.4e38))
                return bad(r, "point %zu of %zu: %c coordinate %lld at scale %g is outside the float range", i + 1,
                           c->count, "XYZ"[k], (long long)x, m->scale[k]);
            c->positions[3 * i + (size_t)k] = (float)v;
        }
    }
    return 0;
}

/*
 * 16-bit RGB to 8-bit colours. The specification says to scale colours to
 * 16 bits, but many writers store 0..255; so the high byte is taken when any
 * value of the file exceeds 255, the values as they are otherwise
 * (docs/las.md). The 16-bit values stay as red16/green16/blue16.
 */
static void fill_colors(asp_cloud *c)
{
    const uint16_t *rgb[3] = {asp_cloud_find_property(c, "red16")->data, asp_cloud_find_property(c, "green16")->data,
                              asp_cloud_find_property(c, "blue16")->data};
    int shift = 0;
    for (size_t i = 0; i < c->count && !shift; i++)
        shift = rgb[0][i] > 255 || rgb[1][i] > 255 || rgb[2][i] > 255;
    for (size_t i = 0; i < c->count; i++) {
        for (int k = 0; k < 3; k++)
            c->colors[4 * i + (size_t)k] = (uint8_t)(shift ? rgb[k][i] >> 8 : rgb[k][i]);
        c->colors[4 * i + 3] = 255;
    }
}

static int read_header(reader *r)
{
    uint8_t h[LAS_HEADER_14] = {0}; // a copy: later fetches reuse the scratch buffer
    const uint8_t *head = NULL; // set by fetch on success (gcc -O3 cannot see it)
    int rc = fetch(r, 0, r->size < LAS_HEADER_14 ? r->size : LAS_HEADER_14, &head);
    if (rc)
        return rc;
    if (r->size) // an empty file fetches nothing: memcpy from NULL, even of 0 bytes, is undefined (UBSan, issue #31)
        memcpy(h, head, r->size < LAS_HEADER_14 ? r->size : LAS_HEADER_14);
    asp_las_meta *m = r->meta;
    if (r->size < 4 || memcmp(h, "LASF", 4) != 0)
        return bad(r, "not a LAS file (the first 4 bytes are not 'LASF')");
    if (r->size < LAS_HEADER_12)
        return bad(r, "truncated header: %zu bytes, a LAS header has at least 227", r->size);
    if (h[LASH_VERSION] != 1 || h[LASH_VERSION + 1] > 4)
        return asp_error_set(r->err, ASP_EUNSUPPORTED, "cannot read '%s': LAS version %u.%u (expected 1.0 to 1.4)",
                             r->name, h[LASH_VERSION], h[LASH_VERSION + 1]);
    unsigned minor = h[LASH_VERSION + 1];
    size_t need = minor >= 4 ? LAS_HEADER_14 : minor == 3 ? LAS_HEADER_13 : LAS_HEADER_12;
    size_t header_size = (size_t)las_get(h + LASH_HEADER_SIZE, 2);
    if (header_size < need)
        return bad(r, "header size %zu is less than the %zu bytes of a LAS 1.%u header", header_size, need, minor);
    if (header_size > r->size)
        return bad(r, "truncated header: the header has %zu bytes, the file %zu", header_size, r->size);
    unsigned fmt = h[LASH_FORMAT];
    if (fmt & 0xc0)
        return asp__las_laz_error(r->name, r->err); // LASzip sets bit 7 (and 6) of the format byte
    if (fmt > LAS_MAX_FORMAT)
        return bad(r, "point data record format %u (expected 0 to 10)", fmt);
    r->fmt = fmt;
    r->reclen = (size_t)las_get(h + LASH_RECORD_LENGTH, 2);
    if (r->reclen < asp__las_format_size(fmt))
        return bad(r, "point record length %zu is less than the %zu bytes of point format %u", r->reclen,
                   asp__las_format_size(fmt), fmt);
    r->point_offset = (size_t)las_get(h + LASH_POINT_OFFSET, 4);
    if (r->point_offset < header_size || r->point_offset > r->size)
        return bad(r, "offset to point data %zu is outside the file (expected %zu to %zu)", r->point_offset,
                   header_size, r->size);
    uint64_t legacy = las_get(h + LASH_LEGACY_COUNT, 4), count = legacy;
    if (minor >= 4) {
        uint64_t wide = las_get(h + LASH_COUNT, 8);
        if (legacy && wide && legacy != wide)
            return bad(r, "the legacy point count %llu disagrees with the 64-bit point count %llu",
                       (unsigned long long)legacy, (unsigned long long)wide);
        count = wide ? wide : legacy;
    }
    size_t room = (r->size - r->point_offset) / r->reclen;
    if (count > room)
        return bad(r, "the header declares %llu points of %zu bytes from byte %zu, but the file holds only %zu whole "
                   "records",
                   (unsigned long long)count, r->reclen, r->point_offset, room);
    if (count > UINT32_MAX)
        return asp_error_set(r->err, ASP_EUNSUPPORTED, "cannot read '%s': %llu points (at most 4294967295)", r->name,
                             (unsigned long long)count);
    r->count = count;
    for (int k = 0; k < 3; k++) {
        m->scale[k] = get_f64(h + LASH_SCALE + 8 * k);
        m->offset[k] = get_f64(h + LASH_OFFSET + 8 * k);
        m->max[k] = get_f64(h + LASH_MAX_X + 16 * k);
        m->min[k] = get_f64(h + LASH_MAX_X + 16 * k + 8);
        if (!isfinite(m->scale[k]) || m->scale[k] == 0.0)
            return bad(r, "%c scale factor %g (expected a finite non-zero number)", "XYZ"[k], m->scale[k]);
        if (!isfinite(m->offset[k]))
            return bad(r, "%c offset %g (expected a finite number)", "XYZ"[k], m->offset[k]);
    }
    m->version_minor = (uint8_t)minor;
    m->point_format = (uint8_t)fmt;
    m->record_length = (uint16_t)r->reclen;
    m->file_source_id = (uint16_t)las_get(h + LASH_SOURCE_ID, 2);
    m->global_encoding = (uint16_t)las_get(h + LASH_ENCODING, 2);
    memcpy(m->guid, h + LASH_GUID, 16);
    copy_text(m->system_id, h + LASH_SYSTEM, 32);
    copy_text(m->software, h + LASH_SOFTWARE, 32);
    m->creation_day = (uint16_t)las_get(h + LASH_DAY, 2);
    m->creation_year = (uint16_t)las_get(h + LASH_YEAR, 2);
    m->point_count = count;
    for (int k = 0; k < 15; k++)
        m->points_by_return[k] = minor >= 4 ? las_get(h + LASH_BY_RETURN + 8 * k, 8)
                                 : k < 5    ? las_get(h + LASH_LEGACY_BY_RETURN + 4 * k, 4)
                                            : 0;
    uint32_t nvlr = (uint32_t)las_get(h + LASH_VLR_COUNT, 4);
    if (nvlr > (r->point_offset - header_size) / LAS_VLR_HEADER)
        return bad(r, "%u VLRs do not fit between the header (%zu bytes) and the point data at byte %zu", nvlr,
                   header_size, r->point_offset);
    rc = read_vlrs(r, header_size, nvlr);
    if (rc == 0 && minor >= 4)
        rc = read_evlrs(r, las_get(h + LASH_EVLR_START, 8), (uint32_t)las_get(h + LASH_EVLR_COUNT, 4));
    return rc;
}

/* Reads from r (its source, size and name set) into *out; frees what r holds. */
static int read_las(reader *r, asp_cloud **out)
{
    const asp_context *ctx = r->ctx;
    asp_error *err = r->err;
    asp_las_meta *meta = asp_calloc(ctx, 1, sizeof *meta);
    if (!meta)
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
    r->meta = meta;
    asp_cloud *c = NULL;
    int rc = read_header(r);
    if (rc == 0) {
        las_field f[LAS_MAX_FIELDS];
        size_t nf = asp__las_fields(r->fmt, f);
        for (size_t i = 0; i < nf; i++) {
            column *col = add_column(r, f[i].name, f[i].type, f[i].offset, f[i].bytes, f[i].kind);
            col->shift = f[i].shift;
            col->mask = f[i].mask;
        }
        rc = plan_extra_bytes(r);
    }
    asp_error e2;
    if (rc == 0 && (rc = asp_cloud_create((size_t)r->count, asp__las_has_rgb(r->fmt) ? ASP_ATTR_COLORS : 0, ctx, &c,
                                          &e2)))
        asp_error_set(err, rc, "cannot read '%s': %s", r->name, e2.msg);
    if (rc == 0)
        rc = route_columns(r, c);
    if (rc == 0)
        rc = decode_records(r, c);
    if (rc == 0)
        rc = fill_positions(r, c);
    if (rc == 0) {
        if (c->colors)
            fill_colors(c);
        c->position_type = ASP_SCALAR_FLOAT64;
        c->up = ASP_UP_Z; // ASPRS LAS 1.4 (2.6 point records): Z is the elevation of the file's CRS
        c->las = meta;
        meta = NULL;
        *out = c;
        c = NULL;
    }
    if (meta) {
        for (size_t i = 0; i < meta->vlr_count; i++)
            asp_free(ctx, meta->vlrs[i].data);
        asp_free(ctx, meta->vlrs);
        asp_free(ctx, meta);
    }
    asp_cloud_destroy(c);
    asp_free(ctx, r->extra_vlr);
    asp_free(ctx, r->scratch);
    return rc;
}

int asp_las_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err)
{
    ASP_ASSERT(out && (data || size == 0));
    reader *r = asp_calloc(ctx, 1, sizeof *r);
    const char *nm = name ? name : "<memory>";
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", nm);
    static const uint8_t none[1] = {0};
    *r = (reader){.b = data ? data : none, .size = size, .name = nm, .ctx = ctx, .err = err};
    int rc = read_las(r, out);
    asp_free(ctx, r);
    return rc;
}

int asp_las_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    ASP_ASSERT(path && out);
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    off_t end = -1;
    if (fseeko(fp, 0, SEEK_END) == 0)
        end = ftello(fp);
    if (end < 0) {
        int e = errno;
        fclose(fp);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    reader *r = asp_calloc(ctx, 1, sizeof *r);
    if (!r) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", path);
    }
    *r = (reader){.fp = fp, .size = (size_t)end, .name = path, .ctx = ctx, .err = err};
    int rc = read_las(r, out);
    asp_free(ctx, r);
    fclose(fp);
    return rc;
}
