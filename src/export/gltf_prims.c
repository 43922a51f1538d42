/*
 * Domain primitives (journal section 3, thesis 3.1-3.3) as glTF: each primitive its textured
 * support rectangle, drawn exactly as src/render/prim_renderer.c draws it (corners centre +-
 * half_u axis_u +- half_v axis_v, texture coordinates on the texture rectangle's texel edges),
 * the level's atlas as baseColorTexture (colour + alpha = basis function, thesis 3.3), and the
 * normal atlas of journal section 6 turned into glTF's tangent-space normal texture.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "export/internal.h"
#include "util/banned.h"

/* Vertex arrays of one level: 4 corners per primitive. */
typedef struct level_arrays {
    float *pos, *nrm, *tan, *uv;
    void *idx;
    float lo[3], hi[3];
} level_arrays;

/* origin: the source's coordinates; up: its up axis, turned to glTF's +y (asp__gltf_turn_up). */
static void fill_level(const asp_dps_level *lv, const double origin[3], asp_up_axis up, level_arrays *a, int wide)
{
    // triangle-strip corner order of the renderer (prim_shaders.c): counter-clockwise seen from the normal
    static const float corner[4][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    for (int k = 0; k < 3; k++) {
        a->lo[k] = INFINITY;
        a->hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        for (int c = 0; c < 4; c++) {
            size_t v = 4 * i + (size_t)c;
            double su = corner[c][0] * (double)p->half_u, sv = corner[c][1] * (double)p->half_v, x[3], n[3], t[3];
            // in double until the offset from origin is taken: centres are world coordinates
            for (int k = 0; k < 3; k++)
                x[k] = p->centre[k] - origin[k] + su * p->axis_u[k] + sv * p->axis_v[k];
            asp__gltf_turn_up(up, x, x);
            asp__gltf_turn_up(up, (const double[3]){p->normal[0], p->normal[1], p->normal[2]}, n);
            asp__gltf_turn_up(up, (const double[3]){p->axis_u[0], p->axis_u[1], p->axis_u[2]}, t);
            for (int k = 0; k < 3; k++) {
                a->pos[3 * v + k] = (float)x[k];
                a->lo[k] = fminf(a->lo[k], (float)x[k]);
                a->hi[k] = fmaxf(a->hi[k], (float)x[k]);
                a->nrm[3 * v + k] = (float)n[k];
                a->tan[4 * v + k] = (float)t[k]; // the tangent-space normal map is unchanged by the turn
            }
            // w = +1: bitangent = normal x axis_u = axis_v, the direction of increasing v (rows)
            a->tan[4 * v + 3] = 1.0f;
            a->uv[2 * v] = ((float)p->tex_x + (0.5f * corner[c][0] + 0.5f) * (float)p->tex_w) / (float)lv->atlas.width;
            a->uv[2 * v + 1] =
                ((float)p->tex_y + (0.5f * corner[c][1] + 0.5f) * (float)p->tex_h) / (float)lv->atlas.height;
        }
        static const unsigned tri[6] = {0, 1, 2, 2, 1, 3};
        for (int t = 0; t < 6; t++) {
            size_t v = 4 * i + tri[t];
            if (wide)
                ((uint32_t *)a->idx)[6 * i + (size_t)t] = (uint32_t)v;
            else
                ((uint16_t *)a->idx)[6 * i + (size_t)t] = (uint16_t)v;
        }
    }
}

/*
 * glTF normal textures are tangent space (spec 3.9.3): per texel of a primitive's rectangle
 * (and its padding) the world normal n becomes (n.axis_u, n.axis_v, n.normal), the frame the
 * TANGENT attribute gives. Texels without a normal (zero vector: the renderer keeps the
 * primitive normal there) and texels outside every rectangle get the flat (0, 0, 1).
 */
static void tangent_normals(const asp_dps_level *lv, uint32_t padding, uint8_t *out)
{
    const asp_image *in = &lv->normal_atlas;
    size_t texels = (size_t)in->width * in->height;
    for (size_t t = 0; t < texels; t++) {
        uint8_t *o = out + 4 * t;
        o[0] = 128;
        o[1] = 128;
        o[2] = 255;
        o[3] = 255;
    }
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        uint32_t x0 = p->tex_x > padding ? p->tex_x - padding : 0, y0 = p->tex_y > padding ? p->tex_y - padding : 0;
        uint32_t x1 = p->tex_x + p->tex_w + padding, y1 = p->tex_y + p->tex_h + padding;
        x1 = x1 < in->width ? x1 : in->width;
        y1 = y1 < in->height ? y1 : in->height;
        for (uint32_t y = y0; y < y1; y++)
            for (uint32_t x = x0; x < x1; x++) {
                const uint8_t *s = in->pixels + 4 * ((size_t)y * in->width + x);
                float n[3];
                for (int k = 0; k < 3; k++)
                    n[k] = s[k] / 127.5f - 1.0f;
                if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] <= 1e-4f)
                    continue;
                float ts[3] = {0, 0, 0};
                for (int k = 0; k < 3; k++) {
                    ts[0] += n[k] * p->axis_u[k];
                    ts[1] += n[k] * p->axis_v[k];
                    ts[2] += n[k] * p->normal[k];
                }
                float len = sqrtf(ts[0] * ts[0] + ts[1] * ts[1] + ts[2] * ts[2]);
                uint8_t *o = out + 4 * ((size_t)y * in->width + x);
                for (int k = 0; k < 3; k++)
                    o[k] = (uint8_t)lrintf(fminf(fmaxf((ts[k] / len * 0.5f + 0.5f) * 255.0f, 0.0f), 255.0f));
            }
    }
}

