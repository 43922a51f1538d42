/*
 * Instance scene files (issue 18 item 4, docs/scene-format.md): strict JSON
 * parsing through cJSON, every distinct source loaded once by the one scene
 * loader (scene.h), and the one framing of the whole scene (the bounding
 * sphere of the instances' spheres), so render, view and eval agree.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "amgsplat/instances.h"
#include "util/json_file.h"
#include "util/regular_file.h"
#include "util/banned.h"

#define SCENE_VERSION 1
enum { MAX_FILE = 64 << 20 };

static const double deg = 3.14159265358979323846 / 180.0;

/* ---- 4x4 column-major affine helpers (double: composition of many small rotations stays exact enough) ---- */

static void mat_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

static void mat_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * k + row] * b[4 * c + k];
            r[4 * c + row] = s;
        }
    memcpy(out, r, sizeof r);
}

/* Rotation about unit axis by angle radians (Rodrigues). */
static void mat_axis_angle(const double axis[3], double angle, double m[16])
{
    double c = cos(angle), s = sin(angle), t = 1 - c, x = axis[0], y = axis[1], z = axis[2];
    mat_identity(m);
    m[0] = t * x * x + c;
    m[1] = t * x * y + s * z;
    m[2] = t * x * z - s * y;
    m[4] = t * x * y - s * z;
    m[5] = t * y * y + c;
    m[6] = t * y * z + s * x;
    m[8] = t * x * z + s * y;
    m[9] = t * y * z - s * x;
    m[10] = t * z * z + c;
}

static double det3(const double m[16])
{
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/* Largest length of the model's three axes: how much it scales a sphere's radius at most. */
static double max_axis_scale(const double m[16])
{
    double best = 0;
    for (int c = 0; c < 3; c++) {
        double l = sqrt(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]);
        best = l > best ? l : best;
    }
    return best;
}

static void mat_apply(const double m[16], const double p[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

/* ---- parsing ---- */

struct parse {
    const char *path;
    asp_error *err;
    asp_instance_scene *s;
    char dir[512]; /* folder of the scene file, "" for the current one */
};

/* n finite numbers of magnitude <= ASP_INSTANCE_SCENE_MAX_COORD from a JSON array of exactly n. */
static int numbers(const cJSON *it, double *v, int n)
{
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return 0;
    int i = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, it)
    {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > ASP_INSTANCE_SCENE_MAX_COORD)
            return 0;
        v[i++] = e->valuedouble;
    }
    return 1;
}

static int source_index(struct parse *p, const char *name, size_t *out, size_t index)
{
    asp_instance_scene *s = p->s;
    for (size_t i = 0; i < s->source_count; i++)
        if (strcmp(s->sources[i].name, name) == 0) {
            *out = i;
            return 0;
        }
    if (s->source_count == ASP_INSTANCE_SCENE_MAX_SOURCES)
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' instance %zu: more than %d distinct sources", p->path, index,
                             ASP_INSTANCE_SCENE_MAX_SOURCES);
    asp_instance_source *src = &s->sources[s->source_count];
    memset(src, 0, sizeof *src);
    snprintf(src->name, sizeof src->name, "%s", name);
    int n = name[0] == '/' || !p->dir[0] ? snprintf(src->path, sizeof src->path, "%s", name)
                                         : snprintf(src->path, sizeof src->path, "%s/%s", p->dir, name);
    if (n < 0 || (size_t)n >= sizeof src->path)
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' instance %zu: 'source' path too long", p->path, index);
    *out = s->source_count++;
    return 0;
}

