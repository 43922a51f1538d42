/* Image metrics: PSNR, SSIM and silhouette IoU against known values. */
#include <unistd.h>

#include "harness.h"
#include "amgsplat/eval.h"

static void make_pattern(asp_image *img, uint32_t w, uint32_t h, int seed)
{
    asp_image_init(img, w, h, NULL);
    unsigned s = (unsigned)seed * 2654435761u + 1;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        s = s * 1664525u + 1013904223u;
        uint8_t v = (uint8_t)(((i % w) * 3 + (i / w) * 5 + (s >> 28)) & 0xff);
        img->pixels[4 * i + 0] = v;
        img->pixels[4 * i + 1] = v;
        img->pixels[4 * i + 2] = (uint8_t)(v / 2);
        img->pixels[4 * i + 3] = 255;
    }
}

static void test_identical(void)
{
    asp_image a;
    make_pattern(&a, 64, 48, 1);
    double psnr = 0, ssim = 0, iou = 0;
    CHECK_OK(asp_image_psnr(&a, &a, &psnr, NULL), (asp_error *)NULL);
    CHECK(isinf(psnr) && psnr > 0);
    CHECK_OK(asp_image_ssim(&a, &a, &ssim, NULL), (asp_error *)NULL);
    CHECK_NEAR(ssim, 1.0, 1e-12);
    CHECK_OK(asp_image_silhouette_iou(&a, &a, NULL, &iou, NULL), (asp_error *)NULL);
    CHECK_NEAR(iou, 1.0, 0);
    asp_image_release(&a);
}

static void test_psnr_known(void)
{
    /* every channel off by 5: MSE = 25, PSNR = 10 log10(255^2 / 25) = 34.151 dB */
    asp_image a, b;
    make_pattern(&a, 32, 32, 2);
    make_pattern(&b, 32, 32, 2);
    for (size_t i = 0; i < 32 * 32; i++)
        for (int c = 0; c < 3; c++)
            b.pixels[4 * i + c] = (uint8_t)(a.pixels[4 * i + c] >= 128 ? a.pixels[4 * i + c] - 5 : a.pixels[4 * i + c] + 5);
    double psnr = 0;
    CHECK_OK(asp_image_psnr(&a, &b, &psnr, NULL), (asp_error *)NULL);
    CHECK_NEAR(psnr, 10.0 * log10(255.0 * 255.0 / 25.0), 1e-9);
    asp_image_release(&a);
    asp_image_release(&b);
}

static void test_ssim_properties(void)
{
    asp_image a, b, c;
    make_pattern(&a, 64, 64, 3);
    make_pattern(&b, 64, 64, 4); /* different noise: still similar structure */
    asp_image_init(&c, 64, 64, NULL);
    uint8_t grey[4] = {128, 128, 128, 255};
    asp_image_fill(&c, grey);
    double sab = 0, sba = 0, sac = 0;
    CHECK_OK(asp_image_ssim(&a, &b, &sab, NULL), (asp_error *)NULL);
    CHECK_OK(asp_image_ssim(&b, &a, &sba, NULL), (asp_error *)NULL);
    CHECK_OK(asp_image_ssim(&a, &c, &sac, NULL), (asp_error *)NULL);
    CHECK_NEAR(sab, sba, 1e-12); /* symmetric */
    CHECK(sab < 1.0 && sab > 0.5);
    CHECK_MSG(sac < 0.5 && sac < sab - 0.3, "flat %g vs noisy %g", sac, sab); /* a flat image keeps none of the structure */
    /* a constant brightness shift keeps structure: SSIM stays high but below 1 */
    for (size_t i = 0; i < 64 * 64; i++)
        for (int k = 0; k < 3; k++)
            b.pixels[4 * i + k] = (uint8_t)(a.pixels[4 * i + k] / 2 + 20);
    double shifted = 0;
    CHECK_OK(asp_image_ssim(&a, &b, &shifted, NULL), (asp_error *)NULL);
    CHECK(shifted < 0.999 && shifted > sac);
    asp_image_release(&a);
    asp_image_release(&b);
    asp_image_release(&c);
}

static void test_errors(void)
{
    asp_image a, b;
    asp_error err = {0};
    make_pattern(&a, 16, 16, 5);
    make_pattern(&b, 16, 17, 5);
    double v;
    CHECK(asp_image_psnr(&a, &b, &v, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "16x17") != NULL);
    asp_image_release(&b);
    make_pattern(&b, 8, 8, 5);
    asp_image c;
    make_pattern(&c, 8, 8, 6);
    CHECK(asp_image_ssim(&b, &c, &v, &err) == ASP_EINVAL);
    asp_image_release(&a);
    asp_image_release(&b);
    asp_image_release(&c);
}

