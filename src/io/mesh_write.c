/*
 * asp_mesh_save: triangle meshes as OBJ+MTL (+ PNG textures) or PLY with
 * faces, uvs and colours, for the simplified-mesh baseline of issue #14. What
 * is written reads back through asp_mesh_load (assimp) with the same counts,
 * so `amgsplat simplify` output feeds `sample`, `render` and `eval`.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "amgsplat/output.h"
#include "util/atomic_file.h"
#include "util/banned.h"

enum { PATH_CAP = 4096 };

/* path without its extension ("dir/out.obj" -> "dir/out"); 0 or -1 when it does not fit. */
static int stem_of(const char *path, char *out, size_t cap)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    size_t len = dot ? (size_t)(dot - path) : strlen(path);
    if (len + 16 >= cap)
        return -1;
    memcpy(out, path, len);
    out[len] = '\0';
    return 0;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/*
 * The texture file name of material i: STEM.png for the first textured
 * material, STEM_<i>.png for later ones (name is what goes into the file,
 * relative to the mesh; full is where it is written).
 */
static void texture_names(const asp_mesh *m, size_t i, const char *stem, char *full, size_t cap)
{
    size_t first = 0;
    while (first < m->material_count && !m->materials[first].texture.pixels)
        first++;
    if (i == first)
        snprintf(full, cap, "%s.png", stem);
    else
        snprintf(full, cap, "%s_%zu.png", stem, i);
}

static int write_textures(const asp_mesh *m, const char *stem, int first_only, asp_error *err)
{
    for (size_t i = 0; i < m->material_count; i++) {
        if (!m->materials[i].texture.pixels)
            continue;
        char full[PATH_CAP + 32];
        texture_names(m, i, stem, full, sizeof full);
        int rc = asp_image_save_png(&m->materials[i].texture, full, err);
        if (rc)
            return rc;
        if (first_only)
            break;
    }
    return 0;
}

/* A material name MTL can hold: no whitespace, not empty, unique in the file (suffix _<i> otherwise). */
static void mtl_name(const asp_mesh *m, size_t i, char *out, size_t cap)
{
    snprintf(out, cap, "%s", m->materials[i].name[0] ? m->materials[i].name : "material");
    for (char *c = out; *c; c++)
        if (*c == ' ' || *c == '\t' || *c == '\r' || *c == '\n' || *c == '#')
            *c = '_';
    for (size_t j = 0; j < i; j++)
        if (strcmp(m->materials[j].name, m->materials[i].name) == 0) {
            size_t len = strlen(out);
            snprintf(out + len, cap - len, "_%zu", i);
            break;
        }
}

static int finish(asp__atomic_file *f, const char *path, asp_error *err)
{
    if (ferror(f->fp)) {
        int e = errno;
        asp__atomic_abort(f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", path, strerror(e ? e : EIO));
    }
    return asp__atomic_commit(f, err);
}

static int write_mtl(const asp_mesh *m, const char *mtl_path, const char *stem, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, mtl_path, err);
    if (rc)
        return rc;
    fprintf(f.fp, "# written by amgsplat\n");
    for (size_t i = 0; i < m->material_count; i++) {
        const asp_material *mat = &m->materials[i];
        char name[80];
        mtl_name(m, i, name, sizeof name);
        fprintf(f.fp, "\nnewmtl %s\nKd %.6g %.6g %.6g\nd %.6g\n", name, mat->diffuse[0], mat->diffuse[1],
                mat->diffuse[2], mat->diffuse[3]);
        if (mat->texture.pixels) {
            char full[PATH_CAP + 32];
            texture_names(m, i, stem, full, sizeof full);
            fprintf(f.fp, "map_Kd %s\n", base_name(full));
        }
    }
    return finish(&f, mtl_path, err);
}

