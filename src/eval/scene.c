/*
 * The one scene loader (STYLE.md 9b) behind render, view and eval: a file
 * recognised by asp_file_recognise, loaded into what the renderer table draws,
 * with the frame of the source point set to fit the camera to (issue 12: one
 * --view, one picture for the points, the .amg and the .dps of a model).
 * It lives in eval, the lowest module above render, because it needs io, amg,
 * prim and hier as well as render's types; render itself knows no files.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "amgsplat/sample.h"
#include "amgsplat/scene.h"
#include "util/banned.h"

/* Copies err->msg so it can be wrapped into a new message in the same buffer. */
static int rewrap(asp_error *err, int rc, const char *fmt_prefix, const char *path)
{
    char msg[sizeof err->msg];
    snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
    return asp_error_set(err, rc, "%s '%s': %s", fmt_prefix, path, msg);
}

static int load_clip_planes(asp_scene *s, const asp_scene_desc *d, asp_error *err)
{
    if (!(d->crease_angle > 0))
        return 0;
    if (!(d->crease_angle < 90))
        return asp_error_set(err, ASP_EINVAL, "crease angle %g is outside (0, 90) degrees", (double)d->crease_angle);
    if (d->crease_if_normals && !s->cloud->normals)
        return 0; // a default: nothing to clip by (asp_crease_clip_planes would refuse)
    s->clip_planes = asp_alloc(&s->ctx, 8 * s->cloud->count * sizeof(float));
    if (!s->clip_planes)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the crease planes of %zu points", s->cloud->count);
    int rc = asp_crease_clip_planes(s->cloud, &(asp_crease_desc){.angle_deg = d->crease_angle}, &s->ctx,
                                    s->clip_planes, NULL, err);
    return rc ? rewrap(err, rc, "cannot clip", s->path) : 0;
}

/* Points: their own frame, drawn in their own local frame. */
static int load_points(asp_scene *s, const asp_scene_desc *d, asp_error *err)
{
    int rc = asp_cloud_load(s->path, &s->ctx, &s->cloud, err);
    if (!rc)
        rc = asp_cloud_frame(s->cloud, &s->frame, err);
    if (!rc)
        memcpy(s->origin, s->cloud->origin, sizeof s->origin);
    return rc ? rc : load_clip_planes(s, d, err);
}

int asp_scene_recolor(asp_scene *s, asp_scene_amg_color color, size_t level, asp_error *err)
{
    if (!s->amg)
        return asp_error_set(err, ASP_EINVAL, "cannot colour '%s': not an .amg decomposition", s->path);
    const asp_cloud *src = asp_amg_cloud(s->amg);
    size_t n = s->cloud->count;
    if ((unsigned)color > ASP_SCENE_AMG_STRICT)
        return asp_error_set(err, ASP_EINVAL, "unknown .amg colour mode %u (expected 0..3)", (unsigned)color);
    if (level >= asp_amg_level_count(s->amg))
        return asp_error_set(err, ASP_EINVAL, "'%s' has no level %zu (it has %zu)", s->path, level,
                             asp_amg_level_count(s->amg));
    if (color == ASP_SCENE_AMG_INPUT) {
        if (src->colors)
            memcpy(s->cloud->colors, src->colors, 4 * n);
        else
            memset(s->cloud->colors, 200, 4 * n); // the renderers' light grey, opaque
        if (!src->colors)
            for (size_t i = 0; i < n; i++)
                s->cloud->colors[4 * i + 3] = 255;
    } else {
        // a scratch buffer first, so the cloud is untouched on failure
        uint8_t *rgba = asp_alloc(&s->ctx, 4 * n);
        if (!rgba)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for the colours of %zu points", n);
        int rc = asp_amg_colorize(s->amg, (asp_amg_color_mode)(color - 1), level, &s->ctx, rgba, err);
        if (!rc)
            memcpy(s->cloud->colors, rgba, 4 * n);
        asp_free(&s->ctx, rgba);
        if (rc)
            return rc;
    }
    s->amg_color = color;
    s->amg_level = level;
    return 0;
}

