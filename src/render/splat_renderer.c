/*
 * Blended elliptical splats on the point-octree (Pajarola, Sainz, Guidotti
 * 2003, seed 001): the kernel psi_E of section 4.2 on each selected surfel's
 * ellipse, visibility splatting with an epsilon-z-buffer (5.3, Fig. 15),
 * additive blending of (psi * colour, psi) (eq. 10), per-pixel normalisation
 * (5.4, eq. 9) and Gouraud lighting with normal-cone offsets (5.2, Fig. 14).
 * Point splats may be cut by two clip planes at sharp creases (Botsch et al.
 * 2005 section 4.2, Zwicker et al. 2004 section 5).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/splat_internal.h"
#include "util/banned.h"

/*
 * One triangle per splat (section 5.2, Fig. 13): the equilateral triangle
 * around the kernel's support circle in ellipse coordinates, grown by 5% so
 * the support never touches an edge. Otherwise a fragment on the rim could be
 * rasterised by the offset triangle of pass 1 and not by the plain one of
 * pass 2 (or the reverse), leaving a pixel with depth but no weight.
 * u_lighting: 0 Gouraud with cone offsets, 1 per pixel, 2 flat, 3 unlit.
 */
static const char *vertex_src =
    "#version 450 core\n" ASP__LOD_GLSL
    "uniform float u_epsilon;\n"
    "uniform int u_eps_uniform;\n"
    "uniform float u_support;\n"
    "uniform float u_radius_scale;\n"
    "uniform uint u_node_count;\n"
    "uniform int u_has_colors;\n"
    "uniform vec4 u_default_color;\n"
    "uniform int u_lighting;\n"
    "uniform int u_unoriented;\n"
    "uniform int u_has_clip;\n"
    "layout(std430, binding = 3) readonly buffer Clips { vec4 clips[]; };\n"
    "out vec2 v_local;\n"
    "out vec3 v_color;\n"
    "out vec3 v_normal;\n"
    "flat out vec3 v_clip0;\n"
    "flat out vec3 v_clip1;\n"
    "const vec2 corners[3] = vec2[3](vec2(-1.7320508, -1.0), vec2(1.7320508, -1.0), vec2(0.0, 2.0));\n"
    // plane (n, d) on the ellipse p(q) = c + q.x a u + q.y b v as the line n.p(q) + d = dot(line, vec3(q, 1))
    "vec3 clip_line(vec4 pl, splat s, float a, float b) {\n"
    "    return vec3(a * dot(pl.xyz, s.u), b * dot(pl.xyz, s.v), dot(pl.xyz, s.c) + pl.w);\n"
    "}\n"
    "void main() {\n"
    "    uint id = ids[gl_InstanceID];\n"
    "    splat s = read_splat(id);\n"
    "    float a = s.a * u_radius_scale, b = s.b * u_radius_scale;\n"
    "    v_clip0 = vec3(0.0, 0.0, 1.0);\n"
    "    v_clip1 = vec3(0.0, 0.0, 1.0);\n"
    "    if (u_has_clip != 0 && id >= u_node_count) {\n"
    "        uint k = 2u * (id - u_node_count);\n"
    "        v_clip0 = clip_line(clips[k], s, a, b);\n"
    "        v_clip1 = clip_line(clips[k + 1u], s, a, b);\n"
    "    }\n"
    "    vec2 q = corners[gl_VertexID] * (1.05 * u_support);\n"
    "    vec3 off = q.x * a * s.u + q.y * b * s.v;\n"
    "    vec3 p = s.c + off;\n"
    // Fig. 15: pass 1 moves the corners away from the eye along their projectors
    "    vec3 ray = p - u_eye;\n"
    "    if (u_epsilon > 0.0 && dot(ray, ray) > 0.0)\n"
    "        p += (u_epsilon * (u_eps_uniform != 0 ? 1.0 : a)) * normalize(ray);\n"
    "    v_local = q;\n"
    "    gl_Position = u_proj * (u_view * vec4(p, 1.0));\n"
    // PCA normals have no sign: face them to the eye. Oriented normals stay, so that blended
    // normals of the front and back sides at a silhouette do not cancel into a frontal one
    "    vec3 n = u_unoriented != 0 && dot(s.n, u_eye - s.c) < 0.0 ? -s.n : s.n;\n"
    "    float theta = id < u_node_count && u_lighting < 2 ? cones[id] : 0.0;\n"
    "    vec3 d = dot(off, off) > 0.0 ? normalize(off) : vec3(0.0);\n"
    "    vec3 nc = normalize(cos(theta) * n + sin(theta) * d);\n"
    "    v_normal = mat3(u_view) * nc;\n"
    "    vec4 col = u_has_colors != 0 ? unpackUnorm4x8(s.color) : u_default_color;\n"
    "    vec3 lin = srgb_to_linear(col.rgb);\n"
    "    float shade = 0.25 + 0.75 * abs(dot(normalize(v_normal), u_light));\n"
    "    v_color = u_lighting == 1 || u_lighting == 3 ? lin : lin * shade;\n"
    "}\n";

