/*
 * The one renderer table (STYLE.md 9b): render, view and eval pick a renderer
 * by name here instead of each keeping a list. Rows: opaque discs (Pajarola
 * et al. 2003 section 5), blended splats and squares of the point hierarchy
 * (seed 001 section 5, seed 004 3.2.6), the domain primitives of a .dps level
 * (journal section 4), textured triangle meshes (seed 004 2.2-2.3), and the hybrid of a
 * level's primitives and its points (issue 18, docs/hybrid.md).
 */
#include <stdio.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

static int need_points(const char *name, const asp_render_source *src, int hier_ok, asp_error *err)
{
    if (src->cloud || (hier_ok && src->hier))
        return 0;
    return asp_error_set(err, ASP_EUNSUPPORTED, "renderer '%s' draws points (a point file or an .amg input)", name);
}

static int make_disc(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                     const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    (void)ctx;
    int rc = need_points("disc", src, 0, err);
    if (rc)
        return rc;
    asp_disc_renderer_desc d = o ? o->disc : (asp_disc_renderer_desc){0};
    d.clip_planes = src->clip_planes;
    return asp_disc_renderer_create(gl, src->cloud, &d, out, err);
}

static int make_splat(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                      const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    int rc = need_points("splat", src, 1, err);
    if (rc)
        return rc;
    asp_splat_renderer_desc d = o ? o->splat : (asp_splat_renderer_desc){0};
    d.clip_planes = src->clip_planes;
    if (src->hier)
        return asp_splat_renderer_create_hier(gl, src->hier, &d, out, err);
    return asp_splat_renderer_create(gl, src->cloud, &d, ctx, out, err);
}

static int make_square(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                       const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    int rc = need_points("square", src, 1, err);
    if (rc)
        return rc;
    asp_square_renderer_desc d = o ? o->square : (asp_square_renderer_desc){0};
    if (src->hier)
        return asp_square_renderer_create_hier(gl, src->hier, &d, out, err);
    return asp_square_renderer_create(gl, src->cloud, &d, ctx, out, err);
}

static int make_prim(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                     const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    (void)ctx;
    if (!src->level)
        return asp_error_set(err, ASP_EUNSUPPORTED, "renderer 'prim' draws domain primitives (a .dps input)");
    asp_prim_renderer_desc d = {.options = o ? o->prim : (asp_prim_render_options){0}};
    // the primitives share the frame of the cloud they came from, so one camera fits both
    memcpy(d.origin, src->origin, sizeof d.origin);
    return asp_prim_renderer_create(gl, src->level, &d, out, err);
}

static int make_mesh(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                     const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    (void)ctx;
    if (!src->mesh)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "renderer 'mesh' draws triangle meshes (OBJ, PLY with faces, OFF, STL, glTF, 3DS)");
    asp_mesh_renderer_desc d = o ? o->mesh : (asp_mesh_renderer_desc){0};
    // the mesh shares the frame of its scene, so one camera fits it and the points sampled from it
    memcpy(d.origin, src->origin, sizeof d.origin);
    return asp_mesh_renderer_create(gl, src->mesh, &d, out, err);
}

/* issue 18 item 3: the level's primitives where they hold, its source points where they fail */
static int make_hybrid(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                       const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    if (!src->level || !src->cloud)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "renderer 'hybrid' draws domain primitives and their source points (a .dps input "
                             "with its point file)");
    asp_hybrid_desc d = o ? o->hybrid : (asp_hybrid_desc){0};
    const asp_prim_render_options *p = &d.prim;
    // callers that set only the primitives' options (eval, the viewer) get them for the hybrid too
    if (o && p->method == 0 && p->alpha_ref == 0 && p->transparency == 0 && p->depth_window == 0 && p->flags == 0 &&
        p->crease_angle == 0)
        d.prim = o->prim;
    memcpy(d.origin, src->origin, sizeof d.origin);
    return asp_hybrid_renderer_create(gl, src->level, src->cloud, &d, ctx, out, err);
}

static int make_cut(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                    const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    (void)ctx;
    if (!src->dps)
        return asp_error_set(err, ASP_EUNSUPPORTED, "renderer 'cut' draws the levels of a .dps together (a .dps input)");
    asp_cut_renderer_desc d = o ? o->cut : (asp_cut_renderer_desc){0};
    memcpy(d.origin, src->origin, sizeof d.origin);
    return asp_cut_renderer_create(gl, src->dps, &d, out, err);
}

/* compute_renderer.c: points drawn by compute shaders (issue 28) */
int asp__compute_renderer_make(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                               const asp_context *ctx, asp_renderer **out, asp_error *err);

static const asp_renderer_kind kinds[] = {
    {"disc", "points", ASP_RENDER_INPUT_POINTS, 0, make_disc},
    {"splat", "splats", ASP_RENDER_INPUT_POINTS, 1, make_splat},
    {"square", "splats", ASP_RENDER_INPUT_POINTS, 1, make_square},
    {"prim", "primitives", ASP_RENDER_INPUT_PRIMS, 0, make_prim},
    {"mesh", "triangles", ASP_RENDER_INPUT_MESH, 0, make_mesh},
    {"hybrid", "primitives and splats", ASP_RENDER_INPUT_PRIMS, 0, make_hybrid},
    {"cut", "primitives", ASP_RENDER_INPUT_PRIMS, 0, make_cut},
    {"compute", "points", ASP_RENDER_INPUT_POINTS, 0, asp__compute_renderer_make},
};
enum { N_KINDS = sizeof kinds / sizeof kinds[0] };

const asp_renderer_kind *asp_renderer_kind_at(size_t i)
{
    return i < N_KINDS ? &kinds[i] : NULL;
}

size_t asp_renderer_kind_count(void)
{
    return N_KINDS;
}

int asp_renderer_kind_find(const char *name, unsigned inputs, const asp_renderer_kind **out, asp_error *err)
{
    char names[128] = "";
    size_t len = 0;
    for (size_t i = 0; i < N_KINDS; i++) {
        if (inputs && !(kinds[i].inputs & inputs))
            continue;
        if (strcmp(kinds[i].name, name) == 0) {
            *out = &kinds[i];
            return 0;
        }
        if (len < sizeof names)
            len += (size_t)snprintf(names + len, sizeof names - len, "%s%s", len ? ", " : "", kinds[i].name);
    }
    return asp_error_set(err, ASP_EINVAL, "unknown renderer '%s' (expected %s)", name, names);
}
