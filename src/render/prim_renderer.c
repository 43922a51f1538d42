/*
 * Loading a .dps level for rendering (issue 5 item 1; journal section 3-4,
 * thesis 4.3): primitives and neighbour lists into GL storage buffers, the
 * level's atlas into one sRGB texture with linear filtering (thesis 5.1 used
 * OpenGL linear filtering), the renderer's options, names and bounds.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/prim_internal.h"
#include "util/banned.h"

static const char *const method_names[] = {"normalized", "prefix", "overlap", "two-pass", "dark-backface",
                                           "dark-backface-soft", "blend-all", "no-blend", "polygons"};
enum { METHOD_COUNT = sizeof method_names / sizeof method_names[0] };

const char *asp_prim_render_method_name(asp_prim_render_method m)
{
    return (unsigned)m < METHOD_COUNT ? method_names[m] : NULL;
}

int asp_prim_render_method_parse(const char *name, asp_prim_render_method *out, asp_error *err)
{
    for (unsigned i = 0; i < METHOD_COUNT; i++)
        if (strcmp(name, method_names[i]) == 0) {
            *out = (asp_prim_render_method)i;
            return 0;
        }
    char list[200] = "";
    size_t len = 0;
    for (unsigned i = 0; i < METHOD_COUNT && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", method_names[i]);
    return asp_error_set(err, ASP_EINVAL, "unknown rendering method '%s' (expected %s)", name, list);
}

/*
 * Twelve well separated sRGB colours for --color-by domain; neighbours get
 * different ones (greedy colouring over the neighbour lists) so overlaps show
 * as mixed colours, as in journal Fig. 5d.
 */
static const uint8_t palette[12][3] = {{230, 25, 75},  {60, 180, 75},  {255, 225, 25}, {0, 130, 200},
                                       {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230},
                                       {210, 245, 60}, {250, 190, 190}, {0, 128, 128}, {170, 110, 40}};

static uint32_t domain_color(const asp_dps_level *lv, const uint8_t *assigned, size_t i)
{
    const asp_prim *p = &lv->prims[i];
    unsigned used = 0;
    for (uint32_t k = 0; k < p->neighbour_count; k++) {
        uint32_t j = lv->neighbours[p->neighbour_first + k];
        if (j < i)
            used |= 1u << assigned[j];
    }
    unsigned c = 0;
    while (c < 12 && (used >> c & 1))
        c++;
    return c < 12 ? c : (unsigned)(i % 12); // more than 12 coloured neighbours: repeat, deterministically
}

static int finite3(const float *v)
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* The checks asp_dps_load makes, for levels built or edited in memory. */
static int check_level(const asp_dps_level *lv, asp_error *err)
{
    if (lv->prim_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot render a level without primitives");
    if (lv->prim_count > (size_t)INT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw %zu primitives in one call (at most %d)",
                             lv->prim_count, INT32_MAX);
    const asp_image *at = &lv->atlas;
    if (!at->pixels || at->width == 0 || at->height == 0)
        return asp_error_set(err, ASP_EFORMAT, "cannot render level %u: it has no atlas", lv->level);
    int has_normals = lv->normal_atlas.width > 0;
    if (has_normals && (!lv->normal_atlas.pixels || lv->normal_atlas.width != at->width ||
                        lv->normal_atlas.height != at->height))
        return asp_error_set(err, ASP_EFORMAT, "cannot render level %u: normal atlas %ux%u, expected %ux%u like the atlas",
                             lv->level, lv->normal_atlas.width, lv->normal_atlas.height, at->width, at->height);
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        if (!isfinite(p->centre[0]) || !isfinite(p->centre[1]) || !isfinite(p->centre[2]) || !finite3(p->axis_u) ||
            !finite3(p->axis_v) || !finite3(p->normal) || !isfinite(p->half_u) || !isfinite(p->half_v) ||
            !(p->half_u >= 0) || !(p->half_v >= 0))
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot render level %u: primitive %zu has a non-finite or negative geometry value",
                                 lv->level, i);
        if (p->tex_w == 0 || p->tex_h == 0 || p->tex_x > at->width || p->tex_w > at->width - p->tex_x ||
            p->tex_y > at->height || p->tex_h > at->height - p->tex_y)
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot render level %u: primitive %zu texture %ux%u at (%u, %u) is outside the "
                                 "%ux%u atlas",
                                 lv->level, i, p->tex_w, p->tex_h, p->tex_x, p->tex_y, at->width, at->height);
        if (p->neighbour_first > lv->neighbour_total || p->neighbour_count > lv->neighbour_total - p->neighbour_first)
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot render level %u: primitive %zu neighbour range %u+%u exceeds the %zu entries",
                                 lv->level, i, p->neighbour_first, p->neighbour_count, lv->neighbour_total);
    }
    for (size_t k = 0; k < lv->neighbour_total; k++)
        if (lv->neighbours[k] >= lv->prim_count)
            return asp_error_set(err, ASP_EFORMAT,
                                 "cannot render level %u: neighbour entry %zu is %u, expected < %zu primitives",
                                 lv->level, k, lv->neighbours[k], lv->prim_count);
    return 0;
}

