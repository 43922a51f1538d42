/*
 * GPU bytes of a mesh: the one count issue #14 compares simplified meshes and
 * domain primitives by (eval's equal-bytes rows), defined in mesh.h so every
 * caller counts the same way.
 */
#include <string.h>

#include "amgsplat/mesh.h"
#include "util/banned.h"

/* 1 when an earlier used material names the same texture file (the renderer would upload it once). */
static int shared_earlier(const asp_mesh *m, const unsigned char *used, size_t i)
{
    const asp_material *a = &m->materials[i];
    if (!a->texture_path[0])
        return 0;
    for (size_t j = 0; j < i; j++)
        if (used[j] && m->materials[j].texture.pixels && strcmp(m->materials[j].texture_path, a->texture_path) == 0)
            return 1;
    return 0;
}

size_t asp_mesh_gpu_bytes(const asp_mesh *mesh, asp_mesh_bytes *out)
{
    asp_mesh_bytes b = {0};
    size_t per_vertex = 12 + 12 + (mesh->uvs ? 8 : 0) + (mesh->colors ? 4 : 0);
    b.vertex = per_vertex * mesh->vertex_count;
    b.index = 4 * 3 * mesh->triangle_count;
    /* materials are few (tens): a byte per material on the stack bounds it at 4096, beyond which all count as used */
    unsigned char used[4096];
    size_t nm = mesh->material_count < sizeof used ? mesh->material_count : sizeof used;
    memset(used, 0, sizeof used);
    for (size_t t = 0; t < mesh->triangle_count; t++)
        if (mesh->material_ids[t] < nm)
            used[mesh->material_ids[t]] = 1;
    for (size_t i = 0; i < mesh->material_count; i++) {
        const asp_image *tex = &mesh->materials[i].texture;
        if (!tex->pixels || (i < nm && !used[i]) || (i < nm && shared_earlier(mesh, used, i)))
            continue;
        /* RGBA8 plus the mipmap chain: 1 + 1/4 + 1/16 + ... = 4/3 */
        b.texture += (size_t)tex->width * tex->height * 4 * 4 / 3;
    }
    b.total = b.vertex + b.index + b.texture;
    if (out)
        *out = b;
    return b.total;
}
