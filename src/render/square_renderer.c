/*
 * Fixed-size square points (Schwarz 2004, seed 004 section 3.2.6: the
 * "rectangular point-representations used by graphics hardware", traded for
 * speed): each splat of the hierarchy cut is one GL point, sized by its
 * projected extent (3.2.3) or a fixed number of pixels, opaque and depth-tested.
 */
#include <math.h>
#include <string.h>

#include "render/edl_internal.h"
#include "render/splat_internal.h"
#include "util/banned.h"

/*
 * The projected size is 2 a (the ellipse's major diameter) in pixels at the
 * splat centre's depth: proj[1][1] * height / 2 pixels per unit at w = 1, so
 * the square contains the ellipse (seed 004 3.2.3 uses the node cube's half
 * diagonal for the same purpose). Dividing by clip w serves perspective and
 * orthographic projections alike.
 */
static const char *vertex_src =
    "#version 450 core\n" ASP__LOD_GLSL
    "uniform float u_px_per_unit;\n"
    "uniform float u_point_size;\n"
    "uniform float u_max_size;\n"
    "uniform float u_radius_scale;\n"
    "uniform int u_has_colors;\n"
    "uniform vec4 u_default_color;\n"
    "uniform int u_unlit;\n"
    "flat out vec3 v_color;\n"
    "void main() {\n"
    "    splat s = read_splat(ids[gl_VertexID]);\n"
    "    gl_Position = u_proj * (u_view * vec4(s.c, 1.0));\n"
    "    float size = u_point_size > 0.0 ? u_point_size\n"
    "                                    : 2.0 * s.a * u_radius_scale * u_px_per_unit / max(gl_Position.w, 1e-20);\n"
    "    gl_PointSize = clamp(size, 1.0, u_max_size);\n"
    "    vec4 col = u_has_colors != 0 ? unpackUnorm4x8(s.color) : u_default_color;\n"
    "    float lambert = abs(dot(normalize(mat3(u_view) * s.n), u_light));\n"
    "    v_color = srgb_to_linear(col.rgb) * (u_unlit != 0 ? 1.0 : 0.25 + 0.75 * lambert);\n"
    "}\n";

static const char *fragment_src =
    "#version 450 core\n"
    "flat in vec3 v_color;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "    o_color = vec4(v_color, 1.0);\n"
    "}\n";

enum { U_PX_PER_UNIT = ASP__LOD_U_COUNT, U_POINT_SIZE, U_MAX_SIZE, U_RADIUS_SCALE, U_HAS_COLORS, U_DEFAULT_COLOR,
       U_UNLIT, U_COUNT };
static const char *uniform_names[U_COUNT] = {ASP__LOD_UNIFORM_NAMES, "u_px_per_unit", "u_point_size", "u_max_size",
                                             "u_radius_scale", "u_has_colors", "u_default_color", "u_unlit"};

typedef struct square_renderer {
    asp_renderer base; // first two members as asp__lod_renderer
    asp__lod lod;
    asp__gl_program program;
    GLint uniforms[U_COUNT];
    asp__gl_vertex_array vao; // no attributes: the vertex shader reads the storage buffers
    float point_size, radius_scale, max_size;
    asp__edl edl; /* eye-dome lighting around the draw when on */
} square_renderer;

static void square_destroy(asp_renderer *base)
{
    square_renderer *q = (square_renderer *)base;
    asp__gl_program_destroy(&q->program);
    asp__edl_release(&q->edl);
    if (q->vao.id)
        glDeleteVertexArrays(1, &q->vao.id);
    asp__lod_renderer_free((asp__lod_renderer *)q);
}

