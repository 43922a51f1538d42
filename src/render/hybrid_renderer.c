/*
 * The hybrid renderer (issue 18 item 3; journal section 6 and thesis 2.6.3
 * future work): a level's domain primitives where they represent their
 * region, the points of the point hierarchy (seed 001) where they do not
 * (hybrid_select.c decides), blended in one normalised accumulation
 * (Pajarola et al. 2003 5.3-5.4), so no seam shows where the two meet.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "render/prim_internal.h"
#include "render/splat_internal.h"
#include "util/banned.h"

static const char *resolve_vertex_src =
    "#version 450 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

/* colour = sum(w c) / sum(w) over primitives and splats alike (seed 001 eq. 9); no weight: background */
static const char *resolve_fragment_src =
    "#version 450 core\n"
    "layout(binding = 0) uniform sampler2D u_accum;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "    vec4 acc = texelFetch(u_accum, ivec2(gl_FragCoord.xy), 0);\n"
    "    if (!(acc.a > 0.0))\n"
    "        discard;\n"
    "    o_color = vec4(acc.rgb / acc.a, 1.0);\n"
    "}\n";

typedef struct hybrid_renderer {
    asp_renderer base;
    asp_renderer *prims;  /* the level (a prim renderer) drawing only the kept primitives; NULL when none is */
    asp_renderer *splats; /* the drawn points (a splat renderer owning their hierarchy), NULL when none */
    asp_hybrid_counts counts;
    asp__gl_program resolve;
    asp__gl_vertex_array vao;
    asp__gl_framebuffer fbo;
    GLuint accum, depth; /* RGBA32F sums, DEPTH_COMPONENT32F shared visibility */
    uint32_t width, height;
} hybrid_renderer;

static void targets_release(hybrid_renderer *h)
{
    if (h->fbo.id)
        glDeleteFramebuffers(1, &h->fbo.id);
    if (h->accum)
        glDeleteTextures(1, &h->accum);
    if (h->depth)
        glDeleteTextures(1, &h->depth);
    h->fbo.id = h->accum = h->depth = 0;
    h->width = h->height = 0;
}

static int targets_ensure(hybrid_renderer *h, uint32_t w, uint32_t ht, asp_error *err)
{
    if (h->fbo.id && h->width == w && h->height == ht)
        return 0;
    targets_release(h);
    asp__gl_clear_errors(h->base.gl);
    // float sums: splat weights pile up far beyond 1 where many overlap (splat_renderer.c accum_ensure)
    glCreateTextures(GL_TEXTURE_2D, 1, &h->accum);
    glTextureStorage2D(h->accum, 1, GL_RGBA32F, (GLsizei)w, (GLsizei)ht);
    glCreateTextures(GL_TEXTURE_2D, 1, &h->depth);
    glTextureStorage2D(h->depth, 1, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)ht);
    glCreateFramebuffers(1, &h->fbo.id);
    glNamedFramebufferTexture(h->fbo.id, GL_COLOR_ATTACHMENT0, h->accum, 0);
    glNamedFramebufferTexture(h->fbo.id, GL_DEPTH_ATTACHMENT, h->depth, 0);
    int rc = asp__gl_check(h->base.gl, "create the hybrid accumulation target", err);
    if (!rc && glCheckNamedFramebufferStatus(h->fbo.id, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        rc = asp_error_set(err, ASP_EGL, "cannot create the hybrid accumulation framebuffer");
    if (rc) {
        targets_release(h);
        return rc;
    }
    h->width = w;
    h->height = ht;
    return 0;
}

static void hybrid_destroy(asp_renderer *base)
{
    hybrid_renderer *h = (hybrid_renderer *)base;
    asp_renderer_destroy(h->prims);
    asp_renderer_destroy(h->splats);
    targets_release(h);
    asp__gl_program_destroy(&h->resolve);
    if (h->vao.id)
        glDeleteVertexArrays(1, &h->vao.id);
    asp_context actx = base->gl->actx;
    asp_free(&actx, h);
}


static void draw_parts(hybrid_renderer *h, const asp__frame *f, int depth_only)
{
    if (h->prims)
        asp__prim_hybrid_pass((asp__prim_renderer *)h->prims, h->counts.prims_kept, depth_only);
    if (h->splats)
        asp__splat_hybrid_pass(h->splats, f, depth_only);
}

static int hybrid_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    hybrid_renderer *h = (hybrid_renderer *)base;
    GLint caller = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &caller);
    int rc = targets_ensure(h, f->width, f->height, err);
    if (!rc && h->splats)
        rc = asp__splat_hybrid_select(h->splats, f, err);
    if (rc)
        return rc;
    if (h->prims)
        asp__prim_hybrid_begin((asp__prim_renderer *)h->prims, f);
    static const GLfloat zero[4] = {0, 0, 0, 0};
    const GLfloat far_depth = 1.0f;
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glClearNamedFramebufferfv(h->fbo.id, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(h->fbo.id, GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, h->fbo.id);

    /*
     * Pass 1, one visibility for both: the primitives' alpha-tested depth
     * pushed back by their depth window (thesis 4.4.2) and the splats' pushed
     * back by epsilon (seed 001 5.3, Fig. 15). Whichever surface is nearer
     * decides, so a point region in front hides the primitives behind it and
     * the reverse.
     */
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    draw_parts(h, f, 1);

    // pass 2: everything in front of that layer adds (colour x weight, weight) into the same sums
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    draw_parts(h, f, 0);

    // pass 3: one division for both, onto the caller's framebuffer
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)caller);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glBindTextureUnit(0, h->accum);
    glUseProgram(h->resolve.id);
    glBindVertexArray(h->vao.id);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTextureUnit(0, 0);
    asp__gl_restore_state((GLuint)caller);
    base->count = h->counts.prims_kept + (h->splats ? asp_renderer_count(h->splats) : 0);
    return asp__gl_check(base->gl, "draw the hybrid of primitives and points", err);
}