/*
 * The support test per sample when multisampling (as the disc renderer: the
 * shader runs at the pixel centre, which may lie outside a small splat), so
 * both passes cover exactly the same samples. The clip planes are lines in
 * the ellipse coordinates v_local (the position is affine in them), tested at
 * the same positions, so both passes also clip the same samples.
 */
#define COVERAGE_GLSL                                                                            \
    "flat in vec3 v_clip0;\n"                                                                    \
    "flat in vec3 v_clip1;\n"                                                                    \
    "bool inside(vec2 q, float s2) {\n"                                                          \
    "    vec3 h = vec3(q, 1.0);\n"                                                               \
    "    return dot(q, q) <= s2 && dot(v_clip0, h) >= 0.0 && dot(v_clip1, h) >= 0.0;\n"          \
    "}\n"                                                                                        \
    "int coverage() {\n"                                                                         \
    "    float s2 = u_support * u_support;\n"                                                    \
    "    int mask = 0;\n"                                                                        \
    "    if (gl_NumSamples > 1) {\n"                                                             \
    "        for (int i = 0; i < gl_NumSamples; i++) {\n"                                        \
    "            if (inside(interpolateAtSample(v_local, i), s2))\n"                             \
    "                mask |= 1 << i;\n"                                                          \
    "        }\n"                                                                                \
    "    } else if (inside(v_local, s2)) {\n"                                                    \
    "        mask = -1;\n"                                                                       \
    "    }\n"                                                                                    \
    "    return mask;\n"                                                                         \
    "}\n"

/* Pass 1 (section 5.3): depth only, the alpha test shaping the ellipse. */
static const char *depth_fragment_src =
    "#version 450 core\n"
    "in vec2 v_local;\n"
    "uniform float u_support;\n" COVERAGE_GLSL
    "void main() {\n"
    "    int mask = coverage();\n"
    "    if (mask == 0)\n"
    "        discard;\n"
    "    gl_SampleMask[0] = mask;\n"
    "}\n";

/*
 * Pass 2: psi_E (eq. 12) at the fragment's ellipse radius r, in units of the
 * semi-axes (asp_splat_renderer_desc explains b). A sample inside the support
 * whose pixel centre is outside gets the rim weight. Opaque mode writes the
 * shaded colour straight into the caller's framebuffer instead.
 */
static const char *blend_fragment_src =
    "#version 450 core\n"
    "in vec2 v_local;\n"
    "in vec3 v_color;\n"
    "in vec3 v_normal;\n"
    "uniform float u_support;\n"
    "uniform float u_ka, u_kb, u_kn, u_kscale, u_ksigma;\n"
    "uniform int u_kgauss;\n"
    "uniform int u_opaque;\n"
    "layout(location = 0) out vec4 o_accum;\n"
    "layout(location = 1) out vec4 o_normal;\n" COVERAGE_GLSL
    "void main() {\n"
    "    int mask = coverage();\n"
    "    if (mask == 0)\n"
    "        discard;\n"
    "    gl_SampleMask[0] = mask;\n"
    "    if (u_opaque != 0) {\n"
    "        o_accum = vec4(v_color, 1.0);\n"
    "        o_normal = vec4(0.0);\n"
    "        return;\n"
    "    }\n"
    // the same formula as asp_splat_kernel_weight (kernel_weight below)
    "    float r = min(length(v_local), u_support) * u_kscale;\n"
    "    float w = u_kgauss != 0 ? exp(-r * r / (2.0 * u_ksigma * u_ksigma)) : exp(-u_ka * pow(r / u_kb, u_kn));\n"
    "    o_accum = vec4(w * v_color, w);\n"
    "    o_normal = vec4(w * v_normal, w);\n"
    "}\n";

static const char *resolve_vertex_src =
    "#version 450 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

/*
 * Pass 3 (section 5.4): colour = sum(psi c) / sum(psi); with per-pixel
 * lighting the blended normal is lit here. Pixels without weight keep the
 * caller's background. The pass-1 depth goes along so the image has a depth
 * buffer like the other renderers'. Multisampled targets are resolved per
 * sample (gl_SampleID), so silhouettes keep their antialiasing.
 */
#define RESOLVE_GLSL                                                                         \
    "uniform vec3 u_light;\n"                                                                \
    "uniform int u_pixel_light;\n"                                                           \
    "layout(location = 0) out vec4 o_color;\n"                                               \
    "void main() {\n"                                                                        \
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"                                                \
    "    vec4 acc = FETCH(u_accum);\n"                                                       \
    "    if (!(acc.a > 0.0))\n"                                                              \
    "        discard;\n"                                                                     \
    "    vec3 c = acc.rgb / acc.a;\n"                                                        \
    "    if (u_pixel_light != 0) {\n"                                                        \
    "        vec3 n = FETCH(u_normal).xyz;\n"                                                \
    "        float lambert = dot(n, n) > 0.0 ? abs(dot(normalize(n), u_light)) : 1.0;\n"     \
    "        c *= 0.25 + 0.75 * lambert;\n"                                                  \
    "    }\n"                                                                                \
    "    gl_FragDepth = FETCH(u_depth).r;\n"                                                 \
    "    o_color = vec4(c, 1.0);\n"                                                          \
    "}\n"

