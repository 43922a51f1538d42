/*
 * RGBA8 images: allocation, file I/O through Debian's libstb (stb_image,
 * stb_image_write; no stb source is copied into the repo), bilinear lookup
 * for texture sampling and contact sheets for multi-view renders.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include "amgsplat/image.h"
#include "util/atomic_file.h"
#include "util/image_header.h"
#include "util/regular_file.h"
#include "util/banned.h"

/* 16k x 16k RGBA is 1 GiB: anything larger is a lying header or a mistake. */
enum { ASP_IMAGE_MAX_SIDE = 16384 };

int asp_image_init(asp_image *img, uint32_t width, uint32_t height, asp_error *err)
{
    ASP_ASSERT(img);
    memset(img, 0, sizeof *img);
    if (width == 0 || height == 0 || width > ASP_IMAGE_MAX_SIDE || height > ASP_IMAGE_MAX_SIDE)
        return asp_error_set(err, ASP_EINVAL, "image size %ux%u is outside 1..%d", width, height, ASP_IMAGE_MAX_SIDE);
    img->pixels = calloc((size_t)width * height, 4);
    if (!img->pixels)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %ux%u image", width, height);
    img->width = width;
    img->height = height;
    return 0;
}

void asp_image_release(asp_image *img)
{
    if (!img)
        return;
    free(img->pixels);
    memset(img, 0, sizeof *img);
}

void asp_image_fill(asp_image *img, const uint8_t rgba[4])
{
    ASP_ASSERT(img && rgba);
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        memcpy(img->pixels + 4 * i, rgba, 4);
}

int asp_image_load(asp_image *img, const char *path, asp_error *err)
{
    ASP_ASSERT(img && path);
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_file(fp, &w, &h, &comp)) {
        char why[160];
        asp__image_problem(fp, stbi_failure_reason(), ASP_IMAGE_MAX_SIDE, why, sizeof why);
        fclose(fp);
        return asp_error_set(err, ASP_EFORMAT, "cannot read image '%s': %s", path, why);
    }
    if (w <= 0 || h <= 0 || w > ASP_IMAGE_MAX_SIDE || h > ASP_IMAGE_MAX_SIDE) {
        fclose(fp);
        return asp_error_set(err, ASP_EFORMAT, "image '%s' is %dx%d, outside 1..%d per side", path, w, h,
                             ASP_IMAGE_MAX_SIDE);
    }
    char bomb[200];
    if (asp__png_precheck(fp, ASP_IMAGE_MAX_SIDE, bomb, sizeof bomb)) {
        fclose(fp);
        return asp_error_set(err, ASP_EFORMAT, "cannot decode image '%s': %s", path, bomb);
    }
    unsigned char *data = stbi_load_from_file(fp, &w, &h, &comp, 4);
    if (!data) {
        char why[160];
        asp__image_problem(fp, stbi_failure_reason(), ASP_IMAGE_MAX_SIDE, why, sizeof why);
        fclose(fp);
        return asp_error_set(err, ASP_EFORMAT, "cannot decode image '%s': %s", path, why);
    }
    fclose(fp);
    memset(img, 0, sizeof *img);
    img->pixels = malloc((size_t)w * h * 4);
    if (!img->pixels) {
        stbi_image_free(data);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for image '%s'", path);
    }
    memcpy(img->pixels, data, (size_t)w * h * 4);
    stbi_image_free(data);
    img->width = (uint32_t)w;
    img->height = (uint32_t)h;
    return 0;
}

static void write_to_file(void *context, void *data, int size)
{
    asp__atomic_file *f = context;
    if (size > 0)
        fwrite(data, 1, (size_t)size, f->fp);
}

int asp_image_save_png(const asp_image *img, const char *path, asp_error *err)
{
    ASP_ASSERT(img && path);
    if (!img->pixels || img->width == 0 || img->height == 0)
        return asp_error_set(err, ASP_EINVAL, "cannot write '%s': the image is empty", path);
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    if (!stbi_write_png_to_func(write_to_file, &f, (int)img->width, (int)img->height, 4, img->pixels,
                                (int)img->width * 4)) {
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_EIO, "cannot encode PNG '%s'", path);
    }
    return asp__atomic_commit(&f, err);
}

static inline int wrap(int i, int n)
{
    i %= n;
    return i < 0 ? i + n : i;
}

void asp_image_sample_bilinear(const asp_image *img, float u, float v, float out[4])
{
    /* texel centres at (i + 0.5) / w, GL_REPEAT; v = 0 is the bottom row (OpenGL) */
    float x = u * (float)img->width - 0.5f;
    float y = (1.0f - v) * (float)img->height - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int x0 = wrap((int)fx, (int)img->width), x1 = wrap((int)fx + 1, (int)img->width);
    int y0 = wrap((int)fy, (int)img->height), y1 = wrap((int)fy + 1, (int)img->height);
    const uint8_t *p00 = img->pixels + 4 * ((size_t)y0 * img->width + x0);
    const uint8_t *p10 = img->pixels + 4 * ((size_t)y0 * img->width + x1);
    const uint8_t *p01 = img->pixels + 4 * ((size_t)y1 * img->width + x0);
    const uint8_t *p11 = img->pixels + 4 * ((size_t)y1 * img->width + x1);
    for (int c = 0; c < 4; c++)
        out[c] = (1 - ay) * ((1 - ax) * p00[c] + ax * p10[c]) + ay * ((1 - ax) * p01[c] + ax * p11[c]);
}

int asp_image_contact_sheet(const asp_image *tiles, size_t n, uint32_t cols, asp_image *dst, asp_error *err)
{
    ASP_ASSERT((tiles || n == 0) && dst);
    if (n == 0)
        return asp_error_set(err, ASP_EINVAL, "contact sheet needs at least one image");
    uint32_t w = tiles[0].width, h = tiles[0].height;
    for (size_t i = 1; i < n; i++)
        if (tiles[i].width != w || tiles[i].height != h)
            return asp_error_set(err, ASP_EINVAL, "contact sheet image %zu is %ux%u, expected %ux%u", i,
                                 tiles[i].width, tiles[i].height, w, h);
    if (cols == 0) {
        /* near-square, preferring a column count that leaves no empty tile (8 views: 4x2, not 3x3) */
        cols = (uint32_t)ceil(sqrt((double)n));
        for (uint32_t c = cols; (double)c <= ceil(sqrt(2.0 * (double)n)); c++)
            if (n % c == 0) {
                cols = c;
                break;
            }
    }
    if (cols > n)
        cols = (uint32_t)n;
    uint32_t rows = (uint32_t)((n + cols - 1) / cols);
    int rc = asp_image_init(dst, w * cols, h * rows, err);
    if (rc)
        return rc;
    /* empty tiles take the first tile's corner colour, which is its background */
    asp_image_fill(dst, tiles[0].pixels);
    for (size_t i = 0; i < n; i++) {
        uint32_t ox = (uint32_t)(i % cols) * w, oy = (uint32_t)(i / cols) * h;
        for (uint32_t y = 0; y < h; y++)
            memcpy(dst->pixels + 4 * ((size_t)(oy + y) * dst->width + ox), tiles[i].pixels + 4 * (size_t)y * w,
                   4 * (size_t)w);
    }
    return 0;
}
