/*
 * Image problems told from the header (see image_header.h). PNG's IHDR is
 * at bytes 16-23 (width, height, big-endian) after the 8-byte signature and
 * the chunk's length and type.
 */
#include <stdint.h>
#include <string.h>

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
