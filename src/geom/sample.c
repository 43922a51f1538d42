/*
 * Mesh-to-point sampling front end: option defaults, validation, timing, and
 * the per-point surface attributes every method shares (interpolated normals
 * and texture/vertex/material colour, Schwarz 2004 sections 3.1.6-3.1.7).
 */
#include <math.h>
#include <string.h>

#include "amgsplat/sample.h"
#include "geom/sample_internal.h"
#include "util/banned.h"

static const char *const method_names[] = {"area", "vertices", "voxel"};

const char *asp_sample_method_name(asp_sample_method method)
{
    return (unsigned)method < 3 ? method_names[method] : "unknown";
}

int asp_sample_method_parse(const char *name, asp_sample_method *out, asp_error *err)
{
    for (unsigned i = 0; i < 3; i++)
        if (strcmp(name, method_names[i]) == 0) {
            *out = (asp_sample_method)i;
            return 0;
        }
    return asp_error_set(err, ASP_EINVAL, "unknown sampling method '%s'; expected area, vertices or voxel", name);
}

int asp__mesh_has_color(const asp_mesh *m)
{
    if (m->colors)
        return 1;
    for (size_t i = 0; i < m->material_count; i++)
        if ((m->uvs && m->materials[i].texture.pixels) || m->materials[i].has_color)
            return 1;
    return 0;
}

void asp__surface_point(const asp_mesh *m, size_t t, const double w[3], double pos[3], double nrm[3], double uv[2],
                        float rgba[4])
{
    const uint32_t *v = m->triangles + 3 * t;
    if (pos)
        for (int c = 0; c < 3; c++)
            pos[c] = w[0] * m->positions[3 * (size_t)v[0] + c] + w[1] * m->positions[3 * (size_t)v[1] + c] +
                     w[2] * m->positions[3 * (size_t)v[2] + c];
    if (nrm) {
        double len2 = 0.0;
        for (int c = 0; c < 3; c++) {
            nrm[c] = w[0] * m->normals[3 * (size_t)v[0] + c] + w[1] * m->normals[3 * (size_t)v[1] + c] +
                     w[2] * m->normals[3 * (size_t)v[2] + c];
            len2 += nrm[c] * nrm[c];
        }
        if (!(len2 > 1e-12)) {
            /* opposite vertex normals (a crease folded back) cancel: the face normal is the honest answer */
            const float *a = m->positions + 3 * (size_t)v[0], *b = m->positions + 3 * (size_t)v[1],
                        *p = m->positions + 3 * (size_t)v[2];
            double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
            double e2[3] = {(double)p[0] - a[0], (double)p[1] - a[1], (double)p[2] - a[2]};
            nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
        }
    }
    double tuv[2] = {0.0, 0.0};
    if (m->uvs)
        for (int c = 0; c < 2; c++)
            tuv[c] = w[0] * m->uvs[2 * (size_t)v[0] + c] + w[1] * m->uvs[2 * (size_t)v[1] + c] +
                     w[2] * m->uvs[2 * (size_t)v[2] + c];
    if (uv)
        uv[0] = tuv[0], uv[1] = tuv[1];
    if (!rgba)
        return;
    const asp_material *mat = &m->materials[m->material_ids[t]];
    if (m->uvs && mat->texture.pixels) {
        /* the texture replaces the diffuse colour: OBJ exporters write Kd 0.8 next to map_Kd and mean the image */
        asp_image_sample_bilinear(&mat->texture, (float)tuv[0], (float)tuv[1], rgba);
    } else if (m->colors) {
        for (int c = 0; c < 4; c++)
            rgba[c] = (float)(w[0] * m->colors[4 * (size_t)v[0] + c] + w[1] * m->colors[4 * (size_t)v[1] + c] +
                              w[2] * m->colors[4 * (size_t)v[2] + c]);
    } else {
        for (int c = 0; c < 4; c++)
            rgba[c] = 255.0f * fminf(1.0f, fmaxf(0.0f, mat->diffuse[c]));
    }
}

int asp__sample_cloud_create(const asp_mesh *m, const asp_sample_desc *d, size_t count, const asp_context *ctx,
                             asp_cloud **out, asp_error *err)
{
    unsigned attrs = ASP_ATTR_NORMALS | ASP_ATTR_RADII;
    if (asp__mesh_has_color(m))
        attrs |= ASP_ATTR_COLORS;
    if (d->with_uvs && m->uvs)
        attrs |= ASP_ATTR_UVS;
    if (d->with_labels)
        attrs |= ASP_ATTR_LABELS;
    int rc = asp_cloud_create(count, attrs, ctx, out, err);
    if (rc == 0)
        memcpy((*out)->origin, m->origin, sizeof m->origin);
    return rc;
}

static uint8_t to_u8(float x)
{
    return x <= 0.0f ? 0 : x >= 255.0f ? 255 : (uint8_t)lrintf(x);
}

void asp__sample_store(asp_cloud *c, size_t i, const double pos[3], const double nrm[3], const double uv[2],
                       const float rgba[4], uint32_t label)
{
    double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    for (int k = 0; k < 3; k++) {
        c->positions[3 * i + k] = (float)pos[k];
        c->normals[3 * i + k] = len > 0.0 ? (float)(nrm[k] / len) : (k == 2 ? 1.0f : 0.0f);
    }
    if (c->colors)
        for (int k = 0; k < 4; k++)
            c->colors[4 * i + k] = to_u8(rgba[k]);
    if (c->uvs)
        c->uvs[2 * i] = (float)uv[0], c->uvs[2 * i + 1] = (float)uv[1];
    if (c->labels)
        c->labels[i] = label;
}

int asp_sample_mesh(const asp_mesh *mesh, const asp_sample_desc *desc, const asp_context *ctx, asp_cloud **out,
                    asp_sample_stats *stats, asp_error *err)
{
    asp_sample_desc d = desc ? *desc : (asp_sample_desc){0};
    if (d.points == 0)
        d.points = 100000;
    if (d.grid == 0)
        d.grid = 256;
    if (d.radius_scale == 0.0f)
        d.radius_scale = 1.0f;
    if (d.points >= UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "cannot make %zu points; at most 4294967294", d.points);
    if (d.grid > (1u << 20))
        return asp_error_set(err, ASP_EINVAL, "voxel grid %u is outside 1..1048576", d.grid);
    if (!(d.radius_scale > 0.0f) || !isfinite(d.radius_scale))
        return asp_error_set(err, ASP_EINVAL, "radius scale %g must be positive", (double)d.radius_scale);
    int rc = asp_mesh_validate(mesh, "mesh", err);
    if (rc)
        return rc;
    asp_sample_stats st = {0};
    st.area = asp_mesh_area(mesh);
    asp_cloud *c = NULL;
    switch (d.method) {
    case ASP_SAMPLE_AREA: rc = asp__sample_area(mesh, &d, ctx, &c, &st, err); break;
    case ASP_SAMPLE_VERTICES: rc = asp__sample_vertices(mesh, &d, ctx, &c, &st, err); break;
    case ASP_SAMPLE_VOXEL: rc = asp__sample_voxel(mesh, &d, ctx, &c, &st, err); break;
    default: return asp_error_set(err, ASP_EINVAL, "unknown sampling method %d", (int)d.method);
    }
    if (rc)
        return rc;
    double sum = 0.0;
    for (size_t i = 0; i < c->count; i++)
        sum += c->radii[i];
    st.points = c->count;
    st.mean_radius = c->count ? sum / (double)c->count : 0.0;
    if (stats)
        *stats = st;
    *out = c;
    return 0;
}
