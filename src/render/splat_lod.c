/*
 * The point hierarchy on the GPU for the splat and square renderers: all
 * splats uploaded once, the view-dependent cut of every frame (seed 001
 * section 5.1 step 1; seed 004 3.2.1-3.2.5) uploaded as splat ids that an
 * instanced draw reads, and the LOD and statistics entries of their function
 * tables (the public calls dispatch to them, renderer.c).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/splat_internal.h"
#include "util/banned.h"

/*
 * Seed 001 Fig. 14 tilts the corner normals by the full cone semi-angle; a
 * node straddling a sharp crease has a cone of 90 degrees or more, which would
 * turn corner normals edge-on. 60 degrees keeps the interpolated shade
 * plausible there.
 */
static const float max_cone = 1.04719755f;

int asp__lod_check_option(const char *renderer, const char *name, float v, asp_error *err)
{
    if (!isfinite(v) || v < 0)
        return asp_error_set(err, ASP_EINVAL, "%s renderer option %s = %g is not a finite number >= 0", renderer,
                             name, (double)v);
    return 0;
}

/* Builds (cloud != NULL, owned) or borrows (hier) the hierarchy and takes the shared options. */
static int lod_prepare(asp__lod *lod, const asp_cloud *cloud, const asp_hier *hier, const asp__lod_desc *desc,
                       asp_error *err)
{
    memset(lod, 0, sizeof *lod);
    if (cloud) {
        int rc = asp_hier_build(cloud, desc->hier, desc->ctx, &lod->owned, err);
        if (rc)
            return rc;
        hier = lod->owned;
    }
    lod->hier = hier;
    lod->nodes = asp_hier_node_count(hier);
    lod->points = asp_hier_point_count(hier);
    // instance counts are GLsizei; the splat buffer is indexed by 4 * id in uint
    if (lod->nodes + lod->points > (size_t)INT32_MAX / 4) {
        asp__lod_release(NULL, lod);
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw a hierarchy of %zu nodes and %zu points (at most %d splats)",
                             lod->nodes, lod->points, INT32_MAX / 4);
    }
    // all points at one position and no radii: every ellipse is empty, nothing could be seen
    const asp_hier_splat *root = asp_hier_splats(hier);
    if (!(root->a > 0)) {
        size_t n = lod->points;
        asp__lod_release(NULL, lod);
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot render splats: all %zu points are at the same position and have no radius", n);
    }
    lod->has_colors = (asp_hier_flags(hier) & ASP_HIER_HAS_COLORS) != 0;
    const uint8_t *dc = desc->default_color;
    int given = dc[0] || dc[1] || dc[2] || dc[3];
    for (int c = 0; c < 4; c++)
        lod->default_color[c] = given ? dc[c] / 255.0f : (c < 3 ? 200.0f / 255.0f : 1.0f);
    lod->tolerance = desc->tolerance;
    lod->cull_backfaces = (desc->flags & ASP_SPLAT_CULL_BACKFACES) != 0;
    lod->count = lod->points;
    return 0;
}

int asp__lod_renderer_create(asp_gl_context *gl, size_t size, const asp__renderer_vtable *vt, const asp_cloud *cloud,
                             const asp_hier *hier, const asp__lod_desc *desc, asp__lod_renderer **out, asp_error *err)
{
    asp__lod_renderer *r = asp_calloc(&gl->actx, 1, size);
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %s renderer", vt->name);
    int rc = lod_prepare(&r->lod, cloud, hier, desc, err);
    if (rc) {
        asp_free(&gl->actx, r);
        return rc;
    }
    r->base.vt = vt;
    r->base.gl = gl;
    r->base.count = r->lod.count;
    *out = r;
    return 0;
}

int asp__lod_renderer_finish(asp__lod_renderer *r, asp_renderer **out, asp_error *err)
{
    char what[64];
    snprintf(what, sizeof what, "create the %s renderer", r->base.vt->name);
    int rc = asp__gl_check(r->base.gl, what, err);
    if (rc) {
        r->base.vt->destroy(&r->base);
        return rc;
    }
    *out = &r->base;
    return 0;
}