/* The point part's tolerance: the frame budget controller trades the points' detail for time. */
static int hybrid_set_lod(asp_renderer *base, float tolerance, uint32_t depth_limit, asp_error *err)
{
    hybrid_renderer *h = (hybrid_renderer *)base;
    return h->splats ? asp_renderer_set_lod(h->splats, tolerance, depth_limit, err) : 0;
}

static void hybrid_stats(const asp_renderer *base, asp_renderer_stats *out)
{
    const hybrid_renderer *h = (const hybrid_renderer *)base;
    if (h->splats) {
        asp_renderer_stats_get(h->splats, out);
        out->count += h->counts.prims_kept;
    } else {
        out->count = h->counts.prims_kept;
        out->points = 0;
    }
}

static const asp__renderer_vtable hybrid_vtable = {
    .name = "hybrid", .draw = hybrid_draw, .destroy = hybrid_destroy, .set_lod = hybrid_set_lod,
    .stats = hybrid_stats};

/*
 * The drawn points as a cloud in the frame of origin, with radii (estimated
 * over all points when missing) and, when planes is given (8 floats per
 * point of pts), their crease clip planes in *sub_planes (8 per drawn point).
 */
static int drawn_cloud(const asp_cloud *pts, const uint32_t *cover, size_t drawn, const double origin[3],
                       const float *planes, const asp_context *ctx, asp_cloud **out, float **sub_planes,
                       asp_error *err)
{
    float *radii = pts->radii;
    if (!radii) {
        radii = asp_alloc(ctx, pts->count * sizeof *radii);
        if (!radii)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu point radii", pts->count);
        // the 8th neighbour, as the reference's k = 8 neighbourhood ellipses (hier.h); over all points, so an
        // isolated drawn point gets the spacing of the surface, not of the other drawn points
        int rc = asp_estimate_radii(pts->positions, pts->count, 3 * sizeof(float), &(asp_radii_desc){.k = 8}, radii, ctx, err);
        if (rc) {
            asp_free(ctx, radii);
            return rc;
        }
    }
    unsigned attrs = ASP_ATTR_RADII | (pts->normals ? ASP_ATTR_NORMALS : 0) | (pts->colors ? ASP_ATTR_COLORS : 0);
    asp_cloud *c = NULL;
    int rc = asp_cloud_create(drawn, attrs, ctx, &c, err);
    float *sp = NULL;
    if (!rc && planes && !(sp = asp_alloc(ctx, 8 * drawn * sizeof *sp))) {
        asp_cloud_destroy(c);
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the clip planes of %zu points", drawn);
    }
    if (!rc) {
        memcpy(c->origin, origin, sizeof c->origin);
        float shift[3];
        for (int k = 0; k < 3; k++)
            shift[k] = (float)(pts->origin[k] - origin[k]);
        size_t m = 0;
        for (size_t j = 0; j < pts->count; j++) {
            if (cover[j] != ASP_HYBRID_DRAWN)
                continue;
            for (int k = 0; k < 3; k++)
                c->positions[3 * m + k] = pts->positions[3 * j + k] + shift[k];
            if (pts->normals)
                memcpy(c->normals + 3 * m, pts->normals + 3 * j, 3 * sizeof(float));
            if (pts->colors)
                memcpy(c->colors + 4 * m, pts->colors + 4 * j, 4);
            c->radii[m] = radii[j];
            if (sp) {
                // planes are offsets n . x + d in the points' frame: move d with the shift
                for (int q = 0; q < 2; q++) {
                    const float *pl = planes + 8 * j + 4 * q;
                    float *o = sp + 8 * m + 4 * q;
                    memcpy(o, pl, 4 * sizeof(float));
                    if (pl[0] != 0 || pl[1] != 0 || pl[2] != 0)
                        o[3] = pl[3] - (pl[0] * shift[0] + pl[1] * shift[1] + pl[2] * shift[2]);
                }
            }
            m++;
        }
        *out = c;
        *sub_planes = sp;
    }
    if (radii != pts->radii)
        asp_free(ctx, radii);
    return rc;
}

