/*
 * Plain-text point files (.xyz, .pts, .txt): one point per line, "x y z
 * [nx ny nz] [r g b]" or the Leica PTS "x y z intensity [r g b]" layout. The
 * simplest raw-scan exchange format, read here as the unstructured input of
 * the pipeline (journal Sect. 1, Fig. 2). The column count of the first data line decides the layout.
 */
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/io.h"
#include "io/buffered_source.h"
#include "io/ply_internal.h"
#include "util/atomic_file.h"
#include "io/cloud_check.h"
#include "util/banned.h"

enum { LINE_MAX_BYTES = 1 << 16, MAX_COLS = 9 };

typedef struct text_reader {
    asp__src src;
    const asp_context *ctx;
    const char *name;
    asp_error *err;
    double *vals; /* rows * cols values */
    size_t rows, cap;
    int cols;
    char *line;   /* NUL-terminated copy of the current line */
    /* colour evidence: first line (0 = none) where a value is not an integer 0..255 / not in 0..1 */
    size_t not_byte_line, not_unit_line;
    double not_byte_value, not_unit_value;
    int all_unit_triples; /* six columns: every last triple is (1,0,0), (0,1,0) or (0,0,1) */
    double declared;      /* the leading point count (.pts), -1 when there is none */
    size_t declared_line;
} text_reader;

static int fail(text_reader *t, size_t line, const char *what, double v)
{
    return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu: %s%.9g", t->name, line, what, v);
}

static int push_row(text_reader *t, const double *v)
{
    if ((t->rows + 1) * (size_t)t->cols > t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 1024 * (size_t)t->cols;
        double *grown = asp_realloc(t->ctx, t->vals, t->cap * sizeof *grown, cap * sizeof *grown);
        if (!grown)
            return asp_error_set(t->err, ASP_ENOMEM, "cannot read '%s': out of memory", t->name);
        t->vals = grown;
        t->cap = cap;
    }
    memcpy(t->vals + t->rows * (size_t)t->cols, v, (size_t)t->cols * sizeof *v);
    t->rows++;
    return 0;
}

/* Records why the colour columns of this row could not be 0..255 bytes or 0..1 fractions. */
static void colour_evidence(text_reader *t, const double *c, size_t line)
{
    for (int k = 0; k < 3; k++) {
        double v = c[k];
        if (!t->not_byte_line && !(v >= 0 && v <= 255 && v == floor(v))) {
            t->not_byte_line = line;
            t->not_byte_value = v;
        }
        if (!t->not_unit_line && !(v >= 0 && v <= 1)) {
            t->not_unit_line = line;
            t->not_unit_value = v;
        }
    }
    if (c[0] + c[1] + c[2] != 1.0 || c[0] * c[1] + c[1] * c[2] + c[0] * c[2] != 0.0)
        t->all_unit_triples = 0;
}

/*
 * A .pts count that disagrees with the points that follow means a cut-off
 * or mislabelled file; both numbers go in the message (issue #13).
 */
static int check_declared(const text_reader *t)
{
    if (t->declared < 0 || t->declared == (double)t->rows)
        return 0;
    return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu declares %.0f points, but %zu follow",
                         t->name, t->declared_line, t->declared, t->rows);
}