static cJSON *texture_info(int texture)
{
    cJSON *t = cJSON_CreateObject();
    if (t)
        cJSON_AddNumberToObject(t, "index", texture);
    return t;
}

static int add_material(asp__gltf *g, const char *name, int color_tex, int normal_tex, const asp_gltf_desc *d,
                        float cutoff, int billboards)
{
    cJSON *m = cJSON_CreateObject();
    if (!m) {
        g->failed = 1;
        return -1;
    }
    cJSON_AddStringToObject(m, "name", name);
    cJSON *pbr = cJSON_AddObjectToObject(m, "pbrMetallicRoughness");
    if (pbr) {
        cJSON_AddItemToObject(pbr, "baseColorTexture", texture_info(color_tex));
        // a matte dielectric: lit viewers show the texture colour, not a metal
        cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
        cJSON_AddNumberToObject(pbr, "roughnessFactor", 1);
    }
    if (normal_tex >= 0)
        cJSON_AddItemToObject(m, "normalTexture", texture_info(normal_tex));
    if (billboards) {
        /* a billboard cloud's alpha is a binary mask (issue 30): always MASK, at 0.5 unless a cutoff is given */
        cJSON_AddStringToObject(m, "alphaMode", "MASK");
        cJSON_AddNumberToObject(m, "alphaCutoff", d->alpha_cutoff > 0 ? d->alpha_cutoff : 0.5);
    } else if (d->alpha_mode == ASP_GLTF_ALPHA_MASK) {
        cJSON_AddStringToObject(m, "alphaMode", "MASK");
        cJSON_AddNumberToObject(m, "alphaCutoff", cutoff);
    } else {
        cJSON_AddStringToObject(m, "alphaMode", "BLEND");
    }
    // the seeds draw both faces of every rectangle (journal Fig. 10 culls by its own test)
    cJSON_AddTrueToObject(m, "doubleSided");
    if (!(d->flags & ASP_GLTF_LIT)) {
        cJSON *ext = cJSON_AddObjectToObject(m, "extensions");
        cJSON_AddObjectToObject(ext, "KHR_materials_unlit");
        asp__gltf_use_extension(g, "KHR_materials_unlit");
    }
    return asp__gltf_append(g, g->materials, m);
}