/* .amg: a private copy of its points to colour, framed by the recorded frame of the source points. */
static int load_amg(asp_scene *s, const asp_scene_desc *d, asp_error *err)
{
    int rc = asp_amg_load(s->path, &s->ctx, &s->amg, err);
    if (!rc)
        rc = asp_cloud_clone(asp_amg_cloud(s->amg), &s->cloud, err);
    if (rc)
        return rc;
    memcpy(s->origin, s->cloud->origin, sizeof s->origin);
    s->frame = *asp_amg_frame(s->amg);
    if (!(s->frame.radius > 0) && (rc = asp_cloud_frame(s->cloud, &s->frame, err)) != 0)
        return rc;
    size_t level = asp_amg_level_count(s->amg) - 1;
    if (d->level && (rc = asp_amg_level_parse(s->amg, d->level, &level, err)) != 0)
        return rewrap(err, rc, "cannot draw", s->path);
    if (d->amg_color != ASP_SCENE_AMG_INPUT || !asp_amg_cloud(s->amg)->colors) {
        rc = asp_cloud_add_attrs(s->cloud, ASP_ATTR_COLORS, err);
        if (!rc)
            rc = asp_scene_recolor(s, d->amg_color, level, err);
        if (rc)
            return rc;
    }
    s->amg_color = d->amg_color;
    s->amg_level = level;
    return load_clip_planes(s, d, err);
}

/* The source file a .dps names (asp_dps_source_find). Loads its points (world frame kept in origin). */
/* given: a point file or .amg the caller names instead of the .dps's source (render --hybrid-points) */
static int load_dps_source_cloud(const asp_scene *s, const char *given, asp_cloud **out, asp_error *err)
{
    char found[4096];
    asp_file_type type;
    int rc = given ? asp_file_recognise(given, &type, err)
                   : asp_dps_source_find(s->dps, s->path, found, sizeof found, &type, err);
    if (rc)
        return rc;
    const char *src = given ? given : found;
    if (type.kind == ASP_FILE_AMG) {
        asp_amg *amg = NULL;
        rc = asp_amg_load(src, &s->ctx, &amg, err);
        if (!rc)
            rc = asp_cloud_clone(asp_amg_cloud(amg), out, err);
        asp_amg_destroy(amg);
        return rc;
    }
    if (type.kind == ASP_FILE_POINTS || strcmp(type.format, "ply") == 0)
        return asp_cloud_load(src, &s->ctx, out, err);
    return asp_error_set(err, ASP_EUNSUPPORTED, "source '%s' of '%s' is a %s, not points", src, s->path,
                         asp_file_kind_name(type.kind));
}

/* The frame of a .dps that records none: its source points', else the level's own bounds. */
static int frame_dps_fallback(asp_scene *s, asp_error *err)
{
    asp_cloud *cloud = NULL;
    if (load_dps_source_cloud(s, NULL, &cloud, NULL) == 0) {
        int rc = asp_cloud_frame(cloud, &s->frame, NULL);
        asp_cloud_destroy(cloud);
        if (!rc)
            return 0;
    }
    // the level's own bounds, in every build (prim.h: no GL), so no-GL and GL builds frame alike
    float c[3], r;
    int rc = asp_prim_level_bounding_sphere(&s->dps->levels[s->dps_level], NULL, c, &r, err);
    if (rc)
        return rewrap(err, rc, "cannot frame", s->path);
    for (int k = 0; k < 3; k++)
        s->frame.center[k] = c[k];
    s->frame.radius = r;
    return 0;
}

