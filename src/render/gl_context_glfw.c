/*
 * Windowed OpenGL 4.5 core context through GLFW, behind the same
 * asp_gl_context as the headless EGL backend (STYLE.md section 9), for the
 * interactive viewer. GLFW state is process-wide: one window at a time.
 */
#include <stdio.h>
#include <string.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "render/internal.h"
#include "util/banned.h"

static const char *glfw_reason(void)
{
    const char *msg = NULL;
    glfwGetError(&msg);
    return msg ? msg : "unknown GLFW error";
}

int asp_gl_context_create_window(const asp_gl_context_desc *desc, const asp_context *ctx, asp_gl_context **out,
                                  asp_error *err)
{
    static const asp_gl_context_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int w = desc->width ? (int)desc->width : 1280, h = desc->height ? (int)desc->height : 800;
    if (desc->width > 16384 || desc->height > 16384)
        return asp_error_set(err, ASP_EINVAL, "window size %ux%u is outside 1..16384", desc->width, desc->height);
    asp_gl_context *gl = asp_calloc(ctx, 1, sizeof *gl);
    if (!gl)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a GL context");
    if (ctx)
        gl->actx = *ctx;
    gl->backend = ASP__GL_GLFW;
    if (!glfwInit()) {
        asp_error_set(err, ASP_EGL, "no OpenGL 4.5 window: %s", glfw_reason());
        asp_free(ctx, gl);
        return ASP_EGL;
    }
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, (desc->flags & ASP_GL_CONTEXT_DEBUG) ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_TRUE);
    GLFWwindow *win = glfwCreateWindow(w, h, desc->title ? desc->title : "amgsplat", NULL, NULL);
    if (!win) {
        asp_error_set(err, ASP_EGL, "no OpenGL 4.5 window: %s", glfw_reason());
        glfwTerminate();
        asp_free(ctx, gl);
        return ASP_EGL;
    }
    glfwMakeContextCurrent(win);
    gl->window = win;
    snprintf(gl->backend_name, sizeof gl->backend_name, "glfw");
    int rc = asp__gl_context_setup(gl, err);
    if (rc) {
        glfwDestroyWindow(win);
        glfwTerminate();
        asp_free(ctx, gl);
        return rc;
    }
    asp__gl_pin_driver();
    *out = gl;
    return 0;
}

int asp__gl_glfw_make_current(asp_gl_context *gl, asp_error *err)
{
    (void)err;
    if (glfwGetCurrentContext() != (GLFWwindow *)gl->window)
        glfwMakeContextCurrent((GLFWwindow *)gl->window);
    return 0;
}

void asp__gl_glfw_destroy(asp_gl_context *gl)
{
    glfwDestroyWindow((GLFWwindow *)gl->window);
    glfwTerminate();
}

void asp_gl_context_swap_buffers(asp_gl_context *gl)
{
    if (gl->backend == ASP__GL_GLFW)
        glfwSwapBuffers((GLFWwindow *)gl->window);
}

void asp_gl_context_poll_events(asp_gl_context *gl)
{
    if (gl->backend == ASP__GL_GLFW)
        glfwPollEvents();
}

int asp_gl_context_should_close(const asp_gl_context *gl)
{
    return gl->backend == ASP__GL_GLFW && glfwWindowShouldClose((GLFWwindow *)gl->window);
}

void asp_gl_context_framebuffer_size(const asp_gl_context *gl, uint32_t *width, uint32_t *height)
{
    int w = 0, h = 0;
    if (gl->backend == ASP__GL_GLFW)
        glfwGetFramebufferSize((GLFWwindow *)gl->window, &w, &h);
    *width = w > 0 ? (uint32_t)w : 0;
    *height = h > 0 ? (uint32_t)h : 0;
}

void *asp_gl_context_window(const asp_gl_context *gl)
{
    return gl->backend == ASP__GL_GLFW ? gl->window : NULL;
}

int asp_gl_context_read_window(asp_gl_context *gl, asp_image *out, asp_error *err)
{
    if (gl->backend != ASP__GL_GLFW)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read a window back: the context is headless");
    uint32_t w = 0, h = 0;
    asp_gl_context_framebuffer_size(gl, &w, &h);
    if (w == 0 || h == 0)
        return asp_error_set(err, ASP_EINVAL, "cannot read a window back: it has no pixels (minimised)");
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    asp_image img;
    rc = asp_image_init(&img, w, h, err);
    if (rc)
        return rc;
    size_t stride = 4 * (size_t)w;
    uint8_t *row = asp_alloc(&gl->actx, stride);
    if (!row) {
        asp_image_release(&img);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %ux%u window read-back", w, h);
    }
    asp__gl_clear_errors(gl);
    // the bytes as stored: already sRGB-encoded when the window is sRGB-capable
    glDisable(GL_FRAMEBUFFER_SRGB);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadnPixels(0, 0, (GLsizei)w, (GLsizei)h, GL_RGBA, GL_UNSIGNED_BYTE, (GLsizei)(stride * h), img.pixels);
    rc = asp__gl_check(gl, "read the window back", err);
    if (!rc) {
        asp__image_flip_rows(&img, row);
        // a window is opaque whatever alpha its visual stores (or lacks)
        for (size_t i = 0; i < (size_t)w * h; i++)
            img.pixels[4 * i + 3] = 255;
    }
    asp_free(&gl->actx, row);
    if (rc) {
        asp_image_release(&img);
        return rc;
    }
    *out = img;
    return 0;
}
