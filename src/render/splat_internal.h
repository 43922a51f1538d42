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
 * GLSL declarations of the buffers, and a function reading splat `id` into
 * local variables: centre c, colour bits, normal n, axes u, v with semi-axes
 * a, b (asp_hier_splat, 64 bytes = 4 uvec4; uvec4 because the colour bytes
 * read as a float could be a NaN pattern a driver need not preserve).
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
    "}\n"

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

extern const asp__renderer_vtable asp__splat_vtable;
extern const asp__renderer_vtable asp__square_vtable;

/* r as a hierarchy renderer, or NULL for other kinds. */
asp__lod_renderer *asp__lod_renderer_of(asp_renderer *r);

/*
 * Checks the shared options and builds (cloud != NULL, owned) or borrows
 * (hier) the hierarchy. default_color all 0 means light grey.
 */
int asp__lod_prepare(asp__lod *lod, const asp_cloud *cloud, const asp_hier *hier, const asp_hier_desc *hdesc,
                     const asp_context *ctx, float tolerance, unsigned flags, const uint8_t default_color[4],
                     asp_error *err);

/* Uploads the splats and cone angles and makes the cut buffers; gl must be current. */
int asp__lod_upload(asp_gl_context *gl, asp__lod *lod, const char *what, asp_error *err);

/*
 * Cuts the hierarchy for the frame, uploads the ids and binds the three
 * storage buffers; sets lod->count (and base->count).
 */
int asp__lod_select(asp__lod_renderer *r, const asp__frame *f, asp_error *err);

/* Frees GL buffers, the cut and an owned hierarchy. */
void asp__lod_release(const asp_context *actx, asp__lod *lod);

/* Validates a float option: finite and >= 0 (0 = default). */
int asp__lod_check_option(const char *renderer, const char *name, float v, asp_error *err);

#endif
