/*
 * The rendering methods of domain primitives, as pass sequences: the seeds'
 * overlap (journal Fig. 10, thesis 4.4.4), two-pass (4.4.2), dark back-face
 * hard and soft (4.4.3), blend-all and no-blend (appendix C), the opaque
 * polygons of journal Fig. 12b, and normalized (Pajarola et al. 2003 5.3-5.4)
 * and prefix (thesis 4.4, Fig. 4.4-4.5) on programmable hardware.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/prim_internal.h"
#include "util/banned.h"

/*
 * The polygons method draws each support rectangle where its domain lies:
 * where the basis function (texture alpha) exceeds the domain threshold tau
 * (journal eq. 8, thesis 2.5: the domain is the points with Psi > tau). With
 * affine textures (thesis 3.2.2) that is a polygon inside the convex hull of
 * the domain's projected points, the "tighter fitting n-sided bounding
 * polygon" the journal (3.1) and the thesis (3.1) name as the alternative to
 * the rectangle. The rectangle's empty corners widen the silhouette: bunny,
 * 354 primitives, view 30,20, 128 px, IoU against the points 0.873 with whole
 * rectangles, 0.948 at alpha > 0, 0.955 at alpha > tau. The renderer sees one
 * level, not the build options, so this is the default tau (0.05, the one
 * `amgsplat build` uses); a set built through the library with another tau is
 * trimmed at 0.05 all the same. --outline still draws the whole rectangles.
 */
#define POLYGON_ALPHA_REF 0.05f

void asp__prim_targets_release(asp__prim_targets *t)
{
    GLuint fbos[3] = {t->seed_fbo.id, t->front_fbo.id, t->accum_fbo.id};
    for (int i = 0; i < 3; i++)
        if (fbos[i])
            glDeleteFramebuffers(1, &fbos[i]);
    GLuint tex[4] = {t->accum_float, t->accum_fixed, t->depth, t->id};
    for (int i = 0; i < 4; i++)
        if (tex[i])
            glDeleteTextures(1, &tex[i]);
    memset(t, 0, sizeof *t);
}

static GLuint make_texture(uint32_t w, uint32_t h, GLenum format)
{
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, format, (GLsizei)w, (GLsizei)h);
    // integer textures are incomplete with linear filtering; every read is a texelFetch anyway
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return tex;
}

static int check_fbo(GLuint fbo, const char *which, asp_error *err)
{
    GLenum status = glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER);
    if (status == GL_FRAMEBUFFER_COMPLETE)
        return 0;
    return asp_error_set(err, ASP_EGL, "cannot create the primitive %s framebuffer: status 0x%04x", which,
                         (unsigned)status);
}

/*
 * RGBA16 unorm for the seeds: blending clamps to 0..1 as their 8-bit
 * framebuffers did (over-bright saturates, the soft back-face subtraction
 * stops at black), with more precision. RGBA32F for the normalised sums,
 * whose weights may be far from 1 before the division.
 */
static int targets_ensure(asp_gl_context *gl, asp__prim_targets *t, uint32_t w, uint32_t h, asp_error *err)
{
    if (t->seed_fbo.id && t->width == w && t->height == h)
        return 0;
    asp__prim_targets_release(t);
    asp__gl_clear_errors(gl);
    t->accum_float = make_texture(w, h, GL_RGBA32F);
    t->accum_fixed = make_texture(w, h, GL_RGBA16);
    t->depth = make_texture(w, h, GL_DEPTH_COMPONENT32F);
    t->id = make_texture(w, h, GL_R32UI);
    glCreateFramebuffers(1, &t->seed_fbo.id);
    glNamedFramebufferTexture(t->seed_fbo.id, GL_COLOR_ATTACHMENT0, t->accum_fixed, 0);
    glNamedFramebufferTexture(t->seed_fbo.id, GL_DEPTH_ATTACHMENT, t->depth, 0);
    glCreateFramebuffers(1, &t->front_fbo.id);
    glNamedFramebufferTexture(t->front_fbo.id, GL_COLOR_ATTACHMENT0, t->id, 0);
    glNamedFramebufferTexture(t->front_fbo.id, GL_DEPTH_ATTACHMENT, t->depth, 0);
    glCreateFramebuffers(1, &t->accum_fbo.id);
    glNamedFramebufferTexture(t->accum_fbo.id, GL_COLOR_ATTACHMENT0, t->accum_float, 0);
    int rc = asp__gl_check(gl, "create the primitive render targets", err);
    if (!rc)
        rc = check_fbo(t->seed_fbo.id, "accumulation", err);
    if (!rc)
        rc = check_fbo(t->front_fbo.id, "front layer", err);
    if (!rc)
        rc = check_fbo(t->accum_fbo.id, "normalisation", err);
    if (rc) {
        asp__prim_targets_release(t);
        return rc;
    }
    t->width = w;
    t->height = h;
    return 0;
}

