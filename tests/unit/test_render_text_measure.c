/*
 * The text overlay's measure (src/render/text_overlay.c): the box it draws
 * grows with the lines and the longest line and scales linearly, so a caller
 * can centre a block of text (the experiment's instruction screens) before
 * drawing it. Pure: no GL context.
 */
#include "amgsplat/render.h"
#include "harness.h"

static void test_measure(void)
{
    float w1, h1, w2, h2, wl, hl, w0, h0;
    asp_text_overlay_measure("ENTER: start", 1.0f, &w1, &h1);
    asp_text_overlay_measure("ENTER: start", 3.0f, &w2, &h2);
    CHECK_NEAR(w2, 3.0f * w1, 1e-4);
    CHECK_NEAR(h2, 3.0f * h1, 1e-4);
    asp_text_overlay_measure("ENTER: start", 0.0f, &w0, &h0); // 0: the default scale 2
    CHECK_NEAR(w0, 2.0f * w1, 1e-4);
    // a second, longer line: taller, and as wide as the longer line alone
    asp_text_overlay_measure("ENTER\nENTER: start, ESC: stop", 1.0f, &wl, &hl);
    CHECK(hl > h1);
    asp_text_overlay_measure("ENTER: start, ESC: stop", 1.0f, &w0, &h0);
    CHECK_NEAR(wl, w0, 1e-4);
    CHECK(wl > w1 && w1 > 6.0f); // wider than the padding alone
}

TEST_MAIN(TEST_CASE(test_measure))