static const char *resolve_fragment_src[2] = {
    "#version 450 core\n"
    "#define FETCH(t) texelFetch(t, p, 0)\n"
    "layout(binding = 0) uniform sampler2D u_accum;\n"
    "layout(binding = 1) uniform sampler2D u_normal;\n"
    "layout(binding = 2) uniform sampler2D u_depth;\n" RESOLVE_GLSL,
    "#version 450 core\n"
    "#define FETCH(t) texelFetch(t, p, gl_SampleID)\n"
    "layout(binding = 0) uniform sampler2DMS u_accum;\n"
    "layout(binding = 1) uniform sampler2DMS u_normal;\n"
    "layout(binding = 2) uniform sampler2DMS u_depth;\n" RESOLVE_GLSL};

enum { U_EPSILON = ASP__LOD_U_COUNT, U_SUPPORT, U_RADIUS_SCALE, U_NODE_COUNT, U_HAS_COLORS, U_DEFAULT_COLOR,
       U_LIGHTING, U_KA, U_KB, U_KN, U_OPAQUE, U_UNORIENTED, U_HAS_CLIP, U_KSCALE, U_KSIGMA, U_KGAUSS,
       U_EPS_UNIFORM, U_COUNT };
static const char *uniform_names[U_COUNT] = {ASP__LOD_UNIFORM_NAMES, "u_epsilon", "u_support", "u_radius_scale",
                                             "u_node_count", "u_has_colors", "u_default_color", "u_lighting", "u_ka",
                                             "u_kb", "u_kn", "u_opaque", "u_unoriented", "u_has_clip",
                                             "u_kscale", "u_ksigma", "u_kgauss", "u_eps_uniform"};
enum { PROG_DEPTH, PROG_BLEND, PROG_COUNT };

/* The float accumulation target of passes 1 and 2, kept while size and samples stay. */
typedef struct accum_target {
    uint32_t width, height, samples;
    int with_normals;
    asp__gl_framebuffer fbo;
    GLuint color, normal, depth; /* textures */
} accum_target;

/* One instance of a draw_instances call: its frame and its cut's range in the instanced id buffer. */
typedef struct splat_instance {
    asp__frame frame;
    size_t first, count;
} splat_instance;

typedef struct splat_renderer {
    asp_renderer base; // first two members as asp__lod_renderer
    asp__lod lod;
    asp__gl_program programs[PROG_COUNT];
    GLint uniforms[PROG_COUNT][U_COUNT];
    asp__gl_program resolve[2]; // single-sample, multisample; built when first needed
    GLint resolve_light[2], resolve_pixel_light[2];
    asp__gl_vertex_array vao; // no attributes: everything comes from storage buffers
    asp__gl_buffer clips;     // 2 planes per point splat in hierarchy order; one zero plane pair without clipping
    int has_clip;
    accum_target acc;
    float ka, kb, kn, epsilon, support, radius_scale, kscale, ksigma;
    int kgauss, eps_uniform;
    asp_splat_lighting lighting;
    asp_splat_mode mode;
    /* draw_instances: every instance's cut side by side (ranges aligned for glBindBufferRange) */
    asp__gl_buffer inst_ids;
    size_t inst_ids_capacity; /* ids the GPU buffer holds */
    asp_index *inst_cut;      /* CPU copy, inst_cut_capacity ids */
    size_t inst_cut_capacity;
    splat_instance *insts;
    size_t insts_capacity;
} splat_renderer;

static void accum_release(accum_target *t)
{
    if (t->fbo.id)
        glDeleteFramebuffers(1, &t->fbo.id);
    GLuint tex[3] = {t->color, t->normal, t->depth};
    for (int i = 0; i < 3; i++)
        if (tex[i])
            glDeleteTextures(1, &tex[i]);
    memset(t, 0, sizeof *t);
}

static GLuint make_texture(uint32_t w, uint32_t h, uint32_t samples, GLenum format)
{
    GLuint tex = 0;
    if (samples > 1) {
        glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &tex);
        glTextureStorage2DMultisample(tex, (GLsizei)samples, format, (GLsizei)w, (GLsizei)h, GL_TRUE);
    } else {
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, format, (GLsizei)w, (GLsizei)h);
    }
    return tex;
}

/*
 * RGBA32F: the weights of a pixel can be as small as the rim weight times a
 * dark linear colour (1e-4 and less), and a 1M-point cut piles hundreds of
 * splats on a pixel of a distant view; half floats would lose the 8-bit result.
 */
