/*
 * libFuzzer target for the text point reader alone (asp_xyz_read_memory:
 * .xyz, .pts, .txt): any bytes give a clean "cannot read" error or a valid
 * cloud, never a crash, a hang or an allocation out of proportion to the
 * input (the budget allocator aborts past 4x the input plus 1 MB). Seeds:
 *   mkdir corpus-xyz && cp tests/data/bad/?*.xyz tests/data/bad/?*.pts corpus-xyz/
 *   ./fuzz_xyz -max_total_time=600 -rss_limit_mb=2048 -max_len=4096 corpus-xyz
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/io.h"
#include "fuzz_support.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_budget b;
    asp_context ctx = fuzz_budget_context(&b, size, "fuzz_xyz");
    asp_cloud *c = NULL;
    asp_error err = {0};
    int rc = asp_xyz_read_memory(data, size, "fuzz.xyz", &ctx, &c, &err);
    if (rc != 0) {
        if (c || strncmp(err.msg, "cannot read 'fuzz.xyz'", 22) != 0)
            abort();
        return 0;
    }
    if (!c || c->count == 0)
        abort();
    for (size_t i = 0; i < 3 * c->count; i++)
        if (!isfinite(c->positions[i]))
            abort(); // the reader refuses non-finite coordinates
    asp_cloud_validate(c, NULL);
    asp_cloud_destroy(c);
    return 0;
}
