/*
 * Headless OpenGL 4.5 through EGL without any surface (EGL_KHR_surfaceless_
 * context): renders go to an offscreen framebuffer (framebuffer.c). Tries GPU
 * devices, Mesa's surfaceless platform (llvmpipe on machines without a GPU),
 * software devices, then the default display (STYLE.md section 9).
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include <epoxy/egl.h>

#include "render/internal.h"
#include "util/banned.h"
#include "util/child_process.h"

enum { MAX_DEVICES = 16 };

/* What was tried and why it failed, for the one error message the caller sees. */
struct trail {
    char text[220];
    size_t len;
};

static void trail_add(struct trail *t, const char *fmt, ...)
{
    if (t->len + 4 >= sizeof t->text)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(t->text + t->len, sizeof t->text - t->len, fmt, ap);
    va_end(ap);
    if (n > 0)
        t->len += (size_t)n < sizeof t->text - t->len ? (size_t)n : sizeof t->text - t->len - 1;
}

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "unknown EGL error";
    }
}

/* Whole-word search in a space-separated extension list (NULL means none). */
static int has_ext(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

static EGLContext create_context(EGLDisplay dpy, unsigned flags, const char *dpy_ext, EGLint minor_egl)
{
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_ext(dpy_ext, "EGL_KHR_no_config_context") && !has_ext(dpy_ext, "EGL_MESA_configless_context")) {
        /*
         * EGL_SURFACE_TYPE defaults to EGL_WINDOW_BIT, which no config of a display without windows
         * has (NVIDIA's EGL device platform): ask for pbuffer configs, then for any (mask 0).
         */
        const EGLint want[2][5] = {{EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE},
                                   {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE}};
        EGLint n = 0;
        for (int i = 0; i < 2 && n < 1; i++)
            if (!eglChooseConfig(dpy, want[i], &config, 1, &n))
                n = 0;
        if (n < 1)
            return EGL_NO_CONTEXT;
    }
    // EGL 1.5 spells the debug request as a boolean, EGL_KHR_create_context as a flag bit
    EGLint attrs[16], k = 0;
    attrs[k++] = EGL_CONTEXT_MAJOR_VERSION_KHR;
    attrs[k++] = 4;
    attrs[k++] = EGL_CONTEXT_MINOR_VERSION_KHR;
    attrs[k++] = 5;
    attrs[k++] = EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR;
    attrs[k++] = EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR;
    if (flags & ASP_GL_CONTEXT_DEBUG) {
        if (minor_egl >= 5) {
            attrs[k++] = EGL_CONTEXT_OPENGL_DEBUG;
            attrs[k++] = EGL_TRUE;
        } else {
            attrs[k++] = EGL_CONTEXT_FLAGS_KHR;
            attrs[k++] = EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR;
        }
    }
    attrs[k] = EGL_NONE;
    return eglCreateContext(dpy, config, EGL_NO_CONTEXT, attrs);
}

/* Tries one display; on success gl holds a current 4.5 context and 1 is returned. */
static int try_display(asp_gl_context *gl, EGLDisplay dpy, const char *label, unsigned flags, struct trail *t)
{
    if (dpy == EGL_NO_DISPLAY) {
        trail_add(t, "%s%s: no display (%s)", t->len ? "; " : "", label, egl_error_name(eglGetError()));
        return 0;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor)) {
        trail_add(t, "%s%s: eglInitialize failed (%s)", t->len ? "; " : "", label, egl_error_name(eglGetError()));
        return 0;
    }
    /*
     * The display stays initialised on every path: EGL displays are shared by
     * the whole process, and eglTerminate would break other users of it.
     */
    const char *ext = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_ext(ext, "EGL_KHR_surfaceless_context")) {
        trail_add(t, "%s%s: no EGL_KHR_surfaceless_context", t->len ? "; " : "", label);
        return 0;
    }
    if (!has_ext(ext, "EGL_KHR_create_context") && (major < 1 || (major == 1 && minor < 5))) {
        trail_add(t, "%s%s: EGL %d.%d cannot ask for a core profile", t->len ? "; " : "", label, major, minor);
        return 0;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        trail_add(t, "%s%s: no desktop OpenGL (%s)", t->len ? "; " : "", label, egl_error_name(eglGetError()));
        return 0;
    }
    EGLContext ctx = create_context(dpy, flags, ext, major > 1 ? 5 : minor);
    if (ctx == EGL_NO_CONTEXT) {
        trail_add(t, "%s%s: eglCreateContext for OpenGL 4.5 core failed (%s)", t->len ? "; " : "", label,
                  egl_error_name(eglGetError()));
        return 0;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        trail_add(t, "%s%s: eglMakeCurrent failed (%s)", t->len ? "; " : "", label, egl_error_name(eglGetError()));
        eglDestroyContext(dpy, ctx);
        return 0;
    }
    gl->egl_display = dpy;
    gl->egl_context = ctx;
    asp_error setup_err = {0, ""};
    if (asp__gl_context_setup(gl, &setup_err) != 0) {
        trail_add(t, "%s%s: %s", t->len ? "; " : "", label, setup_err.msg);
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(dpy, ctx);
        gl->egl_display = gl->egl_context = NULL;
        return 0;
    }
    snprintf(gl->backend_name, sizeof gl->backend_name, "%s", label);
    return 1;
}

