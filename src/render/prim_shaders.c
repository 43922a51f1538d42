/*
 * GLSL of the domain-primitive renderer: each primitive is its textured
 * support rectangle (journal section 3, thesis 3.1), coloured by the atlas
 * (colour x alpha, alpha = basis function, thesis 4.3) and selected against
 * the front-most layer for the normalized and prefix methods (thesis 4.4,
 * Fig. 4.5; Pajarola et al. 2003 sections 5.3-5.4).
 */
#include "render/prim_internal.h"
#include "util/banned.h"

/* The primitive, neighbour and crease-plane buffers (prim_internal.h asp__prim_gpu, clip_buffer). */
#define PRIM_GLSL                                                                    \
    "struct prim { vec4 c; vec4 u; vec4 v; vec4 n; vec4 uv; uvec4 info; uvec4 clip; };\n" \
    "layout(std430, binding = 0) readonly buffer Prims { prim prims[]; };\n"        \
    "layout(std430, binding = 1) readonly buffer Neighbours { uint nbrs[]; };\n"    \
    "layout(std430, binding = 2) readonly buffer Clips { vec4 clips[]; };\n" /* 2 per record */

/*
 * u_corners 0: triangle-strip order, counter-clockwise seen from the normal
 * (axis_u x axis_v), so GL back-face culling agrees with the thesis's
 * "facing the camera" test; 1: line-loop order for outlines, pulled slightly
 * towards the eye so an outline wins the depth test against its own rectangle.
 */
const char *const asp__prim_vertex_src =
    "#version 450 core\n" PRIM_GLSL
    "layout(location = 0) in uint a_id;\n"
    "uniform mat4 u_view;\n"
    "uniform mat4 u_proj;\n"
    "uniform int u_corners;\n"
    "out vec2 v_uv;\n"
    "out vec3 v_eye;\n"
    "out vec3 v_local;\n"
    "flat out uint v_id;\n"
    "flat out vec3 v_normal;\n"
    "flat out vec3 v_domain;\n"
    "const vec2 strip[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));\n"
    "const vec2 loop[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0));\n"
    "vec3 srgb_to_linear(vec3 c) {\n"
    "    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));\n"
    "}\n"
    "void main() {\n"
    "    prim p = prims[a_id];\n"
    "    vec2 k = u_corners != 0 ? loop[gl_VertexID] : strip[gl_VertexID];\n"
    "    vec3 w = p.c.xyz + k.x * p.u.xyz + k.y * p.v.xyz;\n"
    "    v_uv = p.uv.xy + (0.5 * k + 0.5) * p.uv.zw;\n"
    "    vec4 e = u_view * vec4(w, 1.0);\n"
    "    v_eye = e.xyz;\n"
    "    v_local = w;\n"
    "    v_id = a_id;\n"
    "    v_normal = mat3(u_view) * p.n.xyz;\n"
    "    v_domain = srgb_to_linear(unpackUnorm4x8(p.info.z).rgb);\n"
    "    gl_Position = u_proj * e;\n"
    "    if (u_corners != 0)\n"
    "        gl_Position.z -= 2e-4 * gl_Position.w;\n"
    "}\n";

/*
 * Fragment stages share this prologue. window_depth maps an eye-space point
 * to the depth buffer's 0..1 (glDepthRange 0, 1); eye_distance inverts it
 * for a stored depth: -z_eye = P32 / (ndc + P22).
 */