static int parse_instance(struct parse *p, const cJSON *o, size_t index, asp_instance *inst)
{
    const char *path = p->path;
    asp_error *err = p->err;
    if (!cJSON_IsObject(o))
        return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: expected an object", path, index);
    static const char *const keys[] = {"source", "translate", "rotate_deg", "rotate_axis_angle", "scale", "matrix",
                                       "name"};
    const cJSON *it;
    cJSON_ArrayForEach(it, o)
    {
        int known = 0;
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
            known |= strcmp(it->string, keys[k]) == 0;
        if (!known)
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s' instance %zu: unknown field '%.40s' (expected source, translate, rotate_deg, "
                                 "rotate_axis_angle, scale, matrix, name)",
                                 path, index, it->string);
    }
    const cJSON *src = cJSON_GetObjectItemCaseSensitive(o, "source");
    if (!src)
        return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: missing 'source'", path, index);
    if (!cJSON_IsString(src) || !src->valuestring[0] || strlen(src->valuestring) >= sizeof p->s->sources[0].name)
        return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: 'source' must be a file name under %zu bytes", path,
                             index, sizeof p->s->sources[0].name);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(o, "name");
    if (name && !cJSON_IsString(name))
        return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: 'name' must be a string", path, index);
    int rc = source_index(p, src->valuestring, &inst->source, index);
    if (rc)
        return rc;

    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(o, "matrix");
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(o, "translate");
    const cJSON *rd = cJSON_GetObjectItemCaseSensitive(o, "rotate_deg");
    const cJSON *ra = cJSON_GetObjectItemCaseSensitive(o, "rotate_axis_angle");
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(o, "scale");
    if (mat) {
        if (tr || rd || ra || sc)
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s' instance %zu: 'matrix' replaces translate, rotate and scale (give one or the "
                                 "other)",
                                 path, index);
        if (!numbers(mat, inst->model, 16))
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s' instance %zu: 'matrix' must be 16 finite numbers (column-major) of magnitude "
                                 "<= %g",
                                 path, index, ASP_INSTANCE_SCENE_MAX_COORD);
        if (inst->model[3] != 0 || inst->model[7] != 0 || inst->model[11] != 0 || inst->model[15] != 1)
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s' instance %zu: 'matrix' must be affine (last row 0 0 0 1, column-major)", path,
                                 index);
    } else {
        double t[3] = {0, 0, 0}, scale[3] = {1, 1, 1};
        if (tr && !numbers(tr, t, 3))
            return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: 'translate' must be three finite numbers", path,
                                 index);
        if (rd && ra)
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s' instance %zu: give 'rotate_deg' or 'rotate_axis_angle', not both", path, index);
        double rot[16];
        mat_identity(rot);
        if (rd) {
            double e[3];
            if (!numbers(rd, e, 3))
                return asp_error_set(err, ASP_EFORMAT,
                                     "'%s' instance %zu: 'rotate_deg' must be three finite angles in degrees", path,
                                     index);
            static const double axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
            for (int a = 0; a < 3; a++) { // x first, then y, then z: R = Rz Ry Rx
                double r[16];
                mat_axis_angle(axes[a], e[a] * deg, r);
                mat_mul(r, rot, rot);
            }
        }
        if (ra) {
            double v[4];
            double len = 0;
            if (numbers(ra, v, 4))
                len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(len > 1e-12))
                return asp_error_set(err, ASP_EFORMAT,
                                     "'%s' instance %zu: 'rotate_axis_angle' must be [x, y, z, degrees] with a "
                                     "non-zero axis",
                                     path, index);
            double axis[3] = {v[0] / len, v[1] / len, v[2] / len};
            mat_axis_angle(axis, v[3] * deg, rot);
        }
        if (sc) {
            int ok = cJSON_IsNumber(sc) ? (scale[0] = scale[1] = scale[2] = sc->valuedouble, 1) : numbers(sc, scale, 3);
            for (int a = 0; a < 3; a++)
                ok = ok && scale[a] > 0 && scale[a] <= ASP_INSTANCE_SCENE_MAX_COORD;
            if (!ok)
                return asp_error_set(err, ASP_EFORMAT,
                                     "'%s' instance %zu: 'scale' must be a number > 0 or three of them", path, index);
        }
        double s[16];
        mat_identity(s);
        s[0] = scale[0];
        s[5] = scale[1];
        s[10] = scale[2];
        mat_mul(rot, s, inst->model);
        for (int a = 0; a < 3; a++)
            inst->model[12 + a] = t[a];
    }
    // relative to the axes' own size, so a tiny but regular scale passes and a flattened matrix does not
    double ms = max_axis_scale(inst->model);
    double det = det3(inst->model);
    if (!(fabs(det) > 1e-9 * ms * ms * ms) || !(ms > 0))
        return asp_error_set(err, ASP_EFORMAT, "'%s' instance %zu: the transform is singular (determinant 0)", path,
                             index);
    // a mirror turns front faces into back faces, which the primitives and meshes cull
    if (det < 0)
        return asp_error_set(err, ASP_EFORMAT,
                             "'%s' instance %zu: the transform mirrors (negative determinant); mirrored instances "
                             "are not supported",
                             path, index);
    return 0;
}