static int check_options(const asp_prim_render_options *o, asp_error *err)
{
    if ((unsigned)o->method >= METHOD_COUNT)
        return asp_error_set(err, ASP_EINVAL, "unknown rendering method %d (expected 0..%d)", (int)o->method,
                             METHOD_COUNT - 1);
    unsigned known = ASP_PRIM_RENDER_OUTLINE | ASP_PRIM_RENDER_COLOR_BY_DOMAIN | ASP_PRIM_RENDER_NO_NORMAL_MAP |
                     ASP_PRIM_RENDER_OVERLAP_BACKFACES | ASP_PRIM_RENDER_DEBUG_EIGENVECTORS | ASP_PRIM_RENDER_DEBUG_TEXELS |
                     ASP_PRIM_RENDER_DEBUG_TRIANGULATION;
    if (o->flags & ~known)
        return asp_error_set(err, ASP_EINVAL, "unknown primitive rendering flags 0x%x", o->flags & ~known);
    if (isnan(o->alpha_ref) || o->alpha_ref > 1)
        return asp_error_set(err, ASP_EINVAL, "alpha reference %g is outside 0..1", (double)o->alpha_ref);
    if (!(o->transparency >= 0 && o->transparency <= 1))
        return asp_error_set(err, ASP_EINVAL, "transparency %g is outside 0..1 (1 = opaque)", (double)o->transparency);
    if (isnan(o->depth_window) || isinf(o->depth_window))
        return asp_error_set(err, ASP_EINVAL, "depth window %g is not finite", (double)o->depth_window);
    if (isnan(o->crease_angle))
        return asp_error_set(err, ASP_EINVAL, "crease angle is not a number (expected degrees, or < 0 for none)");
    return 0;
}

static void resolve_options(const asp__prim_renderer *r, const asp_prim_render_options *in,
                            asp_prim_render_options *o)
{
    *o = *in;
    o->alpha_ref = in->alpha_ref > 0 ? in->alpha_ref : in->alpha_ref < 0 ? 0.0f : 0.1f;
    if (r->billboards) {
        /* a billboard cloud's alpha is a binary mask (issue 30; Decoret et al. 2003): drawn opaque and
           depth-tested where it is set, halfway between 0 and 1 under linear filtering, never blended or
           normalised; polygons (outlines of the planes) stay available */
        if (o->method != ASP_PRIM_RENDER_POLYGONS)
            o->method = ASP_PRIM_RENDER_NO_BLEND;
        if (in->alpha_ref == 0)
            o->alpha_ref = 0.5f;
    }
    o->transparency = in->transparency > 0 ? in->transparency : 1.0f;
    o->depth_window = in->depth_window > 0 ? in->depth_window : in->depth_window < 0 ? 0.0f : r->default_window;
    float angle = in->crease_angle == 0 ? ASP_PRIM_CREASE_ANGLE_DEFAULT : in->crease_angle;
    o->crease_angle = angle < 0 || angle >= 180 ? -1.0f : angle;
    const uint8_t *c = in->outline_color;
    if (!(c[0] || c[1] || c[2] || c[3])) {
        static const uint8_t green[4] = {0, 255, 0, 255};
        memcpy(o->outline_color, green, 4);
    }
}

