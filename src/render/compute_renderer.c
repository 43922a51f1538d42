/*
 * Points drawn by compute shaders into a storage-buffer framebuffer (issue 28 item 1; the
 * rasteriser of Schuetz, Kerbl and Wimmer 2021): each splat is an ellipse (seed 001 section 4.1,
 * the leaves of the point hierarchy, or the cloud's discs when it has normals and radii) tested
 * at the centres of the pixels of its screen footprint by intersecting each pixel's ray with the
 * ellipse's plane, so a pixel is covered exactly where the raster renderers' triangle plus alpha
 * test (disc_renderer.c, splat_renderer.c) covers it.
 *  - opaque: the nearest splat per pixel. With GL_NV_shader_atomic_int64 (checked at run time)
 *    one pass of 64-bit atomicMin(depth << 32 | colour); else a 32-bit atomicMin of the depth,
 *    then a pass writing the colour where a splat's depth equals the minimum.
 *  - blended (seed 001 5.3-5.4): atomicMin of the epsilon-offset depth (5.3, Fig. 15), then
 *    atomicAdd of (psi c, psi) in 16.16 fixed point for the splats within epsilon of it (eq. 10),
 *    then the division (eq. 9) in the resolve.
 * The splats go in batches of BATCH in Morton order (the hierarchy's octree order,
 * or a Morton sort of the cloud); one workgroup takes one batch and drops it when its bounding
 * box is outside the view frustum before any point is read. Footprints of more than
 * SMALL_PIXELS pixels go to a list that a second dispatch draws with one workgroup per splat, so
 * big splats cost threads in proportion to their area instead of serialising one thread.
 * A full-screen fragment pass (the resolve) writes colour and depth into the caller's
 * framebuffer, so the result composes with other renderers and the caller's sRGB and
 * multisampling as the raster renderers' output does.
 * A splat is 32 bytes: its centre as floats, colour, an octahedral normal, and its axes a u and
 * b v quantised to 16 bits of the largest axis length in its batch (kept with the batch's box).
 * Not done: the hierarchy's LOD (every leaf is drawn), quantised centres, clip planes, per-pixel
 * lighting (a leaf's splat has one normal, so Gouraud and flat agree and pixel lights per splat).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/hier.h"
#include "render/internal.h"
#include "util/banned.h"

/* Constants shared by C and GLSL (STR makes them GLSL text). */
#define BATCH 10240     /* splats per batch = per workgroup of the main dispatch */
#define GROUP 256       /* invocations per workgroup */
#define SMALL_PIXELS 64 /* footprints (pixel-centre boxes) above this go to the big list */
#define FIXED_ONE 65536 /* the fixed-point unit of the blended sums */
#define STR_(x) #x
#define STR(x) STR_(x)
enum {
    BIG_GROUPS = 1024, /* workgroups of the big-list dispatch, striding over the list */
    SPLAT_WORDS = 8    /* 32 bytes per splat: centre, colour, the axes a u and b v, oct normal */
};

/* The passes of the compute program (u_pass). */
enum { PASS_DEPTH, PASS_COLOR, PASS_BLEND_DEPTH, PASS_BLEND_SUM, PASS_DEPTH_COLOR64 };

