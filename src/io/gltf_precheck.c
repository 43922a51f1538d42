/*
 * glTF 2.0 / GLB pre-check (issue #31), before assimp reads the file: the GLB
 * header's length and chunk lengths against the file size, and every
 * buffer, bufferView and accessor range (glTF 2.0 spec 3.6 "Binary Data
 * Storage", 5.1 accessor, 5.11 bufferView) against the bytes it refers to,
 * sparse accessors included (their indices against the accessor's count),
 * and the node graph for cycles. An 11 kB GLB whose JSON chunk claims
 * 0xFFFFFFFF bytes made assimp reach 4.2 GB; a sparse accessor with indices
 * past its count made it read past a heap buffer.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "amgsplat/mesh.h"
#include "io/mesh_precheck.h"
#include "util/byte_io.h"
#include "util/banned.h"

#define GLB_JSON 0x4E4F534Au
#define GLB_BIN 0x004E4942u

typedef struct gltf_check {
    const char *name;
    const cJSON *root;
    const uint8_t *bin; /* the GLB's BIN chunk, NULL when none */
    size_t bin_size;
    int glb;
    asp_error *err;
    asp_gltf_summary *summary; /* non-NULL: describe the file (asp_gltf_summary_load) instead of refusing what
                                  assimp cannot decode */
} gltf_check;

/*
 * Required extensions that change how the bytes read and that assimp 5.2 (Debian 12) does not decode
 * (only the one amgsplat itself writes is listed; others are left to assimp, which names them):
 * a file that requires one is refused before assimp with a message that says so, rather than read
 * as garbage or failing inside it. amgsplat's own compact GLB (export's default, issue #32) is one.
 */
static const char *const undecodable[] = {"EXT_meshopt_compression"};

/* 1 when buffer b is a fallback buffer of EXT_meshopt_compression (it may have no data: the spec's 4.2). */
static int meshopt_fallback(const cJSON *b)
{
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(b, "extensions"),
                                                        "EXT_meshopt_compression");
    return cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(ext, "fallback"));
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* An integer field in [lo, hi]; def when absent (-1: required). 0 or the error code. */
static int get_int(gltf_check *c, const cJSON *obj, const char *key, long long lo, long long hi, long long def,
                   const char *what, long long *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = 0; // set on every path, so callers' values are defined whatever the compiler proves
    if (!v) {
        if (def < 0)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s has no '%s'", c->name, what, key);
        *out = def;
        return 0;
    }
    double d = cJSON_IsNumber(v) ? v->valuedouble : NAN;
    if (!(d >= (double)lo && d <= (double)hi) || d != floor(d))
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: '%s' must be an integer in %lld..%lld", c->name,
                             what, key, lo, hi);
    *out = (long long)d;
    return 0;
}

static int array_size(const cJSON *root, const char *key)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(root, key);
    return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0;
}

/* Bytes a base64 "data:" URI decodes to, or -1 when it is not one. */
static long long data_uri_bytes(const char *uri)
{
    if (strncmp(uri, "data:", 5) != 0)
        return -1;
    const char *comma = strchr(uri, ',');
    if (!comma || !strstr(uri, ";base64"))
        return 0;
    size_t n = strlen(comma + 1);
    const char *e = comma + 1 + n;
    size_t pad = 0;
    while (e > comma + 1 && e[-1] == '=' && pad < 2)
        e--, pad++;
    return (long long)(((size_t)(e - comma - 1) * 3) / 4);
}

static int b64_value(char ch)
{
    if (ch >= 'A' && ch <= 'Z')
        return ch - 'A';
    if (ch >= 'a' && ch <= 'z')
        return ch - 'a' + 26;
    if (ch >= '0' && ch <= '9')
        return ch - '0' + 52;
    return ch == '+' || ch == '-' ? 62 : ch == '/' || ch == '_' ? 63 : -1;
}

