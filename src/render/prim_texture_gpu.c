/*
 * Texture construction on the graphics hardware (thesis 3.6, "Acceleration",
 * future work there): the fills of the radial method (the sums of phi_p times
 * colour and Psi, 3.3.2) and of the linear affine method (barycentric
 * interpolation in the kept Delaunay triangles, 3.3.3, and the radial fringe
 * outside them) in a GL 4.5 compute shader, one invocation per texel. As the
 * thesis proposes, f is read back and the library normalises, extends colour
 * and encodes (asp__prim_texture_finish), the same code as the CPU build.
 * Each texel visits only the samples and triangles binned to its 8 x 8 texel
 * cell, in increasing index order, and evaluates in double precision as
 * texture_radial.c / texture_affine.c do, so the sums are the CPU's sums.
 */
#include <math.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

enum { CELL = 8, GROUP = 64 };

static const char fill_cs[] =
    "#version 450 core\n"
    "layout(local_size_x = 64) in;\n"
    "struct pt { vec4 xyr; vec4 attr; };\n"
    "struct prim { uvec4 a; };\n" /* texel_first, w, h, cell_first */
    "layout(std430, binding = 0) readonly buffer Samples { pt samples[]; };\n"
    "layout(std430, binding = 1) readonly buffer Prims { prim prims[]; };\n"
    "layout(std430, binding = 2) readonly buffer Cells { uvec4 cells[]; };\n" /* samples first, count, tris first, count */
    "layout(std430, binding = 3) readonly buffer SampleLists { uint slist[]; };\n"
    "layout(std430, binding = 4) readonly buffer TriLists { uint tlist[]; };\n"
    "layout(std430, binding = 5) readonly buffer Tris { uvec4 tris[]; };\n"
    "struct texel { vec4 acc; vec4 fc; };\n" /* fc.x = f, fc.y = covered */
    "layout(std430, binding = 6) writeonly buffer Out { texel outs[]; };\n"
    "uniform uint u_texels;\n"
    "uniform uint u_prims;\n"
    "uniform int u_affine;\n"
    "uniform int u_shape;\n" /* 0 linear, 1 constant, 2 gaussian */
    "void main() {\n"
    "    uint g = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;\n"
    "    if (g >= u_texels) return;\n"
    "    uint lo = 0u, hi = u_prims - 1u;\n" /* the last primitive whose first texel is <= g */
    "    while (lo < hi) { uint mid = (lo + hi + 1u) / 2u; if (prims[mid].a.x <= g) lo = mid; else hi = mid - 1u; }\n"
    "    uvec4 p = prims[lo].a;\n"
    "    uint t = g - p.x, i = t % p.y, j = t / p.y;\n"
    "    uint cx = (p.y + 7u) / 8u;\n"
    "    uvec4 c = cells[p.w + (j / 8u) * cx + i / 8u];\n"
    "    precise vec4 acc = vec4(0.0);\n"
    "    precise float f = 0.0;\n"
    "    bool covered = false;\n"
    "    double px = double(i) + 0.5lf, py = double(j) + 0.5lf;\n"
    "    if (u_affine != 0) {\n" /* texture_affine.c: the last containing triangle in index order wins */
    "        for (uint k = 0u; k < c.w; k++) {\n"
    "            uvec4 tr = tris[tlist[c.z + k]];\n"
    "            dvec2 A = dvec2(samples[tr.x].xyr.xy), B = dvec2(samples[tr.y].xyr.xy), C = dvec2(samples[tr.z].xyr.xy);\n"
    "            double area = (B.x - A.x) * (C.y - A.y) - (B.y - A.y) * (C.x - A.x);\n"
    "            if (!(area > 0.0lf)) continue;\n"
    "            double la = (B.x - px) * (C.y - py) - (B.y - py) * (C.x - px);\n"
    "            double lb = (C.x - px) * (A.y - py) - (C.y - py) * (A.x - px);\n"
    "            double lc = area - la - lb;\n"
    "            double eps = -1e-9lf * area;\n"
    "            if (la < eps || lb < eps || lc < eps) continue;\n"
    "            la /= area; lb /= area; lc /= area;\n"
    "            acc = vec4(la * dvec4(samples[tr.x].attr) + lb * dvec4(samples[tr.y].attr) + lc * dvec4(samples[tr.z].attr));\n"
    "            covered = true;\n"
    "        }\n"
    "    }\n"
    "    if (!covered) {\n" /* texture_radial.c; the affine fringe: linear, distance to the texel's nearest point */
    "        for (uint k = 0u; k < c.y; k++) {\n"
    "            pt s = samples[slist[c.x + k]];\n"
    "            double R = s.xyr.z > 1.0 ? double(s.xyr.z) : 1.0lf;\n"
    "            double dx = px - double(s.xyr.x), dy = py - double(s.xyr.y), d2 = dx * dx + dy * dy;\n"
    "            if (d2 > R * R) continue;\n"
    "            double d = sqrt(d2);\n"
    "            if (u_affine != 0) { d = d > 0.5lf ? d - 0.5lf : 0.0lf; d2 = d * d; }\n"
    "            int shape = u_affine != 0 ? 0 : u_shape;\n"
    "            double phi = shape == 1 ? 1.0lf : shape == 2 ? double(exp(float(-d2 * (4.5lf / (R * R))))) : 1.0lf - d / R;\n"
    "            if (!(phi > 0.0lf)) continue;\n"
    "            float ph = float(phi);\n"
    "            f += ph;\n"
    "            acc += ph * s.attr;\n"
    "        }\n"
    "    }\n"
    "    outs[g].acc = acc;\n"
    "    outs[g].fc = vec4(f, covered ? 1.0 : 0.0, 0.0, 0.0);\n"
    "}\n";