static const asp__renderer_vtable prim_vtable;

/* r when it is a domain-primitive renderer (a check of this kind's own handle), else NULL. */
static asp__prim_renderer *prim_of(asp_renderer *r)
{
    return r && r->vt == &prim_vtable ? (asp__prim_renderer *)r : NULL;
}

int asp_prim_renderer_set_options(asp_renderer *r, const asp_prim_render_options *options, asp_error *err)
{
    asp__prim_renderer *p = prim_of(r);
    if (!p)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer has no domain-primitive options",
                             r ? asp_renderer_name(r) : "(null)");
    int rc = check_options(options, err);
    if (rc)
        return rc;
    resolve_options(p, options, &p->opt);
    return 0;
}

int asp_prim_renderer_options(const asp_renderer *r, asp_prim_render_options *out, asp_error *err)
{
    asp__prim_renderer *p = prim_of((asp_renderer *)r);
    if (!p)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer has no domain-primitive options",
                             r ? asp_renderer_name(r) : "(null)");
    *out = p->opt;
    return 0;
}

int asp_prim_renderer_set_debug_lines(asp_renderer *r, const float *lines, size_t segments, asp_error *err)
{
    asp__prim_renderer *p = prim_of(r);
    if (!p)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer draws no triangulation",
                             r ? asp_renderer_name(r) : "(null)");
    return asp__prim_debug_set_lines(p, lines, segments, err);
}

static void prim_destroy(asp_renderer *base)
{
    asp__prim_renderer *r = (asp__prim_renderer *)base;
    asp__prim_targets_release(&r->t);
    asp__prim_debug_destroy(r);
    for (int i = 0; i < ASP__PROG_COUNT; i++)
        asp__gl_program_destroy(&r->programs[i]);
    GLuint bufs[5] = {r->prim_buffer.id, r->neighbour_buffer.id, r->order_buffer.id, r->identity_buffer.id,
                      r->clip_buffer.id};
    for (int i = 0; i < 5; i++)
        if (bufs[i])
            glDeleteBuffers(1, &bufs[i]);
    GLuint vaos[3] = {r->vao.id, r->identity_vao.id, r->empty_vao.id};
    for (int i = 0; i < 3; i++)
        if (vaos[i])
            glDeleteVertexArrays(1, &vaos[i]);
    GLuint tex[2] = {r->atlas, r->normal_atlas};
    for (int i = 0; i < 2; i++)
        if (tex[i])
            glDeleteTextures(1, &tex[i]);
    asp_context actx = base->gl->actx;
    void *blocks[] = {r->centres, r->normals, r->nb_first, r->nb_count, r->neighbours,
                      r->order, r->runs, r->keys, r->drawn};
    for (size_t i = 0; i < sizeof blocks / sizeof blocks[0]; i++)
        asp_free(&actx, blocks[i]);
    asp_free(&actx, r);
}

static int prim_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    asp__prim_renderer *r = (asp__prim_renderer *)base;
    int rc = asp__prim_draw(r, f, err);
    if (!rc && (r->opt.flags & (ASP_PRIM_RENDER_DEBUG_EIGENVECTORS | ASP_PRIM_RENDER_DEBUG_TEXELS |
                                ASP_PRIM_RENDER_DEBUG_TRIANGULATION)))
        rc = asp__prim_debug_draw(r, f, err); // thesis appendix C: over the method's image
    return rc;
}

