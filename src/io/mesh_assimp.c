/*
 * Mesh input through assimp's C API: every format assimp reads (OBJ+MTL, PLY,
 * OFF, STL, glTF/GLB, 3DS ...) becomes one merged triangle mesh with the node
 * transforms applied, per-vertex UVs/colours and per-triangle materials with
 * their diffuse textures, the "polygon-based object" Schwarz 2004 3.1 samples.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stb/stb_image.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "io/mesh_precheck.h"
#include "io/ply_internal.h"
#include "util/atomic_file.h"
#include "util/child_process.h"
#include "util/regular_file.h"
#include "util/banned.h"

enum { MAX_NODE_DEPTH = 256 };

/* Accumulates counts (fill == 0) or writes vertices and triangles (fill == 1) while walking the node tree. */
struct walk {
    const struct aiScene *scene;
    const char *path;
    int fill;
    size_t nv, nt;        /* running totals */
    asp_mesh *mesh;       /* fill: destination (triangles, uvs, colours, material ids) */
    double *world;        /* fill: 3 * nv world positions */
    float *file_normals;  /* fill: 3 * nv transformed file normals, or NULL */
    asp_error *err;
};

typedef struct { double m[4][4]; } mat4;

static mat4 mat4_from_ai(const struct aiMatrix4x4 *a)
{
    mat4 r = {{{a->a1, a->a2, a->a3, a->a4}, {a->b1, a->b2, a->b3, a->b4},
               {a->c1, a->c2, a->c3, a->c4}, {a->d1, a->d2, a->d3, a->d4}}};
    return r;
}

static mat4 mat4_mul(const mat4 *a, const mat4 *b)
{
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j] +
                        a->m[i][3] * b->m[3][j];
    return r;
}

