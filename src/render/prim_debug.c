/*
 * Debug drawings of the thesis's viewer (Reniers 2004, appendix C) over a
 * domain-primitive image: the eigenvectors of each support plane (the PCA
 * axes, thesis 3.1) and the midpoints of the texels a primitive's texture
 * covers (alpha > 0, thesis 3.3), generated in the vertex shader from the
 * renderer's primitive buffer (no upload), and the affine triangulation
 * (3.3.3) as lines the caller gives (asp_prim_level_triangles).
 */
#include <math.h>
#include <string.h>

#include "render/prim_internal.h"
#include "util/banned.h"

struct asp__prim_debug {
    asp__gl_program axes, texels, lines;
    GLint axes_view, axes_proj, texels_view, texels_proj, texels_size, lines_view, lines_proj;
    GLuint line_buffer;  /* 6 floats per segment */
    size_t segments;
    GLsizei max_texels; /* the largest texture's texel count: vertices per primitive of the texel draw */
    GLint atlas_w, atlas_h;
};

#define DEBUG_PRIM_GLSL                                                                   \
    "struct prim { vec4 c; vec4 u; vec4 v; vec4 n; vec4 uv; uvec4 info; uvec4 clip; };\n" \
    "layout(std430, binding = 0) readonly buffer Prims { prim prims[]; };\n"               \
    "uniform mat4 u_view;\n"                                                              \
    "uniform mat4 u_proj;\n"                                                              \
    "out vec3 v_color;\n"

/* Vertex 2a, 2a + 1: the centre and the end of axis a (u, v, normal) of primitive gl_InstanceID. */
static const char axes_vs[] =
    "#version 450 core\n" DEBUG_PRIM_GLSL
    "const vec3 colors[3] = vec3[3](vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0));\n"
    "void main() {\n"
    "    prim p = prims[gl_InstanceID];\n"
    "    int a = gl_VertexID / 2;\n"
    "    vec3 d = a == 0 ? p.u.xyz : a == 1 ? p.v.xyz : p.n.xyz * min(length(p.u.xyz), length(p.v.xyz));\n"
    "    vec3 w = p.c.xyz + float(gl_VertexID % 2) * d;\n"
    "    v_color = colors[a];\n"
    "    gl_Position = u_proj * (u_view * vec4(w, 1.0));\n"
    "}\n";

/*
 * Vertex t of primitive gl_InstanceID: texel (t mod tex_w, t / tex_w) of its texture (build.md: column i
 * at s = -half_u + (i + 0.5) texel); texels past its texture or with alpha 0 are moved outside the clip
 * volume.
 */
static const char texels_vs[] =
    "#version 450 core\n" DEBUG_PRIM_GLSL
    "layout(binding = 0) uniform sampler2D u_atlas;\n"
    "uniform ivec2 u_atlas_size;\n"
    "void main() {\n"
    "    prim p = prims[gl_InstanceID];\n"
    "    ivec2 o = ivec2(round(p.uv.xy * vec2(u_atlas_size)));\n"
    "    ivec2 s = ivec2(round(p.uv.zw * vec2(u_atlas_size)));\n"
    "    ivec2 t = ivec2(gl_VertexID % max(s.x, 1), gl_VertexID / max(s.x, 1));\n"
    "    v_color = vec3(1.0, 0.0, 1.0);\n"
    "    gl_PointSize = 1.0;\n"
    "    if (t.y >= s.y || texelFetch(u_atlas, o + t, 0).a == 0.0) {\n"
    "        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);\n"
    "        return;\n"
    "    }\n"
    "    vec2 k = -1.0 + (2.0 * vec2(t) + 1.0) / vec2(s);\n"
    "    vec3 w = p.c.xyz + k.x * p.u.xyz + k.y * p.v.xyz;\n"
    "    gl_Position = u_proj * (u_view * vec4(w, 1.0));\n"
    "}\n";

/* Vertex gl_VertexID of the caller's segments (asp_prim_renderer_set_debug_lines). */
static const char lines_vs[] =
    "#version 450 core\n"
    "layout(std430, binding = 3) readonly buffer Lines { float lp[]; };\n"
    "uniform mat4 u_view;\n"
    "uniform mat4 u_proj;\n"
    "out vec3 v_color;\n"
    "void main() {\n"
    "    int k = 3 * gl_VertexID;\n"
    "    v_color = vec3(0.0, 1.0, 1.0);\n"
    "    gl_Position = u_proj * (u_view * vec4(lp[k], lp[k + 1], lp[k + 2], 1.0));\n"
    "}\n";

static const char debug_fs[] = "#version 450 core\n"
                               "in vec3 v_color;\n"
                               "out vec4 o_color;\n"
                               "void main() { o_color = vec4(v_color, 1.0); }\n";