#define COMPUTE_GLSL                                                                                   \
    "layout(local_size_x = " STR(GROUP) ") in;\n"                                                                 \
    "layout(std430, binding = 0) readonly buffer Splats { uvec4 splats[]; };\n"                        \
    "layout(std430, binding = 1) readonly buffer Boxes { vec4 boxes[]; };\n"                           \
    "layout(std430, binding = 2) buffer Depth { uint depth[]; };\n"                                    \
    "layout(std430, binding = 3) buffer Color { uint color[]; };\n"                                    \
    "layout(std430, binding = 4) buffer Big { uint big_count; uint big_pad[3]; uvec4 big[]; };\n"      \
    FB64_DECL                                                                                          \
    /* in the splats' own frame: the eye, the view direction, the unit direction towards the light */ \
    "uniform vec3 u_eye;\n"                                                                            \
    "uniform vec3 u_view_dir;\n"                                                                       \
    "uniform mat4 u_mvp;\n"                                                                            \
    "uniform vec3 u_light;\n"                                                                          \
    "uniform int u_unlit;\n"                                                                           \
    "uniform ivec2 u_size;\n"                                                                          \
    "uniform int u_persp;\n"                                                                           \
    /* the pass is a constant of its program: llvmpipe runs both sides of a branch under a lane    */ \
    /* mask, so a uniform pass would pay for the per-pixel work of every pass in each           */ \
    "const int u_pass = PASS;\n"                                                                      \
    "uniform int u_big;\n"                                                                             \
    "uniform int u_append;\n"                                                                          \
    "uniform uint u_batch0;\n"                                                                         \
    "uniform uint u_points;\n"                                                                         \
    "uniform uint u_big_cap;\n"                                                                        \
    "uniform float u_support;\n"                                                                       \
    "uniform float u_radius_scale;\n"                                                                  \
    "uniform float u_epsilon;\n"                                                                       \
    "uniform int u_eps_uniform;\n"                                                                     \
    "uniform float u_ka, u_kb, u_kn, u_kscale, u_ksigma;\n"                                            \
    "const int u_kgauss = KGAUSS;\n" /* the kernel too: exp and pow would both run */              \
    "uniform int u_has_colors;\n"                                                                      \
    "uniform vec4 u_default_color;\n"                                                                  \
    "vec3 oct_decode(vec2 e) {\n"                                                                      \
    "    vec3 v = vec3(e, 1.0 - abs(e.x) - abs(e.y));\n"                                               \
    "    if (v.z < 0.0)\n"                                                                             \
    "        v.xy = (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);\n"     \
    "    return normalize(v);\n"                                                                       \
    "}\n"                                                                                              \
    /* 256 entries: sRGB byte to linear light, so no pow() per splat */                               \
    "uniform float u_lut[256];\n"                                                                      \
    /*                                                                                                 \
     * One splat as the map from its ellipse coordinates q (in semi-axes) to homogeneous pixel         \
     * coordinates: S [q, 1] = clip.w (x, y, 1), the columns of S being the projected axes a u, b v    \
     * and centre c. Its inverse takes a pixel centre to [q, 1] / clip.w, so the coverage test of a    \
     * pixel is three multiply-adds and a comparison, exact as the raster renderers' interpolated      \
     * ellipse coordinates; the window depth of the plane is affine in the pixel (dz).                 \
     */                                                                                                \
    "struct sp { mat3 inv; vec3 dz; float s2; uint pk; vec3 rgb; ivec2 lo, hi; };\n"                   \
    "vec3 screen_h(vec4 v) {\n"                                                                        \
    "    return vec3(0.5 * float(u_size.x) * (v.x + v.w), 0.5 * float(u_size.y) * (v.y + v.w), v.w);\n" \
    "}\n"                                                                                              \
    "bool setup(uvec4 r0, uvec4 r1, float scale, out sp s) {\n"                                       \
    "    vec3 c = uintBitsToFloat(r0.xyz);\n"                                                          \
    "    vec2 e0 = unpackSnorm2x16(r1.x), e1 = unpackSnorm2x16(r1.y), e2 = unpackSnorm2x16(r1.z);\n"    \
    "    float k = scale * u_radius_scale;\n"                                                          \
    "    vec3 au = vec3(e0, e1.x) * k, bv = vec3(e1.y, e2) * k;\n"                                     \
    "    s.s2 = u_support * u_support;\n"                                                              \
    "    vec4 cc = u_mvp * vec4(c, 1.0);\n"                                                            \
    "    vec4 cu = u_mvp * vec4(au, 0.0);\n"                                                           \
    "    vec4 cv = u_mvp * vec4(bv, 0.0);\n"                                                           \
    "    mat3 S = mat3(screen_h(cu), screen_h(cv), screen_h(cc));\n"                                   \
    /*                                                                                                 \
     * The tight pixel box: the support circle |q| = s is the conic diag(1, 1, -s^2), its tangent     \
     * lines the dual conic D = S diag(1, 1, -1 / s^2) S^T in pixels; the vertical tangents x = X     \
     * solve D00 - 2 X D02 + X^2 D22 = 0 (and y likewise). D22 >= 0: the ellipse reaches the eye      \
     * plane and its projection is unbounded, so the whole screen is tested.                          \
     */                                                                                                \
    "    vec3 s0 = S[0], s1 = S[1], s2 = S[2] * inversesqrt(s.s2);\n"                                  \
    "    float d00 = s0.x * s0.x + s1.x * s1.x - s2.x * s2.x;\n"                                       \
    "    float d11 = s0.y * s0.y + s1.y * s1.y - s2.y * s2.y;\n"                                       \
    "    float d22 = s0.z * s0.z + s1.z * s1.z - s2.z * s2.z;\n"                                       \
    "    float d02 = s0.x * s0.z + s1.x * s1.z - s2.x * s2.z;\n"                                       \
    "    float d12 = s0.y * s0.z + s1.y * s1.z - s2.y * s2.z;\n"                                       \
    "    vec2 lo = vec2(0.0), hi = vec2(u_size);\n"                                                    \
    "    if (d22 < 0.0) {\n"                                                                           \
    "        if (!(cc.w > 0.0))\n"                                                                     \
    "            return false;\n"                                                                      \
    "        vec2 mid = vec2(d02, d12) / d22;\n"                                                       \
    "        vec2 ext = sqrt(max(vec2(d02 * d02 - d00 * d22, d12 * d12 - d11 * d22), 0.0)) / abs(d22);\n" \
    "        lo = mid - ext; hi = mid + ext;\n"                                                      \
    "    }\n"                                                                                          \
    "    lo = max(lo, vec2(-1.0)); hi = min(hi, vec2(u_size) + 1.0);\n"                                \
    "    s.lo = max(ivec2(ceil(lo - 0.5)), ivec2(0));\n"                                               \
    "    s.hi = min(ivec2(floor(hi - 0.5)), u_size - 1);\n"                                            \
    "    if (s.lo.x > s.hi.x || s.lo.y > s.hi.y)\n"                                                    \
    "        return false;\n"                                                                          \
    "    float det = determinant(S);\n"                                                                \
    /* edge-on: the raster renderers' triangle has no area either */                                    \
    "    if (!(abs(det) > 0.0))\n"                                                                     \
    "        return false;\n"                                                                          \
    "    s.inv = inverse(S);\n"                                                                        \
    "    s.dz = 0.5 * (vec3(cu.z, cv.z, cc.z) * s.inv) + vec3(0.0, 0.0, 0.5);\n"                       \
    "    if (u_pass == 2) {\n"                                                                         \
    /* seed 001 Fig. 15: the depth pass moves the splat away from the eye by epsilon along the         \
       projector of its centre (the raster renderer moves each corner along its own) */                \
    "        vec3 ray = u_persp != 0 ? c - u_eye : u_view_dir;\n"                                      \
    "        float len = u_epsilon * (u_eps_uniform != 0 ? 1.0 : length(au));\n"                          \
    "        vec4 co = cc + u_mvp * vec4(len * normalize(ray), 0.0);\n"                                   \
    "        s.dz.z += 0.5 * (co.z / co.w - cc.z / cc.w);\n"                                           \
    "    }\n"                                                                                          \
    "    s.pk = 0u;\n"                                                                                 \
    "    s.rgb = vec3(0.0);\n"                                                                         \
    "    if (u_pass == 1 || u_pass == 3 || u_pass == 4) {\n"                                           \
    "        uint col = u_has_colors != 0 ? r0.w : packUnorm4x8(u_default_color);\n"                   \
    "        vec3 n = oct_decode(unpackSnorm2x16(r1.w));\n"                                              \
    "        float shade = u_unlit != 0 ? 1.0 : 0.25 + 0.75 * abs(dot(n, u_light));\n"                 \
    /* opaque: the sRGB bytes and the shade, turned into light once per pixel by the resolve */          \
    "        s.pk = (col & 0x00FFFFFFu) | (uint(shade * 255.0 + 0.5) << 24);\n"                        \
    "        if (u_pass == 3)\n"                                                                       \
    "            s.rgb = vec3(u_lut[col & 255u], u_lut[(col >> 8) & 255u], u_lut[(col >> 16) & 255u]) * shade;\n" \
    "    }\n"                                                                                          \
    "    return true;\n"                                                                               \
    "}\n"                                                                                              \
    /* pixel (x, y) against the splat, then the pass's atomic */                                       \
    "void pixel(sp s, int x, int y) {\n"                                                               \
    "    vec3 pc = vec3(float(x) + 0.5, float(y) + 0.5, 1.0);\n"                                       \
    "    vec3 h = s.inv * pc;\n"                                                                       \
    "    if (!(h.z > 0.0) || !(dot(h.xy, h.xy) <= s.s2 * h.z * h.z))\n"                                \
    "        return;\n"                                                                                \
    "    float z = dot(s.dz, pc);\n"                                                                   \
    "    if (!(z >= 0.0 && z <= 1.0))\n"                                                               \
    "        return;\n"                                                                                \
    "    uint i = uint(y) * uint(u_size.x) + uint(x);\n"                                               \
    "    uint zb = floatBitsToUint(z);\n"                                                              \
    "    if (u_pass == 0 || u_pass == 2) {\n"                                                          \
    /* a plain read first: most splats are behind the minimum so far, and the depth only decreases,  \
       so a stale read costs one atomic, never a wrong result */                                       \
    "        if (zb < depth[i])\n"                                                                     \
    "            atomicMin(depth[i], zb);\n"                                                           \
    "    } else if (u_pass == 1) {\n"                                                                  \
    "        if (zb == depth[i])\n"                                                                    \
    "            color[i] = s.pk;\n"                                                                   \
    "    } else if (u_pass == 3) {\n"                                                                  \
    "        if (zb > depth[i])\n"                                                                     \
    "            return;\n"                                                                            \
    /* the same formula as asp_splat_kernel_weight */                                                   \
    "        float r = min(length(h.xy) / h.z, u_support) * u_kscale;\n"                               \
    "        float w = u_kgauss != 0 ? exp(-r * r / (2.0 * u_ksigma * u_ksigma)) : exp(-u_ka * pow(r / u_kb, u_kn));\n" \
    "        uvec3 c = uvec3(s.rgb * (w * " STR(FIXED_ONE) ".0) + 0.5);\n"                                          \
    "        if (c.r != 0u) atomicAdd(color[4u * i], c.r);\n"                                          \
    "        if (c.g != 0u) atomicAdd(color[4u * i + 1u], c.g);\n"                                     \
    "        if (c.b != 0u) atomicAdd(color[4u * i + 2u], c.b);\n"                                     \
    "        atomicAdd(color[4u * i + 3u], max(uint(w * " STR(FIXED_ONE) ".0 + 0.5), 1u));\n"                      \
    "    }\n"                                                                                          \
    FB64_PASS                                                                                          \
    "}\n"                                                                                              \
    "void main() {\n"                                                                                  \
    "    uint lid = gl_LocalInvocationID.x;\n"                                                         \
    "    if (u_big != 0) {\n"                                                                          \
    /* one splat per workgroup, its footprint's pixels spread over the threads */                       \
    "        uint n = min(big_count, u_big_cap);\n"                                                    \
    "        for (uint e = gl_WorkGroupID.x; e < n; e += gl_NumWorkGroups.x) {\n"                      \
    "            sp s;\n"                                                                              \
    "            if (!setup(big[3u * e], big[3u * e + 1u], uintBitsToFloat(big[3u * e + 2u].x), s))\n"                                      \
    "                continue;\n"                                                                      \
    "            int w = s.hi.x - s.lo.x + 1;\n"                                                       \
    "            uint count = uint(w) * uint(s.hi.y - s.lo.y + 1);\n"                                  \
    "            for (uint k = lid; k < count; k += " STR(GROUP) "u)\n"                                           \
    "                pixel(s, s.lo.x + int(k % uint(w)), s.lo.y + int(k / uint(w)));\n"        \
    "        }\n"                                                                                      \
    "        return;\n"                                                                                \
    "    }\n"                                                                                          \
    /*                                                                                                 \
     * The workgroup's batch, culled by its box before any splat is read. Every invocation tests the   \
     * box itself (the same answer for the whole workgroup: 8 corners, once per 40 splats) instead of  \
     * one test shared through a barrier (as fast on llvmpipe, 1M points, 3 runs each, within noise).  \
     */                                                                                                \
    "    uint batch = u_batch0 + gl_WorkGroupID.x;\n"                                                  \
    "    vec4 b0 = boxes[2u * batch], b1 = boxes[2u * batch + 1u];\n"                                  \
    "    ivec3 neg = ivec3(0), pos = ivec3(0);\n"                                                      \
    "    for (int k = 0; k < 8; k++) {\n"                                                              \
    "        vec3 p = vec3((k & 1) != 0 ? b1.x : b0.x, (k & 2) != 0 ? b1.y : b0.y, (k & 4) != 0 ? b1.z : b0.z);\n" \
    "        vec4 q = u_mvp * vec4(p, 1.0);\n"                                                         \
    "        neg += ivec3(lessThan(q.xyz, vec3(-q.w)));\n"                                             \
    "        pos += ivec3(greaterThan(q.xyz, vec3(q.w)));\n"                                           \
    "    }\n"                                                                                          \
    "    if (any(equal(neg, ivec3(8))) || any(equal(pos, ivec3(8))))\n"                                \
    "        return;\n"                                                                                \
    "    float scale = b0.w;\n"                                                                        \
    "    uint first = gl_WorkGroupID.x * " STR(BATCH) "u;\n"                                                    \
    "    uint last = min(first + " STR(BATCH) "u, u_points);\n"                                                 \
    "    for (uint j = first + lid; j < last; j += " STR(GROUP) "u) {\n"                                          \
    "        uvec4 r0 = splats[2u * j], r1 = splats[2u * j + 1u];\n"                                   \
    "        sp s;\n"                                                                                  \
    "        if (!setup(r0, r1, scale, s))\n"                                                                 \
    "            continue;\n"                                                                          \
    "        int w = s.hi.x - s.lo.x + 1, h = s.hi.y - s.lo.y + 1;\n"                                  \
    "        if (w * h > " STR(SMALL_PIXELS) ") {\n"                                                                      \
    "            if (u_append == 0)\n"                                                                 \
    "                continue;\n"                                                                      \
    "            uint e = atomicAdd(big_count, 1u);\n"                                                 \
    "            if (e < u_big_cap) { big[3u * e] = r0; big[3u * e + 1u] = r1; big[3u * e + 2u] = uvec4(floatBitsToUint(scale)); continue; }\n" \
    /* the list is full: the one-pass 64-bit path draws the splat here; a two-pass path's caller sees \
       the count above the list's size and draws the frame again with a larger list */                \
    "            if (u_pass != 4)\n"                                                                   \
    "                continue;\n"                                                                      \
    "        }\n"                                                                                      \
    "        for (int y = s.lo.y; y <= s.hi.y; y++)\n"                                                 \
    "            for (int x = s.lo.x; x <= s.hi.x; x++)\n"                                             \
    "                pixel(s, x, y);\n"                                                        \
    "    }\n"                                                                                          \
    "}\n"