static int cmp_key(const void *a, const void *b)
{
    const struct asp__prim_key *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id); // ties by index: the same order on every run
}

/* Sorts the primitives by the distance from the eye to their centre (thesis 4.4.1), nearest first. */
static void sort_by_distance(asp__prim_renderer *r, const float eye[3])
{
    for (size_t i = 0; i < r->count; i++) {
        const float *c = r->centres + 3 * i;
        float d[3] = {c[0] - eye[0], c[1] - eye[1], c[2] - eye[2]};
        r->keys[i].key = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        r->keys[i].id = (uint32_t)i;
    }
    qsort(r->keys, r->count, sizeof *r->keys, cmp_key);
}

static int facing(const asp__prim_renderer *r, uint32_t i, const float eye[3])
{
    const float *c = r->centres + 3 * i, *n = r->normals + 3 * i;
    return n[0] * (eye[0] - c[0]) + n[1] * (eye[1] - c[1]) + n[2] * (eye[2] - c[2]) > 0;
}

/* Appends order entry id under kind, extending the last run when it is of the same kind. */
static void push(asp__prim_renderer *r, size_t *no, size_t *nr, asp__run_kind kind, uint32_t id)
{
    r->order[*no] = id;
    if (*nr && r->runs[*nr - 1].kind == kind && r->runs[*nr - 1].first + r->runs[*nr - 1].count == *no)
        r->runs[*nr - 1].count++;
    else
        r->runs[(*nr)++] = (asp__run){kind, (uint32_t)*no, 1};
    (*no)++;
}

/*
 * Journal Fig. 10: for each front-facing primitive, front to back, the
 * primitive and its neighbours not drawn yet are added, then the primitive is
 * locked. Each primitive enters a colour run at most once and a lock run at
 * most once, so the lists hold at most 2 count entries.
 */
static size_t overlap_runs(asp__prim_renderer *r, const float eye[3], size_t *nruns)
{
    sort_by_distance(r, eye);
    memset(r->drawn, 0, r->count * sizeof *r->drawn);
    size_t no = 0, nr = 0;
    for (size_t k = 0; k < r->count; k++) {
        uint32_t i = r->keys[k].id;
        if (!facing(r, i, eye))
            continue;
        if (!r->drawn[i]) {
            r->drawn[i] = 1;
            push(r, &no, &nr, ASP__RUN_ADD, i);
        }
        for (uint32_t m = 0; m < r->nb_count[i]; m++) {
            uint32_t j = r->neighbours[r->nb_first[i] + m];
            if (!r->drawn[j]) {
                r->drawn[j] = 1;
                push(r, &no, &nr, ASP__RUN_ADD, j);
            }
        }
        push(r, &no, &nr, ASP__RUN_LOCK, i);
    }
    *nruns = nr;
    return no;
}

