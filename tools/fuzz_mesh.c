/*
 * libFuzzer target for the mesh path (asp_mesh_load: amgsplat's pre-checks,
 * then assimp). assimp reads files by name, so the bytes go to a temporary
 * file whose extension the first byte picks (off, obj, stl, ply, 3ds, gltf);
 * the pre-checks also run on the bytes alone. Any input gives a clean error
 * naming the file or a mesh whose triangles index its vertices. Seeds:
 * tests/data/bad/mesh/ and small meshes, each prefixed with its extension's
 * byte (0 off, 1 obj, 2 stl, 3 ply, 4 3ds, 5 gltf):
 *   ./fuzz_mesh -max_total_time=600 -rss_limit_mb=2048 -max_len=8192 corpus-mesh
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "io/mesh_precheck.h"

static const char *const exts[] = {"off", "obj", "stl", "ply", "3ds", "gltf"};
enum { NEXT = sizeof exts / sizeof exts[0] };
static char paths[NEXT][64];

static void cleanup(void)
{
    for (int i = 0; i < NEXT; i++)
        if (paths[i][0])
            unlink(paths[i]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int k = data[0] % NEXT;
    if (!paths[0][0]) {
        for (int i = 0; i < NEXT; i++)
            snprintf(paths[i], sizeof paths[i], "/tmp/fuzz_mesh_%d.%s", (int)getpid(), exts[i]);
        atexit(cleanup);
    }
    asp_error err = {0};
    if (asp__mesh_precheck_memory(data + 1, size - 1, "fuzz", exts[k], &err) != 0 &&
        strncmp(err.msg, "cannot read 'fuzz': ", 20) != 0)
        abort();
    FILE *f = fopen(paths[k], "wb");
    if (!f || fwrite(data + 1, 1, size - 1, f) != size - 1)
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
