/*
 * The recognition observer's view of a frame (src/experiment/observer.c): the
 * silhouette in its bounding box and the colour histogram do not depend on
 * where or how large the object is on screen, tell a disc from a bar, and a
 * frame of background alone shows nothing.
 */
#include "amgsplat/amgsplat.h"
#include "experiment/internal.h"
#include "harness.h"

static const uint8_t bg[4] = {40, 40, 48, 255};

/* an ellipse (rx, ry) at (cx, cy) in colour c on the background */
static void draw_ellipse(asp_image *img, float cx, float cy, float rx, float ry, const uint8_t c[4])
{
    asp_image_fill(img, bg);
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = 0; x < img->width; x++) {
            float dx = ((float)x + 0.5f - cx) / rx, dy = ((float)y + 0.5f - cy) / ry;
            if (dx * dx + dy * dy <= 1.0f)
                memcpy(&img->pixels[4 * ((size_t)y * img->width + x)], c, 4);
        }
}

static void test_features(void)
{
    static const uint8_t grey[4] = {200, 200, 200, 255}, brown[4] = {150, 90, 40, 255};
    asp_image img = {0};
    CHECK_OK(asp_image_init(&img, 160, 120, NULL), NULL);
    exp_features small, big, bar, other_colour, none;
    draw_ellipse(&img, 30, 30, 10, 10, grey);
    asp__exp_features(&img, bg, &small);
    draw_ellipse(&img, 100, 60, 40, 40, grey);
    asp__exp_features(&img, bg, &big);
    draw_ellipse(&img, 80, 60, 50, 8, grey);
    asp__exp_features(&img, bg, &bar);
    draw_ellipse(&img, 100, 60, 40, 40, brown);
    asp__exp_features(&img, bg, &other_colour);
    asp_image_fill(&img, bg);
    asp__exp_features(&img, bg, &none);
    CHECK(!small.empty && !big.empty && none.empty);
    float same = asp__exp_feature_score(&small, &big);
    float shape = asp__exp_feature_score(&big, &bar);
    float colour = asp__exp_feature_score(&big, &other_colour);
    CHECK_MSG(same > 0.9f, "a disc small and large: %g", same);
    CHECK_MSG(shape < same - 0.3f, "disc against bar %g, disc against disc %g", shape, same);
    CHECK_MSG(colour < same - 0.25f && colour > shape, "grey against brown disc: %g", colour);
    CHECK(asp__exp_feature_score(&big, &none) == 0.0f);
    float sum = 0.0f;
    for (int i = 0; i < EXP_HIST; i++)
        sum += big.hist[i];
    CHECK_NEAR(sum, 1.0, 1e-5);
    asp_image_release(&img);
}

TEST_MAIN(TEST_CASE(test_features))
