/*
 * Text over a frame: stb_easy_font's glyph quads (the font of the experiment
 * screens and the eval charts) drawn in pixel coordinates over whatever the
 * last frame drew, in a translucent box, without depth test or clear. The
 * viewer shows its frame figures with it (issue 18 item 5); the GL stays in
 * src/render (STYLE.md 9).
 */
#include <string.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "render/internal.h"
#include "util/banned.h"

enum { MAX_TEXT = 4096, FLOATS_PER_VERTEX = 6 };

struct asp_text_overlay {
    asp_gl_context *gl;
    asp__gl_program program;
    asp__gl_vertex_array vao;
    asp__gl_buffer vertices;
    GLint u_size;
};

static const char vertex_src[] =
    "#version 450 core\n"
    "layout(location = 0) in vec2 a_pos;   // pixels from the top-left corner\n"
    "layout(location = 1) in vec4 a_color; // linear RGB, straight alpha\n"
    "uniform vec2 u_size;\n"
    "out vec4 v_color;\n"
    "void main() {\n"
    "    v_color = a_color;\n"
    "    gl_Position = vec4(2.0 * a_pos.x / u_size.x - 1.0, 1.0 - 2.0 * a_pos.y / u_size.y, 0.0, 1.0);\n"
    "}\n";

static const char fragment_src[] =
    "#version 450 core\n"
    "in vec4 v_color;\n"
    "out vec4 o_color;\n"
    "void main() { o_color = v_color; }\n";

int asp_text_overlay_create(asp_gl_context *gl, asp_text_overlay **out, asp_error *err)
{
    ASP_ASSERT(gl && out);
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    asp_text_overlay *o = asp_calloc(&gl->actx, 1, sizeof *o);
    if (!o)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a text overlay");
    o->gl = gl;
    asp__gl_clear_errors(gl);
    rc = asp__gl_program_create(gl, "text overlay", vertex_src, fragment_src, &o->program, err);
    if (rc) {
        asp_free(&gl->actx, o);
        return rc;
    }
    o->u_size = glGetUniformLocation(o->program.id, "u_size");
    glCreateVertexArrays(1, &o->vao.id);
    glCreateBuffers(1, &o->vertices.id);
    GLsizei stride = FLOATS_PER_VERTEX * sizeof(float);
    glVertexArrayVertexBuffer(o->vao.id, 0, o->vertices.id, 0, stride);
    glVertexArrayAttribFormat(o->vao.id, 0, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(o->vao.id, 1, 4, GL_FLOAT, GL_FALSE, 2 * sizeof(float));
    for (GLuint a = 0; a < 2; a++) {
        glVertexArrayAttribBinding(o->vao.id, a, 0);
        glEnableVertexArrayAttrib(o->vao.id, a);
    }
    rc = asp__gl_check(gl, "create the text overlay", err);
    if (rc) {
        asp_text_overlay_destroy(o);
        return rc;
    }
    *out = o;
    return 0;
}

/* Two triangles of one axis-aligned quad (corners in the order stb_easy_font emits them) into v. */
static float *put_quad(float *v, const float xy[4][2], const float color[4])
{
    static const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++) {
        *v++ = xy[order[i]][0];
        *v++ = xy[order[i]][1];
        memcpy(v, color, 4 * sizeof(float));
        v += 4;
    }
    return v;
}

static void linear_color(const uint8_t c[4], float out[4])
{
    for (int k = 0; k < 3; k++)
        out[k] = asp__srgb_to_linear(c[k]);
    out[3] = c[3] / 255.0f;
}

/* stb_easy_font's extent of text in font units; it takes a mutable string but only reads it */
static void font_extent(const char *text, float *w, float *h)
{
    *w = (float)stb_easy_font_width((char *)text);
    *h = (float)stb_easy_font_height((char *)text);
}

void asp_text_overlay_measure(const char *text, float scale, float *width, float *height)
{
    ASP_ASSERT(text && width && height);
    float s = scale > 0 ? scale : 2.0f, tw, th;
    font_extent(text, &tw, &th);
    *width = tw * s + 6.0f * s; // the box's padding is 3 font units a side
    *height = th * s + 6.0f * s;
}