static int make_parts(hybrid_renderer *h, const asp_dps_level *level, const asp_cloud *points,
                      const asp_hybrid_desc *d, const asp_context *ctx, asp_error *err)
{
    asp_gl_context *gl = h->base.gl;
    uint8_t *replaced = asp_alloc(ctx, level->prim_count);
    uint32_t *cover = asp_alloc(ctx, points->count * sizeof *cover);
    if (!replaced || !cover) {
        asp_free(ctx, replaced);
        asp_free(ctx, cover);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the hybrid split of %zu points", points->count);
    }
    asp_hybrid_split_desc limits = {d->error_limit, d->turned_limit, d->coverage_min};
    int rc = asp_hybrid_split(level, points, &limits, ctx, replaced, cover, NULL, &h->counts, err);
    if (!rc && h->counts.prims_kept) {
        // the whole level goes up, so kept primitives keep the crease planes of replaced neighbours
        asp_prim_renderer_desc pd = {.options = d->prim};
        pd.options.method = ASP_PRIM_RENDER_NORMALIZED;
        pd.options.transparency = 0;
        pd.options.flags &= ~(unsigned)(ASP_PRIM_RENDER_OUTLINE | ASP_PRIM_RENDER_COLOR_BY_DOMAIN);
        memcpy(pd.origin, d->origin, sizeof pd.origin);
        rc = asp_prim_renderer_create(gl, level, &pd, &h->prims, err);
        if (!rc)
            asp__prim_hybrid_keep((asp__prim_renderer *)h->prims, replaced);
    }
    /*
     * The points' splats end at sharp creases as the primitives do (same
     * angle; asp_crease_clip_planes allows below 90 degrees), found among all
     * points, since the other face of a crease may be a kept primitive's.
     */
    float crease = d->prim.crease_angle == 0 ? ASP_PRIM_CREASE_ANGLE_DEFAULT : d->prim.crease_angle;
    float *planes = NULL;
    if (!rc && h->counts.points_drawn && points->normals && crease > 0 && crease < 90) {
        planes = asp_alloc(ctx, 8 * points->count * sizeof *planes);
        if (!planes)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the crease planes of %zu points", points->count);
        else
            rc = asp_crease_clip_planes(points, &(asp_crease_desc){.angle_deg = crease}, ctx, planes, NULL, err);
    }
    if (!rc && h->counts.points_drawn) {
        asp_cloud *c = NULL;
        float *sub_planes = NULL;
        rc = drawn_cloud(points, cover, h->counts.points_drawn, d->origin, planes, ctx, &c, &sub_planes, err);
        if (!rc) {
            asp_splat_renderer_desc sd = d->splat;
            sd.mode = ASP_SPLAT_BLEND;
            sd.clip_planes = sub_planes;
            rc = asp_splat_renderer_create(gl, c, &sd, ctx, &h->splats, err);
        }
        asp_free(ctx, sub_planes);
        asp_cloud_destroy(c);
    }
    asp_free(ctx, planes);
    asp_free(ctx, replaced);
    asp_free(ctx, cover);
    return rc;
}

int asp_hybrid_renderer_create(asp_gl_context *gl, const asp_dps_level *level, const asp_cloud *points,
                               const asp_hybrid_desc *desc, const asp_context *ctx, asp_renderer **out,
                               asp_error *err)
{
    ASP_ASSERT(gl && level && points && out);
    static const asp_hybrid_desc zero_desc;
    const asp_hybrid_desc *d = desc ? desc : &zero_desc;
    int rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    hybrid_renderer *h = asp_calloc(&gl->actx, 1, sizeof *h);
    if (!h)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the hybrid renderer");
    h->base.vt = &hybrid_vtable;
    h->base.gl = gl;
    rc = make_parts(h, level, points, d, ctx, err);
    if (!rc)
        rc = asp__gl_program_create(gl, "hybrid resolve", resolve_vertex_src, resolve_fragment_src, &h->resolve, err);
    if (!rc) {
        glCreateVertexArrays(1, &h->vao.id);
        rc = asp__gl_check(gl, "create the hybrid renderer", err);
    }
    if (rc) {
        hybrid_destroy(&h->base);
        return rc;
    }
    h->base.count = h->counts.prims_kept + h->counts.points_drawn;
    *out = &h->base;
    return 0;
}

int asp_hybrid_renderer_counts(const asp_renderer *r, asp_hybrid_counts *out, asp_error *err)
{
    if (!r || r->vt != &hybrid_vtable)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer is not a hybrid", r ? asp_renderer_name(r) : "NULL");
    *out = ((const hybrid_renderer *)r)->counts;
    return 0;
}
