/*
 * Private to the domain-primitive renderer (prim_renderer.c, prim_methods.c,
 * prim_shaders.c): the primitives of one .dps level on the GPU, the offscreen
 * targets of the rendering methods (journal section 4, thesis chapter 4,
 * Pajarola et al. 2003 section 5.4) and the per-frame draw list.
 */
#ifndef ASP_RENDER_PRIM_INTERNAL_H
#define ASP_RENDER_PRIM_INTERNAL_H

#include "render/internal.h"

/* Storage-buffer bindings of the primitive shaders. */
enum { ASP__PRIM_BIND_PRIMS = 0, ASP__PRIM_BIND_NEIGHBOURS = 1, ASP__PRIM_BIND_CLIPS = 2 };

/* Texture units of the primitive shaders. */
enum { ASP__PRIM_UNIT_ATLAS = 0, ASP__PRIM_UNIT_NORMALS = 1, ASP__PRIM_UNIT_FRONT_DEPTH = 2,
       ASP__PRIM_UNIT_FRONT_ID = 3, ASP__PRIM_UNIT_ACCUM = 4 };

/*
 * One primitive as the shaders read it (std430, 112 bytes): centre relative to
 * the renderer's origin, the half-extent vectors half_u axis_u and half_v
 * axis_v, the unit normal, the atlas rectangle in texture coordinates
 * (u0, v0, du, dv) and (neighbour first, neighbour count, packed sRGB domain
 * colour, flags).
 */
typedef struct asp__prim_gpu {
    float c[4], u[4], v[4], n[4], uv[4];
    uint32_t info[4];
    uint32_t clip[4]; /* crease records: first, count (asp__prim_creases), 0, 0 */
} asp__prim_gpu;

/* What a fragment of the main program does (uniform u_pass). */
enum asp__prim_pass {
    ASP__PASS_ADD = 0,    /* additive (colour x alpha, alpha) */
    ASP__PASS_OPAQUE = 1, /* colour, alpha 1 (no-blend, polygons) */
    ASP__PASS_CLEAR = 2,  /* hard dark back-face: writes 0 where alpha > 0 */
    ASP__PASS_DARKEN = 3, /* soft dark back-face: (alpha, alpha, alpha, alpha), reverse-subtracted */
    ASP__PASS_OUTLINE = 4 /* the support rectangle's edges in one colour */
};

/* How pass-2 fragments are selected against the front-most layer (uniform u_select). */
enum { ASP__SELECT_ALL = 0, ASP__SELECT_WINDOW = 1, ASP__SELECT_PREFIX = 2 };

/* The shader programs: the main one (colour passes), depth only (optionally offset), id + depth, resolve. */
enum { ASP__PROG_MAIN, ASP__PROG_DEPTH, ASP__PROG_ID, ASP__PROG_RESOLVE, ASP__PROG_COUNT };

extern const char *const asp__prim_vertex_src;
extern const char *const asp__prim_fragment_src[3]; /* main, depth, id (same order as the programs) */
extern const char *const asp__prim_resolve_vertex_src;
extern const char *const asp__prim_resolve_fragment_src;

/* Uniform names shared by the programs; a program lacking one gets location -1 (ignored by GL). */
enum { PU_VIEW, PU_PROJ, PU_LIGHT, PU_LIT, PU_NORMAL_MAP, PU_DOMAIN_COLORS, PU_PASS, PU_SELECT, PU_ALPHA_REF,
       PU_TRANSPARENCY, PU_WINDOW, PU_OFFSET, PU_OUTLINE_COLOR, PU_CORNERS, PU_NORMALIZE, PU_CREASE_COS, PU_COUNT };
extern const char *const asp__prim_uniform_names[PU_COUNT];

/* A run of consecutive entries of the frame's draw order, drawn with one state. */
typedef enum asp__run_kind {
    ASP__RUN_ADD,       /* additive colour, depth-tested against the locks, no depth writes */
    ASP__RUN_LOCK,      /* depth only, alpha test (overlap's lock) */
    ASP__RUN_CLEAR,     /* dark back-face, hard */
    ASP__RUN_DARKEN     /* dark back-face, soft */
} asp__run_kind;

typedef struct asp__run {
    asp__run_kind kind;
    uint32_t first, count;
} asp__run;

/* Offscreen targets, kept while the size stays. */
typedef struct asp__prim_targets {
    uint32_t width, height;
    GLuint accum_float;  /* RGBA32F: normalized, prefix */
    GLuint accum_fixed;  /* RGBA16 unorm: the seeds' methods, clamped like their 8-bit framebuffers */
    GLuint depth;        /* DEPTH_COMPONENT32F */
    GLuint id;           /* R32UI: the front-most primitive + 1 (prefix) */
    asp__gl_framebuffer seed_fbo;  /* accum_fixed + depth */
    asp__gl_framebuffer front_fbo; /* id + depth */
    asp__gl_framebuffer accum_fbo; /* accum_float only: pass 2 reads depth and id as textures */
} asp__prim_targets;