static int build_program(asp_gl_context *gl, GLuint *out, asp_error *err)
{
    asp__gl_clear_errors(gl);
    const char *src = fill_cs;
    GLuint p = glCreateShaderProgramv(GL_COMPUTE_SHADER, 1, &src);
    GLint ok = GL_FALSE;
    if (p)
        glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        if (p)
            glGetProgramInfoLog(p, sizeof log, NULL, log);
        log[strcspn(log, "\n")] = '\0';
        glDeleteProgram(p);
        return asp_error_set(err, ASP_EGL, "cannot build the texture fill compute shader: %s", log);
    }
    *out = p;
    return 0;
}

/* Cell c of primitive k's grid: every sample whose footprint and every triangle whose box reaches it. */
typedef struct bins {
    uint32_t *cells;   /* 4 per cell: sample first, count, triangle first, count */
    uint32_t *slist, *tlist;
    size_t cell_total, s_total, t_total;
} bins;

static void cell_range(double lo, double hi, uint32_t n, long *c0, long *c1)
{
    long i0 = (long)lo, i1 = (long)hi;
    i0 = i0 < 0 ? 0 : i0, i1 = i1 >= (long)n ? (long)n - 1 : i1;
    *c0 = i0 / CELL, *c1 = i1 < i0 ? -1 : i1 / CELL;
}

