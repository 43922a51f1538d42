/*
 * Mesh pre-checks (see mesh_precheck.h). OFF is read line by line (Geomview's
 * OFF: keyword, "nv nf ne", nv vertex lines, nf face lines "k i1 .. ik [colour]",
 * '#' comments); binary STL's triangle count must fit its size (80-byte
 * header, count, 50 bytes a triangle), ASCII STL follows its grammar; an OBJ must not end inside a face or
 * vertex line, the mark of a file cut off.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io/mesh_precheck.h"
#include "util/byte_io.h"
#include "util/regular_file.h"
#include "util/banned.h"

/* The smallest vertex line "0 0 0\n" and face line "3 0 1 2\n": what the counts must fit in. */
#define OFF_MIN_VERTEX_BYTES 6
#define OFF_MIN_FACE_BYTES 8

typedef struct cursor {
    const char *p, *end;
    size_t line;
} cursor;

/* The next line with its comment cut and not blank; 0 at the end of the bytes. */
static int next_line(cursor *c, const char **s, const char **e)
{
    while (c->p < c->end) {
        const char *b = c->p, *nl = memchr(b, '\n', (size_t)(c->end - b));
        const char *le = nl ? nl : c->end;
        c->p = nl ? nl + 1 : c->end;
        c->line++;
        const char *hash = memchr(b, '#', (size_t)(le - b));
        if (hash)
            le = hash;
        while (b < le && (*b == ' ' || *b == '\t' || *b == '\r'))
            b++;
        while (le > b && (le[-1] == ' ' || le[-1] == '\t' || le[-1] == '\r'))
            le--;
        if (b < le) {
            *s = b, *e = le;
            return 1;
        }
    }
    return 0;
}

/*
 * Parses a non-negative integer word at *s (advancing past it and following blanks); -1 if there is
 * none. At most 18 digits (10^18 - 1 fits a long long with room for the next * 10): a longer count
 * is no count at all, which the callers refuse (found by fuzz_mesh: 19 nines overflowed).
 */
static long long take_count(const char **s, const char *e)
{
    const char *p = *s;
    long long v = 0;
    int digits = 0;
    while (p < e && *p >= '0' && *p <= '9' && digits < 18) {
        v = 10 * v + (*p++ - '0');
        digits++;
    }
    if (!digits || (p < e && *p != ' ' && *p != '\t'))
        return -1;
    while (p < e && (*p == ' ' || *p == '\t'))
        p++;
    *s = p;
    return v;
}

static int check_off(const char *b, size_t size, const char *name, asp_error *err)
{
    cursor c = {b, b + size, 0};
    const char *s, *e;
    if (!next_line(&c, &s, &e))
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': empty OFF file", name);
    const char *kw = s;
    while (s < e && *s != ' ' && *s != '\t')
        s++;
    size_t kl = (size_t)(s - kw);
    // the keyword is [ST][C][N][4][n]OFF; assimp also reads counts glued to it ("OFF99999...": fuzz_mesh,
    // a 10-minute run, made it allocate 51 GB), so a keyword followed by more is cut after "OFF"
    for (size_t i = 0; i + 3 <= kl && kl > 3; i++) {
        if (memcmp(kw + i, "OFF", 3) == 0) {
            int prefix = 1;
            for (size_t j = 0; j < i; j++)
                prefix &= strchr("STCN4n", kw[j]) != NULL;
            if (prefix) {
                s = kw + i + 3;
                kl = i + 3;
            }
            break;
        }
        if (!strchr("STCN4n", kw[i]))
            break;
    }
    if (kl < 3 || memcmp(kw + kl - 3, "OFF", 3) != 0)
        return 0; // no keyword: assimp decides what this is
    for (size_t i = 0; i + 3 < kl; i++)
        if (kw[i] == '4' || kw[i] == 'n')
            return 0; // 4OFF / nOFF: other dimensions, left to assimp
    while (s < e && (*s == ' ' || *s == '\t'))
        s++;
    if (e - s >= 6 && memcmp(s, "BINARY", 6) == 0)
        return 0;
    if (s == e && !next_line(&c, &s, &e))
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': OFF file ends before its vertex and face counts",
                             name);
    size_t count_line = c.line;
    long long nv = take_count(&s, e), nf = nv < 0 ? -1 : take_count(&s, e);
    if (nv < 0 || nf < 0)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: expected the counts 'vertices faces edges'",
                             name, count_line);
    size_t left = (size_t)(c.end - c.p);
    if ((unsigned long long)nv > left / OFF_MIN_VERTEX_BYTES ||
        (unsigned long long)nf > (left - (size_t)nv * OFF_MIN_VERTEX_BYTES) / OFF_MIN_FACE_BYTES)
        return asp_error_set(err, ASP_EFORMAT,
                             "cannot read '%s': line %zu declares %lld vertices and %lld faces, but only %zu bytes "
                             "follow (each vertex needs at least %d, each face %d)",
                             name, count_line, nv, nf, left, OFF_MIN_VERTEX_BYTES, OFF_MIN_FACE_BYTES);
    if (nv >= UINT32_MAX || nf >= UINT32_MAX)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %lld vertices and %lld faces exceed 2^32-1", name,
                             nv, nf);
    for (long long v = 0; v < nv; v++)
        if (!next_line(&c, &s, &e))
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot read '%s': holds %lld of the %lld vertices it declares: the file is cut off",
                                 name, v, nv);
    for (long long f = 0; f < nf; f++) {
        if (!next_line(&c, &s, &e))
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot read '%s': holds %lld of the %lld faces it declares: the file is cut off", name,
                                 f, nf);
        long long k = take_count(&s, e);
        if (k < 0)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: face %lld: expected a vertex count",
                                 name, c.line, f);
        for (long long i = 0; i < k; i++) {
            long long idx = take_count(&s, e);
            if (idx < 0)
                return asp_error_set(err, ASP_EFORMAT,
                                     "cannot read '%s': line %zu: face %lld: expected %lld vertex indices", name,
                                     c.line, f, k);
            if (idx >= nv)
                return asp_error_set(err, ASP_EFORMAT,
                                     "cannot read '%s': line %zu: face %lld references vertex %lld of %lld (indices "
                                     "0..%lld)",
                                     name, c.line, f, idx, nv, nv - 1);
        }
    }
    return 0;
}

