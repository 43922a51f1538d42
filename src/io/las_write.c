/*
 * LAS writer (ASPRS LAS 1.2-1.4, point formats 0-3 and 6-8, LAS 1.4 R15): the
 * fields asp_las_read names back into records, the source's scale, offset,
 * header and VLRs reused, and every other attribute as typed Extra Bytes
 * (Table 24), so LAS in, LAS out keeps every value and LAS out, LAS in keeps
 * what amgsplat has.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amgsplat/io.h"
#include "io/las_internal.h"
#include "util/atomic_file.h"
#include "io/cloud_check.h"
#include "util/banned.h"

enum { CHUNK = 1 << 14, MAX_EXTRA = 256 };

/* One extra-bytes column: a property, a normal component, the radius or the label. */
typedef struct extra {
    char name[33];
    unsigned data_type; /* LAS Extra Bytes data type 1-10 */
    unsigned bytes;
    char kind;
    const asp_property *prop; /* or NULL: */
    const float *f;           /* normals (stride 3) or radii (stride 1) */
    const uint32_t *u;        /* labels */
    size_t stride, k;
    size_t offset;            /* in the record */
} extra;

typedef struct writer {
    const asp_cloud *c;
    const char *path;
    asp_error *err;
    unsigned fmt, minor;
    double scale[3], offset[3];
    las_field fields[LAS_MAX_FIELDS];
    const asp_property *src[LAS_MAX_FIELDS]; /* property of each field, or NULL */
    size_t nfields;
    extra extras[MAX_EXTRA];
    size_t nextras, reclen;
    int rgb_from16;
    const asp_property *angle_other; /* scan angle in the other unit (rank vs 0.006 degree steps) */
} writer;