/* Cofactor matrix of the upper 3x3: proportional to the inverse transpose, which carries normals. */
static void normal_matrix(const mat4 *t, double n[3][3], double *det)
{
    const double(*m)[4] = t->m;
    n[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    n[0][1] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    n[0][2] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    n[1][0] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
    n[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
    n[1][2] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
    n[2][0] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
    n[2][1] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
    n[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    *det = m[0][0] * n[0][0] + m[0][1] * n[0][1] + m[0][2] * n[0][2];
}

/* Bounded copy that always terminates; truncation of a name or path in a message is acceptable. */
static void copy_str(char *dst, size_t cap, const char *src)
{
    size_t len = strlen(src);
    if (len >= cap)
        len = cap - 1;
    memcpy(dst, src, len);
    dst[len] = '\0';
}

static uint8_t unit_to_u8(float x)
{
    if (!(x > 0.0f))
        return 0;
    if (x >= 1.0f)
        return 255;
    return (uint8_t)lrintf(x * 255.0f);
}

static size_t mesh_triangles(const struct aiMesh *am)
{
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
        return 0;
    size_t n = 0;
    for (unsigned f = 0; f < am->mNumFaces; f++)
        n += am->mFaces[f].mNumIndices == 3;
    return n;
}

static int fill_mesh(struct walk *w, const struct aiMesh *am, unsigned mesh_index, const mat4 *t)
{
    asp_mesh *m = w->mesh;
    size_t base = w->nv;
    double nm[3][3], det;
    normal_matrix(t, nm, &det);
    for (unsigned v = 0; v < am->mNumVertices; v++) {
        const struct aiVector3D *p = &am->mVertices[v];
        double *o = w->world + 3 * (base + v);
        for (int r = 0; r < 3; r++)
            o[r] = t->m[r][0] * p->x + t->m[r][1] * p->y + t->m[r][2] * p->z + t->m[r][3];
        if (!isfinite(o[0]) || !isfinite(o[1]) || !isfinite(o[2]))
            return asp_error_set(w->err, ASP_EFORMAT, "cannot read '%s': mesh %u vertex %u has a non-finite coordinate",
                                 w->path, mesh_index, v);
        if (w->file_normals) {
            const struct aiVector3D *n = &am->mNormals[v];
            float *d = w->file_normals + 3 * (base + v);
            for (int r = 0; r < 3; r++)
                d[r] = (float)(nm[r][0] * n->x + nm[r][1] * n->y + nm[r][2] * n->z);
        }
        if (m->uvs) {
            const struct aiVector3D *uv = am->mTextureCoords[0] ? &am->mTextureCoords[0][v] : NULL;
            m->uvs[2 * (base + v)] = uv ? uv->x : 0.0f;
            m->uvs[2 * (base + v) + 1] = uv ? uv->y : 0.0f;
        }
        if (m->colors) {
            uint8_t *c = m->colors + 4 * (base + v);
            if (am->mColors[0]) {
                const struct aiColor4D *s = &am->mColors[0][v];
                c[0] = unit_to_u8(s->r), c[1] = unit_to_u8(s->g), c[2] = unit_to_u8(s->b), c[3] = unit_to_u8(s->a);
            } else {
                /* meshes without vertex colours show their material colour (filled in after materials load) */
                c[0] = c[1] = c[2] = c[3] = 0;
            }
        }
    }
    /* a mirroring transform flips the winding; swap to keep triangles counter-clockwise from outside */
    int flip = det < 0.0;
    for (unsigned f = 0; f < am->mNumFaces; f++) {
        const struct aiFace *face = &am->mFaces[f];
        if (face->mNumIndices != 3)
            continue;
        uint32_t *tri = m->triangles + 3 * w->nt;
        for (int k = 0; k < 3; k++) {
            unsigned idx = face->mIndices[flip && k ? 3 - k : k];
            if (idx >= am->mNumVertices)
                return asp_error_set(w->err, ASP_EFORMAT, "cannot read '%s': mesh %u face %u uses vertex %u of %u",
                                     w->path, mesh_index, f, idx, am->mNumVertices);
            tri[k] = (uint32_t)(base + idx);
        }
        m->material_ids[w->nt] = am->mMaterialIndex < m->material_count ? am->mMaterialIndex : 0;
        w->nt++;
    }
    return 0;
}

static int walk_node(struct walk *w, const struct aiNode *node, const mat4 *parent, int depth)
{
    if (depth > MAX_NODE_DEPTH)
        return asp_error_set(w->err, ASP_EFORMAT, "cannot read '%s': node hierarchy deeper than %d", w->path,
                             MAX_NODE_DEPTH);
    mat4 local = mat4_from_ai(&node->mTransformation);
    mat4 t = mat4_mul(parent, &local);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        unsigned mi = node->mMeshes[i];
        if (mi >= w->scene->mNumMeshes)
            return asp_error_set(w->err, ASP_EFORMAT, "cannot read '%s': node '%s' names mesh %u of %u", w->path,
                                 node->mName.data, mi, w->scene->mNumMeshes);
        const struct aiMesh *am = w->scene->mMeshes[mi];
        size_t nt = mesh_triangles(am);
        if (nt == 0)
            continue;
        if (w->fill) {
            int rc = fill_mesh(w, am, mi, &t);
            if (rc)
                return rc;
        } else {
            w->nt += nt;
        }
        w->nv += am->mNumVertices;
        if (w->nv >= UINT32_MAX || w->nt >= UINT32_MAX)
            return asp_error_set(w->err, ASP_EUNSUPPORTED, "cannot read '%s': more than 2^32-1 vertices or triangles",
                                 w->path);
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) {
        int rc = walk_node(w, node->mChildren[c], &t, depth + 1);
        if (rc)
            return rc;
    }
    return 0;
}

/* Which meshes the walk reaches, to decide which optional arrays the merged mesh needs. */
static void scan_attrs(const struct aiScene *s, const struct aiNode *node, int depth, int *uvs, int *colors,
                       int *all_normals, unsigned *uv_sets)
{
    if (depth > MAX_NODE_DEPTH)
        return;
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= s->mNumMeshes)
            continue;
        const struct aiMesh *am = s->mMeshes[node->mMeshes[i]];
        if (mesh_triangles(am) == 0)
            continue;
        *uvs |= am->mTextureCoords[0] != NULL;
        *colors |= am->mColors[0] != NULL;
        *all_normals &= am->mNormals != NULL;
        unsigned sets = 0;
        for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; k++)
            sets += am->mTextureCoords[k] != NULL;
        *uv_sets = sets > *uv_sets ? sets : *uv_sets;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        scan_attrs(s, node->mChildren[c], depth + 1, uvs, colors, all_normals, uv_sets);
}

static int image_from_rgba(asp_image *img, const uint8_t *rgba, uint32_t w, uint32_t h, asp_error *err)
{
    int rc = asp_image_init(img, w, h, err);
    if (rc)
        return rc;
    memcpy(img->pixels, rgba, (size_t)w * h * 4);
    return 0;
}

