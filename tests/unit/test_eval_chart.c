/* Line charts: the series lands where its data says, bad input is refused, output is deterministic. */
#include <math.h>
#include <string.h>

#include "harness.h"
#include "amgsplat/eval.h"
#include "chart_probe.h"

static const uint8_t *const blue = chart_blue; /* palette colour 0 */

/* Mean x of the pixels of colour c in the top and bottom halves of the image; count of such pixels. */
static size_t colour_halves(const asp_image *img, const uint8_t c[3], double *top_x, double *bottom_x)
{
    double sx[2] = {0, 0};
    size_t n[2] = {0, 0};
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = 0; x < img->width; x++) {
            if (chart_pixel_is(img, x, y, c, 30)) {
                int h = y >= img->height / 2;
                sx[h] += x;
                n[h]++;
            }
        }
    *top_x = n[0] ? sx[0] / (double)n[0] : NAN;
    *bottom_x = n[1] ? sx[1] / (double)n[1] : NAN;
    return n[0] + n[1];
}

static void test_rising_and_falling(void)
{
    double x[5] = {1, 2, 3, 4, 5}, up[5] = {1, 2, 3, 4, 5}, down[5] = {5, 4, 3, 2, 1};
    asp_image a = {0}, b = {0};
    asp_chart_series s = {.name = NULL, .x = x, .y = up, .count = 5};
    CHECK_OK(asp_chart_draw(&s, 1, NULL, &a, NULL), (asp_error *)NULL);
    CHECK(a.width == 560 && a.height == 340);
    double top, bottom;
    CHECK(colour_halves(&a, blue, &top, &bottom) > 100);
    CHECK_MSG(top > bottom + 100, "rising line: top half x %.1f, bottom half x %.1f", top, bottom);
    s.y = down;
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = 300, .height = 200}, &b, NULL), (asp_error *)NULL);
    CHECK(b.width == 300 && b.height == 200);
    CHECK(colour_halves(&b, blue, &top, &bottom) > 50);
    CHECK_MSG(top + 60 < bottom, "falling line: top half x %.1f, bottom half x %.1f", top, bottom);
    asp_image_release(&a);
    asp_image_release(&b);
}

static void test_nan_skipped_and_background(void)
{
    double x[3] = {1, 2, 3}, y[3] = {NAN, NAN, NAN};
    asp_chart_series s = {.x = x, .y = y, .count = 3};
    asp_image img = {0};
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.title = "t", .x_label = "x", .y_label = "y"}, &img, NULL),
             (asp_error *)NULL);
    double top, bottom;
    CHECK(colour_halves(&img, blue, &top, &bottom) == 0);
    /* the corner is white and opaque */
    CHECK(img.pixels[0] == 255 && img.pixels[1] == 255 && img.pixels[2] == 255 && img.pixels[3] == 255);
    asp_image_release(&img);
}

static void test_legend_and_log(void)
{
    double x[4] = {8, 40, 200, 1000}, y1[4] = {0.5, 0.6, 0.7, 0.8}, y2[4] = {0.9, 0.9, 0.92, 0.95};
    asp_chart_series s[2] = {{"points", x, y1, 4}, {"dp", x, y2, 4}};
    asp_image a = {0}, b = {0};
    asp_chart_desc d = {.flags = ASP_CHART_LOG_X, .y_min = 0, .y_max = 1};
    CHECK_OK(asp_chart_draw(s, 2, &d, &a, NULL), (asp_error *)NULL);
    CHECK_OK(asp_chart_draw(s, 2, &d, &b, NULL), (asp_error *)NULL);
    CHECK(memcmp(a.pixels, b.pixels, (size_t)a.width * a.height * 4) == 0);
    const uint8_t *red = chart_vermillion; /* palette colour 1: the second series */
    double top, bottom;
    CHECK(colour_halves(&a, red, &top, &bottom) > 50);
    /* y in 0..1: the second series (0.9 .. 0.95) lies in the top half only */
    double top1, bottom1;
    colour_halves(&a, red, &top1, &bottom1);
    CHECK(isnan(bottom1));
    asp_image_release(&a);
    asp_image_release(&b);
}

static void test_bad_input(void)
{
    asp_image img = {0};
    asp_error err = {0};
    double x[2] = {1, 2};
    CHECK(asp_chart_draw(NULL, 0, &(asp_chart_desc){.width = 100}, &img, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "100x") != NULL);
    CHECK(asp_chart_draw(NULL, 0, &(asp_chart_desc){.width = 5000}, &img, &err) == ASP_EINVAL);
    asp_chart_series s = {.name = "broken", .x = x, .y = NULL, .count = 2};
    CHECK(asp_chart_draw(&s, 1, NULL, &img, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "'broken'") != NULL);
    CHECK(img.pixels == NULL && img.width == 0);
    /* no series: axes only */
    CHECK_OK(asp_chart_draw(NULL, 0, NULL, &img, &err), &err);
    asp_image_release(&img);
}

TEST_MAIN(TEST_CASE(test_rising_and_falling), TEST_CASE(test_nan_skipped_and_background),
          TEST_CASE(test_legend_and_log), TEST_CASE(test_bad_input))