/* The 32-bit program: no 64-bit buffer, pass 4 never runs. */
#define FB64_DECL ""
#define FB64_PASS ""
static const char *compute32_head = "#version 450 core\n";
static const char *compute32_body = COMPUTE_GLSL;
#undef FB64_DECL
#undef FB64_PASS

/* The 64-bit program: depth in the high word, so the minimum carries the nearest splat's colour. */
#define FB64_DECL "layout(std430, binding = 5) buffer Fb64 { uint64_t fb64[]; };\n"
#define FB64_PASS                                                                  \
    "    else if (u_pass == 4)\n"                                                  \
    "        atomicMin(fb64[i], packUint2x32(uvec2(s.pk, zb)));\n"
static const char *compute64_head = "#version 450 core\n"
                                    "#extension GL_ARB_gpu_shader_int64 : require\n"
                                    "#extension GL_NV_shader_atomic_int64 : require\n";
static const char *compute64_body = COMPUTE_GLSL;
#undef FB64_DECL
#undef FB64_PASS

static const char *resolve_vertex_src =
    "#version 450 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

/* u_mode: 0 depth + colour words, 1 the 64-bit words, 2 blended sums (seed 001 eq. 9). */
#define RESOLVE_GLSL                                                                                   \
    "layout(std430, binding = 2) readonly buffer Depth { uint depth[]; };\n"                           \
    "layout(std430, binding = 3) readonly buffer Color { uint color[]; };\n"                           \
    "uniform int u_mode;\n"                                                                            \
    "uniform ivec2 u_size;\n"                                                                          \
    "layout(location = 0) out vec4 o_color;\n"                                                         \
    "vec3 srgb_to_linear(vec3 c) {\n"                                                                  \
    "    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));\n" \
    "}\n"                                                                                              \
    "void main() {\n"                                                                                  \
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"                                                          \
    "    if (p.x >= u_size.x || p.y >= u_size.y)\n"                                                    \
    "        discard;\n"                                                                               \
    "    uint i = uint(p.y) * uint(u_size.x) + uint(p.x);\n"                                           \
    "    uint z, c;\n"                                                                                 \
    "    vec3 rgb;\n"                                                                                  \
    "    if (u_mode == 2) {\n"                                                                         \
    "        z = depth[i];\n"                                                                          \
    "        uint w = color[4u * i + 3u];\n"                                                           \
    "        if (w == 0u)\n"                                                                           \
    "            discard;\n"                                                                           \
    "        rgb = vec3(color[4u * i], color[4u * i + 1u], color[4u * i + 2u]) / float(w);\n"          \
    "    } else {\n"                                                                                   \
    "        FETCH_OPAQUE\n"                                                                           \
    "        if (z == 0xFFFFFFFFu)\n"                                                                  \
    "            discard;\n"                                                                           \
    "        vec4 cs = unpackUnorm4x8(c);\n"                                                          \
    "        rgb = srgb_to_linear(cs.rgb) * cs.a;\n"                                           \
    "    }\n"                                                                                          \
    "    gl_FragDepth = uintBitsToFloat(z);\n"                                                         \
    "    o_color = vec4(rgb, 1.0);\n"                                                                  \
    "}\n"

