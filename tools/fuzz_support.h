/*
 * Shared by the fuzzers: for the checksummed formats (fuzz_amg.c, fuzz_dps.c)
 * an allocator that aborts past a byte budget and the retry of each input with
 * its payload size and CRC-32 trailer made consistent; for the readers that
 * take a path (fuzz_image.c, fuzz_stats_log.c) one temporary file per process. Static inline in a header,
 * not a .c file, because CMake builds every tools/fuzz_*.c as its own fuzzer
 * from that one file; this name stays outside that glob.
 */
#ifndef ASP_TOOLS_FUZZ_SUPPORT_H
#define ASP_TOOLS_FUZZ_SUPPORT_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/core.h"
#include "util/checksum.h"

/* Both formats: a 64-byte header, then the payload, then a 4-byte CRC-32 of everything before it. */
enum { FUZZ_HEADER_BYTES = 64, FUZZ_TRAILER_BYTES = 4 };

/* Counts what one load allocates through the context; `who` names the fuzzer in the abort message. */
typedef struct fuzz_budget {
    size_t limit, total;
    const char *who;
} fuzz_budget;

static inline void *fuzz_budget_alloc(void *user, size_t size, size_t alignment)
{
    fuzz_budget *b = user;
    b->total += size;
    if (b->total > b->limit) {
        fprintf(stderr, "%s: %zu bytes allocated in total, limit %zu\n", b->who, b->total, b->limit);
        abort();
    }
    return aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}

static inline void fuzz_budget_free(void *user, void *ptr)
{
    (void)user;
    free(ptr);
}

/*
 * A one-thread context for loading size input bytes: allocating more than a few
 * times the input in total means the reader trusted a forged count, so it aborts.
 * b must outlive the load.
 */
static inline asp_context fuzz_budget_context(fuzz_budget *b, size_t size, const char *who)
{
    *b = (fuzz_budget){.limit = 4 * size + (1u << 20), .total = 0, .who = who};
    return (asp_context){.threads = 1, .allocator = {fuzz_budget_alloc, fuzz_budget_free, b}};
}

/*
 * Calls one(data, size), then one() again on a copy whose payload size (8 bytes,
 * little-endian, at header byte payload_at) and CRC-32 trailer are consistent,
 * unless that copy is the input itself: a random mutation almost never keeps
 * the checksum, and without the fix the parser behind it would go unfuzzed.
 */
static inline void fuzz_with_fixed_trailer(const uint8_t *data, size_t size, size_t payload_at,
                                           void (*one)(const uint8_t *, size_t))
{
    one(data, size);
    if (size < FUZZ_HEADER_BYTES + FUZZ_TRAILER_BYTES)
        return;
    uint8_t *fixed = malloc(size);
    if (!fixed)
        return;
    memcpy(fixed, data, size);
    uint64_t payload = size - FUZZ_HEADER_BYTES - FUZZ_TRAILER_BYTES;
    for (int k = 0; k < 8; k++)
        fixed[payload_at + k] = (uint8_t)(payload >> (8 * k));
    uint32_t crc = asp__crc32(0, fixed, size - FUZZ_TRAILER_BYTES);
    for (int k = 0; k < 4; k++)
        fixed[size - FUZZ_TRAILER_BYTES + k] = (uint8_t)(crc >> (8 * k));
    if (memcmp(fixed, data, size) != 0)
        one(fixed, size);
    free(fixed);
}

/* The temporary file of fuzz_input_file, removed at exit. */
static char fuzz_path[64];

static inline void fuzz_remove_path(void)
{
    if (fuzz_path[0])
        unlink(fuzz_path);
}

/*
 * Writes the input to /tmp/<who>_<pid>.<ext> (one file per process, rewritten
 * for each input, removed at exit) for readers that take a path; returns it.
 */
static inline const char *fuzz_input_file(const char *who, const char *ext, const uint8_t *data, size_t size)
{
    if (!fuzz_path[0]) {
        snprintf(fuzz_path, sizeof fuzz_path, "/tmp/%s_%d.%s", who, (int)getpid(), ext);
        atexit(fuzz_remove_path);
    }
    FILE *f = fopen(fuzz_path, "wb");
    if (!f || fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
    return fuzz_path;
}

#endif
