/*
 * Eye-dome lighting (Boucheny 2009, "Visualisation scientifique interactive de
 * grands volumes de donnees", chapter 5; the shading of CloudCompare's and
 * Potree's point views): points without normals cannot be lit, so each pixel
 * is darkened by how far its neighbours on a small circle of the screen stand
 * in front of it, in log depth. Silhouettes and creases get dark rims, slopes
 * away from the eye shade gradually, and no normal is needed. One screen-space
 * pass over the depth the renderer drew into a private target.
 */
#include <math.h>
#include <string.h>

#include "render/edl_internal.h"
#include "util/banned.h"

/* Default sampling radius in pixels: neighbours one to two pixels away, as Boucheny's full-resolution pass. */
static const float default_radius = 1.4f;

static const char vertex_src[] =
    "#version 450 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

/*
 * u_proj = (P[10], P[11], P[14], P[15]) of the column-major projection: the
 * eye distance of a window depth d is -z_e with z_e = (P14 - n P15) / (n P11 -
 * P10), n = 2 d - 1 (inverting z_ndc = (P10 z_e + P14) / (P11 z_e + P15)), so
 * perspective and orthographic cameras both work. Log depth makes the
 * response independent of the scene's scale and distance (Boucheny 5.2).
 * The factor 300 turns mean log2 differences of a few thousandths (a slope
 * seen over 1.4 px) into a visible shade, a jump of a few percent into a
 * dark rim; strength scales it.
 */
