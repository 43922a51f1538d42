/*
 * The glTF 2.0 document both exports fill (internal.h): JSON through cJSON, one binary buffer,
 * and the two layouts of the spec: GLB (4.4: 12-byte header, a JSON chunk padded with spaces,
 * a BIN chunk padded with zeros, all 4-byte aligned) or a .gltf with a .bin and PNG files.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <meshoptimizer.h>
#include <stb/stb_image_write.h>

#include "export/internal.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/banned.h"

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != suffix[i])
            return 0;
    }
    return 1;
}

int asp__gltf_init(asp__gltf *g, const char *path, const char *generator_note, const asp_context *ctx,
                   asp_error *err)
{
    memset(g, 0, sizeof *g);
    g->ctx = ctx;
    if (ends_with(path, ".glb"))
        g->glb = 1;
    else if (!ends_with(path, ".gltf"))
        return asp_error_set(err, ASP_EINVAL, "cannot export to '%s': expected a name ending in .glb or .gltf", path);
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t len = strlen(base) - (g->glb ? 4 : 5);
    if (len == 0 || len >= sizeof g->stem)
        return asp_error_set(err, ASP_EINVAL, "cannot export to '%s': the file name must have 1 to %zu characters "
                             "before the extension", path, sizeof g->stem - 1);
    memcpy(g->stem, base, len);
    g->stem[len] = '\0';
    g->root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(g->root, "asset");
    if (asset) {
        cJSON_AddStringToObject(asset, "version", "2.0");
        char gen[128];
        snprintf(gen, sizeof gen, "amgsplat export%s%s", generator_note ? " " : "", generator_note ? generator_note : "");
        cJSON_AddStringToObject(asset, "generator", gen);
    }
    g->extensions_used = cJSON_CreateArray();
    g->extensions_required = cJSON_CreateArray();
    g->buffer_views = cJSON_CreateArray();
    g->accessors = cJSON_CreateArray();
    g->images = cJSON_CreateArray();
    g->textures = cJSON_CreateArray();
    g->samplers = cJSON_CreateArray();
    g->materials = cJSON_CreateArray();
    g->meshes = cJSON_CreateArray();
    g->nodes = cJSON_CreateArray();
    if (!g->root || !asset || !g->extensions_used || !g->extensions_required || !g->buffer_views || !g->accessors ||
        !g->images || !g->textures || !g->samplers || !g->materials || !g->meshes || !g->nodes) {
        asp__gltf_release(g);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the glTF document of '%s'", path);
    }
    return 0;
}

void asp__gltf_release(asp__gltf *g)
{
    cJSON *arrays[] = {g->extensions_used, g->extensions_required, g->buffer_views, g->accessors, g->images,
                       g->textures, g->samplers, g->materials, g->meshes, g->nodes};
    // arrays not yet moved into root are owned here (finish_json clears those it moves)
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        cJSON_Delete(arrays[i]);
    cJSON_Delete(g->root);
    asp_free(g->ctx, g->bin);
    for (size_t i = 0; i < g->png_count; i++)
        asp_free(g->ctx, g->pngs[i].data);
    asp_free(g->ctx, g->pngs);
    memset(g, 0, sizeof *g);
}

int asp__gltf_append(asp__gltf *g, cJSON *array, cJSON *obj)
{
    if (!obj || !cJSON_AddItemToArray(array, obj)) {
        cJSON_Delete(obj);
        g->failed = 1;
        return -1;
    }
    return cJSON_GetArraySize(array) - 1;
}

cJSON *asp__gltf_numbers(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++)
        if (!cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]))) {
            cJSON_Delete(a);
            return NULL;
        }
    return a;
}

static int bin_append(asp__gltf *g, const void *data, size_t size, size_t *offset)
{
    // every view starts on a 4-byte boundary (spec 3.6.2.4: accessor data alignment)
    size_t start = (g->bin_size + 3) & ~(size_t)3;
    if (size > SIZE_MAX - start - 4)
        return -1;
    size_t need = start + size;
    if (need > g->bin_capacity) {
        size_t cap = g->bin_capacity ? g->bin_capacity : 1 << 16;
        while (cap < need)
            cap = cap > SIZE_MAX / 2 ? need : 2 * cap;
        uint8_t *p = asp_realloc(g->ctx, g->bin, g->bin_capacity, cap);
        if (!p)
            return -1;
        g->bin = p;
        g->bin_capacity = cap;
    }
    memset(g->bin + g->bin_size, 0, start - g->bin_size);
    memcpy(g->bin + start, data, size);
    g->bin_size = need;
    *offset = start;
    return 0;
}

int asp__gltf_view(asp__gltf *g, const void *data, size_t size, int target)
{
    size_t offset = 0;
    if (bin_append(g, data, size, &offset)) {
        g->failed = 1;
        return -1;
    }
    cJSON *v = cJSON_CreateObject();
    if (v) {
        cJSON_AddNumberToObject(v, "buffer", 0);
        cJSON_AddNumberToObject(v, "byteOffset", (double)offset);
        cJSON_AddNumberToObject(v, "byteLength", (double)size);
        if (target)
            cJSON_AddNumberToObject(v, "target", target);
    }
    return asp__gltf_append(g, g->buffer_views, v);
}

int asp__gltf_view_meshopt(asp__gltf *g, const void *data, size_t count, size_t stride, const char *filter)
{
    ASP_ASSERT(stride % 4 == 0 && stride > 0 && stride <= 256);
    size_t bound = meshopt_encodeVertexBufferBound(count, stride);
    unsigned char *enc = asp_alloc(g->ctx, bound);
    if (!enc) {
        g->failed = 1;
        return -1;
    }
    size_t size = meshopt_encodeVertexBuffer(enc, bound, data, count, stride);
    // EXT_meshopt_compression decodes vertex codec version 0 only (header byte 0xa0); Debian's 0.18
    // writes it, a later library might default to version 1, which the extension's decoders refuse
    size_t offset = 0;
    if (size == 0 || enc[0] != 0xa0 || bin_append(g, enc, size, &offset)) {
        asp_free(g->ctx, enc);
        g->failed = 1;
        return -1;
    }
    asp_free(g->ctx, enc);
    size_t raw = count * stride;
    cJSON *v = cJSON_CreateObject();
    cJSON *ext = v ? cJSON_AddObjectToObject(cJSON_AddObjectToObject(v, "extensions"), "EXT_meshopt_compression")
                   : NULL;
    if (ext) {
        // the view proper (what a decoder fills) in the data-less fallback buffer 1
        cJSON_AddNumberToObject(v, "buffer", 1);
        cJSON_AddNumberToObject(v, "byteOffset", (double)g->fallback_size);
        cJSON_AddNumberToObject(v, "byteLength", (double)raw);
        cJSON_AddNumberToObject(v, "byteStride", (double)stride);
        cJSON_AddNumberToObject(v, "target", ASP__GL_ARRAY_BUFFER);
        cJSON_AddNumberToObject(ext, "buffer", 0);
        cJSON_AddNumberToObject(ext, "byteOffset", (double)offset);
        cJSON_AddNumberToObject(ext, "byteLength", (double)size);
        cJSON_AddNumberToObject(ext, "byteStride", (double)stride);
        cJSON_AddNumberToObject(ext, "count", (double)count);
        cJSON_AddStringToObject(ext, "mode", "ATTRIBUTES");
        if (filter && strcmp(filter, "NONE") != 0)
            cJSON_AddStringToObject(ext, "filter", filter);
    }
    g->fallback_size += (raw + 3) & ~(size_t)3;
    asp__gltf_require_extension(g, "EXT_meshopt_compression");
    if (v && !ext) {
        cJSON_Delete(v);
        v = NULL;
    }
    return asp__gltf_append(g, g->buffer_views, v);
}

static int type_components(const char *type)
{
    return strcmp(type, "SCALAR") == 0 ? 1 : strcmp(type, "VEC2") == 0 ? 2 : strcmp(type, "VEC3") == 0 ? 3 : 4;
}

int asp__gltf_accessor(asp__gltf *g, int view, int component_type, size_t count, const char *type, int normalized,
                       const float *min, const float *max)
{
    if (view < 0)
        return -1;
    cJSON *a = cJSON_CreateObject();
    if (a) {
        cJSON_AddNumberToObject(a, "bufferView", view);
        cJSON_AddNumberToObject(a, "componentType", component_type);
        if (normalized)
            cJSON_AddTrueToObject(a, "normalized");
        cJSON_AddNumberToObject(a, "count", (double)count);
        cJSON_AddStringToObject(a, "type", type);
        int n = type_components(type);
        if (min && max) {
            double lo[4], hi[4];
            for (int k = 0; k < n; k++) {
                lo[k] = min[k];
                hi[k] = max[k];
            }
            cJSON_AddItemToObject(a, "min", asp__gltf_numbers(lo, n));
            cJSON_AddItemToObject(a, "max", asp__gltf_numbers(hi, n));
        }
    }
    return asp__gltf_append(g, g->accessors, a);
}

struct png_sink {
    const asp_context *ctx;
    unsigned char *data;
    size_t size, capacity;
    int failed;
};

static void png_write(void *context, void *data, int size)
{
    struct png_sink *s = context;
    if (s->failed || size <= 0)
        return;
    if (s->size + (size_t)size > s->capacity) {
        size_t cap = s->capacity ? 2 * s->capacity : 1 << 16;
        while (cap < s->size + (size_t)size)
            cap *= 2;
        unsigned char *p = asp_realloc(s->ctx, s->data, s->capacity, cap);
        if (!p) {
            s->failed = 1;
            return;
        }
        s->data = p;
        s->capacity = cap;
    }
    memcpy(s->data + s->size, data, (size_t)size);
    s->size += (size_t)size;
}

int asp__gltf_image(asp__gltf *g, const uint8_t *rgba, uint32_t width, uint32_t height, const char *name)
{
    struct png_sink s = {.ctx = g->ctx};
    if (!stbi_write_png_to_func(png_write, &s, (int)width, (int)height, 4, rgba, (int)width * 4) || s.failed) {
        asp_free(g->ctx, s.data);
        g->failed = 1;
        return -1;
    }
    cJSON *img = cJSON_CreateObject();
    if (!img) {
        asp_free(g->ctx, s.data);
        g->failed = 1;
        return -1;
    }
    cJSON_AddStringToObject(img, "name", name);
    if (g->glb) {
        int view = asp__gltf_view(g, s.data, s.size, 0);
        asp_free(g->ctx, s.data);
        if (view < 0) {
            cJSON_Delete(img);
            return -1;
        }
        cJSON_AddNumberToObject(img, "bufferView", view);
        cJSON_AddStringToObject(img, "mimeType", "image/png");
    } else {
        asp__gltf_png *p = asp_realloc(g->ctx, g->pngs, g->png_count * sizeof *p, (g->png_count + 1) * sizeof *p);
        if (!p) {
            asp_free(g->ctx, s.data);
            cJSON_Delete(img);
            g->failed = 1;
            return -1;
        }
        g->pngs = p;
        asp__gltf_png *q = &p[g->png_count++];
        q->data = s.data;
        q->size = s.size;
        snprintf(q->uri, sizeof q->uri, "%s_%s.png", g->stem, name);
        cJSON_AddStringToObject(img, "uri", q->uri);
    }
    return asp__gltf_append(g, g->images, img);
}

int asp__gltf_texture(asp__gltf *g, int image)
{
    if (image < 0)
        return -1;
    if (cJSON_GetArraySize(g->samplers) == 0) {
        // the renderer's atlas sampling: GL_LINEAR without mipmaps, clamped (prim_renderer.c upload_atlas)
        cJSON *s = cJSON_CreateObject();
        if (s) {
            cJSON_AddNumberToObject(s, "magFilter", ASP__GL_LINEAR);
            cJSON_AddNumberToObject(s, "minFilter", ASP__GL_LINEAR);
            cJSON_AddNumberToObject(s, "wrapS", ASP__GL_CLAMP_TO_EDGE);
            cJSON_AddNumberToObject(s, "wrapT", ASP__GL_CLAMP_TO_EDGE);
        }
        if (asp__gltf_append(g, g->samplers, s) < 0)
            return -1;
    }
    cJSON *t = cJSON_CreateObject();
    if (t) {
        cJSON_AddNumberToObject(t, "sampler", 0);
        cJSON_AddNumberToObject(t, "source", image);
    }
    return asp__gltf_append(g, g->textures, t);
}

void asp__gltf_use_extension(asp__gltf *g, const char *name)
{
    cJSON *e;
    cJSON_ArrayForEach(e, g->extensions_used)
    {
        if (cJSON_IsString(e) && strcmp(e->valuestring, name) == 0)
            return;
    }
    if (!cJSON_AddItemToArray(g->extensions_used, cJSON_CreateString(name)))
        g->failed = 1;
}

void asp__gltf_require_extension(asp__gltf *g, const char *name)
{
    asp__gltf_use_extension(g, name);
    cJSON *e;
    cJSON_ArrayForEach(e, g->extensions_required)
    {
        if (cJSON_IsString(e) && strcmp(e->valuestring, name) == 0)
            return;
    }
    if (!cJSON_AddItemToArray(g->extensions_required, cJSON_CreateString(name)))
        g->failed = 1;
}

void asp__gltf_turn_up(asp_up_axis up, const double in[3], double out[3])
{
    double x = in[0], y = in[1], z = in[2];
    int neg = up >= ASP_UP_NEG_Y && up <= ASP_UP_NEG_X;
    asp_up_axis axis = neg ? (asp_up_axis)(up - ASP_UP_NEG_Y) : up;
    if (axis == ASP_UP_Z) { // -90 degrees about x: z -> y, y -> -z
        out[0] = x;
        out[1] = z;
        out[2] = -y;
    } else if (axis == ASP_UP_X) { // +90 degrees about z: x -> y, y -> -x
        out[0] = -y;
        out[1] = x;
        out[2] = z;
    } else {
        out[0] = x;
        out[1] = y;
        out[2] = z;
    }
    if (neg) { // then 180 degrees about z: the negative axis, now at -y, to +y
        out[0] = -out[0];
        out[1] = -out[1];
    }
}

void asp__gltf_turn_up_f(asp_up_axis up, float v[3])
{
    double d[3] = {v[0], v[1], v[2]};
    asp__gltf_turn_up(up, d, d);
    for (int k = 0; k < 3; k++)
        v[k] = (float)d[k];
}

static const char *up_name(asp_up_axis up)
{
    static const char *const names[] = {"y", "z", "x", "-y", "-z", "-x"};
    return (unsigned)up < 6 ? names[up] : "y";
}

cJSON *asp__gltf_extras(const char *kind, const char *source, const double origin[3], const asp_frame *frame)
{
    cJSON *extras = cJSON_CreateObject();
    cJSON *a = cJSON_AddObjectToObject(extras, "amgsplat");
    if (!a)
        return extras;
    cJSON_AddNumberToObject(a, "version", 1);
    cJSON_AddStringToObject(a, "kind", kind);
    if (source && source[0])
        cJSON_AddStringToObject(a, "source", source);
    cJSON_AddItemToObject(a, "origin", asp__gltf_numbers(origin, 3));
    if (frame && frame->radius > 0) {
        // amgsplat render's camera (asp_camera_frame): this sphere, fov_y 40, y up, fitted to the nearer sides
        cJSON *f = cJSON_AddObjectToObject(a, "frame");
        if (f) {
            double c[3];
            asp__gltf_turn_up(frame->up, frame->center, c);
            cJSON_AddItemToObject(f, "center", asp__gltf_numbers(c, 3));
            cJSON_AddNumberToObject(f, "radius", frame->radius);
            if (frame->half[0] > 0 || frame->half[1] > 0 || frame->half[2] > 0) {
                // the box of a flat, wide set (asp_camera_frame fits it), its sides along glTF's axes
                double h[3];
                asp__gltf_turn_up(frame->up, frame->half, h);
                for (int k = 0; k < 3; k++)
                    h[k] = fabs(h[k]);
                cJSON_AddItemToObject(f, "half", asp__gltf_numbers(h, 3));
            }
        }
        cJSON_AddNumberToObject(a, "fovY", 40);
    }
    // the source's up axis, and the matrix (column-major, glTF's) from these coordinates back to its
    // own: where the source has a CRS (asset.extras.amgsplat.crs), toSource x gives its coordinates
    asp_up_axis up = frame ? frame->up : ASP_UP_Y;
    cJSON_AddStringToObject(a, "sourceUp", up_name(up));
    double m[16] = {0};
    for (int c = 0; c < 3; c++) {
        double e[3] = {c == 0, c == 1, c == 2}, t[3];
        asp__gltf_turn_up(up, e, t); // column c of the turn; the inverse of a rotation is its transpose
        for (int r = 0; r < 3; r++)
            m[4 * r + c] = t[r];
    }
    m[15] = 1;
    cJSON_AddItemToObject(a, "toSource", asp__gltf_numbers(m, 16));
    return extras;
}

/* Moves the arrays that have entries into root (glTF forbids empty arrays) and adds the buffer. */
static int finish_json(asp__gltf *g)
{
    cJSON *buffers = cJSON_AddArrayToObject(g->root, "buffers");
    cJSON *b = cJSON_CreateObject();
    if (!buffers || !b) {
        cJSON_Delete(b);
        return -1;
    }
    cJSON_AddNumberToObject(b, "byteLength", (double)g->bin_size);
    if (!g->glb) {
        char uri[128];
        snprintf(uri, sizeof uri, "%s.bin", g->stem);
        cJSON_AddStringToObject(b, "uri", uri);
    }
    cJSON_AddItemToArray(buffers, b);
    if (g->fallback_size) {
        // EXT_meshopt_compression's fallback buffer: the decoded views' home, no uri, no data
        cJSON *f = cJSON_CreateObject();
        cJSON *fe = f ? cJSON_AddObjectToObject(cJSON_AddObjectToObject(f, "extensions"), "EXT_meshopt_compression")
                      : NULL;
        if (!fe || !cJSON_AddItemToArray(buffers, f)) {
            cJSON_Delete(f);
            return -1;
        }
        cJSON_AddNumberToObject(f, "byteLength", (double)g->fallback_size);
        cJSON_AddTrueToObject(fe, "fallback");
    }
    struct { const char *name; cJSON **array; } parts[] = {
        {"extensionsUsed", &g->extensions_used}, {"extensionsRequired", &g->extensions_required},
        {"bufferViews", &g->buffer_views}, {"accessors", &g->accessors},
        {"images", &g->images}, {"samplers", &g->samplers}, {"textures", &g->textures},
        {"materials", &g->materials}, {"meshes", &g->meshes}, {"nodes", &g->nodes}};
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
        cJSON *arr = *parts[i].array;
        *parts[i].array = NULL; // owned by root (or freed) from here on
        if (cJSON_GetArraySize(arr) == 0)
            cJSON_Delete(arr);
        else if (!cJSON_AddItemToObject(g->root, parts[i].name, arr)) {
            cJSON_Delete(arr);
            return -1;
        }
    }
    return 0;
}