/* Thesis 4.4.3: back to front; front faces add, back faces reset (hard) or darken (soft). */
static size_t backface_runs(asp__prim_renderer *r, const float eye[3], int soft, size_t *nruns)
{
    sort_by_distance(r, eye);
    size_t no = 0, nr = 0;
    for (size_t k = r->count; k-- > 0;) {
        uint32_t i = r->keys[k].id;
        asp__run_kind kind = facing(r, i, eye) ? ASP__RUN_ADD : soft ? ASP__RUN_DARKEN : ASP__RUN_CLEAR;
        push(r, &no, &nr, kind, i);
    }
    *nruns = nr;
    return no;
}

static void set_uniforms(asp__prim_renderer *r, const asp__frame *f)
{
    const asp_prim_render_options *o = &r->opt;
    float outline[4];
    for (int c = 0; c < 3; c++)
        outline[c] = asp__srgb_to_linear(o->outline_color[c]);
    outline[3] = o->outline_color[3] / 255.0f;
    for (int p = 0; p < ASP__PROG_RESOLVE; p++) {
        GLuint id = r->programs[p].id;
        const GLint *u = r->uniforms[p];
        glProgramUniformMatrix4fv(id, u[PU_VIEW], 1, GL_FALSE, f->view);
        glProgramUniformMatrix4fv(id, u[PU_PROJ], 1, GL_FALSE, f->proj);
        glProgramUniform3fv(id, u[PU_LIGHT], 1, f->light_eye);
        glProgramUniform1i(id, u[PU_LIT], (f->flags & ASP_RENDER_UNLIT) ? 0 : 1);
        glProgramUniform1i(id, u[PU_NORMAL_MAP],
                           r->has_normal_map && !(o->flags & ASP_PRIM_RENDER_NO_NORMAL_MAP));
        glProgramUniform1i(id, u[PU_DOMAIN_COLORS], (o->flags & ASP_PRIM_RENDER_COLOR_BY_DOMAIN) != 0);
        glProgramUniform1f(id, u[PU_ALPHA_REF], o->alpha_ref);
        glProgramUniform1f(id, u[PU_WINDOW], o->depth_window);
        glProgramUniform1f(id, u[PU_OFFSET], 0.0f);
        glProgramUniform4fv(id, u[PU_OUTLINE_COLOR], 1, outline);
        glProgramUniform1i(id, u[PU_CORNERS], 0);
        glProgramUniform1i(id, u[PU_SELECT], ASP__SELECT_ALL);
        glProgramUniform1f(id, u[PU_TRANSPARENCY], o->transparency);
        // cos of the crease angle; -2 (below any cosine) turns clipping off
        glProgramUniform1f(id, u[PU_CREASE_COS],
                           o->crease_angle > 0 ? (float)cos(o->crease_angle * 3.14159265358979323846 / 180.0)
                                               : -2.0f);
    }
}

/* The uniforms that differ between instances of one frame: the view (model folded in) and projection. */
static void frame_uniforms(asp__prim_renderer *r, const asp__frame *f)
{
    for (int p = 0; p < ASP__PROG_RESOLVE; p++) {
        GLuint id = r->programs[p].id;
        glProgramUniformMatrix4fv(id, r->uniforms[p][PU_VIEW], 1, GL_FALSE, f->view);
        glProgramUniformMatrix4fv(id, r->uniforms[p][PU_PROJ], 1, GL_FALSE, f->proj);
    }
}

/* Draws every primitive once, or once per instance frame (n > 0) into the same target. */
static void draw_all_frames(asp__prim_renderer *r, const asp__frame *frames, size_t n);

static void main_pass(asp__prim_renderer *r, enum asp__prim_pass pass)
{
    glUseProgram(r->programs[ASP__PROG_MAIN].id);
    glProgramUniform1i(r->programs[ASP__PROG_MAIN].id, r->uniforms[ASP__PROG_MAIN][PU_PASS], (GLint)pass);
}

static void depth_pass(asp__prim_renderer *r, int prog, float offset, float alpha_ref)
{
    GLuint id = r->programs[prog].id;
    glProgramUniform1f(id, r->uniforms[prog][PU_OFFSET], offset);
    glProgramUniform1f(id, r->uniforms[prog][PU_ALPHA_REF], alpha_ref);
    glUseProgram(id);
}