/* Byte at of a data URI's decoded content (at < data_uri_bytes); -1 when the text is not base64 there. */
static int data_uri_byte(const char *uri, size_t at)
{
    const char *s = strchr(uri, ',') + 1;
    size_t q = at / 3 * 4, r = at % 3;
    int a = b64_value(s[q]), b = a < 0 ? -1 : b64_value(s[q + 1]);
    if (a < 0 || b < 0)
        return -1;
    if (r == 0)
        return (a << 2 | b >> 4) & 0xff;
    int cc = b64_value(s[q + 2]);
    if (cc < 0)
        return -1;
    if (r == 1)
        return (b << 4 | cc >> 2) & 0xff;
    int d = b64_value(s[q + 3]);
    return d < 0 ? -1 : (cc << 6 | d) & 0xff;
}

/* The size of the file a relative URI names beside the glTF, or -1 (missing, not a regular file). */
static long long side_file_bytes(const char *gltf, const char *uri)
{
    if (strchr(uri, ':') || uri[0] == '/' || strstr(uri, "%"))
        return -2; // absolute, a scheme or percent-encoded: left to assimp
    const char *slash = strrchr(gltf, '/');
    char full[4096];
    snprintf(full, sizeof full, "%.*s%s", slash ? (int)(slash - gltf + 1) : 0, gltf, uri);
    struct stat st;
    if (stat(full, &st) != 0 || !S_ISREG(st.st_mode))
        return -1;
    return (long long)st.st_size;
}

static int check_buffers(gltf_check *c, long long *lens, int n)
{
    const cJSON *bufs = cJSON_GetObjectItemCaseSensitive(c->root, "buffers");
    for (int i = 0; i < n; i++) {
        const cJSON *b = cJSON_GetArrayItem(bufs, i);
        char what[48];
        snprintf(what, sizeof what, "buffer %d", i);
        if (!cJSON_IsObject(b))
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s is not an object", c->name, what);
        int rc = get_int(c, b, "byteLength", 1, (long long)1 << 53, -1, what, &lens[i]);
        if (rc)
            return rc;
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
        long long have;
        if (!uri && meshopt_fallback(b))
            continue; // no bytes of its own: the compressed views decode into it
        if (!uri) {
            if (!c->glb || i != 0)
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s has no 'uri' (only a GLB's first "
                                     "buffer may be its BIN chunk)", c->name, what);
            if (!c->bin)
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s is the GLB's BIN chunk, which the "
                                     "file lacks", c->name, what);
            have = (long long)c->bin_size;
        } else if (!cJSON_IsString(uri)) {
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: 'uri' is not a string", c->name, what);
        } else if ((have = data_uri_bytes(uri->valuestring)) == -1) {
            have = side_file_bytes(c->name, uri->valuestring);
            if (have == -1)
                return asp_error_set(c->err, ASP_EIO, "cannot read '%s': %s: '%.200s' is missing or not a regular file",
                                     c->name, what, uri->valuestring);
            if (have == -2)
                continue;
        }
        if (lens[i] > have)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s declares %lld bytes, but holds %lld",
                                 c->name, what, lens[i], have);
    }
    return 0;
}

static int check_views(gltf_check *c, const long long *buf_lens, int nbuf, long long *view_lens, int n)
{
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(c->root, "bufferViews");
    for (int i = 0; i < n; i++) {
        const cJSON *v = cJSON_GetArrayItem(views, i);
        char what[48];
        snprintf(what, sizeof what, "bufferView %d", i);
        long long buf, off, len, stride;
        int rc = get_int(c, v, "buffer", 0, nbuf - 1LL, -1, what, &buf);
        if (!rc)
            rc = get_int(c, v, "byteOffset", 0, (long long)1 << 53, 0, what, &off);
        if (!rc)
            rc = get_int(c, v, "byteLength", 1, (long long)1 << 53, -1, what, &len);
        if (!rc)
            rc = get_int(c, v, "byteStride", 4, 252, 0, what, &stride);
        if (rc)
            return rc;
        if (off + len > buf_lens[buf])
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s spans bytes %lld..%lld of buffer %lld, "
                                 "which has %lld", c->name, what, off, off + len, buf, buf_lens[buf]);
        view_lens[i] = len;
    }
    return 0;
}