static int write_file(const char *path, const void *a, size_t na, const void *b, size_t nb, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    if ((na && fwrite(a, 1, na, f.fp) != na) || (nb && fwrite(b, 1, nb, f.fp) != nb)) {
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s'", path);
    }
    return asp__atomic_commit(&f, err);
}

static int write_glb(const char *path, const char *json, const uint8_t *bin, size_t bin_size, asp_gltf_stats *st,
                     asp_error *err)
{
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3, bpad = (bin_size + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + 8 + bpad;
    if (total > UINT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': %zu bytes exceed the 4 GiB of a GLB file",
                             path, total);
    uint8_t head[20], bin_head[8];
    asp__store_u32(head, 0x46546C67u); // "glTF"
    asp__store_u32(head + 4, 2);
    asp__store_u32(head + 8, (uint32_t)total);
    asp__store_u32(head + 12, (uint32_t)jpad);
    asp__store_u32(head + 16, 0x4E4F534Au); // "JSON"
    asp__store_u32(bin_head, (uint32_t)bpad);
    asp__store_u32(bin_head + 4, 0x004E4942u); // "BIN\0"
    static const char spaces[3] = {' ', ' ', ' '}; // the spec pads the JSON chunk with spaces
    static const uint8_t zeros[3] = {0, 0, 0};      // and the binary chunk with zeros
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    struct { const void *p; size_t n; } parts[] = {{head, 20}, {json, jlen}, {spaces, jpad - jlen}, {bin_head, 8},
                                                   {bin, bin_size}, {zeros, bpad - bin_size}};
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
        if (parts[i].n && fwrite(parts[i].p, 1, parts[i].n, f.fp) != parts[i].n) {
            asp__atomic_abort(&f);
            return asp_error_set(err, ASP_EIO, "cannot write '%s'", path);
        }
    rc = asp__atomic_commit(&f, err);
    if (!rc) {
        st->json_bytes = jpad;
        st->bin_bytes = bpad;
        st->file_bytes = total;
        st->files = 1;
    }
    return rc;
}

/* path's directory (with its slash) + name */
static int sibling(char *out, size_t cap, const char *path, const char *name)
{
    const char *slash = strrchr(path, '/');
    int dir = slash ? (int)(slash - path + 1) : 0;
    int n = snprintf(out, cap, "%.*s%s", dir, path, name);
    return n > 0 && (size_t)n < cap ? 0 : -1;
}

static int write_separate(asp__gltf *g, const char *path, const char *json, asp_gltf_stats *st, asp_error *err)
{
    char file[4096 + 128];
    char bin_name[128];
    snprintf(bin_name, sizeof bin_name, "%s.bin", g->stem);
    if (sibling(file, sizeof file, path, bin_name))
        return asp_error_set(err, ASP_EINVAL, "cannot export to '%s': the path is too long", path);
    int rc = write_file(file, g->bin, g->bin_size, NULL, 0, err);
    size_t bytes = g->bin_size, files = 1;
    for (size_t i = 0; !rc && i < g->png_count; i++) {
        if (sibling(file, sizeof file, path, g->pngs[i].uri))
            return asp_error_set(err, ASP_EINVAL, "cannot export to '%s': the path is too long", path);
        rc = write_file(file, g->pngs[i].data, g->pngs[i].size, NULL, 0, err);
        bytes += g->pngs[i].size;
        files++;
    }
    // the .gltf last, so a complete one never names missing files
    if (!rc)
        rc = write_file(path, json, strlen(json), NULL, 0, err);
    if (!rc) {
        st->json_bytes = strlen(json);
        st->bin_bytes = g->bin_size;
        st->file_bytes = bytes + strlen(json);
        st->files = files + 1;
    }
    return rc;
}

/* The first non-finite number under item (cJSON prints it as null), its place in *where; 0 when all are finite. */
static int json_nonfinite(const cJSON *item, char *where, size_t cap)
{
    if (cJSON_IsNumber(item) && !isfinite(item->valuedouble)) {
        snprintf(where, cap, "%s", item->string ? item->string : "a value");
        return 1;
    }
    const cJSON *c;
    int i = 0;
    cJSON_ArrayForEach(c, item) {
        if (json_nonfinite(c, where, cap)) {
            char inner[192];
            snprintf(inner, sizeof inner, "%s", where);
            if (item->string)
                snprintf(where, cap, "%s[%d].%s", item->string, i, inner);
            return 1;
        }
        i++;
    }
    return 0;
}

/* Which mesh's attribute reads accessor a, for the message; "" when none. */
static void accessor_user(const cJSON *root, int a, char *out, size_t cap)
{
    const cJSON *m, *p, *at;
    int mi = 0;
    out[0] = '\0';
    cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(root, "meshes")) {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(m, "name");
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(m, "primitives")) {
            cJSON_ArrayForEach(at, cJSON_GetObjectItemCaseSensitive(p, "attributes")) {
                if (cJSON_IsNumber(at) && at->valueint == a) {
                    if (cJSON_IsString(name))
                        snprintf(out, cap, " (%s of mesh '%s')", at->string, name->valuestring);
                    else
                        snprintf(out, cap, " (%s of mesh %d)", at->string, mi);
                    return;
                }
            }
        }
        mi++;
    }
}