static int parse_camera(struct parse *p, const cJSON *cam)
{
    asp_instance_camera *c = &p->s->camera;
    if (!cJSON_IsObject(cam))
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' camera: expected an object {\"eye\", \"target\", \"fov\"}",
                             p->path);
    const cJSON *it;
    cJSON_ArrayForEach(it, cam)
    {
        if (strcmp(it->string, "eye") && strcmp(it->string, "target") && strcmp(it->string, "fov"))
            return asp_error_set(p->err, ASP_EFORMAT, "'%s' camera: unknown field '%.40s' (expected eye, target, fov)",
                                 p->path, it->string);
    }
    if (!numbers(cJSON_GetObjectItemCaseSensitive(cam, "eye"), c->eye, 3) ||
        !numbers(cJSON_GetObjectItemCaseSensitive(cam, "target"), c->target, 3))
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' camera: 'eye' and 'target' must be three finite numbers each",
                             p->path);
    double d2 = 0;
    for (int a = 0; a < 3; a++)
        d2 += (c->eye[a] - c->target[a]) * (c->eye[a] - c->target[a]);
    if (!(d2 > 0))
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' camera: 'eye' and 'target' are the same point", p->path);
    const cJSON *fov = cJSON_GetObjectItemCaseSensitive(cam, "fov");
    if (fov && !(cJSON_IsNumber(fov) && fov->valuedouble > 0 && fov->valuedouble < 180))
        return asp_error_set(p->err, ASP_EFORMAT, "'%s' camera: 'fov' must be degrees in (0, 180)", p->path);
    c->fov_y = fov ? (float)fov->valuedouble : 0.0f;
    c->given = 1;
    return 0;
}

static int parse_root(struct parse *p, const cJSON *root)
{
    const char *path = p->path;
    asp_error *err = p->err;
    asp_instance_scene *s = p->s;
    if (!cJSON_IsObject(root))
        return asp_error_set(err, ASP_EFORMAT, "'%s': expected a JSON object with \"version\" and \"instances\"", path);
    const cJSON *it;
    cJSON_ArrayForEach(it, root)
    {
        if (strcmp(it->string, "version") && strcmp(it->string, "instances") && strcmp(it->string, "camera") &&
            strcmp(it->string, "background") && strcmp(it->string, "comment") && strcmp(it->string, "generator"))
            return asp_error_set(err, ASP_EFORMAT,
                                 "'%s': unknown field '%.40s' (expected version, instances, camera, background, "
                                 "comment, generator)",
                                 path, it->string);
    }
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (!cJSON_IsNumber(ver) || ver->valuedouble != SCENE_VERSION)
        return asp_error_set(err, ASP_EFORMAT, "'%s': 'version' must be %d", path, SCENE_VERSION);
    const cJSON *inst = cJSON_GetObjectItemCaseSensitive(root, "instances");
    int n = cJSON_IsArray(inst) ? cJSON_GetArraySize(inst) : -1;
    if (n < 1)
        return asp_error_set(err, ASP_EFORMAT, "'%s': 'instances' must be a non-empty array", path);
    if (n > ASP_INSTANCE_SCENE_MAX_INSTANCES)
        return asp_error_set(err, ASP_EFORMAT, "'%s': %d instances, more than %d", path, n,
                             ASP_INSTANCE_SCENE_MAX_INSTANCES);
    s->instances = asp_calloc(&s->ctx, (size_t)n, sizeof *s->instances);
    size_t nsrc = (size_t)n < ASP_INSTANCE_SCENE_MAX_SOURCES ? (size_t)n : ASP_INSTANCE_SCENE_MAX_SOURCES;
    s->sources = asp_calloc(&s->ctx, nsrc, sizeof *s->sources);
    if (!s->instances || !s->sources)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the %d instances of '%s'", n, path);
    const cJSON *o;
    cJSON_ArrayForEach(o, inst)
    {
        int rc = parse_instance(p, o, s->instance_count, &s->instances[s->instance_count]);
        if (rc)
            return rc;
        s->instance_count++;
    }
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (cam) {
        int rc = parse_camera(p, cam);
        if (rc)
            return rc;
    }
    const cJSON *bg = cJSON_GetObjectItemCaseSensitive(root, "background");
    if (bg) {
        double v[4] = {0, 0, 0, 255};
        int nb = cJSON_IsArray(bg) ? cJSON_GetArraySize(bg) : 0;
        int ok = (nb == 3 || nb == 4) && numbers(bg, v, nb);
        for (int c = 0; c < 4; c++)
            ok = ok && v[c] >= 0 && v[c] <= 255 && v[c] == floor(v[c]);
        if (!ok)
            return asp_error_set(err, ASP_EFORMAT, "'%s': 'background' must be [R, G, B] or [R, G, B, A], integers in 0..255",
                                 path);
        for (int c = 0; c < 4; c++)
            s->background[c] = (uint8_t)v[c];
        s->has_background = 1;
    }
    return 0;
}