static int component_bytes(long long type)
{
    switch (type) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

static int type_components(const char *t)
{
    static const struct { const char *name; int n; } types[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                                {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(t, types[i].name) == 0)
            return types[i].n;
    return 0;
}

/* The byte at of bufferView view, when the file holds it (GLB BIN, data URI); -1 otherwise. */
static int view_byte(gltf_check *c, long long view, long long at)
{
    const cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(c->root, "bufferViews"), (int)view);
    const cJSON *off = cJSON_GetObjectItemCaseSensitive(v, "byteOffset");
    long long buf = (long long)cJSON_GetObjectItemCaseSensitive(v, "buffer")->valuedouble;
    at += off ? (long long)off->valuedouble : 0;
    const cJSON *b = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(c->root, "buffers"), (int)buf);
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
    if (!uri)
        return c->bin && at < (long long)c->bin_size ? c->bin[at] : -1;
    if (data_uri_bytes(uri->valuestring) > at)
        return data_uri_byte(uri->valuestring, (size_t)at);
    return -1;
}

/* A sparse accessor's indices and values inside their views, and each index below the accessor's count. */
static int check_sparse(gltf_check *c, const cJSON *sp, const char *what, long long count, long long elem,
                        const long long *view_lens, int nview)
{
    long long n, iv, ioff, ict, vv, voff;
    const cJSON *ind = cJSON_GetObjectItemCaseSensitive(sp, "indices");
    const cJSON *val = cJSON_GetObjectItemCaseSensitive(sp, "values");
    if (!cJSON_IsObject(ind) || !cJSON_IsObject(val))
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: sparse needs 'indices' and 'values'", c->name,
                             what);
    int rc = get_int(c, sp, "count", 1, count, -1, what, &n);
    if (!rc)
        rc = get_int(c, ind, "bufferView", 0, nview - 1LL, -1, what, &iv);
    if (!rc)
        rc = get_int(c, ind, "byteOffset", 0, (long long)1 << 53, 0, what, &ioff);
    if (!rc)
        rc = get_int(c, ind, "componentType", 5121, 5125, -1, what, &ict);
    if (!rc)
        rc = get_int(c, val, "bufferView", 0, nview - 1LL, -1, what, &vv);
    if (!rc)
        rc = get_int(c, val, "byteOffset", 0, (long long)1 << 53, 0, what, &voff);
    if (rc)
        return rc;
    if (ict != 5121 && ict != 5123 && ict != 5125)
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: sparse indices of componentType %lld", c->name,
                             what, ict);
    int ib = component_bytes(ict);
    if (ioff + n * ib > view_lens[iv] || voff + n * elem > view_lens[vv])
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: %lld sparse entries do not fit their "
                             "bufferViews %lld and %lld", c->name, what, n, iv, vv);
    for (long long k = 0; k < n; k++) {
        long long idx = 0;
        for (int b = ib - 1; b >= 0; b--) {
            int byte = view_byte(c, iv, ioff + k * ib + b);
            if (byte < 0)
                return 0; // the bytes are in a file beside it: assimp checks what it reads there
            idx = idx << 8 | byte;
        }
        if (idx >= count)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: sparse index %lld is %lld, past its %lld "
                                 "elements", c->name, what, k, idx, count);
    }
    return 0;
}

