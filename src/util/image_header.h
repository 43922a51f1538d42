/*
 * What is wrong with an image file that stb_image refuses, told from its
 * first bytes (issue #13: a 100000x100000 PNG and a text file both got
 * "unknown image type"). Shared by asp_image_load and asp_image_probe.
 * Not public API.
 */
#ifndef ASP_UTIL_IMAGE_HEADER_H
#define ASP_UTIL_IMAGE_HEADER_H

#include <stddef.h>
#include <stdio.h>

/*
 * Writes a description of why fp (rewound first; its position is left at
 * the start) is not a decodable image into out: "empty file", "PNG header
 * says 100000x100000, beyond the 1..16384 pixels a side read here", "not an
 * image: no PNG, JPEG, GIF, BMP or PSD signature", or stb's own reason
 * (passed in) when the header looks right.
 */
void asp__image_problem(FILE *fp, const char *stb_reason, unsigned max_side, char *out, size_t cap);

/*
 * Checks before stb_image decodes a PNG, which allocates what the file
 * declares (fuzz_image: 115 bytes whose IDAT chunk declared 1.7 GB made it
 * allocate 2 GB): every chunk must fit the file, and the image data must not
 * inflate past what the header's size needs (a decompression bomb). Returns
 * 1 with out filled when either fails; 0 otherwise, also for what is not a
 * PNG. fp is rewound.
 */
int asp__png_precheck(FILE *fp, unsigned max_side, char *out, size_t cap);

/*
 * asp__png_precheck, and the image data must inflate without error to the
 * bytes the header's size needs (issue #31: info reported a PNG cut inside
 * its data, or without IDAT, as whole). For 'amgsplat info', which decodes
 * nothing.
 */
int asp__png_verify(FILE *fp, unsigned max_side, char *out, size_t cap);

#endif