static cJSON *attribute_map(int pos, int nrm, int tan, int uv)
{
    cJSON *a = cJSON_CreateObject();
    if (a) {
        cJSON_AddNumberToObject(a, "POSITION", pos);
        cJSON_AddNumberToObject(a, "NORMAL", nrm);
        if (tan >= 0) // only with a normal texture, the one thing glTF uses tangents for
            cJSON_AddNumberToObject(a, "TANGENT", tan);
        cJSON_AddNumberToObject(a, "TEXCOORD_0", uv);
    }
    return a;
}

/* Mean sqrt(half_u half_v): the renderer's default depth window is half of it (prim_renderer.c). */
static double mean_radius(const asp_dps_level *lv)
{
    double s = 0;
    for (size_t i = 0; i < lv->prim_count; i++)
        s += sqrt((double)lv->prims[i].half_u * lv->prims[i].half_v);
    return s / (double)lv->prim_count;
}

/* origin: the source's coordinates (the node's translation is it turned to y-up). */
/* Level index as one node of g, positions relative to origin; local: no node translation (a tile's
   tileset transform adds the origin back), else the translation is origin. */
static int export_level(asp__gltf *g, const asp_dps *dps, size_t index, const double origin[3], int local,
                        const asp_gltf_desc *d, float cutoff, asp_gltf_stats *st, asp_error *err)
{
    const asp_dps_level *lv = &dps->levels[index];
    char lname[16], name[64], img[48];
    asp_dps_level_name(dps, index, lname);
    size_t n = lv->prim_count, nv = 4 * n;
    if (n == 0 || !lv->atlas.pixels)
        return asp_error_set(err, ASP_EDEGENERATE, "level %s has no primitives to export", lname);
    if (n > UINT32_MAX / 8)
        return asp_error_set(err, ASP_EUNSUPPORTED, "level %s: %zu primitives exceed 32-bit glTF indices", lname, n);
    int wide = nv > 65535;
    level_arrays a;
    a.pos = asp_alloc(g->ctx, nv * 3 * sizeof(float));
    a.nrm = asp_alloc(g->ctx, nv * 3 * sizeof(float));
    a.tan = asp_alloc(g->ctx, nv * 4 * sizeof(float));
    a.uv = asp_alloc(g->ctx, nv * 2 * sizeof(float));
    a.idx = asp_alloc(g->ctx, 6 * n * (wide ? 4 : 2));
    uint8_t *normals = NULL;
    int has_normals = lv->normal_atlas.width > 0 && lv->normal_atlas.pixels && !(d->flags & ASP_GLTF_NO_NORMAL_MAP) &&
                      lv->normal_atlas.width == lv->atlas.width && lv->normal_atlas.height == lv->atlas.height;
    if (has_normals)
        normals = asp_alloc(g->ctx, (size_t)lv->atlas.width * lv->atlas.height * 4);
    int rc = 0;
    if (!a.pos || !a.nrm || !a.tan || !a.uv || !a.idx || (has_normals && !normals)) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the %zu quads of level %s", n, lname);
        goto done;
    }
    fill_level(lv, origin, dps->frame.up, &a, wide);
    int ipos = asp__gltf_accessor(g, asp__gltf_view(g, a.pos, nv * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, nv,
                                  "VEC3", 0, a.lo, a.hi);
    int inrm = asp__gltf_accessor(g, asp__gltf_view(g, a.nrm, nv * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, nv,
                                  "VEC3", 0, NULL, NULL);
    int itan = has_normals ? asp__gltf_accessor(g, asp__gltf_view(g, a.tan, nv * 16, ASP__GL_ARRAY_BUFFER),
                                                ASP__GL_FLOAT, nv, "VEC4", 0, NULL, NULL)
                           : -1;
    int iuv = asp__gltf_accessor(g, asp__gltf_view(g, a.uv, nv * 8, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, nv, "VEC2",
                                 0, NULL, NULL);
    int iidx = asp__gltf_accessor(g, asp__gltf_view(g, a.idx, 6 * n * (wide ? 4 : 2), ASP__GL_ELEMENT_ARRAY_BUFFER),
                                  wide ? ASP__GL_UNSIGNED_INT : ASP__GL_UNSIGNED_SHORT, 6 * n, "SCALAR", 0, NULL,
                                  NULL);
    snprintf(img, sizeof img, "%s_atlas", lname);
    int color_tex = asp__gltf_texture(g, asp__gltf_image(g, lv->atlas.pixels, lv->atlas.width, lv->atlas.height, img));
    int normal_tex = -1;
    if (has_normals) {
        tangent_normals(lv, dps->desc.padding, normals);
        snprintf(img, sizeof img, "%s_normal", lname);
        normal_tex = asp__gltf_texture(g, asp__gltf_image(g, normals, lv->atlas.width, lv->atlas.height, img));
    }
    snprintf(name, sizeof name, "%s (%zu primitives)", lname, n);
    int mat = add_material(g, name, color_tex, normal_tex, d, cutoff, lv->billboards != 0);
    if (g->failed || ipos < 0 || inrm < 0 || (has_normals && itan < 0) || iuv < 0 || iidx < 0 || color_tex < 0 || mat < 0) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory exporting level %s", lname);
        goto done;
    }
    cJSON *mesh = cJSON_CreateObject(), *prims = cJSON_AddArrayToObject(mesh, "primitives"), *pr = cJSON_CreateObject();
    if (pr) {
        cJSON_AddItemToObject(pr, "attributes", attribute_map(ipos, inrm, itan, iuv));
        cJSON_AddNumberToObject(pr, "indices", iidx);
        cJSON_AddNumberToObject(pr, "material", mat);
        cJSON_AddNumberToObject(pr, "mode", 4); // TRIANGLES
    }
    cJSON_AddItemToArray(prims, pr);
    cJSON_AddStringToObject(mesh, "name", name);
    int imesh = asp__gltf_append(g, g->meshes, mesh);
    cJSON *node = cJSON_CreateObject();
    if (node) {
        cJSON_AddStringToObject(node, "name", name);
        cJSON_AddNumberToObject(node, "mesh", imesh);
        double t[3];
        asp__gltf_turn_up(dps->frame.up, origin, t);
        if (!local)
            cJSON_AddItemToObject(node, "translation", asp__gltf_numbers(t, 3));
        cJSON *ex = cJSON_AddObjectToObject(node, "extras");
        cJSON *am = cJSON_AddObjectToObject(ex, "amgsplat");
        cJSON_AddStringToObject(am, "level", lname);
        cJSON_AddNumberToObject(am, "amgLevel", lv->level);
        cJSON_AddNumberToObject(am, "primitives", (double)n);
        cJSON_AddBoolToObject(am, "normalMap", has_normals);
        // what the renderer's normalized method needs to blend as `amgsplat render` does
        cJSON_AddNumberToObject(am, "alphaRef", 0.1);
        cJSON_AddNumberToObject(am, "depthWindow", 0.5 * mean_radius(lv));
        // issue 30: a billboard cloud is drawn by its material (alphaMode MASK), never blended
        if (lv->billboards)
            cJSON_AddTrueToObject(am, "billboards");
    }
    if (imesh < 0 || asp__gltf_append(g, g->nodes, node) < 0) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory exporting level %s", lname);
        goto done;
    }
    st->primitives += n;
    st->nodes++;
done:
    asp_free(g->ctx, a.pos);
    asp_free(g->ctx, a.nrm);
    asp_free(g->ctx, a.tan);
    asp_free(g->ctx, a.uv);
    asp_free(g->ctx, a.idx);
    asp_free(g->ctx, normals);
    return rc;
}

