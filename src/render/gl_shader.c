/*
 * GLSL program building with the compiler's log in the error message, so a
 * driver that rejects a shader says where (STYLE.md section 4: errors name
 * what failed and why).
 */
#include <stdio.h>
#include <string.h>

#include "render/internal.h"
#include "util/child_process.h"
#include "util/banned.h"

/* First line of a compiler log: the rest usually repeats the same cause. */
static void first_line(char *dst, size_t cap, const char *log)
{
    size_t n = strcspn(log, "\n");
    if (n >= cap)
        n = cap - 1;
    memcpy(dst, log, n);
    dst[n] = '\0';
}

static GLuint compile(GLenum stage, const char *src, const char *name, asp_error *err)
{
    const char *stage_name = stage == GL_VERTEX_SHADER ? "vertex" : "fragment";
    GLuint sh = glCreateShader(stage);
    if (!sh) {
        asp_error_set(err, ASP_EGL, "cannot create the %s shader of '%s'", stage_name, name);
        return 0;
    }
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = GL_FALSE;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "", line[160];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        first_line(line, sizeof line, log);
        asp_error_set(err, ASP_EGL, "cannot compile the %s shader of '%s': %s", stage_name, name, line);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

int asp__gl_program_create(asp_gl_context *gl, const char *name, const char *vs, const char *fs,
                           asp__gl_program *out, asp_error *err)
{
    asp__gl_clear_errors(gl);
    // issue #31: Mesa's compiler crashes when its allocations fail (ulimit -v); the room is checked first
    char room[224];
    snprintf(room, sizeof room, "compiling the '%.40s' shaders (%s)", name, gl->renderer);
    if (asp__address_space_headroom(ASP_GL_SHADER_HEADROOM, room, err))
        return ASP_ENOMEM;
    GLuint v = compile(GL_VERTEX_SHADER, vs, name, err);
    if (!v)
        return ASP_EGL;
    GLuint f = compile(GL_FRAGMENT_SHADER, fs, name, err);
    if (!f) {
        glDeleteShader(v);
        return ASP_EGL;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    // the program keeps the compiled stages; the shader objects can go now
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = GL_FALSE;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "", line[160];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        first_line(line, sizeof line, log);
        glDeleteProgram(p);
        return asp_error_set(err, ASP_EGL, "cannot link shader program '%s': %s", name, line);
    }
    char what[96];
    snprintf(what, sizeof what, "build shader program '%s'", name);
    int rc = asp__gl_check(gl, what, err);
    if (rc) {
        glDeleteProgram(p);
        return rc;
    }
    out->id = p;
    return 0;
}

void asp__gl_program_destroy(asp__gl_program *p)
{
    if (p->id)
        glDeleteProgram(p->id);
    p->id = 0;
}