static int is_software_device(EGLDeviceEXT dev, const char *client_ext)
{
    if (!has_ext(client_ext, "EGL_EXT_device_query"))
        return 0;
    return has_ext(eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS), "EGL_MESA_device_software");
}

/* Tries the EGL devices whose software-ness equals want_software. */
static int try_devices(asp_gl_context *gl, const char *client_ext, int want_software, unsigned flags,
                       struct trail *t)
{
    if (!has_ext(client_ext, "EGL_EXT_platform_device") ||
        !(has_ext(client_ext, "EGL_EXT_device_enumeration") || has_ext(client_ext, "EGL_EXT_device_base")))
        return 0;
    EGLDeviceEXT devices[MAX_DEVICES];
    EGLint n = 0;
    if (!eglQueryDevicesEXT(MAX_DEVICES, devices, &n))
        return 0;
    for (EGLint i = 0; i < n; i++) {
        if (is_software_device(devices[i], client_ext) != want_software)
            continue;
        EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
        if (try_display(gl, dpy, "egl-device", flags, t))
            return 1;
    }
    return 0;
}

static int try_surfaceless(asp_gl_context *gl, const char *client_ext, unsigned flags, struct trail *t)
{
    if (!has_ext(client_ext, "EGL_MESA_platform_surfaceless"))
        return 0;
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    return try_display(gl, dpy, "egl-surfaceless", flags, t);
}

int asp_gl_context_create_headless(const asp_gl_context_desc *desc, const asp_context *ctx, asp_gl_context **out,
                                  asp_error *err)
{
    static const asp_gl_context_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    // Mesa does not survive running out of address space while it loads (util/child_process.h)
    int rc = asp__address_space_headroom(ASP_GL_CONTEXT_HEADROOM, "creating a GL context", err);
    if (rc)
        return rc;
    asp_gl_context *gl = asp_calloc(ctx, 1, sizeof *gl);
    if (!gl)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a GL context");
    if (ctx)
        gl->actx = *ctx;
    gl->backend = ASP__GL_EGL;

    /* Client extensions need EGL 1.5 or EGL_EXT_client_extensions; NULL means neither. */
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client)
        eglGetError(); // clear EGL_BAD_DISPLAY
    if (!has_ext(client, "EGL_EXT_platform_base"))
        client = NULL; // eglGetPlatformDisplayEXT is unavailable: only the default display is left
    struct trail t = {"", 0};
    unsigned flags = desc->flags;
    int ok;
    if (flags & ASP_GL_CONTEXT_SOFTWARE)
        ok = try_surfaceless(gl, client, flags, &t) || try_devices(gl, client, 1, flags, &t) ||
             try_display(gl, eglGetDisplay(EGL_DEFAULT_DISPLAY), "egl-default", flags, &t) ||
             try_devices(gl, client, 0, flags, &t);
    else
        // GPUs first: on a machine with both, Mesa's surfaceless platform would pick llvmpipe
        ok = try_devices(gl, client, 0, flags, &t) || try_surfaceless(gl, client, flags, &t) ||
             try_devices(gl, client, 1, flags, &t) ||
             try_display(gl, eglGetDisplay(EGL_DEFAULT_DISPLAY), "egl-default", flags, &t);
    if (!ok) {
        asp_free(ctx, gl);
        return asp_error_set(err, ASP_EGL, "no OpenGL 4.5 context: %s", t.text);
    }
    *out = gl;
    return 0;
}

int asp__gl_egl_make_current(asp_gl_context *gl, asp_error *err)
{
    if (eglGetCurrentContext() == (EGLContext)gl->egl_context)
        return 0;
    if (!eglMakeCurrent((EGLDisplay)gl->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, (EGLContext)gl->egl_context))
        return asp_error_set(err, ASP_EGL, "cannot make the GL context current: eglMakeCurrent failed (%s)",
                             egl_error_name(eglGetError()));
    return 0;
}

void asp__gl_egl_destroy(asp_gl_context *gl)
{
    EGLDisplay dpy = (EGLDisplay)gl->egl_display;
    if (eglGetCurrentContext() == (EGLContext)gl->egl_context)
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(dpy, (EGLContext)gl->egl_context);
}
