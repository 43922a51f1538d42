/*
 * libFuzzer target for asp_mesh_simplify on arbitrary meshes: vertex and
 * triangle counts, positions (any float bits, NaN and infinities too), indices
 * (in and out of range, repeated), materials and targets from the input. The
 * simplifier must return 0 with a mesh whose indices and material ids are in
 * range and no larger than the input, or a clean ASP_EFORMAT; never a crash,
 * a read past an array, or one of meshoptimizer's assertions. The result's
 * GPU byte count must add up.
 * Build with -DASP_FUZZ=ON, then: ./fuzz_mesh_simplify -max_total_time=60 -max_len=4096
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "amgsplat/mesh.h"

static uint32_t take_u32(const uint8_t **p, const uint8_t *end)
{
    uint32_t v = 0;
    for (int i = 0; i < 4 && *p < end; i++, (*p)++)
        v |= (uint32_t)**p << (8 * i);
    return v;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 6)
        return 0;
    const uint8_t *p = data, *end = data + size;
    size_t nv = 1 + *p++ % 64, nt = 1 + *p++ % 96, nm = 1 + *p++ % 3;
    unsigned flags = *p++ & 7u;
    size_t target = *p++ % 128;
    int finite_only = *p++ & 1; // half the inputs keep to what asp_mesh_load produces
    asp_mesh *m = NULL;
    if (asp_mesh_create(nv, nt, ASP_MESH_UVS, NULL, &m, NULL))
        return 0;
    for (size_t i = 0; i < 3 * nv; i++) {
        uint32_t bits = take_u32(&p, end);
        float f;
        memcpy(&f, &bits, 4);
        if (finite_only && !(f == f && f - f == 0.0f))
            f = (float)(bits % 17) - 8.0f;
        m->positions[i] = f;
    }
    for (size_t i = 0; i < 3 * nt; i++)
        m->triangles[i] = p < end ? (uint32_t)(*p++ % (nv + (finite_only ? 0 : 2))) : (uint32_t)(i % nv);
    for (size_t t = 0; t < nt; t++)
        m->material_ids[t] = p < end ? (uint32_t)(*p++ % (nm + (finite_only ? 0 : 1))) : 0;
    asp_material *mats = asp_calloc(&m->ctx, nm, sizeof *mats);
    if (!mats) {
        asp_mesh_destroy(m);
        return 0;
    }
    mats[0] = m->materials[0];
    asp_free(&m->ctx, m->materials);
    m->materials = mats;
    m->material_count = nm;
    asp_mesh *s = NULL;
    asp_mesh_simplify_stats st;
    asp_error err = {0};
    int rc = asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = target, .flags = flags}, NULL, &s, &st,
                               &err);
    if (rc == 0) {
        if (!s || s->triangle_count > nt || s->vertex_count > nv || s->material_count != nm)
            abort();
        for (size_t i = 0; i < 3 * s->triangle_count; i++)
            if (s->triangles[i] >= s->vertex_count)
                abort();
        for (size_t t = 0; t < s->triangle_count; t++)
            if (s->material_ids[t] >= s->material_count)
                abort();
        asp_mesh_bytes b;
        if (asp_mesh_gpu_bytes(s, &b) != b.vertex + b.index + b.texture || b.index != 12 * s->triangle_count)
            abort();
        asp_mesh_destroy(s);
    } else if (rc != ASP_EFORMAT || s != NULL || strncmp(err.msg, "cannot simplify: ", 17) != 0) {
        abort();
    }
    asp_mesh_destroy(m);
    return 0;
}