/* The programs, and the largest texture's texel count from the primitive records already on the GPU. */
static int debug_init(asp__prim_renderer *r, asp_error *err)
{
    asp_gl_context *gl = r->base.gl;
    struct asp__prim_debug *d = asp_calloc(&gl->actx, 1, sizeof *d);
    asp__prim_gpu *g = asp_alloc(&gl->actx, r->count * sizeof *g);
    if (!d || !g) {
        asp_free(&gl->actx, d);
        asp_free(&gl->actx, g);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the debug drawings of %zu primitives", r->count);
    }
    r->debug = d;
    glGetTextureLevelParameteriv(r->atlas, 0, GL_TEXTURE_WIDTH, &d->atlas_w);
    glGetTextureLevelParameteriv(r->atlas, 0, GL_TEXTURE_HEIGHT, &d->atlas_h);
    glGetNamedBufferSubData(r->prim_buffer.id, 0, (GLsizeiptr)(r->count * sizeof *g), g);
    double most = 0;
    for (size_t i = 0; i < r->count; i++)
        most = fmax(most, round(g[i].uv[2] * d->atlas_w) * round(g[i].uv[3] * d->atlas_h));
    asp_free(&gl->actx, g);
    d->max_texels = (GLsizei)most;
    int rc = asp__gl_program_create(gl, "primitive debug axes", axes_vs, debug_fs, &d->axes, err);
    if (!rc)
        rc = asp__gl_program_create(gl, "primitive debug texels", texels_vs, debug_fs, &d->texels, err);
    if (!rc)
        rc = asp__gl_program_create(gl, "primitive debug lines", lines_vs, debug_fs, &d->lines, err);
    if (rc)
        return rc;
    d->axes_view = glGetUniformLocation(d->axes.id, "u_view");
    d->axes_proj = glGetUniformLocation(d->axes.id, "u_proj");
    d->texels_view = glGetUniformLocation(d->texels.id, "u_view");
    d->texels_proj = glGetUniformLocation(d->texels.id, "u_proj");
    d->texels_size = glGetUniformLocation(d->texels.id, "u_atlas_size");
    d->lines_view = glGetUniformLocation(d->lines.id, "u_view");
    d->lines_proj = glGetUniformLocation(d->lines.id, "u_proj");
    return asp__gl_check(gl, "create the primitive debug drawings", err);
}

int asp__prim_debug_draw(asp__prim_renderer *r, const asp__frame *f, asp_error *err)
{
    if (!r->debug) {
        int rc = debug_init(r, err);
        if (rc)
            return rc;
    }
    struct asp__prim_debug *d = r->debug;
    if (!d->axes.id || !d->texels.id || !d->lines.id)
        return asp_error_set(err, ASP_EGL, "the primitive debug drawings failed to build before");
    // drawn on top, as the thesis's viewer overlays them: no depth test, no blending
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ASP__PRIM_BIND_PRIMS, r->prim_buffer.id);
    glBindVertexArray(r->empty_vao.id);
    if (r->opt.flags & ASP_PRIM_RENDER_DEBUG_TEXELS && d->max_texels > 0) {
        glProgramUniformMatrix4fv(d->texels.id, d->texels_view, 1, GL_FALSE, f->view);
        glProgramUniformMatrix4fv(d->texels.id, d->texels_proj, 1, GL_FALSE, f->proj);
        glProgramUniform2i(d->texels.id, d->texels_size, d->atlas_w, d->atlas_h);
        glBindTextureUnit(0, r->atlas);
        glUseProgram(d->texels.id);
        glDrawArraysInstanced(GL_POINTS, 0, d->max_texels, (GLsizei)r->count);
        glBindTextureUnit(0, 0);
    }
    if (r->opt.flags & ASP_PRIM_RENDER_DEBUG_EIGENVECTORS) {
        glProgramUniformMatrix4fv(d->axes.id, d->axes_view, 1, GL_FALSE, f->view);
        glProgramUniformMatrix4fv(d->axes.id, d->axes_proj, 1, GL_FALSE, f->proj);
        glUseProgram(d->axes.id);
        glDrawArraysInstanced(GL_LINES, 0, 6, (GLsizei)r->count);
    }
    if (r->opt.flags & ASP_PRIM_RENDER_DEBUG_TRIANGULATION && d->segments > 0) {
        glProgramUniformMatrix4fv(d->lines.id, d->lines_view, 1, GL_FALSE, f->view);
        glProgramUniformMatrix4fv(d->lines.id, d->lines_proj, 1, GL_FALSE, f->proj);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, d->line_buffer);
        glUseProgram(d->lines.id);
        glDrawArrays(GL_LINES, 0, (GLsizei)(2 * d->segments));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, 0);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    glEnable(GL_DEPTH_TEST);
    return asp__gl_check(r->base.gl, "draw the primitive debug drawings", err);
}

void asp__prim_debug_destroy(asp__prim_renderer *r)
{
    if (!r->debug)
        return;
    asp__gl_program_destroy(&r->debug->axes);
    asp__gl_program_destroy(&r->debug->texels);
    asp__gl_program_destroy(&r->debug->lines);
    if (r->debug->line_buffer)
        glDeleteBuffers(1, &r->debug->line_buffer);
    asp_free(&r->base.gl->actx, r->debug);
    r->debug = NULL;
}

int asp__prim_debug_set_lines(asp__prim_renderer *r, const float *lines, size_t segments, asp_error *err)
{
    if (!lines && segments)
        return asp_error_set(err, ASP_EINVAL, "no lines for %zu segments", segments);
    if (segments > (size_t)INT32_MAX / 2)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw %zu segments in one call", segments);
    asp_renderer *base = &r->base;
    int rc = asp__gl_ensure_current(base->gl, err);
    if (!rc && !r->debug)
        rc = debug_init(r, err);
    if (rc)
        return rc;
    struct asp__prim_debug *d = r->debug;
    if (d->line_buffer)
        glDeleteBuffers(1, &d->line_buffer);
    d->line_buffer = 0;
    d->segments = 0;
    if (segments) {
        glCreateBuffers(1, &d->line_buffer);
        glNamedBufferStorage(d->line_buffer, (GLsizeiptr)(6 * segments * sizeof(float)), lines, 0);
        d->segments = segments;
    }
    return asp__gl_check(base->gl, "upload the triangulation lines", err);
}