/* The next blank-separated word of [*s, e) in w (cut at cap - 1 bytes); 0 when there is none. */
static size_t take_word(const char **s, const char *e, char *w, size_t cap)
{
    const char *p = *s;
    while (p < e && (*p == ' ' || *p == '\t'))
        p++;
    const char *b = p;
    while (p < e && *p != ' ' && *p != '\t')
        p++;
    size_t n = (size_t)(p - b);
    snprintf(w, cap, "%.*s", (int)(n < cap ? n : cap - 1), b);
    *s = p;
    return n;
}

/* Three finite numbers after a keyword ("facet normal", "vertex"); 0, or the word that is not one. */
static int take_three(const char **s, const char *e, char *bad, size_t cap)
{
    for (int k = 0; k < 3; k++) {
        char w[64];
        size_t n = take_word(s, e, w, sizeof w);
        char *end = NULL;
        double v = n && n < sizeof w ? strtod(w, &end) : 0;
        if (!n || n >= sizeof w || !end || *end || !(v - v == 0)) {
            snprintf(bad, cap, "%s", n ? w : "nothing");
            return -1;
        }
    }
    char w[64];
    if (take_word(s, e, w, sizeof w)) {
        snprintf(bad, cap, "a fourth value '%.60s'", w);
        return -1;
    }
    return 0;
}

/*
 * ASCII STL: "solid", then facets of "facet normal n n n", "outer loop", three "vertex x y z",
 * "endloop", "endfacet", then "endsolid". assimp reads anything else into a message quoting the
 * rest of the file and leaks the mesh it was building (fuzz_mesh, issue #13), so the grammar is
 * checked here, naming the line.
 */
