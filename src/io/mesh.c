/*
 * asp_mesh lifecycle and checks: allocation, area-weighted vertex normals
 * (welded by position so UV seams do not crease the shading), surface area
 * and validation before sampling (Schwarz 2004 section 3.1.6 assumes a normal
 * per vertex; this is where meshes without one get it).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/mesh.h"
#include "util/atomic_file.h"
#include "util/banned.h"

static void release_arrays(asp_mesh *m)
{
    const asp_context *ctx = &m->ctx;
    asp_free(ctx, m->positions);
    asp_free(ctx, m->normals);
    asp_free(ctx, m->uvs);
    asp_free(ctx, m->colors);
    asp_free(ctx, m->triangles);
    asp_free(ctx, m->material_ids);
    for (size_t i = 0; m->materials && i < m->material_count; i++) {
        const asp_material *mat = &m->materials[i];
        // a texture read from a file stops being protected from outputs (mesh_assimp.c, issue #31)
        if (mat->texture.pixels && mat->texture_path[0] && mat->texture_path[0] != '*')
            asp__atomic_unprotect(mat->texture_path);
        asp_image_release(&m->materials[i].texture);
    }
    asp_free(ctx, m->materials);
}

void asp_mesh_destroy(asp_mesh *mesh)
{
    if (!mesh)
        return;
    asp_context ctx = mesh->ctx;
    release_arrays(mesh);
    asp_free(&ctx, mesh);
}

int asp_mesh_create(size_t vertex_count, size_t triangle_count, unsigned attrs, const asp_context *ctx,
                    asp_mesh **out, asp_error *err)
{
    if (vertex_count >= UINT32_MAX || triangle_count >= UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "mesh of %zu vertices and %zu triangles exceeds 2^32-1", vertex_count,
                             triangle_count);
    asp_mesh *m = asp_calloc(ctx, 1, sizeof *m);
    if (!m)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a mesh");
    if (ctx)
        m->ctx = *ctx;
    m->vertex_count = vertex_count;
    m->triangle_count = triangle_count;
    /* +1 keeps every array non-NULL for empty meshes, so a NULL always means out of memory */
    m->positions = asp_calloc(ctx, 3 * vertex_count + 1, sizeof(float));
    m->normals = asp_calloc(ctx, 3 * vertex_count + 1, sizeof(float));
    m->triangles = asp_calloc(ctx, 3 * triangle_count + 1, sizeof(uint32_t));
    m->material_ids = asp_calloc(ctx, triangle_count + 1, sizeof(uint32_t));
    m->materials = asp_calloc(ctx, 1, sizeof(asp_material));
    if (attrs & ASP_MESH_UVS)
        m->uvs = asp_calloc(ctx, 2 * vertex_count + 1, sizeof(float));
    if (attrs & ASP_MESH_COLORS)
        m->colors = asp_calloc(ctx, 4 * vertex_count + 1, sizeof(uint8_t));
    if (!m->positions || !m->normals || !m->triangles || !m->material_ids || !m->materials ||
        ((attrs & ASP_MESH_UVS) && !m->uvs) || ((attrs & ASP_MESH_COLORS) && !m->colors)) {
        asp_mesh_destroy(m);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a mesh of %zu vertices and %zu triangles",
                             vertex_count, triangle_count);
    }
    m->material_count = 1;
    snprintf(m->materials[0].name, sizeof m->materials[0].name, "DefaultMaterial");
    for (int c = 0; c < 3; c++)
        m->materials[0].diffuse[c] = 0.6f;
    m->materials[0].diffuse[3] = 1.0f;
    *out = m;
    return 0;
}