typedef struct asp__prim_renderer {
    asp_renderer base; /* first: an asp_renderer * is an asp__prim_renderer * */
    asp_prim_render_options opt; /* resolved: defaults filled in */
    float default_window;        /* depth window when opt.depth_window is 0 */
    size_t count, neighbour_total;
    int has_normal_map;
    int billboards;              /* the level is a billboard cloud (asp_dps_level.billboards): always no-blend */
    /* CPU copies for sorting and the overlap traversal */
    float *centres;              /* 3 per primitive, local frame */
    float *normals;              /* 3 per primitive */
    uint32_t *nb_first, *nb_count, *neighbours;
    /* per frame */
    uint32_t *order;             /* draw order, up to 2 count + 1 entries (overlap: colour + lock lists) */
    asp__run *runs;              /* up to 2 count + 1 */
    size_t order_capacity;
    struct asp__prim_key { float key; uint32_t id; } *keys; /* sort keys (squared eye distance), count */
    uint32_t *drawn;             /* overlap's R flags, count */
    /* GL */
    asp__gl_program programs[ASP__PROG_COUNT];
    GLint uniforms[ASP__PROG_COUNT][PU_COUNT];
    asp__gl_buffer prim_buffer, neighbour_buffer, order_buffer, identity_buffer;
    asp__gl_buffer clip_buffer;  /* crease records (asp__prim_creases) */
    size_t crease_total;
    asp__gl_vertex_array vao;    /* a_id from order_buffer */
    asp__gl_vertex_array identity_vao; /* a_id = 0 .. count-1 */
    asp__gl_vertex_array empty_vao;    /* the resolve triangle */
    GLuint atlas, normal_atlas;  /* textures */
    asp__prim_targets t;
    struct asp__prim_debug *debug; /* debug drawings (prim_debug.c), made on first use */
} asp__prim_renderer;

/* Draws one frame with r->opt into the currently bound draw framebuffer. */
int asp__prim_draw(asp__prim_renderer *r, const asp__frame *f, asp_error *err);
/* draw_instances of the vtable: count instances placed by models (16 floats each), one accumulation
 * for the normalized method, else one frame each far to near. */
int asp__prim_draw_instances(asp__prim_renderer *r, const asp__frame *f, const float *models, size_t count,
                             asp_error *err);

/*
 * Finds the pairs of primitives of lv that cross at a sharp crease (more than
 * 20 degrees, along a line inside both rectangles where both textures' alpha
 * exceeds 0.1, consistent sides, the cut removing an alpha-weighted area of at
 * most one texel times its length; prim_creases.c) in the frame centred on origin. Writes per primitive
 * first[i], count[i] (n entries each) into *entries, 8 floats per record:
 * the other's support plane (nx, ny, nz, d) oriented so i's kept side is
 * >= 0, cos of their angle, the other's id, 0, 0; *total records (the array
 * has at least one, zeroed). Free *entries with asp_free(ctx). Returns 0 or
 * ASP_ENOMEM.
 */
int asp__prim_creases(const asp_dps_level *lv, const double origin[3], const asp_context *ctx, uint32_t *first,
                      uint32_t *count, float **entries, size_t *total, asp_error *err);

/*
 * The hybrid renderer's access (hybrid_renderer.c). keep writes the ids of
 * the primitives not replaced (replaced: count flags) to the draw order once
 * and returns how many; the crease records stay those of the whole level, so
 * a kept primitive is still cut by the plane of a replaced neighbour. begin
 * sets the frame's uniforms (opacity 1, texture colours); pass binds r's
 * buffers and textures and draws the kept front-facing primitives into the
 * bound framebuffer with the caller's depth and blend state: depth_only 1
 * writes the alpha-tested depth pushed back by the depth window along the eye
 * rays, 0 adds (colour x alpha, alpha) of every fragment.
 */
size_t asp__prim_hybrid_keep(asp__prim_renderer *r, const uint8_t *replaced);
void asp__prim_hybrid_begin(asp__prim_renderer *r, const asp__frame *f);
void asp__prim_hybrid_pass(asp__prim_renderer *r, size_t kept, int depth_only);

/* Frees the offscreen targets. */
void asp__prim_targets_release(asp__prim_targets *t);

/* Thesis appendix C debug drawings (ASP_PRIM_RENDER_DEBUG_*) over the current draw framebuffer; prim_debug.c. */
int asp__prim_debug_draw(asp__prim_renderer *r, const asp__frame *f, asp_error *err);
void asp__prim_debug_destroy(asp__prim_renderer *r);
/* asp_prim_renderer_set_debug_lines on a renderer known to be r (prim_renderer.c checked the kind). */
int asp__prim_debug_set_lines(asp__prim_renderer *r, const float *lines, size_t segments, asp_error *err);

#endif
