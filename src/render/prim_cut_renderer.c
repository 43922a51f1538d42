/*
 * The cut renderer (issue 18 item 2; journal section 6, thesis 2.6.3): every
 * level of a .dps uploaded once, and per frame, per instance, the view-
 * dependent cut of asp_dps_cut (seed 001 section 5: detail by screen error)
 * drawn with alpha x d_f through one normalized accumulation (Pajarola et al.
 * 2003 5.3-5.4, the prim renderer's default method), so levels meet without a
 * seam and many instances blend as one surface set.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "render/prim_cut_internal.h"
#include "util/banned.h"

/* One drawn item as the vertex stage reads it (12 bytes, divisor 1). */
typedef struct cut_item {
    uint32_t prim, inst;
    float weight;
} cut_item;

typedef struct cut_level {
    asp__gl_buffer prims;
    GLuint atlas;
    float window;          /* depth window: half the level's mean primitive radius (as the prim renderer);
                              NEEDSWORK: not scaled by an instance's model matrix (right for scale 1) */
    size_t first, count;   /* this frame's items */
} cut_level;

typedef struct cut_renderer {
    asp_renderer base;     /* first */
    const asp_dps *dps;
    asp_context actx;
    float tolerance, alpha_ref, transparency, size_weight;
    double fade, origin[3];
    size_t nlevels;
    cut_level *levels;
    /* instances: count matrices (identity when none set), one cut each */
    float *models;
    size_t instances, cut_capacity;
    asp_dps_cut **cuts;
    uint8_t *visible;
    double time, last_time; /* caller's clock; NAN = not given */
    /* per frame */
    cut_item *items;
    size_t item_capacity, gpu_item_capacity, gpu_model_capacity, drawn;
    double select_seconds;  /* CPU time of the last frame's cuts and item list */
    asp__gl_buffer item_buffer, model_buffer;
    asp__gl_vertex_array vao, empty_vao;
    asp__gl_program draw, resolve;
    GLint u_draw[7], u_resolve[2];
    /* targets */
    uint32_t width, height;
    GLuint front_depth, accum;
    asp__gl_framebuffer front_fbo, accum_fbo;
} cut_renderer;

enum { UD_VIEW, UD_PROJ, UD_LIGHT, UD_LIT, UD_PASS, UD_ALPHA_REF, UD_WINDOW };

static const asp__renderer_vtable cut_vtable;

static cut_renderer *cut_of(asp_renderer *r)
{
    return r && r->vt == &cut_vtable ? (cut_renderer *)r : NULL;
}

static void release_targets(cut_renderer *r)
{
    if (r->front_fbo.id)
        glDeleteFramebuffers(1, &r->front_fbo.id);
    if (r->accum_fbo.id)
        glDeleteFramebuffers(1, &r->accum_fbo.id);
    if (r->front_depth)
        glDeleteTextures(1, &r->front_depth);
    if (r->accum)
        glDeleteTextures(1, &r->accum);
    r->front_fbo.id = r->accum_fbo.id = r->front_depth = r->accum = 0;
    r->width = r->height = 0;
}

static GLuint target_texture(uint32_t w, uint32_t h, GLenum format)
{
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, format, (GLsizei)w, (GLsizei)h);
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return tex;
}

