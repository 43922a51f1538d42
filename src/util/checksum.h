/*
 * CRC-32 (IEEE 802.3) for the checksummed binary formats (.amg, .dps), from
 * zlib rather than a hand-rolled table. Chaining works like zlib's crc32():
 * start with 0 and pass the previous value back in.
 */
#ifndef ASP_UTIL_CHECKSUM_H
#define ASP_UTIL_CHECKSUM_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

uint32_t asp__crc32(uint32_t crc, const void *data, size_t len);

/*
 * FNV-1a 64 of the .hier format (docs/hier.md). Chaining: start with
 * ASP__FNV1A64_START and pass the previous value back in.
 */
#define ASP__FNV1A64_START 0xcbf29ce484222325ULL
uint64_t asp__fnv1a64(uint64_t h, const void *data, size_t len);

/*
 * A file writer that keeps the running CRC-32 of everything written and
 * remembers the first write failure, so format writers check once at the end.
 */
typedef struct asp__crc_writer {
    FILE *fp;
    uint32_t crc;
    int failed;
} asp__crc_writer;

/* Appends len bytes (nothing after a failure). */
void asp__crc_put(asp__crc_writer *w, const void *data, size_t len);

#endif
