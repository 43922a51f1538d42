/*
 * Image metrics for judging renders (journal section 6 asks for an image
 * difference metric): PSNR, SSIM (Wang et al. 2004, luma, 11x11 Gaussian
 * window, sigma 1.5) and silhouette intersection-over-union.
 */
#ifndef AMGSPLAT_EVAL_H
#define AMGSPLAT_EVAL_H

#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * PSNR in dB over the RGB channels of two equally sized images (alpha is
 * ignored); identical images give INFINITY. Returns 0 or ASP_EINVAL (sizes differ).
 */
int asp_image_psnr(const asp_image *a, const asp_image *b, double *out, asp_error *err);

/**
 * Mean SSIM of the luma (Rec. 601) of two equally sized images, with the
 * standard 11x11 Gaussian window (sigma 1.5), K1 = 0.01, K2 = 0.03, L = 255,
 * over every window position that fits inside the image. 1 for identical
 * images. Images smaller than 11x11 fail with ASP_EINVAL.
 */
int asp_image_ssim(const asp_image *a, const asp_image *b, double *out, asp_error *err);

/**
 * Intersection over union of the foregrounds of a and b. A pixel is foreground
 * when its alpha is non-zero if background is NULL, else when its RGB differs
 * from background's RGB. Two empty foregrounds give 1.
 */
int asp_image_silhouette_iou(const asp_image *a, const asp_image *b, const uint8_t background[3], double *out,
                             asp_error *err);

/** Number of foreground pixels (same rule as asp_image_silhouette_iou). */
size_t asp_image_foreground_count(const asp_image *img, const uint8_t background[3]);

#ifdef __cplusplus
}
#endif
#endif