static const char fragment_src[] =
    "#version 450 core\n"
    "layout(binding = 0) uniform sampler2D u_color;\n"
    "layout(binding = 1) uniform sampler2D u_depth;\n"
    "uniform vec4 u_proj;\n"
    "uniform float u_strength;\n"
    "uniform float u_radius;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "float log_distance(float d) {\n"
    "    float n = 2.0 * d - 1.0;\n"
    "    float z = (u_proj.z - n * u_proj.w) / (n * u_proj.y - u_proj.x);\n"
    "    return log2(max(-z, 1e-30));\n"
    "}\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "    ivec2 top = textureSize(u_depth, 0) - 1;\n"
    "    float d = texelFetch(u_depth, p, 0).r;\n"
    "    if (d >= 1.0)\n"
    "        discard; // nothing drawn: the caller's background stays\n"
    "    float here = log_distance(d), sum = 0.0;\n"
    "    for (int i = 0; i < 8; i++) {\n"
    "        float a = 0.78539816 * float(i);\n"
    "        ivec2 q = clamp(ivec2(floor(gl_FragCoord.xy + u_radius * vec2(cos(a), sin(a)))), ivec2(0), top);\n"
    "        float dq = texelFetch(u_depth, q, 0).r;\n"
    "        if (dq < 1.0) // the background is infinitely far: it never shades\n"
    "            sum += max(0.0, here - log_distance(dq));\n"
    "    }\n"
    "    float shade = exp(-300.0 * u_strength * sum / 8.0);\n"
    "    vec4 c = texelFetch(u_color, p, 0);\n"
    "    o_color = vec4(c.rgb * shade, 1.0);\n"
    "    gl_FragDepth = d;\n"
    "}\n";

int asp__edl_check(const asp_edl_desc *desc, asp_error *err)
{
    if (!(desc->strength >= 0) || !isfinite(desc->strength))
        return asp_error_set(err, ASP_EINVAL, "eye-dome lighting strength %g is not a finite number >= 0",
                             (double)desc->strength);
    if (!(desc->radius >= 0 && desc->radius <= 16))
        return asp_error_set(err, ASP_EINVAL, "eye-dome lighting radius %g px is outside 0..16",
                             (double)desc->radius);
    return 0;
}

int asp__edl_init(asp__edl *e, asp_gl_context *gl, const asp_edl_desc *desc, asp_error *err)
{
    memset(e, 0, sizeof *e);
    int rc = asp__edl_check(desc, err);
    if (rc)
        return rc;
    e->desc = *desc;
    if (e->desc.radius == 0)
        e->desc.radius = default_radius;
    if (!asp__edl_on(e))
        return 0;
    rc = asp__gl_program_create(gl, "eye-dome lighting", vertex_src, fragment_src, &e->program, err);
    if (rc)
        return rc;
    e->u_strength = glGetUniformLocation(e->program.id, "u_strength");
    e->u_radius = glGetUniformLocation(e->program.id, "u_radius");
    e->u_proj = glGetUniformLocation(e->program.id, "u_proj");
    glCreateVertexArrays(1, &e->vao.id);
    return asp__gl_check(gl, "create the eye-dome lighting pass", err);
}

static void targets_release(asp__edl *e)
{
    if (e->fbo.id)
        glDeleteFramebuffers(1, &e->fbo.id);
    if (e->color)
        glDeleteTextures(1, &e->color);
    if (e->depth)
        glDeleteTextures(1, &e->depth);
    e->fbo.id = e->color = e->depth = 0;
    e->width = e->height = 0;
}

static int targets_ensure(asp__edl *e, asp_gl_context *gl, uint32_t w, uint32_t h, asp_error *err)
{
    if (e->fbo.id && e->width == w && e->height == h)
        return 0;
    targets_release(e);
    asp__gl_clear_errors(gl);
    // sRGB like the frame's own target, so shading stays in linear light and sampling decodes it
    glCreateTextures(GL_TEXTURE_2D, 1, &e->color);
    glTextureStorage2D(e->color, 1, GL_SRGB8_ALPHA8, (GLsizei)w, (GLsizei)h);
    glCreateTextures(GL_TEXTURE_2D, 1, &e->depth);
    glTextureStorage2D(e->depth, 1, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
    glCreateFramebuffers(1, &e->fbo.id);
    glNamedFramebufferTexture(e->fbo.id, GL_COLOR_ATTACHMENT0, e->color, 0);
    glNamedFramebufferTexture(e->fbo.id, GL_DEPTH_ATTACHMENT, e->depth, 0);
    int rc = asp__gl_check(gl, "create the eye-dome lighting target", err);
    if (!rc && glCheckNamedFramebufferStatus(e->fbo.id, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        rc = asp_error_set(err, ASP_EGL, "cannot create the eye-dome lighting framebuffer of %ux%u", w, h);
    if (rc) {
        targets_release(e);
        return rc;
    }
    e->width = w;
    e->height = h;
    return 0;
}

int asp__edl_begin(asp__edl *e, asp_gl_context *gl, const asp__frame *f, asp_error *err)
{
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &e->caller);
    int rc = targets_ensure(e, gl, f->width, f->height, err);
    if (rc)
        return rc;
    static const GLfloat clear[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    glDepthMask(GL_TRUE);
    glClearNamedFramebufferfv(e->fbo.id, GL_COLOR, 0, clear);
    glClearNamedFramebufferfv(e->fbo.id, GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e->fbo.id);
    return 0;
}

int asp__edl_end(asp__edl *e, asp_gl_context *gl, const asp__frame *f, asp_error *err)
{
    GLuint p = e->program.id;
    glProgramUniform1f(p, e->u_strength, e->desc.strength);
    glProgramUniform1f(p, e->u_radius, e->desc.radius);
    glProgramUniform4f(p, e->u_proj, f->proj[10], f->proj[11], f->proj[14], f->proj[15]);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)e->caller);
    // the depth written keeps the caller's depth buffer right for whatever it draws next
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS); // over the caller's clear (depth 1) and anything it drew nearer
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBindTextureUnit(0, e->color);
    glBindTextureUnit(1, e->depth);
    glUseProgram(p);
    glBindVertexArray(e->vao.id);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    return asp__gl_check(gl, "draw the eye-dome lighting pass", err);
}

void asp__edl_release(asp__edl *e)
{
    targets_release(e);
    asp__gl_program_destroy(&e->program);
    if (e->vao.id)
        glDeleteVertexArrays(1, &e->vao.id);
    e->vao.id = 0;
}
