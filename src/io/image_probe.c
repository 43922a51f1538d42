/*
 * What an image file holds without decoding it: size and channel count from
 * stb_image's header reader, for 'amgsplat info' (asp_image_load always gives
 * RGBA, so the file's own channel count would be lost). A PNG's chunks and
 * image data are checked whole too (issue #31): info reports no damaged file
 * as readable.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <stb/stb_image.h>

#include "amgsplat/io.h"
#include "util/image_header.h"
#include "util/regular_file.h"
#include "util/banned.h"

int asp_image_probe(const char *path, asp_image_header *out, asp_error *err)
{
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    int w = 0, h = 0, comp = 0;
    int ok = stbi_info_from_file(fp, &w, &h, &comp);
    char why[160] = "image header out of range";
    if (!ok)
        asp__image_problem(fp, stbi_failure_reason(), 1u << 24, why, sizeof why); // stb_image's own side limit
    else if (asp__png_verify(fp, 1u << 24, why, sizeof why)) // a PNG's structure and data, not only its header
        ok = 0;
    fclose(fp);
    if (!ok || w <= 0 || h <= 0 || comp < 1 || comp > 4)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %s", path, why);
    out->width = (uint32_t)w;
    out->height = (uint32_t)h;
    out->channels = (unsigned)comp;
    return 0;
}