int asp_instance_scene_parse(const char *text, size_t len, const char *path, asp_instance_scene *out,
                             asp_error *err)
{
    ASP_ASSERT(text || !len);
    ASP_ASSERT(path && out);
    asp_instance_scene s;
    memset(&s, 0, sizeof s);
    if (strlen(path) >= sizeof s.path)
        return asp_error_set(err, ASP_EINVAL, "cannot read '%.64s...': path longer than %zu bytes", path,
                             sizeof s.path - 1);
    snprintf(s.path, sizeof s.path, "%s", path);
    struct parse p = {.path = path, .err = err, .s = &s};
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(p.dir, sizeof p.dir, "%.*s", (int)(slash == path ? 1 : slash - path), path);
    cJSON *root = cJSON_ParseWithLength(text ? text : "", len);
    if (!root) {
        const char *at = cJSON_GetErrorPtr();
        size_t off = at && text && at >= text && at <= text + len ? (size_t)(at - text) : 0;
        return asp_error_set(err, ASP_EFORMAT, "'%s': not JSON near byte %zu", path, off);
    }
    int rc = parse_root(&p, root);
    cJSON_Delete(root);
    if (rc) {
        asp_instance_scene_release(&s);
        return rc;
    }
    *out = s;
    return 0;
}

int asp_instance_scene_read(const char *path, asp_instance_scene *out, asp_error *err)
{
    char *text = NULL;
    size_t len = 0;
    int rc = asp__text_file_read(path, MAX_FILE, "a scene file", &text, &len, err);
    if (!rc)
        rc = asp_instance_scene_parse(text, len, path, out, err);
    free(text);
    return rc;
}

/* Bounding sphere of the instances' spheres: centre of their box, radius to the farthest far side. */
static int frame_instances(asp_instance_scene *s, asp_error *err)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < s->instance_count; i++) {
        const asp_instance *in = &s->instances[i];
        const asp_frame *f = &s->sources[in->source].scene.frame;
        double c[3], r = f->radius * max_axis_scale(in->model);
        mat_apply(in->model, f->center, c);
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], c[a] - r);
            hi[a] = fmax(hi[a], c[a] + r);
        }
    }
    double center[3], r2 = 0;
    for (int a = 0; a < 3; a++)
        center[a] = 0.5 * (lo[a] + hi[a]);
    for (size_t i = 0; i < s->instance_count; i++) {
        const asp_instance *in = &s->instances[i];
        const asp_frame *f = &s->sources[in->source].scene.frame;
        double c[3], d2 = 0, r = f->radius * max_axis_scale(in->model);
        mat_apply(in->model, f->center, c);
        for (int a = 0; a < 3; a++)
            d2 += (c[a] - center[a]) * (c[a] - center[a]);
        double d = sqrt(d2) + r;
        r2 = fmax(r2, d * d);
    }
    if (!(r2 > 0) || !isfinite(r2))
        return asp_error_set(err, ASP_EDEGENERATE, "'%s': nothing to frame (every instance is one point)", s->path);
    memcpy(s->frame.center, center, sizeof center);
    s->frame.radius = sqrt(r2);
    return 0;
}

