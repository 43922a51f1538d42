/*
 * Peak signal-to-noise ratio over RGB, the simplest of the image-difference
 * metrics the journal's section 6 asks for.
 */
#include <math.h>

#include "eval/internal.h"
#include "util/banned.h"

int asp__image_same_size(const asp_image *a, const asp_image *b, asp_error *err)
{
    if (!a->pixels || !b->pixels)
        return asp_error_set(err, ASP_EINVAL, "cannot compare an empty image");
    if (a->width != b->width || a->height != b->height)
        return asp_error_set(err, ASP_EINVAL, "images differ in size: %ux%u and %ux%u", a->width, a->height,
                             b->width, b->height);
    return 0;
}

int asp_image_psnr(const asp_image *a, const asp_image *b, double *out, asp_error *err)
{
    int rc = asp__image_same_size(a, b, err);
    if (rc)
        return rc;
    size_t n = (size_t)a->width * a->height;
    /* integer sum of squared differences: exact and order independent */
    uint64_t sse = 0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            int d = (int)a->pixels[4 * i + c] - (int)b->pixels[4 * i + c];
            sse += (uint64_t)(d * d);
        }
    if (sse == 0) {
        *out = INFINITY;
        return 0;
    }
    double mse = (double)sse / (3.0 * (double)n);
    *out = 10.0 * log10(255.0 * 255.0 / mse);
    return 0;
}