static void draw_all(asp__prim_renderer *r)
{
    glBindVertexArray(r->identity_vao.id);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)r->count);
}

static void draw_all_frames(asp__prim_renderer *r, const asp__frame *frames, size_t n)
{
    if (!n) {
        draw_all(r);
        return;
    }
    for (size_t k = 0; k < n; k++) {
        frame_uniforms(r, &frames[k]);
        draw_all(r);
    }
}

static void draw_run(asp__prim_renderer *r, const asp__run *run)
{
    glBindVertexArray(r->vao.id);
    // the base instance offsets the instanced a_id fetch into the frame's order
    glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)run->count, run->first);
}

static void additive(void)
{
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
}

/* Issues the runs on the seed target: colour runs add, lock runs write alpha-tested depth. */
static void draw_runs(asp__prim_renderer *r, size_t nruns)
{
    for (size_t k = 0; k < nruns; k++) {
        const asp__run *run = &r->runs[k];
        switch (run->kind) {
        case ASP__RUN_ADD:
            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glDepthMask(GL_FALSE);
            additive();
            main_pass(r, ASP__PASS_ADD);
            break;
        case ASP__RUN_LOCK:
            glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
            glDepthMask(GL_TRUE);
            glDisable(GL_BLEND);
            depth_pass(r, ASP__PROG_DEPTH, 0.0f, r->opt.alpha_ref);
            break;
        case ASP__RUN_CLEAR:
            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glDisable(GL_BLEND);
            main_pass(r, ASP__PASS_CLEAR);
            break;
        case ASP__RUN_DARKEN:
            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_REVERSE_SUBTRACT); // dst - src, clamped at 0 by the unorm target
            glBlendFunc(GL_ONE, GL_ONE);
            main_pass(r, ASP__PASS_DARKEN);
            break;
        }
        draw_run(r, run);
    }
    glBlendEquation(GL_FUNC_ADD);
}

/* The seeds' methods on the clamped fixed-point target. */
static void draw_seed(asp__prim_renderer *r, const asp__frame *f)
{
    const asp_prim_render_options *o = &r->opt;
    static const GLfloat zero[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->t.seed_fbo.id);
    glClearNamedFramebufferfv(r->t.seed_fbo.id, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(r->t.seed_fbo.id, GL_DEPTH, 0, &far_depth);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    size_t nruns = 0, no = 0;
    switch (o->method) {
    case ASP_PRIM_RENDER_OVERLAP:
        no = overlap_runs(r, f->eye, &nruns);
        glNamedBufferSubData(r->order_buffer.id, 0, (GLsizeiptr)(no * sizeof(uint32_t)), r->order);
        // back faces are never drawn: the cause of the thesis's dark spots (5.3.1, Fig. 5.7); the
        // pseudocode (journal Fig. 10) adds every neighbour of a front face, back faces included
        if (!(o->flags & ASP_PRIM_RENDER_OVERLAP_BACKFACES)) {
            glEnable(GL_CULL_FACE);
            glCullFace(GL_BACK);
        }
        draw_runs(r, nruns);
        break;
    case ASP_PRIM_RENDER_TWO_PASS:
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        depth_pass(r, ASP__PROG_DEPTH, o->depth_window, o->alpha_ref);
        draw_all(r);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_FALSE);
        additive();
        main_pass(r, ASP__PASS_ADD);
        draw_all(r);
        break;
    case ASP_PRIM_RENDER_DARK_BACKFACE:
    case ASP_PRIM_RENDER_DARK_BACKFACE_SOFT:
        no = backface_runs(r, f->eye, o->method == ASP_PRIM_RENDER_DARK_BACKFACE_SOFT, &nruns);
        glNamedBufferSubData(r->order_buffer.id, 0, (GLsizeiptr)(no * sizeof(uint32_t)), r->order);
        glDisable(GL_DEPTH_TEST); // a painter's algorithm: the order decides (thesis 4.4.3)
        draw_runs(r, nruns);
        break;
    case ASP_PRIM_RENDER_BLEND_ALL:
        glDisable(GL_DEPTH_TEST);
        additive();
        main_pass(r, ASP__PASS_ADD);
        draw_all(r);
        break;
    case ASP_PRIM_RENDER_NO_BLEND:
    case ASP_PRIM_RENDER_POLYGONS:
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
        main_pass(r, ASP__PASS_OPAQUE);
        if (o->method == ASP_PRIM_RENDER_POLYGONS)
            glProgramUniform1f(r->programs[ASP__PROG_MAIN].id, r->uniforms[ASP__PROG_MAIN][PU_ALPHA_REF],
                               POLYGON_ALPHA_REF);
        draw_all(r);
        break;
    default:
        break;
    }
    glDisable(GL_CULL_FACE);
}

