/*
 * Charts and sheets explain themselves (issue 29): a chart saved as PNG has a
 * legend with every series' colour in it, clearly distinct colours, at least 3
 * ticks on each axis (a single point, a constant series and a narrow log axis
 * too), a horizontal y label, and says "no data" rather than nothing; a
 * labelled contact sheet keeps its tiles and writes its labels in the margins.
 */
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/eval.h"
#include "amgsplat/image.h"
#include "chart_probe.h"
#include "harness.h"

enum { W = 640, H = 380 };

/* Series colours 0..2 of the palette (Okabe-Ito blue, vermillion, bluish green). */
static const uint8_t green[3] = {0, 158, 115};

static size_t count_colour(const asp_image *img, long x0, long y0, long x1, long y1, const uint8_t c[3])
{
    size_t n = 0;
    for (long y = y0; y < y1; y++)
        for (long x = x0; x < x1; x++)
            n += chart_pixel_is(img, x, y, c, 30);
    return n;
}

/* Runs of dark pixels along a row (dx 1) or a column (dy 1) from (x, y), n pixels: the tick marks. */
static int dark_runs(const asp_image *img, long x, long y, long dx, long dy, long n)
{
    int runs = 0, in = 0;
    for (long i = 0; i < n; i++) {
        int d = chart_dark(img, x + i * dx, y + i * dy);
        runs += d && !in;
        in = d;
    }
    return runs;
}

/* Tick marks on the bottom and left edges of the plot (drawn 5 pixels inwards from the frame). */
static void tick_counts(const asp_image *img, int *nx, int *ny)
{
    long x0, y0, x1, y1;
    *nx = *ny = 0;
    if (!chart_frame(img, &x0, &y0, &x1, &y1))
        return;
    *nx = dark_runs(img, x0 + 2, y1 - 3, 1, 0, x1 - x0 - 3);
    *ny = dark_runs(img, x0 + 3, y0 + 2, 0, 1, y1 - y0 - 3);
}

static void test_saved_chart_legend_and_colours(void)
{
    double x[5] = {10, 100, 1000, 10000, 100000};
    double y[3][5] = {{0.9, 0.8, 0.7, 0.6, 0.5}, {0.5, 0.55, 0.6, 0.65, 0.7}, {0.2, 0.3, 0.3, 0.35, 0.4}};
    asp_chart_series s[3] = {{"points", x, y[0], 5}, {"dp-normalized", x, y[1], 5}, {"hybrid", x, y[2], 5}};
    asp_image img = {0}, back = {0};
    CHECK_OK(asp_chart_draw(s, 3,
                            &(asp_chart_desc){.width = W,
                                              .height = H,
                                              .title = "SSIM against primitives",
                                              .x_label = "primitives",
                                              .y_label = "SSIM (1 = identical)",
                                              .flags = ASP_CHART_LOG_X},
                            &img, NULL),
             (asp_error *)NULL);
    char path[256];
    snprintf(path, sizeof path, "/tmp/asp_test_chart_%d.png", (int)getpid());
    CHECK_OK(asp_image_save_png(&img, path, NULL), (asp_error *)NULL);
    FILE *f = fopen(path, "rb");
    long bytes = 0;
    if (f) {
        fseek(f, 0, SEEK_END);
        bytes = ftell(f);
        fclose(f);
    }
    CHECK_MSG(bytes > 5000, "the chart's PNG has %ld bytes", bytes);
    CHECK_OK(asp_image_load(&back, path, NULL), (asp_error *)NULL);
    remove(path);
    CHECK(back.width == W && back.height == H);
    long x0, y0, x1, y1;
    CHECK(chart_frame(&back, &x0, &y0, &x1, &y1));
    // the legend, right of the plot: ink (the names) and each series' colour
    size_t ink = 0;
    for (long yy = y0; yy < y1; yy++)
        for (long xx = x1 + 4; xx < W; xx++)
            ink += chart_dark(&back, xx, yy);
    CHECK_MSG(ink > 100, "legend area: %zu dark pixels", ink);
    const uint8_t *colours[3] = {chart_blue, chart_vermillion, green};
    for (int k = 0; k < 3; k++) {
        size_t in_legend = count_colour(&back, x1 + 4, y0, W, y1, colours[k]);
        size_t in_plot = count_colour(&back, x0 + 1, y0 + 1, x1, y1, colours[k]);
        CHECK_MSG(in_legend > 10 && in_plot > 100, "series %d: %zu pixels in the legend, %zu in the plot", k,
                  in_legend, in_plot);
    }
    // clearly distinct: every pair differs by over 100 in summed channels
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++) {
            int d = abs(colours[a][0] - colours[b][0]) + abs(colours[a][1] - colours[b][1]) +
                    abs(colours[a][2] - colours[b][2]);
            CHECK_MSG(d > 100, "colours %d and %d differ by %d", a, b, d);
        }
    int nx, ny;
    tick_counts(&back, &nx, &ny);
    CHECK_MSG(nx >= 3 && ny >= 3, "ticks: %d on x, %d on y", nx, ny);
    // the y label is horizontal, above the plot: its ink is wider than tall
    long lx0 = W, lx1 = -1, ly0 = H, ly1 = -1;
    for (long yy = y0 - 28; yy < y0 - 9; yy++)
        for (long xx = 0; xx < x0 + 200; xx++)
            if (yy >= 0 && chart_dark(&back, xx, yy)) {
                lx0 = xx < lx0 ? xx : lx0;
                lx1 = xx > lx1 ? xx : lx1;
                ly0 = yy < ly0 ? yy : ly0;
                ly1 = yy > ly1 ? yy : ly1;
            }
    CHECK_MSG(lx1 - lx0 > 5 * (ly1 - ly0 + 1), "y label ink %ld..%ld x %ld..%ld", lx0, lx1, ly0, ly1);
    asp_image_release(&img);
    asp_image_release(&back);
}

