/*
 * Simplified meshes, the polygon baseline of issue #14 (seed 004 sections
 * 2.2-2.3 compare points with texture-mapped polygons; thesis 6.2 counts
 * primitives against meshes): meshoptimizer's edge-collapse simplifier
 * (quadric error metric, Garland and Heckbert 1997) on the index buffer, then
 * a compact copy of the vertices still in use with all their attributes.
 */
#include <float.h>
#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "util/banned.h"

/* More than this far above the target counts as stopping short (the tolerance issue #14's tests use). */
static const double short_tolerance = 0.05;

/*
 * Simplifies one index list (a material group) into dst (capacity index_count)
 * towards target_tris triangles; returns the index count written and raises
 * *max_error to the group's error.
 */
static size_t simplify_group(uint32_t *dst, const uint32_t *idx, size_t index_count, const asp_mesh *m,
                             size_t target_tris, float target_error, unsigned options, int sloppy, float *max_error)
{
    float e = 0.0f;
    size_t n;
    if (target_tris * 3 >= index_count) {
        memcpy(dst, idx, index_count * sizeof *dst);
        return index_count;
    }
    if (sloppy)
        n = meshopt_simplifySloppy(dst, idx, index_count, m->positions, m->vertex_count, 3 * sizeof(float),
                                   target_tris * 3, target_error, &e);
    else
        n = meshopt_simplify(dst, idx, index_count, m->positions, m->vertex_count, 3 * sizeof(float), target_tris * 3,
                             target_error, options, &e);
    if (e > *max_error)
        *max_error = e;
    return n;
}

/*
 * Runs the simplifier over every material group: by[] holds the triangles'
 * indices sorted by material (start[k]..start[k+1] for group k). Output goes
 * to dst with the material of each output triangle in dst_mat.
 */
static size_t simplify_all(uint32_t *dst, uint32_t *dst_mat, const uint32_t *by, const size_t *start,
                           const uint32_t *group_mat, size_t groups, const asp_mesh *m,
                           const asp_mesh_simplify_desc *d, int sloppy, float *max_error)
{
    size_t out = 0, total = m->triangle_count;
    float target_error = d->target_error > 0.0 ? (float)d->target_error : FLT_MAX;
    unsigned options = (d->flags & ASP_MESH_SIMPLIFY_LOCK_BORDER) ? meshopt_SimplifyLockBorder : 0;
    if (groups > 1)
        options |= meshopt_SimplifyLockBorder; // a free border would open a crack against the next material
    size_t target = d->target_triangles ? d->target_triangles : 0;
    *max_error = 0.0f;
    for (size_t g = 0; g < groups; g++) {
        size_t tris = (start[g + 1] - start[g]) / 3;
        /* the target shared by triangle count, rounded, at least one triangle per material */
        size_t share = target ? (size_t)((double)target * (double)tris / (double)total + 0.5) : 0;
        if (target && share < 1)
            share = 1;
        size_t n = simplify_group(dst + out, by + start[g], start[g + 1] - start[g], m, share, target_error, options,
                                  sloppy, max_error);
        for (size_t t = 0; t < n / 3; t++)
            dst_mat[out / 3 + t] = group_mat[g];
        out += n;
    }
    return out;
}

static int copy_materials(const asp_mesh *src, asp_mesh *dst, asp_error *err)
{
    asp_material *mats = asp_calloc(&dst->ctx, src->material_count, sizeof *mats);
    if (!mats)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu materials", src->material_count);
    for (size_t i = 0; i < src->material_count; i++) {
        mats[i] = src->materials[i];
        mats[i].texture = (asp_image){0};
        const asp_image *t = &src->materials[i].texture;
        if (!t->pixels)
            continue;
        int rc = asp_image_init(&mats[i].texture, t->width, t->height, err);
        if (rc) {
            for (size_t j = 0; j < i; j++)
                asp_image_release(&mats[j].texture);
            asp_free(&dst->ctx, mats);
            return rc;
        }
        memcpy(mats[i].texture.pixels, t->pixels, (size_t)t->width * t->height * 4);
    }
    asp_free(&dst->ctx, dst->materials);
    dst->materials = mats;
    dst->material_count = src->material_count;
    return 0;
}

