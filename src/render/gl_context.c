/*
 * The backend-independent half of asp_gl_context: checks that the context
 * really is OpenGL 4.5 (every renderer relies on direct state access, core in
 * 4.5), reads its limits, and dispatches to the EGL or GLFW backend.
 */
#include <stdio.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

static void copy_gl_string(char *dst, size_t cap, GLenum name)
{
    const GLubyte *s = glGetString(name);
    snprintf(dst, cap, "%s", s ? (const char *)s : "unknown");
}

int asp__gl_context_setup(asp_gl_context *gl, asp_error *err)
{
    copy_gl_string(gl->renderer, sizeof gl->renderer, GL_RENDERER);
    copy_gl_string(gl->version, sizeof gl->version, GL_VERSION);
    int version = epoxy_gl_version();
    if (!epoxy_is_desktop_gl() || version < 45)
        return asp_error_set(err, ASP_EGL, "no OpenGL 4.5 context: %s offers only '%s'", gl->renderer,
                             gl->version);
    glGetIntegerv(GL_MAX_SAMPLES, &gl->max_samples);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &gl->max_size);
    GLint dims[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
    if (dims[0] < gl->max_size)
        gl->max_size = dims[0];
    if (dims[1] < gl->max_size)
        gl->max_size = dims[1];
    if (gl->max_samples < 1)
        gl->max_samples = 1;
    asp__gl_debug_install(gl);
    return asp__gl_check(gl, "set up the GL context", err);
}

int asp__gl_ensure_current(asp_gl_context *gl, asp_error *err)
{
    return gl->backend == ASP__GL_GLFW ? asp__gl_glfw_make_current(gl, err) : asp__gl_egl_make_current(gl, err);
}

int asp_gl_context_make_current(asp_gl_context *gl, asp_error *err)
{
    return asp__gl_ensure_current(gl, err);
}

void asp_gl_context_destroy(asp_gl_context *gl)
{
    if (!gl)
        return;
    if (asp__gl_ensure_current(gl, NULL) == 0)
        asp__gl_target_release(&gl->target);
    if (gl->backend == ASP__GL_GLFW)
        asp__gl_glfw_destroy(gl);
    else
        asp__gl_egl_destroy(gl);
    asp_context actx = gl->actx;
    asp_free(&actx, gl);
}

const char *asp_gl_context_renderer(const asp_gl_context *gl)
{
    return gl->renderer;
}

const char *asp_gl_context_version(const asp_gl_context *gl)
{
    return gl->version;
}

const char *asp_gl_context_backend(const asp_gl_context *gl)
{
    return gl->backend_name;
}

int asp_gl_context_check(asp_gl_context *gl, asp_error *err)
{
    return asp__gl_check(gl, "render", err);
}