static int check_accessors(gltf_check *c, const long long *view_lens, int nview, long long *counts, int n)
{
    const cJSON *accs = cJSON_GetObjectItemCaseSensitive(c->root, "accessors");
    for (int i = 0; i < n; i++) {
        const cJSON *a = cJSON_GetArrayItem(accs, i);
        char what[48];
        snprintf(what, sizeof what, "accessor %d", i);
        if (!cJSON_IsObject(a))
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s is not an object", c->name, what);
        long long ct, count, off, view = -1;
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(a, "type");
        int rc = get_int(c, a, "componentType", 5120, 5126, -1, what, &ct);
        if (!rc)
            rc = get_int(c, a, "count", 1, (long long)1 << 32, -1, what, &count);
        if (!rc)
            rc = get_int(c, a, "byteOffset", 0, (long long)1 << 53, 0, what, &off);
        if (!rc && cJSON_GetObjectItemCaseSensitive(a, "bufferView"))
            rc = get_int(c, a, "bufferView", 0, nview - 1LL, -1, what, &view);
        if (rc)
            return rc;
        int cb = component_bytes(ct), nc = cJSON_IsString(type) ? type_components(type->valuestring) : 0;
        if (!cb || !nc)
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: unknown componentType %lld or type", c->name,
                                 what, ct);
        long long elem = (long long)cb * nc;
        if (view >= 0) {
            const cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(c->root, "bufferViews"), (int)view);
            const cJSON *st = cJSON_GetObjectItemCaseSensitive(v, "byteStride");
            long long stride = st ? (long long)st->valuedouble : elem;
            if (off + stride * (count - 1) + elem > view_lens[view])
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: %lld elements of %lld bytes from byte "
                                     "%lld do not fit bufferView %lld (%lld bytes)", c->name, what, count, elem, off,
                                     view, view_lens[view]);
        }
        const cJSON *sp = cJSON_GetObjectItemCaseSensitive(a, "sparse");
        if (sp && (rc = check_sparse(c, sp, what, count, elem, view_lens, nview)))
            return rc;
        counts[i] = count;
    }
    return 0;
}

/* Every primitive's attributes index accessors of one count; indices, materials and targets in range. */
static int check_meshes(gltf_check *c, const long long *counts, int nacc)
{
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(c->root, "meshes"), *m;
    int mi = 0, nmat = array_size(c->root, "materials");
    cJSON_ArrayForEach(m, meshes) {
        const cJSON *prims = cJSON_GetObjectItemCaseSensitive(m, "primitives"), *p;
        int pi = 0;
        cJSON_ArrayForEach(p, prims) {
            char what[64];
            snprintf(what, sizeof what, "mesh %d primitive %d", mi, pi);
            const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(p, "attributes"), *at;
            long long n = -1, ai;
            cJSON_ArrayForEach(at, attrs) {
                char w2[128];
                snprintf(w2, sizeof w2, "%s attributes", what);
                int rc = get_int(c, attrs, at->string, 0, nacc - 1LL, -1, w2, &ai);
                if (rc)
                    return rc;
                if (n >= 0 && counts[ai] != n)
                    return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: attribute '%.40s' has %lld "
                                         "elements, another %lld", c->name, what, at->string, counts[ai], n);
                n = counts[ai];
            }
            long long x;
            int rc = cJSON_GetObjectItemCaseSensitive(p, "indices") ? get_int(c, p, "indices", 0, nacc - 1LL, -1, what, &x) : 0;
            if (!rc && cJSON_GetObjectItemCaseSensitive(p, "material"))
                rc = get_int(c, p, "material", 0, nmat - 1LL, -1, what, &x);
            if (!rc)
                rc = get_int(c, p, "mode", 0, 6, 4, what, &x);
            if (rc)
                return rc;
            const cJSON *targets = cJSON_GetObjectItemCaseSensitive(p, "targets"), *t;
            cJSON_ArrayForEach(t, targets) {
                cJSON_ArrayForEach(at, t) {
                    rc = get_int(c, t, at->string, 0, nacc - 1LL, -1, what, &ai);
                    if (rc)
                        return rc;
                    if (n >= 0 && counts[ai] != n)
                        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: morph target '%.40s' has "
                                             "%lld elements, the attributes %lld", c->name, what, at->string, counts[ai], n);
                }
            }
            pi++;
        }
        mi++;
    }
    return 0;
}