/* FETCH_OPAQUE, a GLSL macro: the nearest splat's depth z and packed colour c */
static const char *resolve32_src = "#version 450 core\n"
                                   "#define FETCH_OPAQUE z = depth[i]; c = color[i];\n" RESOLVE_GLSL;
static const char *resolve64_src =
    "#version 450 core\n"
    "#extension GL_ARB_gpu_shader_int64 : require\n"
    "layout(std430, binding = 5) readonly buffer Fb64 { uint64_t fb64[]; };\n"
    "#define FETCH_OPAQUE if (u_mode == 1) { uvec2 v = unpackUint2x32(fb64[i]); z = v.y; c = v.x; } "
    "else { z = depth[i]; c = color[i]; }\n" RESOLVE_GLSL;

enum { U_EYE, U_VIEW_DIR, U_MVP, U_LIGHT, U_UNLIT, U_SIZE, U_PERSP, U_BIG, U_APPEND, U_BATCH0,
       U_POINTS, U_BIG_CAP, U_SUPPORT, U_RADIUS_SCALE, U_EPSILON, U_EPS_UNIFORM, U_KA, U_KB, U_KN, U_KSCALE,
       U_KSIGMA, U_HAS_COLORS, U_DEFAULT_COLOR, U_LUT, U_COUNT };
static const char *uniform_names[U_COUNT] = {
    "u_eye", "u_view_dir", "u_mvp", "u_light", "u_unlit", "u_size", "u_persp",
    "u_big", "u_append", "u_batch0", "u_points", "u_big_cap", "u_support", "u_radius_scale", "u_epsilon",
    "u_eps_uniform", "u_ka", "u_kb", "u_kn", "u_kscale", "u_ksigma", "u_has_colors",
    "u_default_color", "u_lut"};

typedef struct compute_renderer {
    asp_renderer base; // first, so an asp_renderer * is a compute_renderer *
    /* one program a pass of the mode, the pass compiled in: the 64-bit one-pass program where it is
       used, else the 32-bit depth pass and its colour (opaque) or sum (blended) pass */
    asp__gl_program program[2];
    int programs;
    asp__gl_program resolve;
    GLint u[2][U_COUNT];
    GLint r_mode, r_size;
    asp__gl_vertex_array vao;
    asp__gl_buffer splats, boxes, depth, color, big, fb64;
    size_t points, batches, chunk_batches;
    uint32_t fb_width, fb_height, big_cap;
    int opaque, use64;
} compute_renderer;

/* Sets uniform `which` of every pass program: fn is a glProgramUniform* function, then its values. */
#define SET_UNIFORM(c, fn, which, ...)                                                              \
    for (int k_ = 0; k_ < (c)->programs; k_++)                                                      \
    fn((c)->program[k_].id, (c)->u[k_][which], __VA_ARGS__)

static void del_buffer(asp__gl_buffer *b)
{
    if (b->id)
        glDeleteBuffers(1, &b->id);
    b->id = 0;
}

static void compute_destroy(asp_renderer *base)
{
    compute_renderer *c = (compute_renderer *)base;
    asp__gl_buffer *bufs[] = {&c->splats, &c->boxes, &c->depth, &c->color, &c->big, &c->fb64};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
        del_buffer(bufs[i]);
    if (c->vao.id)
        glDeleteVertexArrays(1, &c->vao.id);
    for (int k = 0; k < 2; k++)
        asp__gl_program_destroy(&c->program[k]);
    asp__gl_program_destroy(&c->resolve);
    asp_context actx = base->gl->actx;
    asp_free(&actx, c);
}

const char *asp_compute_renderer_path(const asp_renderer *r)
{
    if (!r || !r->vt || strcmp(r->vt->name, "compute") != 0)
        return NULL;
    const compute_renderer *c = (const compute_renderer *)r;
    return !c->opaque ? "blend-atomic32" : c->use64 ? "opaque-atomic64" : "opaque-atomic32";
}

/* The per-pixel buffers for a width x height frame, kept while the size stays. */
static int ensure_framebuffer(compute_renderer *c, uint32_t w, uint32_t h, asp_error *err)
{
    if (c->depth.id && c->fb_width == w && c->fb_height == h)
        return 0;
    del_buffer(&c->depth);
    del_buffer(&c->color);
    del_buffer(&c->fb64);
    asp_gl_context *gl = c->base.gl;
    asp__gl_clear_errors(gl);
    size_t px = (size_t)w * h;
    glCreateBuffers(1, &c->depth.id);
    glNamedBufferStorage(c->depth.id, (GLsizeiptr)(px * 4), NULL, GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &c->color.id);
    glNamedBufferStorage(c->color.id, (GLsizeiptr)(px * (c->opaque ? 4 : 16)), NULL, GL_DYNAMIC_STORAGE_BIT);
    if (c->use64) {
        glCreateBuffers(1, &c->fb64.id);
        glNamedBufferStorage(c->fb64.id, (GLsizeiptr)(px * 8), NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    int rc = asp__gl_check(gl, "allocate the compute renderer's frame buffers", err);
    if (rc)
        return rc;
    c->fb_width = w;
    c->fb_height = h;
    return 0;
}

static void normalize3(float *v)
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] = l > 0 ? v[k] / l : 0.0f;
}