static int check_stl_ascii(const char *b, size_t size, const char *name, asp_error *err)
{
    static const char *const want[] = {"facet", "outer", "vertex", "vertex", "vertex", "endloop", "endfacet"};
    cursor c = {b, b + size, 0};
    const char *s, *e;
    int state = -1; // -1: outside a solid; 0: between facets; 1..7: the next line is want[state - 1]
    char w[64], bad[96];
    while (1) {
        // next_line cuts '#': an STL has no comments, but a solid's name may hold one, which is harmless
        if (!next_line(&c, &s, &e))
            break;
        size_t n = take_word(&s, e, w, sizeof w);
        for (char *q = w; *q; q++)
            *q = (char)(*q >= 'A' && *q <= 'Z' ? *q - 'A' + 'a' : *q);
        (void)n;
        if (state == -1) {
            if (strcmp(w, "solid") != 0)
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: expected 'solid', got "
                                     "'%.40s'", name, c.line, w);
            state = 0;
            continue;
        }
        if (state == 0 && strcmp(w, "endsolid") == 0) {
            state = -1;
            continue;
        }
        const char *expect = want[state == 0 ? 0 : state - 1];
        if (state == 0)
            state = 1;
        if (strcmp(w, expect) != 0)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: expected '%s'%s, got "
                                 "'%.40s'", name, c.line, expect, state == 1 ? " or 'endsolid'" : "", w);
        if (state == 1) {
            if (take_word(&s, e, w, sizeof w) == 0 || strcmp(w, "normal") != 0 || take_three(&s, e, bad, sizeof bad))
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: expected 'facet normal "
                                     "NX NY NZ' with three finite numbers", name, c.line);
        } else if (state == 2) {
            if (take_word(&s, e, w, sizeof w) == 0 || strcmp(w, "loop") != 0)
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: expected 'outer loop'",
                                     name, c.line);
        } else if (state <= 5) {
            if (take_three(&s, e, bad, sizeof bad))
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: vertex %d of a facet: "
                                     "expected three finite numbers, got %s", name, c.line, state - 2, bad);
        }
        state = state == 7 ? 0 : state + 1;
    }
    if (state > 0)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: ASCII STL: the file ends inside a facet "
                             "(expected '%s'): it is cut off", name, c.line, want[state - 1]);
    return 0;
}

static int check_stl(const unsigned char *b, size_t size, const char *name, asp_error *err)
{
    if (size >= 5 && memcmp(b, "solid", 5) == 0) {
        // ASCII STL, unless a binary header happens to start with "solid": then "facet" is absent early on
        size_t look = size < 1024 ? size : 1024;
        for (size_t i = 0; i + 5 <= look; i++)
            if (memcmp(b + i, "facet", 5) == 0)
                return check_stl_ascii((const char *)b, size, name, err);
    }
    if (size < 84)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %zu bytes, too short for binary STL (84 at least)",
                             name, size);
    uint32_t n = (uint32_t)b[80] | (uint32_t)b[81] << 8 | (uint32_t)b[82] << 16 | (uint32_t)b[83] << 24;
    if ((uint64_t)n * 50 > size - 84)
        return asp_error_set(err, ASP_EFORMAT,
                             "cannot read '%s': binary STL declares %u triangles (%llu bytes), but %zu bytes follow its "
                             "header",
                             name, n, (unsigned long long)n * 50, size - 84);
    return 0;
}

static int check_obj(const char *b, size_t size, const char *name, asp_error *err)
{
    if (size == 0 || b[size - 1] == '\n')
        return 0;
    const char *s = b + size;
    while (s > b && s[-1] != '\n')
        s--;
    size_t line = 1;
    for (const char *p = b; p < s; p++)
        line += *p == '\n';
    const char *e = b + size;
    int face = e - s >= 2 && s[0] == 'f' && (s[1] == ' ' || s[1] == '\t');
    int vert = e - s >= 2 && s[0] == 'v' && (s[1] == ' ' || s[1] == '\t');
    if (!face && !vert)
        return 0;
    int words = 0;
    for (const char *p = s + 1; p < e;) {
        while (p < e && (*p == ' ' || *p == '\t' || *p == '\r'))
            p++;
        if (p < e)
            words++;
        while (p < e && *p != ' ' && *p != '\t' && *p != '\r')
            p++;
    }
    if (words >= 3) {
        // issue #31: the last statement, cut or not, must be well formed: numbers after 'v', indices after 'f'
        for (const char *p = s + 1; p < e;) {
            while (p < e && (*p == ' ' || *p == '\t' || *p == '\r'))
                p++;
            const char *w = p;
            while (p < e && *p != ' ' && *p != '\t' && *p != '\r')
                p++;
            if (w == p)
                break;
            char tok[64];
            size_t n = (size_t)(p - w);
            snprintf(tok, sizeof tok, "%.*s", (int)(n < sizeof tok ? n : sizeof tok - 1), w);
            int ok = n < sizeof tok;
            if (ok && vert) {
                char *end;
                strtod(tok, &end);
                ok = *end == '\0';
            } else if (ok) { // v, v/t, v//n, v/t/n, each index an optionally negative integer
                int digits = 0;
                for (const char *q = tok; ok && *q; q++) {
                    if (*q >= '0' && *q <= '9')
                        digits++;
                    else if (*q == '/' || (*q == '-' && (q == tok || q[-1] == '/')))
                        ok = *q == '-' || q > tok;
                    else
                        ok = 0;
                }
                ok = ok && digits > 0 && tok[n - 1] != '-';
            }
            if (!ok)
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu, the last, ends without a newline "
                                     "and its %s '%s' is malformed: the file is cut off", name, line,
                                     vert ? "value" : "index", tok);
        }
        return 0;
    }
    return asp_error_set(err, ASP_EFORMAT,
                         "cannot read '%s': line %zu: the file ends inside a %s line ('%.*s'): it is cut off", name,
                         line, face ? "face" : "vertex", (int)(e - s < 40 ? e - s : 40), s);
}

