/*
 * GLSL of the cut renderer (issue 18, docs/cut.md): the primitives of several
 * .dps levels, each drawn item carrying its weight d_f and its instance's
 * model matrix, blended with the normalized method of the prim renderer
 * (Pajarola et al. 2003 sections 5.3-5.4; prim_shaders.c, whose resolve pass
 * is reused as is). Per-item weights and instances need their own vertex
 * stage; the fragment stage keeps the prim renderer's window test and shading.
 */
#include "render/prim_cut_internal.h"
#include "util/banned.h"

const char *const asp__cut_vertex_src =
    "#version 450 core\n"
    "struct prim { vec4 c; vec4 u; vec4 v; vec4 n; vec4 uv; uvec4 info; uvec4 clip; };\n"
    "layout(std430, binding = 0) readonly buffer Prims { prim prims[]; };\n"
    "layout(std430, binding = 3) readonly buffer Models { mat4 models[]; };\n"
    "layout(location = 0) in uint a_prim;\n"
    "layout(location = 1) in uint a_inst;\n"
    "layout(location = 2) in float a_weight;\n"
    "uniform mat4 u_view;\n"
    "uniform mat4 u_proj;\n"
    "out vec2 v_uv;\n"
    "out vec3 v_eye;\n"
    "flat out vec3 v_normal;\n"
    "flat out float v_weight;\n"
    /* counter-clockwise seen from the normal, as the prim renderer's strip, so back faces cull alike */
    "const vec2 strip[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));\n"
    "void main() {\n"
    "    prim p = prims[a_prim];\n"
    "    vec2 k = strip[gl_VertexID];\n"
    "    vec3 w = p.c.xyz + k.x * p.u.xyz + k.y * p.v.xyz;\n"
    "    v_uv = p.uv.xy + (0.5 * k + 0.5) * p.uv.zw;\n"
    "    mat4 mv = u_view * models[a_inst];\n"
    "    vec4 e = mv * vec4(w, 1.0);\n"
    "    v_eye = e.xyz;\n"
    "    v_normal = mat3(mv) * p.n.xyz;\n"
    "    v_weight = a_weight;\n"
    "    gl_Position = u_proj * e;\n"
    "}\n";

/*
 * u_pass 0: the front-most alpha-tested layer (depth only). u_pass 1: colour x
 * alpha x d_f and alpha x d_f of the fragments within u_window behind that
 * layer along the eye ray (the prim renderer's selected(), relative tolerance
 * 1e-5 so the front layer's own fragments pass).
 */
const char *const asp__cut_fragment_src =
    "#version 450 core\n"
    "in vec2 v_uv;\n"
    "in vec3 v_eye;\n"
    "flat in vec3 v_normal;\n"
    "flat in float v_weight;\n"
    "layout(binding = 0) uniform sampler2D u_atlas;\n"
    "layout(binding = 2) uniform sampler2D u_front_depth;\n"
    "uniform mat4 u_proj;\n"
    "uniform vec3 u_light;\n"
    "uniform int u_lit;\n"
    "uniform int u_pass;\n"
    "uniform float u_alpha_ref;\n"
    "uniform float u_window;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "float eye_distance_z(float depth) {\n"
    "    return u_proj[3][2] / ((2.0 * depth - 1.0) + u_proj[2][2]);\n"
    "}\n"
    "vec3 shade(vec3 c) {\n"
    "    if (u_lit == 0)\n"
    "        return c;\n"
    "    vec3 n = v_normal;\n"
    "    float lambert = dot(n, n) > 0.0 ? abs(dot(normalize(n), u_light)) : 1.0;\n"
    "    return c * (0.25 + 0.75 * lambert);\n"
    "}\n"
    "void main() {\n"
    "    if (u_pass == 0) {\n"
    "        if (!(texture(u_atlas, v_uv).a > u_alpha_ref))\n"
    "            discard;\n"
    "        o_color = vec4(0.0);\n"
    "        return;\n"
    "    }\n"
    /* the window test before the (filtered, sRGB) atlas fetch: most fragments of a field lie behind */
    /* the front layer, and a CPU rasteriser pays for every fetch */
    "    float front = texelFetch(u_front_depth, ivec2(gl_FragCoord.xy), 0).r;\n"
    "    if (!(front < 1.0))\n"
    "        discard;\n"
    "    float mine = -v_eye.z, theirs = eye_distance_z(front);\n"
    "    float along = (mine - theirs) * length(v_eye) / max(mine, 1e-30);\n"
    "    if (along > u_window + 1e-5 * length(v_eye))\n"
    "        discard;\n"
    "    vec4 tex = texture(u_atlas, v_uv);\n"
    "    if (!(tex.a > 0.0))\n"
    "        discard;\n"
    "    float w = tex.a * v_weight;\n"
    "    o_color = vec4(shade(tex.rgb) * w, w);\n"
    "}\n";