static int invalid(writer *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int invalid(writer *w, const char *fmt, ...)
{
    char what[220];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return asp_error_set(w->err, ASP_EINVAL, "cannot write '%s': %s", w->path, what);
}

static unsigned choose_format(const asp_cloud *c, const asp_save_desc *desc)
{
    if (desc && desc->las_format)
        return desc->las_format - 1;
    if (c->las) {
        static const unsigned without_wave[LAS_MAX_FORMAT + 1] = {0, 1, 2, 3, 1, 3, 6, 7, 8, 6, 8};
        return c->las->point_format <= LAS_MAX_FORMAT ? without_wave[c->las->point_format] : 6;
    }
    return asp_cloud_find_property(c, "nir") ? 8 : c->colors ? 7 : 6;
}

static int is_field(const writer *w, const char *name)
{
    for (size_t i = 0; i < w->nfields; i++)
        if (strcmp(w->fields[i].name, name) == 0)
            return 1;
    return 0;
}

static int add_extra(writer *w, const char *name, asp_scalar_type type, extra **out)
{
    static const struct { asp_scalar_type t; unsigned dt, bytes; char kind; } map[] = {
        {ASP_SCALAR_UINT8, 1, 1, 'u'},  {ASP_SCALAR_INT8, 2, 1, 's'},    {ASP_SCALAR_UINT16, 3, 2, 'u'},
        {ASP_SCALAR_INT16, 4, 2, 's'},  {ASP_SCALAR_UINT32, 5, 4, 'u'},  {ASP_SCALAR_INT32, 6, 4, 's'},
        {ASP_SCALAR_FLOAT32, 9, 4, 'f'}, {ASP_SCALAR_FLOAT64, 10, 8, 'f'}};
    if (strlen(name) > 32)
        return invalid(w, "property '%s' cannot be a LAS extra bytes field (names have at most 32 bytes)", name);
    if (w->nextras == MAX_EXTRA)
        return invalid(w, "more than %d extra properties", MAX_EXTRA);
    extra *e = &w->extras[w->nextras++];
    memset(e, 0, sizeof *e);
    snprintf(e->name, sizeof e->name, "%s", name);
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (map[i].t == type) {
            e->data_type = map[i].dt;
            e->bytes = map[i].bytes;
            e->kind = map[i].kind;
        }
    e->offset = w->reclen;
    w->reclen += e->bytes;
    e->stride = 1;
    *out = e;
    return 0;
}

/* Fields of the format from properties; everything else the cloud has as extra bytes. */
static int plan(writer *w)
{
    const asp_cloud *c = w->c;
    w->nfields = asp__las_fields(w->fmt, w->fields);
    w->reclen = asp__las_format_size(w->fmt);
    for (size_t i = 0; i < w->nfields; i++)
        w->src[i] = asp_cloud_find_property(c, w->fields[i].name);
    w->angle_other = asp_cloud_find_property(c, w->fmt < 6 ? "scan_angle" : "scan_angle_rank");
    /* red16..: used when they give the colours by the reader's rule, so LAS -> LAS keeps all 16 bits */
    const asp_property *rgb[3] = {asp_cloud_find_property(c, "red16"), asp_cloud_find_property(c, "green16"),
                                  asp_cloud_find_property(c, "blue16")};
    if (c->colors && rgb[0] && rgb[1] && rgb[2]) {
        int shift = 0, same = 1;
        for (size_t i = 0; i < c->count && !shift; i++)
            for (int k = 0; k < 3; k++)
                shift |= asp_property_value(rgb[k], i) > 255;
        for (size_t i = 0; i < c->count && same; i++)
            for (int k = 0; k < 3; k++) {
                double v = asp_property_value(rgb[k], i);
                same &= v >= 0 && v <= 65535 && (uint8_t)((unsigned)v >> (shift ? 8 : 0)) == c->colors[4 * i + k];
            }
        w->rgb_from16 = same;
    } else if (!c->colors && rgb[0] && rgb[1] && rgb[2]) {
        w->rgb_from16 = 1;
    }
    extra *e;
    int rc;
    if (c->normals)
        for (int k = 0; k < 3; k++) {
            if ((rc = add_extra(w, (const char *[]){"nx", "ny", "nz"}[k], ASP_SCALAR_FLOAT32, &e)))
                return rc;
            e->f = c->normals, e->stride = 3, e->k = (size_t)k;
        }
    if (c->radii) {
        if ((rc = add_extra(w, "radius", ASP_SCALAR_FLOAT32, &e)))
            return rc;
        e->f = c->radii;
    }
    if (c->labels) {
        if ((rc = add_extra(w, "label", ASP_SCALAR_UINT32, &e)))
            return rc;
        e->u = c->labels;
    }
    for (size_t i = 0; i < c->property_count; i++) {
        const asp_property *p = &c->properties[i];
        if (is_field(w, p->name) || p == w->angle_other ||
            (w->rgb_from16 && (p == rgb[0] || p == rgb[1] || p == rgb[2]) && asp__las_has_rgb(w->fmt)))
            continue;
        if ((c->normals && (!strcmp(p->name, "nx") || !strcmp(p->name, "ny") || !strcmp(p->name, "nz"))) ||
            (c->radii && !strcmp(p->name, "radius")) || (c->labels && !strcmp(p->name, "label")))
            return invalid(w, "extra property '%s' clashes with the %s written as extra bytes", p->name,
                           p->name[0] == 'n' ? "normals" : p->name[0] == 'r' ? "radii" : "labels");
        if ((rc = add_extra(w, p->name, p->type, &e)))
            return rc;
        e->prop = p;
    }
    if (w->reclen > 65535)
        return invalid(w, "a point record of %zu bytes (at most 65535)", w->reclen);
    return 0;
}

/* Rounded value of field f for point i, checked against the field's range in this format. */
static int field_bits(writer *w, size_t fi, size_t i, uint64_t *out)
{
    const las_field *f = &w->fields[fi];
    const asp_property *p = w->src[fi];
    double v = 0;
    if (p)
        v = asp_property_value(p, i);
    else if (!strcmp(f->name, "return_number") || !strcmp(f->name, "number_of_returns"))
        v = 1; // a single return: what a point without pulse information is
    else if (w->angle_other && !strcmp(f->name, "scan_angle"))
        v = asp_property_value(w->angle_other, i) / 0.006;
    else if (w->angle_other && !strcmp(f->name, "scan_angle_rank"))
        v = asp_property_value(w->angle_other, i) * 0.006;
    if (!strcmp(f->name, "red16") || !strcmp(f->name, "green16") || !strcmp(f->name, "blue16")) {
        int k = f->name[0] == 'r' ? 0 : f->name[0] == 'g' ? 1 : 2;
        v = w->rgb_from16 && p ? v : w->c->colors ? 257.0 * w->c->colors[4 * i + (size_t)k] : 0;
    }
    if (f->kind == 'f') {
        double d = v;
        if (f->bytes == 8) {
            memcpy(out, &d, 8);
        } else {
            float x = (float)d;
            uint32_t u;
            memcpy(&u, &x, 4);
            *out = u;
        }
        return 0;
    }
    double r = nearbyint(v);
    double lo = 0, hi;
    if (f->kind == 's') {
        hi = ldexp(1, 8 * (int)f->bytes - 1) - 1;
        lo = -hi - 1;
    } else {
        hi = f->mask ? f->mask : ldexp(1, 8 * (int)f->bytes) - 1;
    }
    if (!(r >= lo && r <= hi))
        return invalid(w, "point %zu: %s %.17g does not fit point format %u (%.0f to %.0f)%s", i + 1, f->name, v,
                       w->fmt, lo, hi, w->fmt < 6 ? "; formats 6-8 hold more" : "");
    int64_t s = (int64_t)r;
    *out = f->kind == 's' ? (uint64_t)s & (f->bytes == 8 ? ~0ull : (1ull << (8 * f->bytes)) - 1) : (uint64_t)s;
    return 0;
}

/* World coordinates to the record integers, checked against int32. */
static int quantise(writer *w, size_t i, int32_t X[3], double world[3])
{
    const asp_cloud *c = w->c;
    for (int k = 0; k < 3; k++) {
        double v = (c->origin[k] - w->offset[k] + (double)c->positions[3 * i + (size_t)k]) / w->scale[k];
        double r = nearbyint(v);
        if (!(r >= INT32_MIN && r <= INT32_MAX))
            return invalid(w, "point %zu: %c %.17g is %.0f steps of %g from the offset %.17g, outside int32; use a "
                           "larger scale (--las-scale)",
                           i + 1, "xyz"[k], c->origin[k] + (double)c->positions[3 * i + (size_t)k], r, w->scale[k],
                           w->offset[k]);
        X[k] = (int32_t)r;
        world[k] = w->offset[k] + w->scale[k] * r;
    }
    return 0;
}

static void encode(writer *w, size_t i, const int32_t X[3], uint8_t *rec, uint64_t *bits)
{
    memset(rec, 0, w->reclen);
    for (int k = 0; k < 3; k++)
        las_put(rec + 4 * k, (uint32_t)X[k], 4);
    for (size_t f = 0; f < w->nfields; f++) {
        const las_field *fl = &w->fields[f];
        if (fl->mask)
            rec[fl->offset] |= (uint8_t)((bits[f] & fl->mask) << fl->shift);
        else
            las_put(rec + fl->offset, bits[f], fl->bytes);
    }
    for (size_t x = 0; x < w->nextras; x++) {
        const extra *e = &w->extras[x];
        double v = e->prop ? asp_property_value(e->prop, i) : e->f ? e->f[i * e->stride + e->k] : e->u[i];
        uint64_t u;
        if (e->kind == 'f' && e->bytes == 4) {
            float f = (float)v;
            uint32_t u32;
            memcpy(&u32, &f, 4);
            u = u32;
        } else if (e->kind == 'f') {
            memcpy(&u, &v, 8);
        } else if (e->kind == 's') {
            u = (uint64_t)(int64_t)v;
        } else {
            u = (uint64_t)v;
        }
        las_put(rec + e->offset, u, e->bytes);
    }
}

static void put_text(uint8_t *dst, const char *s, size_t n)
{
    memset(dst, 0, n);
    size_t len = strlen(s);
    memcpy(dst, s, len < n ? len : n);
}

static void put_f64(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    las_put(p, u, 8);
}

/* The Extra Bytes VLR payload: one 192-byte descriptor per extra column. */
static void extra_descriptors(const writer *w, uint8_t *d)
{
    memset(d, 0, w->nextras * LAS_EXTRA_DESCRIPTOR);
    for (size_t x = 0; x < w->nextras; x++) {
        uint8_t *e = d + x * LAS_EXTRA_DESCRIPTOR;
        e[2] = (uint8_t)w->extras[x].data_type;
        put_text(e + 4, w->extras[x].name, 32);
        put_text(e + 160, "amgsplat attribute", 32);
    }
}

typedef struct stats {
    double lo[3], hi[3];
    uint64_t by_return[15];
} stats;

static int write_failed(writer *w, asp__atomic_file *f)
{
    int e = errno ? errno : EIO;
    asp__atomic_abort(f);
    return asp_error_set(w->err, ASP_EIO, "cannot write '%s': %s", w->path, strerror(e));
}

static void header(const writer *w, const stats *st, size_t header_size, size_t nvlr, size_t point_offset,
                   uint64_t evlr_start, size_t nevlr, uint8_t *h)
{
    const asp_cloud *c = w->c;
    const asp_las_meta *m = c->las;
    memset(h, 0, LAS_HEADER_14);
    memcpy(h, "LASF", 4);
    if (m) {
        las_put(h + LASH_SOURCE_ID, m->file_source_id, 2);
        memcpy(h + LASH_GUID, m->guid, 16);
    }
    /* bit 0 (GPS time type) carries over; bit 1-2 (waveforms) do not; bit 4 (WKT) only with a 1.4 file */
    unsigned enc = m ? m->global_encoding & (w->minor >= 4 ? 0x11u : 0x01u) : 0;
    las_put(h + LASH_ENCODING, enc, 2);
    h[LASH_VERSION] = 1;
    h[LASH_VERSION + 1] = (uint8_t)w->minor;
    put_text(h + LASH_SYSTEM, m && m->system_id[0] ? m->system_id : "amgsplat", 32);
    put_text(h + LASH_SOFTWARE, "amgsplat", 32);
    unsigned day = m ? m->creation_day : 0, year = m ? m->creation_year : 0;
    if (!m) {
        time_t now = time(NULL);
        struct tm tmv;
        if (gmtime_r(&now, &tmv)) {
            day = (unsigned)tmv.tm_yday + 1;
            year = (unsigned)tmv.tm_year + 1900;
        }
    }
    las_put(h + LASH_DAY, day, 2);
    las_put(h + LASH_YEAR, year, 2);
    las_put(h + LASH_HEADER_SIZE, header_size, 2);
    las_put(h + LASH_POINT_OFFSET, point_offset, 4);
    las_put(h + LASH_VLR_COUNT, nvlr, 4);
    h[LASH_FORMAT] = (uint8_t)w->fmt;
    las_put(h + LASH_RECORD_LENGTH, w->reclen, 2);
    /* legacy counts: 0 for formats 6-10 and past 2^32-1 (LAS 1.4 R15 Table 3) */
    int legacy = w->fmt < 6 && c->count <= UINT32_MAX;
    las_put(h + LASH_LEGACY_COUNT, legacy ? c->count : 0, 4);
    for (int k = 0; k < 5; k++)
        las_put(h + LASH_LEGACY_BY_RETURN + 4 * k, legacy ? st->by_return[k] : 0, 4);
    for (int k = 0; k < 3; k++) {
        put_f64(h + LASH_SCALE + 8 * k, w->scale[k]);
        put_f64(h + LASH_OFFSET + 8 * k, w->offset[k]);
        put_f64(h + LASH_MAX_X + 16 * k, st->hi[k]);
        put_f64(h + LASH_MAX_X + 16 * k + 8, st->lo[k]);
    }
    if (w->minor >= 4) {
        las_put(h + LASH_EVLR_START, nevlr ? evlr_start : 0, 8);
        las_put(h + LASH_EVLR_COUNT, nevlr, 4);
        las_put(h + LASH_COUNT, c->count, 8);
        for (int k = 0; k < 15; k++)
            las_put(h + LASH_BY_RETURN + 8 * k, st->by_return[k], 8);
    }
}

/* First pass: every value checked and the header's bounds and return counts, before the file is opened. */
static int survey(writer *w, stats *st)
{
    const asp_cloud *c = w->c;
    size_t ret = SIZE_MAX;
    for (size_t f = 0; f < w->nfields; f++)
        if (!strcmp(w->fields[f].name, "return_number"))
            ret = f;
    for (int k = 0; k < 3; k++)
        st->lo[k] = c->count ? INFINITY : 0, st->hi[k] = c->count ? -INFINITY : 0;
    memset(st->by_return, 0, sizeof st->by_return);
    for (size_t i = 0; i < c->count; i++) {
        int32_t X[3];
        double world[3];
        int rc = quantise(w, i, X, world);
        for (int k = 0; k < 3 && rc == 0; k++) {
            st->lo[k] = world[k] < st->lo[k] ? world[k] : st->lo[k];
            st->hi[k] = world[k] > st->hi[k] ? world[k] : st->hi[k];
        }
        for (size_t f = 0; f < w->nfields && rc == 0; f++) {
            uint64_t b;
            rc = field_bits(w, f, i, &b);
            if (rc == 0 && f == ret && b >= 1 && b <= 15)
                st->by_return[b - 1]++;
        }
        if (rc)
            return rc;
    }
    return 0;
}

static void choose_quantisation(writer *w, const asp_save_desc *desc)
{
    const asp_cloud *c = w->c;
    double scale = desc ? desc->las_scale : 0;
    for (int k = 0; k < 3; k++) {
        w->scale[k] = scale > 0 ? scale : c->las ? c->las->scale[k] : 0.001;
        if (c->las) {
            w->offset[k] = c->las->offset[k];
            continue;
        }
        double lo = INFINITY;
        for (size_t i = 0; i < c->count; i++) {
            double v = c->origin[k] + (double)c->positions[3 * i + (size_t)k];
            lo = v < lo ? v : lo;
        }
        w->offset[k] = c->count ? floor(lo) : 0;
    }
}

static int write_vlr(FILE *fp, const asp_las_vlr *v, int extended)
{
    uint8_t h[LAS_EVLR_HEADER];
    memset(h, 0, sizeof h);
    put_text(h + 2, v->user_id, 16);
    las_put(h + 18, v->record_id, 2);
    las_put(h + 20, v->size, extended ? 8 : 2);
    put_text(h + (extended ? 28 : 22), v->description, 32);
    size_t hn = extended ? LAS_EVLR_HEADER : LAS_VLR_HEADER;
    return fwrite(h, 1, hn, fp) != hn || (v->size && fwrite(v->data, 1, v->size, fp) != v->size);
}

int asp_las_write(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err)
{
    ASP_ASSERT(cloud && path);
    writer *w = asp_calloc(&cloud->ctx, 1, sizeof *w);
    if (!w)
        return asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
    w->c = cloud;
    w->path = path;
    w->err = err;
    w->fmt = choose_format(cloud, desc);
    int rc = 0;
    if (w->fmt > 8 || w->fmt == 4 || w->fmt == 5)
        rc = invalid(w, "point format %u: this writer writes formats 0-3 and 6-8 (4, 5, 9 and 10 carry waveforms)",
                     w->fmt);
    /*
     * 1.4 for formats 6-8 and for EVLRs; the source's version when its format is kept (LAS -> LAS
     * reproduces the file); else 1.2, which every LAS reader reads (loaders.gl reads at most 1.3)
     */
    int same_format = cloud->las && cloud->las->point_format == w->fmt;
    w->minor = w->fmt >= 6 ? 4 : same_format && cloud->las->version_minor > 2 ? cloud->las->version_minor : 2;
    for (size_t i = 0; cloud->las && i < cloud->las->vlr_count; i++)
        if (cloud->las->vlrs[i].extended)
            w->minor = 4;
    if (rc == 0) {
        choose_quantisation(w, desc);
        rc = plan(w);
    }
    stats st;
    if (rc == 0)
        rc = survey(w, &st);
    /* VLRs: the source's (those too large for a VLR become EVLRs in 1.4), then Extra Bytes */
    const asp_las_meta *m = cloud->las;
    size_t nvlr = 0, nevlr = 0, vlr_bytes = 0;
    asp_las_vlr extra_vlr = {.user_id = "LASF_Spec", .record_id = 4, .description = "Extra Bytes"};
    uint8_t *desc_bytes = NULL;
    if (rc == 0 && w->nextras) {
        extra_vlr.size = w->nextras * LAS_EXTRA_DESCRIPTOR;
        desc_bytes = asp_alloc(&cloud->ctx, extra_vlr.size);
        if (!desc_bytes)
            rc = asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
        else
            extra_descriptors(w, desc_bytes);
        extra_vlr.data = desc_bytes;
    }
    for (size_t i = 0; rc == 0 && m && i < m->vlr_count; i++) {
        const asp_las_vlr *v = &m->vlrs[i];
        int as_evlr = v->extended || v->size > 65535;
        if (as_evlr && w->minor < 4 && v->size > 65535)
            rc = invalid(w, "VLR '%s' %u holds %zu bytes, more than a LAS 1.%u VLR can (65535); write format 6-8 "
                         "(LAS 1.4) to keep it",
                         v->user_id, v->record_id, v->size, w->minor);
        else if (as_evlr && w->minor >= 4)
            nevlr++;
        else
            nvlr++, vlr_bytes += LAS_VLR_HEADER + v->size;
    }
    if (w->nextras)
        nvlr++, vlr_bytes += LAS_VLR_HEADER + extra_vlr.size;
    size_t header_size = w->minor >= 4 ? LAS_HEADER_14 : w->minor == 3 ? LAS_HEADER_13 : LAS_HEADER_12;
    size_t point_offset = header_size + vlr_bytes;
    if (rc == 0 && point_offset > UINT32_MAX)
        rc = invalid(w, "VLRs of %zu bytes do not fit before the points", vlr_bytes);
    asp__atomic_file f;
    uint8_t *buf = NULL;
    uint64_t *bits = NULL;
    if (rc == 0 && !(buf = asp_alloc(&cloud->ctx, (size_t)CHUNK * w->reclen)))
        rc = asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
    if (rc == 0 && !(bits = asp_alloc(&cloud->ctx, LAS_MAX_FIELDS * sizeof *bits)))
        rc = asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
    if (rc == 0)
        rc = asp__atomic_open(&f, path, err);
    if (rc == 0) {
        uint8_t h[LAS_HEADER_14];
        uint64_t evlr_start = point_offset + (uint64_t)cloud->count * w->reclen;
        header(w, &st, header_size, nvlr, point_offset, evlr_start, nevlr, h);
        int bad = fwrite(h, 1, header_size, f.fp) != header_size;
        for (size_t i = 0; !bad && m && i < m->vlr_count; i++)
            if (!((m->vlrs[i].extended || m->vlrs[i].size > 65535) && w->minor >= 4))
                bad = write_vlr(f.fp, &m->vlrs[i], 0);
        if (!bad && w->nextras)
            bad = write_vlr(f.fp, &extra_vlr, 0);
        for (size_t i0 = 0; !bad && i0 < cloud->count; i0 += CHUNK) {
            size_t n = cloud->count - i0 < CHUNK ? cloud->count - i0 : CHUNK;
            for (size_t j = 0; j < n; j++) {
                int32_t X[3];
                double world[3];
                quantise(w, i0 + j, X, world); // checked by survey
                for (size_t fi = 0; fi < w->nfields; fi++)
                    field_bits(w, fi, i0 + j, &bits[fi]);
                encode(w, i0 + j, X, buf + j * w->reclen, bits);
            }
            bad = fwrite(buf, w->reclen, n, f.fp) != n;
        }
        for (size_t i = 0; !bad && m && i < m->vlr_count; i++)
            if ((m->vlrs[i].extended || m->vlrs[i].size > 65535) && w->minor >= 4)
                bad = write_vlr(f.fp, &m->vlrs[i], 1);
        // read back as asp_cloud_load reads it (issue #31: every output kind)
        rc = bad ? write_failed(w, &f)
                 : asp__atomic_commit_checked(&f, asp__cloud_reads_back, &(asp__cloud_readback){cloud, "las"}, err);
    }
    asp_free(&cloud->ctx, bits);
    asp_free(&cloud->ctx, buf);
    asp_free(&cloud->ctx, desc_bytes);
    asp_free(&cloud->ctx, w);
    return rc;
}
