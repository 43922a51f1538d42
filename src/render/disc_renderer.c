/*
 * Opaque oriented discs (journal section 1; Pajarola et al. 2003 section 5.1:
 * each surfel is a triangle in its tangent plane, shaped per fragment; here
 * the equilateral triangle around the disc of radius r, with fragments outside
 * the disc discarded, as the alpha test of their section 5.3 first pass),
 * optionally cut by two clip planes per disc at sharp creases (Botsch et al.
 * 2005 section 4.2, Zwicker et al. 2004 section 5). One instanced draw, one
 * vertex buffer binding per cloud attribute (STYLE.md section 6), GL 4.5 DSA.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/edl_internal.h"
#include "render/internal.h"
#include "util/banned.h"

/*
 * corners[] is the equilateral triangle with inradius 1: one triangle per disc
 * halves the per-triangle setup that dominates small splats (35% less CPU on
 * llvmpipe than a two-triangle square, for 30% more fragments).
 */
static const char *vertex_src =
    "#version 450 core\n"
    "layout(location = 0) in vec3 a_position;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "layout(location = 2) in vec4 a_color;\n"
    "layout(location = 3) in float a_radius;\n"
    "layout(location = 4) in vec4 a_clip0;\n"
    "layout(location = 5) in vec4 a_clip1;\n"
    "uniform mat4 u_view;\n"
    "uniform mat4 u_proj;\n"
    "uniform vec3 u_eye;\n"
    "uniform int u_has_normals;\n"
    "uniform int u_has_colors;\n"
    "uniform int u_has_radii;\n"
    "uniform vec4 u_default_color;\n"
    "uniform float u_default_radius;\n"
    "uniform float u_radius_scale;\n"
    "uniform int u_has_clip;\n"
    "out vec2 v_local;\n"
    "flat out vec3 v_normal;\n"
    "flat out vec3 v_color;\n"
    "flat out vec3 v_clip0;\n"
    "flat out vec3 v_clip1;\n"
    "const vec2 corners[3] = vec2[3](vec2(-1.7320508, -1.0), vec2(1.7320508, -1.0), vec2(0.0, 2.0));\n"
    "vec3 srgb_to_linear(vec3 c) {\n"
    "    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));\n"
    "}\n"
    // plane (n, d) on the disc p(q) = c + r (q.x t + q.y b) as the line n.p(q) + d = dot(line, vec3(q, 1))
    "vec3 clip_line(vec4 pl, vec3 c, vec3 t, vec3 b, float r) {\n"
    "    return vec3(r * dot(pl.xyz, t), r * dot(pl.xyz, b), dot(pl.xyz, c) + pl.w);\n"
    "}\n"
    "void main() {\n"
    "    vec2 corner = corners[gl_VertexID];\n"
    "    vec3 n = u_has_normals != 0 ? a_normal : u_eye - a_position;\n"
    "    n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 0.0, 1.0);\n"
    "    vec3 helper = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);\n"
    "    vec3 t = normalize(cross(n, helper));\n"
    "    vec3 b = cross(n, t);\n"
    "    float r = (u_has_radii != 0 ? a_radius : u_default_radius) * u_radius_scale;\n"
    "    vec3 p = a_position + r * (corner.x * t + corner.y * b);\n"
    "    v_local = corner;\n"
    "    v_clip0 = u_has_clip != 0 ? clip_line(a_clip0, a_position, t, b, r) : vec3(0.0, 0.0, 1.0);\n"
    "    v_clip1 = u_has_clip != 0 ? clip_line(a_clip1, a_position, t, b, r) : vec3(0.0, 0.0, 1.0);\n"
    "    v_normal = mat3(u_view) * n;\n"
    "    v_color = srgb_to_linear(u_has_colors != 0 ? a_color.rgb : u_default_color.rgb);\n"
    "    gl_Position = u_proj * (u_view * vec4(p, 1.0));\n"
    "}\n";

/*
 * With multisampling the shader runs once per pixel, at the pixel centre,
 * which for a sub-pixel triangle lies outside it: testing the disc there would
 * discard samples the disc covers and let the background through. So the disc
 * test is made at each sample position (interpolateAtSample) and becomes the
 * sample mask; exact coverage at the cost of a loop, not per-sample shading.
 * The clip planes are tested at the same positions: each plane, restricted to
 * the disc's plane, is a line in the disc coordinates v_local (the local-frame
 * position is affine in them), so the test is one dot product per plane.
 */
