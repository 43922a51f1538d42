/*
 * libFuzzer target for the LAS reader (asp_las_read_memory): any bytes give a
 * clean "cannot read" error or a valid cloud, never a crash, a hang or an
 * allocation out of proportion to the input. The budget is 10x the input plus
 * 8 MB, not the 4x plus 1 MB of the other readers: a record of one-byte extra
 * bytes with a scale widens each byte to a double (8x), and each extra byte
 * is a property, whose table asp_cloud_add_property grows one entry at a time
 * (the reader's cap of about 300 properties bounds that at 4 MB). Seeds:
 *   amgsplat convert some.ply seed.las; python3 tests/cli/las_handmade.py seed14.las 4 7 20 --extra
 *   ./fuzz_las -max_total_time=600 -rss_limit_mb=2048 -max_len=65536 corpus-las
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
    asp_context ctx = fuzz_budget_context(&b, size, "fuzz_las");
    b.limit = 10 * size + (8u << 20);
    asp_cloud *c = NULL;
    asp_error err = {0};
    int rc = asp_las_read_memory(data, size, "fuzz.las", &ctx, &c, &err);
    if (rc != 0) {
        if (c || strncmp(err.msg, "cannot read 'fuzz.las'", 22) != 0)
            abort();
        return 0;
    }
    if (!c || !c->las)
        abort();
    for (size_t i = 0; i < 3 * c->count; i++)
        if (!isfinite(c->positions[i]))
            abort(); // the reader refuses coordinates outside the float range
    for (int k = 0; k < 3; k++)
        if (!isfinite(c->origin[k]))
            abort();
    volatile double sink = 0;
    for (size_t p = 0; p < c->property_count; p++)
        sink += ((const uint8_t *)c->properties[p].data)[c->count ? c->count - 1 : 0];
    (void)sink;
    asp_cloud_destroy(c);
    return 0;
}