/*
 * normalized and prefix: front layer, selected sums, then the division in the resolve. With
 * frames (n > 0), every instance's front layer first, then every instance's sums, so instances
 * that touch blend as one surface and one clear and one resolve serve them all.
 */
static void draw_normalized(asp__prim_renderer *r, int prefix, const asp__frame *frames, size_t n)
{
    const asp_prim_render_options *o = &r->opt;
    static const GLfloat zero[4] = {0, 0, 0, 0};
    static const GLuint none[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    glClearNamedFramebufferuiv(r->t.front_fbo.id, GL_COLOR, 0, none);
    glClearNamedFramebufferfv(r->t.front_fbo.id, GL_DEPTH, 0, &far_depth);
    glClearNamedFramebufferfv(r->t.accum_fbo.id, GL_COLOR, 0, zero);

    // pass 1: the front-most alpha-tested layer (with its primitive's id for prefix)
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->t.front_fbo.id);
    /*
     * Back faces are left out of both passes: on a closed surface they are
     * the far side, and at a silhouette they would add a darker, differently
     * lit layer (the octahedron's SSIM against its points: 0.88 with them,
     * 0.91 without). The division makes up for the weight they would add.
     */
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(prefix, prefix, prefix, prefix);
    depth_pass(r, prefix ? ASP__PROG_ID : ASP__PROG_DEPTH, 0.0f, o->alpha_ref);
    draw_all_frames(r, frames, n);

    // pass 2: add what lies within the window behind it (and, for prefix, belongs to its neighbourhood)
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->t.accum_fbo.id);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_FALSE);
    glDisable(GL_DEPTH_TEST);
    additive();
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, r->t.depth);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_ID, r->t.id);
    GLuint mp = r->programs[ASP__PROG_MAIN].id;
    glProgramUniform1i(mp, r->uniforms[ASP__PROG_MAIN][PU_SELECT], prefix ? ASP__SELECT_PREFIX : ASP__SELECT_WINDOW);
    // the opacity is applied after the division, where it is not divided away
    glProgramUniform1f(mp, r->uniforms[ASP__PROG_MAIN][PU_TRANSPARENCY], 1.0f);
    main_pass(r, ASP__PASS_ADD);
    draw_all_frames(r, frames, n);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, 0);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_ID, 0);
    glDisable(GL_CULL_FACE);
}

static void resolve(asp__prim_renderer *r, GLuint caller_fbo, int normalize)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, caller_fbo);
    if (normalize) {
        // the front layer's depth goes along (LEQUAL: a cleared buffer takes every pixel, as before),
        // so what the caller drew nearer stays in front: instances of a scene compose (issue 18)
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LEQUAL);
        glDepthMask(GL_TRUE);
        glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, r->t.depth);
    } else {
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
    }
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    // premultiplied "over" the caller's background
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    GLuint p = r->programs[ASP__PROG_RESOLVE].id;
    glProgramUniform1i(p, r->uniforms[ASP__PROG_RESOLVE][PU_NORMALIZE], normalize);
    glProgramUniform1f(p, r->uniforms[ASP__PROG_RESOLVE][PU_TRANSPARENCY], r->opt.transparency);
    glBindTextureUnit(ASP__PRIM_UNIT_ACCUM, normalize ? r->t.accum_float : r->t.accum_fixed);
    glUseProgram(p);
    glBindVertexArray(r->empty_vao.id);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTextureUnit(ASP__PRIM_UNIT_ACCUM, 0);
    glBindTextureUnit(ASP__PRIM_UNIT_FRONT_DEPTH, 0);
    glDisable(GL_BLEND);
    glDepthFunc(GL_LESS);
}

