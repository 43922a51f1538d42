/*
 * The scene renderer (issue 18 item 4): many instances of several source
 * renderers in one frame. Instances outside the view frustum are skipped
 * (seed 004 3.2.1's view-frustum culling, per instance sphere); the rest are
 * drawn by the source's instanced draw when it has one, else one by one with
 * the model folded into the view, far to near (painter's order for renderers
 * whose resolve paints without a depth test), all into one depth buffer.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/scene_renderer.h"
#include "render/internal.h"
#include "util/banned.h"

typedef struct group {
    asp_renderer *r;
    float *models; /* 16 per instance */
    size_t count;
    float center[3], radius;
    int one_by_one;
} group;

typedef struct instance_ref {
    float key;     /* squared distance from the eye: larger first */
    uint32_t group;
    uint32_t index;
} instance_ref;

typedef struct scene_renderer {
    asp_renderer base;
    group *groups;
    size_t group_count, total;
    instance_ref *refs; /* total */
    float *batch;       /* 16 * the largest group: the visible models of one instanced draw */
    size_t drawn;
} scene_renderer;

static const asp__renderer_vtable scene_vtable;

/* The largest axis scale of affine m: a sphere of radius r moved by m fits in radius r times it. */
static float max_axis(const float m[16])
{
    float best = 0;
    for (int c = 0; c < 3; c++) {
        float l = sqrtf(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]);
        best = l > best ? l : best;
    }
    return best;
}

/* 1 when instance i of g may show: its moved sphere meets every frustum plane's inner side. */
static int visible(const group *g, size_t i, const float planes[6][4], const float eye[3], float *key)
{
    const float *m = g->models + 16 * i;
    float w[3];
    for (int r = 0; r < 3; r++)
        w[r] = m[r] * g->center[0] + m[4 + r] * g->center[1] + m[8 + r] * g->center[2] + m[12 + r];
    float d2 = 0;
    for (int r = 0; r < 3; r++)
        d2 += (w[r] - eye[r]) * (w[r] - eye[r]);
    *key = d2;
    if (!(g->radius > 0))
        return 1;
    float rad = g->radius * max_axis(m);
    for (int p = 0; p < 6; p++)
        if (planes[p][0] * w[0] + planes[p][1] * w[1] + planes[p][2] * w[2] + planes[p][3] < -rad)
            return 0;
    return 1;
}

static int far_first(const void *a, const void *b)
{
    const instance_ref *x = a, *y = b;
    if (x->key != y->key)
        return x->key > y->key ? -1 : 1;
    // ties in a fixed order, so a frame never depends on qsort's
    return x->group != y->group ? (x->group < y->group ? -1 : 1) : (x->index < y->index ? -1 : x->index > y->index);
}

static int draw_folded(asp_renderer *r, const asp__frame *f, const float model[16], asp_error *err)
{
    asp__frame local;
    asp__frame_fold(f, model, &local);
    return r->vt->draw(r, &local, err);
}

/*
 * Whether g's renderer gets its instances in one instanced draw: its table says so (draw_instances,
 * and instanced for its current options, e.g. domain primitives only with the normalized method)
 * and the group does not ask for the reference path.
 */
static int instanced(const group *g)
{
    return !g->one_by_one && asp__renderer_instanced(g->r);
}

static int scene_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    scene_renderer *s = (scene_renderer *)base;
    float planes[6][4];
    asp_camera_frustum_planes(f->view, f->proj, planes);
    size_t nref = 0, count = 0, drawn = 0;
    for (size_t gi = 0; gi < s->group_count; gi++) {
        group *g = &s->groups[gi];
        size_t nb = 0;
        int batch = instanced(g);
        for (size_t i = 0; i < g->count; i++) {
            float key;
            if (!visible(g, i, planes, f->eye, &key))
                continue;
            if (batch)
                memcpy(s->batch + 16 * nb++, g->models + 16 * i, 16 * sizeof(float));
            else
                s->refs[nref++] = (instance_ref){key, (uint32_t)gi, (uint32_t)i};
        }
        if (nb) {
            // instanced renderers share one accumulation and the depth test: order does not matter
            int rc = g->r->vt->draw_instances(g->r, f, s->batch, nb, err);
            if (rc)
                return rc;
            count += g->r->count;
            drawn += nb;
        }
    }
    qsort(s->refs, nref, sizeof *s->refs, far_first);
    for (size_t k = 0; k < nref; k++) {
        group *g = &s->groups[s->refs[k].group];
        int rc = draw_folded(g->r, f, g->models + 16 * (size_t)s->refs[k].index, err);
        if (rc)
            return rc;
        count += g->r->count;
    }
    s->drawn = drawn + nref;
    base->count = count;
    return 0;
}

static int scene_set_lod(asp_renderer *base, float tolerance, uint32_t depth_limit, asp_error *err)
{
    scene_renderer *s = (scene_renderer *)base;
    int any = 0;
    for (size_t gi = 0; gi < s->group_count; gi++) {
        asp_error e = {0, ""};
        int rc = asp_renderer_set_lod(s->groups[gi].r, tolerance, depth_limit, &e);
        if (rc == 0)
            any = 1;
        else if (rc != ASP_EUNSUPPORTED)
            return asp_error_set(err, rc, "%s", e.msg);
    }
    return any ? 0 : asp_error_set(err, ASP_EUNSUPPORTED, "no renderer of the scene has a level of detail to set");
}