/* Nodes: mesh, skin, camera and child indices in range, each node the child of one parent at most (no cycles). */
static int check_nodes(gltf_check *c)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(c->root, "nodes"), *n;
    int count = array_size(c->root, "nodes"), nmesh = array_size(c->root, "meshes");
    if (count == 0)
        return 0;
    int *parent = malloc((size_t)count * sizeof *parent);
    if (!parent)
        return asp_error_set(c->err, ASP_ENOMEM, "out of memory checking '%s'", c->name);
    for (int i = 0; i < count; i++)
        parent[i] = -1;
    int i = 0, rc = 0;
    cJSON_ArrayForEach(n, nodes) {
        char what[48];
        snprintf(what, sizeof what, "node %d", i);
        long long x;
        if (cJSON_GetObjectItemCaseSensitive(n, "mesh") && (rc = get_int(c, n, "mesh", 0, nmesh - 1LL, -1, what, &x)))
            break;
        const cJSON *ch, *kids = cJSON_GetObjectItemCaseSensitive(n, "children");
        cJSON_ArrayForEach(ch, kids) {
            double d = cJSON_IsNumber(ch) ? ch->valuedouble : -1;
            if (!(d >= 0 && d < count) || d != floor(d)) {
                rc = asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': %s: child is not a node index 0..%d", c->name,
                                   what, count - 1);
                break;
            }
            if (parent[(int)d] >= 0 || (int)d == i) {
                rc = asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': node %d is a child twice or of itself (the "
                                   "nodes must form trees)", c->name, (int)d);
                break;
            }
            parent[(int)d] = i;
        }
        if (rc)
            break;
        i++;
    }
    // one parent each: a cycle shows as a walk up that does not end within count steps
    for (int k = 0; rc == 0 && k < count; k++) {
        int p = parent[k], steps = 0;
        while (p >= 0 && steps <= count)
            p = parent[p], steps++;
        if (steps > count)
            rc = asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': node %d is its own ancestor", c->name, k);
    }
    free(parent);
    if (rc)
        return rc;
    const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(c->root, "scenes"), *s;
    int si = 0;
    cJSON_ArrayForEach(s, scenes) {
        const cJSON *r, *roots = cJSON_GetObjectItemCaseSensitive(s, "nodes");
        cJSON_ArrayForEach(r, roots) {
            double d = cJSON_IsNumber(r) ? r->valuedouble : -1;
            if (!(d >= 0 && d < count) || d != floor(d))
                return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': scene %d names a node that is not one of "
                                     "0..%d", c->name, si, count - 1);
        }
        si++;
    }
    return 0;
}

/*
 * The file's required extensions: refused when assimp cannot decode one (undecodable[]), unless
 * c->summary asks for a description, which is then filled from the JSON (counts are the POSITION
 * accessors' element counts, already checked against their buffers).
 */
static int required_extensions(gltf_check *c, const long long *counts)
{
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(c->root, "extensionsRequired"), *e;
    const char *blocker = NULL;
    cJSON_ArrayForEach(e, req) {
        if (!cJSON_IsString(e))
            return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': extensionsRequired holds a non-string",
                                 c->name);
        for (size_t k = 0; k < sizeof undecodable / sizeof undecodable[0] && !blocker; k++)
            if (strcmp(e->valuestring, undecodable[k]) == 0)
                blocker = undecodable[k];
        if (c->summary) {
            size_t len = strlen(c->summary->required);
            snprintf(c->summary->required + len, sizeof c->summary->required - len, "%s%s", len ? "," : "",
                     e->valuestring);
        }
    }
    if (c->summary) {
        asp_gltf_summary *s = c->summary;
        s->glb = c->glb;
        s->decodable = blocker == NULL;
        int nacc = array_size(c->root, "accessors");
        const cJSON *m, *p;
        cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(c->root, "meshes")) {
            cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(m, "primitives")) {
                const cJSON *pos = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(p, "attributes"),
                                                                    "POSITION");
                const cJSON *mode = cJSON_GetObjectItemCaseSensitive(p, "mode");
                long long n = cJSON_IsNumber(pos) && pos->valuedouble >= 0 && pos->valuedouble < nacc
                                  ? counts[(int)pos->valuedouble] : 0;
                s->primitives++;
                if (cJSON_IsNumber(mode) && mode->valueint == 0)
                    s->points += (size_t)n;
                else
                    s->vertices += (size_t)n;
            }
        }
        return 0;
    }
    if (blocker)
        return asp_error_set(c->err, ASP_EUNSUPPORTED, "cannot read '%s' as a mesh: it requires %s, which the mesh "
                             "reader (assimp) cannot decode (a compact amgsplat export: write it with "
                             "'amgsplat export --plain' for tools that need plain glTF)", c->name, blocker);
    return 0;
}