#define FRAGMENT_PROLOGUE                                                                   \
    "#version 450 core\n" PRIM_GLSL                                                         \
    "in vec2 v_uv;\n"                                                                       \
    "in vec3 v_eye;\n"                                                                      \
    "in vec3 v_local;\n"                                                                    \
    "flat in uint v_id;\n"                                                                  \
    "flat in vec3 v_normal;\n"                                                              \
    "flat in vec3 v_domain;\n"                                                              \
    "layout(binding = 0) uniform sampler2D u_atlas;\n"                                      \
    "uniform mat4 u_proj;\n"                                                                \
    "uniform float u_alpha_ref;\n"                                                          \
    "uniform float u_offset;\n"                                                             \
    "uniform float u_crease_cos;\n"                                                         \
    "float window_depth(vec3 e) {\n"                                                        \
    "    vec4 c = u_proj * vec4(e, 1.0);\n"                                                 \
    "    return 0.5 * (c.z / c.w) + 0.5;\n"                                                 \
    "}\n"                                                                                   \
    "float eye_distance_z(float depth) {\n"                                                 \
    "    return u_proj[3][2] / ((2.0 * depth - 1.0) + u_proj[2][2]);\n"                     \
    "}\n"                                                                                   \
    /* sharp creases: drop the part of this primitive beyond the support plane of a */  \
    /* primitive it crosses at more than the crease angle (prim_creases.c) */        \
    "void crease_clip() {\n"                                                                \
    "    if (u_crease_cos < -1.0)\n"                                                        \
    "        return;\n"                                                                     \
    "    uvec4 range = prims[v_id].clip;\n"                                                \
    "    for (uint k = range.x; k < range.x + range.y; k++) {\n"                           \
    "        vec4 pl = clips[2u * k];\n"                                                   \
    "        if (clips[2u * k + 1u].x < u_crease_cos && dot(pl.xyz, v_local) + pl.w < 0.0)\n" \
    "            discard;\n"                                                                \
    "    }\n"                                                                               \
    "}\n"                                                                                   \
    /* the alpha test of the thesis (4.4.4): lock only where alpha > reference */           \
    "float alpha_tested() {\n"                                                              \
    "    crease_clip();\n"                                                                  \
    "    float a = texture(u_atlas, v_uv).a;\n"                                             \
    "    if (!(a > u_alpha_ref))\n"                                                         \
    "        discard;\n"                                                                    \
    "    return a;\n"                                                                       \
    "}\n"                                                                                   \
    /* depth of this fragment pushed u_offset further along its eye ray (thesis 4.4.2) */    \
    "float offset_depth() {\n"                                                              \
    "    float d = length(v_eye);\n"                                                        \
    "    return clamp(window_depth(v_eye * (1.0 + u_offset / max(d, 1e-30))), 0.0, 1.0);\n"  \
    "}\n"

/*
 * Colour passes. selected() is the pass-2 test of normalized (window) and
 * prefix (window + the front primitive or one of its neighbours): the
 * distance behind the front layer is measured along the eye ray, with a
 * relative tolerance of 1e-5 so that the front primitive's own fragments
 * always pass (pass 1 and pass 2 compute the same depth slightly differently).
 */