static int load_dps(asp_scene *s, const asp_scene_desc *d, asp_error *err)
{
    int rc = asp_dps_load(s->path, &s->ctx, &s->dps, err);
    if (rc)
        return rc;
    if (s->dps->level_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot draw '%s': it holds no level", s->path);
    if (d->level && asp_dps_level_parse(s->dps, d->level, &s->dps_level, err)) {
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
        return asp_error_set(err, ASP_EINVAL, "'%s' has %s", s->path, msg);
    }
    s->frame = s->dps->frame;
    if (!(s->frame.radius > 0) && (rc = frame_dps_fallback(s, err)) != 0)
        return rc;
    // the primitives are stored in world coordinates; centring their frame keeps float precision
    memcpy(s->origin, s->frame.center, sizeof s->origin);
    return 0;
}

int asp_scene_mesh_frame(const asp_mesh *mesh, asp_frame *out, asp_error *err)
{
    ASP_ASSERT(mesh && out);
    // the vertices framed as points of radius 0 (asp_positions_frame is asp_cloud_frame's core)
    return asp_positions_frame(mesh->positions, mesh->vertex_count, mesh->origin, 0.0, out, err);
}

void asp_scene_mesh_describe(const asp_mesh *m, asp_render_material *materials, asp_render_mesh *r)
{
    ASP_ASSERT(m && r && (materials || m->material_count == 0));
    for (size_t i = 0; i < m->material_count; i++) {
        const asp_material *mt = &m->materials[i];
        for (int c = 0; c < 4; c++) {
            // a material without a colour of its own is drawn like points without colours: light grey
            float v = mt->has_color ? mt->diffuse[c] : (c < 3 ? 200.0f / 255.0f : 1.0f);
            materials[i].color[c] = v < 0 ? 0 : v > 1 ? 1 : v;
        }
        materials[i].texture = mt->texture.pixels ? &mt->texture : NULL;
    }
    memset(r, 0, sizeof *r);
    r->vertex_count = m->vertex_count;
    r->triangle_count = m->triangle_count;
    memcpy(r->origin, m->origin, sizeof r->origin);
    r->positions = m->positions;
    r->normals = m->normals;
    r->uvs = m->uvs;
    r->colors = m->colors;
    r->triangles = m->triangles;
    r->material_ids = m->material_ids;
    r->material_count = m->material_count;
    r->materials = materials;
}

/* The mesh's arrays as render's plain description; the sampler's colour rule decides the material colours. */
static int describe_mesh(asp_scene *s, asp_error *err)
{
    const asp_mesh *m = s->mesh;
    s->materials = asp_calloc(&s->ctx, m->material_count, sizeof *s->materials);
    if (!s->materials)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu materials", m->material_count);
    asp_scene_mesh_describe(m, s->materials, &s->render_mesh);
    return 0;
}

/* Meshes: drawn in their own frame; a PLY's vertices are points as well. */
static int load_mesh(asp_scene *s, const asp_scene_desc *d, asp_error *err)
{
    asp_mesh_load_desc md = {.texture_override = d->texture, .allow_missing_textures = 1};
    int rc = asp_mesh_load(s->path, &md, &s->ctx, &s->mesh, err);
    if (!rc)
        rc = asp_scene_mesh_frame(s->mesh, &s->frame, err);
    if (!rc)
        rc = describe_mesh(s, err);
    if (rc)
        return rc;
    memcpy(s->origin, s->mesh->origin, sizeof s->origin);
    if (strcmp(s->type.format, "ply") != 0)
        return 0;
    rc = asp_cloud_load(s->path, &s->ctx, &s->cloud, err);
    if (!rc)
        memcpy(s->origin, s->cloud->origin, sizeof s->origin);
    return rc ? rc : load_clip_planes(s, d, err);
}

static int load_hier(asp_scene *s, asp_error *err)
{
    int rc = asp_hier_load(s->path, &s->ctx, &s->hier, err);
    if (rc)
        return rc;
    s->frame = *asp_hier_frame(s->hier);
    asp_hier_origin(s->hier, s->origin);
    if (!(s->frame.radius > 0))
        return asp_error_set(err, ASP_EDEGENERATE, "cannot frame '%s': its hierarchy has no extent", s->path);
    return 0;
}

int asp_scene_load(const char *path, const asp_scene_desc *desc, const asp_context *ctx, asp_scene *out,
                   asp_error *err)
{
    static const asp_scene_desc zero_desc;
    const asp_scene_desc *d = desc ? desc : &zero_desc;
    asp_scene s;
    memset(&s, 0, sizeof s);
    if (ctx)
        s.ctx = *ctx;
    if (strlen(path) >= sizeof s.path)
        return asp_error_set(err, ASP_EINVAL, "cannot open '%.64s...': path longer than %zu bytes", path,
                             sizeof s.path - 1);
    snprintf(s.path, sizeof s.path, "%s", path);
    int rc = asp_file_recognise(path, &s.type, err);
    if (rc)
        return rc;
    switch (s.type.kind) {
    case ASP_FILE_POINTS: rc = load_points(&s, d, err); break;
    case ASP_FILE_AMG: rc = load_amg(&s, d, err); break;
    case ASP_FILE_DPS: rc = load_dps(&s, d, err); break;
    case ASP_FILE_HIER: rc = load_hier(&s, err); break;
    case ASP_FILE_MESH: rc = load_mesh(&s, d, err); break;
    default:
        rc = asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw '%s': %s %s, not points, a mesh, .amg, .dps or .hier", path,
                           s.type.kind == ASP_FILE_IMAGE ? "an image" : "a file of kind",
                           s.type.kind == ASP_FILE_IMAGE ? s.type.format : asp_file_kind_name(s.type.kind));
        break;
    }
    if (rc) {
        asp_scene_release(&s);
        return rc;
    }
    *out = s;
    return 0;
}