static void test_iou(void)
{
    /* two overlapping squares on a white background: 8x8 and 8x8 shifted by 4: I = 32, U = 96 */
    asp_image a, b;
    uint8_t white[4] = {255, 255, 255, 255}, bg[3] = {255, 255, 255};
    asp_image_init(&a, 32, 32, NULL);
    asp_image_init(&b, 32, 32, NULL);
    asp_image_fill(&a, white);
    asp_image_fill(&b, white);
    for (int y = 8; y < 16; y++)
        for (int x = 8; x < 16; x++) {
            memset(a.pixels + 4 * (y * 32 + x), 0, 3);
            memset(b.pixels + 4 * (y * 32 + x + 4), 0, 3);
        }
    double iou = 0;
    CHECK_OK(asp_image_silhouette_iou(&a, &b, bg, &iou, NULL), (asp_error *)NULL);
    CHECK_NEAR(iou, 32.0 / 96.0, 1e-12);
    CHECK(asp_image_foreground_count(&a, bg) == 64);
    asp_image_release(&a);
    asp_image_release(&b);
}

/* Disc of radius 20 about (32, 32) and the square [30, 64)^2, pixel centres tested: the silhouettes below. */
static int in_disc(int x, int y)
{
    double dx = x + 0.5 - 32, dy = y + 0.5 - 32;
    return dx * dx + dy * dy <= 400;
}

static int in_square(int x, int y)
{
    return x >= 30 && y >= 30;
}

/* A shaded shape on a flat background; transparent: alpha 0 (and black) off the shape instead. */
static void draw(asp_image *img, int (*inside)(int, int), const uint8_t bg[3], int transparent)
{
    asp_image_init(img, 64, 64, NULL);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            uint8_t *p = img->pixels + 4 * (y * 64 + x);
            if (inside(x, y)) {
                p[0] = (uint8_t)(40 + 2 * x), p[1] = (uint8_t)(30 + y), p[2] = 90, p[3] = 255;
            } else if (transparent) {
                memset(p, 0, 4);
            } else {
                memcpy(p, bg, 3);
                p[3] = 255;
            }
        }
}

/*
 * Issue 12: with a white background imgdiff reported IoU 1.000 for two clearly
 * different silhouettes (alpha is 255 everywhere). The silhouette of an opaque
 * image now comes from its background colour, detected from the corners or
 * given; alpha still rules when an image has any. Expected values by counting.
 */
static void test_silhouettes(void)
{
    size_t both = 0, any = 0, disc = 0, square = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            both += (size_t)(in_disc(x, y) && in_square(x, y));
            any += (size_t)(in_disc(x, y) || in_square(x, y));
            disc += (size_t)in_disc(x, y);
            square += (size_t)in_square(x, y);
        }
    const double want = (double)both / (double)any;
    CHECK(want > 0.1 && want < 0.5); /* clearly different shapes */
    const uint8_t white[3] = {255, 255, 255}, black[3] = {0, 0, 0}, red[3] = {255, 0, 0};
    asp_image a, b;
    draw(&a, in_disc, white, 0);
    draw(&b, in_square, white, 0);
    /* an antialiased background pixel, off both shapes: within the default tolerance of white */
    memset(a.pixels + 4 * (32 * 64 + 2), 250, 3);
    double iou = 0, old = 0;
    asp_silhouette_info info[2];
    CHECK_OK(asp_image_silhouette_iou(&a, &b, NULL, &old, NULL), (asp_error *)NULL);
    CHECK(old == 1); /* alpha alone sees two full frames: the bug */
    CHECK_OK(asp_image_silhouettes(&a, &b, NULL, &iou, info, NULL), (asp_error *)NULL);
    CHECK_NEAR(iou, want, 1e-12);
    CHECK(info[0].source == ASP_SILHOUETTE_CORNERS && info[1].source == ASP_SILHOUETTE_CORNERS);
    CHECK(memcmp(info[0].background, white, 3) == 0 && memcmp(info[1].background, white, 3) == 0);
    /* the square covers the bottom-right corner: three of four corners still name the background */
    CHECK(info[0].corners_agreeing == 4 && info[1].corners_agreeing == 3);
    CHECK(info[0].foreground == disc && info[1].foreground == square);
    CHECK(strcmp(asp_silhouette_source_name(info[0].source), "corners") == 0);
    /* exact matching counts the antialiased pixel as silhouette: one more in a and in the union */
    CHECK_OK(asp_image_silhouettes(&a, &b, &(asp_silhouette_desc){.tolerance = -1}, &iou, info, NULL),
             (asp_error *)NULL);
    CHECK_NEAR(iou, (double)both / (double)(any + 1), 1e-12);
    CHECK(info[0].foreground == disc + 1);
    /* a given background: the same result for the right colour; the wrong one makes everything silhouette */
    CHECK_OK(asp_image_silhouettes(&a, &b, &(asp_silhouette_desc){.background = white}, &iou, info, NULL),
             (asp_error *)NULL);
    CHECK_NEAR(iou, want, 1e-12);
    CHECK(info[0].source == ASP_SILHOUETTE_BACKGROUND && info[1].source == ASP_SILHOUETTE_BACKGROUND);
    CHECK_OK(asp_image_silhouettes(&a, &b, &(asp_silhouette_desc){.background = red}, &iou, info, NULL),
             (asp_error *)NULL);
    CHECK_NEAR(iou, 1.0, 1e-12);
    asp_image_release(&a);
    asp_image_release(&b);
    /* a black background is detected as such */
    draw(&a, in_disc, black, 0);
    draw(&b, in_square, black, 0);
    CHECK_OK(asp_image_silhouettes(&a, &b, NULL, &iou, info, NULL), (asp_error *)NULL);
    CHECK_NEAR(iou, want, 1e-12);
    CHECK(memcmp(info[0].background, black, 3) == 0 && memcmp(info[1].background, black, 3) == 0);
    asp_image_release(&b);
    /* alpha rules when an image has it, even with a background given; the other image keeps its colour rule */
    draw(&b, in_square, white, 1);
    CHECK_OK(asp_image_silhouettes(&a, &b, &(asp_silhouette_desc){.background = black}, &iou, info, NULL),
             (asp_error *)NULL);
    CHECK_NEAR(iou, want, 1e-12);
    CHECK(info[0].source == ASP_SILHOUETTE_BACKGROUND && info[1].source == ASP_SILHOUETTE_ALPHA);
    CHECK(info[1].foreground == square);
    asp_image_release(&a);
    draw(&a, in_disc, white, 1);
    CHECK_OK(asp_image_silhouettes(&a, &b, NULL, &iou, info, NULL), (asp_error *)NULL);
    CHECK_NEAR(iou, want, 1e-12);
    CHECK(info[0].source == ASP_SILHOUETTE_ALPHA && info[1].source == ASP_SILHOUETTE_ALPHA);
    CHECK(strcmp(asp_silhouette_source_name(info[0].source), "alpha") == 0);
    /* sizes differ: ASP_EINVAL, outputs unchanged */
    asp_image c;
    asp_image_init(&c, 32, 64, NULL);
    iou = -5;
    asp_error err = {0};
    CHECK(asp_image_silhouettes(&a, &c, NULL, &iou, info, &err) == ASP_EINVAL && iou == -5);
    asp_image_release(&c);
    asp_image_release(&a);
    asp_image_release(&b);
}