static int accum_ensure(asp_gl_context *gl, accum_target *t, uint32_t w, uint32_t h, uint32_t samples,
                        int with_normals, asp_error *err)
{
    if (t->fbo.id && t->width == w && t->height == h && t->samples == samples && t->with_normals == with_normals)
        return 0;
    accum_release(t);
    asp__gl_clear_errors(gl);
    t->color = make_texture(w, h, samples, GL_RGBA32F);
    if (with_normals)
        t->normal = make_texture(w, h, samples, GL_RGBA16F);
    t->depth = make_texture(w, h, samples, GL_DEPTH_COMPONENT32F);
    glCreateFramebuffers(1, &t->fbo.id);
    glNamedFramebufferTexture(t->fbo.id, GL_COLOR_ATTACHMENT0, t->color, 0);
    if (with_normals)
        glNamedFramebufferTexture(t->fbo.id, GL_COLOR_ATTACHMENT1, t->normal, 0);
    glNamedFramebufferTexture(t->fbo.id, GL_DEPTH_ATTACHMENT, t->depth, 0);
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(t->fbo.id, with_normals ? 2 : 1, bufs);
    int rc = asp__gl_check(gl, "create the splat accumulation target", err);
    if (!rc) {
        GLenum status = glCheckNamedFramebufferStatus(t->fbo.id, GL_DRAW_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE)
            rc = asp_error_set(err, ASP_EGL, "cannot create the splat accumulation framebuffer: status 0x%04x",
                               (unsigned)status);
    }
    if (rc) {
        accum_release(t);
        return rc;
    }
    t->width = w;
    t->height = h;
    t->samples = samples;
    t->with_normals = with_normals;
    return 0;
}

static void splat_destroy(asp_renderer *base)
{
    splat_renderer *s = (splat_renderer *)base;
    accum_release(&s->acc);
    for (int i = 0; i < PROG_COUNT; i++)
        asp__gl_program_destroy(&s->programs[i]);
    for (int i = 0; i < 2; i++)
        asp__gl_program_destroy(&s->resolve[i]);
    if (s->vao.id)
        glDeleteVertexArrays(1, &s->vao.id);
    if (s->clips.id)
        glDeleteBuffers(1, &s->clips.id);
    if (s->inst_ids.id)
        glDeleteBuffers(1, &s->inst_ids.id);
    asp_free(&base->gl->actx, s->inst_cut);
    asp_free(&base->gl->actx, s->insts);
    asp__lod_renderer_free((asp__lod_renderer *)s);
}

static int lighting_code(const splat_renderer *s, const asp__frame *f)
{
    if (f->flags & ASP_RENDER_UNLIT)
        return 3;
    // per-pixel lighting needs the resolve pass; opaque splats have none, so they get Gouraud
    if (s->lighting == ASP_SPLAT_LIGHT_PIXEL && s->mode == ASP_SPLAT_OPAQUE)
        return 0;
    return (int)s->lighting;
}

static void set_frame_uniforms(splat_renderer *s, int prog, const asp__frame *f, float epsilon, int opaque)
{
    GLuint p = s->programs[prog].id;
    const GLint *u = s->uniforms[prog];
    asp__lod_frame_uniforms(p, u, f);
    glProgramUniform1f(p, u[U_EPSILON], epsilon);
    glProgramUniform1i(p, u[U_LIGHTING], lighting_code(s, f));
    glProgramUniform1i(p, u[U_OPAQUE], opaque);
}

static void draw_splats(splat_renderer *s, int prog)
{
    glUseProgram(s->programs[prog].id);
    glBindVertexArray(s->vao.id);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, (GLsizei)s->lod.count);
}

static int ensure_resolve(splat_renderer *s, int ms, asp_error *err)
{
    if (s->resolve[ms].id)
        return 0;
    int rc = asp__gl_program_create(s->base.gl, ms ? "splat resolve (multisample)" : "splat resolve",
                                    resolve_vertex_src, resolve_fragment_src[ms], &s->resolve[ms], err);
    if (rc)
        return rc;
    s->resolve_light[ms] = glGetUniformLocation(s->resolve[ms].id, "u_light");
    s->resolve_pixel_light[ms] = glGetUniformLocation(s->resolve[ms].id, "u_pixel_light");
    return 0;
}

/* Samples of the caller's draw framebuffer, which the accumulation target matches when it can. */
static uint32_t target_samples(const asp_gl_context *gl)
{
    GLint samples = 0, max_color = 1, max_depth = 1;
    glGetIntegerv(GL_SAMPLES, &samples);
    glGetIntegerv(GL_MAX_COLOR_TEXTURE_SAMPLES, &max_color);
    glGetIntegerv(GL_MAX_DEPTH_TEXTURE_SAMPLES, &max_depth);
    (void)gl;
    // a per-sample resolve needs equal counts; otherwise accumulate per pixel
    if (samples > 1 && samples <= max_color && samples <= max_depth)
        return (uint32_t)samples;
    return 1;
}


/*
 * One pass of the splats: the last cut with frame f, or with batch (n > 0) each instance's cut with
 * its own frame, all into the same target, so every instance's depth is down before any blends.
 */
