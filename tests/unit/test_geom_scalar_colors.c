/*
 * Colour by a per-point scalar (src/geom/scalar_colors.c, issue 29): the ASPRS class palette's exact
 * colours, the viridis ramp's ends at the field's min and max (elevation along the up axis, any
 * property), intensity clipped at its 1st/99th percentiles, and an unknown name refused with the
 * file's properties listed.
 */
#include <string.h>

#include "amgsplat/geom.h"
#include "harness.h"

static int rgb_is(const uint8_t *c, int r, int g, int b) { return c[0] == r && c[1] == g && c[2] == b; }

static void test_palette_and_ramp(void)
{
    uint8_t c[3];
    asp_scalar_color_class(2, c); // ground: brown
    CHECK(rgb_is(c, 150, 100, 50));
    asp_scalar_color_class(6, c); // building
    CHECK(rgb_is(c, 230, 80, 40));
    asp_scalar_color_class(9, c); // water: blue
    CHECK(rgb_is(c, 40, 90, 220));
    asp_scalar_color_class(5, c); // high vegetation: green dominates
    CHECK(c[1] > c[0] && c[1] > c[2]);
    asp_scalar_color_ramp(0, c); // viridis ends
    CHECK(rgb_is(c, 68, 1, 84));
    asp_scalar_color_ramp(1, c);
    CHECK(rgb_is(c, 253, 231, 37));
    asp_scalar_color_ramp(2, c); // clamped
    CHECK(rgb_is(c, 253, 231, 37));
    uint8_t a[3], b[3]; // lightness ordered: the sum of channels grows along the ramp
    asp_scalar_color_ramp(0.25, a);
    asp_scalar_color_ramp(0.75, b);
    CHECK(a[0] + a[1] + a[2] < b[0] + b[1] + b[2]);
}

static void test_cloud(void)
{
    asp_cloud *c = NULL;
    asp_error err = {0, ""};
    CHECK(asp_cloud_create(4, 0, NULL, &c, &err) == 0);
    asp_property *cls = NULL, *in = NULL;
    CHECK(asp_cloud_add_property(c, "classification", ASP_SCALAR_UINT8, &cls, &err) == 0);
    CHECK(asp_cloud_add_property(c, "intensity", ASP_SCALAR_UINT16, &in, &err) == 0);
    cls = &c->properties[0]; // adding a property may move the array: the first pointer is stale
    const uint8_t classes[4] = {2, 6, 9, 2};
    const uint16_t intensity[4] = {100, 200, 300, 60000};
    for (int i = 0; i < 4; i++) {
        c->positions[3 * i + 2] = (float)(10 * i); // z: 0, 10, 20, 30
        c->positions[3 * i + 1] = (float)(-i);     // y: 0 .. -3
        ((uint8_t *)cls->data)[i] = classes[i];
        ((uint16_t *)in->data)[i] = intensity[i];
    }
    c->origin[2] = 1000; // elevation is the world coordinate; its range, not the value, picks the colour
    CHECK(asp_cloud_color_by(c, "elevation", ASP_UP_Z, &err) == 0);
    CHECK(rgb_is(c->colors, 68, 1, 84) && c->colors[3] == 255);
    CHECK(rgb_is(c->colors + 12, 253, 231, 37));
    CHECK(asp_cloud_color_by(c, "elevation", ASP_UP_Y, &err) == 0); // y falls with i: the ends swap
    CHECK(rgb_is(c->colors, 253, 231, 37) && rgb_is(c->colors + 12, 68, 1, 84));
    CHECK(asp_cloud_color_by(c, "elevation", ASP_UP_NEG_Z, &err) == 0);
    CHECK(rgb_is(c->colors, 253, 231, 37));
    CHECK(asp_cloud_color_by(c, "classification", ASP_UP_Z, &err) == 0);
    CHECK(rgb_is(c->colors, 150, 100, 50) && rgb_is(c->colors + 4, 230, 80, 40) && rgb_is(c->colors + 8, 40, 90, 220));
    CHECK(asp_cloud_color_by(c, "prop:classification", ASP_UP_Z, &err) == 0); // as a plain ramp: 2 .. 9
    CHECK(rgb_is(c->colors, 68, 1, 84) && rgb_is(c->colors + 8, 253, 231, 37));
    CHECK(asp_cloud_color_by(c, "intensity", ASP_UP_Z, &err) == 0); // grey: black at the 1st percentile, white at the 99th
    CHECK(c->colors[0] == 0 && c->colors[0] == c->colors[1] && c->colors[12] == 255);
    CHECK(asp_cloud_color_by(c, "height", ASP_UP_Z, &err) == ASP_EINVAL);
    CHECK_MSG(strstr(err.msg, "'height'") && strstr(err.msg, "classification, intensity"), "%s", err.msg);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_palette_and_ramp), TEST_CASE(test_cloud))