static int square_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    square_renderer *q = (square_renderer *)base;
    int rc = asp__lod_select((asp__lod_renderer *)q, f, err);
    if (rc || q->lod.count == 0)
        return rc;
    GLuint p = q->program.id;
    const GLint *u = q->uniforms;
    asp__lod_frame_uniforms(p, u, f);
    glProgramUniform1f(p, u[U_PX_PER_UNIT], f->proj[5] * 0.5f * (float)f->height);
    glProgramUniform1i(p, u[U_UNLIT], (f->flags & ASP_RENDER_UNLIT) ? 1 : 0);
    if (asp__edl_on(&q->edl) && (rc = asp__edl_begin(&q->edl, base->gl, f, err)) != 0)
        return rc;
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(p);
    glBindVertexArray(q->vao.id);
    glDrawArrays(GL_POINTS, 0, (GLsizei)q->lod.count);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_PROGRAM_POINT_SIZE);
    if (asp__edl_on(&q->edl))
        return asp__edl_end(&q->edl, base->gl, f, err);
    return asp__gl_check(base->gl, "draw squares", err);
}

static const asp__renderer_vtable square_vtable = {.name = "square",
                                                  .draw = square_draw,
                                                  .destroy = square_destroy,
                                                  .set_lod = asp__lod_set_lod,
                                                  .stats = asp__lod_stats,
                                                  .set_budget = asp__lod_set_budget};

static int check_desc(const asp_square_renderer_desc *d, asp_error *err)
{
    int rc = asp__lod_check_option("square", "point_size", d->point_size, err);
    if (!rc)
        rc = asp__lod_check_option("square", "tolerance", d->tolerance, err);
    if (!rc)
        rc = asp__lod_check_option("square", "radius_scale", d->radius_scale, err);
    if (!rc)
        rc = asp__edl_check(&d->edl, err);
    return rc;
}

static int create(asp_gl_context *gl, const asp_cloud *cloud, const asp_hier *hier, const asp_context *ctx,
                  const asp_square_renderer_desc *desc, asp_renderer **out, asp_error *err)
{
    static const asp_square_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = check_desc(desc, err);
    if (rc)
        return rc;
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    GLfloat range[2] = {1, 1};
    glGetFloatv(GL_POINT_SIZE_RANGE, range);
    if (desc->point_size > range[1])
        return asp_error_set(err, ASP_EINVAL, "square size %g pixels exceeds this GL context's limit of %g",
                             (double)desc->point_size, (double)range[1]);
    asp__lod_renderer *lr;
    rc = asp__lod_renderer_create(gl, sizeof(square_renderer), &square_vtable, cloud, hier, ASP__LOD_DESC(desc, ctx),
                                  &lr, err);
    if (rc)
        return rc;
    square_renderer *q = (square_renderer *)lr;
    q->point_size = desc->point_size;
    q->radius_scale = desc->radius_scale > 0 ? desc->radius_scale : 1.0f;
    q->max_size = range[1];

    rc = asp__gl_program_create(gl, "square", vertex_src, fragment_src, &q->program, err);
    if (!rc)
        rc = asp__edl_init(&q->edl, gl, &desc->edl, err);
    if (!rc)
        rc = asp__lod_upload(gl, &q->lod, "square", err);
    if (rc) {
        square_destroy(&q->base);
        return rc;
    }
    for (int i = 0; i < U_COUNT; i++)
        q->uniforms[i] = glGetUniformLocation(q->program.id, uniform_names[i]);
    glCreateVertexArrays(1, &q->vao.id);
    GLuint p = q->program.id;
    glProgramUniform1f(p, q->uniforms[U_POINT_SIZE], q->point_size);
    glProgramUniform1f(p, q->uniforms[U_MAX_SIZE], q->max_size);
    glProgramUniform1f(p, q->uniforms[U_RADIUS_SCALE], q->radius_scale);
    glProgramUniform1i(p, q->uniforms[U_HAS_COLORS], q->lod.has_colors);
    glProgramUniform4fv(p, q->uniforms[U_DEFAULT_COLOR], 1, q->lod.default_color);
    return asp__lod_renderer_finish(lr, out, err);
}

int asp_square_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_square_renderer_desc *desc,
                              const asp_context *ctx,                                asp_renderer **out, asp_error *err)
{
    return create(gl, cloud, NULL, ctx, desc, out, err);
}

int asp_square_renderer_create_hier(asp_gl_context *gl, const asp_hier *hier, const asp_square_renderer_desc *desc,
                                    asp_renderer **out, asp_error *err)
{
    return create(gl, NULL, hier, NULL, desc, out, err);
}