static int prim_draw_instances(asp_renderer *base, const asp__frame *f, const float *models, size_t count,
                               asp_error *err)
{
    return asp__prim_draw_instances((asp__prim_renderer *)base, f, models, count, err);
}

/*
 * Instances in one draw only with the normalized method: the seeds' methods paint without a
 * depth test and need the scene's global far-to-near order, prefix selects by primitive id,
 * which instances share, and outlines are drawn per frame.
 */
static int prim_instanced(const asp_renderer *base)
{
    const asp__prim_renderer *r = (const asp__prim_renderer *)base;
    return r->opt.method == ASP_PRIM_RENDER_NORMALIZED && !(r->opt.flags & ASP_PRIM_RENDER_OUTLINE);
}

static const asp__renderer_vtable prim_vtable = {.name = "prim",
                                                 .draw = prim_draw,
                                                 .destroy = prim_destroy,
                                                 .draw_instances = prim_draw_instances,
                                                 .instanced = prim_instanced};

/* CPU copies used every frame by the sorted methods. */
static int alloc_cpu(asp__prim_renderer *r, asp_error *err)
{
    asp_context *a = &r->base.gl->actx;
    size_t n = r->count, nb = r->neighbour_total ? r->neighbour_total : 1;
    r->order_capacity = 2 * n + 1;
    r->centres = asp_alloc(a, 3 * n * sizeof(float));
    r->normals = asp_alloc(a, 3 * n * sizeof(float));
    r->nb_first = asp_alloc(a, n * sizeof(uint32_t));
    r->nb_count = asp_alloc(a, n * sizeof(uint32_t));
    r->neighbours = asp_alloc(a, nb * sizeof(uint32_t));
    r->order = asp_alloc(a, r->order_capacity * sizeof(uint32_t));
    r->runs = asp_alloc(a, r->order_capacity * sizeof(asp__run));
    r->keys = asp_alloc(a, n * sizeof *r->keys);
    r->drawn = asp_alloc(a, n * sizeof(uint32_t));
    if (!r->centres || !r->normals || !r->nb_first || !r->nb_count || !r->neighbours || !r->order || !r->runs ||
        !r->keys || !r->drawn)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the draw lists of %zu primitives", n);
    return 0;
}

/* Fills the GPU records (and the CPU copies); returns the mean primitive radius sqrt(half_u half_v). */
static double fill_prims(asp__prim_renderer *r, const asp_dps_level *lv, const double origin[3], asp__prim_gpu *g)
{
    uint8_t *assigned = (uint8_t *)r->drawn; // scratch: count bytes fit in count uint32
    double sum_radius = 0;
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        asp__prim_gpu *q = &g[i];
        memset(q, 0, sizeof *q);
        for (int a = 0; a < 3; a++) {
            q->c[a] = (float)(p->centre[a] - origin[a]);
            q->u[a] = p->axis_u[a] * p->half_u;
            q->v[a] = p->axis_v[a] * p->half_v;
            q->n[a] = p->normal[a];
            r->centres[3 * i + a] = q->c[a];
            r->normals[3 * i + a] = p->normal[a];
        }
        // texel edges: the rectangle's s = -half_u is the left edge of column tex_x (build.md)
        q->uv[0] = (float)p->tex_x / (float)lv->atlas.width;
        q->uv[1] = (float)p->tex_y / (float)lv->atlas.height;
        q->uv[2] = (float)p->tex_w / (float)lv->atlas.width;
        q->uv[3] = (float)p->tex_h / (float)lv->atlas.height;
        unsigned c = domain_color(lv, assigned, i);
        assigned[i] = (uint8_t)c;
        q->info[0] = p->neighbour_first;
        q->info[1] = p->neighbour_count;
        q->info[2] = (uint32_t)palette[c][0] | (uint32_t)palette[c][1] << 8 | (uint32_t)palette[c][2] << 16 |
                     0xffu << 24;
        q->info[3] = p->flags;
        r->nb_first[i] = p->neighbour_first;
        r->nb_count[i] = p->neighbour_count;
        sum_radius += sqrt((double)p->half_u * p->half_v);
    }
    if (lv->neighbour_total)
        memcpy(r->neighbours, lv->neighbours, lv->neighbour_total * sizeof(uint32_t));
    return sum_radius / (double)lv->prim_count;
}