/* The output mesh: the vertices the index list uses, in first-use order (meshopt's vertex fetch order). */
static int build_output(const asp_mesh *m, const uint32_t *idx, const uint32_t *mat, size_t index_count,
                        const asp_context *ctx, unsigned flags, asp_mesh **out, asp_error *err)
{
    uint32_t *remap = asp_alloc(ctx, (m->vertex_count + 1) * sizeof *remap);
    if (!remap)
        return asp_error_set(err, ASP_ENOMEM, "out of memory simplifying a mesh of %zu vertices", m->vertex_count);
    size_t nv = meshopt_optimizeVertexFetchRemap(remap, idx, index_count, m->vertex_count);
    unsigned attrs = (m->uvs ? ASP_MESH_UVS : 0) | (m->colors ? ASP_MESH_COLORS : 0);
    asp_mesh *o = NULL;
    int rc = asp_mesh_create(nv, index_count / 3, attrs, ctx, &o, err);
    if (rc == 0)
        rc = copy_materials(m, o, err);
    if (rc) {
        asp_mesh_destroy(o);
        asp_free(ctx, remap);
        return rc;
    }
    for (size_t v = 0; v < m->vertex_count; v++) {
        uint32_t r = remap[v];
        if (r == UINT32_MAX)
            continue;
        memcpy(o->positions + 3 * (size_t)r, m->positions + 3 * v, 3 * sizeof(float));
        memcpy(o->normals + 3 * (size_t)r, m->normals + 3 * v, 3 * sizeof(float));
        if (m->uvs)
            memcpy(o->uvs + 2 * (size_t)r, m->uvs + 2 * v, 2 * sizeof(float));
        if (m->colors)
            memcpy(o->colors + 4 * (size_t)r, m->colors + 4 * v, 4);
    }
    for (size_t i = 0; i < index_count; i++)
        o->triangles[i] = remap[idx[i]];
    memcpy(o->material_ids, mat, index_count / 3 * sizeof *mat);
    asp_free(ctx, remap);
    memcpy(o->origin, m->origin, sizeof o->origin);
    o->uv_set_count = m->uv_set_count;
    o->up = m->up;
    memcpy(o->up_rule, m->up_rule, sizeof o->up_rule);
    if ((flags & ASP_MESH_SIMPLIFY_RECOMPUTE_NORMALS) && (rc = asp_mesh_compute_normals(o, err)) != 0) {
        asp_mesh_destroy(o);
        return rc;
    }
    *out = o;
    return 0;
}

/* Sorts the triangles' indices by material (stable, counting sort); returns the number of groups. */
static size_t group_by_material(const asp_mesh *m, uint32_t *by, size_t *start, uint32_t *group_mat, size_t *count)
{
    for (size_t t = 0; t < m->triangle_count; t++)
        count[m->material_ids[t]]++;
    size_t groups = 0, at = 0;
    for (size_t k = 0; k < m->material_count; k++) {
        if (!count[k])
            continue;
        group_mat[groups] = (uint32_t)k;
        start[groups++] = at;
        size_t n = count[k];
        count[k] = at; // now the write cursor of material k
        at += 3 * n;
    }
    start[groups] = at;
    for (size_t t = 0; t < m->triangle_count; t++) {
        size_t *c = &count[m->material_ids[t]];
        memcpy(by + *c, m->triangles + 3 * t, 3 * sizeof *by);
        *c += 3;
    }
    return groups;
}