static void scene_stats(const asp_renderer *base, asp_renderer_stats *out)
{
    const scene_renderer *s = (const scene_renderer *)base;
    out->count = base->count;
    out->points = 0;
    for (size_t gi = 0; gi < s->group_count; gi++) {
        asp_renderer_stats st;
        asp_renderer_stats_get(s->groups[gi].r, &st);
        out->points += st.points * s->groups[gi].count;
        out->nodes += st.nodes * s->groups[gi].count;
        out->select_seconds += st.select_seconds;
        if (st.tolerance > out->tolerance)
            out->tolerance = st.tolerance;
        if (st.depth_limit > out->depth_limit)
            out->depth_limit = st.depth_limit;
    }
}

static void scene_destroy(asp_renderer *base)
{
    scene_renderer *s = (scene_renderer *)base;
    asp_context actx = base->gl->actx;
    for (size_t gi = 0; gi < s->group_count; gi++) {
        asp_renderer_destroy(s->groups[gi].r);
        asp_free(&actx, s->groups[gi].models);
    }
    asp_free(&actx, s->groups);
    asp_free(&actx, s->refs);
    asp_free(&actx, s->batch);
    asp_free(&actx, s);
}

static const asp__renderer_vtable scene_vtable = {.name = "scene", .draw = scene_draw, .destroy = scene_destroy,
                                                  .set_lod = scene_set_lod, .stats = scene_stats};

static int check_group(asp_gl_context *gl, const asp_scene_renderer_group *g, size_t gi, asp_error *err)
{
    if (!g->renderer || g->renderer->gl != gl)
        return asp_error_set(err, ASP_EINVAL, "scene group %zu: %s", gi,
                             g->renderer ? "a renderer of another GL context" : "no renderer");
    if (g->count && !g->models)
        return asp_error_set(err, ASP_EINVAL, "scene group %zu: %zu instances without models", gi, g->count);
    if (g->count > UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "scene group %zu: %zu instances, more than 2^32 - 1", gi, g->count);
    for (size_t k = 0; k < 16 * g->count; k++)
        if (!isfinite(g->models[k]))
            return asp_error_set(err, ASP_EINVAL, "scene group %zu instance %zu: a non-finite model matrix", gi,
                                 k / 16);
    if (!isfinite(g->center[0]) || !isfinite(g->center[1]) || !isfinite(g->center[2]) || !(g->radius >= 0) ||
        !isfinite(g->radius))
        return asp_error_set(err, ASP_EINVAL, "scene group %zu: a non-finite bounding sphere", gi);
    return 0;
}

int asp_scene_renderer_create(asp_gl_context *gl, const asp_scene_renderer_group *groups, size_t group_count,
                              asp_renderer **out, asp_error *err)
{
    ASP_ASSERT(gl && out && (groups || !group_count));
    int rc = group_count ? 0 : asp_error_set(err, ASP_EINVAL, "a scene renderer needs at least one group");
    size_t total = 0, largest = 0;
    for (size_t gi = 0; gi < group_count && !rc; gi++) {
        rc = check_group(gl, &groups[gi], gi, err);
        total += groups[gi].count;
        largest = groups[gi].count > largest ? groups[gi].count : largest;
    }
    scene_renderer *s = rc ? NULL : asp_calloc(&gl->actx, 1, sizeof *s);
    if (!rc && s) {
        s->groups = asp_calloc(&gl->actx, group_count, sizeof *s->groups);
        s->refs = asp_calloc(&gl->actx, total ? total : 1, sizeof *s->refs);
        s->batch = asp_calloc(&gl->actx, 16 * (largest ? largest : 1), sizeof(float));
    }
    if (!rc && (!s || !s->groups || !s->refs || !s->batch))
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a scene of %zu instances", total);
    for (size_t gi = 0; !rc && gi < group_count; gi++) {
        const asp_scene_renderer_group *g = &groups[gi];
        group *d = &s->groups[gi];
        d->models = asp_alloc(&gl->actx, 16 * (g->count ? g->count : 1) * sizeof(float));
        if (!d->models) {
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a scene of %zu instances", total);
            break;
        }
        if (g->count)
            memcpy(d->models, g->models, 16 * g->count * sizeof(float));
        d->count = g->count;
        memcpy(d->center, g->center, sizeof d->center);
        d->radius = g->radius;
        d->one_by_one = g->one_by_one != 0;
    }
    if (rc) {
        // the renderers belong to us from the call on: none leaks on failure
        for (size_t gi = 0; gi < group_count; gi++) {
            asp_renderer_destroy(groups[gi].renderer);
            if (s && s->groups)
                asp_free(&gl->actx, s->groups[gi].models);
        }
        if (s) {
            asp_free(&gl->actx, s->groups);
            asp_free(&gl->actx, s->refs);
            asp_free(&gl->actx, s->batch);
            asp_free(&gl->actx, s);
        }
        return rc;
    }
    for (size_t gi = 0; gi < group_count; gi++)
        s->groups[gi].r = groups[gi].renderer;
    s->group_count = group_count;
    s->total = total;
    s->base.vt = &scene_vtable;
    s->base.gl = gl;
    s->base.count = 0;
    *out = &s->base;
    return 0;
}

size_t asp_scene_renderer_drawn(const asp_renderer *r)
{
    return r && r->vt == &scene_vtable ? ((const scene_renderer *)r)->drawn : 0;
}