static int parse_lines(text_reader *t)
{
    size_t lineno = 0;
    int first = 1;
    for (;;) {
        const char *raw;
        size_t len;
        int got = asp__src_line(&t->src, LINE_MAX_BYTES, &raw, &len);
        lineno++;
        if (got == 0)
            return check_declared(t);
        if (got == -1)
            return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu: longer than %d bytes", t->name,
                                 lineno, LINE_MAX_BYTES);
        if (got == -2)
            return asp_error_set(t->err, t->src.nomem ? ASP_ENOMEM : ASP_EIO, "cannot read '%s': %s", t->name,
                                 t->src.nomem ? "out of memory" : strerror(t->src.io_errno));
        memcpy(t->line, raw, len);
        t->line[len] = '\0';
        const char *p = t->line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0' || *p == '#' || (p[0] == '/' && p[1] == '/'))
            continue;
        double v[MAX_COLS + 1];
        int n = 0, rc;
        while (n <= MAX_COLS && (rc = asp__scalar_parse(&p, ",;", ASP_SCALAR_FLOAT64, &v[n])) == 0)
            n++;
        if (n <= MAX_COLS && rc == -2) {
            char tok[40];
            size_t k = 0;
            while (p[k] && !isspace((unsigned char)p[k]) && p[k] != ',' && p[k] != ';' && k < 32)
                tok[k] = (p[k] >= 0x20 && p[k] < 0x7f) ? p[k] : '?', k++;
            tok[k] = '\0';
            return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu: value '%s' is not a number",
                                 t->name, lineno, tok);
        }
        if (n == 0)
            continue; /* only separators */
        // issue #31: a file cut inside its last line and one that merely lacks the final newline look
        // alike; a malformed row fails above and below, a well-formed one is read with a warning
        if (t->src.unterminated)
            asp_warn(t->ctx, "'%s': line %zu, the last, has no newline at its end: if the file was cut off there, "
                     "its values are incomplete", t->name, lineno);
        if (first && n == 1 && v[0] >= 0 && v[0] == floor(v[0])) {
            first = 0; /* a point count, as .pts files start with */
            t->declared = v[0];
            t->declared_line = lineno;
            continue;
        }
        first = 0;
        if (t->cols == 0) {
            if (n != 3 && n != 4 && n != 6 && n != 7 && n != 9)
                return asp_error_set(t->err, ASP_EFORMAT,
                                     "cannot read '%s': line %zu: expected 3, 4, 6, 7 or 9 values per line, got %s%d",
                                     t->name, lineno, n > MAX_COLS ? "more than " : "", n > MAX_COLS ? MAX_COLS : n);
            t->cols = n;
        } else if (n != t->cols) {
            return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu: expected %d values, got %s%d",
                                 t->name, lineno, t->cols, n > MAX_COLS ? "more than " : "",
                                 n > MAX_COLS ? MAX_COLS : n);
        }
        for (int k = 0; k < 3; k++) {
            if (!isfinite(v[k]))
                return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': line %zu: coordinate %c is %s",
                                     t->name, lineno, "xyz"[k], isnan(v[k]) ? "NaN" : "infinite");
            // positions are float offsets: a value past FLT_MAX would become infinite (found by fuzz_xyz)
            if (fabs(v[k]) > FLT_MAX)
                return asp_error_set(t->err, ASP_EFORMAT,
                                     "cannot read '%s': line %zu: coordinate %c %.9g is outside the float range "
                                     "(magnitude at most %.9g)",
                                     t->name, lineno, "xyz"[k], v[k], (double)FLT_MAX);
        }
        if (t->cols >= 6)
            colour_evidence(t, v + t->cols - 3, lineno);
        if ((rc = push_row(t, v)))
            return rc;
    }
}

