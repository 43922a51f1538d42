/*
 * Reading a chart image in tests (src/eval/chart.c draws with PLplot, anti-aliased): colours
 * match within a tolerance, and the plot area is found from its dark frame, so the tests map
 * data to pixels the way the chart does.
 */
#ifndef ASP_TEST_CHART_PROBE_H
#define ASP_TEST_CHART_PROBE_H

#include <stdlib.h>

#include "amgsplat/image.h"

/* The chart's palette colours 0 and 1 (Okabe-Ito blue and vermillion). */
static const uint8_t chart_blue[3] = {0, 114, 178}, chart_vermillion[3] = {213, 94, 0};

/* Pixel (x, y) is within tol (sum of channel differences) of c; 0 outside the image. */
static inline int chart_pixel_is(const asp_image *img, long x, long y, const uint8_t c[3], int tol)
{
    if (x < 0 || y < 0 || x >= (long)img->width || y >= (long)img->height)
        return 0;
    const uint8_t *p = img->pixels + ((size_t)y * img->width + (size_t)x) * 4;
    return abs(p[0] - c[0]) + abs(p[1] - c[1]) + abs(p[2] - c[2]) <= tol;
}

static inline int chart_dark(const asp_image *img, long x, long y)
{
    const uint8_t *p = img->pixels + ((size_t)y * img->width + (size_t)x) * 4;
    return p[0] < 120 && p[1] < 120 && p[2] < 120 && abs(p[0] - p[1]) < 20 && abs(p[1] - p[2]) < 20;
}

/*
 * The plot area's frame: the outermost rows and columns where over 40% of the
 * image's width (height) is dark grey. Returns 0 when no frame is found.
 */
static inline int chart_frame(const asp_image *img, long *x0, long *y0, long *x1, long *y1)
{
    *x0 = *y0 = -1;
    *x1 = *y1 = -1;
    for (long y = 0; y < (long)img->height; y++) {
        long n = 0;
        for (long x = 0; x < (long)img->width; x++)
            n += chart_dark(img, x, y);
        if (n * 10 > (long)img->width * 4) {
            if (*y0 < 0)
                *y0 = y;
            *y1 = y;
        }
    }
    for (long x = 0; x < (long)img->width; x++) {
        long n = 0;
        for (long y = 0; y < (long)img->height; y++)
            n += chart_dark(img, x, y);
        if (n * 10 > (long)img->height * 4) {
            if (*x0 < 0)
                *x0 = x;
            *x1 = x;
        }
    }
    return *x0 >= 0 && *y0 >= 0 && *x1 > *x0 + 20 && *y1 > *y0 + 20;
}

#endif