static void draw_pass(splat_renderer *s, int prog, const asp__frame *f, float epsilon, const splat_instance *batch,
                      size_t n)
{
    if (!n) {
        set_frame_uniforms(s, prog, f, epsilon, 0);
        draw_splats(s, prog);
        return;
    }
    glUseProgram(s->programs[prog].id);
    glBindVertexArray(s->vao.id);
    for (size_t i = 0; i < n; i++) {
        if (!batch[i].count)
            continue;
        set_frame_uniforms(s, prog, &batch[i].frame, epsilon, 0);
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_IDS, s->inst_ids.id,
                          (GLintptr)(batch[i].first * sizeof(asp_index)),
                          (GLsizeiptr)(batch[i].count * sizeof(asp_index)));
        glDrawArraysInstanced(GL_TRIANGLES, 0, 3, (GLsizei)batch[i].count);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_IDS, s->lod.ids.id);
}

static int draw_blended(splat_renderer *s, const asp__frame *f, GLint caller_fbo, const splat_instance *batch,
                        size_t nbatch, asp_error *err)
{
    asp_gl_context *gl = s->base.gl;
    int pixel_light = lighting_code(s, f) == 1;
    uint32_t samples = target_samples(gl);
    int ms = samples > 1;
    int rc = accum_ensure(gl, &s->acc, f->width, f->height, samples, pixel_light, err);
    if (!rc)
        rc = ensure_resolve(s, ms, err);
    if (rc)
        return rc;
    static const GLfloat zero[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    // clears obey the write masks
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glClearNamedFramebufferfv(s->acc.fbo.id, GL_COLOR, 0, zero);
    if (pixel_light)
        glClearNamedFramebufferfv(s->acc.fbo.id, GL_COLOR, 1, zero);
    glClearNamedFramebufferfv(s->acc.fbo.id, GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, s->acc.fbo.id);

    // pass 1: the epsilon-offset depth of the visible surface
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    draw_pass(s, PROG_DEPTH, f, s->epsilon, batch, nbatch);

    // pass 2: every splat within epsilon of it adds (psi c, psi); depth read-only
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    draw_pass(s, PROG_BLEND, f, 0.0f, batch, nbatch);

    // pass 3: normalise into the caller's framebuffer
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)caller_fbo);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    GLuint rp = s->resolve[ms].id;
    glProgramUniform3fv(rp, s->resolve_light[ms], 1, f->light_eye);
    glProgramUniform1i(rp, s->resolve_pixel_light[ms], pixel_light);
    glBindTextureUnit(0, s->acc.color);
    glBindTextureUnit(1, pixel_light ? s->acc.normal : s->acc.color);
    glBindTextureUnit(2, s->acc.depth);
    glUseProgram(rp);
    glBindVertexArray(s->vao.id);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    for (GLuint unit = 0; unit < 3; unit++)
        glBindTextureUnit(unit, 0);
    return 0;
}

static int splat_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    splat_renderer *s = (splat_renderer *)base;
    GLint caller_fbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller_fbo);
    int rc = asp__lod_select((asp__lod_renderer *)s, f, err);
    if (rc)
        return rc;
    if (s->lod.count == 0)
        return 0; // everything culled: the background stays
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_CLIPS, s->clips.id);
    if (s->mode == ASP_SPLAT_OPAQUE) {
        set_frame_uniforms(s, PROG_BLEND, f, 0.0f, 1);
        draw_splats(s, PROG_BLEND);
    } else {
        rc = draw_blended(s, f, caller_fbo, NULL, 0, err);
    }
    asp__gl_restore_state((GLuint)caller_fbo);
    if (rc)
        return rc;
    return asp__gl_check(base->gl, "draw splats", err);
}

/* Grows *p (elem bytes each) to hold need entries; contents kept. */
static int grow(asp_context *a, void **p, size_t *cap, size_t need, size_t elem, asp_error *err)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 64;
    while (n < need)
        n *= 2;
    void *q = asp_alloc(a, n * elem);
    if (!q)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu splat instances' cuts", need);
    if (*p)
        memcpy(q, *p, *cap * elem);
    asp_free(a, *p);
    *p = q;
    *cap = n;
    return 0;
}

/*
 * Selects every instance's cut (each with its own view: far instances get coarse cuts) into one id
 * buffer, ranges aligned to GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT so each binds on its own.
 */
