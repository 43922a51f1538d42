/*
 * Private to src/render/: eye-dome lighting (edl.c), the screen-space pass a
 * point renderer wraps around its own drawing when asp_edl_desc.strength > 0.
 */
#ifndef ASP_RENDER_EDL_INTERNAL_H
#define ASP_RENDER_EDL_INTERNAL_H

#include "render/internal.h"

typedef struct asp__edl {
    asp_edl_desc desc;        /* strength > 0: on; radius resolved (0 -> the default) */
    asp__gl_program program;
    asp__gl_vertex_array vao; /* empty: the full-screen triangle comes from gl_VertexID */
    asp__gl_framebuffer fbo;  /* the renderer draws here between begin and end */
    GLuint color, depth;      /* SRGB8_ALPHA8 and DEPTH_COMPONENT32F textures of fbo */
    uint32_t width, height;
    GLint caller;             /* the draw framebuffer bound at begin, composed into at end */
    GLint u_strength, u_radius, u_proj;
} asp__edl;

/* Checks desc (strength >= 0 and finite, radius in 0..16 px). Returns 0 or ASP_EINVAL. Pure. */
int asp__edl_check(const asp_edl_desc *desc, asp_error *err);

/* Keeps desc; compiles the pass when it is on. e is zeroed first. Returns 0, ASP_EGL or ASP_ENOMEM. */
int asp__edl_init(asp__edl *e, asp_gl_context *gl, const asp_edl_desc *desc, asp_error *err);

/* Nonzero when the pass is on (desc.strength > 0). */
static inline int asp__edl_on(const asp__edl *e)
{
    return e->desc.strength > 0;
}

/*
 * Redirects the drawing that follows into e's own single-sample target of
 * the frame's size, cleared to transparent black and depth 1, remembering
 * the caller's draw framebuffer. Returns 0 or ASP_EGL (target not complete).
 */
int asp__edl_begin(asp__edl *e, asp_gl_context *gl, const asp__frame *f, asp_error *err);

/*
 * Shades what was drawn since begin (Boucheny 2009) and writes it, with its
 * depth, over the caller's framebuffer, which is bound again; pixels where
 * nothing was drawn keep the caller's background. Returns 0 or ASP_EGL.
 */
int asp__edl_end(asp__edl *e, asp_gl_context *gl, const asp__frame *f, asp_error *err);

/* Frees e's GL objects (the context must be current); a zeroed e is accepted. */
void asp__edl_release(asp__edl *e);

#endif
