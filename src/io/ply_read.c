/*
 * PLY reader: the whole format (ascii, binary little/big endian, every scalar
 * type, lists in any element, elements in any order) into an asp_cloud, the
 * point-set input of the pipeline (journal Sect. 1, Fig. 2; per-sample
 * normals and uvs as in Schwarz 2004 3.1.6-3.1.7). Counts are checked
 * against the file size before anything is allocated, so a lying header
 * cannot exhaust memory.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/io.h"
#include "io/buffered_source.h"
#include "io/ply_internal.h"
#include "util/banned.h"

enum { ENC_ASCII, ENC_LE, ENC_BE };
enum { D_SKIP, D_POS, D_NORMAL, D_COLOR, D_RADIUS, D_UV, D_LABEL, D_EXTRA, D_FACE, D_STRIP };
enum { NAME_MAX_LEN = 63, HEADER_LINE_MAX = 1 << 16, BODY_LINE_MAX = 1 << 24, CHUNK_RECORDS = 1 << 14 };

typedef struct ply_prop {
    char name[NAME_MAX_LEN + 1];
    asp_scalar_type type;       /* value type; item type of a list */
    asp_scalar_type count_type; /* NONE for a scalar property */
    size_t line;
    int dest, k;                /* destination and its component / extra index */
    size_t offset;              /* byte offset in a fixed binary record */
} ply_prop;

typedef struct ply_element {
    char name[NAME_MAX_LEN + 1];
    uint64_t count;
    size_t line;
    ply_prop *props;
    size_t nprops, cap;
    int fixed;       /* no list property: every binary record has rec_size bytes */
    size_t rec_size; /* binary: scalar sizes plus list count sizes (the minimum when not fixed) */
} ply_element;

typedef struct reader {
    asp__src src;
    const asp_context *ctx;
    const char *name;
    asp_error *err;
    int enc, swap;
    ply_element *elems;
    size_t nelems, elem_cap;
    char *notes; /* comment/obj_info lines: kind byte ('c' or 'o'), text, NUL; back to back */
    size_t notes_len, notes_cap;
    size_t line;            /* lines consumed so far (header and ascii body) */
    ply_element *vertex;
    size_t short_faces;     /* face lists of fewer than 3 indices: no surface (issue #13) */
    const ply_prop *pos[3]; /* x, y, z of the vertex element */
    asp_cloud *cloud;
    double origin[3];
    int wide[3];            /* axis stored as double or 32-bit integer: needs an origin */
    uint32_t *faces;        /* 3 indices per triangle */
    size_t face_count, face_cap;
    double *tmp;            /* CHUNK_RECORDS values, one column of a binary chunk */
    char *scratch;          /* NUL-terminated copy of the current text line */
    size_t scratch_cap;
} reader;

/* ---------- errors ---------- */

/* Printable excerpt of untrusted text for messages (binary junk becomes '?'). */
static const char *excerpt(char out[40], const char *s, size_t len)
{
    size_t n = len < 32 ? len : 32;
    for (size_t i = 0; i < n; i++)
        out[i] = (s[i] >= 0x20 && s[i] < 0x7f && s[i] != '\'') ? s[i] : '?';
    if (len > 32) {
        memcpy(out + 32, "...", 3);
        n = 35;
    }
    out[n] = '\0';
    return out;
}

#define FAIL_LINE(r, lineno, ...) fail_line(r, ASP_EFORMAT, lineno, __VA_ARGS__)

