/*
 * asp_cloud: structure-of-arrays point set (STYLE.md section 6). Every array
 * comes from the cloud's own context allocator, so destroy frees with the
 * allocator that allocated.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/cloud.h"
#include "util/banned.h"

size_t asp_scalar_size(asp_scalar_type t)
{
    switch (t) {
    case ASP_SCALAR_INT8: case ASP_SCALAR_UINT8: return 1;
    case ASP_SCALAR_INT16: case ASP_SCALAR_UINT16: return 2;
    case ASP_SCALAR_INT32: case ASP_SCALAR_UINT32: case ASP_SCALAR_FLOAT32: return 4;
    case ASP_SCALAR_FLOAT64: return 8;
    default: return 0;
    }
}

const char *asp_scalar_name(asp_scalar_type t)
{
    static const char *names[] = {"none", "char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
    return (unsigned)t < sizeof names / sizeof names[0] ? names[t] : "none";
}

static void *alloc_array(asp_cloud *c, size_t count, size_t elem)
{
    return asp_calloc(&c->ctx, count ? count : 1, elem);
}

int asp_cloud_add_attrs(asp_cloud *c, unsigned attrs, asp_error *err)
{
    ASP_ASSERT(c);
    size_t n = c->count;
#define ADD(bit, field, elems, type)                                                   \
    if ((attrs & (bit)) && !c->field) {                                                \
        c->field = alloc_array(c, n, (elems) * sizeof(type));                          \
        if (!c->field)                                                                 \
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu points' " #field, n); \
    }
    ADD(ASP_ATTR_NORMALS, normals, 3, float)
    ADD(ASP_ATTR_COLORS, colors, 4, uint8_t)
    ADD(ASP_ATTR_RADII, radii, 1, float)
    ADD(ASP_ATTR_UVS, uvs, 2, float)
    ADD(ASP_ATTR_LABELS, labels, 1, uint32_t)
#undef ADD
    return 0;
}

int asp_cloud_create(size_t count, unsigned attrs, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    ASP_ASSERT(out);
    if (count >= UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "%zu points is more than a cloud holds (2^32-1)", count);
    if (count > SIZE_MAX / (3 * sizeof(float)))
        return asp_error_set(err, ASP_ENOMEM, "%zu points do not fit in memory", count);
    asp_cloud *c = asp_calloc(ctx, 1, sizeof *c);
    if (!c)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    if (ctx)
        c->ctx = *ctx;
    c->count = count;
    c->position_type = ASP_SCALAR_FLOAT32;
    c->color_type = ASP_SCALAR_UINT8;
    c->positions = alloc_array(c, count, 3 * sizeof(float));
    if (!c->positions) {
        asp_cloud_destroy(c);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu points", count);
    }
    int rc = asp_cloud_add_attrs(c, attrs, err);
    if (rc) {
        asp_cloud_destroy(c);
        return rc;
    }
    *out = c;
    return 0;
}

static void free_strings(const asp_context *ctx, char **s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        asp_free(ctx, s[i]);
    asp_free(ctx, s);
}

void asp_cloud_destroy(asp_cloud *c)
{
    if (!c)
        return;
    asp_context ctx = c->ctx;
    asp_free(&ctx, c->positions);
    asp_free(&ctx, c->normals);
    asp_free(&ctx, c->colors);
    asp_free(&ctx, c->radii);
    asp_free(&ctx, c->uvs);
    asp_free(&ctx, c->labels);
    for (size_t i = 0; i < c->property_count; i++)
        asp_free(&ctx, c->properties[i].data);
    asp_free(&ctx, c->properties);
    asp_free(&ctx, c->faces);
    free_strings(&ctx, c->comments, c->comment_count);
    free_strings(&ctx, c->obj_info, c->obj_info_count);
    if (c->las) {
        for (size_t i = 0; i < c->las->vlr_count; i++)
            asp_free(&ctx, c->las->vlrs[i].data);
        asp_free(&ctx, c->las->vlrs);
        asp_free(&ctx, c->las);
    }
    asp_free(&ctx, c);
}

unsigned asp_cloud_attrs(const asp_cloud *c)
{
    return (c->normals ? ASP_ATTR_NORMALS : 0) | (c->colors ? ASP_ATTR_COLORS : 0) |
           (c->radii ? ASP_ATTR_RADII : 0) | (c->uvs ? ASP_ATTR_UVS : 0) | (c->labels ? ASP_ATTR_LABELS : 0);
}

asp_property *asp_cloud_find_property(const asp_cloud *c, const char *name)
{
    for (size_t i = 0; i < c->property_count; i++)
        if (strcmp(c->properties[i].name, name) == 0)
            return &c->properties[i];
    return NULL;
}

int asp_cloud_add_property(asp_cloud *c, const char *name, asp_scalar_type type, asp_property **out,
                           asp_error *err)
{
    ASP_ASSERT(c && name);
    size_t len = strlen(name);
    if (len == 0 || len >= sizeof c->properties[0].name)
        return asp_error_set(err, ASP_EINVAL, "property name '%.80s' must have 1 to 63 bytes", name);
    if (asp_scalar_size(type) == 0)
        return asp_error_set(err, ASP_EINVAL, "property '%s' has no scalar type", name);
    if (asp_cloud_find_property(c, name))
        return asp_error_set(err, ASP_EINVAL, "property '%s' appears twice", name);
    void *data = alloc_array(c, c->count, asp_scalar_size(type));
    asp_property *grown = asp_realloc(&c->ctx, c->properties, c->property_count * sizeof *grown,
                                      (c->property_count + 1) * sizeof *grown);
    if (!data || !grown) {
        asp_free(&c->ctx, data);
        if (grown)
            c->properties = grown;
        return asp_error_set(err, ASP_ENOMEM, "out of memory for property '%s'", name);
    }
    c->properties = grown;
    asp_property *p = &c->properties[c->property_count++];
    memset(p, 0, sizeof *p);
    memcpy(p->name, name, len + 1);
    p->type = type;
    p->data = data;
    if (out)
        *out = p;
    return 0;
}

static int push_string(asp_cloud *c, char ***list, size_t *n, const char *text, asp_error *err)
{
    size_t len = strlen(text);
    char *s = asp_alloc(&c->ctx, len + 1);
    char **grown = asp_realloc(&c->ctx, *list, *n * sizeof *grown, (*n + 1) * sizeof *grown);
    if (!s || !grown) {
        asp_free(&c->ctx, s);
        if (grown)
            *list = grown;
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a comment");
    }
    memcpy(s, text, len + 1);
    *list = grown;
    (*list)[(*n)++] = s;
    return 0;
}

int asp_cloud_add_comment(asp_cloud *c, const char *text, asp_error *err)
{
    return push_string(c, &c->comments, &c->comment_count, text, err);
}

int asp_cloud_add_obj_info(asp_cloud *c, const char *text, asp_error *err)
{
    return push_string(c, &c->obj_info, &c->obj_info_count, text, err);
}

int asp_cloud_set_faces(asp_cloud *c, const uint32_t *faces, size_t face_count, asp_error *err)
{
    ASP_ASSERT(c && (faces || face_count == 0));
    for (size_t i = 0; i < 3 * face_count; i++)
        if (faces[i] >= c->count)
            return asp_error_set(err, ASP_EFORMAT, "face %zu: vertex index %u is not below the vertex count %zu",
                                 i / 3, faces[i], c->count);
    if (face_count > SIZE_MAX / (3 * sizeof(uint32_t)))
        return asp_error_set(err, ASP_ENOMEM, "%zu faces do not fit in memory", face_count);
    uint32_t *copy = asp_alloc(&c->ctx, 3 * face_count * sizeof *copy);
    if (!copy)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu faces", face_count);
    memcpy(copy, faces, 3 * face_count * sizeof *copy);
    asp_free(&c->ctx, c->faces);
    c->faces = copy;
    c->face_count = face_count;
    return 0;
}

void asp_cloud_world_position(const asp_cloud *c, size_t i, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = c->origin[k] + (double)c->positions[3 * i + k];
}

int asp_cloud_bounds(const asp_cloud *c, float lo[3], float hi[3], asp_error *err)
{
    ASP_ASSERT(c && lo && hi);
    if (c->count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "the point set is empty");
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = c->positions[k];
    for (size_t i = 1; i < c->count; i++)
        for (int k = 0; k < 3; k++) {
            float v = c->positions[3 * i + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    return 0;
}

int asp_cloud_validate(const asp_cloud *c, asp_error *err)
{
    ASP_ASSERT(c);
    static const char axis[] = "xyz";
    for (size_t i = 0; i < c->count; i++) {
        for (int k = 0; k < 3; k++) {
            float v = c->positions[3 * i + k];
            if (!isfinite(v))
                return asp_error_set(err, ASP_EFORMAT, "point %zu: coordinate %c is %s", i, axis[k],
                                     isnan(v) ? "NaN" : "infinite");
            if (c->normals && !isfinite(c->normals[3 * i + k]))
                return asp_error_set(err, ASP_EFORMAT, "point %zu: normal component %c is not finite", i, axis[k]);
        }
        if (c->radii && !(isfinite(c->radii[i]) && c->radii[i] >= 0.0f))
            return asp_error_set(err, ASP_EFORMAT, "point %zu: radius %g is not a finite non-negative number", i,
                                 (double)c->radii[i]);
        if (c->uvs && !(isfinite(c->uvs[2 * i]) && isfinite(c->uvs[2 * i + 1])))
            return asp_error_set(err, ASP_EFORMAT, "point %zu: texture coordinate is not finite", i);
    }
    return 0;
}

/* Deep copy of the LAS metadata into c (which has none yet). */
static int clone_las(asp_cloud *c, const asp_las_meta *src, asp_error *err)
{
    c->las = asp_alloc(&c->ctx, sizeof *c->las);
    if (!c->las)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    *c->las = *src;
    c->las->vlr_count = 0;
    c->las->vlrs = src->vlr_count ? asp_calloc(&c->ctx, src->vlr_count, sizeof *c->las->vlrs) : NULL;
    if (src->vlr_count && !c->las->vlrs)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    for (size_t i = 0; i < src->vlr_count; i++) {
        asp_las_vlr *v = &c->las->vlrs[i];
        *v = src->vlrs[i];
        v->data = asp_alloc(&c->ctx, v->size ? v->size : 1);
        if (!v->data)
            return asp_error_set(err, ASP_ENOMEM, "out of memory");
        memcpy(v->data, src->vlrs[i].data, v->size);
        c->las->vlr_count = i + 1;
    }
    return 0;
}