static int load_embedded(const struct aiScene *scene, const char *ref, const char *path, const char *material,
                         asp_image *img, asp_error *err)
{
    const struct aiTexture *tex = NULL;
    if (ref[0] == '*') {
        char *end;
        long i = strtol(ref + 1, &end, 10);
        if (*end == '\0' && i >= 0 && (unsigned long)i < scene->mNumTextures)
            tex = scene->mTextures[i];
    } else {
        for (unsigned i = 0; i < scene->mNumTextures; i++)
            if (strcmp(scene->mTextures[i]->mFilename.data, ref) == 0)
                tex = scene->mTextures[i];
    }
    if (!tex)
        return ASP_EIO; /* not embedded: caller looks for a file */
    if (tex->mHeight == 0) {
        int w, h, comp;
        if (tex->mWidth > INT32_MAX)
            return asp_error_set(err, ASP_EFORMAT, "cannot decode embedded texture '%s' of material '%s' in '%s'", ref,
                                 material, path);
        stbi_uc *data = stbi_load_from_memory((const stbi_uc *)tex->pcData, (int)tex->mWidth, &w, &h, &comp, 4);
        if (!data)
            return asp_error_set(err, ASP_EFORMAT, "cannot decode embedded texture '%s' of material '%s' in '%s': %s",
                                 ref, material, path, stbi_failure_reason());
        int rc = image_from_rgba(img, data, (uint32_t)w, (uint32_t)h, err);
        stbi_image_free(data);
        return rc;
    }
    if ((uint64_t)tex->mWidth * tex->mHeight > (uint64_t)16384 * 16384)
        return asp_error_set(err, ASP_EFORMAT, "embedded texture '%s' of material '%s' in '%s' is %ux%u", ref, material,
                             path, tex->mWidth, tex->mHeight);
    int rc = asp_image_init(img, tex->mWidth, tex->mHeight, err);
    if (rc)
        return rc;
    /* aiTexel is stored b, g, r, a */
    for (size_t i = 0; i < (size_t)tex->mWidth * tex->mHeight; i++) {
        img->pixels[4 * i + 0] = tex->pcData[i].r;
        img->pixels[4 * i + 1] = tex->pcData[i].g;
        img->pixels[4 * i + 2] = tex->pcData[i].b;
        img->pixels[4 * i + 3] = tex->pcData[i].a;
    }
    return 0;
}

/*
 * Whether something exists at p: a FIFO or directory named by map_Kd counts,
 * so asp_image_load then refuses it by name instead of "No such file".
 */