static void mat4_mul(const float *a, const float *b, float *out)
{
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            float s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * k + row] * b[4 * col + k];
            out[4 * col + row] = s;
        }
}

/*
 * One pass (program k) over every splat: the batches in chunks whose splats fit one storage
 * binding, then the big list.
 */
static void dispatch_pass(compute_renderer *c, int k, int append)
{
    GLuint p = c->program[k].id;
    const GLint *u = c->u[k];
    glUseProgram(p);
    glProgramUniform1i(p, u[U_APPEND], append);
    glProgramUniform1i(p, u[U_BIG], 0);
    for (size_t b0 = 0; b0 < c->batches; b0 += c->chunk_batches) {
        size_t nb = c->batches - b0 < c->chunk_batches ? c->batches - b0 : c->chunk_batches;
        size_t first = b0 * BATCH, n = c->points - first < nb * BATCH ? c->points - first : nb * BATCH;
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, c->splats.id, (GLintptr)(first * SPLAT_WORDS * 4),
                          (GLsizeiptr)(n * SPLAT_WORDS * 4));
        glProgramUniform1ui(p, u[U_BATCH0], (GLuint)b0);
        glProgramUniform1ui(p, u[U_POINTS], (GLuint)n);
        glDispatchCompute((GLuint)nb, 1, 1);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glProgramUniform1i(p, u[U_BIG], 1);
    glDispatchCompute(BIG_GROUPS, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

/*
 * Clears the storage framebuffer and runs the point passes. The first pass of each pair appends
 * the splats whose footprint is too big for one invocation to the big list, which holds big_cap
 * of them; with read_count, the count it returns is every big splat seen, so a frame that
 * overflowed the list is known and redrawn by the caller with a larger one (no splat is dropped);
 * without, 0.
 */
static GLuint draw_passes(compute_renderer *c, int read_count)
{
    static const GLuint far_bits = 0xFFFFFFFFu, zero = 0;
    // a previous draw's resolve may still be queued (llvmpipe bins draws, runs dispatches at once):
    // it must read these buffers before they are cleared (scenes draw the renderer once per instance)
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glClearNamedBufferData(c->depth.id, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &far_bits);
    if (c->use64)
        glClearNamedBufferData(c->fb64.id, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &far_bits);
    else
        glClearNamedBufferData(c->color.id, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glClearNamedBufferSubData(c->big.id, GL_R32UI, 0, 16, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, c->boxes.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, c->depth.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, c->color.id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, c->big.id);
    if (c->use64)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, c->fb64.id);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // the depth pass (or the one 64-bit pass) appends the large splats; the second reads the list
    for (int k = 0; k < c->programs; k++)
        dispatch_pass(c, k, k == 0);

    GLuint big_count = 0;
    if (read_count) {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(c->big.id, 0, sizeof big_count, &big_count);
    }
    return big_count;
}

/* Replaces the big list by one of cap entries (48 bytes each: the record and its batch's scale). */
static int grow_big_list(compute_renderer *c, uint32_t cap, asp_error *err)
{
    asp__gl_clear_errors(c->base.gl);
    glDeleteBuffers(1, &c->big.id);
    c->big.id = 0;
    glCreateBuffers(1, &c->big.id);
    glNamedBufferStorage(c->big.id, (GLsizeiptr)(16 + (size_t)cap * 48), NULL, GL_DYNAMIC_STORAGE_BIT);
    c->big_cap = cap;
    SET_UNIFORM(c, glProgramUniform1ui, U_BIG_CAP, cap);
    char what[96];
    snprintf(what, sizeof what, "grow the compute renderer's list of large splats to %u", cap);
    return asp__gl_check(c->base.gl, what, err);
}

static int compute_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    compute_renderer *c = (compute_renderer *)base;
    int rc = ensure_framebuffer(c, f->width, f->height, err);
    if (rc)
        return rc;
    float mvp[16];
    mat4_mul(f->proj, f->view, mvp);
    // the light and the view direction into the splats' frame: the transposed rotation of the view
    float light[3], dir[3];
    for (int j = 0; j < 3; j++) {
        light[j] = 0;
        for (int i = 0; i < 3; i++)
            light[j] += f->view[4 * j + i] * f->light_eye[i];
        dir[j] = -f->view[4 * j + 2];
    }
    normalize3(light);
    normalize3(dir);
    SET_UNIFORM(c, glProgramUniform3fv, U_EYE, 1, f->eye);
    SET_UNIFORM(c, glProgramUniform3fv, U_VIEW_DIR, 1, dir);
    SET_UNIFORM(c, glProgramUniformMatrix4fv, U_MVP, 1, GL_FALSE, mvp);
    SET_UNIFORM(c, glProgramUniform3fv, U_LIGHT, 1, light);
    SET_UNIFORM(c, glProgramUniform1i, U_UNLIT, (f->flags & ASP_RENDER_UNLIT) ? 1 : 0);
    SET_UNIFORM(c, glProgramUniform2i, U_SIZE, (GLint)f->width, (GLint)f->height);
    // a perspective projection has -1 in row 3 of column 2; an orthographic one 0
    SET_UNIFORM(c, glProgramUniform1i, U_PERSP, f->proj[11] != 0.0f);

    /*
     * A two-pass frame with more large splats than the list holds is drawn again with a list that
     * holds them. Reading the count back waits for the passes (about 4 ms a frame on an H200 at
     * 10M-100M points), so it is read only where an overflow is possible: more points than the list
     * holds, and not the one-pass 64-bit path, which draws what the list cannot take in place.
     */
    int may_overflow = c->points > c->big_cap && !(c->opaque && c->use64);
    for (;;) {
        GLuint big = draw_passes(c, may_overflow);
        if (big <= c->big_cap)
            break;
        if ((rc = grow_big_list(c, big, err)) != 0)
            return rc;
    }

    // the resolve: one full-screen triangle into the caller's framebuffer, depth-tested as any draw
    GLuint rp = c->resolve.id;
    glProgramUniform1i(rp, c->r_mode, !c->opaque ? 2 : c->use64 ? 1 : 0);
    glProgramUniform2i(rp, c->r_size, (GLint)f->width, (GLint)f->height);
    GLint fbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glUseProgram(rp);
    glBindVertexArray(c->vao.id);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    asp__gl_restore_state((GLuint)fbo);
    return asp__gl_check(base->gl, "draw points with compute shaders", err);
}

static const asp__renderer_vtable compute_vtable = {.name = "compute", .draw = compute_draw,
                                                    .destroy = compute_destroy};

/* Octahedral encoding of a unit vector into two signed 16-bit normalised values (packSnorm2x16). */
static uint32_t oct_pack(const float v[3])
{
    float s = fabsf(v[0]) + fabsf(v[1]) + fabsf(v[2]);
    float x = s > 0 ? v[0] / s : 0, y = s > 0 ? v[1] / s : 0;
    if (v[2] < 0) {
        float ox = x;
        x = (1 - fabsf(y)) * (ox >= 0 ? 1.0f : -1.0f);
        y = (1 - fabsf(ox)) * (y >= 0 ? 1.0f : -1.0f);
    }
    int32_t qx = (int32_t)lroundf(fminf(fmaxf(x, -1.0f), 1.0f) * 32767.0f);
    int32_t qy = (int32_t)lroundf(fminf(fmaxf(y, -1.0f), 1.0f) * 32767.0f);
    return ((uint32_t)qx & 0xFFFFu) | (((uint32_t)qy & 0xFFFFu) << 16);
}

/* A unit vector perpendicular to unit n. */
static void tangent_of(const float n[3], float t[3])
{
    const float h[3] = {fabsf(n[0]) < 0.9f ? 1.0f : 0.0f, fabsf(n[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
    t[0] = n[1] * h[2] - n[2] * h[1];
    t[1] = n[2] * h[0] - n[0] * h[2];
    t[2] = n[0] * h[1] - n[1] * h[0];
    float l = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int d = 0; d < 3; d++)
        t[d] = l > 0 ? t[d] / l : (d == 0);
}

/* Two values in [-1, 1] as GLSL's packSnorm2x16. */
static uint32_t snorm2(float x, float y)
{
    int32_t qx = (int32_t)lroundf(fminf(fmaxf(x, -1.0f), 1.0f) * 32767.0f);
    int32_t qy = (int32_t)lroundf(fminf(fmaxf(y, -1.0f), 1.0f) * 32767.0f);
    return ((uint32_t)qx & 0xFFFFu) | (((uint32_t)qy & 0xFFFFu) << 16);
}

/* One splat of the source in drawing order: centre, colour, unit normal, the axes a u and b v. */
typedef struct src_splat {
    float c[3], n[3], au[3], bv[3];
    const uint8_t *col;
} src_splat;

typedef struct source {
    const asp_hier_splat *leaves; /* the hierarchy's point splats, or NULL */
    const asp_cloud *cloud;       /* else the cloud's discs, in order[] */
    const uint32_t *order;
    const uint8_t *default_color;
} source;

static void source_get(const source *src, size_t i, src_splat *o)
{
    if (src->leaves) {
        const asp_hier_splat *h = &src->leaves[i];
        for (int d = 0; d < 3; d++) {
            o->c[d] = h->center[d];
            o->n[d] = h->normal[d];
            o->au[d] = h->a * h->u[d];
            o->bv[d] = h->b * h->v[d];
        }
        o->col = h->color;
        return;
    }
    const asp_cloud *cl = src->cloud;
    size_t k = src->order[i];
    const float *n = cl->normals + 3 * k;
    float t[3];
    tangent_of(n, t);
    const float b[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
    float r = cl->radii[k];
    for (int d = 0; d < 3; d++) {
        o->c[d] = cl->positions[3 * k + d];
        o->n[d] = n[d];
        o->au[d] = r * t[d];
        o->bv[d] = r * b[d];
    }
    o->col = cl->colors ? cl->colors + 4 * k : src->default_color;
}

/*
 * The records and batch boxes of src's n splats: each batch's axes quantised to 16 bits of the
 * batch's largest axis length (its box's w), its box grown by that length times grow.
 */
static void pack_batches(const source *src, size_t n, float grow, uint32_t *w, float *boxes)
{
    for (size_t b = 0; b * BATCH < n; b++) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, r = 0;
        size_t end = (b + 1) * BATCH < n ? (b + 1) * BATCH : n;
        src_splat sp;
        for (size_t i = b * BATCH; i < end; i++) {
            source_get(src, i, &sp);
            for (int d = 0; d < 3; d++) {
                lo[d] = fminf(lo[d], sp.c[d]), hi[d] = fmaxf(hi[d], sp.c[d]);
                r = fmaxf(r, fmaxf(fabsf(sp.au[d]), fabsf(sp.bv[d])));
            }
        }
        float inv = r > 0 ? 1.0f / r : 0.0f;
        for (size_t i = b * BATCH; i < end; i++) {
            source_get(src, i, &sp);
            uint32_t *o = w + SPLAT_WORDS * i;
            memcpy(o, sp.c, 12);
            o[3] = (uint32_t)sp.col[0] | (uint32_t)sp.col[1] << 8 | (uint32_t)sp.col[2] << 16 |
                   (uint32_t)sp.col[3] << 24;
            o[4] = snorm2(sp.au[0] * inv, sp.au[1] * inv);
            o[5] = snorm2(sp.au[2] * inv, sp.bv[0] * inv);
            o[6] = snorm2(sp.bv[1] * inv, sp.bv[2] * inv);
            o[7] = oct_pack(sp.n);
        }
        // a component of the axes is at most r; the support's reach at most sqrt(3) r
        for (int d = 0; d < 3; d++) {
            boxes[8 * b + d] = lo[d] - 1.7320508f * r * grow;
            boxes[8 * b + 4 + d] = hi[d] + 1.7320508f * r * grow;
        }
        boxes[8 * b + 3] = r;
        boxes[8 * b + 7] = 0;
    }
}

/* Spreads the low 10 bits of v to every third bit (Morton code). */
static uint32_t spread10(uint32_t v)
{
    v &= 0x3FFu;
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

/*
 * The cloud's points in Morton order of their 30-bit codes in the bounding box (three 10-bit radix
 * passes); order[i] is the i-th point. NULL when out of memory.
 */
static uint32_t *morton_order(asp_context *a, const asp_cloud *cloud)
{
    size_t n = cloud->count;
    uint32_t *key = asp_alloc(a, n * 4), *order = asp_alloc(a, n * 4), *tk = asp_alloc(a, n * 4),
             *to = asp_alloc(a, n * 4), *hist = asp_calloc(a, 1024, 4);
    if (!key || !order || !tk || !to || !hist) {
        asp_free(a, key), asp_free(a, order), asp_free(a, tk), asp_free(a, to), asp_free(a, hist);
        return NULL;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const float *p = cloud->positions;
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            lo[d] = fminf(lo[d], p[3 * i + d]), hi[d] = fmaxf(hi[d], p[3 * i + d]);
    float ext = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    float sc = ext > 0 ? 1023.0f / ext : 0.0f;
    for (size_t i = 0; i < n; i++) {
        uint32_t q[3];
        for (int d = 0; d < 3; d++)
            q[d] = (uint32_t)((p[3 * i + d] - lo[d]) * sc);
        key[i] = spread10(q[0]) | spread10(q[1]) << 1 | spread10(q[2]) << 2;
        order[i] = (uint32_t)i;
    }
    for (int shift = 0; shift < 30; shift += 10) {
        memset(hist, 0, 1024 * 4);
        for (size_t i = 0; i < n; i++)
            hist[(key[i] >> shift) & 1023u]++;
        uint32_t sum = 0;
        for (int b = 0; b < 1024; b++) {
            uint32_t h = hist[b];
            hist[b] = sum;
            sum += h;
        }
        for (size_t i = 0; i < n; i++) {
            uint32_t dst = hist[(key[i] >> shift) & 1023u]++;
            tk[dst] = key[i];
            to[dst] = order[i];
        }
        uint32_t *t = key;
        key = tk, tk = t;
        t = order, order = to, to = t;
    }
    asp_free(a, key), asp_free(a, tk), asp_free(a, to), asp_free(a, hist);
    return order;
}

/*
 * The splat records and batch boxes: the hierarchy's leaves in its (octree) order, or the cloud's
 * discs (normal, radius) in Morton order. *out: points * SPLAT_WORDS words, *boxes_out 8 floats a batch.
 */
static int build_records(asp_context *a, const asp_cloud *cloud, const asp_hier *hier, const uint8_t dflt[4],
                         float grow, uint32_t **out, float **boxes_out, size_t *count, asp_error *err)
{
    static const uint8_t grey[4] = {200, 200, 200, 255};
    source src = {.cloud = cloud};
    src.default_color = dflt && (dflt[0] || dflt[1] || dflt[2] || dflt[3]) ? dflt : grey;
    size_t n = hier ? asp_hier_point_count(hier) : cloud->count;
    size_t batches = (n + BATCH - 1) / BATCH;
    uint32_t *w = asp_alloc(a, n * SPLAT_WORDS * 4);
    float *boxes = asp_alloc(a, batches * 8 * sizeof(float));
    uint32_t *order = NULL;
    if (hier)
        src.leaves = asp_hier_splats(hier) + asp_hier_node_count(hier);
    else if (w && boxes)
        src.order = order = morton_order(a, cloud);
    if (!w || !boxes || (!hier && !order)) {
        asp_free(a, w);
        asp_free(a, boxes);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu compute splats (%zu bytes)", n,
                             n * SPLAT_WORDS * 4);
    }
    pack_batches(&src, n, grow, w, boxes);
    asp_free(a, order);
    *out = w;
    *boxes_out = boxes;
    *count = n;
    return 0;
}

/*
 * The compute program of one pass: head (version, extensions), the constants (the pass, and
 * whether the kernel is psi_G), body.
 */
static int compile_compute(asp_gl_context *gl, const char *name, const char *head, const char *body, int pass,
                           int gauss, asp__gl_program *out, asp_error *err)
{
    char define[64];
    snprintf(define, sizeof define, "#define PASS %d\n#define KGAUSS %d\n", pass, gauss != 0);
    const char *src[3] = {head, define, body};
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
    glShaderSource(sh, 3, src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    char log[512] = "";
    if (!ok) {
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        return asp_error_set(err, ASP_EGL, "cannot compile the %s compute shader of pass %d: %.300s", name, pass,
                             log);
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, sh);
    glLinkProgram(p);
    glDeleteShader(sh);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        return asp_error_set(err, ASP_EGL, "cannot link the %s compute program of pass %d: %.300s", name, pass,
                             log);
    }
    out->id = p;
    (void)gl;
    return 0;
}

/* Kernel constants as asp_splat_renderer_desc defines them (splat_renderer.c kernel_params_of). */
static void set_static_uniforms(compute_renderer *c, const asp_splat_renderer_desc *d, int has_colors)
{
    float ka = d->kernel_a > 0 ? d->kernel_a : 6.0f, kb = d->kernel_b > 0 ? d->kernel_b : 1.5f;
    float kn = d->kernel_n > 0 ? d->kernel_n : 3.0f, sigma = d->kernel_sigma > 0 ? d->kernel_sigma : 0.5f;
    int rim_at_b = (d->flags & ASP_SPLAT_KERNEL_RIM_AT_B) != 0;
    // opaque splats are the whole ellipse, as disc and opaque splat draw them
    float support = c->opaque || rim_at_b ? 1.0f : fminf(kb, 1.0f), kscale = rim_at_b ? kb : 1.0f;
    float eps = d->epsilon > 0 ? d->epsilon : d->epsilon < 0 ? 0.0f : 1.0f;
    SET_UNIFORM(c, glProgramUniform1f, U_SUPPORT, support);
    SET_UNIFORM(c, glProgramUniform1f, U_RADIUS_SCALE, d->radius_scale > 0 ? d->radius_scale : 1.0f);
    SET_UNIFORM(c, glProgramUniform1f, U_EPSILON, eps);
    SET_UNIFORM(c, glProgramUniform1i, U_EPS_UNIFORM, (d->flags & ASP_SPLAT_EPSILON_UNIFORM) != 0);
    SET_UNIFORM(c, glProgramUniform1f, U_KA, ka);
    SET_UNIFORM(c, glProgramUniform1f, U_KB, kb);
    SET_UNIFORM(c, glProgramUniform1f, U_KN, kn);
    SET_UNIFORM(c, glProgramUniform1f, U_KSCALE, kscale);
    SET_UNIFORM(c, glProgramUniform1f, U_KSIGMA, sigma);
    SET_UNIFORM(c, glProgramUniform1i, U_HAS_COLORS, has_colors);
    const uint8_t *dc = d->default_color;
    int given = dc[0] || dc[1] || dc[2] || dc[3];
    float col[4];
    for (int k = 0; k < 4; k++)
        col[k] = given ? dc[k] / 255.0f : (k < 3 ? 200.0f / 255.0f : 1.0f);
    SET_UNIFORM(c, glProgramUniform4fv, U_DEFAULT_COLOR, 1, col);
    SET_UNIFORM(c, glProgramUniform1ui, U_BIG_CAP, c->big_cap);
    float lut[256];
    for (int k = 0; k < 256; k++)
        lut[k] = asp__srgb_to_linear((uint8_t)k);
    SET_UNIFORM(c, glProgramUniform1fv, U_LUT, 256, lut);
}

static int upload(compute_renderer *c, const uint32_t *w, const float *boxes, size_t n, asp_error *err)
{
    asp_gl_context *gl = c->base.gl;
    c->points = n;
    c->batches = (n + BATCH - 1) / BATCH;
    // a storage binding holds at most GL_MAX_SHADER_STORAGE_BLOCK_SIZE bytes: whole batches per chunk
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    GLint max_groups = 65535;
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &max_groups);
    size_t per_batch = (size_t)BATCH * SPLAT_WORDS * 4;
    c->chunk_batches = max_block > 0 ? (size_t)max_block / per_batch : 1;
    if (c->chunk_batches < 1)
        c->chunk_batches = 1;
    if (c->chunk_batches > (size_t)max_groups)
        c->chunk_batches = (size_t)max_groups;
    c->big_cap = n < (1u << 20) ? (uint32_t)n : 1u << 20;
    asp__gl_clear_errors(gl);
    glCreateBuffers(1, &c->splats.id);
    glNamedBufferStorage(c->splats.id, (GLsizeiptr)(n * SPLAT_WORDS * 4), w, 0);
    glCreateBuffers(1, &c->boxes.id);
    glNamedBufferStorage(c->boxes.id, (GLsizeiptr)(c->batches * 8 * sizeof(float)), boxes, 0);
    glCreateBuffers(1, &c->big.id);
    // a big-list entry is the record and its batch's axis scale: 48 bytes
    glNamedBufferStorage(c->big.id, (GLsizeiptr)(16 + (size_t)c->big_cap * 48), NULL, GL_DYNAMIC_STORAGE_BIT);
    char what[80];
    snprintf(what, sizeof what, "upload %zu compute splats", n);
    return asp__gl_check(gl, what, err);
}

static int has_gl_extension(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++) {
        const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
        if (e && strcmp(e, name) == 0)
            return 1;
    }
    return 0;
}

static int create(asp_gl_context *gl, const asp_cloud *cloud, const asp_hier *hier, const asp_splat_renderer_desc *desc,
                  const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    static const asp_splat_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    if (!hier && (!cloud || cloud->count == 0))
        return asp_error_set(err, ASP_EDEGENERATE, "cannot render an empty point set");
    if (!(desc->radius_scale >= 0) || !isfinite(desc->radius_scale) || !isfinite(desc->epsilon))
        return asp_error_set(err, ASP_EINVAL, "compute renderer: radius scale %g or epsilon %g is not finite",
                             (double)desc->radius_scale, (double)desc->epsilon);
    int rc = cloud ? asp_cloud_validate(cloud, err) : 0;
    if (rc)
        return rc;
    size_t total = hier ? asp_hier_point_count(hier) : cloud->count;
    // the Morton order indexes points with 32 bits
    if (total > (size_t)UINT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw %zu points with compute shaders (at most %u)",
                             total, UINT32_MAX);
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    asp_hier *owned = NULL;
    // without normals and radii the splats are the hierarchy's leaf ellipses (k-neighbourhoods), as splat has them
    if (!hier && !(cloud->normals && cloud->radii)) {
        rc = asp_hier_build(cloud, &desc->hier, ctx, &owned, err);
        if (rc)
            return rc;
        hier = owned;
    }
    asp_context *a = &gl->actx;
    uint32_t *words = NULL;
    float *boxes = NULL;
    size_t n = 0;
    float radius_scale = desc->radius_scale > 0 ? desc->radius_scale : 1.0f;
    rc = build_records(a, hier ? NULL : cloud, hier, desc->default_color, radius_scale, &words, &boxes, &n, err);
    int has_colors = hier ? (asp_hier_flags(hier) & ASP_HIER_HAS_COLORS) != 0 : cloud->colors != NULL;
    if (owned)
        asp_hier_destroy(owned);
    if (rc)
        return rc;
    compute_renderer *c = asp_calloc(a, 1, sizeof *c);
    if (!c) {
        asp_free(a, words);
        asp_free(a, boxes);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a compute renderer");
    }
    c->base.vt = &compute_vtable;
    c->base.gl = gl;
    c->base.count = n;
    c->opaque = desc->mode == ASP_SPLAT_OPAQUE;
    int gauss = desc->kernel == ASP_SPLAT_KERNEL_PSI_G;
    c->use64 = c->opaque && has_gl_extension("GL_NV_shader_atomic_int64") &&
               has_gl_extension("GL_ARB_gpu_shader_int64");
    if (c->use64) {
        // a driver that lists the extensions but fails the shaders still draws, by the 32-bit path
        asp_error e64;
        c->programs = 1;
        if (compile_compute(gl, "64-bit", compute64_head, compute64_body, PASS_DEPTH_COLOR64, gauss, &c->program[0],
                            &e64) ||
            asp__gl_program_create(gl, "compute resolve (64-bit)", resolve_vertex_src, resolve64_src, &c->resolve,
                                   &e64)) {
            asp__gl_program_destroy(&c->program[0]);
            asp__gl_program_destroy(&c->resolve);
            asp__gl_clear_errors(gl);
            c->use64 = 0;
        }
    }
    rc = 0;
    if (!c->use64) {
        c->programs = 2;
        int first = c->opaque ? PASS_DEPTH : PASS_BLEND_DEPTH, second = c->opaque ? PASS_COLOR : PASS_BLEND_SUM;
        rc = compile_compute(gl, "32-bit", compute32_head, compute32_body, first, gauss, &c->program[0], err);
        if (!rc)
            rc = compile_compute(gl, "32-bit", compute32_head, compute32_body, second, gauss, &c->program[1], err);
        if (!rc)
            rc = asp__gl_program_create(gl, "compute resolve", resolve_vertex_src, resolve32_src, &c->resolve, err);
    }
    if (!rc)
        rc = upload(c, words, boxes, n, err);
    asp_free(a, words);
    asp_free(a, boxes);
    if (rc) {
        compute_destroy(&c->base);
        return rc;
    }
    for (int i = 0; i < U_COUNT; i++)
        for (int k = 0; k < c->programs; k++)
            c->u[k][i] = glGetUniformLocation(c->program[k].id, uniform_names[i]);
    c->r_mode = glGetUniformLocation(c->resolve.id, "u_mode");
    c->r_size = glGetUniformLocation(c->resolve.id, "u_size");
    glCreateVertexArrays(1, &c->vao.id);
    set_static_uniforms(c, desc, has_colors);
    rc = asp__gl_check(gl, "create the compute renderer", err);
    if (rc) {
        compute_destroy(&c->base);
        return rc;
    }
    *out = &c->base;
    return 0;
}

/* The renderer table's row (renderer_table.c): a given hierarchy's leaves, else the cloud; splat's options. */
int asp__compute_renderer_make(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *o,
                               const asp_context *ctx, asp_renderer **out, asp_error *err)
{
    if (!src->cloud && !src->hier)
        return asp_error_set(err, ASP_EUNSUPPORTED, "renderer 'compute' draws points (a point file or an .amg input)");
    asp_splat_renderer_desc d = o ? o->splat : (asp_splat_renderer_desc){0};
    return create(gl, src->hier ? NULL : src->cloud, src->hier, &d, ctx, out, err);
}