int asp_scene_load_source(asp_scene *s, asp_error *err)
{
    return asp_scene_load_source_from(s, NULL, err);
}

int asp_scene_load_source_from(asp_scene *s, const char *path, asp_error *err)
{
    if (path && !s->dps)
        return asp_error_set(err, ASP_EINVAL, "'%s' is not a .dps file: points '%s' have no primitives to join",
                             s->path, path);
    if (!s->dps && !s->mesh)
        return asp_error_set(err, ASP_EINVAL, "'%s' is not a .dps file or a mesh: its points are drawn already",
                             s->path);
    if (s->cloud)
        return 0;
    asp_cloud *cloud = NULL;
    int rc;
    if (s->mesh) {
        // area samples, as `amgsplat sample --method area`: the points the mesh is compared with (issue 14)
        asp_sample_desc sd = {.method = ASP_SAMPLE_AREA, .points = ASP_SCENE_MESH_POINTS};
        rc = asp_sample_mesh(s->mesh, &sd, &s->ctx, &cloud, NULL, err);
    } else {
        rc = load_dps_source_cloud(s, path, &cloud, err);
    }
    if (rc)
        return rc;
    // into the primitives' frame: world = origin + position stays true
    for (size_t i = 0; i < cloud->count; i++)
        for (int k = 0; k < 3; k++)
            cloud->positions[3 * i + k] = (float)(cloud->positions[3 * i + k] + (cloud->origin[k] - s->origin[k]));
    memcpy(cloud->origin, s->origin, sizeof cloud->origin);
    s->cloud = cloud;
    return 0;
}

const asp_dps_level *asp_scene_dps_level(const asp_scene *s)
{
    return s->dps ? &s->dps->levels[s->dps_level] : NULL;
}

void asp_scene_render_source(const asp_scene *s, asp_render_source *out)
{
    memset(out, 0, sizeof *out);
    out->cloud = s->cloud;
    out->hier = s->hier;
    out->clip_planes = s->clip_planes;
    out->level = asp_scene_dps_level(s);
    out->dps = s->dps;
    out->mesh = s->mesh ? &s->render_mesh : NULL;
    memcpy(out->origin, s->origin, sizeof out->origin);
}

unsigned asp_scene_inputs(const asp_scene *s)
{
    return (s->cloud || s->hier ? (unsigned)ASP_RENDER_INPUT_POINTS : 0u) |
           (s->dps ? (unsigned)ASP_RENDER_INPUT_PRIMS : 0u) | (s->mesh ? (unsigned)ASP_RENDER_INPUT_MESH : 0u);
}

void asp_scene_release(asp_scene *s)
{
    asp_free(&s->ctx, s->clip_planes);
    asp_cloud_destroy(s->cloud);
    asp_amg_destroy(s->amg);
    asp_dps_destroy(s->dps);
    asp_hier_destroy(s->hier);
    asp_free(&s->ctx, s->materials);
    asp_mesh_destroy(s->mesh);
    memset(s, 0, sizeof *s);
}