static int readable(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

/* Texture references are relative to the model file; exporters often write Windows separators or stale folders. */
static int resolve_texture(const char *model, const char *ref, char *out, size_t cap)
{
    char clean[1024];
    copy_str(clean, sizeof clean, ref);
    for (char *c = clean; *c; c++)
        if (*c == '\\')
            *c = '/';
    const char *slash = strrchr(model, '/');
    int dir_len = slash ? (int)(slash - model) : 0;
    if (clean[0] == '/')
        copy_str(out, cap, clean);
    else if (slash)
        snprintf(out, cap, "%.*s/%s", dir_len, model, clean);
    else
        copy_str(out, cap, clean);
    if (readable(out))
        return 1;
    const char *base = strrchr(clean, '/');
    if (base) {
        char alt[1024];
        if (slash)
            snprintf(alt, sizeof alt, "%.*s/%s", dir_len, model, base + 1);
        else
            copy_str(alt, sizeof alt, base + 1);
        if (readable(alt)) {
            copy_str(out, cap, alt);
            return 1;
        }
    }
    return 0;
}

static int load_override(const char *override, const char *material, asp_material *mat, asp_error *err)
{
    asp_error e = {0};
    int rc = asp_image_load(&mat->texture, override, &e);
    if (rc)
        return asp_error_set(err, rc, "%s (texture for material '%s')", e.msg, material);
    asp__atomic_protect(override, "a texture");
    copy_str(mat->texture_path, sizeof mat->texture_path, override);
    return 0;
}

/* A material's texture reference that the reader process leaves to the parent: a file to look for. */
typedef struct texture_ref {
    char ref[1024];
} texture_ref;

/*
 * The reader process's part of the materials: names, colours and embedded
 * textures (their bytes came from the model file itself); a reference to a
 * texture file goes to refs[i] for the parent (finish_materials), which opens
 * and decodes image files with the reader contained no longer involved.
 */
static int read_materials(const struct aiScene *scene, const char *path, asp_mesh *m, texture_ref *refs,
                          asp_error *err)
{
    for (size_t i = 0; i < m->material_count; i++) {
        asp_material *mat = &m->materials[i];
        const struct aiMaterial *am = scene->mMaterials[i];
        struct aiString s;
        if (aiGetMaterialString(am, AI_MATKEY_NAME, &s) == aiReturn_SUCCESS)
            copy_str(mat->name, sizeof mat->name, s.data);
        else
            snprintf(mat->name, sizeof mat->name, "material %zu", i);
        struct aiColor4D c;
        if (aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &c) == aiReturn_SUCCESS) {
            mat->diffuse[0] = c.r, mat->diffuse[1] = c.g, mat->diffuse[2] = c.b, mat->diffuse[3] = c.a;
            mat->has_color = strcmp(mat->name, AI_DEFAULT_MATERIAL_NAME) != 0;
        } else {
            mat->diffuse[0] = mat->diffuse[1] = mat->diffuse[2] = 0.6f, mat->diffuse[3] = 1.0f;
        }
        enum aiTextureType type = aiTextureType_DIFFUSE;
        if (aiGetMaterialTextureCount(am, type) == 0)
            type = aiTextureType_BASE_COLOR;
        if (aiGetMaterialTextureCount(am, type) > 0 &&
            aiGetMaterialTexture(am, type, 0, &s, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS &&
            s.length > 0) {
            int rc = load_embedded(scene, s.data, path, mat->name, &mat->texture, err);
            if (rc == 0) {
                copy_str(mat->texture_path, sizeof mat->texture_path, s.data);
                continue;
            }
            if (rc != ASP_EIO)
                return rc;
            copy_str(refs[i].ref, sizeof refs[i].ref, s.data);
        }
    }
    return 0;
}

/* The parent's part: texture files named by the materials, the override, the missing ones (mesh.h). */
static int finish_materials(const char *path, const asp_mesh_load_desc *desc, asp_mesh *m, const texture_ref *refs,
                            asp_error *err)
{
    for (size_t i = 0; i < m->material_count; i++) {
        asp_material *mat = &m->materials[i];
        if (mat->texture.pixels)
            continue; // embedded
        if (refs[i].ref[0]) {
            char file[1024];
            if (resolve_texture(path, refs[i].ref, file, sizeof file)) {
                asp_error e = {0};
                int rc = asp_image_load(&mat->texture, file, &e);
                if (rc)
                    return asp_error_set(err, rc, "%s (texture of material '%s')", e.msg, mat->name);
                char role[40];
                snprintf(role, sizeof role, "the texture of material '%.12s'", mat->name);
                asp__atomic_protect(file, role);
                copy_str(mat->texture_path, sizeof mat->texture_path, file);
                continue;
            }
            if (!desc->texture_override && desc->allow_missing_textures) {
                mat->texture_missing = 1;
                copy_str(mat->texture_path, sizeof mat->texture_path, file);
                continue;
            }
            if (!desc->texture_override)
                return asp_error_set(err, ASP_EIO,
                                     "cannot open texture '%s' of material '%s' in '%s': No such file; "
                                     "pass --texture FILE to use another image",
                                     file, mat->name, path);
        }
        if (desc->texture_override) {
            int rc = load_override(desc->texture_override, mat->name, mat, err);
            if (rc)
                return rc;
        }
    }
    return 0;
}

/* Vertices without their own colour take their triangle's material colour, so every vertex colour is meaningful. */
static void fill_material_colors(asp_mesh *m)
{
    for (size_t t = 0; t < m->triangle_count; t++) {
        const float *d = m->materials[m->material_ids[t]].diffuse;
        for (int k = 0; k < 3; k++) {
            uint8_t *c = m->colors + 4 * (size_t)m->triangles[3 * t + k];
            if (c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 0)
                c[0] = unit_to_u8(d[0]), c[1] = unit_to_u8(d[1]), c[2] = unit_to_u8(d[2]), c[3] = 255;
        }
    }
}

/*
 * The reader process's mesh: the scene's triangles merged with the node
 * transforms applied, materials (read_materials) and the file's normals when
 * every mesh has them (*file_normals = 1; else the parent computes them).
 */
static int build(const struct aiScene *scene, const char *path, const asp_mesh_load_desc *desc, const mat4 *start,
                 const asp_context *ctx, asp_mesh **out, texture_ref **refs_out, int *file_normals, asp_error *err)
{
    if (!scene->mRootNode)
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' has no triangles", path);
    struct walk w = {.scene = scene, .path = path, .err = err};
    int rc = walk_node(&w, scene->mRootNode, start, 0);
    if (rc)
        return rc;
    if (w.nt == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' has no triangles", path);
    int has_uvs = 0, has_colors = 0, all_normals = 1;
    unsigned uv_sets = 0;
    scan_attrs(scene, scene->mRootNode, 0, &has_uvs, &has_colors, &all_normals, &uv_sets);
    if (desc->texture_override && !has_uvs)
        return asp_error_set(err, ASP_EINVAL, "'%s' has no texture coordinates, so texture '%s' cannot be applied",
                             path, desc->texture_override);
    asp_mesh *m = NULL;
    rc = asp_mesh_create(w.nv, w.nt, (has_uvs ? ASP_MESH_UVS : 0) | (has_colors ? ASP_MESH_COLORS : 0), ctx, &m, err);
    if (rc)
        return rc;
    if (scene->mNumMaterials > 0) {
        asp_material *mats = asp_calloc(ctx, scene->mNumMaterials, sizeof *mats);
        if (!mats) {
            asp_mesh_destroy(m);
            return asp_error_set(err, ASP_ENOMEM, "out of memory for %u materials", scene->mNumMaterials);
        }
        asp_free(ctx, m->materials);
        m->materials = mats;
        m->material_count = scene->mNumMaterials;
    }
    m->uv_set_count = uv_sets;
    int use_file_normals = all_normals && !desc->ignore_file_normals;
    w.fill = 1;
    w.nv = w.nt = 0;
    w.mesh = m;
    w.world = asp_alloc(ctx, 3 * m->vertex_count * sizeof(double) + 1);
    w.file_normals = use_file_normals ? m->normals : NULL;
    texture_ref *refs = asp_calloc(ctx, m->material_count, sizeof *refs);
    if (!w.world || !refs) {
        asp_free(ctx, w.world);
        asp_free(ctx, refs);
        asp_mesh_destroy(m);
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", path);
    }
    rc = walk_node(&w, scene->mRootNode, start, 0);
    if (rc == 0)
        rc = read_materials(scene, path, m, refs, err);
    if (rc) {
        asp_free(ctx, w.world);
        asp_free(ctx, refs);
        asp_mesh_destroy(m);
        return rc;
    }
    /* positions become floats around the bounding-box centre: float keeps ~7 digits of the extent, not of UTM offsets */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int c = 0; c < 3; c++)
            lo[c] = fmin(lo[c], w.world[3 * v + c]), hi[c] = fmax(hi[c], w.world[3 * v + c]);
    for (int c = 0; c < 3; c++)
        m->origin[c] = 0.5 * (lo[c] + hi[c]);
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int c = 0; c < 3; c++)
            m->positions[3 * v + c] = (float)(w.world[3 * v + c] - m->origin[c]);
    asp_free(ctx, w.world);
    if (m->colors)
        fill_material_colors(m);
    *out = m;
    *refs_out = refs;
    *file_normals = use_file_normals;
    return 0;
}

