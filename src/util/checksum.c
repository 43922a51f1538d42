/*
 * CRC-32 through zlib (see checksum.h); zlib takes uInt lengths, so long
 * buffers go in chunks.
 */
#include <limits.h>
#include <zlib.h>

#include "util/checksum.h"
#include "util/banned.h"

uint32_t asp__crc32(uint32_t crc, const void *data, size_t len)
{
    const unsigned char *p = data;
    uLong c = crc;
    while (len > 0) {
        uInt chunk = len > (size_t)UINT_MAX ? UINT_MAX : (uInt)len;
        c = crc32(c, p, chunk);
        p += chunk;
        len -= chunk;
    }
    return (uint32_t)c;
}

void asp__crc_put(asp__crc_writer *w, const void *data, size_t len)
{
    if (w->failed || len == 0)
        return;
    w->crc = asp__crc32(w->crc, data, len);
    if (fwrite(data, 1, len, w->fp) != len)
        w->failed = 1;
}

uint64_t asp__fnv1a64(uint64_t h, const void *data, size_t len)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < len; i++) {
        h ^= p[i];
        h *= 0x100000001b3ULL; // the 64-bit FNV prime
    }
    return h;
}
