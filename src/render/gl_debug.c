/*
 * GL error collection (STYLE.md section 9: KHR_debug messages become
 * asp_error). The debug callback runs synchronously on the thread that made
 * the failing call and only records; the next asp__gl_check reports.
 */
#include <stdio.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

const char *asp__gl_error_name(GLenum code)
{
    switch (code) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
    default: return "unknown GL error";
    }
}

static void GLAPIENTRY on_debug_message(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                        const GLchar *message, const void *user)
{
    (void)source;
    (void)id;
    (void)severity;
    if (type != GL_DEBUG_TYPE_ERROR || !user)
        return;
    asp_gl_context *gl = (asp_gl_context *)user;
    // the first error is usually the cause; later ones are consequences
    if (gl->debug_errors++ == 0) {
        int n = length >= 0 && (size_t)length < sizeof gl->debug_msg ? (int)length : (int)sizeof gl->debug_msg - 1;
        snprintf(gl->debug_msg, sizeof gl->debug_msg, "%.*s", n, message ? message : "");
        // drivers end messages with a newline or full stop; our messages end bare
        size_t len = strlen(gl->debug_msg);
        while (len > 0 && (gl->debug_msg[len - 1] == '\n' || gl->debug_msg[len - 1] == '.' ||
                           gl->debug_msg[len - 1] == ' '))
            gl->debug_msg[--len] = '\0';
    }
}

void asp__gl_debug_install(asp_gl_context *gl)
{
    /*
     * Synchronous output keeps the callback on this thread, so it may write
     * gl without locking. Only errors are enabled: performance and other
     * chatter would cost time on debug contexts and mean nothing to users.
     */
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(on_debug_message, gl);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, NULL, GL_FALSE);
    glDebugMessageControl(GL_DONT_CARE, GL_DEBUG_TYPE_ERROR, GL_DONT_CARE, 0, NULL, GL_TRUE);
}

void asp__gl_clear_errors(asp_gl_context *gl)
{
    // glGetError keeps one flag per error kind; a bounded loop guards against a lost context
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; i++)
        ;
    gl->debug_errors = 0;
    gl->debug_msg[0] = '\0';
}

int asp__gl_check(asp_gl_context *gl, const char *what, asp_error *err)
{
    GLenum code = glGetError();
    unsigned n = gl->debug_errors;
    if (code == GL_NO_ERROR && n == 0)
        return 0;
    int rc;
    if (code == GL_OUT_OF_MEMORY) // issue #31: the same clean out-of-memory error as elsewhere
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory: cannot %s (GL_OUT_OF_MEMORY from %s)", what, gl->renderer);
    else if (n > 0)
        rc = asp_error_set(err, ASP_EGL, "cannot %s: %s: %s%s", what,
                           code != GL_NO_ERROR ? asp__gl_error_name(code) : "GL error", gl->debug_msg,
                           n > 1 ? " (and more errors)" : "");
    else
        rc = asp_error_set(err, ASP_EGL, "cannot %s: GL error %s", what, asp__gl_error_name(code));
    asp__gl_clear_errors(gl);
    return rc;
}