/* Twice the triangle's area vector (cross product of two edges), in double. */
static void triangle_cross(const asp_mesh *m, size_t t, double out[3])
{
    const uint32_t *v = m->triangles + 3 * t;
    const float *a = m->positions + 3 * (size_t)v[0], *b = m->positions + 3 * (size_t)v[1],
                *c = m->positions + 3 * (size_t)v[2];
    double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    double e2[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

double asp_mesh_area(const asp_mesh *mesh)
{
    /* summed in double: a million float-sized terms would lose the small triangles */
    double area = 0.0;
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        double x[3];
        triangle_cross(mesh, t, x);
        area += 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    }
    return area;
}

/* qsort has no user pointer, so each entry carries its key (no global state, STYLE.md 7). */
struct weld_entry {
    float p[3];
    uint32_t v;
};

static int cmp_weld(const void *pa, const void *pb)
{
    const struct weld_entry *a = pa, *b = pb;
    for (int c = 0; c < 3; c++)
        if (a->p[c] != b->p[c])
            return a->p[c] < b->p[c] ? -1 : 1;
    return a->v < b->v ? -1 : (a->v > b->v);
}

int asp_mesh_compute_normals(asp_mesh *mesh, asp_error *err)
{
    const asp_context *ctx = &mesh->ctx;
    size_t nv = mesh->vertex_count;
    double *acc = asp_calloc(ctx, 3 * nv + 1, sizeof(double));
    struct weld_entry *order = asp_alloc(ctx, (nv + 1) * sizeof(struct weld_entry));
    uint32_t *group = asp_alloc(ctx, (nv + 1) * sizeof(uint32_t));
    if (!acc || !order || !group) {
        asp_free(ctx, acc);
        asp_free(ctx, order);
        asp_free(ctx, group);
        return asp_error_set(err, ASP_ENOMEM, "out of memory computing normals of %zu vertices", nv);
    }
    /* group[v] = first vertex (in sorted order) with v's exact position */
    for (size_t v = 0; v < nv; v++) {
        memcpy(order[v].p, mesh->positions + 3 * v, sizeof order[v].p);
        order[v].v = (uint32_t)v;
    }
    qsort(order, nv, sizeof *order, cmp_weld);
    for (size_t s = 0; s < nv; s++) {
        uint32_t v = order[s].v;
        if (s > 0 && order[s].p[0] == order[s - 1].p[0] && order[s].p[1] == order[s - 1].p[1] &&
            order[s].p[2] == order[s - 1].p[2])
            group[v] = group[order[s - 1].v];
        else
            group[v] = v;
    }
    /* the cross product's length is twice the area: summing it weights each face by its area */
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        double x[3];
        triangle_cross(mesh, t, x);
        for (int k = 0; k < 3; k++) {
            size_t g = group[mesh->triangles[3 * t + k]];
            for (int c = 0; c < 3; c++)
                acc[3 * g + c] += x[c];
        }
    }
    for (size_t v = 0; v < nv; v++) {
        const double *a = acc + 3 * (size_t)group[v];
        double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        float *n = mesh->normals + 3 * v;
        if (len > 0.0 && isfinite(len)) {
            for (int c = 0; c < 3; c++)
                n[c] = (float)(a[c] / len);
        } else {
            n[0] = 0.0f, n[1] = 0.0f, n[2] = 1.0f;
        }
    }
    asp_free(ctx, acc);
    asp_free(ctx, order);
    asp_free(ctx, group);
    return 0;
}

int asp_mesh_validate(const asp_mesh *mesh, const char *name, asp_error *err)
{
    if (!name)
        name = "mesh";
    if (mesh->triangle_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' has no triangles", name);
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        for (int k = 0; k < 3; k++)
            if (mesh->triangles[3 * t + k] >= mesh->vertex_count)
                return asp_error_set(err, ASP_EFORMAT, "mesh '%s': triangle %zu uses vertex %u of %zu", name, t,
                                     mesh->triangles[3 * t + k], mesh->vertex_count);
        if (mesh->material_ids[t] >= mesh->material_count)
            return asp_error_set(err, ASP_EFORMAT, "mesh '%s': triangle %zu uses material %u of %zu", name, t,
                                 mesh->material_ids[t], mesh->material_count);
    }
    static const char axis[] = "xyz";
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        for (int c = 0; c < 3; c++) {
            if (!isfinite(mesh->positions[3 * v + c]))
                return asp_error_set(err, ASP_EFORMAT, "mesh '%s': vertex %zu: coordinate %c is not finite", name,
                                     v, axis[c]);
            // issue #31: a 1e38 triangle sampled into radii of infinity; samplers and renderers square
            // coordinate differences in float, which stay finite within +-1e18 of the origin
            if (fabsf(mesh->positions[3 * v + c]) > ASP_MESH_MAX_COORD)
                return asp_error_set(err, ASP_EFORMAT, "mesh '%s': vertex %zu: coordinate %c is %g, beyond the "
                                     "+-%g that float arithmetic on it allows (around the centre %g)", name, v,
                                     axis[c], (double)mesh->positions[3 * v + c], ASP_MESH_MAX_COORD, mesh->origin[c]);
            if (!isfinite(mesh->normals[3 * v + c]))
                return asp_error_set(err, ASP_EFORMAT, "mesh '%s': vertex %zu: normal %c is not finite", name, v,
                                     axis[c]);
        }
        if (mesh->uvs && (!isfinite(mesh->uvs[2 * v]) || !isfinite(mesh->uvs[2 * v + 1])))
            return asp_error_set(err, ASP_EFORMAT, "mesh '%s': vertex %zu: texture coordinate is not finite", name,
                                 v);
    }
    for (int c = 0; c < 3; c++)
        if (!isfinite(mesh->origin[c]))
            return asp_error_set(err, ASP_EFORMAT, "mesh '%s': its origin's %c is not finite", name, axis[c]);
    double area = asp_mesh_area(mesh);
    if (!(area > 0.0) || !isfinite(area))
        return asp_error_set(err, ASP_EDEGENERATE, "mesh '%s' has zero surface area", name);
    return 0;
}
