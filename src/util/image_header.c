/*
 * Image problems told from the header (see image_header.h). PNG's IHDR is
 * at bytes 16-23 (width, height, big-endian) after the 8-byte signature and
 * the chunk's length and type.
 */
#include <stdint.h>
#include <string.h>
#include <zlib.h>

#include "util/image_header.h"
#include "util/banned.h"

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/*
 * Walks a PNG's chunks (length, type, data, CRC) from byte 8: a file cut off shows as a chunk that
 * runs past the end, or as no IEND. 1 with out filled when the structure is what is wrong.
 */
static int png_structure(FILE *fp, char *out, size_t cap)
{
    if (fseek(fp, 0, SEEK_END) != 0)
        return 0;
    long size = ftell(fp);
    long at = 8;
    int idat = 0;
    while (size >= 0 && at + 8 <= size) {
        unsigned char c[8];
        if (fseek(fp, at, SEEK_SET) != 0 || fread(c, 1, 8, fp) != 8)
            break;
        uint32_t len = be32(c);
        char type[5];
        for (int k = 0; k < 4; k++)
            type[k] = c[4 + k] >= 32 && c[4 + k] < 127 ? (char)c[4 + k] : '?';
        type[4] = '\0';
        if ((long long)len + 12 > (long long)(size - at)) {
            snprintf(out, cap, "cut off: chunk '%s' at byte %ld declares %u bytes, only %ld follow", type, at, len,
                     size - at - 8 > 0 ? size - at - 8 : 0);
            return 1;
        }
        idat |= memcmp(type, "IDAT", 4) == 0;
        if (memcmp(type, "IEND", 4) == 0)
            return 0;
        at += 12 + (long)len;
    }
    snprintf(out, cap, "cut off at byte %ld: %s", size,
             idat ? "no IEND chunk after the image data" : "no image data (IDAT) and no IEND chunk");
    return 1;
}

void asp__image_problem(FILE *fp, const char *stb_reason, unsigned max_side, char *out, size_t cap)
{
    unsigned char h[32];
    rewind(fp);
    size_t n = fread(h, 1, sizeof h, fp);
    rewind(fp);
    const char *reason = stb_reason && *stb_reason ? stb_reason : "damaged image data";
    if (n == 0) {
        snprintf(out, cap, "empty file");
    } else if (n >= 8 && memcmp(h, "\x89PNG\r\n\x1a\n", 8) == 0) {
        if (n < 24 || memcmp(h + 12, "IHDR", 4) != 0) {
            snprintf(out, cap, "PNG signature without a complete IHDR header (%zu bytes)", n);
        } else {
            uint32_t w = be32(h + 16), hh = be32(h + 20);
            if (w == 0 || hh == 0 || w > max_side || hh > max_side)
                snprintf(out, cap, "PNG header says %ux%u, outside the 1..%u pixels a side read here", w, hh,
                         max_side);
            else if (strcmp(reason, "unknown image type") == 0) // stb's PNG test failed on the IHDR itself
                snprintf(out, cap, "PNG of %ux%u that stb_image refuses (too large, or a bad bit depth or colour type)",
                         w, hh);
            else if (png_structure(fp, out, cap))
                ; // out says where the file is cut off
            else if (strcmp(reason, "outofdata") == 0) // stb's words for an inflate that ran out of input
                snprintf(out, cap, "PNG of %ux%u: the compressed image data ends early", w, hh);
            else
                snprintf(out, cap, "PNG of %ux%u: damaged image data (stb_image: %s)", w, hh, reason);
            rewind(fp);
        }
    } else if ((n >= 3 && memcmp(h, "\xff\xd8\xff", 3) == 0) || (n >= 6 && memcmp(h, "GIF8", 4) == 0) ||
               (n >= 2 && memcmp(h, "BM", 2) == 0) || (n >= 4 && memcmp(h, "8BPS", 4) == 0)) {
        snprintf(out, cap, "%s", reason);
    } else if (strcmp(reason, "unknown image type") == 0) {
        snprintf(out, cap, "not an image: no PNG, JPEG, GIF, BMP or PSD signature in its first bytes");
    } else {
        snprintf(out, cap, "%s", reason);
    }
}