static int select_instances(splat_renderer *s, const asp__frame *f, const float *models, size_t count,
                            size_t *total, asp_error *err)
{
    asp_context *a = &s->base.gl->actx;
    GLint align_bytes = 16;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align_bytes);
    size_t align = align_bytes > (GLint)sizeof(asp_index) ? (size_t)align_bytes / sizeof(asp_index) : 1;
    int rc = grow(a, (void **)&s->insts, &s->insts_capacity, count, sizeof *s->insts, err);
    size_t used = 0;
    for (size_t i = 0; !rc && i < count; i++) {
        splat_instance *in = &s->insts[i];
        asp__frame_fold(f, models + 16 * i, &in->frame);
        rc = asp__lod_select((asp__lod_renderer *)s, &in->frame, err);
        if (rc)
            break;
        in->first = (used + align - 1) / align * align;
        in->count = s->lod.count;
        rc = grow(a, (void **)&s->inst_cut, &s->inst_cut_capacity, in->first + in->count, sizeof *s->inst_cut, err);
        if (!rc && in->count)
            memcpy(s->inst_cut + in->first, s->lod.cut, in->count * sizeof *s->inst_cut);
        used = in->first + in->count;
    }
    if (rc)
        return rc;
    if (used > s->inst_ids_capacity) {
        if (s->inst_ids.id)
            glDeleteBuffers(1, &s->inst_ids.id);
        s->inst_ids_capacity = used + used / 2;
        glCreateBuffers(1, &s->inst_ids.id);
        glNamedBufferData(s->inst_ids.id, (GLsizeiptr)(s->inst_ids_capacity * sizeof(asp_index)), NULL,
                          GL_STREAM_DRAW);
    }
    if (used)
        glNamedBufferSubData(s->inst_ids.id, 0, (GLsizeiptr)(used * sizeof(asp_index)), s->inst_cut);
    *total = used;
    return asp__gl_check(s->base.gl, "upload the splat instances' cuts", err);
}

/*
 * Every instance in one accumulation (seed 001 section 5): all depth passes, then all blend passes,
 * then one normalisation, so touching instances blend and occlude as one surface set, and the
 * full-screen clear and resolve are paid once, not per instance. Opaque splats are depth-tested
 * alone: one ordinary draw per instance composes.
 */
static int splat_draw_instances(asp_renderer *base, const asp__frame *f, const float *models, size_t count,
                                asp_error *err)
{
    splat_renderer *s = (splat_renderer *)base;
    if (s->mode == ASP_SPLAT_OPAQUE) {
        size_t drawn = 0;
        for (size_t i = 0; i < count; i++) {
            asp__frame fi;
            asp__frame_fold(f, models + 16 * i, &fi);
            int rc = splat_draw(base, &fi, err);
            if (rc)
                return rc;
            drawn += base->count;
        }
        base->count = drawn;
        return 0;
    }
    GLint caller_fbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller_fbo);
    size_t used = 0;
    int rc = select_instances(s, f, models, count, &used, err);
    if (rc)
        return rc;
    size_t drawn = 0;
    for (size_t i = 0; i < count; i++)
        drawn += s->insts[i].count;
    base->count = drawn;
    if (!drawn)
        return 0; // everything culled: the background stays
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_CLIPS, s->clips.id);
    rc = draw_blended(s, f, caller_fbo, s->insts, count, err);
    asp__gl_restore_state((GLuint)caller_fbo);
    if (rc)
        return rc;
    return asp__gl_check(base->gl, "draw splat instances", err);
}

static const asp__renderer_vtable splat_vtable = {.name = "splat",
                                                 .draw = splat_draw,
                                                 .destroy = splat_destroy,
                                                 .set_lod = asp__lod_set_lod,
                                                 .stats = asp__lod_stats,
                                                 .draw_instances = splat_draw_instances,
                                                 .set_budget = asp__lod_set_budget};

static void set_static_uniforms(splat_renderer *s)
{
    for (int i = 0; i < PROG_COUNT; i++) {
        GLuint p = s->programs[i].id;
        const GLint *u = s->uniforms[i];
        glProgramUniform1f(p, u[U_SUPPORT], s->support);
        glProgramUniform1f(p, u[U_RADIUS_SCALE], s->radius_scale);
        glProgramUniform1ui(p, u[U_NODE_COUNT], (GLuint)s->lod.nodes);
        glProgramUniform1i(p, u[U_HAS_COLORS], s->lod.has_colors);
        glProgramUniform4fv(p, u[U_DEFAULT_COLOR], 1, s->lod.default_color);
        glProgramUniform1f(p, u[U_KA], s->ka);
        glProgramUniform1f(p, u[U_KB], s->kb);
        glProgramUniform1f(p, u[U_KN], s->kn);
        glProgramUniform1i(p, u[U_UNORIENTED], (asp_hier_flags(s->lod.hier) & ASP_HIER_UNORIENTED) != 0);
        glProgramUniform1i(p, u[U_HAS_CLIP], s->has_clip);
        glProgramUniform1f(p, u[U_KSCALE], s->kscale);
        glProgramUniform1f(p, u[U_KSIGMA], s->ksigma);
        glProgramUniform1i(p, u[U_KGAUSS], s->kgauss);
        glProgramUniform1i(p, u[U_EPS_UNIFORM], s->eps_uniform);
    }
}