/* bc3: the atlas's BC3 blocks (issue 27), uploaded as they are where the GL has S3TC (llvmpipe has);
 * elsewhere img, their decoded texels, as RGBA8: the same picture at 4 bytes a texel. */
static GLuint upload_atlas(const asp_image *img, const uint8_t *bc3, GLenum format, GLenum bc3_format)
{
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    if (bc3 && epoxy_has_gl_extension("GL_EXT_texture_compression_s3tc") &&
        (bc3_format != GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT5_EXT || epoxy_has_gl_extension("GL_EXT_texture_sRGB"))) {
        glTextureStorage2D(tex, 1, bc3_format, (GLsizei)img->width, (GLsizei)img->height);
        glCompressedTextureSubImage2D(tex, 0, 0, 0, (GLsizei)img->width, (GLsizei)img->height, bc3_format,
                                      (GLsizei)((size_t)img->width * img->height), bc3);
    } else {
        glTextureStorage2D(tex, 1, format, (GLsizei)img->width, (GLsizei)img->height);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTextureSubImage2D(tex, 0, 0, 0, (GLsizei)img->width, (GLsizei)img->height, GL_RGBA, GL_UNSIGNED_BYTE,
                            img->pixels);
    }
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

/* The a_id attribute (location 0) of vao from buf, one per instance. */
static void bind_ids(GLuint vao, GLuint buf)
{
    glVertexArrayVertexBuffer(vao, 0, buf, 0, sizeof(uint32_t));
    glVertexArrayAttribIFormat(vao, 0, 1, GL_UNSIGNED_INT, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glVertexArrayBindingDivisor(vao, 0, 1);
    glEnableVertexArrayAttrib(vao, 0);
}

static int build_programs(asp__prim_renderer *r, asp_error *err)
{
    static const char *names[ASP__PROG_COUNT] = {"primitives", "primitive depth", "primitive ids",
                                                 "primitive resolve"};
    for (int i = 0; i < ASP__PROG_COUNT; i++) {
        const char *vs = i == ASP__PROG_RESOLVE ? asp__prim_resolve_vertex_src : asp__prim_vertex_src;
        const char *fs = i == ASP__PROG_RESOLVE ? asp__prim_resolve_fragment_src : asp__prim_fragment_src[i];
        int rc = asp__gl_program_create(r->base.gl, names[i], vs, fs, &r->programs[i], err);
        if (rc)
            return rc;
        for (int u = 0; u < PU_COUNT; u++)
            r->uniforms[i][u] = glGetUniformLocation(r->programs[i].id, asp__prim_uniform_names[u]);
    }
    return 0;
}

static int upload(asp__prim_renderer *r, const asp_dps_level *lv, const double origin[3], asp_error *err)
{
    asp_gl_context *gl = r->base.gl;
    size_t n = lv->prim_count;
    asp__prim_gpu *g = asp_alloc(&gl->actx, n * sizeof *g);
    if (!g)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu primitive records", n);
    r->default_window = (float)(0.5 * fill_prims(r, lv, origin, g));
    // crease planes: per primitive a range of (plane, cos angle, other id) records, 32 bytes each
    uint32_t *first = r->order, *count = (uint32_t *)r->keys; // scratch, both hold >= n uint32
    float *creases = NULL;
    size_t crease_total = 0;
    int rc = asp__prim_creases(lv, origin, &gl->actx, first, count, &creases, &crease_total, err);
    if (rc) {
        asp_free(&gl->actx, g);
        return rc;
    }
    for (size_t i = 0; i < n; i++) {
        g[i].clip[0] = first[i];
        g[i].clip[1] = count[i];
    }
    r->crease_total = crease_total;
    glCreateBuffers(1, &r->clip_buffer.id);
    glNamedBufferStorage(r->clip_buffer.id, (GLsizeiptr)(8 * (crease_total ? crease_total : 1) * sizeof(float)),
                         creases, 0);
    asp_free(&gl->actx, creases);
    glCreateBuffers(1, &r->prim_buffer.id);
    glNamedBufferStorage(r->prim_buffer.id, (GLsizeiptr)(n * sizeof *g), g, 0);
    asp_free(&gl->actx, g);
    // an empty storage buffer cannot be bound; one unused entry keeps the binding valid
    uint32_t none = 0;
    size_t nb = lv->neighbour_total;
    glCreateBuffers(1, &r->neighbour_buffer.id);
    glNamedBufferStorage(r->neighbour_buffer.id, (GLsizeiptr)((nb ? nb : 1) * sizeof(uint32_t)),
                         nb ? (const void *)lv->neighbours : &none, 0);
    // identity order 0..n-1 for the unsorted methods, built in the order scratch
    for (size_t i = 0; i < n; i++)
        r->order[i] = (uint32_t)i;
    glCreateBuffers(1, &r->identity_buffer.id);
    glNamedBufferStorage(r->identity_buffer.id, (GLsizeiptr)(n * sizeof(uint32_t)), r->order, 0);
    glCreateBuffers(1, &r->order_buffer.id);
    glNamedBufferStorage(r->order_buffer.id, (GLsizeiptr)(r->order_capacity * sizeof(uint32_t)), NULL,
                         GL_DYNAMIC_STORAGE_BIT);
    glCreateVertexArrays(1, &r->vao.id);
    bind_ids(r->vao.id, r->order_buffer.id);
    glCreateVertexArrays(1, &r->identity_vao.id);
    bind_ids(r->identity_vao.id, r->identity_buffer.id);
    glCreateVertexArrays(1, &r->empty_vao.id);
    r->atlas = upload_atlas(&lv->atlas, lv->atlas_bc3, GL_SRGB8_ALPHA8, GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT5_EXT);
    if (r->has_normal_map)
        r->normal_atlas =
            upload_atlas(&lv->normal_atlas, lv->normal_bc3, GL_RGBA8, GL_COMPRESSED_RGBA_S3TC_DXT5_EXT);
    char what[96];
    snprintf(what, sizeof what, "upload %zu primitives and a %ux%u atlas", n, lv->atlas.width, lv->atlas.height);
    return asp__gl_check(gl, what, err);
}

int asp_prim_renderer_create(asp_gl_context *gl, const asp_dps_level *level, const asp_prim_renderer_desc *desc,
                             asp_renderer **out, asp_error *err)
{
    static const asp_prim_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = check_level(level, err);
    if (!rc)
        rc = check_options(&desc->options, err);
    if (!rc)
        rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    GLint max_tex = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    if (level->atlas.width > (uint32_t)max_tex || level->atlas.height > (uint32_t)max_tex)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot upload the %ux%u atlas of level %u: this GL allows %d texels a side "
                             "(rebuild with a larger --texel-size)",
                             level->atlas.width, level->atlas.height, level->level, max_tex);
    asp__prim_renderer *r = asp_calloc(&gl->actx, 1, sizeof *r);
    if (!r)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a domain-primitive renderer");
    r->base.vt = &prim_vtable;
    r->base.gl = gl;
    r->base.count = level->prim_count;
    r->count = level->prim_count;
    r->neighbour_total = level->neighbour_total;
    r->has_normal_map = level->normal_atlas.width > 0;
    r->billboards = level->billboards != 0;
    rc = alloc_cpu(r, err);
    if (!rc)
        rc = build_programs(r, err);
    if (!rc)
        rc = upload(r, level, desc->origin, err);
    if (rc) {
        prim_destroy(&r->base);
        return rc;
    }
    resolve_options(r, &desc->options, &r->opt);
    *out = &r->base;
    return 0;
}
