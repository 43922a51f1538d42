/*
 * Private to src/render/: the asp_gl_context layout shared by the EGL and GLFW
 * backends, typed GL object handles (STYLE.md section 9), error collection,
 * shader building, the offscreen target and the renderer interface.
 */
#ifndef ASP_RENDER_INTERNAL_H
#define ASP_RENDER_INTERNAL_H

#include <epoxy/gl.h>

#include "amgsplat/render.h"

/* Typed handles so a buffer can never be passed where a program is expected. */
typedef struct asp__gl_buffer { GLuint id; } asp__gl_buffer;
typedef struct asp__gl_program { GLuint id; } asp__gl_program;
typedef struct asp__gl_vertex_array { GLuint id; } asp__gl_vertex_array;
typedef struct asp__gl_framebuffer { GLuint id; } asp__gl_framebuffer;
typedef struct asp__gl_renderbuffer { GLuint id; } asp__gl_renderbuffer;

/* Offscreen render target, reused between renders of the same size. */
typedef struct asp__gl_target {
    uint32_t width, height, samples;
    asp__gl_framebuffer fbo;          /* draw target, multisampled when samples > 1 */
    asp__gl_renderbuffer color, depth;
    asp__gl_framebuffer resolve_fbo;  /* single-sample copy read back when samples > 1 */
    asp__gl_renderbuffer resolve_color;
} asp__gl_target;

enum asp__gl_backend { ASP__GL_EGL = 1, ASP__GL_GLFW = 2 };

struct asp_gl_context {
    asp_context actx;          /* allocator this struct came from */
    enum asp__gl_backend backend;
    void *egl_display;         /* EGLDisplay (EGL backend) */
    void *egl_context;         /* EGLContext (EGL backend) */
    void *window;              /* GLFWwindow * (GLFW backend) */
    char backend_name[32];
    char renderer[128];
    char version[128];
    GLint max_samples, max_size;
    /* KHR_debug errors collected by the callback, reported by asp__gl_check */
    unsigned debug_errors;
    char debug_msg[200];
    asp__gl_target target;
};

/* Queries strings and limits, checks GL >= 4.5 core, installs the debug callback. */
int asp__gl_context_setup(asp_gl_context *gl, asp_error *err);
/* Makes gl current if it is not. */
int asp__gl_ensure_current(asp_gl_context *gl, asp_error *err);
/* Backends' make-current. */
int asp__gl_egl_make_current(asp_gl_context *gl, asp_error *err);
int asp__gl_glfw_make_current(asp_gl_context *gl, asp_error *err);
void asp__gl_egl_destroy(asp_gl_context *gl);
void asp__gl_glfw_destroy(asp_gl_context *gl);

/* Installs the KHR_debug callback that collects errors into gl. */
void asp__gl_debug_install(asp_gl_context *gl);
/* Reports collected errors as "cannot <what>: GL error ..." (ASP_EGL) and clears them. */
int asp__gl_check(asp_gl_context *gl, const char *what, asp_error *err);
/* Discards collected errors (before an operation whose errors we want to attribute). */
void asp__gl_clear_errors(asp_gl_context *gl);

/*
 * Uploads one attribute array into a new immutable buffer (*buf) and binds it to vao at binding ==
 * location attr; divisor 1 advances it once per instance (discs), 0 once per vertex (meshes).
 */
void asp__gl_attrib_buffer(asp__gl_vertex_array vao, GLuint attr, asp__gl_buffer *buf, const void *data, size_t bytes,
                           GLint comps, GLenum type, GLboolean normalized, GLsizei stride, GLuint divisor);

/* Turns GL's bottom-up rows into asp_image's top-down ones in place; row: 4 * width bytes of scratch. */
void asp__image_flip_rows(asp_image *img, uint8_t *row);
/* "GL_INVALID_ENUM" for a glGetError code. */
const char *asp__gl_error_name(GLenum code);

/* Compiles and links a program from vertex and fragment sources; name appears in errors. */
int asp__gl_program_create(asp_gl_context *gl, const char *name, const char *vs, const char *fs,
                           asp__gl_program *out, asp_error *err);
void asp__gl_program_destroy(asp__gl_program *p);

/* After a multi-pass draw: the caller's draw framebuffer back and GL's default state (no blending, add
 * equation, no culling, depth test LESS with writes, all colour channels, no vertex array or program). */
void asp__gl_restore_state(GLuint fbo);

/* Makes sure gl->target is width x height with samples (reallocating if needed). */
int asp__gl_target_ensure(asp_gl_context *gl, uint32_t width, uint32_t height, uint32_t samples,
                          asp_error *err);
