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
            else
                snprintf(out, cap, "PNG of %ux%u: %s", w, hh, reason);
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