int asp__mesh_precheck_memory(const void *data, size_t size, const char *name, const char *format, asp_error *err)
{
    if (strcmp(format, "off") == 0)
        return check_off(data, size, name, err);
    if (strcmp(format, "stl") == 0)
        return check_stl(data, size, name, err);
    if (strcmp(format, "obj") == 0)
        return check_obj(data, size, name, err);
    if (strcmp(format, "gltf") == 0 || strcmp(format, "glb") == 0)
        return asp__gltf_precheck_memory(data, size, name, err);
    if (strcmp(format, "dae") == 0)
        return asp__dae_precheck_memory(data, size, name, err);
    if (strcmp(format, "3ds") == 0)
        return asp__3ds_precheck_memory(data, size, name, err);
    return 0;
}

/* Refuses name (relative to the OBJ's directory) when it exists and is not a regular file. */
static int check_side_file(const char *obj, const char *name, size_t len, asp_error *err)
{
    const char *slash = strrchr(obj, '/');
    char full[4096];
    if (len == 0 || len >= 2048)
        return 0;
    if (name[0] == '/' || !slash)
        snprintf(full, sizeof full, "%.*s", (int)len, name);
    else
        snprintf(full, sizeof full, "%.*s/%.*s", (int)(slash - obj), obj, (int)len, name);
    struct stat st;
    if (stat(full, &st) != 0)
        return 0; // a missing .mtl is assimp's to report (it carries on without materials)
    return S_ISREG(st.st_mode) ? 0 : asp__regular_file_check(full, err);
}

/*
 * assimp opens an OBJ's material libraries itself, and would block on a
 * FIFO named by 'mtllib' (issue #13): each one is checked first, as the whole
 * rest of the line and word by word (assimp's reading of names with spaces).
 */
static int check_mtllibs(const char *path, const char *b, size_t size, asp_error *err)
{
    cursor c = {b, b + size, 0};
    const char *s, *e;
    while (next_line(&c, &s, &e)) {
        if (e - s < 8 || memcmp(s, "mtllib", 6) != 0 || (s[6] != ' ' && s[6] != '\t'))
            continue;
        const char *p = s + 7;
        while (p < e && (*p == ' ' || *p == '\t'))
            p++;
        asp_error why = {0};
        int rc = check_side_file(path, p, (size_t)(e - p), &why);
        for (const char *w = p; rc == 0 && w < e;) {
            const char *we = w;
            while (we < e && *we != ' ' && *we != '\t')
                we++;
            rc = check_side_file(path, w, (size_t)(we - w), &why);
            w = we;
            while (w < e && (*w == ' ' || *w == '\t'))
                w++;
        }
        if (rc)
            return asp_error_set(err, rc, "%s (the material library of '%s', line %zu)", why.msg, path, c.line);
    }
    return 0;
}