int asp_mesh_simplify(const asp_mesh *mesh, const asp_mesh_simplify_desc *desc, const asp_context *ctx,
                      asp_mesh **out, asp_mesh_simplify_stats *stats, asp_error *err)
{
    ASP_ASSERT(mesh && out);
    asp_mesh_simplify_desc d = desc ? *desc : (asp_mesh_simplify_desc){0};
    size_t ni = 3 * mesh->triangle_count;
    for (size_t i = 0; i < ni; i++)
        if (mesh->triangles[i] >= mesh->vertex_count)
            return asp_error_set(err, ASP_EFORMAT, "cannot simplify: triangle %zu uses vertex %u of %zu", i / 3,
                                 mesh->triangles[i], mesh->vertex_count);
    for (size_t t = 0; t < mesh->triangle_count; t++)
        if (mesh->material_ids[t] >= mesh->material_count)
            return asp_error_set(err, ASP_EFORMAT, "cannot simplify: triangle %zu uses material %u of %zu", t,
                                 mesh->material_ids[t], mesh->material_count);
    if (d.target_triangles == 0 && !(d.target_error > 0.0))
        d.target_triangles = mesh->triangle_count; // no target at all: a copy

    size_t nm = mesh->material_count;
    uint32_t *by = asp_alloc(ctx, (ni + 1) * sizeof *by);
    uint32_t *dst = asp_alloc(ctx, (ni + 1) * sizeof *dst);
    uint32_t *dst_mat = asp_alloc(ctx, (mesh->triangle_count + 1) * sizeof *dst_mat);
    uint32_t *alt = asp_alloc(ctx, (ni + 1) * sizeof *alt);
    uint32_t *alt_mat = asp_alloc(ctx, (mesh->triangle_count + 1) * sizeof *alt_mat);
    size_t *start = asp_calloc(ctx, nm + 1, sizeof *start);
    size_t *count = asp_calloc(ctx, nm, sizeof *count);
    uint32_t *group_mat = asp_calloc(ctx, nm, sizeof *group_mat);
    int rc = 0;
    if (!by || !dst || !dst_mat || !alt || !alt_mat || !start || !count || !group_mat) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory simplifying a mesh of %zu triangles", mesh->triangle_count);
        goto done;
    }
    size_t groups = group_by_material(mesh, by, start, group_mat, count);
    float e = 0.0f;
    size_t n = simplify_all(dst, dst_mat, by, start, group_mat, groups, mesh, &d, 0, &e);
    size_t target = d.target_triangles;
    int used_sloppy = 0;
    int is_short = target && (double)(n / 3) > (double)target * (1.0 + short_tolerance);
    if (is_short && (d.flags & ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK)) {
        float e2 = 0.0f;
        size_t n2 = simplify_all(alt, alt_mat, by, start, group_mat, groups, mesh, &d, 1, &e2);
        double miss = fabs((double)(n / 3) - (double)target), miss2 = fabs((double)(n2 / 3) - (double)target);
        if (n2 >= 3 && miss2 < miss) {
            memcpy(dst, alt, n2 * sizeof *dst);
            memcpy(dst_mat, alt_mat, n2 / 3 * sizeof *dst_mat);
            n = n2, e = e2, used_sloppy = 1;
            is_short = (double)(n / 3) > (double)target * (1.0 + short_tolerance);
        }
    }
    asp_mesh *o = NULL;
    rc = build_output(mesh, dst, dst_mat, n, ctx, d.flags, &o, err);
    if (rc)
        goto done;
    if (stats) {
        *stats = (asp_mesh_simplify_stats){
            .input_triangles = mesh->triangle_count,
            .input_vertices = mesh->vertex_count,
            .output_triangles = o->triangle_count,
            .output_vertices = o->vertex_count,
            .target_triangles = desc ? desc->target_triangles : 0,
            .error = e,
            .error_world = (double)e * meshopt_simplifyScale(mesh->positions, mesh->vertex_count, 3 * sizeof(float)),
            .short_of_target = is_short,
            .sloppy = used_sloppy,
            .material_groups = groups,
        };
    }
    *out = o;
done:
    asp_free(ctx, by);
    asp_free(ctx, dst);
    asp_free(ctx, dst_mat);
    asp_free(ctx, alt);
    asp_free(ctx, alt_mat);
    asp_free(ctx, start);
    asp_free(ctx, count);
    asp_free(ctx, group_mat);
    return rc;
}
