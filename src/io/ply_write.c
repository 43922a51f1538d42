/*
 * PLY writer: binary little/big endian or ascii, the layout asp_ply_read
 * maps back (positions, normals, colours, radius, uvs, labels, every extra
 * property with its type, faces, comments), so read-write round trips keep
 * the data. Records are built a chunk at a time, column by column, and
 * written with one fwrite per chunk; the file appears atomically.
 */
#include <errno.h>
#include <string.h>

#include "amgsplat/io.h"
#include "io/ply_internal.h"
#include "util/atomic_file.h"
#include "io/cloud_check.h"
#include "util/banned.h"

enum { S_POS, S_NORMAL, S_COLOR, S_RADIUS, S_UV, S_LABEL, S_EXTRA };
enum { CHUNK_RECORDS = 1 << 14, TEXT_FLUSH = 1 << 20 };

typedef struct column {
    const char *name;
    asp_scalar_type type; /* type in the file */
    int src, k;
    size_t offset;        /* in a binary record */
} column;

typedef struct writer {
    const asp_cloud *cloud;
    const char *path;
    asp_error *err;
    asp__atomic_file file;
    int ascii, swap, wide;
    column *cols;
    size_t ncols, rec_size;
    uint8_t *buf; /* binary: CHUNK_RECORDS records; ascii: text up to TEXT_FLUSH plus one line */
    size_t buf_cap, buf_len;
    double *tmp;
} writer;

static int write_failed(writer *w)
{
    int e = errno ? errno : EIO;
    asp__atomic_abort(&w->file);
    return asp_error_set(w->err, ASP_EIO, "cannot write '%s': %s", w->path, strerror(e));
}

static int put(writer *w, const void *data, size_t n)
{
    if (n && fwrite(data, 1, n, w->file.fp) != n)
        return write_failed(w);
    return 0;
}

static int add_col(writer *w, const char *name, asp_scalar_type type, int src, int k)
{
    for (size_t i = 0; i < w->ncols; i++)
        if (strcmp(w->cols[i].name, name) == 0)
            return asp_error_set(w->err, ASP_EINVAL,
                                 "cannot write '%s': extra property '%s' clashes with a standard property", w->path,
                                 name);
    column *c = &w->cols[w->ncols++];
    c->name = name;
    c->type = type;
    c->src = src;
    c->k = k;
    c->offset = w->rec_size;
    w->rec_size += asp_scalar_size(type);
    return 0;
}

static int plan_columns(writer *w)
{
    const asp_cloud *c = w->cloud;
    w->cols = asp_calloc(&c->ctx, 16 + c->property_count, sizeof *w->cols);
    if (!w->cols)
        return asp_error_set(w->err, ASP_ENOMEM, "cannot write '%s': out of memory", w->path);
    /* double world coordinates when float offsets alone would not give the true position */
    w->wide = c->position_type == ASP_SCALAR_FLOAT64 || c->origin[0] != 0.0 || c->origin[1] != 0.0 ||
              c->origin[2] != 0.0;
    asp_scalar_type pt = w->wide ? ASP_SCALAR_FLOAT64 : ASP_SCALAR_FLOAT32;
    static const char *const xyz[] = {"x", "y", "z"}, *const nxyz[] = {"nx", "ny", "nz"},
                             *const rgba[] = {"red", "green", "blue", "alpha"},
                             *const uv[] = {"texture_u", "texture_v"};
    int rc = 0;
    for (int k = 0; k < 3; k++)
        add_col(w, xyz[k], pt, S_POS, k);
    if (c->normals)
        for (int k = 0; k < 3; k++)
            add_col(w, nxyz[k], ASP_SCALAR_FLOAT32, S_NORMAL, k);
    if (c->colors) {
        int alpha = 0;
        for (size_t i = 0; i < c->count && !alpha; i++)
            alpha = c->colors[4 * i + 3] != 255;
        asp_scalar_type ct = c->color_type == ASP_SCALAR_FLOAT32 || c->color_type == ASP_SCALAR_FLOAT64
                                 ? ASP_SCALAR_FLOAT32
                                 : ASP_SCALAR_UINT8;
        for (int k = 0; k < 3 + alpha; k++)
            add_col(w, rgba[k], ct, S_COLOR, k);
    }
    if (c->radii)
        add_col(w, "radius", ASP_SCALAR_FLOAT32, S_RADIUS, 0);
    if (c->uvs)
        for (int k = 0; k < 2; k++)
            add_col(w, uv[k], ASP_SCALAR_FLOAT32, S_UV, k);
    if (c->labels)
        add_col(w, "label", ASP_SCALAR_UINT32, S_LABEL, 0);
    for (size_t i = 0; i < c->property_count && rc == 0; i++)
        rc = add_col(w, c->properties[i].name, c->properties[i].type, S_EXTRA, (int)i);
    return rc;
}