static void prim_origin(const asp_dps *dps, const size_t *levels, size_t count, double origin[3])
{
    if (dps->frame.radius > 0) {
        memcpy(origin, dps->frame.center, 3 * sizeof(double));
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t l = 0; l < count; l++) {
        const asp_dps_level *lv = &dps->levels[levels[l]];
        for (size_t i = 0; i < lv->prim_count; i++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fmin(lo[k], lv->prims[i].centre[k]);
                hi[k] = fmax(hi[k], lv->prims[i].centre[k]);
            }
    }
    for (int k = 0; k < 3; k++)
        origin[k] = lo[k] <= hi[k] ? 0.5 * (lo[k] + hi[k]) : 0.0;
}

static int export_dps(const asp_dps *dps, const char *path, const asp_gltf_desc *desc, int local,
                      asp_gltf_stats *stats, asp_error *err)
{
    ASP_ASSERT(dps && path);
    static const asp_gltf_desc zero;
    const asp_gltf_desc *d = desc ? desc : &zero;
    if (d->alpha_mode != ASP_GLTF_ALPHA_BLEND && d->alpha_mode != ASP_GLTF_ALPHA_MASK)
        return asp_error_set(err, ASP_EINVAL, "unknown alpha mode %d (expected blend or mask)", (int)d->alpha_mode);
    if (!(d->alpha_cutoff >= 0 && d->alpha_cutoff < 1))
        return asp_error_set(err, ASP_EINVAL, "alpha cutoff %g is outside [0, 1)", (double)d->alpha_cutoff);
    float cutoff = d->alpha_cutoff > 0 ? d->alpha_cutoff : 0.1f;
    size_t count = d->levels ? d->level_count : dps->level_count;
    if (count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' holds no level to export", dps->source);
    size_t *levels = asp_alloc(&dps->ctx, count * sizeof *levels);
    if (!levels)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu levels", count);
    for (size_t i = 0; i < count; i++) {
        levels[i] = d->levels ? d->levels[i] : i;
        if (levels[i] >= dps->level_count) {
            asp_free(&dps->ctx, levels);
            return asp_error_set(err, ASP_EINVAL, "level index %zu is out of range (the file holds %zu levels)",
                                 d->levels[i], dps->level_count);
        }
    }
    asp_gltf_stats st = {0};
    double origin[3]; // the source's coordinates; st.origin is it turned to glTF's y-up
    prim_origin(dps, levels, count, origin);
    asp__gltf_turn_up(dps->frame.up, origin, st.origin);
    asp__gltf g;
    int rc = asp__gltf_init(&g, path, "(domain primitives)", &dps->ctx, err);
    for (size_t i = 0; !rc && i < count; i++)
        rc = export_level(&g, dps, levels[i], origin, local, d, cutoff, &st, err);
    if (!rc) {
        // one scene per level, named by it: plain viewers show one level, not all of them on top of each other
        cJSON *scenes = cJSON_AddArrayToObject(g.root, "scenes");
        for (size_t i = 0; i < count; i++) {
            cJSON *s = cJSON_CreateObject();
            char lname[16];
            asp_dps_level_name(dps, levels[i], lname);
            cJSON_AddStringToObject(s, "name", lname);
            double node = (double)i;
            cJSON_AddItemToObject(s, "nodes", asp__gltf_numbers(&node, 1));
            static const double none[3] = {0, 0, 0};
            cJSON_AddItemToObject(s, "extras",
                                  asp__gltf_extras("primitives", dps->source, local ? none : st.origin, &dps->frame));
            if (asp__gltf_append(&g, scenes, s) < 0)
                break;
        }
        cJSON_AddNumberToObject(g.root, "scene", 0);
        rc = asp__gltf_write(&g, path, &st, err);
    }
    if (g.root)
        asp__gltf_release(&g);
    asp_free(&dps->ctx, levels);
    if (!rc && stats)
        *stats = st;
    return rc;
}

int asp_gltf_export_dps(const asp_dps *dps, const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats,
                        asp_error *err)
{
    return export_dps(dps, path, desc, 0, stats, err);
}

int asp__gltf_prims_tile(const asp_dps *dps, size_t level, const char *path, const asp_gltf_desc *desc,
                         asp_gltf_stats *stats, asp_error *err)
{
    asp_gltf_desc d = desc ? *desc : (asp_gltf_desc){0};
    d.levels = &level;
    d.level_count = 1;
    return export_dps(dps, path, &d, 1, stats, err);
}
