/*
 * Textured triangle meshes, the polygon baseline that seed 004 (sections
 * 2.2-2.3, chapter 4) compares point-based objects with: opaque, depth-tested
 * triangles with mipmapped sRGB textures, vertex or material colours, and the
 * lighting of the point renderers (colour * (0.25 + 0.75 |n . l|), two-sided),
 * so a mesh and the discs sampled from it are comparable pixel for pixel.
 * One vertex buffer per array (STYLE.md section 6), one draw per material.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

static const char *vertex_src =
    "#version 450 core\n"
    "layout(location = 0) in vec3 a_position;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "layout(location = 3) in vec4 a_color;\n"
    "uniform mat4 u_view;\n"
    "uniform mat4 u_proj;\n"
    "uniform vec3 u_offset;\n"
    "out vec3 v_eye_pos;\n"
    "out vec3 v_normal;\n"
    "out vec2 v_uv;\n"
    "out vec4 v_color;\n"
    "void main() {\n"
    "    vec4 e = u_view * vec4(a_position + u_offset, 1.0);\n"
    "    v_eye_pos = e.xyz;\n"
    "    v_normal = mat3(u_view) * a_normal;\n"
    "    v_uv = a_uv;\n"
    "    v_color = a_color;\n"
    "    gl_Position = u_proj * e;\n"
    "}\n";

/*
 * Vertex colours are interpolated as stored (sRGB) and decoded per fragment,
 * as the sampler interpolates the bytes; the texture is decoded by the
 * GL_SRGB8_ALPHA8 format before filtering, so mipmaps average light, not
 * code values. UV v = 0 is the image bottom while the image is uploaded top
 * row first, hence 1 - v. The face normal of a flat triangle comes from the
 * screen derivatives of the eye-space position: no extra vertex data.
 */