/* A depth-only front layer and an RGBA32F sum (the weights may be far from 1 before the division). */
static int targets_ensure(cut_renderer *r, uint32_t w, uint32_t h, asp_error *err)
{
    if (r->front_fbo.id && r->width == w && r->height == h)
        return 0;
    release_targets(r);
    asp__gl_clear_errors(r->base.gl);
    r->front_depth = target_texture(w, h, GL_DEPTH_COMPONENT32F);
    r->accum = target_texture(w, h, GL_RGBA32F);
    glCreateFramebuffers(1, &r->front_fbo.id);
    glNamedFramebufferTexture(r->front_fbo.id, GL_DEPTH_ATTACHMENT, r->front_depth, 0);
    glNamedFramebufferDrawBuffer(r->front_fbo.id, GL_NONE);
    glCreateFramebuffers(1, &r->accum_fbo.id);
    glNamedFramebufferTexture(r->accum_fbo.id, GL_COLOR_ATTACHMENT0, r->accum, 0);
    int rc = asp__gl_check(r->base.gl, "create the cut renderer's targets", err);
    if (!rc && (glCheckNamedFramebufferStatus(r->front_fbo.id, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE ||
                glCheckNamedFramebufferStatus(r->accum_fbo.id, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE))
        rc = asp_error_set(err, ASP_EGL, "cannot create the cut renderer's framebuffers: incomplete");
    if (rc) {
        release_targets(r);
        return rc;
    }
    r->width = w, r->height = h;
    return 0;
}

static void cut_destroy(asp_renderer *base)
{
    cut_renderer *r = (cut_renderer *)base;
    asp_context *a = &r->actx;
    for (size_t i = 0; r->levels && i < r->nlevels; i++) {
        if (r->levels[i].prims.id)
            glDeleteBuffers(1, &r->levels[i].prims.id);
        if (r->levels[i].atlas)
            glDeleteTextures(1, &r->levels[i].atlas);
    }
    for (size_t i = 0; i < r->cut_capacity; i++)
        asp_dps_cut_destroy(r->cuts[i]);
    GLuint bufs[2] = {r->item_buffer.id, r->model_buffer.id};
    glDeleteBuffers(2, bufs);
    GLuint vaos[2] = {r->vao.id, r->empty_vao.id};
    glDeleteVertexArrays(2, vaos);
    asp__gl_program_destroy(&r->draw);
    asp__gl_program_destroy(&r->resolve);
    release_targets(r);
    asp_free(a, r->levels);
    asp_free(a, r->models);
    asp_free(a, r->cuts);
    asp_free(a, r->visible);
    asp_free(a, r->items);
    asp_free(a, r);
}

/* The level's records (centres relative to origin, as the prim renderer's fill_prims) and its atlas. */
static int upload_level(cut_renderer *r, const asp_dps_level *lv, cut_level *out, asp_error *err)
{
    size_t n = lv->prim_count;
    asp__prim_gpu *g = asp_calloc(&r->actx, n, sizeof *g);
    if (!g)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu primitive records", n);
    double sum_radius = 0;
    for (size_t i = 0; i < n; i++) {
        const asp_prim *p = &lv->prims[i];
        for (int a = 0; a < 3; a++) {
            g[i].c[a] = (float)(p->centre[a] - r->origin[a]);
            g[i].u[a] = p->axis_u[a] * p->half_u;
            g[i].v[a] = p->axis_v[a] * p->half_v;
            g[i].n[a] = p->normal[a];
        }
        g[i].uv[0] = (float)p->tex_x / (float)lv->atlas.width;
        g[i].uv[1] = (float)p->tex_y / (float)lv->atlas.height;
        g[i].uv[2] = (float)p->tex_w / (float)lv->atlas.width;
        g[i].uv[3] = (float)p->tex_h / (float)lv->atlas.height;
        sum_radius += sqrt((double)p->half_u * p->half_v);
    }
    out->window = (float)(0.5 * sum_radius / (double)n);
    glCreateBuffers(1, &out->prims.id);
    glNamedBufferStorage(out->prims.id, (GLsizeiptr)(n * sizeof *g), g, 0);
    asp_free(&r->actx, g);
    glCreateTextures(GL_TEXTURE_2D, 1, &out->atlas);
    glTextureStorage2D(out->atlas, 1, GL_SRGB8_ALPHA8, (GLsizei)lv->atlas.width, (GLsizei)lv->atlas.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(out->atlas, 0, 0, 0, (GLsizei)lv->atlas.width, (GLsizei)lv->atlas.height, GL_RGBA,
                        GL_UNSIGNED_BYTE, lv->atlas.pixels);
    glTextureParameteri(out->atlas, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(out->atlas, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(out->atlas, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(out->atlas, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return 0;
}

static int build_programs(cut_renderer *r, asp_error *err)
{
    static const char *ud[7] = {"u_view", "u_proj", "u_light", "u_lit", "u_pass", "u_alpha_ref", "u_window"};
    int rc = asp__gl_program_create(r->base.gl, "cut primitives", asp__cut_vertex_src, asp__cut_fragment_src,
                                    &r->draw, err);
    if (!rc)
        rc = asp__gl_program_create(r->base.gl, "cut resolve", asp__prim_resolve_vertex_src,
                                    asp__prim_resolve_fragment_src, &r->resolve, err);
    if (rc)
        return rc;
    for (int u = 0; u < 7; u++)
        r->u_draw[u] = glGetUniformLocation(r->draw.id, ud[u]);
    r->u_resolve[0] = glGetUniformLocation(r->resolve.id, "u_normalize");
    r->u_resolve[1] = glGetUniformLocation(r->resolve.id, "u_transparency");
    return 0;
}

static void item_attributes(cut_renderer *r)
{
    GLuint vao = r->vao.id;
    glVertexArrayVertexBuffer(vao, 0, r->item_buffer.id, 0, sizeof(cut_item));
    glVertexArrayAttribIFormat(vao, 0, 1, GL_UNSIGNED_INT, offsetof(cut_item, prim));
    glVertexArrayAttribIFormat(vao, 1, 1, GL_UNSIGNED_INT, offsetof(cut_item, inst));
    glVertexArrayAttribFormat(vao, 2, 1, GL_FLOAT, GL_FALSE, offsetof(cut_item, weight));
    for (GLuint a = 0; a < 3; a++) {
        glVertexArrayAttribBinding(vao, a, 0);
        glEnableVertexArrayAttrib(vao, a);
    }
    glVertexArrayBindingDivisor(vao, 0, 1);
}

/* Grows the pool of per-instance cuts to n (each keeps its own fade). */
static int ensure_cuts(cut_renderer *r, size_t n, asp_error *err)
{
    if (n <= r->cut_capacity)
        return 0;
    asp_dps_cut **c = asp_calloc(&r->actx, n, sizeof *c);
    uint8_t *vis = asp_calloc(&r->actx, n, 1);
    if (!c || !vis) {
        asp_free(&r->actx, c);
        asp_free(&r->actx, vis);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu instance cuts", n);
    }
    if (r->cut_capacity)
        memcpy(c, r->cuts, r->cut_capacity * sizeof *c);
    for (size_t i = r->cut_capacity; i < n; i++) {
        int rc = asp_dps_cut_create(r->dps, r->fade == 0 ? -1 : r->fade, &r->actx, &c[i], err);
        if (rc) {
            for (size_t k = r->cut_capacity; k < i; k++)
                asp_dps_cut_destroy(c[k]);
            asp_free(&r->actx, c);
            asp_free(&r->actx, vis);
            return rc;
        }
    }
    asp_free(&r->actx, r->cuts);
    asp_free(&r->actx, r->visible);
    r->cuts = c, r->visible = vis, r->cut_capacity = n;
    return 0;
}

static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

int asp_cut_renderer_set_instances(asp_renderer *base, const float *models, size_t count, asp_error *err)
{
    cut_renderer *r = cut_of(base);
    if (!r)
        return asp_error_set(err, ASP_EINVAL, "the %s renderer draws no instances of a cut", asp_renderer_name(base));
    size_t n = count ? count : 1;
    float *m = asp_alloc(&r->actx, 16 * n * sizeof *m);
    if (!m)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu instances", n);
    memcpy(m, count ? models : identity, 16 * n * sizeof *m);
    int rc = ensure_cuts(r, n, err);
    if (rc) {
        asp_free(&r->actx, m);
        return rc;
    }
    asp_free(&r->actx, r->models);
    r->models = m, r->instances = n;
    return 0;
}

int asp_cut_renderer_set_time(asp_renderer *base, double seconds, asp_error *err)
{
    cut_renderer *r = cut_of(base);
    if (!r || !isfinite(seconds))
        return asp_error_set(err, ASP_EINVAL, "a cut renderer and a finite time are needed");
    r->time = seconds;
    return 0;
}

int asp_cut_renderer_create(asp_gl_context *gl, const asp_dps *dps, const asp_cut_renderer_desc *desc,
                            asp_renderer **out, asp_error *err)
{
    static const asp_cut_renderer_desc zero;
    if (!desc)
        desc = &zero;
    if (!dps || !out || dps->level_count == 0)
        return asp_error_set(err, ASP_EINVAL, "the cut renderer needs a .dps with levels");
    if (dps->level_count > 1 && !asp_dps_has_links(dps))
        return asp_error_set(err, ASP_EINVAL, "no links between the levels of this .dps (version 1 or 2, or a merged "
                             "level): rebuild it with 'amgsplat build --level L-6..L' for a cut across levels");
    if (isnan(desc->tolerance) || isnan(desc->alpha_ref) || desc->alpha_ref > 1 || isnan(desc->transparency) ||
        desc->transparency > 1 || isnan(desc->fade_seconds) || isnan(desc->size_weight))
        return asp_error_set(err, ASP_EINVAL, "cut renderer options: tolerance %g, alpha reference %g, transparency "
                             "%g, fade %g s", (double)desc->tolerance, (double)desc->alpha_ref,
                             (double)desc->transparency, desc->fade_seconds);
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    GLint max_tex = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    for (size_t i = 0; i < dps->level_count; i++)
        if (dps->levels[i].atlas.width > (uint32_t)max_tex || dps->levels[i].atlas.height > (uint32_t)max_tex)
            return asp_error_set(err, ASP_EUNSUPPORTED, "cannot upload the %ux%u atlas of level %u: this GL allows "
                                 "%d texels a side", dps->levels[i].atlas.width, dps->levels[i].atlas.height,
                                 dps->levels[i].level, max_tex);
    cut_renderer *r = asp_calloc(&gl->actx, 1, sizeof *r);
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a cut renderer");
    r->base.vt = &cut_vtable;
    r->base.gl = gl;
    r->actx = gl->actx;
    r->dps = dps;
    r->tolerance = desc->tolerance > 0 ? desc->tolerance : desc->tolerance < 0 ? 0.0f : 1.0f;
    r->alpha_ref = desc->alpha_ref > 0 ? desc->alpha_ref : desc->alpha_ref < 0 ? 0.0f : 0.1f;
    r->transparency = desc->transparency > 0 ? desc->transparency : 1.0f;
    r->size_weight = desc->size_weight > 0 ? desc->size_weight : desc->size_weight < 0 ? 0.0f : 0.2f;
    r->fade = desc->fade_seconds == 0 ? 0.25 : desc->fade_seconds < 0 ? 0 : desc->fade_seconds;
    r->time = r->last_time = NAN;
    memcpy(r->origin, desc->origin, sizeof r->origin);
    r->nlevels = dps->level_count;
    r->levels = asp_calloc(&r->actx, r->nlevels, sizeof *r->levels);
    rc = r->levels ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for a cut renderer");
    asp__gl_clear_errors(gl);
    for (size_t i = 0; !rc && i < r->nlevels; i++)
        rc = upload_level(r, &dps->levels[i], &r->levels[i], err);
    if (!rc)
        rc = build_programs(r, err);
    if (!rc) {
        glCreateBuffers(1, &r->item_buffer.id);
        glCreateBuffers(1, &r->model_buffer.id);
        glCreateVertexArrays(1, &r->vao.id);
        glCreateVertexArrays(1, &r->empty_vao.id);
        rc = asp_cut_renderer_set_instances(&r->base, NULL, 0, err);
    }
    if (!rc)
        rc = asp__gl_check(gl, "upload the levels of a cut", err);
    if (rc) {
        cut_destroy(&r->base);
        return rc;
    }
    *out = &r->base;
    return 0;
}

/* x = A^-1 (y - t) for the affine column-major m; returns 0 when A is singular. */
static int affine_inverse_point(const float *m, const float y[3], double x[3])
{
    double a[3][3], b[3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            a[i][j] = m[4 * j + i];
        b[i] = (double)y[i] - m[12 + i];
    }
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(fabs(det) > 1e-30))
        return 0;
    // Cramer's rule: three columns replaced by b
    for (int c = 0; c < 3; c++) {
        double t[3][3];
        memcpy(t, a, sizeof t);
        for (int i = 0; i < 3; i++)
            t[i][c] = b[i];
        x[c] = (t[0][0] * (t[1][1] * t[2][2] - t[1][2] * t[2][1]) - t[0][1] * (t[1][0] * t[2][2] - t[1][2] * t[2][0]) +
                t[0][2] * (t[1][0] * t[2][1] - t[1][1] * t[2][0])) / det;
    }
    return 1;
}

/* The instance's bounding sphere (the dps frame, scaled by the matrix's largest column) against the frustum. */
static int sphere_visible(const cut_renderer *r, const float *model, const asp__frame *f)
{
    const asp_frame *fr = &r->dps->frame;
    if (!(fr->radius > 0))
        return 1;
    double c[3], e[3], s = 0;
    for (int i = 0; i < 3; i++)
        c[i] = fr->center[i] - r->origin[i];
    for (int j = 0; j < 3; j++) {
        double len = sqrt((double)model[4 * j] * model[4 * j] + (double)model[4 * j + 1] * model[4 * j + 1] +
                          (double)model[4 * j + 2] * model[4 * j + 2]);
        s = len > s ? len : s;
    }
    double w[3];
    for (int i = 0; i < 3; i++)
        w[i] = model[i] * c[0] + model[4 + i] * c[1] + model[8 + i] * c[2] + model[12 + i];
    for (int i = 0; i < 3; i++)
        e[i] = f->view[i] * w[0] + f->view[4 + i] * w[1] + f->view[8 + i] * w[2] + f->view[12 + i];
    double rad = fr->radius * s, tx = 1.0 / f->proj[0], ty = 1.0 / f->proj[5], depth = -e[2];
    if (depth < -rad)
        return 0; // wholly behind the eye
    if ((fabs(e[0]) - depth * tx) / sqrt(1 + tx * tx) > rad || (fabs(e[1]) - depth * ty) / sqrt(1 + ty * ty) > rad)
        return 0;
    return 1;
}

/* Updates every visible instance's cut and lays out the items by level, then by instance. */
static int build_items(cut_renderer *r, const asp__frame *f, asp_error *err)
{
    double dt = isnan(r->time) || isnan(r->last_time) ? -1 : r->time - r->last_time;
    r->last_time = r->time;
    asp_dps_cut_view view = {.pixels_per_unit = 0.5 * f->height * f->proj[5], .tolerance = r->tolerance,
                             .size_weight = r->size_weight};
    size_t total = 0;
    for (size_t i = 0; i < r->instances; i++) {
        const float *m = r->models + 16 * i;
        double local[3] = {0, 0, 0}; // gcc -O3 cannot see that affine_inverse_point fills it when it returns 1
        r->visible[i] = sphere_visible(r, m, f) && affine_inverse_point(m, f->eye, local);
        if (!r->visible[i])
            continue;
        for (int k = 0; k < 3; k++)
            view.eye[k] = local[k] + r->origin[k];
        int rc = asp_dps_cut_update(r->cuts[i], &view, dt, err);
        if (rc)
            return rc;
        total += asp_dps_cut_items(r->cuts[i], NULL);
    }
    if (total > r->item_capacity) {
        size_t cap = total + total / 2 + 64;
        cut_item *it = asp_alloc(&r->actx, cap * sizeof *it);
        if (!it)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu drawn primitives", total);
        asp_free(&r->actx, r->items);
        r->items = it, r->item_capacity = cap;
    }
    size_t n = 0;
    for (size_t l = 0; l < r->nlevels; l++) {
        r->levels[l].first = n;
        for (size_t i = 0; i < r->instances; i++) {
            if (!r->visible[i])
                continue;
            const asp_dps_cut_item *ci;
            size_t m = asp_dps_cut_items(r->cuts[i], &ci);
            for (size_t q = 0; q < m; q++)
                if (ci[q].level == l)
                    r->items[n++] = (cut_item){ci[q].prim, (uint32_t)i, ci[q].weight};
        }
        r->levels[l].count = n - r->levels[l].first;
    }
    r->drawn = n;
    r->base.count = n;
    return 0;
}

/* Grows buffer to hold bytes (contents replaced every frame, so the old ones need not survive). */
static void stream(GLuint *buf, size_t *capacity, const void *data, size_t bytes)
{
    if (bytes > *capacity) {
        size_t cap = bytes + bytes / 2 + 256;
        glNamedBufferData(*buf, (GLsizeiptr)cap, NULL, GL_STREAM_DRAW);
        *capacity = cap;
    }
    if (bytes)
        glNamedBufferSubData(*buf, 0, (GLsizeiptr)bytes, data);
}

static void draw_levels(cut_renderer *r, int pass)
{
    glProgramUniform1i(r->draw.id, r->u_draw[UD_PASS], pass);
    for (size_t l = 0; l < r->nlevels; l++) {
        const cut_level *lv = &r->levels[l];
        if (!lv->count)
            continue;
        glProgramUniform1f(r->draw.id, r->u_draw[UD_WINDOW], lv->window);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_PRIMS, lv->prims.id);
        glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, lv->atlas);
        glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)lv->count, (GLuint)lv->first);
    }
}

static int cut_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    cut_renderer *r = (cut_renderer *)base;
    double t0 = asp_time_now();
    int rc = build_items(r, f, err);
    r->select_seconds = asp_time_now() - t0;
    if (!rc)
        rc = targets_ensure(r, f->width, f->height, err);
    if (rc)
        return rc;
    GLint caller = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller);
    stream(&r->item_buffer.id, &r->gpu_item_capacity, r->items, r->drawn * sizeof *r->items);
    stream(&r->model_buffer.id, &r->gpu_model_capacity, r->models, 16 * r->instances * sizeof(float));
    if (r->drawn)
        item_attributes(r); /* the buffer may have been reallocated */
    glProgramUniformMatrix4fv(r->draw.id, r->u_draw[UD_VIEW], 1, GL_FALSE, f->view);
    glProgramUniformMatrix4fv(r->draw.id, r->u_draw[UD_PROJ], 1, GL_FALSE, f->proj);
    glProgramUniform3fv(r->draw.id, r->u_draw[UD_LIGHT], 1, f->light_eye);
    glProgramUniform1i(r->draw.id, r->u_draw[UD_LIT], (f->flags & ASP_RENDER_UNLIT) ? 0 : 1);
    glProgramUniform1f(r->draw.id, r->u_draw[UD_ALPHA_REF], r->alpha_ref);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__CUT_BIND_MODELS, r->model_buffer.id);
    glUseProgram(r->draw.id);
    glBindVertexArray(r->vao.id);
    static const GLfloat zero[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    // pass 1: the front-most alpha-tested layer; back faces culled as in the prim renderer's normalized method
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->front_fbo.id);
    glClearNamedFramebufferfv(r->front_fbo.id, GL_DEPTH, 0, &far_depth);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    draw_levels(r, 0);
    // pass 2: colour x alpha x d_f within each level's window behind it
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->accum_fbo.id);
    glClearNamedFramebufferfv(r->accum_fbo.id, GL_COLOR, 0, zero);
    glDepthMask(GL_FALSE);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, r->front_depth);
    draw_levels(r, 1);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, 0);
    glDisable(GL_CULL_FACE);
    // the division, "over" the caller's background (prim_shaders.c's resolve)
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)caller);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glProgramUniform1i(r->resolve.id, r->u_resolve[0], 1);
    glProgramUniform1f(r->resolve.id, r->u_resolve[1], r->transparency);
    glBindTextureUnit(ASP__PRIM_UNIT_ACCUM, r->accum);
    glUseProgram(r->resolve.id);
    glBindVertexArray(r->empty_vao.id);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTextureUnit(ASP__PRIM_UNIT_ACCUM, 0);
    glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, 0);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glBindVertexArray(0);
    glUseProgram(0);
    return asp__gl_check(r->base.gl, "draw a cut of domain primitives", err);
}