/* ---------- header ---------- */

static int put_text_line(writer *w, const char *kw, const char *text)
{
    int rc = put(w, kw, strlen(kw));
    /* a newline inside a comment would end the header line early */
    for (const char *p = text; rc == 0 && *p; p++) {
        char ch = (*p == '\n' || *p == '\r') ? ' ' : *p;
        rc = put(w, &ch, 1);
    }
    return rc ? rc : put(w, "\n", 1);
}

static int write_header(writer *w, int index_uint)
{
    const asp_cloud *c = w->cloud;
    char line[160];
    const char *enc = w->ascii ? "ascii" : (w->swap != asp__host_big_endian() ? "binary_big_endian"
                                                                              : "binary_little_endian");
    int n = snprintf(line, sizeof line, "ply\nformat %s 1.0\n", enc);
    int rc = put(w, line, (size_t)n);
    for (size_t i = 0; i < c->comment_count && rc == 0; i++)
        rc = put_text_line(w, "comment ", c->comments[i]);
    for (size_t i = 0; i < c->obj_info_count && rc == 0; i++)
        rc = put_text_line(w, "obj_info ", c->obj_info[i]);
    if (rc)
        return rc;
    n = snprintf(line, sizeof line, "element vertex %zu\n", c->count);
    rc = put(w, line, (size_t)n);
    for (size_t i = 0; i < w->ncols && rc == 0; i++) {
        n = snprintf(line, sizeof line, "property %s %s\n", asp_scalar_name(w->cols[i].type), w->cols[i].name);
        rc = put(w, line, (size_t)n);
    }
    if (rc == 0 && c->face_count) {
        n = snprintf(line, sizeof line, "element face %zu\nproperty list uchar %s vertex_indices\n", c->face_count,
                     index_uint ? "uint" : "int");
        rc = put(w, line, (size_t)n);
    }
    return rc ? rc : put(w, "end_header\n", 11);
}

/* ---------- values ---------- */

/* Column values of points i0..i0+n as doubles (exact for every standard attribute). */
static void gather(const writer *w, const column *col, size_t i0, size_t n, double *out)
{
    const asp_cloud *c = w->cloud;
    switch (col->src) {
    case S_POS: {
        double o = c->origin[col->k];
        for (size_t t = 0; t < n; t++)
            out[t] = o + (double)c->positions[3 * (i0 + t) + col->k];
        break;
    }
    case S_NORMAL:
        for (size_t t = 0; t < n; t++)
            out[t] = c->normals[3 * (i0 + t) + col->k];
        break;
    case S_COLOR:
        if (col->type == ASP_SCALAR_UINT8)
            for (size_t t = 0; t < n; t++)
                out[t] = c->colors[4 * (i0 + t) + col->k];
        else
            for (size_t t = 0; t < n; t++)
                out[t] = (float)(c->colors[4 * (i0 + t) + col->k] / 255.0);
        break;
    case S_RADIUS:
        for (size_t t = 0; t < n; t++)
            out[t] = c->radii[i0 + t];
        break;
    case S_UV:
        for (size_t t = 0; t < n; t++)
            out[t] = c->uvs[2 * (i0 + t) + col->k];
        break;
    case S_LABEL:
        for (size_t t = 0; t < n; t++)
            out[t] = c->labels[i0 + t];
        break;
    default:
        // S_EXTRA columns are copied by the callers in their own type, never gathered as doubles
        ASP_ASSERT(!"gather of a column without a cloud array");
    }
}

