/*
 * The chart kinds the experiment report draws (src/eval/chart.c): markers
 * without lines (seed 004 Fig 4.1 as a scatter), error bars, histogram bars
 * (Figs 4.2-4.5) and whole-number x ticks. Pixels are checked at the places
 * the plot maps the data to (the plot area found from its frame, chart_probe.h).
 */
#include "amgsplat/eval.h"
#include "chart_probe.h"
#include "harness.h"

static int is_blue(const asp_image *img, long x, long y)
{
    return chart_pixel_is(img, x, y, chart_blue, 40); // palette colour 0
}

/* Any blue pixel within r of (x, y). */
static int blue_near(const asp_image *img, long x, long y, long r)
{
    for (long dy = -r; dy <= r; dy++)
        for (long dx = -r; dx <= r; dx++)
            if (is_blue(img, x + dx, y + dy))
                return 1;
    return 0;
}

enum { W = 400, H = 300 };

/* The plot area of the last chart framed (frame()). */
static long X0, X1, Y0, Y1;

static int frame(const asp_image *img)
{
    int ok = chart_frame(img, &X0, &Y0, &X1, &Y1);
    CHECK_MSG(ok, "no plot frame found in the %ux%u chart", img->width, img->height);
    return ok;
}

static long map(double v, double lo, double hi, long p0, long p1)
{
    return p0 + lrint((v - lo) / (hi - lo) * (double)(p1 - p0));
}

static void test_markers_only(void)
{
    const double x[2] = {0, 1}, y[2] = {0, 1};
    asp_chart_series s = {.x = x, .y = y, .count = 2};
    asp_image lines = {0}, dots = {0};
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = W, .height = H}, &lines, NULL), (asp_error *)NULL);
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = W, .height = H, .flags = ASP_CHART_MARKERS}, &dots, NULL),
             (asp_error *)NULL);
    if (!frame(&lines))
        return;
    // the middle of the segment: drawn as a line, empty as a scatter; the markers in both
    long mx = (X0 + X1) / 2, my = (Y0 + Y1) / 2;
    CHECK(blue_near(&lines, mx, my, 2));
    CHECK(!blue_near(&dots, mx, my, 4));
    long ex = map(1, -0.05, 1.05, X0, X1), ey = map(1, 1.05, -0.05, Y0, Y1);
    CHECK(blue_near(&dots, ex, ey, 3) && blue_near(&lines, ex, ey, 3));
    asp_image_release(&lines);
    asp_image_release(&dots);
}

static void test_error_bars_widen_the_range(void)
{
    const double x[2] = {0, 1}, y[2] = {1, 1}, e[2] = {5, 5};
    const double *errs[1] = {e};
    asp_chart_series s = {.x = x, .y = y, .count = 2};
    asp_image img = {0};
    CHECK_OK(asp_chart_draw(&s, 1,
                            &(asp_chart_desc){.width = W, .height = H, .flags = ASP_CHART_MARKERS, .y_err = errs}, &img,
                            NULL),
             (asp_error *)NULL);
    if (!frame(&img))
        return;
    // y range -4..6 padded by 5%: the bar of the first point reaches y = 5 and -3
    double lo = -4 - 0.5, hi = 6 + 0.5;
    long bx = map(0, -0.05, 1.05, X0, X1) + 1;
    CHECK(blue_near(&img, bx, map(5, hi, lo, Y0, Y1), 1));
    CHECK(blue_near(&img, bx, map(-3, hi, lo, Y0, Y1), 1));
    // nothing blue between the two points: markers only
    CHECK(!blue_near(&img, (X0 + X1) / 2, map(1, hi, lo, Y0, Y1), 4));
    asp_image_release(&img);
}

static void test_bars(void)
{
    const double x[3] = {0, 1, 2}, y[3] = {1, 2, 3};
    asp_chart_series s = {.x = x, .y = y, .count = 3};
    asp_image img = {0};
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = W, .height = H, .flags = ASP_CHART_BARS}, &img, NULL),
             (asp_error *)NULL);
    if (!frame(&img))
        return;
    // x range -0.5..2.5 (half a slot each side) padded by 5%, y from 0 (bars stand on the axis) to 3 + 5%
    const double xl = -0.65, xh = 2.65;
    long bx = map(2, xl, xh, X0, X1);
    CHECK(is_blue(&img, bx, Y1 - 3));                                    // the bottom of the tallest bar
    CHECK(is_blue(&img, bx, map(2.9, 3.15, 0, Y0, Y1)));                 // near its top
    CHECK(!is_blue(&img, bx, map(3.1, 3.15, 0, Y0, Y1)));                // above its top
    CHECK(!is_blue(&img, map(0, xl, xh, X0, X1), map(1.5, 3.15, 0, Y0, Y1))); // above the first bar
    CHECK(!is_blue(&img, map(0.5, xl, xh, X0, X1), Y1 - 3));             // the gap between bars
    asp_image_release(&img);
}

static void test_integer_ticks(void)
{
    // 0.9..2.1 would get ticks every 0.2; whole numbers only: fewer tick labels, so fewer dark pixels
    const double x[2] = {0.9, 2.1}, y[2] = {0, 1};
    asp_chart_series s = {.x = x, .y = y, .count = 2};
    asp_image a = {0}, b = {0};
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = W, .height = H}, &a, NULL), (asp_error *)NULL);
    CHECK_OK(asp_chart_draw(&s, 1, &(asp_chart_desc){.width = W, .height = H, .flags = ASP_CHART_X_INTEGER}, &b, NULL),
             (asp_error *)NULL);
    if (!frame(&a))
        return;
    size_t ink_a = 0, ink_b = 0;
    for (long yy = Y1 + 4; yy < Y1 + 20; yy++) // the x tick labels' row
        for (long xx = 0; xx < W; xx++) {
            ink_a += a.pixels[((size_t)yy * W + (size_t)xx) * 4] < 100;
            ink_b += b.pixels[((size_t)yy * W + (size_t)xx) * 4] < 100;
        }
    CHECK_MSG(ink_b > 0 && ink_b * 2 < ink_a, "label ink %zu with whole-number ticks, %zu without", ink_b, ink_a);
    asp_image_release(&a);
    asp_image_release(&b);
}

TEST_MAIN(TEST_CASE(test_markers_only), TEST_CASE(test_error_bars_widen_the_range), TEST_CASE(test_bars),
          TEST_CASE(test_integer_ticks))