/* The texel ranges texture_radial.c and texture_affine.c visit, as cell ranges; pass 0 counts, 1 fills. */
static void bin_pass(const asp_prim_fill_batch *b, const size_t *cell_first, bins *B, int pass)
{
    for (size_t k = 0; k < b->prim_count; k++) {
        uint32_t w = b->w[k], h = b->h[k], cx = (w + CELL - 1) / CELL;
        for (size_t s = b->sample_first[k]; s < b->sample_first[k + 1]; s++) {
            double R = b->r[s] > 1.0f ? b->r[s] : 1.0, px = b->x[s], py = b->y[s];
            long i0, i1, j0, j1;
            cell_range(floor(px - R - 0.5), ceil(px + R - 0.5), w, &i0, &i1);
            cell_range(floor(py - R - 0.5), ceil(py + R - 0.5), h, &j0, &j1);
            for (long j = j0; j <= j1; j++)
                for (long i = i0; i <= i1; i++) {
                    uint32_t *c = &B->cells[4 * (cell_first[k] + (size_t)j * cx + (size_t)i)];
                    if (pass)
                        B->slist[c[0] + c[1]] = (uint32_t)s;
                    c[1]++;
                }
        }
        if (b->method != ASP_PRIM_AFFINE)
            continue;
        for (size_t t = b->tri_first[k]; t < b->tri_first[k + 1]; t++) {
            const uint32_t *v = &b->tri[3 * t];
            double xmin = fmin(b->x[v[0]], fmin(b->x[v[1]], b->x[v[2]])), xmax = fmax(b->x[v[0]], fmax(b->x[v[1]], b->x[v[2]]));
            double ymin = fmin(b->y[v[0]], fmin(b->y[v[1]], b->y[v[2]])), ymax = fmax(b->y[v[0]], fmax(b->y[v[1]], b->y[v[2]]));
            double i0d = ceil(xmin - 0.5), i1d = floor(xmax - 0.5), j0d = ceil(ymin - 0.5), j1d = floor(ymax - 0.5);
            if (i1d < 0 || j1d < 0 || i0d > i1d || j0d > j1d)
                continue;
            long i0, i1, j0, j1;
            cell_range(i0d, i1d, w, &i0, &i1);
            cell_range(j0d, j1d, h, &j0, &j1);
            for (long j = j0; j <= j1; j++)
                for (long i = i0; i <= i1; i++) {
                    uint32_t *c = &B->cells[4 * (cell_first[k] + (size_t)j * cx + (size_t)i)];
                    if (pass)
                        B->tlist[c[2] + c[3]] = (uint32_t)t;
                    c[3]++;
                }
        }
    }
}

static int make_bins(const asp_prim_fill_batch *b, size_t *cell_first, const asp_context *actx, bins *B,
                     asp_error *err)
{
    cell_first[0] = 0;
    for (size_t k = 0; k < b->prim_count; k++)
        cell_first[k + 1] = cell_first[k] + (size_t)((b->w[k] + CELL - 1) / CELL) * ((b->h[k] + CELL - 1) / CELL);
    B->cell_total = cell_first[b->prim_count];
    B->cells = asp_calloc(actx, 4 * B->cell_total, sizeof *B->cells);
    if (!B->cells)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu texture cells", B->cell_total);
    bin_pass(b, cell_first, B, 0);
    for (size_t c = 0; c < B->cell_total; c++) {
        B->cells[4 * c] = (uint32_t)B->s_total, B->cells[4 * c + 2] = (uint32_t)B->t_total;
        B->s_total += B->cells[4 * c + 1], B->t_total += B->cells[4 * c + 3];
        B->cells[4 * c + 1] = B->cells[4 * c + 3] = 0;
        if (B->s_total > UINT32_MAX || B->t_total > UINT32_MAX)
            return asp_error_set(err, ASP_EUNSUPPORTED, "texture batch too large for 32-bit cell lists");
    }
    B->slist = asp_alloc(actx, (B->s_total + 1) * sizeof *B->slist);
    B->tlist = asp_alloc(actx, (B->t_total + 1) * sizeof *B->tlist);
    if (!B->slist || !B->tlist)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the cell lists of a texture batch");
    bin_pass(b, cell_first, B, 1);
    return 0;
}

static GLuint buffer(const void *data, size_t bytes, GLbitfield flags)
{
    GLuint id = 0;
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, (GLsizeiptr)(bytes ? bytes : 16), data, flags); // an empty buffer cannot be bound
    return id;
}