/*
 * Journal Fig. 12b: the support rectangles' edges, hidden where the drawn
 * surface (alpha-tested, or the whole rectangle for polygons) lies in front.
 */
static void outlines(asp__prim_renderer *r)
{
    float ref = r->opt.method == ASP_PRIM_RENDER_POLYGONS ? POLYGON_ALPHA_REF : r->opt.alpha_ref;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    depth_pass(r, ASP__PROG_DEPTH, 0.0f, ref);
    draw_all(r);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthFunc(GL_LEQUAL);
    GLuint mp = r->programs[ASP__PROG_MAIN].id;
    glProgramUniform1i(mp, r->uniforms[ASP__PROG_MAIN][PU_CORNERS], 1);
    main_pass(r, ASP__PASS_OUTLINE);
    glBindVertexArray(r->identity_vao.id);
    glDrawArraysInstanced(GL_LINE_LOOP, 0, 4, (GLsizei)r->count);
    glProgramUniform1i(mp, r->uniforms[ASP__PROG_MAIN][PU_CORNERS], 0);
}


int asp__prim_draw(asp__prim_renderer *r, const asp__frame *f, asp_error *err)
{
    asp_gl_context *gl = r->base.gl;
    GLint caller = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller);
    int rc = targets_ensure(gl, &r->t, f->width, f->height, err);
    if (rc)
        return rc;
    set_uniforms(r, f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_PRIMS, r->prim_buffer.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_NEIGHBOURS, r->neighbour_buffer.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_CLIPS, r->clip_buffer.id);
    glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, r->atlas);
    glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, r->normal_atlas ? r->normal_atlas : r->atlas);
    int normalize = r->opt.method == ASP_PRIM_RENDER_NORMALIZED || r->opt.method == ASP_PRIM_RENDER_PREFIX;
    if (normalize)
        draw_normalized(r, r->opt.method == ASP_PRIM_RENDER_PREFIX, NULL, 0);
    else
        draw_seed(r, f);
    resolve(r, (GLuint)caller, normalize);
    if (r->opt.flags & ASP_PRIM_RENDER_OUTLINE)
        outlines(r);
    glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, 0);
    glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, 0);
    asp__gl_restore_state((GLuint)caller);
    return asp__gl_check(gl, "draw domain primitives", err);
}

/*
 * For the hybrid renderer (hybrid_renderer.c), which blends these primitives
 * with point splats in its own normalised accumulation: the two passes of
 * the normalised sum as the two-pass form (thesis 4.4.2) draws them, into
 * whatever framebuffer and depth/blend state the caller set.
 */
void asp__prim_hybrid_begin(asp__prim_renderer *r, const asp__frame *f)
{
    set_uniforms(r, f);
    GLuint mp = r->programs[ASP__PROG_MAIN].id;
    // the weights are divided later, by the hybrid's resolve
    glProgramUniform1f(mp, r->uniforms[ASP__PROG_MAIN][PU_TRANSPARENCY], 1.0f);
    glProgramUniform1i(mp, r->uniforms[ASP__PROG_MAIN][PU_DOMAIN_COLORS], 0);
}

size_t asp__prim_hybrid_keep(asp__prim_renderer *r, const uint8_t *replaced)
{
    size_t n = 0;
    for (size_t i = 0; i < r->count; i++)
        if (!replaced[i])
            r->order[n++] = (uint32_t)i;
    // the hybrid always draws the normalised sums, which never rewrite the order buffer
    if (n)
        glNamedBufferSubData(r->order_buffer.id, 0, (GLsizeiptr)(n * sizeof(uint32_t)), r->order);
    return n;
}

