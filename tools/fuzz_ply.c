/*
 * libFuzzer target for the point-file parsers (asp_ply_read_memory, and the
 * text reader on the same bytes): arbitrary input must give a clean error or
 * a valid cloud, never a crash, leak, hang or huge allocation (STYLE.md 11).
 * Build with -DASP_FUZZ=ON (see CMakeLists.txt), then seed from the tests:
 *   mkdir corpus && cp tests/data/bad/[a-z]* corpus/
 *   ./fuzz_ply -max_total_time=600 -rss_limit_mb=2048 -max_len=4096 corpus
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/io.h"

static void check(int rc, asp_cloud *c, const asp_error *err)
{
    if (rc == 0) {
        if (!c || c->count == 0)
            abort();
        /* touch every array so a short allocation shows under ASan */
        volatile float sink = 0;
        for (size_t i = 0; i < 3 * c->count; i++)
            sink += c->positions[i];
        for (size_t i = 0; i < 3 * c->face_count; i++)
            if (c->faces[i] >= c->count)
                abort();
        (void)sink;
        asp_cloud_validate(c, NULL);
        asp_cloud_destroy(c);
        return;
    }
    /* failures leave the output alone and always explain themselves */
    if (c || strncmp(err->msg, "cannot read '", 13) != 0)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    asp_cloud *c = NULL;
    asp_error err = {0};
    int rc = asp_ply_read_memory(data, size, "fuzz.ply", NULL, &c, &err);
    check(rc, c, &err);
    c = NULL;
    memset(&err, 0, sizeof err);
    rc = asp_xyz_read_memory(data, size, "fuzz.xyz", NULL, &c, &err);
    check(rc, c, &err);
    return 0;
}
