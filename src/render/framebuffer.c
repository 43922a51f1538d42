/*
 * The offscreen render target of a headless context: an sRGB colour buffer
 * (so shading happens in linear light and is encoded on store) and a 24-bit
 * depth buffer, multisampled on request with a single-sample resolve copy.
 * Kept in the context and reused while the size and sample count stay; and
 * the row flip of every read-back (the offscreen target's, the window's).
 */
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

void asp__gl_target_release(asp__gl_target *t)
{
    GLuint fbos[2] = {t->fbo.id, t->resolve_fbo.id};
    GLuint rbs[3] = {t->color.id, t->depth.id, t->resolve_color.id};
    for (int i = 0; i < 2; i++)
        if (fbos[i])
            glDeleteFramebuffers(1, &fbos[i]);
    for (int i = 0; i < 3; i++)
        if (rbs[i])
            glDeleteRenderbuffers(1, &rbs[i]);
    t->fbo.id = t->resolve_fbo.id = 0;
    t->color.id = t->depth.id = t->resolve_color.id = 0;
    t->width = t->height = t->samples = 0;
}

/*
 * Issue #31: 16384x16384, inside GL_MAX_RENDERBUFFER_SIZE, ended in "status
 * 0x8cd6" (an attachment the driver could not allocate): the message says
 * the size, the memory it needs and the context's side limit.
 */
static int check_complete(const asp_gl_context *gl, GLuint fbo, const char *which, uint32_t w, uint32_t h,
                          uint32_t samples, asp_error *err)
{
    GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
    if (status == GL_FRAMEBUFFER_COMPLETE)
        return 0;
    double mb = (double)w * h * 8.0 * (samples > 1 ? samples : 1) / (1 << 20); // RGBA8 colour + 24/8 depth
    return asp_error_set(err, status == GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT ? ASP_ENOMEM : ASP_EGL,
                         "cannot create the %s framebuffer of %ux%u with %u sample%s (%.0f MB; the GL context allows "
                         "up to %d pixels a side): status 0x%04x%s", which, w, h, samples > 1 ? samples : 1,
                         samples > 1 ? "s" : "", mb, gl->max_size, (unsigned)status,
                         status == GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT
                             ? " (incomplete attachment: out of memory for it; try a smaller --size or --samples)"
                             : "");
}

int asp__gl_target_ensure(asp_gl_context *gl, uint32_t width, uint32_t height, uint32_t samples, asp_error *err)
{
    asp__gl_target *t = &gl->target;
    if (t->fbo.id && t->width == width && t->height == height && t->samples == samples)
        return 0;
    asp__gl_target_release(t);
    asp__gl_clear_errors(gl);
    // samples == 1 would still make a multisampled buffer on some drivers; 0 means a plain one
    GLsizei s = samples > 1 ? (GLsizei)samples : 0;
    glCreateRenderbuffers(1, &t->color.id);
    glNamedRenderbufferStorageMultisample(t->color.id, s, GL_SRGB8_ALPHA8, (GLsizei)width, (GLsizei)height);
    glCreateRenderbuffers(1, &t->depth.id);
    glNamedRenderbufferStorageMultisample(t->depth.id, s, GL_DEPTH_COMPONENT24, (GLsizei)width, (GLsizei)height);
    glCreateFramebuffers(1, &t->fbo.id);
    glNamedFramebufferRenderbuffer(t->fbo.id, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t->color.id);
    glNamedFramebufferRenderbuffer(t->fbo.id, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t->depth.id);
    int rc = asp__gl_check(gl, "create the offscreen framebuffer", err);
    if (!rc)
        rc = check_complete(gl, t->fbo.id, "offscreen", width, height, samples, err);
    if (!rc && s > 0) {
        glCreateRenderbuffers(1, &t->resolve_color.id);
        glNamedRenderbufferStorage(t->resolve_color.id, GL_SRGB8_ALPHA8, (GLsizei)width, (GLsizei)height);
        glCreateFramebuffers(1, &t->resolve_fbo.id);
        glNamedFramebufferRenderbuffer(t->resolve_fbo.id, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                       t->resolve_color.id);
        rc = asp__gl_check(gl, "create the resolve framebuffer", err);
        if (!rc)
            rc = check_complete(gl, t->resolve_fbo.id, "resolve", width, height, 1, err);
    }
    if (rc) {
        asp__gl_target_release(t);
        return rc;
    }
    t->width = width;
    t->height = height;
    t->samples = samples;
    return 0;
}

void asp__gl_restore_state(GLuint fbo)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindVertexArray(0);
    glUseProgram(0);
}

void asp__image_flip_rows(asp_image *img, uint8_t *row)
{
    size_t stride = 4 * (size_t)img->width;
    for (uint32_t y = 0; y < img->height / 2; y++) {
        uint8_t *a = img->pixels + y * stride, *b = img->pixels + (img->height - 1 - y) * stride;
        memcpy(row, a, stride);
        memcpy(a, b, stride);
        memcpy(b, row, stride);
    }
}