/* Bytes per pixel row of a PNG before filtering (with its filter byte); 0 for an unknown colour type. */
static uint64_t png_row_bytes(uint32_t w, unsigned depth, unsigned colour)
{
    unsigned channels = colour == 0 ? 1 : colour == 2 ? 3 : colour == 3 ? 1 : colour == 4 ? 2 : colour == 6 ? 4 : 0;
    return channels ? ((uint64_t)w * channels * depth + 7) / 8 + 1 : 0;
}

/* strict (asp__png_verify): the data must also inflate whole to what the image needs. */
static int png_check(FILE *fp, unsigned max_side, int strict, char *out, size_t cap)
{
    unsigned char h[33];
    rewind(fp);
    size_t n = fread(h, 1, sizeof h, fp);
    int rc = 0;
    if (n < 33 || memcmp(h, "\x89PNG\r\n\x1a\n", 8) != 0 || memcmp(h + 12, "IHDR", 4) != 0)
        goto done; // not a PNG: stb judges it
    uint32_t w = be32(h + 16), hh = be32(h + 20);
    uint64_t row = png_row_bytes(w, h[24], h[25]);
    if (!row || w == 0 || hh == 0 || w > max_side || hh > max_side)
        goto done; // described by asp__image_problem
    // stb allocates what a chunk declares before reading it: 115 bytes declaring 1.7 GB made it take 2 GB
    if (png_structure(fp, out, cap)) {
        rc = 1;
        goto done;
    }
    // Adam7 adds at most one filter byte per pass row and a partial byte per pass: 7 of each per row
    const uint64_t bound = row * hh + (h[28] ? 14 * (uint64_t)hh + 64 : 0);
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit(&z) != Z_OK)
        goto done;
    unsigned char in[16384], sink[65536];
    uint64_t produced = 0;
    long at = 33;
    int zrc = Z_OK;
    while (zrc != Z_STREAM_END && fseek(fp, at, SEEK_SET) == 0) {
        unsigned char c[8];
        if (fread(c, 1, 8, fp) != 8 || memcmp(c + 4, "IEND", 4) == 0)
            break;
        uint32_t len = be32(c);
        at += 12 + (long)len;
        if (memcmp(c + 4, "IDAT", 4) != 0)
            continue;
        while (len > 0 && zrc != Z_STREAM_END) {
            size_t take = len < sizeof in ? len : sizeof in;
            if (fread(in, 1, take, fp) != take)
                break;
            len -= (uint32_t)take;
            z.next_in = in;
            z.avail_in = (uInt)take;
            do {
                z.next_out = sink;
                z.avail_out = sizeof sink;
                zrc = inflate(&z, Z_NO_FLUSH);
                produced += sizeof sink - z.avail_out;
            } while (zrc == Z_OK && z.avail_out == 0 && produced <= bound);
            if (produced > bound) {
                snprintf(out, cap, "PNG of %ux%u: its image data inflates past the %llu bytes such an image holds "
                         "(a decompression bomb)", w, hh, (unsigned long long)bound);
                rc = 1;
                break;
            }
            if (zrc != Z_OK && zrc != Z_STREAM_END)
                break; // damaged data: stb says so
        }
        if (rc)
            break;
        if (strict && zrc != Z_OK && zrc != Z_STREAM_END) {
            snprintf(out, cap, "PNG of %ux%u: damaged image data (zlib: %s)", w, hh, z.msg ? z.msg : "error");
            rc = 1;
            break;
        }
    }
    inflateEnd(&z);
    // non-interlaced images need exactly row * height bytes; Adam7's passes need at least the pixels' own
    if (strict && !rc && (zrc != Z_STREAM_END || produced < (h[28] ? row * hh - hh : row * hh))) {
        snprintf(out, cap, "PNG of %ux%u: its image data %s %llu of the %llu bytes the image needs", w, hh,
                 produced ? "inflates to" : "is missing:", (unsigned long long)produced,
                 (unsigned long long)(row * hh));
        rc = 1;
    }
done:
    rewind(fp);
    return rc;
}

int asp__png_precheck(FILE *fp, unsigned max_side, char *out, size_t cap)
{
    return png_check(fp, max_side, 0, out, cap);
}

int asp__png_verify(FILE *fp, unsigned max_side, char *out, size_t cap)
{
    return png_check(fp, max_side, 1, out, cap);
}