static const char main_fragment[] =
    FRAGMENT_PROLOGUE
    "layout(binding = 1) uniform sampler2D u_normals;\n"
    "layout(binding = 2) uniform sampler2D u_front_depth;\n"
    "layout(binding = 3) uniform usampler2D u_front_id;\n"
    "uniform mat4 u_view;\n"
    "uniform vec3 u_light;\n"
    "uniform int u_lit;\n"
    "uniform int u_normal_map;\n"
    "uniform int u_domain_colors;\n"
    "uniform int u_pass;\n"
    "uniform int u_select;\n"
    "uniform float u_transparency;\n"
    "uniform float u_window;\n"
    "uniform vec4 u_outline_color;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "vec3 shade(vec3 rgb) {\n"
    "    vec3 c = u_domain_colors != 0 ? v_domain : rgb;\n"
    "    if (u_lit == 0)\n"
    "        return c;\n"
    "    vec3 n = v_normal;\n"
    "    if (u_normal_map != 0) {\n"
    "        vec3 m = texture(u_normals, v_uv).xyz * 2.0 - 1.0;\n"
    "        if (dot(m, m) > 1e-4)\n"
    "            n = mat3(u_view) * m;\n"
    "    }\n"
    "    float lambert = dot(n, n) > 0.0 ? abs(dot(normalize(n), u_light)) : 1.0;\n"
    "    return c * (0.25 + 0.75 * lambert);\n"
    "}\n"
    "bool is_neighbour(uint front, uint id) {\n"
    "    uvec4 info = prims[front].info;\n"
    "    for (uint k = 0u; k < info.y; k++)\n"
    "        if (nbrs[info.x + k] == id)\n"
    "            return true;\n"
    "    return false;\n"
    "}\n"
    "bool selected() {\n"
    "    if (u_select == 0)\n"
    "        return true;\n"
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "    float front = texelFetch(u_front_depth, p, 0).r;\n"
    "    if (!(front < 1.0))\n"
    "        return false;\n"
    "    if (u_select == 2) {\n"
    "        uint fid = texelFetch(u_front_id, p, 0).r;\n"
    "        if (fid == 0u)\n"
    "            return false;\n"
    "        fid -= 1u;\n"
    "        if (fid != v_id && !is_neighbour(fid, v_id))\n"
    "            return false;\n"
    "    }\n"
    "    float mine = -v_eye.z, theirs = eye_distance_z(front);\n"
    "    float along = (mine - theirs) * length(v_eye) / max(mine, 1e-30);\n"
    "    return along <= u_window + 1e-5 * length(v_eye);\n"
    "}\n"
    "void main() {\n"
    "    if (u_pass == 4) {\n"
    "        o_color = u_outline_color;\n"
    "        return;\n"
    "    }\n"
    "    crease_clip();\n"
    "    vec4 tex = texture(u_atlas, v_uv);\n"
    "    float a = tex.a;\n"
    "    if (u_pass == 1) {\n"
    "        if (u_alpha_ref >= 0.0 && !(a > u_alpha_ref))\n"
    "            discard;\n"
    "        o_color = vec4(shade(tex.rgb), 1.0);\n"
    "        return;\n"
    "    }\n"
    "    if (!(a > 0.0))\n"
    "        discard;\n"
    "    if (u_pass == 2) {\n"
    "        o_color = vec4(0.0);\n"
    "        return;\n"
    "    }\n"
    "    if (u_pass == 3) {\n"
    "        o_color = vec4(a);\n"
    "        return;\n"
    "    }\n"
    "    if (!selected())\n"
    "        discard;\n"
    "    float w = a * u_transparency;\n"
    "    o_color = vec4(shade(tex.rgb) * w, w);\n"
    "}\n";

/* Depth only: overlap's locks, two-pass's offset layer, normalized's front layer. */
static const char depth_fragment[] =
    FRAGMENT_PROLOGUE
    "void main() {\n"
    "    alpha_tested();\n"
    "    gl_FragDepth = offset_depth();\n"
    "}\n";

/* Prefix pass 1: the front-most alpha-tested primitive's id (+1; 0 = none) with its depth. */
static const char id_fragment[] =
    FRAGMENT_PROLOGUE
    "layout(location = 0) out uint o_id;\n"
    "void main() {\n"
    "    alpha_tested();\n"
    "    gl_FragDepth = offset_depth();\n"
    "    o_id = v_id + 1u;\n"
    "}\n";

const char *const asp__prim_fragment_src[3] = {main_fragment, depth_fragment, id_fragment};

const char *const asp__prim_resolve_vertex_src =
    "#version 450 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

/*
 * normalize: colour = sum(c a) / sum(a) (Pajarola et al. 5.4) at the global
 * opacity u_transparency. Otherwise the seeds' sum is taken as premultiplied
 * colour with coverage min(sum a, 1): over black it is exactly the seeds'
 * framebuffer, over another background too-dark spots let it through. Blended
 * onto the caller's framebuffer with (1, 1 - alpha). normalize also carries the
 * front layer's depth into the caller's depth buffer (depth-tested, LEQUAL), so
 * several draws in one frame (instances of a scene) occlude one another like
 * the other renderers' surfaces.
 */
const char *const asp__prim_resolve_fragment_src =
    "#version 450 core\n"
    "layout(binding = 2) uniform sampler2D u_front_depth;\n"
    "layout(binding = 4) uniform sampler2D u_accum;\n"
    "uniform int u_normalize;\n"
    "uniform float u_transparency;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "    vec4 acc = texelFetch(u_accum, ivec2(gl_FragCoord.xy), 0);\n"
    "    gl_FragDepth = u_normalize != 0 ? texelFetch(u_front_depth, ivec2(gl_FragCoord.xy), 0).r : gl_FragCoord.z;\n"
    "    if (u_normalize != 0) {\n"
    "        if (!(acc.a > 0.0))\n"
    "            discard;\n"
    "        o_color = vec4(acc.rgb / acc.a * u_transparency, u_transparency);\n"
    "        return;\n"
    "    }\n"
    "    vec3 c = clamp(acc.rgb, 0.0, 1.0);\n"
    "    float a = clamp(acc.a, 0.0, 1.0);\n"
    "    if (!(a > 0.0) && !any(greaterThan(c, vec3(0.0))))\n"
    "        discard;\n"
    "    o_color = vec4(c, a);\n"
    "}\n";

const char *const asp__prim_uniform_names[PU_COUNT] = {
    "u_view", "u_proj", "u_light", "u_lit", "u_normal_map", "u_domain_colors", "u_pass", "u_select",
    "u_alpha_ref", "u_transparency", "u_window", "u_offset", "u_outline_color", "u_corners", "u_normalize",
    "u_crease_cos"};
