/*
 * Private to the hierarchy renderers (splat_renderer.c, square_renderer.c):
 * the point hierarchy's splats uploaded once to a GL shader storage buffer,
 * and the per-frame view-dependent cut (seed 001 section 5.1 step 1, seed 004
 * 3.2) uploaded as a list of splat ids that an instanced draw reads.
 */
#ifndef ASP_RENDER_SPLAT_INTERNAL_H
#define ASP_RENDER_SPLAT_INTERNAL_H

#include "render/internal.h"

/* Shader storage bindings shared by the hierarchy renderers' vertex shaders. */
enum { ASP__LOD_BIND_SPLATS = 0, ASP__LOD_BIND_IDS = 1, ASP__LOD_BIND_CONES = 2,
       ASP__LOD_BIND_CLIPS = 3 /* splat renderer only: 2 clip planes per point splat */ };

/*
 * GLSL declarations of the buffers, a function reading splat `id` into local
 * variables: centre c, colour bits, normal n, axes u, v with semi-axes a, b
 * (asp_hier_splat, 64 bytes = 4 uvec4; uvec4 because the colour bytes read as
 * a float could be a NaN pattern a driver need not preserve), and the
 * per-frame uniforms that asp__lod_frame_uniforms sets.
 */
#define ASP__LOD_GLSL                                                                   \
    "layout(std430, binding = 0) readonly buffer Splats { uvec4 splats[]; };\n"         \
    "layout(std430, binding = 1) readonly buffer Ids { uint ids[]; };\n"                \
    "layout(std430, binding = 2) readonly buffer Cones { float cones[]; };\n"           \
    "struct splat { vec3 c; uint color; vec3 n; vec3 u; float a; vec3 v; float b; };\n" \
    "splat read_splat(uint id) {\n"                                                     \
    "    uvec4 s0 = splats[4u * id], s1 = splats[4u * id + 1u];\n"                      \
    "    uvec4 s2 = splats[4u * id + 2u], s3 = splats[4u * id + 3u];\n"                 \
    "    splat s;\n"                                                                    \
    "    s.c = uintBitsToFloat(s0.xyz); s.color = s0.w; s.n = uintBitsToFloat(s1.xyz);\n" \
    "    s.u = uintBitsToFloat(s2.xyz); s.a = uintBitsToFloat(s2.w);\n"                 \
    "    s.v = uintBitsToFloat(s3.xyz); s.b = uintBitsToFloat(s3.w);\n"                 \
    "    return s;\n"                                                                   \
    "}\n"                                                                               \
    "vec3 srgb_to_linear(vec3 c) {\n"                                                   \
    "    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));\n" \
    "}\n"                                                                               \
    "uniform mat4 u_view;\n"                                                            \
    "uniform mat4 u_proj;\n"                                                            \
    "uniform vec3 u_eye;\n"                                                             \
    "uniform vec3 u_light;\n"

/* The names of the uniforms of ASP__LOD_GLSL, which start every hierarchy renderer's table of locations. */
#define ASP__LOD_UNIFORM_NAMES "u_view", "u_proj", "u_eye", "u_light"
enum { ASP__LOD_U_VIEW, ASP__LOD_U_PROJ, ASP__LOD_U_EYE, ASP__LOD_U_LIGHT, ASP__LOD_U_COUNT };

/* The hierarchy on the GPU plus the last cut. */
typedef struct asp__lod {
    const asp_hier *hier;
    asp_hier *owned;          /* built by the renderer (freed with it), or NULL when borrowed */
    asp__gl_buffer splats;    /* asp_hier_splats, (nodes + points) * 64 bytes */
    asp__gl_buffer cones;     /* per node: the normal-cone semi-angle used for lighting */
    asp__gl_buffer ids;       /* the cut: select_bound splat ids, rewritten every frame */
    asp_index *cut;           /* CPU copy of the cut, select_bound entries */
    size_t capacity;
    size_t nodes, points;
    int has_colors;
    float default_color[4];   /* sRGB 0..1 for hierarchies without colours */
    float tolerance;
    uint32_t depth_limit;
    size_t budget;            /* > 0: cut to this many splats (asp_hier_select_count) instead of tau */
    int cull_backfaces;
    size_t count;             /* splats in the last cut */
    double select_seconds;
} asp__lod;

