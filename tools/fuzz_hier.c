/*
 * libFuzzer target for the point-hierarchy file reader (asp_hier_load_memory):
 * arbitrary bytes must give a clean error or a consistent hierarchy, never a
 * crash, leak or huge allocation (STYLE.md section 11).
 *   ./fuzz_hier -max_total_time=300 -rss_limit_mb=2048 corpus
 * Seed the corpus with a small saved hierarchy (asp_hier_save; version 2, and a
 * version-1 file for the old-header path). Each input is also tried with its
 * payload size and both FNV-1a checksums made consistent (issue #13): random
 * mutations almost never keep them, and without the fix none of the checks
 * behind them is reached.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/hier.h"
#include "util/checksum.h"

static void one(const uint8_t *data, size_t size)
{
    asp_hier *h = NULL;
    asp_error err = {0};
    int rc = asp_hier_load_memory(data, size, "fuzz.hier", NULL, &h, &err);
    if (rc == 0) {
        if (!h)
            abort();
        /* the recorded (or, version 1, root-sphere) frame is finite with radius >= 0 */
        const asp_frame *f = asp_hier_frame(h);
        if (!(isfinite(f->center[0]) && isfinite(f->center[1]) && isfinite(f->center[2]) && isfinite(f->radius) &&
              f->radius >= 0))
            abort();
        /* every node's child and point ranges must lie inside the arrays */
        size_t n = asp_hier_node_count(h), points = asp_hier_point_count(h);
        const asp_hier_node *nodes = asp_hier_nodes(h);
        for (size_t i = 0; i < n; i++) {
            if (nodes[i].child_count && (size_t)nodes[i].first_child + nodes[i].child_count > n)
                abort();
            if ((size_t)nodes[i].first_point + nodes[i].point_count > points)
                abort();
        }
        asp_hier_destroy(h);
        return;
    }
    if (h || err.msg[0] == '\0')
        abort();
}

static void put64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one(data, size);
    if (size < 12 || memcmp(data, "ASPHIER", 8) != 0)
        return 0;
    const size_t hsize = data[8] == 1 && !data[9] && !data[10] && !data[11] ? 128 : 160;
    if (size < hsize)
        return 0;
    uint8_t *fixed = malloc(size);
    if (!fixed)
        return 0;
    memcpy(fixed, data, size);
    put64(fixed + 80, size - hsize);
    // docs/hier.md: FNV-1a 64 over the payload (stored at byte 88) and over the header before its last 8 bytes
    put64(fixed + 88, asp__fnv1a64(ASP__FNV1A64_START, fixed + hsize, size - hsize));
    put64(fixed + hsize - 8, asp__fnv1a64(ASP__FNV1A64_START, fixed, hsize - 8));
    if (memcmp(fixed, data, size) != 0)
        one(fixed, size);
    free(fixed);
    return 0;
}