static const char *fragment_src =
    "#version 450 core\n"
    "in vec2 v_local;\n"
    "flat in vec3 v_normal;\n"
    "flat in vec3 v_color;\n"
    "flat in vec3 v_clip0;\n"
    "flat in vec3 v_clip1;\n"
    "uniform vec3 u_light;\n"
    "uniform int u_unlit;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "bool inside(vec2 q) {\n"
    "    vec3 h = vec3(q, 1.0);\n"
    "    return dot(q, q) <= 1.0 && dot(v_clip0, h) >= 0.0 && dot(v_clip1, h) >= 0.0;\n"
    "}\n"
    "void main() {\n"
    "    int mask = 0;\n"
    "    if (gl_NumSamples > 1) {\n"
    "        for (int i = 0; i < gl_NumSamples; i++) {\n"
    "            vec2 q = interpolateAtSample(v_local, i);\n"
    "            if (inside(q))\n"
    "                mask |= 1 << i;\n"
    "        }\n"
    "    } else if (inside(v_local)) {\n"
    "        mask = -1;\n"
    "    }\n"
    "    if (mask == 0)\n"
    "        discard;\n"
    "    gl_SampleMask[0] = mask;\n"
    "    float lambert = abs(dot(normalize(v_normal), u_light));\n"
    "    float shade = u_unlit != 0 ? 1.0 : 0.25 + 0.75 * lambert;\n"
    "    o_color = vec4(v_color * shade, 1.0);\n"
    "}\n";

enum { U_VIEW, U_PROJ, U_EYE, U_HAS_NORMALS, U_HAS_COLORS, U_HAS_RADII, U_DEFAULT_COLOR, U_DEFAULT_RADIUS,
       U_RADIUS_SCALE, U_LIGHT, U_UNLIT, U_HAS_CLIP, U_COUNT };
static const char *uniform_names[U_COUNT] = {"u_view", "u_proj", "u_eye", "u_has_normals", "u_has_colors",
                                             "u_has_radii", "u_default_color", "u_default_radius",
                                             "u_radius_scale", "u_light", "u_unlit", "u_has_clip"};

/*
 * Attribute locations equal buffer binding indices, except the clip planes:
 * one buffer at binding A_CLIP feeds locations A_CLIP (plane 0) and A_CLIP + 1.
 */
enum { A_POSITION, A_NORMAL, A_COLOR, A_RADIUS, A_CLIP, A_COUNT };

typedef struct disc_renderer {
    asp_renderer base; // first, so an asp_renderer * is a disc_renderer *
    asp__gl_program program;
    asp__gl_vertex_array vao;
    asp__gl_buffer buffers[A_COUNT];
    GLint uniforms[U_COUNT];
    int has[A_COUNT];
    float default_color[4];
    float default_radius, radius_scale;
    asp__edl edl; /* eye-dome lighting around the draw when on */
} disc_renderer;

static void disc_destroy(asp_renderer *base)
{
    disc_renderer *d = (disc_renderer *)base;
    for (int i = 0; i < A_COUNT; i++)
        if (d->buffers[i].id)
            glDeleteBuffers(1, &d->buffers[i].id);
    if (d->vao.id)
        glDeleteVertexArrays(1, &d->vao.id);
    asp__gl_program_destroy(&d->program);
    asp__edl_release(&d->edl);
    asp_context actx = base->gl->actx;
    asp_free(&actx, d);
}

static int disc_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    disc_renderer *d = (disc_renderer *)base;
    GLuint p = d->program.id;
    const GLint *u = d->uniforms;
    glProgramUniformMatrix4fv(p, u[U_VIEW], 1, GL_FALSE, f->view);
    glProgramUniformMatrix4fv(p, u[U_PROJ], 1, GL_FALSE, f->proj);
    glProgramUniform3fv(p, u[U_EYE], 1, f->eye);
    glProgramUniform3fv(p, u[U_LIGHT], 1, f->light_eye);
    glProgramUniform1i(p, u[U_UNLIT], (f->flags & ASP_RENDER_UNLIT) ? 1 : 0);
    if (asp__edl_on(&d->edl)) {
        int rc = asp__edl_begin(&d->edl, base->gl, f, err);
        if (rc)
            return rc;
    }
    glUseProgram(p);
    glBindVertexArray(d->vao.id);
    // one triangle per point; the point's attributes advance once per instance
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, (GLsizei)base->count);
    glBindVertexArray(0);
    glUseProgram(0);
    if (asp__edl_on(&d->edl))
        return asp__edl_end(&d->edl, base->gl, f, err);
    return asp__gl_check(base->gl, "draw discs", err);
}

static const asp__renderer_vtable disc_vtable = {.name = "disc", .draw = disc_draw, .destroy = disc_destroy};

/* Uploads one attribute array into an immutable buffer and binds it at binding == location. */
static void upload(disc_renderer *d, int attr, const void *data, size_t bytes, GLint comps, GLenum type,
                   GLboolean normalized, GLsizei stride)
{
    asp__gl_attrib_buffer(d->vao, (GLuint)attr, &d->buffers[attr], data, bytes, comps, type, normalized, stride, 1);
    d->has[attr] = 1;
}