void asp__lod_renderer_free(asp__lod_renderer *r)
{
    const asp_context *actx = &r->base.gl->actx; // in gl, which outlives r
    asp__lod_release(actx, &r->lod);
    asp_free(actx, r);
}

int asp__lod_upload(asp_gl_context *gl, asp__lod *lod, const char *what, asp_error *err)
{
    const asp_hier *h = lod->hier;
    lod->capacity = asp_hier_select_bound(h);
    lod->cut = asp_alloc(&gl->actx, lod->capacity * sizeof *lod->cut);
    float *cones = asp_alloc(&gl->actx, lod->nodes * sizeof *cones);
    if (!lod->cut || !cones) {
        asp_free(&gl->actx, cones);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the %s renderer's cut of %zu points", what,
                             lod->capacity);
    }
    // PCA normals have no sign, so their cones are pi: no tilt for them
    int oriented = !(asp_hier_flags(h) & ASP_HIER_UNORIENTED);
    const asp_hier_node *nodes = asp_hier_nodes(h);
    for (size_t i = 0; i < lod->nodes; i++)
        cones[i] = oriented ? fminf(nodes[i].cone_angle, max_cone) : 0.0f;

    asp__gl_clear_errors(gl);
    glCreateBuffers(1, &lod->splats.id);
    glNamedBufferStorage(lod->splats.id, (GLsizeiptr)((lod->nodes + lod->points) * sizeof(asp_hier_splat)),
                         asp_hier_splats(h), 0);
    glCreateBuffers(1, &lod->cones.id);
    glNamedBufferStorage(lod->cones.id, (GLsizeiptr)(lod->nodes * sizeof *cones), cones, 0);
    glCreateBuffers(1, &lod->ids.id);
    glNamedBufferStorage(lod->ids.id, (GLsizeiptr)(lod->capacity * sizeof *lod->cut), NULL,
                         GL_DYNAMIC_STORAGE_BIT);
    asp_free(&gl->actx, cones);
    // out of GPU memory shows up here as GL_OUT_OF_MEMORY from glNamedBufferStorage
    char msg[96];
    snprintf(msg, sizeof msg, "upload %zu splats", lod->nodes + lod->points);
    return asp__gl_check(gl, msg, err);
}

/*
 * asp_hier_select emits a visible node whose children were all culled, so
 * that counts never grow with tau. Such a node's ellipse covers nothing its
 * culled subtree would have shown, but drawn it blurs a wide region at the
 * frustum edges (blended with the fine splats there) or sticks out of a
 * silhouette. A node is such a fallback when it was too large for tau and
 * above the depth limit: the test of asp_hier_select (src/hier/traversal.c,
 * projected()) with the same double arithmetic. Returns the new count.
 */
static size_t drop_fallback_nodes(const asp__lod *lod, const asp__frame *f, size_t count)
{
    const asp_hier_splat *splats = asp_hier_splats(lod->hier);
    const asp_hier_node *nodes = asp_hier_nodes(lod->hier);
    double zrow[4];
    for (int c = 0; c < 4; c++)
        zrow[c] = f->view[4 * c + 2];
    double sx = fabs((double)f->proj[0]) * f->width * 0.5, sy = fabs((double)f->proj[5]) * f->height * 0.5;
    double scale = sx > sy ? sx : sy;
    int ortho = f->proj[15] == 1.0f && f->proj[11] == 0.0f;
    size_t kept = 0;
    for (size_t i = 0; i < count; i++) {
        asp_index id = lod->cut[i];
        if (id < lod->nodes && !(lod->depth_limit && nodes[id].depth + 1 >= lod->depth_limit)) {
            const float *c = splats[id].center;
            double a = splats[id].a, size;
            if (ortho) {
                size = 2.0 * a * scale;
            } else {
                double near = -(zrow[0] * c[0] + zrow[1] * c[1] + zrow[2] * c[2] + zrow[3]) - a;
                size = near > 0 ? 2.0 * a * scale / near : INFINITY;
            }
            if (!(size < lod->tolerance))
                continue;
        }
        lod->cut[kept++] = id;
    }
    return kept;
}