static int fail_line(reader *r, int code, size_t line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static int fail_line(reader *r, int code, size_t line, const char *fmt, ...)
{
    char what[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return asp_error_set(r->err, code, "cannot read '%s': line %zu: %s", r->name, line, what);
}

static int fail_bin(reader *r, const ply_element *e, uint64_t index, uint64_t offset, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

static int fail_bin(reader *r, const ply_element *e, uint64_t index, uint64_t offset, const char *fmt, ...)
{
    char what[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': element '%s' %llu of %llu, byte %llu: %s", r->name,
                         e->name, (unsigned long long)index + 1, (unsigned long long)e->count,
                         (unsigned long long)offset, what);
}

/* Why fill() came up short: read error, out of memory, or the input ended. */
static int fail_short(reader *r, const ply_element *e, uint64_t index)
{
    if (r->src.io_errno)
        return asp_error_set(r->err, ASP_EIO, "cannot read '%s': %s", r->name, strerror(r->src.io_errno));
    if (r->src.nomem)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
    if (!e)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': unexpected end of file", r->name);
    return fail_bin(r, e, index, r->src.size, "unexpected end of file");
}

/* ---------- header ---------- */

static int next_word(const char **p, const char **w, size_t *len)
{
    const char *s = *p;
    while (*s == ' ' || *s == '\t')
        s++;
    const char *start = s;
    while (*s && *s != ' ' && *s != '\t')
        s++;
    *w = start;
    *len = (size_t)(s - start);
    *p = s;
    return *len > 0;
}

static int word_is(const char *w, size_t len, const char *lit)
{
    return strlen(lit) == len && memcmp(w, lit, len) == 0;
}

static int add_note(reader *r, char kind, const char *text)
{
    size_t len = strlen(text);
    if (r->notes_len + len + 2 > r->notes_cap) {
        size_t cap = (r->notes_cap + len + 2) * 2;
        char *grown = asp_realloc(r->ctx, r->notes, r->notes_cap, cap);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        r->notes = grown;
        r->notes_cap = cap;
    }
    r->notes[r->notes_len++] = kind;
    memcpy(r->notes + r->notes_len, text, len + 1);
    r->notes_len += len + 1;
    return 0;
}

static int parse_count(const char *w, size_t len, uint64_t *out)
{
    uint64_t v = 0;
    if (len == 0 || len > 19)
        return -1;
    for (size_t i = 0; i < len; i++) {
        if (w[i] < '0' || w[i] > '9')
            return -1;
        v = v * 10 + (uint64_t)(w[i] - '0');
    }
    *out = v;
    return 0;
}

static int header_element(reader *r, const char *p)
{
    const char *w, *c;
    size_t wl, cl;
    if (!next_word(&p, &w, &wl) || !next_word(&p, &c, &cl))
        return FAIL_LINE(r, r->line, "expected 'element NAME COUNT'");
    char buf[40];
    if (wl > NAME_MAX_LEN)
        return FAIL_LINE(r, r->line, "element name '%s' is longer than %d bytes", excerpt(buf, w, wl), NAME_MAX_LEN);
    uint64_t count;
    if (parse_count(c, cl, &count))
        return FAIL_LINE(r, r->line, "element '%.*s': count '%s' is not a non-negative integer", (int)wl, w,
                         excerpt(buf, c, cl));
    const char *extra;
    size_t el;
    if (next_word(&p, &extra, &el))
        return FAIL_LINE(r, r->line, "expected 'element NAME COUNT', got more");
    for (size_t i = 0; i < r->nelems; i++)
        if (word_is(w, wl, r->elems[i].name))
            return FAIL_LINE(r, r->line, "element '%.*s' appears twice", (int)wl, w);
    if (r->nelems == r->elem_cap) {
        size_t cap = r->elem_cap ? 2 * r->elem_cap : 8;
        ply_element *grown = asp_realloc(r->ctx, r->elems, r->elem_cap * sizeof *grown, cap * sizeof *grown);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        r->elems = grown;
        r->elem_cap = cap;
    }
    ply_element *e = &r->elems[r->nelems++];
    memset(e, 0, sizeof *e);
    memcpy(e->name, w, wl);
    e->count = count;
    e->line = r->line;
    e->fixed = 1;
    return 0;
}

static int header_type(reader *r, const char *w, size_t wl, const char *prop, size_t pl, asp_scalar_type *t)
{
    char buf[40], nb[40];
    *t = asp__ply_type_from_name(w, wl);
    if (*t == ASP_SCALAR_NONE)
        return FAIL_LINE(r, r->line, "unknown scalar type '%s' for property '%s'", excerpt(buf, w, wl),
                         excerpt(nb, prop, pl));
    return 0;
}

static int header_property(reader *r, const char *p)
{
    if (r->nelems == 0)
        return FAIL_LINE(r, r->line, "property before any element");
    ply_element *e = &r->elems[r->nelems - 1];
    const char *w[5];
    size_t wl[5], n = 0;
    while (n < 5 && next_word(&p, &w[n], &wl[n]))
        n++;
    const char *rest;
    size_t rl;
    int is_list = n > 0 && word_is(w[0], wl[0], "list");
    if (n != (is_list ? 4u : 2u) || next_word(&p, &rest, &rl))
        return FAIL_LINE(r, r->line, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
    const char *name = w[n - 1];
    size_t nl = wl[n - 1];
    char buf[40];
    if (nl > NAME_MAX_LEN)
        return FAIL_LINE(r, r->line, "property name '%s' is longer than %d bytes", excerpt(buf, name, nl),
                         NAME_MAX_LEN);
    ply_prop prop;
    memset(&prop, 0, sizeof prop);
    memcpy(prop.name, name, nl);
    prop.line = r->line;
    int rc = header_type(r, w[n - 2], wl[n - 2], name, nl, &prop.type);
    if (rc)
        return rc;
    if (is_list) {
        if ((rc = header_type(r, w[1], wl[1], name, nl, &prop.count_type)))
            return rc;
        if (!asp__scalar_is_int(prop.count_type))
            return FAIL_LINE(r, r->line, "list '%s' has count type '%.*s'; expected an integer type", prop.name,
                             (int)wl[1], w[1]);
    }
    for (size_t i = 0; i < e->nprops; i++)
        if (strcmp(e->props[i].name, prop.name) == 0)
            return FAIL_LINE(r, r->line, "property '%s' appears twice in element '%s'", prop.name, e->name);
    if (e->nprops == e->cap) {
        size_t cap = e->cap ? 2 * e->cap : 16;
        ply_prop *grown = asp_realloc(r->ctx, e->props, e->cap * sizeof *grown, cap * sizeof *grown);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        e->props = grown;
        e->cap = cap;
    }
    prop.offset = e->rec_size;
    e->rec_size += asp_scalar_size(is_list ? prop.count_type : prop.type);
    if (is_list)
        e->fixed = 0;
    e->props[e->nprops++] = prop;
    return 0;
}

static int header_format(reader *r, const char *p, int *seen)
{
    const char *w, *v, *x;
    size_t wl, vl, xl;
    char buf[40];
    if (*seen)
        return FAIL_LINE(r, r->line, "second 'format' line");
    if (!next_word(&p, &w, &wl) || !next_word(&p, &v, &vl) || next_word(&p, &x, &xl))
        return FAIL_LINE(r, r->line, "expected 'format ENCODING 1.0'");
    if (word_is(w, wl, "ascii"))
        r->enc = ENC_ASCII;
    else if (word_is(w, wl, "binary_little_endian"))
        r->enc = ENC_LE;
    else if (word_is(w, wl, "binary_big_endian"))
        r->enc = ENC_BE;
    else
        return FAIL_LINE(r, r->line, "unknown format '%s' (expected ascii, binary_little_endian or binary_big_endian)",
                         excerpt(buf, w, wl));
    if (!(word_is(v, vl, "1.0") || word_is(v, vl, "1")))
        return fail_line(r, ASP_EFORMAT, r->line, "unsupported PLY version '%s' (expected 1.0)", excerpt(buf, v, vl));
    r->swap = r->enc != ENC_ASCII && (r->enc == ENC_BE) != asp__host_big_endian();
    *seen = 1;
    return 0;
}

/* NUL-terminated copy of a line in r->scratch, since the window is not writable and has no terminator. */
static int copy_line(reader *r, const char *line, size_t len)
{
    if (len + 1 > r->scratch_cap) {
        size_t cap = (len + 1) * 2;
        char *grown = asp_realloc(r->ctx, r->scratch, r->scratch_cap, cap);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
        r->scratch = grown;
        r->scratch_cap = cap;
    }
    memcpy(r->scratch, line, len);
    r->scratch[len] = '\0';
    return 0;
}

static int read_header(reader *r)
{
    const char *line;
    size_t len;
    int seen_format = 0;
    for (;;) {
        int got = asp__src_line(&r->src, HEADER_LINE_MAX, &line, &len);
        r->line++;
        if (got == -1)
            return FAIL_LINE(r, r->line, "header line longer than %d bytes", HEADER_LINE_MAX);
        if (got == -2)
            return fail_short(r, NULL, 0);
        if (got == 0) {
            if (r->line == 1)
                return FAIL_LINE(r, r->line, "file is empty (expected 'ply')");
            return FAIL_LINE(r, r->line, "unexpected end of file in the header (no 'end_header')");
        }
        int rc = copy_line(r, line, len);
        if (rc)
            return rc;
        const char *lbuf = r->scratch;
        if (r->line == 1) {
            char buf[40];
            if (strcmp(lbuf, "ply") != 0)
                return FAIL_LINE(r, 1, "not a PLY file: expected 'ply', got '%s'", excerpt(buf, line, len));
            continue;
        }
        const char *p = lbuf, *kw;
        size_t kl;
        if (!next_word(&p, &kw, &kl))
            continue; /* blank header line: tolerated */
        if (word_is(kw, kl, "comment") || word_is(kw, kl, "obj_info")) {
            /* keep the text after one separator byte verbatim, for exact round trips */
            rc = add_note(r, kw[0], *p ? p + 1 : p);
        } else if (word_is(kw, kl, "format")) {
            rc = header_format(r, p, &seen_format);
        } else if (word_is(kw, kl, "element")) {
            rc = seen_format ? header_element(r, p) : FAIL_LINE(r, r->line, "element before the 'format' line");
        } else if (word_is(kw, kl, "property")) {
            rc = header_property(r, p);
        } else if (word_is(kw, kl, "end_header")) {
            if (!seen_format)
                return FAIL_LINE(r, r->line, "no 'format' line before 'end_header'");
            return 0;
        } else if (r->nelems == 0) {
            /*
             * Blender 2.4x writes "Created by Blender ..." without 'comment'.
             * Before the first element such a line cannot shift any column,
             * so it is kept as a comment, with a warning; among properties a
             * misspelt 'property' would, so there it stays an error.
             */
            char buf[40];
            asp_warn(r->ctx, "'%s': line %zu: header line starting '%s' has no 'comment' keyword; kept as a comment",
                     r->name, r->line, excerpt(buf, kw, kl));
            rc = add_note(r, 'c', kw);
        } else {
            char buf[40];
            rc = FAIL_LINE(r, r->line, "unknown header keyword '%s'", excerpt(buf, kw, kl));
        }
        if (rc)
            return rc;
    }
}

/* ---------- mapping properties onto the cloud ---------- */

static ply_prop *find_prop(ply_element *e, const char *name)
{
    for (size_t i = 0; i < e->nprops; i++)
        if (strcmp(e->props[i].name, name) == 0)
            return &e->props[i];
    return NULL;
}

static int type_in(asp_scalar_type t, unsigned mask)
{
    return (mask >> t) & 1u;
}

#define FLOATS ((1u << ASP_SCALAR_FLOAT32) | (1u << ASP_SCALAR_FLOAT64))
#define COLOURS (FLOATS | (1u << ASP_SCALAR_UINT8))

/* Assigns dest to the n named properties if all exist as unassigned scalars of one allowed type. */
static int claim(ply_element *e, const char *const *names, int n, int dest, unsigned types)
{
    ply_prop *p[4];
    for (int i = 0; i < n; i++) {
        p[i] = find_prop(e, names[i]);
        if (!p[i] || p[i]->count_type != ASP_SCALAR_NONE || p[i]->dest != D_EXTRA || !type_in(p[i]->type, types) ||
            p[i]->type != p[0]->type)
            return 0;
    }
    for (int i = 0; i < n; i++) {
        p[i]->dest = dest;
        p[i]->k = i;
    }
    return 1;
}

static int map_vertex(reader *r, unsigned *attrs)
{
    ply_element *e = r->vertex;
    static const char *const xyz[] = {"x", "y", "z"};
    for (size_t i = 0; i < e->nprops; i++)
        e->props[i].dest = e->props[i].count_type ? D_SKIP : D_EXTRA;
    for (int k = 0; k < 3; k++) {
        ply_prop *p = find_prop(e, xyz[k]);
        if (!p)
            return FAIL_LINE(r, e->line, "element 'vertex' has no property '%s'", xyz[k]);
        if (p->count_type)
            return FAIL_LINE(r, p->line, "property '%s' of element 'vertex' is a list; expected a scalar", xyz[k]);
        p->dest = D_POS;
        p->k = k;
        r->pos[k] = p;
        r->wide[k] = p->type == ASP_SCALAR_FLOAT64 || p->type == ASP_SCALAR_INT32 || p->type == ASP_SCALAR_UINT32;
    }
    static const char *const normals[][3] = {{"nx", "ny", "nz"}, {"normal_x", "normal_y", "normal_z"}};
    for (int s = 0; s < 2; s++)
        if (claim(e, normals[s], 3, D_NORMAL, FLOATS)) {
            *attrs |= ASP_ATTR_NORMALS;
            break;
        }
    static const char *const colours[][4] = {
        {"red", "green", "blue", "alpha"}, {"r", "g", "b", "a"},
        {"diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"}};
    for (int s = 0; s < 3; s++)
        if (claim(e, colours[s], 4, D_COLOR, COLOURS) || claim(e, colours[s], 3, D_COLOR, COLOURS)) {
            *attrs |= ASP_ATTR_COLORS;
            break;
        }
    static const char *const radii[][1] = {{"radius"}, {"psz"}, {"point_size"}};
    for (int s = 0; s < 3; s++)
        if (claim(e, radii[s], 1, D_RADIUS, FLOATS)) {
            *attrs |= ASP_ATTR_RADII;
            break;
        }
    static const char *const uvs[][2] = {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}};
    for (int s = 0; s < 3; s++)
        if (claim(e, uvs[s], 2, D_UV, FLOATS)) {
            *attrs |= ASP_ATTR_UVS;
            break;
        }
    static const char *const label[] = {"label"};
    if (claim(e, label, 1, D_LABEL, 1u << ASP_SCALAR_UINT32))
        *attrs |= ASP_ATTR_LABELS;
    return 0;
}

/*
 * Faces come as polygons ("face", fan-triangulated) or as triangle strips
 * ("tristrips", a scanner export; -1 restarts a strip). Taking a strip for
 * one polygon would sample a fan of the wrong triangles (issue #13).
 */
static void map_other(ply_element *e)
{
    int kind = strcmp(e->name, "face") == 0 ? D_FACE : strcmp(e->name, "tristrips") == 0 ? D_STRIP : D_SKIP;
    for (size_t i = 0; i < e->nprops; i++) {
        ply_prop *p = &e->props[i];
        p->dest = D_SKIP;
        if (kind != D_SKIP && p->count_type && asp__scalar_is_int(p->type) &&
            (strcmp(p->name, "vertex_indices") == 0 || strcmp(p->name, "vertex_index") == 0)) {
            p->dest = kind;
            kind = D_SKIP; /* only the first index list */
        }
    }
}

/* Lying-header guard: every record needs some bytes, so the counts must fit in what follows the header. */
static int check_sizes(reader *r)
{
    uint64_t remaining = asp__src_remaining(&r->src), need = 0;
    for (size_t i = 0; i < r->nelems; i++) {
        ply_element *e = &r->elems[i];
        uint64_t min_rec = r->enc == ENC_ASCII ? e->nprops : e->rec_size;
        if (min_rec == 0 || e->count == 0)
            continue;
        if (e->count > (remaining - need) / min_rec)
            return FAIL_LINE(r, e->line,
                             "element '%s' declares %llu records of at least %llu bytes, but only %llu bytes follow "
                             "the header",
                             e->name, (unsigned long long)e->count, (unsigned long long)min_rec,
                             (unsigned long long)(remaining - need));
        need += e->count * min_rec;
    }
    return 0;
}

static int setup_cloud(reader *r)
{
    for (size_t i = 0; i < r->nelems; i++)
        if (strcmp(r->elems[i].name, "vertex") == 0)
            r->vertex = &r->elems[i];
        else
            map_other(&r->elems[i]);
    if (!r->vertex)
        return FAIL_LINE(r, r->line, "no 'vertex' element in the header");
    unsigned attrs = 0;
    int rc = map_vertex(r, &attrs);
    if (rc || (rc = check_sizes(r)))
        return rc;
    ply_element *v = r->vertex;
    if (v->count == 0)
        return FAIL_LINE(r, v->line, "element 'vertex' is empty");
    if (v->count >= UINT32_MAX)
        return fail_line(r, ASP_EUNSUPPORTED, v->line, "%llu points are more than a cloud holds (2^32-1)",
                         (unsigned long long)v->count);
    asp_error e2;
    if (asp_cloud_create((size_t)v->count, attrs, r->ctx, &r->cloud, &e2))
        return asp_error_set(r->err, e2.code, "cannot read '%s': %s", r->name, e2.msg);
    asp_cloud *c = r->cloud;
    int has_alpha = 0;
    c->position_type = (r->wide[0] || r->wide[1] || r->wide[2]) ? ASP_SCALAR_FLOAT64 : ASP_SCALAR_FLOAT32;
    for (size_t i = 0; i < v->nprops; i++) {
        ply_prop *p = &v->props[i];
        if (p->dest == D_COLOR) {
            c->color_type = p->type == ASP_SCALAR_UINT8 ? ASP_SCALAR_UINT8 : ASP_SCALAR_FLOAT32;
            has_alpha |= p->k == 3;
        }
        if (p->dest == D_EXTRA) {
            p->k = (int)c->property_count;
            if (asp_cloud_add_property(c, p->name, p->type, NULL, &e2))
                return asp_error_set(r->err, e2.code, "cannot read '%s': %s", r->name, e2.msg);
        }
    }
    if (c->colors && !has_alpha)
        for (size_t i = 0; i < c->count; i++)
            c->colors[4 * i + 3] = 255;
    for (size_t at = 0; at < r->notes_len;) {
        const char *text = r->notes + at + 1;
        rc = r->notes[at] == 'c' ? asp_cloud_add_comment(c, text, &e2) : asp_cloud_add_obj_info(c, text, &e2);
        if (rc)
            return asp_error_set(r->err, rc, "cannot read '%s': %s", r->name, e2.msg);
        at += strlen(text) + 2;
    }
    return 0;
}

/* ---------- storing values ---------- */

static uint8_t unit_to_byte(double v)
{
    if (!(v > 0.0))
        return 0;
    return v >= 1.0 ? 255 : (uint8_t)(v * 255.0 + 0.5);
}

/* Stores n values of property p for points i0.. ; returns the first bad (non-finite position) index or -1. */
static long store_column(reader *r, const ply_prop *p, size_t i0, const double *v, size_t n)
{
    asp_cloud *c = r->cloud;
    switch (p->dest) {
    case D_POS: {
        float *dst = c->positions + 3 * i0 + p->k;
        double o = r->origin[p->k];
        for (size_t t = 0; t < n; t++) {
            if (!isfinite(v[t]))
                return (long)t;
            dst[3 * t] = (float)(v[t] - o);
        }
        break;
    }
    case D_NORMAL:
        for (size_t t = 0; t < n; t++)
            c->normals[3 * (i0 + t) + p->k] = (float)v[t];
        break;
    case D_COLOR:
        if (p->type == ASP_SCALAR_UINT8)
            for (size_t t = 0; t < n; t++)
                c->colors[4 * (i0 + t) + p->k] = (uint8_t)v[t];
        else
            for (size_t t = 0; t < n; t++)
                c->colors[4 * (i0 + t) + p->k] = unit_to_byte(v[t]);
        break;
    case D_RADIUS:
        for (size_t t = 0; t < n; t++)
            c->radii[i0 + t] = (float)v[t];
        break;
    case D_UV:
        for (size_t t = 0; t < n; t++)
            c->uvs[2 * (i0 + t) + p->k] = (float)v[t];
        break;
    case D_LABEL:
        for (size_t t = 0; t < n; t++)
            c->labels[i0 + t] = (uint32_t)v[t];
        break;
    default:
        break;
    }
    return -1;
}

/* Wide axes keep float offsets from the first point, rounded so the origin prints exactly. */
static void set_origin(reader *r, const double first[3])
{
    for (int k = 0; k < 3; k++)
        r->origin[k] = r->wide[k] && isfinite(first[k]) && fabs(first[k]) < 1e300 ? floor(first[k] + 0.5) : 0.0;
    memcpy(r->cloud->origin, r->origin, sizeof r->origin);
}

static const char *axis_problem(double v)
{
    return isnan(v) ? "NaN" : "infinite";
}

static int add_triangle(reader *r, uint32_t a, uint32_t b, uint32_t c)
{
    if (r->face_count == r->face_cap) {
        size_t cap = r->face_cap ? 2 * r->face_cap : 1024;
        if (cap > SIZE_MAX / (3 * sizeof(uint32_t)))
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': too many faces", r->name);
        uint32_t *grown = asp_realloc(&r->cloud->ctx, r->faces, 3 * r->face_cap * sizeof *grown,
                                      3 * cap * sizeof *grown);
        if (!grown)
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for faces", r->name);
        r->faces = grown;
        r->face_cap = cap;
    }
    uint32_t *f = r->faces + 3 * r->face_count++;
    f[0] = a;
    f[1] = b;
    f[2] = c;
    return 0;
}

/*
 * Triangulation state for one polygon (a fan from its first vertex) or one
 * triangle strip (each vertex with the two before it, every second triangle
 * turned round so all keep the strip's winding; repeated vertices make the
 * zero-area joins between strips and are dropped).
 */
typedef struct fan {
    uint32_t first, prev;
    uint64_t seen;
    int strip;
} fan;

static int fan_push(reader *r, fan *f, uint32_t idx)
{
    int rc = 0;
    if (f->seen == 0)
        f->first = idx;
    else if (f->seen >= 2 && !f->strip)
        rc = add_triangle(r, f->first, f->prev, idx);
    else if (f->seen >= 2 && f->first != f->prev && f->prev != idx && f->first != idx)
        rc = (f->seen & 1) ? add_triangle(r, f->prev, f->first, idx) : add_triangle(r, f->first, f->prev, idx);
    if (f->strip && f->seen >= 1)
        f->first = f->prev;
    f->prev = idx;
    f->seen++;
    return rc;
}

/* ---------- binary bodies ---------- */

static inline uint16_t bswap16(uint16_t x) { return (uint16_t)((x >> 8) | (x << 8)); }
static inline uint32_t bswap32(uint32_t x)
{
    return (x >> 24) | ((x >> 8) & 0xff00u) | ((x << 8) & 0xff0000u) | (x << 24);
}
static inline uint64_t bswap64(uint64_t x) { return ((uint64_t)bswap32((uint32_t)x) << 32) | bswap32((uint32_t)(x >> 32)); }

/* One column of n fixed records (stride bytes apart) into doubles; the type switch sits outside the loop. */
static void load_column(const uint8_t *src, size_t stride, size_t n, asp_scalar_type t, int swap, double *out)
{
#define NATIVE(T)                                 \
    for (size_t i = 0; i < n; i++) {              \
        T x;                                      \
        memcpy(&x, src + i * stride, sizeof x);   \
        out[i] = (double)x;                       \
    }
#define SWAPPED(T, U, SWAP)                       \
    for (size_t i = 0; i < n; i++) {              \
        U u;                                      \
        T x;                                      \
        memcpy(&u, src + i * stride, sizeof u);   \
        u = SWAP(u);                              \
        memcpy(&x, &u, sizeof x);                 \
        out[i] = (double)x;                       \
    }
    switch (t) {
    case ASP_SCALAR_INT8: NATIVE(int8_t) break;
    case ASP_SCALAR_UINT8: NATIVE(uint8_t) break;
    case ASP_SCALAR_INT16: if (swap) { SWAPPED(int16_t, uint16_t, bswap16) } else { NATIVE(int16_t) } break;
    case ASP_SCALAR_UINT16: if (swap) { SWAPPED(uint16_t, uint16_t, bswap16) } else { NATIVE(uint16_t) } break;
    case ASP_SCALAR_INT32: if (swap) { SWAPPED(int32_t, uint32_t, bswap32) } else { NATIVE(int32_t) } break;
    case ASP_SCALAR_UINT32: if (swap) { SWAPPED(uint32_t, uint32_t, bswap32) } else { NATIVE(uint32_t) } break;
    case ASP_SCALAR_FLOAT32: if (swap) { SWAPPED(float, uint32_t, bswap32) } else { NATIVE(float) } break;
    case ASP_SCALAR_FLOAT64: if (swap) { SWAPPED(double, uint64_t, bswap64) } else { NATIVE(double) } break;
    default: break;
    }
#undef NATIVE
#undef SWAPPED
}

/* Raw bytes of an extra property, byte-swapped to native order: exact for every type. */
static void copy_column(const uint8_t *src, size_t stride, size_t n, size_t size, int swap, uint8_t *dst)
{
    for (size_t i = 0; i < n; i++) {
        memcpy(dst + i * size, src + i * stride, size);
        if (swap)
            asp__swap_bytes(dst + i * size, size);
    }
}

static int progress(reader *r)
{
    double f = r->src.size ? (double)asp__src_offset(&r->src) / (double)r->src.size : 1.0;
    if (asp_progress(r->ctx, "read", f))
        return asp_error_set(r->err, ASP_ECANCELED, "cannot read '%s': canceled", r->name);
    return 0;
}

/* Vertex element with only scalars: whole chunks, converted column by column. */
static int read_vertex_fixed(reader *r, ply_element *e)
{
    size_t rs = e->rec_size;
    for (uint64_t i = 0; i < e->count;) {
        uint64_t left = e->count - i;
        size_t n = left < CHUNK_RECORDS ? (size_t)left : CHUNK_RECORDS;
        size_t got = asp__src_fill(&r->src, n * rs);
        if (got < rs)
            return fail_short(r, e, i);
        if (got < n * rs)
            n = got / rs;
        const uint8_t *base = asp__src_ptr(&r->src);
        if (i == 0) {
            double first[3] = {0, 0, 0};
            for (size_t j = 0; j < e->nprops; j++)
                if (e->props[j].dest == D_POS)
                    load_column(base + e->props[j].offset, rs, 1, e->props[j].type, r->swap, &first[e->props[j].k]);
            set_origin(r, first);
        }
        for (size_t j = 0; j < e->nprops; j++) {
            const ply_prop *p = &e->props[j];
            if (p->dest == D_SKIP)
                continue;
            if (p->dest == D_EXTRA) {
                size_t sz = asp_scalar_size(p->type);
                copy_column(base + p->offset, rs, n, sz, r->swap,
                            (uint8_t *)r->cloud->properties[p->k].data + (size_t)i * sz);
                continue;
            }
            load_column(base + p->offset, rs, n, p->type, r->swap, r->tmp);
            long bad = store_column(r, p, (size_t)i, r->tmp, n);
            if (bad >= 0)
                return fail_bin(r, e, i + (uint64_t)bad, asp__src_offset(&r->src) + (uint64_t)bad * rs + p->offset,
                                "coordinate %s is %s", p->name, axis_problem(r->tmp[bad]));
        }
        asp__src_skip(&r->src, n * rs);
        i += n;
        int rc = progress(r);
        if (rc)
            return rc;
    }
    return 0;
}

/* Reads one binary scalar of type t (native order after the call) into raw; returns 0 or an error. */
static int bin_scalar(reader *r, const ply_element *e, uint64_t index, asp_scalar_type t, uint8_t raw[8])
{
    size_t sz = asp_scalar_size(t);
    if (asp__src_fill(&r->src, sz) < sz)
        return fail_short(r, e, index);
    memcpy(raw, asp__src_ptr(&r->src), sz);
    if (r->swap)
        asp__swap_bytes(raw, sz);
    asp__src_skip(&r->src, sz);
    return 0;
}

static int bin_skip(reader *r, const ply_element *e, uint64_t index, uint64_t bytes)
{
    while (bytes > 0) {
        size_t want = bytes < (1u << 20) ? (size_t)bytes : (1u << 20);
        size_t got = asp__src_fill(&r->src, want);
        if (got == 0)
            return fail_short(r, e, index);
        if (got > want)
            got = want;
        asp__src_skip(&r->src, got);
        bytes -= got;
    }
    return 0;
}

static int bin_list(reader *r, const ply_element *e, uint64_t index, const ply_prop *p)
{
    uint8_t raw[8];
    uint64_t at = asp__src_offset(&r->src);
    int rc = bin_scalar(r, e, index, p->count_type, raw);
    if (rc)
        return rc;
    double n = asp__scalar_load(raw, p->count_type);
    if (n < 0)
        return fail_bin(r, e, index, at, "list '%s' has negative count %.0f", p->name, n);
    size_t isz = asp_scalar_size(p->type);
    uint64_t bytes = (uint64_t)n * isz;
    if (bytes > asp__src_remaining(&r->src))
        return fail_bin(r, e, index, at, "list '%s' declares %.0f items, but only %llu bytes remain", p->name, n,
                        (unsigned long long)asp__src_remaining(&r->src));
    if (p->dest != D_FACE && p->dest != D_STRIP)
        return bin_skip(r, e, index, bytes);
    r->short_faces += p->dest == D_FACE && n < 3;
    fan f = {0, 0, 0, p->dest == D_STRIP};
    for (uint64_t k = 0; k < (uint64_t)n; k++) {
        at = asp__src_offset(&r->src);
        if ((rc = bin_scalar(r, e, index, p->type, raw)))
            return rc;
        double v = asp__scalar_load(raw, p->type);
        if (v == -1 && f.strip) {
            f = (fan){0, 0, 0, 1}; // -1 ends one strip and starts the next
            continue;
        }
        if (v < 0 || v >= (double)r->cloud->count)
            return fail_bin(r, e, index, at, "vertex index %.0f is not below the vertex count %zu", v,
                            r->cloud->count);
        if ((rc = fan_push(r, &f, (uint32_t)v)))
            return rc;
    }
    return 0;
}

/* Any element record by record: lists, faces, and vertex elements that contain lists. */
static int read_element_generic(reader *r, ply_element *e)
{
    int is_vertex = e == r->vertex;
    if (!is_vertex && e->fixed)
        return bin_skip(r, e, 0, e->count * e->rec_size); /* check_sizes bounded the product */
    for (uint64_t i = 0; i < e->count; i++) {
        double first[3] = {0, 0, 0};
        uint64_t first_at[3] = {0, 0, 0};
        for (size_t j = 0; j < e->nprops; j++) {
            const ply_prop *p = &e->props[j];
            int rc;
            if (p->count_type) {
                rc = bin_list(r, e, i, p);
            } else {
                uint8_t raw[8];
                uint64_t at = asp__src_offset(&r->src);
                rc = bin_scalar(r, e, i, p->type, raw);
                if (rc == 0 && p->dest == D_EXTRA) {
                    size_t sz = asp_scalar_size(p->type);
                    memcpy((uint8_t *)r->cloud->properties[p->k].data + (size_t)i * sz, raw, sz);
                } else if (rc == 0 && p->dest != D_SKIP) {
                    double v = asp__scalar_load(raw, p->type);
                    if (i == 0 && p->dest == D_POS) {
                        first[p->k] = v; /* stored once the origin is known */
                        first_at[p->k] = at;
                    } else if (store_column(r, p, (size_t)i, &v, 1) >= 0) {
                        rc = fail_bin(r, e, i, at, "coordinate %s is %s", p->name, axis_problem(v));
                    }
                }
            }
            if (rc)
                return rc;
        }
        if (is_vertex && i == 0) {
            set_origin(r, first);
            for (int k = 0; k < 3; k++)
                if (store_column(r, r->pos[k], 0, &first[k], 1) >= 0)
                    return fail_bin(r, e, 0, first_at[k], "coordinate %s is %s", r->pos[k]->name,
                                    axis_problem(first[k]));
        }
        int rc = (i & 0xffff) == 0xffff ? progress(r) : 0;
        if (rc)
            return rc;
    }
    return 0;
}

/* ---------- ascii bodies ---------- */

static int next_body_line(reader *r, const ply_element *e, uint64_t index, char **text)
{
    for (;;) {
        const char *line;
        size_t len;
        int got = asp__src_line(&r->src, BODY_LINE_MAX, &line, &len);
        r->line++;
        if (got == 0)
            return FAIL_LINE(r, r->line, "unexpected end of file: element '%s' declares %llu records, found %llu",
                             e->name, (unsigned long long)e->count, (unsigned long long)index);
        if (got == -1)
            return FAIL_LINE(r, r->line, "line longer than %d bytes", BODY_LINE_MAX);
        if (got == -2)
            return fail_short(r, e, index);
        int rc = copy_line(r, line, len);
        if (rc)
            return rc;
        const char *p = r->scratch;
        while (*p == ' ' || *p == '\t' || *p == '\r')
            p++;
        if (*p) {
            *text = r->scratch;
            return 0;
        }
    }
}

static size_t count_tokens(const char *s)
{
    size_t n = 0;
    uint8_t raw[8];
    while (asp__scalar_parse(&s, NULL, ASP_SCALAR_FLOAT64, raw) != -1) {
        n++;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r')
            s++;
    }
    return n;
}

static int ascii_value(reader *r, const ply_element *e, const char **p, asp_scalar_type t, const char *prop,
                       size_t used, uint8_t raw[8])
{
    int rc = asp__scalar_parse(p, NULL, t, raw);
    if (rc == -1)
        return FAIL_LINE(r, r->line, "expected %s%zu values for element '%s', got %zu", e->fixed ? "" : "at least ",
                         e->fixed ? e->nprops : used + 1, e->name, count_tokens(r->scratch));
    if (rc == -2) {
        const char *end = *p;
        while (*end && *end != ' ' && *end != '\t' && *end != '\r')
            end++;
        char buf[40];
        return FAIL_LINE(r, r->line, "value '%s' is not a valid %s for property '%s' of element '%s'",
                         excerpt(buf, *p, (size_t)(end - *p)), asp_scalar_name(t), prop, e->name);
    }
    return 0;
}

static int read_element_ascii(reader *r, ply_element *e)
{
    for (uint64_t i = 0; i < e->count; i++) {
        char *text = NULL;
        int rc = next_body_line(r, e, i, &text);
        if (rc)
            return rc;
        const char *p = text;
        size_t used = 0;
        double first[3] = {0, 0, 0};
        for (size_t j = 0; j < e->nprops; j++) {
            const ply_prop *q = &e->props[j];
            uint8_t raw[8];
            if (q->count_type) {
                if ((rc = ascii_value(r, e, &p, q->count_type, q->name, used++, raw)))
                    return rc;
                double n = asp__scalar_load(raw, q->count_type);
                if (n < 0)
                    return FAIL_LINE(r, r->line, "list '%s' has negative count %.0f", q->name, n);
                r->short_faces += q->dest == D_FACE && n < 3;
                fan f = {0, 0, 0, q->dest == D_STRIP};
                for (double k = 0; k < n; k++) {
                    if ((rc = ascii_value(r, e, &p, q->type, q->name, used++, raw)))
                        return rc;
                    if (q->dest != D_FACE && q->dest != D_STRIP)
                        continue;
                    double v = asp__scalar_load(raw, q->type);
                    if (v == -1 && f.strip) {
                        f = (fan){0, 0, 0, 1}; // -1 ends one strip and starts the next
                        continue;
                    }
                    if (v < 0 || v >= (double)r->cloud->count)
                        return FAIL_LINE(r, r->line, "vertex index %.0f is not below the vertex count %zu", v,
                                         r->cloud->count);
                    if ((rc = fan_push(r, &f, (uint32_t)v)))
                        return rc;
                }
                continue;
            }
            if ((rc = ascii_value(r, e, &p, q->type, q->name, used++, raw)))
                return rc;
            if (q->dest == D_EXTRA) {
                size_t sz = asp_scalar_size(q->type);
                memcpy((uint8_t *)r->cloud->properties[q->k].data + (size_t)i * sz, raw, sz);
            } else if (q->dest != D_SKIP) {
                double v = asp__scalar_load(raw, q->type);
                if (i == 0 && q->dest == D_POS)
                    first[q->k] = v; /* stored once the origin is known */
                else if (store_column(r, q, (size_t)i, &v, 1) >= 0)
                    return FAIL_LINE(r, r->line, "coordinate %s is %s", q->name, axis_problem(v));
            }
        }
        while (*p == ' ' || *p == '\t' || *p == '\r')
            p++;
        if (*p)
            return FAIL_LINE(r, r->line, "expected %zu values for element '%s', got %zu", used, e->name,
                             count_tokens(text));
        if (e == r->vertex && i == 0) {
            set_origin(r, first);
            for (int k = 0; k < 3; k++)
                if (store_column(r, r->pos[k], 0, &first[k], 1) >= 0)
                    return FAIL_LINE(r, r->line, "coordinate %s is %s", r->pos[k]->name, axis_problem(first[k]));
        }
        rc = (i & 0xffff) == 0xffff ? progress(r) : 0;
        if (rc)
            return rc;
    }
    return 0;
}

static int check_ascii_tail(reader *r)
{
    const char *line;
    size_t len;
    int got;
    while ((got = asp__src_line(&r->src, BODY_LINE_MAX, &line, &len)) == 1) {
        r->line++;
        for (size_t i = 0; i < len; i++)
            if (line[i] != ' ' && line[i] != '\t' && line[i] != '\r' && line[i] != '\0')
                return FAIL_LINE(r, r->line, "unexpected data after the last element (a count is too small)");
    }
    return got == 0 ? 0 : FAIL_LINE(r, r->line + 1, "unexpected data after the last element");
}

/* ---------- driver ---------- */

static int read_body(reader *r)
{
    r->tmp = asp_alloc(r->ctx, CHUNK_RECORDS * sizeof *r->tmp);
    if (!r->tmp)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->name);
    for (size_t i = 0; i < r->nelems; i++) {
        ply_element *e = &r->elems[i];
        if (e->count == 0 || e->nprops == 0)
            continue; /* records with no properties occupy no bytes and no lines */
        int rc;
        if (r->enc == ENC_ASCII)
            rc = read_element_ascii(r, e);
        else if (e == r->vertex && e->fixed)
            rc = read_vertex_fixed(r, e);
        else
            rc = read_element_generic(r, e);
        if (rc)
            return rc;
    }
    if (r->enc == ENC_ASCII)
        return check_ascii_tail(r);
    return 0;
}

static void reader_release(reader *r)
{
    for (size_t i = 0; i < r->nelems; i++)
        asp_free(r->ctx, r->elems[i].props);
    asp_free(r->ctx, r->elems);
    asp_free(r->ctx, r->notes);
    asp_free(r->ctx, r->tmp);
    asp_free(r->ctx, r->scratch);
    if (r->cloud)
        asp_free(&r->cloud->ctx, r->faces);
    asp_cloud_destroy(r->cloud);
    asp__src_close(&r->src);
}

static int read_all(reader *r, asp_cloud **out)
{
    int rc = read_header(r);
    if (rc == 0)
        rc = setup_cloud(r);
    if (rc == 0)
        rc = read_body(r);
    if (rc == 0 && asp_progress(r->ctx, "read", 1.0))
        rc = asp_error_set(r->err, ASP_ECANCELED, "cannot read '%s': canceled", r->name);
    if (rc == 0 && r->face_count) {
        asp_cloud *c = r->cloud;
        c->faces = r->faces;
        c->face_count = r->face_count;
        r->faces = NULL;
    }
    if (rc == 0) {
        *out = r->cloud;
        r->cloud = NULL;
    }
    reader_release(r);
    return rc;
}

int asp_ply_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.name = path;
    r.err = err;
    int rc = asp__src_open_file(&r.src, path, ctx, err);
    if (rc)
        return rc;
    return read_all(&r, out);
}

int asp__ply_read_counting(const char *path, const asp_context *ctx, asp_cloud **out, size_t *short_faces,
                           asp_error *err)
{
    reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.name = path;
    r.err = err;
    int rc = asp__src_open_file(&r.src, path, ctx, err);
    if (rc)
        return rc;
    rc = read_all(&r, out);
    *short_faces = r.short_faces;
    return rc;
}

int asp_ply_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err)
{
    reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.name = name ? name : "<memory>";
    r.err = err;
    asp__src_open_memory(&r.src, data, size, r.name, ctx);
    return read_all(&r, out);
}