/*
 * The parent's end of the load: texture files, normals (the file's,
 * normalised, when every one is usable; else area-weighted) and the checks
 * of asp_mesh_validate, which also guard against a reader process that sent
 * indices or values out of range.
 */
static int finish(asp_mesh *m, const char *path, const asp_mesh_load_desc *desc, const texture_ref *refs,
                  int use_file_normals, asp_error *err)
{
    int rc = finish_materials(path, desc, m, refs, err);
    if (rc)
        return rc;
    int need_normals = !use_file_normals;
    for (size_t v = 0; use_file_normals && v < m->vertex_count; v++) {
        float *n = m->normals + 3 * v;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (!(len > 0.0) || !isfinite(len)) {
            need_normals = 1; /* one broken file normal: trust none of them */
            break;
        }
        for (int c = 0; c < 3; c++)
            n[c] = (float)(n[c] / len);
    }
    if (need_normals)
        rc = asp_mesh_compute_normals(m, err);
    if (rc == 0)
        rc = asp_mesh_validate(m, path, err);
    return rc;
}

/*
 * The proper rotation that turns the file axis `up` to +y (x stays x where it
 * can, so a z-up model keeps its left and right): z-up (x,y,z) -> (x,z,-y).
 */
static mat4 up_rotation(asp_up_axis up)
{
    static const double r[6][3][3] = {
        [ASP_UP_Y] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
        [ASP_UP_Z] = {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
        [ASP_UP_X] = {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        [ASP_UP_NEG_Y] = {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
        [ASP_UP_NEG_Z] = {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},
        [ASP_UP_NEG_X] = {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}},
    };
    unsigned u = (unsigned)up < 6 ? (unsigned)up : 0;
    mat4 m = {{{0}}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m.m[i][j] = r[u][i][j];
    m.m[3][3] = 1;
    return m;
}

static const char *axis_name(asp_up_axis up)
{
    static const char *const names[] = {"y", "z", "x", "-y", "-z", "-x"};
    return (unsigned)up < 6 ? names[up] : "y";
}

/*
 * The turn from assimp's scene to y-up and the rule behind it (mesh.h,
 * asp_mesh_load_desc.up). assimp's 3DS importer multiplies the root by
 * (x,y,z) -> (x,z,-y), taking 3ds Max's z-up for granted; turning the scene
 * as if its -z were up brings back the file's own coordinates.
 */
static mat4 start_transform(const char *format, asp_up_axis up, char *rule, size_t cap)
{
    mat4 t = up_rotation(up);
    int is_3ds = strcmp(format, "3ds") == 0;
    if (is_3ds) {
        mat4 undo = up_rotation(ASP_UP_NEG_Z);
        t = mat4_mul(&t, &undo);
    }
    if (up != ASP_UP_Y)
        snprintf(rule, cap, "as asked: the file's %s turned to y%s", axis_name(up),
                 is_3ds ? " (assimp's 3DS z-up turn undone first)" : "");
    else if (is_3ds)
        snprintf(rule, cap, "3DS stores no up axis: the file's coordinates, assimp's z-up turn undone");
    else if (strcmp(format, "gltf") == 0 || strcmp(format, "glb") == 0)
        snprintf(rule, cap, "glTF is y-up by its specification");
    else if (strcmp(format, "dae") == 0)
        snprintf(rule, cap, "the file's <up_axis>, turned to y by assimp");
    else
        snprintf(rule, cap, "%s stores no up axis: the file's coordinates, y by convention", format[0] ? format : "the format");
    return t;
}

/* A point file handed to the mesh loader gets told what it is, not assimp's "no triangles". */
static int refuse_non_mesh(const char *path, const asp_file_type *t, asp_error *err)
{
    if (t->kind == ASP_FILE_POINTS)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot read '%s': a point file (%s without faces), not a mesh; it needs no sampling: "
                             "give it to decompose, render or estimate as it is",
                             path, t->format);
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': %s %s file (%s), not a mesh", path,
                         t->kind == ASP_FILE_IMAGE ? "an" : "a", asp_file_kind_name(t->kind), t->format);
}

/* Whether the PLY header at path declares a tristrips element (read up to end_header, at most 64 KB). */
static int ply_has_strips(const char *path)
{
    FILE *fp = asp__regular_file_open(path, NULL);
    if (!fp)
        return 0;
    char line[512];
    int found = 0;
    for (int n = 0; n < 1024 && fgets(line, sizeof line, fp); n++) {
        if (strncmp(line, "end_header", 10) == 0)
            break;
        if (strncmp(line, "element tristrips ", 18) == 0)
            found = 1;
    }
    fclose(fp);
    return found;
}

/*
 * PLY meshes go through amgsplat's own reader first (issue #13): it checks
 * the declared counts against the file size before allocating, every face
 * index against the vertex count, and truncated bodies, so assimp never
 * allocates for a lying header (10^12 vertices: std::bad_alloc) nor samples
 * an out-of-range face. Triangle strips, which assimp reads as one triangle,
 * are written out as triangles to *tmp_path for assimp to read instead.
 */
static int ply_precheck(const char *path, const asp_context *ctx, char *tmp_path, size_t cap, asp_error *err)
{
    tmp_path[0] = '\0';
    asp_cloud *c = NULL;
    size_t short_faces = 0;
    int rc = asp__ply_read_counting(path, ctx, &c, &short_faces, err);
    if (rc)
        return rc;
    if (c->face_count == 0) {
        asp_cloud_destroy(c);
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': its face elements hold no triangles", path);
    }
    if (short_faces)
        asp_warn(ctx, "'%s': %zu face%s with fewer than 3 vertices (no surface) left out", path, short_faces,
                 short_faces == 1 ? "" : "s");
    // assimp reads strips as one triangle and aborts (ai_assert in TriangulateProcess) on an empty face:
    // it gets amgsplat's own triangles instead
    if (short_faces || ply_has_strips(path)) {
        const char *dir = getenv("TMPDIR");
        snprintf(tmp_path, cap, "%s/amgsplat-strips-XXXXXX", dir && *dir ? dir : "/tmp");
        int fd = mkstemp(tmp_path);
        if (fd < 0) {
            asp_cloud_destroy(c);
            tmp_path[0] = '\0';
            return asp_error_set(err, ASP_EIO, "cannot read '%s': no temporary file for its triangle strips: %s", path,
                                 strerror(errno));
        }
        close(fd);
        // the writer renames over the name: a .ply suffix is not needed, assimp reads the magic
        rc = asp_ply_write(c, tmp_path, NULL, err);
        if (rc) {
            unlink(tmp_path);
            tmp_path[0] = '\0';
        }
    }
    asp_cloud_destroy(c);
    return rc;
}

/*
 * The reader process (issue #31): assimp runs in a forked child
 * (util/child_process.h), which sends the merged mesh back through a pipe as
 * a head, the arrays and the materials; a crash inside assimp (Collada with a
 * count of -1: SIGSEGV) or a blow-up (the child's address space is capped)
 * becomes an error naming the file. The pre-checks stop what the bytes show
 * before any process starts. Cost on normal files: BENCHMARKS.md (issue #31).
 */
enum { MESH_WIRE_MAGIC = 0x41535057 };

typedef struct wire_head {
    uint32_t magic;
    int32_t rc;
    char msg[256];
    uint64_t nv, nt, nmat;
    uint32_t attrs, uv_sets;
    int32_t file_normals;
    double origin[3];
} wire_head;

typedef struct wire_material {
    char name[64];
    float diffuse[4];
    int32_t has_color;
    char texture_path[512];
    texture_ref ref;
    uint32_t width, height; /* embedded texture decoded in the reader, 0 x 0 when none */
} wire_material;

typedef struct mesh_job {
    const char *path, *import_path;
    asp_mesh_load_desc desc;
    mat4 start;
    asp_context ctx;
    size_t budget;
    /* parent: the result */
    asp_mesh *mesh;
    texture_ref *refs;
    int file_normals;
} mesh_job;

static void send_error(int fd, int rc, const asp_error *e)
{
    wire_head h = {.magic = MESH_WIRE_MAGIC, .rc = rc};
    copy_str(h.msg, sizeof h.msg, e->msg);
    asp__fd_write_all(fd, &h, sizeof h);
}

static void reader_child(void *user, int fd)
{
    mesh_job *j = user;
    asp_error e = {0};
    j->ctx.threads = 1; // no OpenMP team in a forked child: the parent's pool threads do not exist here
    const struct aiScene *scene = aiImportFile(j->import_path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                                   aiProcess_SortByPType | aiProcess_ValidateDataStructure);
    if (!scene) {
        const char *why = aiGetErrorString();
        int rc = ASP_EFORMAT;
        if (why && strstr(why, "bad_alloc"))
            rc = asp_error_set(&e, ASP_ENOMEM, "cannot read '%s': out of memory: the reader (assimp) reached its limit "
                               "of %zu MB", j->path, j->budget >> 20);
        else
            asp_error_set(&e, rc, "cannot read '%s': %s", j->path, why && *why ? why : "unknown format");
        send_error(fd, rc, &e);
        return;
    }
    asp_mesh *m = NULL;
    texture_ref *refs = NULL;
    int file_normals = 0;
    int rc = build(scene, j->path, &j->desc, &j->start, &j->ctx, &m, &refs, &file_normals, &e);
    if (rc) {
        send_error(fd, rc, &e);
        return;
    }
    wire_head h = {.magic = MESH_WIRE_MAGIC, .nv = m->vertex_count, .nt = m->triangle_count, .nmat = m->material_count,
                   .attrs = (m->uvs ? ASP_MESH_UVS : 0) | (m->colors ? ASP_MESH_COLORS : 0), .uv_sets = m->uv_set_count,
                   .file_normals = file_normals};
    memcpy(h.origin, m->origin, sizeof h.origin);
    size_t nv = m->vertex_count, nt = m->triangle_count;
    if (asp__fd_write_all(fd, &h, sizeof h) || asp__fd_write_all(fd, m->positions, 12 * nv) ||
        (file_normals && asp__fd_write_all(fd, m->normals, 12 * nv)) ||
        (m->uvs && asp__fd_write_all(fd, m->uvs, 8 * nv)) || (m->colors && asp__fd_write_all(fd, m->colors, 4 * nv)) ||
        asp__fd_write_all(fd, m->triangles, 12 * nt) || asp__fd_write_all(fd, m->material_ids, 4 * nt))
        return;
    for (size_t i = 0; i < m->material_count; i++) {
        const asp_material *mat = &m->materials[i];
        wire_material w = {.has_color = mat->has_color, .ref = refs[i]};
        memcpy(w.name, mat->name, sizeof w.name);
        memcpy(w.diffuse, mat->diffuse, sizeof w.diffuse);
        memcpy(w.texture_path, mat->texture_path, sizeof w.texture_path);
        if (mat->texture.pixels)
            w.width = mat->texture.width, w.height = mat->texture.height;
        if (asp__fd_write_all(fd, &w, sizeof w) ||
            (mat->texture.pixels && asp__fd_write_all(fd, mat->texture.pixels, (size_t)w.width * w.height * 4)))
            return;
    }
}

/* Reads the reader's mesh; every count is bounded before it sizes an allocation (the child may be damaged). */
static int reader_receive(void *user, int fd, asp_error *err)
{
    mesh_job *j = user;
    wire_head h;
    if (asp__fd_read_all(fd, &h, sizeof h) || h.magic != MESH_WIRE_MAGIC)
        return ASP_ECHILD_STREAM;
    if (h.rc) {
        h.msg[sizeof h.msg - 1] = '\0';
        return asp_error_set(err, h.rc < 0 ? h.rc : ASP_EFORMAT, "%s", h.msg);
    }
    if (h.nmat == 0 || h.nmat > (uint64_t)1 << 20 || (h.attrs & ~(unsigned)(ASP_MESH_UVS | ASP_MESH_COLORS)))
        return ASP_ECHILD_STREAM;
    asp_mesh *m = NULL;
    int rc = asp_mesh_create(h.nv, h.nt, h.attrs, &j->ctx, &m, err);
    if (rc)
        return rc == ASP_EINVAL ? ASP_ECHILD_STREAM : rc;
    texture_ref *refs = asp_calloc(&j->ctx, h.nmat, sizeof *refs);
    asp_material *mats = asp_calloc(&j->ctx, h.nmat, sizeof *mats);
    if (!refs || !mats) {
        asp_free(&j->ctx, refs);
        asp_free(&j->ctx, mats);
        asp_mesh_destroy(m);
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", j->path);
    }
    asp_free(&j->ctx, m->materials);
    m->materials = mats;
    m->material_count = h.nmat;
    m->uv_set_count = h.uv_sets;
    memcpy(m->origin, h.origin, sizeof h.origin);
    size_t nv = m->vertex_count, nt = m->triangle_count;
    rc = ASP_ECHILD_STREAM;
    if (asp__fd_read_all(fd, m->positions, 12 * nv) || (h.file_normals && asp__fd_read_all(fd, m->normals, 12 * nv)) ||
        (m->uvs && asp__fd_read_all(fd, m->uvs, 8 * nv)) || (m->colors && asp__fd_read_all(fd, m->colors, 4 * nv)) ||
        asp__fd_read_all(fd, m->triangles, 12 * nt) || asp__fd_read_all(fd, m->material_ids, 4 * nt))
        goto fail;
    for (size_t i = 0; i < m->material_count; i++) {
        asp_material *mat = &m->materials[i];
        wire_material w;
        if (asp__fd_read_all(fd, &w, sizeof w))
            goto fail;
        w.name[sizeof w.name - 1] = w.texture_path[sizeof w.texture_path - 1] = w.ref.ref[sizeof w.ref.ref - 1] = '\0';
        memcpy(mat->name, w.name, sizeof mat->name);
        memcpy(mat->diffuse, w.diffuse, sizeof mat->diffuse);
        mat->has_color = w.has_color != 0;
        memcpy(mat->texture_path, w.texture_path, sizeof mat->texture_path);
        refs[i] = w.ref;
        if (w.width || w.height) {
            if ((uint64_t)w.width * w.height > (uint64_t)16384 * 16384)
                goto fail;
            int irc = asp_image_init(&mat->texture, w.width, w.height, err);
            if (irc) {
                rc = irc;
                goto fail;
            }
            if (asp__fd_read_all(fd, mat->texture.pixels, (size_t)w.width * w.height * 4))
                goto fail;
        }
    }
    j->mesh = m;
    j->refs = refs;
    j->file_normals = h.file_normals != 0;
    return 0;
fail:
    asp_free(&j->ctx, refs);
    asp_mesh_destroy(m);
    return rc;
}

int asp_mesh_load(const char *path, const asp_mesh_load_desc *desc, const asp_context *ctx, asp_mesh **out,
                  asp_error *err)
{
    asp_mesh_load_desc d = desc ? *desc : (asp_mesh_load_desc){0};
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    struct stat st;
    size_t file_size = fstat(fileno(fp), &st) == 0 ? (size_t)st.st_size : 0;
    fclose(fp);
    /* unknown extensions go on to assimp, which reads more formats than the recogniser names */
    asp_file_type type = {.kind = ASP_FILE_MESH};
    asp_error e = {0};
    int rc = asp_file_recognise(path, &type, &e);
    if (rc && rc != ASP_EUNSUPPORTED)
        return asp_error_set(err, rc, "%s", e.msg);
    if (rc == 0 && type.kind != ASP_FILE_MESH)
        return refuse_non_mesh(path, &type, err);
    char tmp_path[4096] = "";
    if (rc == 0 && strcmp(type.format, "ply") == 0 && (rc = ply_precheck(path, ctx, tmp_path, sizeof tmp_path, err)))
        return rc;
    if (rc == 0 && (rc = asp__mesh_precheck(path, type.format, ctx, err)))
        return rc;
    /*
     * JoinIdenticalVertices (reader_child) welds the per-corner vertices
     * OBJ/STL importers emit; SortByPType puts points and lines into meshes of
     * their own so the walk can skip them. The reader may use 512 MB plus 64
     * bytes per byte of the file (a 'info' of the 2.4 MB bunny OBJ peaks at
     * 49 MB resident, process included) and 60 s plus 10 s per MB of CPU.
     */
    char rule[96];
    mesh_job job = {.path = path, .import_path = tmp_path[0] ? tmp_path : path, .desc = d,
                    .start = start_transform(type.format, d.up, rule, sizeof rule)};
    if (ctx)
        job.ctx = *ctx;
    job.budget = ((size_t)512 << 20) + (file_size < ((size_t)1 << 40) ? 64 * file_size : ((size_t)1 << 46));
    asp__child_desc cd = {.path = path, .reader = "assimp", .memory_budget = job.budget,
                          .cpu_seconds = 60 + (unsigned)(file_size < ((size_t)1 << 36) ? 10 * (file_size >> 20) : 655360)};
    rc = asp__child_run(&cd, reader_child, reader_receive, &job, err);
    if (tmp_path[0])
        unlink(tmp_path);
    if (rc)
        return rc;
    rc = finish(job.mesh, path, &d, job.refs, job.file_normals, err);
    asp_free(&job.ctx, job.refs);
    if (rc) {
        asp_mesh_destroy(job.mesh);
        return rc;
    }
    *out = job.mesh;
    (*out)->up = d.up;
    snprintf((*out)->up_rule, sizeof (*out)->up_rule, "%s", rule);
    return 0;
}