/* Decides the layout from the column count and the colour evidence, then fills the cloud. */
static int build_cloud(text_reader *t, asp_cloud **out)
{
    if (t->rows == 0)
        return asp_error_set(t->err, ASP_EFORMAT, "cannot read '%s': no points in the file", t->name);
    int cols = t->cols;
    int has_rgb = cols == 7 || cols == 9 ||
                  (cols == 6 && !t->not_byte_line && !t->all_unit_triples);
    int has_normals = cols == 9 || (cols == 6 && !has_rgb);
    int has_intensity = cols == 4 || cols == 7;
    int float_rgb = 0;
    if (has_rgb && t->not_byte_line) {
        if (t->not_unit_line) {
            size_t line = t->not_byte_line > t->not_unit_line ? t->not_byte_line : t->not_unit_line;
            double v = t->not_byte_line >= t->not_unit_line ? t->not_byte_value : t->not_unit_value;
            return fail(t, line, "colour values must be integers 0..255 or all in 0..1, got ", v);
        }
        float_rgb = 1;
    }
    unsigned attrs = (has_rgb ? ASP_ATTR_COLORS : 0) | (has_normals ? ASP_ATTR_NORMALS : 0);
    asp_cloud *c;
    asp_error e2;
    if (asp_cloud_create(t->rows, attrs, t->ctx, &c, &e2))
        return asp_error_set(t->err, e2.code, "cannot read '%s': %s", t->name, e2.msg);
    asp_property *intensity = NULL;
    if (has_intensity && asp_cloud_add_property(c, "intensity", ASP_SCALAR_FLOAT32, &intensity, &e2)) {
        asp_cloud_destroy(c);
        return asp_error_set(t->err, e2.code, "cannot read '%s': %s", t->name, e2.msg);
    }
    /* far from zero, float offsets from a rounded bounding-box centre keep the scan's precision */
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = t->vals[k];
    for (size_t i = 1; i < t->rows; i++)
        for (int k = 0; k < 3; k++) {
            double v = t->vals[i * (size_t)cols + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    int far = 0;
    for (int k = 0; k < 3; k++)
        far |= fabs(lo[k]) > 65536.0 || fabs(hi[k]) > 65536.0;
    for (int k = 0; k < 3 && far; k++)
        c->origin[k] = floor(0.5 * (lo[k] + hi[k]) + 0.5);
    c->position_type = far ? ASP_SCALAR_FLOAT64 : ASP_SCALAR_FLOAT32;
    c->color_type = float_rgb ? ASP_SCALAR_FLOAT32 : ASP_SCALAR_UINT8;
    for (size_t i = 0; i < t->rows; i++) {
        const double *v = t->vals + i * (size_t)cols;
        for (int k = 0; k < 3; k++)
            c->positions[3 * i + k] = (float)(v[k] - c->origin[k]);
        if (has_normals)
            for (int k = 0; k < 3; k++)
                c->normals[3 * i + k] = (float)v[3 + k];
        if (has_intensity)
            ((float *)intensity->data)[i] = (float)v[3];
        if (has_rgb) {
            const double *rgb = v + cols - 3;
            for (int k = 0; k < 3; k++)
                c->colors[4 * i + k] = float_rgb ? (uint8_t)(rgb[k] * 255.0 + 0.5) : (uint8_t)rgb[k];
            c->colors[4 * i + 3] = 255;
        }
    }
    *out = c;
    return 0;
}

static int read_text(text_reader *t, asp_cloud **out)
{
    int rc = 0;
    t->declared = -1;
    t->src.cr_lines = 1; // CR, LF and CRLF all end a line: a CR-only file is not one point (issue #13)
    t->all_unit_triples = 1;
    t->line = asp_alloc(t->ctx, LINE_MAX_BYTES + 1);
    if (!t->line)
        rc = asp_error_set(t->err, ASP_ENOMEM, "cannot read '%s': out of memory", t->name);
    if (rc == 0)
        rc = parse_lines(t);
    if (rc == 0)
        rc = build_cloud(t, out);
    asp_free(t->ctx, t->line);
    asp_free(t->ctx, t->vals);
    asp__src_close(&t->src);
    return rc;
}

int asp_xyz_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    text_reader t;
    memset(&t, 0, sizeof t);
    t.ctx = ctx;
    t.name = path;
    t.err = err;
    int rc = asp__src_open_file(&t.src, path, ctx, err);
    return rc ? rc : read_text(&t, out);
}

int asp_xyz_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err)
{
    text_reader t;
    memset(&t, 0, sizeof t);
    t.ctx = ctx;
    t.name = name ? name : "<memory>";
    t.err = err;
    asp__src_open_memory(&t.src, data, size, t.name, ctx);
    return read_text(&t, out);
}

/* ---------- writing ---------- */

/* Leica PTS opens with the point count; the one recogniser says which text flavour a name asks for. */
static int wants_count_line(const char *path)
{
    asp_file_type t;
    return asp_file_type_of_name(path, &t, NULL) == 0 && strcmp(t.format, "pts") == 0;
}

int asp_xyz_write(const asp_cloud *c, const char *path, const asp_save_desc *desc, asp_error *err)
{
    (void)desc;
    const asp_property *intensity = c->normals ? NULL : asp_cloud_find_property(c, "intensity");
    int world = c->origin[0] != 0.0 || c->origin[1] != 0.0 || c->origin[2] != 0.0;
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    if (wants_count_line(path))
        fprintf(f.fp, "%zu\n", c->count);
    char line[16 * 32];
    for (size_t i = 0; i < c->count; i++) {
        size_t len = 0;
        for (int k = 0; k < 3; k++) {
            if (k)
                line[len++] = ' ';
            len += world ? asp__format_double(line + len, c->origin[k] + (double)c->positions[3 * i + k])
                         : asp__format_float(line + len, c->positions[3 * i + k]);
        }
        if (c->normals)
            for (int k = 0; k < 3; k++) {
                line[len++] = ' ';
                len += asp__format_float(line + len, c->normals[3 * i + k]);
            }
        if (intensity) {
            line[len++] = ' ';
            len += asp__format_scalar(line + len, (const uint8_t *)intensity->data + i * asp_scalar_size(intensity->type),
                                      intensity->type);
        }
        if (c->colors)
            len += (size_t)snprintf(line + len, 48, " %u %u %u", c->colors[4 * i], c->colors[4 * i + 1],
                                    c->colors[4 * i + 2]);
        line[len++] = '\n';
        if (fwrite(line, 1, len, f.fp) != len)
            break;
    }
    // read back as asp_cloud_load reads it (issue #31: every output kind)
    return asp__atomic_commit_checked(&f, asp__cloud_reads_back, &(asp__cloud_readback){c, "xyz"}, err);
}