static inline uint32_t bswap32(uint32_t x)
{
    return (x >> 24) | ((x >> 8) & 0xff00u) | ((x << 8) & 0xff0000u) | (x << 24);
}
static inline uint64_t bswap64(uint64_t x) { return ((uint64_t)bswap32((uint32_t)x) << 32) | bswap32((uint32_t)(x >> 32)); }

/* Standard columns are float, double, uchar or uint; the type switch sits outside the loop. */
static void scatter(uint8_t *dst, size_t stride, size_t n, asp_scalar_type t, int swap, const double *v)
{
    switch (t) {
    case ASP_SCALAR_UINT8:
        for (size_t i = 0; i < n; i++)
            dst[i * stride] = (uint8_t)v[i];
        break;
    case ASP_SCALAR_FLOAT32:
        for (size_t i = 0; i < n; i++) {
            float f = (float)v[i];
            uint32_t u;
            memcpy(&u, &f, 4);
            u = swap ? bswap32(u) : u;
            memcpy(dst + i * stride, &u, 4);
        }
        break;
    case ASP_SCALAR_UINT32:
        for (size_t i = 0; i < n; i++) {
            uint32_t u = (uint32_t)v[i];
            u = swap ? bswap32(u) : u;
            memcpy(dst + i * stride, &u, 4);
        }
        break;
    case ASP_SCALAR_FLOAT64:
        for (size_t i = 0; i < n; i++) {
            uint64_t u;
            memcpy(&u, &v[i], 8);
            u = swap ? bswap64(u) : u;
            memcpy(dst + i * stride, &u, 8);
        }
        break;
    default:
        break;
    }
}

static int write_vertices_binary(writer *w)
{
    const asp_cloud *c = w->cloud;
    size_t rs = w->rec_size;
    for (size_t i = 0; i < c->count;) {
        size_t n = c->count - i < CHUNK_RECORDS ? c->count - i : CHUNK_RECORDS;
        for (size_t j = 0; j < w->ncols; j++) {
            const column *col = &w->cols[j];
            uint8_t *dst = w->buf + col->offset;
            if (col->src == S_EXTRA) {
                size_t sz = asp_scalar_size(col->type);
                const uint8_t *src = (const uint8_t *)c->properties[col->k].data + i * sz;
                for (size_t t = 0; t < n; t++) {
                    memcpy(dst + t * rs, src + t * sz, sz);
                    if (w->swap)
                        asp__swap_bytes(dst + t * rs, sz);
                }
                continue;
            }
            gather(w, col, i, n, w->tmp);
            scatter(dst, rs, n, col->type, w->swap, w->tmp);
        }
        int rc = put(w, w->buf, n * rs);
        if (rc)
            return rc;
        i += n;
        if (asp_progress(&c->ctx, "write", (double)i / (double)c->count)) {
            asp__atomic_abort(&w->file);
            return asp_error_set(w->err, ASP_ECANCELED, "cannot write '%s': canceled", w->path);
        }
    }
    return 0;
}

static int flush_text(writer *w, int force)
{
    if (w->buf_len < TEXT_FLUSH && !force)
        return 0;
    int rc = put(w, w->buf, w->buf_len);
    w->buf_len = 0;
    return rc;
}

static int write_vertices_ascii(writer *w)
{
    const asp_cloud *c = w->cloud;
    for (size_t i = 0; i < c->count; i++) {
        char *line = (char *)w->buf + w->buf_len;
        size_t len = 0;
        for (size_t j = 0; j < w->ncols; j++) {
            const column *col = &w->cols[j];
            if (j)
                line[len++] = ' ';
            if (col->src == S_EXTRA) {
                size_t sz = asp_scalar_size(col->type);
                len += asp__format_scalar(line + len, (const uint8_t *)c->properties[col->k].data + i * sz,
                                          col->type);
                continue;
            }
            double v;
            gather(w, col, i, 1, &v);
            if (col->type == ASP_SCALAR_FLOAT64)
                len += asp__format_double(line + len, v);
            else if (col->type == ASP_SCALAR_FLOAT32)
                len += asp__format_float(line + len, (float)v);
            else
                len += (size_t)snprintf(line + len, 32, "%.0f", v);
        }
        line[len++] = '\n';
        w->buf_len += len;
        int rc = flush_text(w, 0);
        if (rc)
            return rc;
    }
    return flush_text(w, 1);
}

