/*
 * Structural similarity (Wang, Bovik, Sheikh, Simoncelli 2004) on luma with
 * the reference implementation's parameters: 11x11 Gaussian window, sigma
 * 1.5, K1 = 0.01, K2 = 0.03, L = 255, averaged over the "valid" windows
 * (those entirely inside the image), as MATLAB's ssim_index does.
 */
#include <math.h>
#include <stdlib.h>

#include "eval/internal.h"
#include "util/banned.h"

enum { WIN = 11, HALF = 5 };

static void luma(const asp_image *img, double *dst)
{
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = img->pixels + 4 * i;
        dst[i] = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]; /* Rec. 601, as in the SSIM paper's tests */
    }
}

/* Separable Gaussian filter, valid region only: dst is (w-10) x (h-10). */
static void filter_valid(const double *src, uint32_t w, uint32_t h, const double *g, double *tmp, double *dst)
{
    uint32_t ow = w - 2 * HALF, oh = h - 2 * HALF;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < ow; x++) {
            double s = 0;
            for (int k = 0; k < WIN; k++)
                s += g[k] * src[(size_t)y * w + x + k];
            tmp[(size_t)y * ow + x] = s;
        }
    for (uint32_t y = 0; y < oh; y++)
        for (uint32_t x = 0; x < ow; x++) {
            double s = 0;
            for (int k = 0; k < WIN; k++)
                s += g[k] * tmp[(size_t)(y + k) * ow + x];
            dst[(size_t)y * ow + x] = s;
        }
}

int asp_image_ssim(const asp_image *a, const asp_image *b, double *out, asp_error *err)
{
    int rc = asp__image_same_size(a, b, err);
    if (rc)
        return rc;
    uint32_t w = a->width, h = a->height;
    if (w < WIN || h < WIN)
        return asp_error_set(err, ASP_EINVAL, "SSIM needs images of at least %dx%d pixels, got %ux%u", WIN, WIN, w, h);
    double g[WIN], gs = 0;
    for (int k = 0; k < WIN; k++) {
        double d = k - HALF;
        g[k] = exp(-d * d / (2.0 * 1.5 * 1.5));
        gs += g[k];
    }
    for (int k = 0; k < WIN; k++)
        g[k] /= gs;

    size_t n = (size_t)w * h, on = (size_t)(w - 2 * HALF) * (h - 2 * HALF);
    /* x, y, x^2, y^2, xy inputs; their filtered means; one scratch row-pass buffer */
    double *buf = malloc(sizeof(double) * (5 * n + 5 * on + n));
    if (!buf)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for SSIM of %ux%u images", w, h);
    double *x = buf, *y = x + n, *xx = y + n, *yy = xx + n, *xy = yy + n;
    double *mx = xy + n, *my = mx + on, *mxx = my + on, *myy = mxx + on, *mxy = myy + on, *tmp = mxy + on;
    luma(a, x);
    luma(b, y);
    for (size_t i = 0; i < n; i++) {
        xx[i] = x[i] * x[i];
        yy[i] = y[i] * y[i];
        xy[i] = x[i] * y[i];
    }
    filter_valid(x, w, h, g, tmp, mx);
    filter_valid(y, w, h, g, tmp, my);
    filter_valid(xx, w, h, g, tmp, mxx);
    filter_valid(yy, w, h, g, tmp, myy);
    filter_valid(xy, w, h, g, tmp, mxy);
    const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    double sum = 0;
    for (size_t i = 0; i < on; i++) {
        double vx = mxx[i] - mx[i] * mx[i], vy = myy[i] - my[i] * my[i], cxy = mxy[i] - mx[i] * my[i];
        sum += ((2 * mx[i] * my[i] + c1) * (2 * cxy + c2)) /
               ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
    }
    free(buf);
    *out = sum / (double)on;
    return 0;
}