int asp__lod_select(asp__lod_renderer *r, const asp__frame *f, asp_error *err)
{
    asp__lod *lod = &r->lod;
    asp_hier_view view;
    memset(&view, 0, sizeof view);
    memcpy(view.view, f->view, sizeof view.view);
    memcpy(view.proj, f->proj, sizeof view.proj);
    memcpy(view.eye, f->eye, sizeof view.eye);
    view.width = f->width;
    view.height = f->height;
    view.tau = lod->tolerance;
    view.depth_limit = lod->depth_limit;
    view.cull_backfaces = lod->cull_backfaces;
    double t0 = asp_time_now();
    size_t count = 0;
    // a count cut leaves fallback nodes out itself (asp_hier_select_count)
    int rc = lod->budget ? asp_hier_select_count(lod->hier, &view, lod->budget, lod->cut, lod->capacity, &count, err)
                         : asp_hier_select(lod->hier, &view, lod->cut, lod->capacity, &count, err);
    if (rc)
        return rc;
    // the bound is the point count and a cut never exceeds it; guard anyway
    if (count > lod->capacity)
        count = lod->capacity;
    if (!lod->budget)
        count = drop_fallback_nodes(lod, f, count);
    if (count)
        glNamedBufferSubData(lod->ids.id, 0, (GLsizeiptr)(count * sizeof *lod->cut), lod->cut);
    lod->select_seconds = asp_time_now() - t0;
    lod->count = count;
    r->base.count = count;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_SPLATS, lod->splats.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_IDS, lod->ids.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_CONES, lod->cones.id);
    return 0;
}

void asp__lod_frame_uniforms(GLuint program, const GLint *loc, const asp__frame *f)
{
    glProgramUniformMatrix4fv(program, loc[ASP__LOD_U_VIEW], 1, GL_FALSE, f->view);
    glProgramUniformMatrix4fv(program, loc[ASP__LOD_U_PROJ], 1, GL_FALSE, f->proj);
    glProgramUniform3fv(program, loc[ASP__LOD_U_EYE], 1, f->eye);
    glProgramUniform3fv(program, loc[ASP__LOD_U_LIGHT], 1, f->light_eye);
}

void asp__lod_release(const asp_context *actx, asp__lod *lod)
{
    GLuint bufs[3] = {lod->splats.id, lod->cones.id, lod->ids.id};
    for (int i = 0; i < 3; i++)
        if (bufs[i])
            glDeleteBuffers(1, &bufs[i]);
    lod->splats.id = lod->cones.id = lod->ids.id = 0;
    asp_free(actx, lod->cut);
    lod->cut = NULL;
    asp_hier_destroy(lod->owned);
    lod->owned = NULL;
    lod->hier = NULL;
}

/* The table entries of the hierarchy renderers (splat, square): r starts with asp__lod_renderer. */

int asp__lod_set_lod(asp_renderer *r, float tolerance, uint32_t depth_limit, asp_error *err)
{
    (void)err; // asp_renderer_set_lod checked the tolerance; any depth limit is valid
    asp__lod *lod = &((asp__lod_renderer *)r)->lod;
    lod->tolerance = tolerance;
    lod->depth_limit = depth_limit;
    return 0;
}

int asp__lod_set_budget(asp_renderer *r, size_t splats, asp_error *err)
{
    (void)err;
    ((asp__lod_renderer *)r)->lod.budget = splats;
    return 0;
}

void asp__lod_stats(const asp_renderer *r, asp_renderer_stats *out)
{
    const asp__lod *lod = &((const asp__lod_renderer *)r)->lod;
    out->count = lod->count;
    out->points = lod->points;
    out->nodes = lod->nodes;
    out->tolerance = lod->tolerance;
    out->depth_limit = lod->depth_limit;
    out->budget = lod->budget;
    out->select_seconds = lod->select_seconds;
}