void asp__prim_hybrid_pass(asp__prim_renderer *r, size_t kept, int depth_only)
{
    if (kept == 0)
        return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_PRIMS, r->prim_buffer.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_NEIGHBOURS, r->neighbour_buffer.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_CLIPS, r->clip_buffer.id);
    glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, r->atlas);
    glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, r->normal_atlas ? r->normal_atlas : r->atlas);
    // back faces culled, as in normalized (draw_normalized explains why)
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    if (depth_only)
        depth_pass(r, ASP__PROG_DEPTH, r->opt.depth_window, r->opt.alpha_ref);
    else
        main_pass(r, ASP__PASS_ADD);
    glBindVertexArray(r->vao.id);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)kept);
    glDisable(GL_CULL_FACE);
    glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, 0);
    glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, 0);
}

/* Sort key of an instance: its frame's origin distance from the eye (the model's translation). */
typedef struct instance_key {
    float d2;
    size_t i;
} instance_key;

static int far_first(const void *a, const void *b)
{
    const instance_key *x = a, *y = b;
    return x->d2 != y->d2 ? (x->d2 > y->d2 ? -1 : 1) : (x->i > y->i) - (x->i < y->i);
}

int asp__prim_draw_instances(asp__prim_renderer *r, const asp__frame *f, const float *models, size_t count,
                             asp_error *err)
{
    asp_gl_context *gl = r->base.gl;
    asp__frame *frames = asp_alloc(&gl->actx, count * sizeof *frames);
    instance_key *keys = asp_alloc(&gl->actx, count * sizeof *keys);
    if (!frames || !keys) {
        asp_free(&gl->actx, frames);
        asp_free(&gl->actx, keys);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu primitive instances", count);
    }
    for (size_t i = 0; i < count; i++) {
        asp__frame_fold(f, models + 16 * i, &frames[i]);
        const float *m = models + 16 * i;
        float dx = m[12] - f->eye[0], dy = m[13] - f->eye[1], dz = m[14] - f->eye[2];
        keys[i] = (instance_key){dx * dx + dy * dy + dz * dz, i};
    }
    int rc = 0;
    // the normalised sums blend every instance in one accumulation; prefix selects by primitive id,
    // which instances share, and outlines and the seeds' methods draw their own passes per frame
    if (r->opt.method == ASP_PRIM_RENDER_NORMALIZED && !(r->opt.flags & ASP_PRIM_RENDER_OUTLINE)) {
        GLint caller = 0;
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller);
        rc = targets_ensure(gl, &r->t, f->width, f->height, err);
        if (!rc) {
            set_uniforms(r, f);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_PRIMS, r->prim_buffer.id);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_NEIGHBOURS, r->neighbour_buffer.id);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_CLIPS, r->clip_buffer.id);
            glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, r->atlas);
            glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, r->normal_atlas ? r->normal_atlas : r->atlas);
            draw_normalized(r, 0, frames, count);
            resolve(r, (GLuint)caller, 1);
            glBindTextureUnit(ASP__PRIM_UNIT_ATLAS, 0);
            glBindTextureUnit(ASP__PRIM_UNIT_NORMALS, 0);
            asp__gl_restore_state((GLuint)caller);
            rc = asp__gl_check(gl, "draw domain primitive instances", err);
        }
        r->base.count = count * r->count;
    } else {
        // one frame each, far to near: the seeds' methods paint without a depth test
        qsort(keys, count, sizeof *keys, far_first);
        for (size_t k = 0; k < count && !rc; k++)
            rc = asp__prim_draw(r, &frames[keys[k].i], err);
        r->base.count = count * r->count;
    }
    asp_free(&gl->actx, frames);
    asp_free(&gl->actx, keys);
    return rc;
}