static int check_desc(const asp_splat_renderer_desc *d, asp_error *err)
{
    const struct {
        const char *name;
        float v;
    } opts[] = {{"kernel_a", d->kernel_a}, {"kernel_b", d->kernel_b}, {"kernel_n", d->kernel_n},
                {"kernel_sigma", d->kernel_sigma},
                {"tolerance", d->tolerance}, {"radius_scale", d->radius_scale}};
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++) {
        int rc = asp__lod_check_option("splat", opts[i].name, opts[i].v, err);
        if (rc)
            return rc;
    }
    if (!isfinite(d->epsilon))
        return asp_error_set(err, ASP_EINVAL, "splat renderer option epsilon = %g is not finite", (double)d->epsilon);
    if ((unsigned)d->lighting > ASP_SPLAT_LIGHT_FLAT)
        return asp_error_set(err, ASP_EINVAL, "unknown splat lighting mode %d (expected 0..2)", (int)d->lighting);
    if ((unsigned)d->mode > ASP_SPLAT_OPAQUE)
        return asp_error_set(err, ASP_EINVAL, "unknown splat mode %d (expected 0..1)", (int)d->mode);
    if ((unsigned)d->kernel > ASP_SPLAT_KERNEL_PSI_G)
        return asp_error_set(err, ASP_EINVAL, "unknown splat kernel %d (expected 0..1)", (int)d->kernel);
    return 0;
}

/* The kernel constants of desc, shared by the blend shader's uniforms and asp_splat_kernel_weight. */
typedef struct kernel_params {
    float ka, kb, kn, sigma, scale, support;
    int gauss;
} kernel_params;

static void kernel_params_of(const asp_splat_renderer_desc *d, kernel_params *k)
{
    k->ka = d->kernel_a > 0 ? d->kernel_a : 6.0f;
    k->kb = d->kernel_b > 0 ? d->kernel_b : 1.5f;
    k->kn = d->kernel_n > 0 ? d->kernel_n : 3.0f;
    k->sigma = d->kernel_sigma > 0 ? d->kernel_sigma : 0.5f;
    k->gauss = d->kernel == ASP_SPLAT_KERNEL_PSI_G;
    if (d->flags & ASP_SPLAT_KERNEL_RIM_AT_B) {
        // seed 001 Fig. 11: the ellipse is the kernel's disc of radius b
        k->scale = k->kb;
        k->support = 1.0f;
    } else {
        // the ellipse is the surfel's support (4.1); b < 1 narrows it to the kernel's own
        k->scale = 1.0f;
        k->support = fminf(k->kb, 1.0f);
    }
}

float asp_splat_kernel_weight(const asp_splat_renderer_desc *desc, float r)
{
    static const asp_splat_renderer_desc zero_desc;
    const asp_splat_renderer_desc *d = desc ? desc : &zero_desc;
    const float v[4] = {d->kernel_a, d->kernel_b, d->kernel_n, d->kernel_sigma};
    for (int i = 0; i < 4; i++)
        if (!(v[i] >= 0) || !isfinite(v[i]))
            return NAN;
    if (!(r >= 0) || !isfinite(r) || (unsigned)d->kernel > ASP_SPLAT_KERNEL_PSI_G)
        return NAN;
    kernel_params k;
    kernel_params_of(d, &k);
    float rk = fminf(r, k.support) * k.scale;
    return k.gauss ? expf(-rk * rk / (2.0f * k.sigma * k.sigma)) : expf(-k.ka * powf(rk / k.kb, k.kn));
}

float asp_render_tolerance_from_area(double percent, uint32_t width, uint32_t height)
{
    if (!(percent > 0) || !isfinite(percent))
        return 0.0f;
    double area = percent / 100.0 * (double)width * (double)height;
    return (float)(2.0 * sqrt(area / 3.14159265358979323846));
}

static int check_clip_planes(const float *planes, size_t points, asp_error *err)
{
    for (size_t i = 0; planes && i < 8 * points; i++)
        if (!isfinite(planes[i]))
            return asp_error_set(err, ASP_EFORMAT, "point %zu: clip plane %zu value %zu is not finite", i / 8,
                                 i % 8 / 4, i % 4);
    return 0;
}

/*
 * The clip planes in hierarchy order (point splat node_count + j reads pair
 * j), from planes indexed by input point; without planes one zero pair, so
 * the storage binding is never empty. gl must be current.
 */
static int upload_clips(splat_renderer *s, const float *planes, asp_error *err)
{
    asp_gl_context *gl = s->base.gl;
    size_t n = planes ? s->lod.points : 1;
    float *buf = asp_calloc(&gl->actx, n, 8 * sizeof(float));
    if (!buf)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the clip planes of %zu splats", n);
    if (planes) {
        const asp_hier_splat *sp = asp_hier_splats(s->lod.hier) + s->lod.nodes;
        for (size_t j = 0; j < n; j++)
            // a loaded hierarchy's index is checked on load; stay safe anyway: no clip for a stray index
            if (sp[j].index < n)
                memcpy(buf + 8 * j, planes + 8 * (size_t)sp[j].index, 8 * sizeof(float));
    }
    asp__gl_clear_errors(gl);
    glCreateBuffers(1, &s->clips.id);
    glNamedBufferStorage(s->clips.id, (GLsizeiptr)(n * 8 * sizeof(float)), buf, 0);
    asp_free(&gl->actx, buf);
    s->has_clip = planes != NULL;
    return asp__gl_check(gl, "upload the splat clip planes", err);
}