static void test_contact_sheet_and_png(void)
{
    asp_image tiles[3], sheet, back;
    for (int i = 0; i < 3; i++)
        make_pattern(&tiles[i], 10, 6, i);
    CHECK_OK(asp_image_contact_sheet(tiles, 3, 0, &sheet, NULL), (asp_error *)NULL);
    CHECK(sheet.width == 30 && sheet.height == 6); /* 3 tiles: one row, no empty tile */
    CHECK(memcmp(sheet.pixels + 4 * 20, tiles[2].pixels, 40) == 0);
    asp_image eight;
    asp_image many[8];
    for (int i = 0; i < 8; i++)
        many[i] = tiles[i % 3];
    CHECK_OK(asp_image_contact_sheet(many, 8, 0, &eight, NULL), (asp_error *)NULL);
    CHECK(eight.width == 40 && eight.height == 12); /* 8 views: 4x2 */
    asp_image_release(&eight);
    asp_image five;
    CHECK_OK(asp_image_contact_sheet(many, 5, 0, &five, NULL), (asp_error *)NULL);
    CHECK(five.width == 30 && five.height == 12); /* 3x2 with one empty tile in the background colour */
    CHECK(memcmp(five.pixels + 4 * (6 * 30 + 29), tiles[0].pixels, 4) == 0);
    asp_image_release(&five);
    char path[256];
    snprintf(path, sizeof path, "/tmp/asp_test_sheet_%d.png", (int)getpid());
    CHECK_OK(asp_image_save_png(&sheet, path, NULL), (asp_error *)NULL);
    CHECK_OK(asp_image_load(&back, path, NULL), (asp_error *)NULL);
    CHECK(back.width == sheet.width && back.height == sheet.height);
    CHECK(back.pixels && memcmp(back.pixels, sheet.pixels, (size_t)sheet.width * sheet.height * 4) == 0);
    remove(path);
    asp_error err = {0};
    CHECK(asp_image_load(&back, "/nonexistent/x.png", &err) == ASP_EIO);
    CHECK(strstr(err.msg, "/nonexistent/x.png") != NULL);
    asp_image_release(&back);
    asp_image_release(&sheet);
    for (int i = 0; i < 3; i++)
        asp_image_release(&tiles[i]);
}

TEST_MAIN(TEST_CASE(test_identical), TEST_CASE(test_psnr_known), TEST_CASE(test_ssim_properties), TEST_CASE(test_errors),
          TEST_CASE(test_iou), TEST_CASE(test_silhouettes), TEST_CASE(test_contact_sheet_and_png))