static int write_faces(writer *w, int index_uint)
{
    const asp_cloud *c = w->cloud;
    (void)index_uint; /* int and uint share the 4-byte layout */
    for (size_t f = 0; f < c->face_count; f++) {
        const uint32_t *t = c->faces + 3 * f;
        if (w->ascii) {
            w->buf_len += (size_t)snprintf((char *)w->buf + w->buf_len, 48, "3 %u %u %u\n", t[0], t[1], t[2]);
        } else {
            uint8_t *p = w->buf + w->buf_len;
            p[0] = 3;
            for (int k = 0; k < 3; k++) {
                uint32_t u = w->swap ? bswap32(t[k]) : t[k];
                memcpy(p + 1 + 4 * k, &u, 4);
            }
            w->buf_len += 13;
        }
        int rc = flush_text(w, 0);
        if (rc)
            return rc;
    }
    return flush_text(w, 1);
}

/* ---------- driver ---------- */

/*
 * No command writes a PLY that asp_ply_read refuses (issue #13): the file is
 * read back whole before it replaces the target. The reader's checks are
 * per value (finite coordinates, list counts, face indices), so a header
 * check would miss what can actually be wrong; the read-back also validates
 * radii, normals and uvs as asp_cloud_load does (issue #31: infinite radii
 * passed asp_ply_read alone).
 */

static int write_all(writer *w)
{
    const asp_cloud *c = w->cloud;
    int index_uint = 0;
    for (size_t i = 0; i < 3 * c->face_count; i++)
        index_uint |= c->faces[i] > INT32_MAX;
    int rc = plan_columns(w);
    if (rc)
        return rc;
    /* ascii lines hold at most 32 bytes per value plus separators */
    size_t line_max = w->ncols * 33 + 64;
    w->buf_cap = w->ascii ? TEXT_FLUSH + line_max : (CHUNK_RECORDS * w->rec_size > TEXT_FLUSH + 64
                                                         ? CHUNK_RECORDS * w->rec_size
                                                         : TEXT_FLUSH + 64);
    w->buf = asp_alloc(&c->ctx, w->buf_cap);
    w->tmp = asp_alloc(&c->ctx, CHUNK_RECORDS * sizeof *w->tmp);
    if (!w->buf || !w->tmp)
        return asp_error_set(w->err, ASP_ENOMEM, "cannot write '%s': out of memory", w->path);
    if ((rc = asp__atomic_open(&w->file, w->path, w->err)))
        return rc;
    rc = write_header(w, index_uint);
    if (rc == 0)
        rc = w->ascii ? write_vertices_ascii(w) : write_vertices_binary(w);
    if (rc == 0)
        rc = write_faces(w, index_uint);
    if (rc == 0)
        return asp__atomic_commit_checked(&w->file, asp__cloud_reads_back, &(asp__cloud_readback){c, "ply"}, w->err);
    asp__atomic_abort(&w->file);
    return rc;
}

int asp_ply_write(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err)
{
    writer w;
    memset(&w, 0, sizeof w);
    w.cloud = cloud;
    w.path = path;
    w.err = err;
    asp_ply_encoding enc = desc ? desc->encoding : ASP_PLY_DEFAULT;
    if (enc != ASP_PLY_DEFAULT && enc != ASP_PLY_ASCII && enc != ASP_PLY_BINARY_LE && enc != ASP_PLY_BINARY_BE)
        return asp_error_set(err, ASP_EINVAL, "cannot write '%s': unknown PLY encoding %d", path, (int)enc);
    w.ascii = enc == ASP_PLY_ASCII;
    w.swap = !w.ascii && ((enc == ASP_PLY_BINARY_BE) != asp__host_big_endian());
    int rc = write_all(&w);
    asp_free(&cloud->ctx, w.cols);
    asp_free(&cloud->ctx, w.buf);
    asp_free(&cloud->ctx, w.tmp);
    return rc;
}