/* A single point, a constant series and a log axis under a decade: still 3 ticks on each axis. */
static void test_three_ticks_always(void)
{
    double one_x[1] = {5}, one_y[1] = {2}, cx[4] = {1, 2, 3, 4}, cy[4] = {7, 7, 7, 7};
    double lx[3] = {1200, 1500, 1900}, ly[3] = {3, 3.5, 4};
    struct {
        asp_chart_series s;
        unsigned flags;
        const char *what;
    } cases[5] = {
        {{"one", one_x, one_y, 1}, 0, "single point"},
        {{"one", one_x, one_y, 1}, ASP_CHART_LOG_X | ASP_CHART_LOG_Y, "single point, log-log"},
        {{"flat", cx, cy, 4}, 0, "constant series"},
        {{"narrow", lx, ly, 3}, ASP_CHART_LOG_X | ASP_CHART_LOG_Y, "log axes under a decade"},
        {{"categories", cx, cy, 2}, ASP_CHART_X_INTEGER | ASP_CHART_MARKERS, "whole-number x over 1..2"},
    };
    for (int i = 0; i < 5; i++) {
        asp_image img = {0};
        CHECK_OK(asp_chart_draw(&cases[i].s, 1,
                                &(asp_chart_desc){.title = cases[i].what, .x_label = "x (m)", .y_label = "y (s)",
                                                  .flags = cases[i].flags},
                                &img, NULL),
                 (asp_error *)NULL);
        int nx, ny;
        tick_counts(&img, &nx, &ny);
        CHECK_MSG(nx >= 3 && ny >= 3, "%s: %d x ticks, %d y ticks", cases[i].what, nx, ny);
        asp_image_release(&img);
    }
}

/* All NaN, or no series: the axes and a message in the plot, no crash. */
static void test_no_data_message(void)
{
    double x[3] = {1, 2, 3}, y[3] = {NAN, NAN, NAN};
    asp_chart_series s = {"broken", x, y, 3};
    for (int k = 0; k < 2; k++) {
        asp_image img = {0};
        asp_error err = {0};
        CHECK_OK(asp_chart_draw(k ? NULL : &s, k ? 0 : 1, NULL, &img, &err), &err);
        long x0, y0, x1, y1;
        CHECK(chart_frame(&img, &x0, &y0, &x1, &y1));
        long cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
        size_t ink = 0;
        for (long yy = cy - 10; yy < cy + 10; yy++)
            for (long xx = cx - 60; xx < cx + 60; xx++)
                ink += chart_dark(&img, xx, yy);
        CHECK_MSG(ink > 30, "no-data message: %zu dark pixels in the middle of the plot", ink);
        asp_image_release(&img);
    }
}

struct draw_job {
    asp_image img;
    int rc;
};