int asp__mesh_precheck(const char *path, const char *format, const asp_context *ctx, asp_error *err)
{
    static const char *const checked[] = {"off", "stl", "obj", "gltf", "glb", "dae", "3ds"};
    int known = 0;
    for (size_t i = 0; i < sizeof checked / sizeof checked[0]; i++)
        known |= strcmp(format, checked[i]) == 0;
    if (!known)
        return 0;
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = asp__byte_slurp(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    rc = asp__mesh_precheck_memory(buf, size, path, format, err);
    int text = strcmp(format, "obj") == 0 || strcmp(format, "off") == 0 || (strcmp(format, "stl") == 0 && size >= 5 &&
                                                                            memcmp(buf, "solid", 5) == 0);
    if (rc == 0 && text && size > 0 && buf[size - 1] != '\n') {
        // issue #31: a cut file and one without its final newline look alike; the last line passed the checks
        size_t line = 1;
        for (size_t i = 0; i < size; i++)
            line += buf[i] == '\n';
        asp_warn(ctx, "'%s': line %zu, the last, has no newline at its end: if the file was cut off there, its "
                 "values are incomplete", path, line);
    }
    if (rc == 0 && strcmp(format, "obj") == 0)
        rc = check_mtllibs(path, (const char *)buf, size, err);
    asp_free(ctx, buf);
    return rc;
}

/*
 * 3DS: chunks of a 16-bit id and a 32-bit length that counts its 6-byte
 * header (the "3D Studio File Format" of the 3ds Max SDK, as assimp's
 * 3DSLoader reads it). The container chunks' children must fit inside them;
 * the vertex (0x4110), face (0x4120), mapping (0x4140) lists hold the bytes
 * their counts claim and faces use existing vertices. Random field values in
 * a 3DS made assimp's reader return vertices of 1e38 (issue #31): the values
 * themselves are checked after the read.
 */
enum { C3DS_MAX_DEPTH = 32 };

static uint32_t le32_3ds(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

typedef struct c3ds {
    const uint8_t *b;
    const char *name;
    long vertices; /* of the current trimesh, -1 before its vertex list */
    asp_error *err;
} c3ds;

static uint16_t le16(const uint8_t *p)
{
    return (uint16_t)(p[0] | p[1] << 8);
}

static int is_container(uint16_t id)
{
    // main, editor, object (after its name), trimesh, material, its texture maps, keyframer and its nodes
    switch (id) {
    case 0x4D4D: case 0x3D3D: case 0x4000: case 0x4100: case 0xAFFF: case 0xA200: case 0xA204: case 0xA210:
    case 0xA220: case 0xA230: case 0xB000: case 0xB002: case 0x4120:
        return 1;
    default:
        return 0;
    }
}

static int walk_3ds(c3ds *c, size_t at, size_t end, int depth)
{
    if (depth > C3DS_MAX_DEPTH)
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS chunks nested deeper than %d",
                             c->name, at, C3DS_MAX_DEPTH);
    while (at < end) {
        if (end - at < 6)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS chunk header cut off (%zu bytes "
                                 "left in its parent)", c->name, at, end - at);
        uint16_t id = le16(c->b + at);
        uint32_t len = le32_3ds(c->b + at + 2);
        if (len < 6 || len > end - at)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS chunk 0x%04X declares %u bytes, "
                                 "but its parent has %zu left", c->name, at, id, len, end - at);
        size_t body = at + 6, stop = at + len;
        const uint8_t *p = c->b + body;
        size_t n = stop - body;
        if (id == 0x4000) { // object: a NUL-terminated name, then chunks
            const uint8_t *nul = memchr(p, 0, n);
            if (!nul)
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS object name not "
                                     "terminated", c->name, body);
            body += (size_t)(nul - p) + 1;
        }
        if (id == 0x4100)
            c->vertices = -1;
        if (id == 0x4110 || id == 0x4120 || id == 0x4140) {
            size_t per = id == 0x4110 ? 12 : 8;
            if (n < 2 || (size_t)le16(p) * per > n - 2)
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS %s list of %u entries does "
                                     "not fit its chunk of %zu bytes", c->name, body,
                                     id == 0x4110 ? "vertex" : id == 0x4120 ? "face" : "mapping", n < 2 ? 0 : le16(p), n);
            unsigned count = le16(p);
            if (id == 0x4110)
                c->vertices = (long)count;
            if (id == 0x4120)
                for (unsigned f = 0; f < count; f++)
                    for (int k = 0; k < 3; k++) {
                        unsigned v = le16(p + 2 + 8 * f + 2 * k);
                        if (c->vertices >= 0 && (long)v >= c->vertices)
                            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': byte %zu: 3DS face %u uses "
                                                 "vertex %u of %ld", c->name, body + 2 + 8 * f, f, v, c->vertices);
                    }
            if (id == 0x4120)
                body += 2 + (size_t)count * 8; // its sub-chunks (materials, smoothing) follow the faces
        }
        if (is_container(id)) {
            int rc = walk_3ds(c, body, stop, depth + 1);
            if (rc)
                return rc;
        }
        at = stop;
    }
    return 0;
}

int asp__3ds_precheck_memory(const void *data, size_t size, const char *name, asp_error *err)
{
    const uint8_t *b = data;
    if (size < 6 || le16(b) != 0x4D4D)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': not a 3DS file (no main chunk 0x4D4D)", name);
    c3ds c = {b, name, -1, err};
    uint32_t len = le32_3ds(b + 2);
    if (len > size || len < 6)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': its 3DS main chunk declares %u bytes, but the file "
                             "has %zu", name, len, size);
    return walk_3ds(&c, 0, len, 0);
}