int asp_cloud_clone(const asp_cloud *src, asp_cloud **out, asp_error *err)
{
    ASP_ASSERT(src && out);
    asp_cloud *c;
    int rc = asp_cloud_create(src->count, asp_cloud_attrs(src), &src->ctx, &c, err);
    if (rc)
        return rc;
    size_t n = src->count;
    memcpy(c->origin, src->origin, sizeof c->origin);
    memcpy(c->positions, src->positions, 3 * n * sizeof(float));
    if (src->normals) memcpy(c->normals, src->normals, 3 * n * sizeof(float));
    if (src->colors) memcpy(c->colors, src->colors, 4 * n);
    if (src->radii) memcpy(c->radii, src->radii, n * sizeof(float));
    if (src->uvs) memcpy(c->uvs, src->uvs, 2 * n * sizeof(float));
    if (src->labels) memcpy(c->labels, src->labels, n * sizeof(uint32_t));
    c->position_type = src->position_type;
    c->up = src->up;
    c->color_type = src->color_type;
    for (size_t i = 0; i < src->property_count && rc == 0; i++) {
        asp_property *p;
        rc = asp_cloud_add_property(c, src->properties[i].name, src->properties[i].type, &p, err);
        if (rc == 0)
            memcpy(p->data, src->properties[i].data, n * asp_scalar_size(p->type));
    }
    for (size_t i = 0; i < src->comment_count && rc == 0; i++)
        rc = asp_cloud_add_comment(c, src->comments[i], err);
    for (size_t i = 0; i < src->obj_info_count && rc == 0; i++)
        rc = asp_cloud_add_obj_info(c, src->obj_info[i], err);
    if (rc == 0 && src->face_count)
        rc = asp_cloud_set_faces(c, src->faces, src->face_count, err);
    if (rc == 0 && src->las)
        rc = clone_las(c, src->las, err);
    if (rc) {
        asp_cloud_destroy(c);
        return rc;
    }
    *out = c;
    return 0;
}

double asp_property_value(const asp_property *p, size_t i)
{
    switch (p->type) {
    case ASP_SCALAR_INT8: return ((const int8_t *)p->data)[i];
    case ASP_SCALAR_UINT8: return ((const uint8_t *)p->data)[i];
    case ASP_SCALAR_INT16: return ((const int16_t *)p->data)[i];
    case ASP_SCALAR_UINT16: return ((const uint16_t *)p->data)[i];
    case ASP_SCALAR_INT32: return ((const int32_t *)p->data)[i];
    case ASP_SCALAR_UINT32: return ((const uint32_t *)p->data)[i];
    case ASP_SCALAR_FLOAT32: return ((const float *)p->data)[i];
    case ASP_SCALAR_FLOAT64: return ((const double *)p->data)[i];
    default: return NAN;
    }
}