static int create(asp_gl_context *gl, const asp_cloud *cloud, const asp_hier *hier, const asp_context *ctx, const asp_splat_renderer_desc *desc,
                  asp_renderer **out, asp_error *err)
{
    static const asp_splat_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = check_desc(desc, err);
    if (!rc && desc->clip_planes)
        rc = check_clip_planes(desc->clip_planes, cloud ? cloud->count : asp_hier_point_count(hier), err);
    if (rc)
        return rc;
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    asp__lod_renderer *lr;
    rc = asp__lod_renderer_create(gl, sizeof(splat_renderer), &splat_vtable, cloud, hier, ASP__LOD_DESC(desc, ctx),
                                  &lr, err);
    if (rc)
        return rc;
    splat_renderer *s = (splat_renderer *)lr;
    kernel_params k;
    kernel_params_of(desc, &k);
    s->ka = k.ka, s->kb = k.kb, s->kn = k.kn, s->ksigma = k.sigma, s->kgauss = k.gauss;
    s->kscale = k.scale, s->support = k.support;
    s->eps_uniform = (desc->flags & ASP_SPLAT_EPSILON_UNIFORM) != 0;
    s->epsilon = desc->epsilon > 0 ? desc->epsilon : desc->epsilon < 0 ? 0.0f : 1.0f;
    if (s->eps_uniform && desc->epsilon == 0) {
        // seed 001 5.3's one epsilon; by default the mean size of the input splats
        const asp_hier_splat *sp = asp_hier_splats(s->lod.hier) + s->lod.nodes;
        double sum = 0;
        for (size_t j = 0; j < s->lod.points; j++)
            sum += sp[j].a;
        s->epsilon = s->lod.points ? (float)(sum / (double)s->lod.points) : 0.0f;
    }
    s->radius_scale = desc->radius_scale > 0 ? desc->radius_scale : 1.0f;
    s->lighting = desc->lighting;
    s->mode = desc->mode;

    rc = asp__gl_program_create(gl, "splat depth", vertex_src, depth_fragment_src, &s->programs[PROG_DEPTH], err);
    if (!rc)
        rc = asp__gl_program_create(gl, "splat blend", vertex_src, blend_fragment_src, &s->programs[PROG_BLEND],
                                    err);
    if (!rc)
        rc = asp__lod_upload(gl, &s->lod, "splat", err);
    if (!rc)
        rc = upload_clips(s, desc->clip_planes, err);
    if (rc) {
        splat_destroy(&s->base);
        return rc;
    }
    for (int i = 0; i < PROG_COUNT; i++)
        for (int j = 0; j < U_COUNT; j++)
            s->uniforms[i][j] = glGetUniformLocation(s->programs[i].id, uniform_names[j]);
    glCreateVertexArrays(1, &s->vao.id);
    set_static_uniforms(s);
    return asp__lod_renderer_finish(lr, out, err);
}

int asp_splat_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_splat_renderer_desc *desc,
                              const asp_context *ctx,                               asp_renderer **out, asp_error *err)
{
    return create(gl, cloud, NULL, ctx, desc, out, err);
}

int asp_splat_renderer_create_hier(asp_gl_context *gl, const asp_hier *hier, const asp_splat_renderer_desc *desc,
                                   asp_renderer **out, asp_error *err)
{
    return create(gl, NULL, hier, NULL, desc, out, err);
}

/*
 * For the hybrid renderer (hybrid_renderer.c): the first two passes of
 * draw_blended into the caller's framebuffer and state, so its primitives
 * and these splats share one accumulation and one division.
 */
int asp__splat_hybrid_select(asp_renderer *r, const asp__frame *f, asp_error *err)
{
    ASP_ASSERT(r->vt == &splat_vtable);
    return asp__lod_select((asp__lod_renderer *)r, f, err);
}

void asp__splat_hybrid_pass(asp_renderer *r, const asp__frame *f, int depth_only)
{
    splat_renderer *s = (splat_renderer *)r;
    if (s->lod.count == 0)
        return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_SPLATS, s->lod.splats.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_IDS, s->lod.ids.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_CONES, s->lod.cones.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__LOD_BIND_CLIPS, s->clips.id);
    int prog = depth_only ? PROG_DEPTH : PROG_BLEND;
    set_frame_uniforms(s, prog, f, depth_only ? s->epsilon : 0.0f, 0);
    // the shared resolve lights nothing: per-pixel lighting falls back to Gouraud
    if (lighting_code(s, f) == 1)
        glProgramUniform1i(s->programs[prog].id, s->uniforms[prog][U_LIGHTING], 0);
    draw_splats(s, prog);
}
