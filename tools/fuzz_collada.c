/*
 * libFuzzer target for Collada (.dae) through the pre-check (issue #31) and
 * the contained reader: asp__dae_precheck_memory on the bytes, then
 * asp_mesh_load of them as a .dae file, where assimp runs in a child process
 * (a count of -1 crashed it with SIGSEGV before the pre-check). Any input
 * gives a clean error naming the file or a mesh whose triangles index its
 * vertices. Seeds: the .dae files of tests/data/bad/assimp/ (make_cases.py):
 *   ./fuzz_collada -max_total_time=600 -rss_limit_mb=2048 -max_len=65536 corpus-dae
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "io/mesh_precheck.h"

static char path[64];

static void cleanup(void)
{
    if (path[0])
        unlink(path);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0]) {
        snprintf(path, sizeof path, "/tmp/fuzz_collada_%d.dae", (int)getpid());
        atexit(cleanup);
    }
    asp_error err = {0};
    int pre = asp__dae_precheck_memory(data, size, "fuzz", &err);
    if (pre != 0 && strncmp(err.msg, "cannot read 'fuzz'", 18) != 0 && pre != ASP_ENOMEM)
        abort();
    if (pre != 0)
        return 0; // the load would stop at the same pre-check
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
    asp_mesh *m = NULL;
    memset(&err, 0, sizeof err);
    asp_context ctx = {.threads = 1};
    int rc = asp_mesh_load(path, &(asp_mesh_load_desc){.allow_missing_textures = 1}, &ctx, &m, &err);
    if (rc != 0) {
        if (m || !strstr(err.msg, path))
            abort();
        return 0;
    }
    for (size_t t = 0; t < 3 * m->triangle_count; t++)
        if (m->triangles[t] >= m->vertex_count)
            abort();
    asp_mesh_destroy(m);
    return 0;
}