/*
 * Issue #31: no glTF with a non-finite number (an exported .hier with a NaN
 * origin wrote "translation": [null, ...]; a .dps, non-finite vertices). The
 * JSON and every float accessor's bytes are checked before a file is
 * written; the element index is the input primitive's or point's within the
 * mesh it names.
 */
static int check_finite(const asp__gltf *g, const char *path, asp_error *err)
{
    char where[256];
    if (json_nonfinite(g->root, where, sizeof where))
        return asp_error_set(err, ASP_EFORMAT, "cannot write '%s': %s is not finite (from the input); nothing written",
                             path, where);
    const cJSON *a;
    int ai = 0;
    cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(g->root, "accessors")) {
        const cJSON *ct = cJSON_GetObjectItemCaseSensitive(a, "componentType");
        const cJSON *vi = cJSON_GetObjectItemCaseSensitive(a, "bufferView");
        const cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(g->root, "bufferViews"),
                                            cJSON_IsNumber(vi) ? vi->valueint : -1);
        const cJSON *off = cJSON_GetObjectItemCaseSensitive(v, "byteOffset");
        const cJSON *len = cJSON_GetObjectItemCaseSensitive(v, "byteLength");
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(a, "type");
        if (cJSON_IsNumber(ct) && ct->valueint == 5126 && cJSON_IsNumber(len) && cJSON_IsString(type)) {
            size_t o = cJSON_IsNumber(off) ? (size_t)off->valuedouble : 0, n = (size_t)len->valuedouble / 4;
            size_t ncomp = (size_t)type_components(type->valuestring);
            for (size_t k = 0; o + 4 * n <= g->bin_size && k < n; k++) {
                float f;
                memcpy(&f, g->bin + o + 4 * k, 4);
                if (!isfinite(f)) {
                    char user[160];
                    accessor_user(g->root, ai, user, sizeof user);
                    return asp_error_set(err, ASP_EFORMAT, "cannot write '%s': accessor %d%s: element %zu is not "
                                         "finite (from the input's element %zu there); nothing written", path, ai,
                                         user, k / ncomp, k / ncomp);
                }
            }
        }
        ai++;
    }
    return 0;
}

int asp__gltf_write(asp__gltf *g, const char *path, asp_gltf_stats *st, asp_error *err)
{
    if (g->failed || finish_json(g))
        return asp_error_set(err, ASP_ENOMEM, "out of memory while building the glTF document for '%s'", path);
    int rc = check_finite(g, path, err);
    if (rc)
        return rc;
    st->images = (size_t)cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(g->root, "images"));
    char *json = g->glb ? cJSON_PrintUnformatted(g->root) : cJSON_Print(g->root);
    if (!json)
        return asp_error_set(err, ASP_ENOMEM, "out of memory printing the glTF JSON of '%s'", path);
    rc = g->glb ? write_glb(path, json, g->bin, g->bin_size, st, err) : write_separate(g, path, json, st, err);
    cJSON_free(json);
    return rc;
}