/* The clip planes: 32 bytes per point, two vec4 attributes at offsets 0 and 16 of one binding. */
static void upload_clip(disc_renderer *d, const float *planes, size_t n)
{
    GLuint vao = d->vao.id;
    glCreateBuffers(1, &d->buffers[A_CLIP].id);
    glNamedBufferStorage(d->buffers[A_CLIP].id, (GLsizeiptr)(8 * n * sizeof(float)), planes, 0);
    glVertexArrayVertexBuffer(vao, A_CLIP, d->buffers[A_CLIP].id, 0, 8 * sizeof(float));
    glVertexArrayBindingDivisor(vao, A_CLIP, 1);
    for (GLuint k = 0; k < 2; k++) {
        glVertexArrayAttribFormat(vao, A_CLIP + k, 4, GL_FLOAT, GL_FALSE, k * 4 * sizeof(float));
        glVertexArrayAttribBinding(vao, A_CLIP + k, A_CLIP);
        glEnableVertexArrayAttrib(vao, A_CLIP + k);
    }
    d->has[A_CLIP] = 1;
}

static void set_static_uniforms(disc_renderer *d)
{
    GLuint p = d->program.id;
    const GLint *u = d->uniforms;
    glProgramUniform1i(p, u[U_HAS_NORMALS], d->has[A_NORMAL]);
    glProgramUniform1i(p, u[U_HAS_COLORS], d->has[A_COLOR]);
    glProgramUniform1i(p, u[U_HAS_RADII], d->has[A_RADIUS]);
    glProgramUniform1i(p, u[U_HAS_CLIP], d->has[A_CLIP]);
    glProgramUniform4fv(p, u[U_DEFAULT_COLOR], 1, d->default_color);
    glProgramUniform1f(p, u[U_DEFAULT_RADIUS], d->default_radius);
    glProgramUniform1f(p, u[U_RADIUS_SCALE], d->radius_scale);
}

static int check_input(const asp_cloud *cloud, const asp_disc_renderer_desc *desc, asp_error *err)
{
    if (cloud->count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot render an empty point set");
    // GLsizei instance counts are signed 32-bit
    if (cloud->count > (size_t)INT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw %zu points in one call (at most %d)", cloud->count,
                             INT32_MAX);
    if (!(desc->radius_scale >= 0) || !isfinite(desc->radius_scale))
        return asp_error_set(err, ASP_EINVAL, "disc radius scale %g is not a finite non-negative number",
                             (double)desc->radius_scale);
    int rc = asp__edl_check(&desc->edl, err);
    if (rc)
        return rc;
    if (desc->clip_planes)
        for (size_t i = 0; i < 8 * cloud->count; i++)
            if (!isfinite(desc->clip_planes[i]))
                return asp_error_set(err, ASP_EFORMAT, "point %zu: clip plane %zu value %zu is not finite", i / 8,
                                     i % 8 / 4, i % 4);
    return asp_cloud_validate(cloud, err);
}

int asp_disc_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_disc_renderer_desc *desc,
                             asp_renderer **out, asp_error *err)
{
    static const asp_disc_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = check_input(cloud, desc, err);
    if (rc)
        return rc;
    float default_radius = cloud->radii ? 0.0f : asp_render_default_radius(cloud);
    if (!cloud->radii && !(default_radius > 0))
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot estimate a disc radius: all %zu points are at the same position", cloud->count);
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    disc_renderer *d = asp_calloc(&gl->actx, 1, sizeof *d);
    if (!d)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a disc renderer");
    d->base.vt = &disc_vtable;
    d->base.gl = gl;
    d->base.count = cloud->count;
    d->default_radius = default_radius;
    d->radius_scale = desc->radius_scale > 0 ? desc->radius_scale : 1.0f;
    const uint8_t *dc = desc->default_color;
    int color_given = dc[0] || dc[1] || dc[2] || dc[3];
    for (int c = 0; c < 4; c++)
        d->default_color[c] = color_given ? dc[c] / 255.0f : (c < 3 ? 200.0f / 255.0f : 1.0f);

    rc = asp__gl_program_create(gl, "disc", vertex_src, fragment_src, &d->program, err);
    if (!rc)
        rc = asp__edl_init(&d->edl, gl, &desc->edl, err);
    if (rc) {
        disc_destroy(&d->base);
        return rc;
    }
    for (int i = 0; i < U_COUNT; i++)
        d->uniforms[i] = glGetUniformLocation(d->program.id, uniform_names[i]);
    glCreateVertexArrays(1, &d->vao.id);
    size_t n = cloud->count;
    upload(d, A_POSITION, cloud->positions, 3 * n * sizeof(float), 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    if (cloud->normals)
        upload(d, A_NORMAL, cloud->normals, 3 * n * sizeof(float), 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    if (cloud->colors)
        upload(d, A_COLOR, cloud->colors, 4 * n, 4, GL_UNSIGNED_BYTE, GL_TRUE, 4);
    if (cloud->radii)
        upload(d, A_RADIUS, cloud->radii, n * sizeof(float), 1, GL_FLOAT, GL_FALSE, sizeof(float));
    if (desc->clip_planes)
        upload_clip(d, desc->clip_planes, n);
    set_static_uniforms(d);
    // out of GPU memory shows up here as GL_OUT_OF_MEMORY from glNamedBufferStorage
    char what[80];
    snprintf(what, sizeof what, "upload %zu points", n);
    rc = asp__gl_check(gl, what, err);
    if (rc) {
        disc_destroy(&d->base);
        return rc;
    }
    *out = &d->base;
    return 0;
}