int asp_text_overlay_draw(asp_text_overlay *o, const char *text, const asp_text_overlay_desc *desc,
                          asp_error *err)
{
    ASP_ASSERT(o && text);
    static const asp_text_overlay_desc zero_desc;
    desc = desc ? desc : &zero_desc;
    size_t len = strlen(text);
    if (len > MAX_TEXT)
        return asp_error_set(err, ASP_EINVAL, "overlay text of %zu characters is over %d", len, MAX_TEXT);
    asp_gl_context *gl = o->gl;
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    uint32_t w = gl->target.width, h = gl->target.height;
    GLuint fbo = gl->target.fbo.id;
    if (gl->backend == ASP__GL_GLFW) {
        asp_gl_context_framebuffer_size(gl, &w, &h);
        fbo = 0; // the window's back buffer
    }
    if (w == 0 || h == 0)
        return 0; // a minimised window or a headless context that drew nothing yet

    // stb_easy_font: ~270 bytes of quads per character at most; it takes a mutable string
    size_t cap = 300 * len + 64;
    char *quads = asp_alloc(&gl->actx, cap + len + 1);
    if (!quads)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu characters of overlay text", len);
    char *copy = quads + cap;
    memcpy(copy, text, len + 1);
    int nq = len ? stb_easy_font_print(0, 0, copy, NULL, quads, (int)cap) : 0;
    float tw, th;
    font_extent(copy, &tw, &th);
    float *verts = asp_alloc(&gl->actx, (size_t)(nq + 2) * 6 * FLOATS_PER_VERTEX * sizeof(float));
    if (!verts) {
        asp_free(&gl->actx, quads);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu characters of overlay text", len);
    }
    float s = desc->scale > 0 ? desc->scale : 2.0f, pad = 3.0f * s;
    int given = desc->color[0] || desc->color[1] || desc->color[2] || desc->color[3];
    const uint8_t white[4] = {255, 255, 255, 255}, shade[4] = {0, 0, 0, 160};
    float fg[4], bg[4];
    linear_color(given ? desc->color : white, fg);
    given = desc->box[0] || desc->box[1] || desc->box[2] || desc->box[3];
    linear_color(given ? desc->box : shade, bg);
    float x0 = desc->x, y0 = desc->y;
    const float box[4][2] = {{x0, y0}, {x0 + tw * s + 2 * pad, y0}, {x0 + tw * s + 2 * pad, y0 + th * s + 2 * pad},
                             {x0, y0 + th * s + 2 * pad}};
    float *v = verts;
    size_t nverts = (size_t)(nq + 1) * 6;
    if (desc->fill[3]) { // a text screen: the whole target first, blended as the box is
        float fc[4];
        linear_color(desc->fill, fc);
        const float all[4][2] = {{0, 0}, {(float)w, 0}, {(float)w, (float)h}, {0, (float)h}};
        v = put_quad(v, all, fc);
        nverts += 6;
    }
    v = put_quad(v, box, bg);
    for (int q = 0; q < nq; q++) {
        float xy[4][2];
        for (int c = 0; c < 4; c++) {
            float p[2];
            memcpy(p, quads + 16 * (4 * q + c), sizeof p); // x, y, z floats then 4 colour bytes
            xy[c][0] = x0 + pad + s * p[0];
            xy[c][1] = y0 + pad + s * p[1];
        }
        v = put_quad(v, xy, fg);
    }
    asp__gl_clear_errors(gl);
    glNamedBufferData(o->vertices.id, (GLsizeiptr)(nverts * FLOATS_PER_VERTEX * sizeof(float)), verts,
                      GL_STREAM_DRAW);
    asp_free(&gl->actx, verts);
    asp_free(&gl->actx, quads);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, (GLsizei)w, (GLsizei)h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_FALSE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_FRAMEBUFFER_SRGB); // colours are linear, like every renderer's output
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(o->program.id);
    glUniform2f(o->u_size, (float)w, (float)h);
    glBindVertexArray(o->vao.id);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)nverts);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
    return asp__gl_check(gl, "draw the text overlay", err);
}

void asp_text_overlay_destroy(asp_text_overlay *o)
{
    if (!o)
        return;
    asp_gl_context *gl = o->gl;
    if (asp__gl_ensure_current(gl, NULL) == 0) {
        glDeleteBuffers(1, &o->vertices.id);
        glDeleteVertexArrays(1, &o->vao.id);
        asp__gl_program_destroy(&o->program);
    }
    asp_free(&gl->actx, o);
}