static void *draw_one(void *arg)
{
    struct draw_job *j = arg;
    double x[3] = {1, 2, 3}, y[3] = {1, 4, 9};
    asp_chart_series s = {"squares", x, y, 3};
    j->rc = asp_chart_draw(&s, 1, &(asp_chart_desc){.title = "t", .x_label = "x", .y_label = "y"}, &j->img, NULL);
    return NULL;
}

/* PLplot keeps global state: charts drawn on 4 threads at once equal the one drawn alone. */
static void test_threads(void)
{
    struct draw_job alone = {0}, jobs[4];
    memset(jobs, 0, sizeof jobs);
    draw_one(&alone);
    CHECK(alone.rc == 0);
    pthread_t t[4];
    for (int i = 0; i < 4; i++)
        CHECK(pthread_create(&t[i], NULL, draw_one, &jobs[i]) == 0);
    for (int i = 0; i < 4; i++) {
        pthread_join(t[i], NULL);
        CHECK(jobs[i].rc == 0 && jobs[i].img.pixels &&
              memcmp(jobs[i].img.pixels, alone.img.pixels, (size_t)alone.img.width * alone.img.height * 4) == 0);
        asp_image_release(&jobs[i].img);
    }
    asp_image_release(&alone.img);
}

static void test_labelled_sheet(void)
{
    // 2 rows x 3 columns of 40x40 tiles, each a flat colour (row r, column c: (40 r + 1, 70 c + 2, 200))
    asp_image grid = {0}, out = {0};
    CHECK_OK(asp_image_init(&grid, 120, 80, NULL), (asp_error *)NULL);
    for (uint32_t y = 0; y < 80; y++)
        for (uint32_t x = 0; x < 120; x++) {
            uint8_t *p = grid.pixels + ((size_t)y * 120 + x) * 4;
            p[0] = (uint8_t)(40 * (y / 40) + 1);
            p[1] = (uint8_t)(70 * (x / 40) + 2);
            p[2] = 200;
            p[3] = (uint8_t)(x == 0 && y == 0 ? 0 : 255); // one transparent pixel, kept
        }
    const char *rows[2] = {"points", "dp-normalized"}, *cols[3] = {"reference", "level L-1\n12 primitives", "level L"};
    CHECK_OK(asp_chart_label_sheet(&grid,
                                   &(asp_chart_sheet_desc){.title = "view 0", .row_count = 2, .col_count = 3,
                                                           .row_labels = rows, .col_labels = cols},
                                   &out, NULL),
             (asp_error *)NULL);
    CHECK(out.width > 120 + 60 && out.height > 80 + 30);
    // every tile is there, whole: find its top-left pixel, then compare the tile
    long ox = -1, oy = -1;
    for (long y = 0; y < (long)out.height && ox < 0; y++)
        for (long x = 0; x < (long)out.width; x++) {
            const uint8_t *p = out.pixels + ((size_t)y * out.width + (size_t)x) * 4;
            if (p[0] == 1 && p[1] == 2 && p[2] == 200 && p[3] == 0) {
                ox = x;
                oy = y;
                break;
            }
        }
    CHECK_MSG(ox > 40 && oy > 20, "first tile at %ld, %ld", ox, oy);
    size_t ink_left = 0, ink_top = 0;
    for (long y = 0; ox > 0 && y < (long)out.height; y++)
        for (long x = 0; x < (long)out.width; x++) {
            if (!chart_dark(&out, x, y))
                continue;
            ink_left += x < ox - 2 && y >= oy;
            ink_top += y < oy - 2 && x >= ox;
        }
    CHECK_MSG(ink_left > 50 && ink_top > 100, "label ink: %zu left of the tiles, %zu above", ink_left, ink_top);
    asp_error err = {0};
    asp_image bad = {0};
    CHECK(asp_chart_label_sheet(&grid, &(asp_chart_sheet_desc){.row_count = 3, .col_count = 3}, &bad, &err) ==
          ASP_EINVAL);
    CHECK(strstr(err.msg, "3 rows") != NULL && bad.pixels == NULL);
    asp_image_release(&grid);
    asp_image_release(&out);
}

TEST_MAIN(TEST_CASE(test_saved_chart_legend_and_colours), TEST_CASE(test_three_ticks_always),
          TEST_CASE(test_no_data_message), TEST_CASE(test_threads), TEST_CASE(test_labelled_sheet))
