/*
 * libFuzzer target for the batched point reader (asp_point_reader_*: binary
 * PLY and LAS read a batch at a time, issue 28), which takes a path: the bytes
 * go to a temporary file. Any bytes give a clean error naming the file, or a
 * reader whose every batch decodes inside the buffers it was given, twice
 * (after a rewind) with the same result, never a crash, leak or hang. Batches
 * of 97 points cross record boundaries at odd places. Seeds: a small binary
 * PLY (amgsplat synth terrain --points 2000, big endian with convert
 * --big-endian) and LAS of formats 1, 3 and 4 (tests/cli/las_handmade.py):
 *   ./fuzz_point_stream -max_total_time=300 -rss_limit_mb=2048 -max_len=65536 tools/corpus/fuzz_point_stream
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/point_stream.h"
#include "fuzz_support.h"

enum { BATCH = 97 };

/* Reads every batch; returns the points read (or UINT64_MAX on an error) and a hash of what they decoded to. */
static uint64_t read_all(asp_point_reader *r, const char *path, uint64_t *hash)
{
    double xyz[3 * BATCH];
    uint8_t rgba[4 * BATCH];
    uint64_t total = 0, h = 1469598103934665603ull;
    for (;;) {
        size_t got = SIZE_MAX;
        asp_error err = {0};
        if (asp_point_reader_read(r, xyz, rgba, BATCH, &got, &err) != 0) {
            if (!strstr(err.msg, path))
                abort(); // the message names the file
            return UINT64_MAX;
        }
        if (got > BATCH)
            abort();
        if (got == 0)
            break;
        total += got;
        // the bytes written: hashed, so reading outside a record shows up under ASan and the rewind is checked
        const uint8_t *p = (const uint8_t *)xyz;
        for (size_t i = 0; i < 3 * got * sizeof(double); i++)
            h = (h ^ p[i]) * 1099511628211ull;
        for (size_t i = 0; i < 4 * got; i++)
            h = (h ^ rgba[i]) * 1099511628211ull;
    }
    *hash = h;
    return total;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file("fuzz_point_stream", "ply", data, size);
    asp_context ctx = {.threads = 1};
    asp_point_reader *r = NULL;
    asp_error err = {0};
    if (asp_point_reader_open(path, &ctx, &r, &err) != 0) {
        if (r || !strstr(err.msg, path))
            abort(); // no reader on failure, and the message names the file
        return 0;
    }
    if (!r)
        abort();
    uint64_t count = asp_point_reader_count(r);
    int colors = asp_point_reader_has_colors(r);
    if (colors != 0 && colors != 1)
        abort();
    uint64_t h1 = 0, h2 = 0;
    uint64_t n1 = read_all(r, path, &h1);
    // the header's count fits the file (checked on open), so every point is read
    if (n1 != count)
        abort();
    if (asp_point_reader_rewind(r, &err) != 0)
        abort();
    uint64_t n2 = read_all(r, path, &h2);
    if (n2 != n1 || h2 != h1)
        abort();
    asp_point_reader_close(r);
    return 0;
}
