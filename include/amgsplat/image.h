/*
 * asp_image: 8-bit RGBA images (sRGB colour, straight alpha) used for
 * textures, renders and image metrics. PNG/JPEG reading goes through
 * stb_image, PNG writing through stb_image_write; files are written to a
 * temporary name and renamed, so a failure never leaves a partial file.
 */
#ifndef AMGSPLAT_IMAGE_H
#define AMGSPLAT_IMAGE_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Caller-owned image; pixels is width * height * 4 bytes, rows top to bottom. */
typedef struct asp_image {
    uint32_t width, height;
    uint8_t *pixels;
} asp_image;

/** Allocates a zeroed (transparent black) image. Returns 0, ASP_EINVAL (zero size) or ASP_ENOMEM. */
int asp_image_init(asp_image *img, uint32_t width, uint32_t height, asp_error *err);
/** Frees the pixels and zeroes img; safe on a zeroed or released image. */
void asp_image_release(asp_image *img);
/** Fills every pixel with one RGBA value. */
void asp_image_fill(asp_image *img, const uint8_t rgba[4]);

/** Loads PNG/JPEG/BMP/TGA into RGBA. Errors name the file and stb's reason. */
int asp_image_load(asp_image *img, const char *path, asp_error *err);
/** Writes a PNG atomically (temporary file + rename). */
int asp_image_save_png(const asp_image *img, const char *path, asp_error *err);

/**
 * Bilinear lookup with wrap-around (OpenGL GL_REPEAT convention: u right, v up,
 * v = 0 is the bottom row). out receives RGBA as floats in 0..255.
 */
void asp_image_sample_bilinear(const asp_image *img, float u, float v, float out[4]);

/**
 * Lays out n equally sized images in a grid of cols columns (cols = 0 picks a
 * near-square grid) into dst (initialised here; release with asp_image_release).
 */
int asp_image_contact_sheet(const asp_image *tiles, size_t n, uint32_t cols, asp_image *dst, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