void asp__gl_target_release(asp__gl_target *t);

/* Per-frame values every renderer needs; matrices column-major. */
typedef struct asp__frame {
    float view[16], proj[16];
    float eye[3];          /* eye position in the renderer's (cloud-local) frame */
    float light_eye[3];    /* unit direction towards the light, eye coordinates */
    unsigned flags;        /* asp_render_flags */
    uint32_t width, height;
} asp__frame;

/*
 * The renderer interface: each kind fills its own function table, and the public calls
 * (renderer.c) only dispatch through it; a NULL optional entry means "not supported" and the
 * dispatcher answers for it (noted per entry). Nothing compares tables to learn a kind: a
 * kind's own public calls (asp_prim_renderer_options, ...) may check that a handle is theirs,
 * against their file's static table, and nothing else.
 *
 * Adding a renderer kind is one new file plus one table row:
 *  1. src/render/<kind>_renderer.c: a struct starting with asp_renderer base, a static
 *     asp__renderer_vtable with name, draw, destroy and whichever optional entries the kind
 *     supports, and a create function (declared in include/amgsplat/render.h) that sets
 *     base.vt, base.gl and base.count. CMake picks the file up (it globs src/render).
 *  2. src/render/renderer_table.c: a make_<kind> adapter (source and options to the create
 *     call) and one row in kinds[] (asp_renderer_kind: name, noun, inputs, has_lod, create).
 *     render, view and eval then offer it by name; asp_renderer_options (render.h) gains a desc
 *     field if the kind has options.
 * No other file changes: the scene renderer, frame budget, statistics and LOD controls reach
 * the kind only through the entries below.
 */
typedef struct asp__renderer_vtable {
    const char *name;
    int (*draw)(asp_renderer *r, const asp__frame *frame, asp_error *err);
    void (*destroy)(asp_renderer *r);
    /* Optional (NULL = ASP_EUNSUPPORTED from asp_renderer_set_lod). Takes the screen tolerance in
     * pixels (already checked finite and >= 0) and the depth limit, so one controller (a frame
     * budget, asp_renderer_set_lod) drives points, primitives, hybrids and scenes alike. */
    int (*set_lod)(asp_renderer *r, float tolerance, uint32_t depth_limit, asp_error *err);
    /* Optional: figures of the last frame for asp_renderer_stats_get, which zeroes *out and presets
     * count and points to r->count first (what a NULL entry reports). */
    void (*stats)(const asp_renderer *r, asp_renderer_stats *out);
    /* Optional: draws count instances in one frame, instance i placed by models[16 i .. 16 i + 15]
     * (renderer-local to world, column-major), sharing one accumulation/normalisation where the
     * renderer has one, so instances occlude and blend as one surface set. NULL: a scene draws
     * such a renderer once per instance with the model folded into frame->view. */
    int (*draw_instances)(asp_renderer *r, const asp__frame *frame, const float *models, size_t count,
                          asp_error *err);
    /* Optional (NULL = ASP_EUNSUPPORTED from asp_renderer_set_budget): cut to at most splats
     * primitives per frame instead of the tolerance (0 = off). */
    int (*set_budget)(asp_renderer *r, size_t splats, asp_error *err);
    /* Optional (NULL = 1): whether draw_instances suits r's current options; 0 makes a scene draw r
     * one instance at a time, far to near (e.g. primitive methods that paint without a depth test). */
    int (*instanced)(const asp_renderer *r);
} asp__renderer_vtable;

/* Whether a scene draws r's instances with one draw_instances call: the entry exists and instanced allows it. */
int asp__renderer_instanced(const asp_renderer *r);

/*
 * The frame of an instance placed by model (renderer-local to world, column-major, affine): view *
 * model as the view, the eye moved into the local frame (model^-1 eye; asp_camera_fold_model).
 * renderer.c; the per-instance draws of the scene renderer and of draw_instances implementations
 * share it.
 */
void asp__frame_fold(const asp__frame *f, const float model[16], asp__frame *out);

struct asp_renderer {
    const asp__renderer_vtable *vt;
    asp_gl_context *gl;
    size_t count;
};

/* sRGB 8-bit to linear light (IEC 61966-2-1). */
float asp__srgb_to_linear(uint8_t v);
/* Linear light in 0..1 to sRGB 8-bit, rounded to nearest. */
uint8_t asp__linear_to_srgb(float v);

/*
 * Sanitizer builds: keeps the current context's GL driver loaded until exit
 * (gl_driver_pin.c explains why); called after a window context is made. A
 * no-op otherwise.
 */
void asp__gl_pin_driver(void);

#endif