int asp_instance_scene_load(const char *path, const asp_scene_desc *desc, const asp_context *ctx,
                            asp_instance_scene *out, asp_error *err)
{
    asp_instance_scene s;
    int rc = asp_instance_scene_read(path, &s, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < s.source_count && !rc; i++) {
        asp_instance_source *src = &s.sources[i];
        size_t first = 0;
        while (s.instances[first].source != i)
            first++;
        asp_file_type type;
        asp_error e = {0, ""};
        rc = asp_file_recognise(src->path, &type, &e);
        if (!rc && type.kind == ASP_FILE_SCENE)
            rc = asp_error_set(&e, ASP_EUNSUPPORTED, "a scene inside a scene is not drawn (give its sources)");
        if (!rc)
            rc = asp_scene_load(src->path, desc, ctx, &src->scene, &e);
        if (rc)
            asp_error_set(err, rc, "'%s' instance %zu source '%s': %s", path, first, src->name, e.msg);
    }
    if (!rc)
        rc = frame_instances(&s, err);
    if (rc) {
        asp_instance_scene_release(&s);
        return rc;
    }
    *out = s;
    return 0;
}

int asp_instance_scene_save(const asp_instance_scene *s, const char *path, asp_error *err)
{
    cJSON *root = cJSON_CreateObject(), *arr = NULL;
    int ok = root && cJSON_AddNumberToObject(root, "version", SCENE_VERSION) &&
             (arr = cJSON_AddArrayToObject(root, "instances"));
    for (size_t i = 0; ok && i < s->instance_count; i++) {
        cJSON *o = cJSON_CreateObject();
        ok = o && cJSON_AddItemToArray(arr, o);
        if (!ok) {
            cJSON_Delete(o);
            break;
        }
        ok = cJSON_AddStringToObject(o, "source", s->sources[s->instances[i].source].name) != NULL;
        cJSON *m = ok ? cJSON_AddArrayToObject(o, "matrix") : NULL;
        ok = m != NULL;
        for (int k = 0; ok && k < 16; k++) {
            // %.17g: read back bit for bit (the generator's determinism test compares files)
            char num[32];
            snprintf(num, sizeof num, "%.17g", s->instances[i].model[k]);
            ok = cJSON_AddItemToArray(m, cJSON_CreateRaw(num));
        }
    }
    if (ok && s->camera.given) {
        cJSON *c = cJSON_AddObjectToObject(root, "camera");
        ok = c && cJSON_AddItemToObject(c, "eye", cJSON_CreateDoubleArray(s->camera.eye, 3)) &&
             cJSON_AddItemToObject(c, "target", cJSON_CreateDoubleArray(s->camera.target, 3)) &&
             (!s->camera.fov_y || cJSON_AddNumberToObject(c, "fov", s->camera.fov_y));
    }
    if (ok && s->has_background) {
        int bg[4] = {s->background[0], s->background[1], s->background[2], s->background[3]};
        ok = cJSON_AddItemToObject(root, "background", cJSON_CreateIntArray(bg, 4));
    }
    if (!ok) {
        cJSON_Delete(root);
        root = NULL; // reported as out of memory
    }
    return asp__json_save(root, path, err);
}

size_t asp_instance_scene_count(const asp_instance_scene *s, size_t source)
{
    size_t n = 0;
    for (size_t i = 0; i < s->instance_count; i++)
        n += s->instances[i].source == source;
    return n;
}

size_t asp_instance_scene_models(const asp_instance_scene *s, size_t source, float *dst)
{
    const double *so = s->sources[source].scene.origin;
    size_t n = 0;
    for (size_t i = 0; i < s->instance_count; i++) {
        const asp_instance *in = &s->instances[i];
        if (in->source != source)
            continue;
        // T(-scene centre) * model * T(source origin), in double so a far scene keeps its digits
        double m[16];
        memcpy(m, in->model, sizeof m);
        double t[3];
        mat_apply(in->model, so, t);
        for (int a = 0; a < 3; a++)
            m[12 + a] = t[a] - s->frame.center[a];
        for (int k = 0; k < 16; k++)
            dst[16 * n + (size_t)k] = (float)m[k];
        n++;
    }
    return n;
}

void asp_instance_scene_release(asp_instance_scene *s)
{
    if (!s)
        return;
    for (size_t i = 0; s->sources && i < s->source_count; i++)
        asp_scene_release(&s->sources[i].scene);
    asp_context ctx = s->ctx;
    asp_free(&ctx, s->sources);
    asp_free(&ctx, s->instances);
    memset(s, 0, sizeof *s);
}