/* Every hierarchy renderer starts with these two members. */
typedef struct asp__lod_renderer {
    asp_renderer base;
    asp__lod lod;
} asp__lod_renderer;

/*
 * The hybrid renderer's access to a splat renderer r (hybrid_renderer.c):
 * select cuts the hierarchy for f (asp__lod_select); pass draws the cut into
 * the bound framebuffer with the caller's depth and blend state: depth_only 1
 * the epsilon-offset depth (seed 001 5.3), 0 the sums (psi c, psi) of eq. 10.
 */
int asp__splat_hybrid_select(asp_renderer *r, const asp__frame *f, asp_error *err);
void asp__splat_hybrid_pass(asp_renderer *r, const asp__frame *f, int depth_only);

/*
 * The set_lod, set_budget and stats entries of every hierarchy renderer's table (splat_lod.c):
 * r is an asp__lod_renderer; set_lod takes the tolerance asp_renderer_set_lod has checked.
 */
int asp__lod_set_lod(asp_renderer *r, float tolerance, uint32_t depth_limit, asp_error *err);
int asp__lod_set_budget(asp_renderer *r, size_t splats, asp_error *err);
void asp__lod_stats(const asp_renderer *r, asp_renderer_stats *out);

/* The options that asp_splat_renderer_desc and asp_square_renderer_desc share, borrowed from the caller's desc. */
typedef struct asp__lod_desc {
    const asp_hier_desc *hier;
    const asp_context *ctx;
    float tolerance;
    unsigned flags;
    const uint8_t *default_color; /* 4 bytes; all 0 means light grey */
} asp__lod_desc;

/* The shared options of d, an asp_splat_renderer_desc or asp_square_renderer_desc (the fields have the same names). */
#define ASP__LOD_DESC(d, c) (&(const asp__lod_desc){&(d)->hier, (c), (d)->tolerance, (d)->flags, (d)->default_color})

/*
 * Allocates a zeroed renderer of size bytes (a struct that starts with
 * asp__lod_renderer) drawing through vt, and builds (cloud != NULL, owned) or
 * borrows (hier) its hierarchy. On failure nothing stays allocated.
 */
int asp__lod_renderer_create(asp_gl_context *gl, size_t size, const asp__renderer_vtable *vt, const asp_cloud *cloud,
                             const asp_hier *hier, const asp__lod_desc *desc, asp__lod_renderer **out, asp_error *err);

/*
 * The last step of creating r: reports the GL errors of its setup as "cannot
 * create the <vt->name> renderer" and destroys r (vt->destroy), or hands r out.
 */
int asp__lod_renderer_finish(asp__lod_renderer *r, asp_renderer **out, asp_error *err);

/* Releases the hierarchy and the cut and frees r; the renderer's own GL objects go first. */
void asp__lod_renderer_free(asp__lod_renderer *r);

/* Uploads the splats and cone angles and makes the cut buffers; gl must be current. */
int asp__lod_upload(asp_gl_context *gl, asp__lod *lod, const char *what, asp_error *err);

/*
 * Cuts the hierarchy for the frame, uploads the ids and binds the three
 * storage buffers; sets lod->count (and base->count).
 */
int asp__lod_select(asp__lod_renderer *r, const asp__frame *f, asp_error *err);

/* Sets the uniforms of ASP__LOD_GLSL from f; loc holds their locations in ASP__LOD_U_* order. */
void asp__lod_frame_uniforms(GLuint program, const GLint *loc, const asp__frame *f);

/* Frees GL buffers, the cut and an owned hierarchy. */
void asp__lod_release(const asp_context *actx, asp__lod *lod);

/* Validates a float option: finite and >= 0 (0 = default). */
int asp__lod_check_option(const char *renderer, const char *name, float v, asp_error *err);

#endif