static int check_json(gltf_check *c, const char *json, size_t len)
{
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root || !cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return asp_error_set(c->err, ASP_EFORMAT, "cannot read '%s': its glTF JSON does not parse", c->name);
    }
    c->root = root;
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(root, "asset");
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(asset, "version");
    if (!cJSON_IsString(ver) || ver->valuestring[0] != '2') {
        cJSON_Delete(root);
        return 0; // glTF 1.0 (or none): a different layout, left to assimp's own checks
    }
    int nbuf = array_size(root, "buffers"), nview = array_size(root, "bufferViews"), nacc = array_size(root, "accessors");
    long long *lens = calloc((size_t)nbuf + (size_t)nview + (size_t)nacc + 1, sizeof *lens);
    int rc = lens ? 0 : asp_error_set(c->err, ASP_ENOMEM, "out of memory checking '%s'", c->name);
    if (!rc)
        rc = check_buffers(c, lens, nbuf);
    if (!rc)
        rc = check_views(c, lens, nbuf, lens + nbuf, nview);
    if (!rc)
        rc = check_accessors(c, lens + nbuf, nview, lens + nbuf + nview, nacc);
    if (!rc)
        rc = check_meshes(c, lens + nbuf + nview, nacc);
    if (!rc)
        rc = check_nodes(c);
    if (!rc)
        rc = required_extensions(c, lens + nbuf + nview);
    free(lens);
    cJSON_Delete(root);
    return rc;
}

static int gltf_precheck(const void *data, size_t size, const char *name, asp_gltf_summary *summary, asp_error *err)
{
    const uint8_t *b = data;
    gltf_check c = {.name = name, .err = err, .summary = summary};
    if (size < 4 || memcmp(b, "glTF", 4) != 0)
        return check_json(&c, data, size);
    c.glb = 1;
    if (size < 12)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %zu bytes, too short for a GLB header (12)", name, size);
    uint32_t version = le32(b + 4), length = le32(b + 8);
    if (length > size || length < 20)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': its GLB header declares %u bytes, but the file has %zu",
                             name, length, size);
    if (version == 1) { // glTF 1.0 binary: content length and format, then the JSON content
        uint32_t clen = le32(b + 12);
        if ((uint64_t)clen + 20 > length)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': its GLB content of %u bytes does not fit its %u "
                                 "bytes", name, clen, length);
        return 0;
    }
    if (version != 2)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': GLB version %u (expected 2)", name, version);
    size_t at = 12;
    const uint8_t *json = NULL;
    size_t json_len = 0;
    for (int chunk = 0; at < length; chunk++) {
        if (length - at < 8)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': byte %zu: GLB chunk header cut off", name, at);
        uint32_t clen = le32(b + at), type = le32(b + at + 4);
        if (clen > length - at - 8)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': byte %zu: GLB chunk %d declares %u bytes, but %zu "
                                 "follow", name, at, chunk, clen, length - at - 8);
        if (chunk == 0 && type != GLB_JSON)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the first GLB chunk is not JSON", name);
        if (chunk == 0)
            json = b + at + 8, json_len = clen;
        else if (chunk == 1 && type == GLB_BIN)
            c.bin = b + at + 8, c.bin_size = clen;
        at += 8 + (size_t)clen;
    }
    if (!json)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': GLB without a JSON chunk", name);
    return check_json(&c, (const char *)json, json_len);
}

int asp_gltf_summary_load(const char *path, const asp_context *ctx, asp_gltf_summary *out, asp_error *err)
{
    ASP_ASSERT(path && out);
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = asp__byte_slurp(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    asp_gltf_summary s;
    memset(&s, 0, sizeof s);
    rc = gltf_precheck(buf, size, path, &s, err);
    asp_free(ctx, buf);
    if (!rc)
        *out = s;
    return rc;
}

int asp__gltf_precheck_memory(const void *data, size_t size, const char *name, asp_error *err)
{
    return gltf_precheck(data, size, name, NULL, err);
}