static const char *fragment_src =
    "#version 450 core\n"
    "in vec3 v_eye_pos;\n"
    "in vec3 v_normal;\n"
    "in vec2 v_uv;\n"
    "in vec4 v_color;\n"
    "uniform int u_source;\n" // 0 material colour, 1 vertex colours, 2 texture
    "uniform vec4 u_material;\n"
    "uniform int u_flat;\n"
    "uniform vec3 u_light;\n"
    "uniform int u_unlit;\n"
    "layout(binding = 0) uniform sampler2D u_texture;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "vec3 srgb_to_linear(vec3 c) {\n"
    "    c = clamp(c, 0.0, 1.0);\n"
    "    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));\n"
    "}\n"
    "void main() {\n"
    "    vec3 c;\n"
    "    if (u_source == 2)\n"
    "        c = texture(u_texture, vec2(v_uv.x, 1.0 - v_uv.y)).rgb;\n"
    "    else if (u_source == 1)\n"
    "        c = srgb_to_linear(v_color.rgb);\n"
    "    else\n"
    "        c = srgb_to_linear(u_material.rgb);\n"
    "    vec3 n = u_flat != 0 ? cross(dFdx(v_eye_pos), dFdy(v_eye_pos)) : v_normal;\n"
    "    float lambert = dot(n, n) > 0.0 ? abs(dot(normalize(n), u_light)) : 1.0;\n"
    "    float shade = u_unlit != 0 ? 1.0 : 0.25 + 0.75 * lambert;\n"
    "    o_color = vec4(c * shade, 1.0);\n"
    "}\n";

enum { U_VIEW, U_PROJ, U_OFFSET, U_SOURCE, U_MATERIAL, U_FLAT, U_LIGHT, U_UNLIT, U_COUNT };
static const char *uniform_names[U_COUNT] = {"u_view",  "u_proj", "u_offset", "u_source",
                                             "u_material", "u_flat", "u_light", "u_unlit"};

enum { A_POSITION, A_NORMAL, A_UV, A_COLOR, A_COUNT };
enum { SOURCE_MATERIAL = 0, SOURCE_VERTEX = 1, SOURCE_TEXTURE = 2 };

/* One draw: the triangles of one material, contiguous in the index buffer. */
typedef struct mesh_part {
    size_t first, count; /* in triangles */
    int source;          /* SOURCE_* */
    float color[4];      /* sRGB, for SOURCE_MATERIAL */
    GLuint texture;      /* for SOURCE_TEXTURE */
} mesh_part;

typedef struct mesh_renderer {
    asp_renderer base; // first, so an asp_renderer * is a mesh_renderer *
    asp__gl_program program;
    asp__gl_vertex_array vao;
    asp__gl_buffer buffers[A_COUNT];
    asp__gl_buffer indices;
    GLint uniforms[U_COUNT];
    float offset[3];
    int flat;
    size_t part_count;
    mesh_part *parts;
} mesh_renderer;

static void mesh_destroy(asp_renderer *base)
{
    mesh_renderer *m = (mesh_renderer *)base;
    for (int i = 0; i < A_COUNT; i++)
        if (m->buffers[i].id)
            glDeleteBuffers(1, &m->buffers[i].id);
    if (m->indices.id)
        glDeleteBuffers(1, &m->indices.id);
    for (size_t i = 0; m->parts && i < m->part_count; i++)
        if (m->parts[i].texture)
            glDeleteTextures(1, &m->parts[i].texture);
    if (m->vao.id)
        glDeleteVertexArrays(1, &m->vao.id);
    asp__gl_program_destroy(&m->program);
    asp_context actx = base->gl->actx;
    asp_free(&actx, m->parts);
    asp_free(&actx, m);
}

static int mesh_draw(asp_renderer *base, const asp__frame *f, asp_error *err)
{
    mesh_renderer *m = (mesh_renderer *)base;
    GLuint p = m->program.id;
    const GLint *u = m->uniforms;
    glProgramUniformMatrix4fv(p, u[U_VIEW], 1, GL_FALSE, f->view);
    glProgramUniformMatrix4fv(p, u[U_PROJ], 1, GL_FALSE, f->proj);
    glProgramUniform3fv(p, u[U_OFFSET], 1, m->offset);
    glProgramUniform3fv(p, u[U_LIGHT], 1, f->light_eye);
    glProgramUniform1i(p, u[U_UNLIT], (f->flags & ASP_RENDER_UNLIT) ? 1 : 0);
    glProgramUniform1i(p, u[U_FLAT], m->flat);
    glUseProgram(p);
    glBindVertexArray(m->vao.id);
    for (size_t i = 0; i < m->part_count; i++) {
        const mesh_part *part = &m->parts[i];
        if (part->count == 0)
            continue;
        glProgramUniform1i(p, u[U_SOURCE], part->source);
        glProgramUniform4fv(p, u[U_MATERIAL], 1, part->color);
        glBindTextureUnit(0, part->source == SOURCE_TEXTURE ? part->texture : 0);
        glDrawElements(GL_TRIANGLES, (GLsizei)(3 * part->count), GL_UNSIGNED_INT,
                       (const void *)(uintptr_t)(3 * part->first * sizeof(uint32_t)));
    }
    glBindTextureUnit(0, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    return asp__gl_check(base->gl, "draw the mesh", err);
}

static const asp__renderer_vtable mesh_vtable = {.name = "mesh", .draw = mesh_draw, .destroy = mesh_destroy};

static void upload(mesh_renderer *m, int attr, const void *data, size_t bytes, GLint comps, GLenum type,
                   GLboolean normalized, GLsizei stride)
{
    asp__gl_attrib_buffer(m->vao, (GLuint)attr, &m->buffers[attr], data, bytes, comps, type, normalized, stride, 0);
}

static int check_input(const asp_render_mesh *mesh, asp_error *err)
{
    if (mesh->triangle_count == 0 || mesh->vertex_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot render a mesh without triangles");
    // glDrawElements counts indices in a signed 32-bit GLsizei
    if (mesh->triangle_count > (size_t)INT32_MAX / 3 || mesh->vertex_count > (size_t)UINT32_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot draw %zu triangles in one call (at most %d)",
                             mesh->triangle_count, INT32_MAX / 3);
    for (size_t i = 0; i < 3 * mesh->vertex_count; i++)
        if (!isfinite(mesh->positions[i]))
            return asp_error_set(err, ASP_EFORMAT, "mesh vertex %zu: position is not finite", i / 3);
    for (size_t i = 0; i < 3 * mesh->triangle_count; i++)
        if (mesh->triangles[i] >= mesh->vertex_count)
            return asp_error_set(err, ASP_EFORMAT, "mesh triangle %zu: vertex index %u out of range (%zu vertices)",
                                 i / 3, mesh->triangles[i], mesh->vertex_count);
    if (mesh->material_ids)
        for (size_t t = 0; t < mesh->triangle_count; t++)
            if (mesh->material_ids[t] >= (mesh->material_count ? mesh->material_count : 1))
                return asp_error_set(err, ASP_EFORMAT, "mesh triangle %zu: material %u out of range (%zu materials)",
                                     t, mesh->material_ids[t], mesh->material_count);
    for (size_t i = 0; i < mesh->material_count; i++) {
        const asp_image *tex = mesh->materials[i].texture;
        if (tex && tex->pixels && (tex->width == 0 || tex->height == 0))
            return asp_error_set(err, ASP_EFORMAT, "mesh material %zu: empty texture", i);
    }
    return 0;
}

/* Mip levels of a full chain down to 1 x 1. */
static GLsizei mip_levels(uint32_t w, uint32_t h)
{
    uint32_t s = w > h ? w : h;
    GLsizei n = 1;
    while (s > 1) {
        s >>= 1;
        n++;
    }
    return n;
}

static int upload_texture(const asp_image *tex, size_t material, GLuint *out, asp_error *err)
{
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (tex->width > (uint32_t)max_size || tex->height > (uint32_t)max_size)
        return asp_error_set(err, ASP_EUNSUPPORTED, "mesh material %zu: texture %ux%u is larger than %d, the limit "
                             "of this GL context", material, tex->width, tex->height, max_size);
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    *out = t;
    glTextureStorage2D(t, mip_levels(tex->width, tex->height), GL_SRGB8_ALPHA8, (GLsizei)tex->width,
                       (GLsizei)tex->height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(t, 0, 0, 0, (GLsizei)tex->width, (GLsizei)tex->height, GL_RGBA, GL_UNSIGNED_BYTE,
                        tex->pixels);
    // sRGB textures are averaged in linear light by the driver (GL 4.5 section 8.14.4)
    glGenerateTextureMipmap(t);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    // OBJ UVs outside 0..1 repeat the image, as the sampler's asp_image_sample_bilinear does
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_REPEAT);
    return 0;
}

/* The triangles grouped by material (a counting sort, stable), and one part per material. */
static int build_parts(mesh_renderer *m, const asp_render_mesh *mesh, uint32_t *sorted, asp_error *err)
{
    size_t nm = mesh->material_count ? mesh->material_count : 1;
    m->parts = asp_calloc(&m->base.gl->actx, nm, sizeof *m->parts);
    if (!m->parts)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu mesh materials", nm);
    m->part_count = nm;
    for (size_t t = 0; t < mesh->triangle_count; t++)
        m->parts[mesh->material_ids ? mesh->material_ids[t] : 0].count++;
    size_t first = 0;
    for (size_t i = 0; i < nm; i++) {
        m->parts[i].first = first;
        first += m->parts[i].count;
        m->parts[i].count = 0;
    }
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        mesh_part *part = &m->parts[mesh->material_ids ? mesh->material_ids[t] : 0];
        memcpy(sorted + 3 * (part->first + part->count), mesh->triangles + 3 * t, 3 * sizeof(uint32_t));
        part->count++;
    }
    for (size_t i = 0; i < nm; i++) {
        mesh_part *part = &m->parts[i];
        const asp_render_material *mat = mesh->material_count ? &mesh->materials[i] : NULL;
        for (int c = 0; c < 4; c++)
            part->color[c] = mat ? mat->color[c] : (c < 3 ? 200.0f / 255.0f : 1.0f);
        // the sampler's rule (asp__surface_point): texture, else vertex colours, else the material colour
        if (mat && mat->texture && mat->texture->pixels && mesh->uvs && part->count) {
            part->source = SOURCE_TEXTURE;
            int rc = upload_texture(mat->texture, i, &part->texture, err);
            if (rc)
                return rc;
        } else if (mesh->colors) {
            part->source = SOURCE_VERTEX;
        } else {
            part->source = SOURCE_MATERIAL;
        }
    }
    return 0;
}

int asp_mesh_renderer_create(asp_gl_context *gl, const asp_render_mesh *mesh, const asp_mesh_renderer_desc *desc,
                             asp_renderer **out, asp_error *err)
{
    ASP_ASSERT(gl && mesh && out);
    ASP_ASSERT(mesh->positions && mesh->triangles && (mesh->materials || mesh->material_count == 0));
    static const asp_mesh_renderer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = check_input(mesh, err);
    if (rc)
        return rc;
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    mesh_renderer *m = asp_calloc(&gl->actx, 1, sizeof *m);
    if (!m)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a mesh renderer");
    m->base.vt = &mesh_vtable;
    m->base.gl = gl;
    m->base.count = mesh->triangle_count;
    // the difference of two world points in double, then float: vertices near the frame stay exact
    for (int k = 0; k < 3; k++)
        m->offset[k] = (float)(mesh->origin[k] - desc->origin[k]);
    m->flat = (desc->flags & ASP_MESH_RENDER_FLAT) || !mesh->normals;
    uint32_t *sorted = asp_alloc(&gl->actx, 3 * mesh->triangle_count * sizeof(uint32_t));
    if (!sorted) {
        mesh_destroy(&m->base);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the indices of %zu triangles",
                             mesh->triangle_count);
    }
    rc = asp__gl_program_create(gl, "mesh", vertex_src, fragment_src, &m->program, err);
    if (!rc) {
        for (int i = 0; i < U_COUNT; i++)
            m->uniforms[i] = glGetUniformLocation(m->program.id, uniform_names[i]);
        glCreateVertexArrays(1, &m->vao.id);
        rc = build_parts(m, mesh, sorted, err);
    }
    if (rc) {
        asp_free(&gl->actx, sorted);
        mesh_destroy(&m->base);
        return rc;
    }
    size_t n = mesh->vertex_count;
    upload(m, A_POSITION, mesh->positions, 3 * n * sizeof(float), 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    if (mesh->normals)
        upload(m, A_NORMAL, mesh->normals, 3 * n * sizeof(float), 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    if (mesh->uvs)
        upload(m, A_UV, mesh->uvs, 2 * n * sizeof(float), 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float));
    if (mesh->colors)
        upload(m, A_COLOR, mesh->colors, 4 * n, 4, GL_UNSIGNED_BYTE, GL_TRUE, 4);
    glCreateBuffers(1, &m->indices.id);
    glNamedBufferStorage(m->indices.id, (GLsizeiptr)(3 * mesh->triangle_count * sizeof(uint32_t)), sorted, 0);
    glVertexArrayElementBuffer(m->vao.id, m->indices.id);
    asp_free(&gl->actx, sorted);
    char what[96];
    snprintf(what, sizeof what, "upload a mesh of %zu triangles", mesh->triangle_count);
    rc = asp__gl_check(gl, what, err);
    if (rc) {
        mesh_destroy(&m->base);
        return rc;
    }
    *out = &m->base;
    return 0;
}
