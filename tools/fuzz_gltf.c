/*
 * libFuzzer target for glTF 2.0 / GLB through the pre-check (issue #31) and
 * the contained reader: asp__gltf_precheck_memory on the bytes, then
 * asp_mesh_load of them as a file (.glb when they start with the GLB magic,
 * else .gltf), where assimp runs in a child process. Any input gives a clean
 * error naming the file or a mesh whose triangles index its vertices; a
 * refusal by the pre-check names the file too. Seeds: tests/data/bad/assimp
 * (make_cases.py: valid files and the lying header, chunk, sparse and
 * bufferView cases):
 *   ./fuzz_gltf -max_total_time=600 -rss_limit_mb=2048 -max_len=65536 corpus-gltf
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "io/mesh_precheck.h"

static char paths[2][64];

static void cleanup(void)
{
    for (int i = 0; i < 2; i++)
        if (paths[i][0])
            unlink(paths[i]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!paths[0][0]) {
        snprintf(paths[0], sizeof paths[0], "/tmp/fuzz_gltf_%d.gltf", (int)getpid());
        snprintf(paths[1], sizeof paths[1], "/tmp/fuzz_gltf_%d.glb", (int)getpid());
        atexit(cleanup);
    }
    int k = size >= 4 && memcmp(data, "glTF", 4) == 0;
    asp_error err = {0};
    int pre = asp__gltf_precheck_memory(data, size, "fuzz", &err);
    if (pre != 0 && strncmp(err.msg, "cannot read 'fuzz'", 18) != 0 && pre != ASP_ENOMEM)
        abort();
    if (pre != 0)
        return 0; // the load would stop at the same pre-check
    FILE *f = fopen(paths[k], "wb");
    if (!f || fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
    asp_mesh *m = NULL;
    memset(&err, 0, sizeof err);
    asp_context ctx = {.threads = 1};
    int rc = asp_mesh_load(paths[k], &(asp_mesh_load_desc){.allow_missing_textures = 1}, &ctx, &m, &err);
    if (rc != 0) {
        if (m || !strstr(err.msg, paths[k]))
            abort();
        return 0;
    }
    for (size_t t = 0; t < 3 * m->triangle_count; t++)
        if (m->triangles[t] >= m->vertex_count)
            abort();
    asp_mesh_destroy(m);
    return 0;
}