static int save_obj(const asp_mesh *m, const char *path, asp_error *err)
{
    char stem[PATH_CAP], mtl_path[PATH_CAP + 8];
    if (stem_of(path, stem, sizeof stem))
        return asp_error_set(err, ASP_EINVAL, "cannot write '%.200s': path too long", path);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", stem);
    int rc = write_textures(m, stem, 0, err);
    if (rc == 0)
        rc = write_mtl(m, mtl_path, stem, err);
    if (rc)
        return rc;
    asp__atomic_file f;
    if ((rc = asp__atomic_open(&f, path, err)))
        return rc;
    FILE *fp = f.fp;
    fprintf(fp, "# written by amgsplat: %zu vertices, %zu triangles\nmtllib %s\n", m->vertex_count, m->triangle_count,
            base_name(mtl_path));
    /* %.9g: the shortest fixed precision that reads back to the same float */
    for (size_t v = 0; v < m->vertex_count; v++) {
        const float *p = m->positions + 3 * v;
        fprintf(fp, "v %.9g %.9g %.9g", m->origin[0] + p[0], m->origin[1] + p[1], m->origin[2] + p[2]);
        if (m->colors) {
            const uint8_t *c = m->colors + 4 * v;
            fprintf(fp, " %.6g %.6g %.6g", c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        }
        fputc('\n', fp);
    }
    for (size_t v = 0; m->uvs && v < m->vertex_count; v++)
        fprintf(fp, "vt %.9g %.9g\n", m->uvs[2 * v], m->uvs[2 * v + 1]);
    for (size_t v = 0; v < m->vertex_count; v++)
        fprintf(fp, "vn %.9g %.9g %.9g\n", m->normals[3 * v], m->normals[3 * v + 1], m->normals[3 * v + 2]);
    /* one pass per material keeps each usemtl block contiguous; materials are few */
    for (size_t k = 0; k < m->material_count; k++) {
        int opened = 0;
        for (size_t t = 0; t < m->triangle_count; t++) {
            if (m->material_ids[t] != k)
                continue;
            if (!opened) {
                char name[80];
                mtl_name(m, k, name, sizeof name);
                fprintf(fp, "usemtl %s\n", name);
                opened = 1;
            }
            const uint32_t *tri = m->triangles + 3 * t;
            fputc('f', fp);
            for (int c = 0; c < 3; c++) {
                unsigned long i = (unsigned long)tri[c] + 1; // OBJ counts from 1
                if (m->uvs)
                    fprintf(fp, " %lu/%lu/%lu", i, i, i);
                else
                    fprintf(fp, " %lu//%lu", i, i);
            }
            fputc('\n', fp);
        }
    }
    return finish(&f, path, err);
}

static void put_f32(uint8_t *d, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    for (int i = 0; i < 4; i++)
        d[i] = (uint8_t)(u >> (8 * i));
}

static int save_ply(const asp_mesh *m, const char *path, const asp_mesh_save_desc *desc, asp_error *err)
{
    char stem[PATH_CAP], tex[PATH_CAP + 32] = "";
    if (stem_of(path, stem, sizeof stem))
        return asp_error_set(err, ASP_EINVAL, "cannot write '%.200s': path too long", path);
    size_t first = 0;
    while (first < m->material_count && !m->materials[first].texture.pixels)
        first++;
    int rc;
    if (first < m->material_count) {
        texture_names(m, first, stem, tex, sizeof tex);
        if ((rc = write_textures(m, stem, 1, err)))
            return rc;
    }
    asp__atomic_file f;
    if ((rc = asp__atomic_open(&f, path, err)))
        return rc;
    FILE *fp = f.fp;
    int ascii = desc && desc->ply_ascii;
    fprintf(fp, "ply\nformat %s 1.0\ncomment written by amgsplat\n", ascii ? "ascii" : "binary_little_endian");
    if (tex[0])
        fprintf(fp, "comment TextureFile %s\n", base_name(tex));
    fprintf(fp, "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\n",
            m->vertex_count);
    if (m->uvs)
        fprintf(fp, "property float texture_u\nproperty float texture_v\n");
    if (m->colors)
        fprintf(fp, "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n");
    /* int as readers expect; uint only where an index would not fit (asp_mesh allows up to 2^32-2) */
    fprintf(fp, "element face %zu\nproperty list uchar %s vertex_indices\nend_header\n", m->triangle_count,
            m->vertex_count > 2147483647u ? "uint" : "int");
    for (size_t v = 0; v < m->vertex_count; v++) {
        float val[8];
        size_t nf = 0;
        for (int c = 0; c < 3; c++)
            val[nf++] = (float)(m->origin[c] + m->positions[3 * v + c]);
        for (int c = 0; c < 3; c++)
            val[nf++] = m->normals[3 * v + c];
        if (m->uvs)
            val[nf++] = m->uvs[2 * v], val[nf++] = m->uvs[2 * v + 1];
        const uint8_t *col = m->colors ? m->colors + 4 * v : NULL;
        if (ascii) {
            for (size_t i = 0; i < nf; i++)
                fprintf(fp, i ? " %.9g" : "%.9g", val[i]);
            if (col)
                fprintf(fp, " %u %u %u %u", col[0], col[1], col[2], col[3]);
            fputc('\n', fp);
        } else {
            uint8_t rec[8 * 4 + 4];
            for (size_t i = 0; i < nf; i++)
                put_f32(rec + 4 * i, val[i]);
            size_t len = 4 * nf;
            if (col)
                memcpy(rec + len, col, 4), len += 4;
            fwrite(rec, 1, len, fp);
        }
    }
    for (size_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = m->triangles + 3 * t;
        if (ascii) {
            fprintf(fp, "3 %u %u %u\n", tri[0], tri[1], tri[2]);
        } else {
            uint8_t rec[13] = {3};
            for (int c = 0; c < 3; c++)
                for (int i = 0; i < 4; i++)
                    rec[1 + 4 * c + i] = (uint8_t)(tri[c] >> (8 * i));
            fwrite(rec, 1, sizeof rec, fp);
        }
    }
    return finish(&f, path, err);
}

int asp_mesh_save(const asp_mesh *mesh, const char *path, const asp_mesh_save_desc *desc, asp_error *err)
{
    ASP_ASSERT(mesh && path);
    asp_file_type type;
    int rc = asp_file_type_of_name(path, &type, err);
    if (rc)
        return rc;
    // OBJ, MTL and textures (PLY and texture) appear all or none (issue #13)
    if (strcmp(type.format, "obj") == 0 || strcmp(type.format, "ply") == 0) {
        asp_output_batch_begin(NULL);
        rc = type.format[0] == 'o' ? save_obj(mesh, path, err) : save_ply(mesh, path, desc, err);
        if (rc) {
            asp_output_batch_abort();
            return rc;
        }
        return asp_output_batch_commit(err);
    }
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': mesh output is .obj or .ply, not .%s", path,
                         type.format);
}