static int cut_set_lod(asp_renderer *base, float tolerance, uint32_t depth_limit, asp_error *err)
{
    (void)depth_limit, (void)err; /* the levels of a .dps are the depth */
    ((cut_renderer *)base)->tolerance = tolerance;
    return 0;
}

static void cut_stats(const asp_renderer *base, asp_renderer_stats *out)
{
    const cut_renderer *r = (const cut_renderer *)base;
    out->count = r->drawn;
    out->tolerance = r->tolerance;
    out->select_seconds = r->select_seconds;
    size_t prims = 0;
    for (size_t l = 0; l < r->nlevels; l++)
        prims += r->dps->levels[l].prim_count;
    out->nodes = prims; /* the primitives of every level: the cut's tree */
    out->points = (size_t)r->dps->source_points;
}

static int cut_draw_instances(asp_renderer *base, const asp__frame *frame, const float *models, size_t count,
                              asp_error *err)
{
    cut_renderer *r = (cut_renderer *)base;
    float *keep = r->models;
    size_t keep_n = r->instances;
    r->models = NULL;
    int rc = asp_cut_renderer_set_instances(base, models, count, err);
    if (rc) {
        r->models = keep;
        return rc;
    }
    rc = cut_draw(base, frame, err);
    asp_free(&r->actx, r->models);
    r->models = keep, r->instances = keep_n;
    return rc;
}

static const asp__renderer_vtable cut_vtable = {
    .name = "cut",
    .draw = cut_draw,
    .destroy = cut_destroy,
    .set_lod = cut_set_lod,
    .stats = cut_stats,
    .draw_instances = cut_draw_instances,
};