/* The asp_prim_fill_fn that asp_prim_gpu_fill_set installs: user is the asp_gl_context it was given. */
static int gpu_fill(void *user, const asp_prim_fill_batch *b, float *acc, float *f, uint8_t *covered, asp_error *err)
{
    asp_gl_context *gl = user;
    ASP_ASSERT(gl && b && acc && f && covered);
    if (b->prim_count == 0)
        return 0;
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    const asp_context *actx = &gl->actx;
    const size_t m = b->prim_count, S = b->sample_first[m], T = b->texel_first[m];
    const size_t NT = b->method == ASP_PRIM_AFFINE ? b->tri_first[m] : 0;
    if (T > UINT32_MAX / 2 || S > UINT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "texture batch of %zu texels is too large for one dispatch", T);
    bins B = {0};
    size_t *cell_first = asp_alloc(actx, (m + 1) * sizeof *cell_first);
    float *smp = asp_alloc(actx, 8 * (S ? S : 1) * sizeof *smp);
    uint32_t *prm = asp_alloc(actx, 4 * m * sizeof *prm), *trs = asp_alloc(actx, 4 * (NT ? NT : 1) * sizeof *trs);
    float *out = asp_alloc(actx, 8 * T * sizeof *out);
    GLuint prog = 0, bufs[7] = {0};
    if (!cell_first || !smp || !prm || !trs || !out) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for a GPU texture batch of %zu texels", T);
        goto done;
    }
    if ((rc = make_bins(b, cell_first, actx, &B, err)) != 0 || (rc = build_program(gl, &prog, err)) != 0)
        goto done;
    for (size_t s = 0; s < S; s++) {
        float *q = &smp[8 * s];
        q[0] = b->x[s], q[1] = b->y[s], q[2] = b->r[s], q[3] = 0;
        memcpy(q + 4, &b->attr[4 * s], 4 * sizeof(float));
    }
    for (size_t k = 0; k < m; k++)
        prm[4 * k] = (uint32_t)b->texel_first[k], prm[4 * k + 1] = b->w[k], prm[4 * k + 2] = b->h[k],
        prm[4 * k + 3] = (uint32_t)cell_first[k];
    for (size_t t = 0; t < NT; t++)
        trs[4 * t] = b->tri[3 * t], trs[4 * t + 1] = b->tri[3 * t + 1], trs[4 * t + 2] = b->tri[3 * t + 2],
        trs[4 * t + 3] = 0;
    bufs[0] = buffer(smp, 8 * S * sizeof(float), 0);
    bufs[1] = buffer(prm, 4 * m * sizeof(uint32_t), 0);
    bufs[2] = buffer(B.cells, 4 * B.cell_total * sizeof(uint32_t), 0);
    bufs[3] = buffer(B.slist, B.s_total * sizeof(uint32_t), 0);
    bufs[4] = buffer(B.tlist, B.t_total * sizeof(uint32_t), 0);
    bufs[5] = buffer(trs, 4 * NT * sizeof(uint32_t), 0);
    bufs[6] = buffer(NULL, 8 * T * sizeof(float), 0);
    for (GLuint i = 0; i < 7; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, bufs[i]);
    glProgramUniform1ui(prog, glGetUniformLocation(prog, "u_texels"), (GLuint)T);
    glProgramUniform1ui(prog, glGetUniformLocation(prog, "u_prims"), (GLuint)m);
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_affine"), b->method == ASP_PRIM_AFFINE);
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_shape"), b->shape);
    glUseProgram(prog);
    // at most 65535 groups a row (the GL minimum): rows of groups beyond, the shader folds y into its index
    size_t groups = (T + GROUP - 1) / GROUP, gx = groups < 65535 ? groups : 65535, gy = (groups + gx - 1) / gx;
    glDispatchCompute((GLuint)gx, (GLuint)gy, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(bufs[6], 0, (GLsizeiptr)(8 * T * sizeof(float)), out);
    glUseProgram(0);
    for (GLuint i = 0; i < 7; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, 0);
    if ((rc = asp__gl_check(gl, "fill textures with the compute shader", err)) != 0)
        goto done;
    for (size_t t = 0; t < T; t++) {
        memcpy(&acc[4 * t], &out[8 * t], 4 * sizeof(float));
        f[t] = out[8 * t + 4];
        covered[t] = out[8 * t + 5] != 0;
    }
done:
    for (int i = 0; i < 7; i++)
        if (bufs[i])
            glDeleteBuffers(1, &bufs[i]);
    if (prog)
        glDeleteProgram(prog);
    asp_free(actx, B.cells);
    asp_free(actx, B.slist);
    asp_free(actx, B.tlist);
    asp_free(actx, cell_first);
    asp_free(actx, smp);
    asp_free(actx, prm);
    asp_free(actx, trs);
    asp_free(actx, out);
    return rc;
}

void asp_prim_gpu_fill_set(asp_prim_desc *desc, asp_gl_context *gl)
{
    ASP_ASSERT(desc && gl);
    desc->fill = gpu_fill;
    desc->fill_user = gl;
}
