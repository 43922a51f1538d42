/*
 * Crease clipping of domain primitives (docs/render-methods.md "Crease
 * clipping"; the too-wide crease transitions of thesis 5.3.1): a hand-made
 * roof of two flat primitives meeting at a ridge, seen from above. Each
 * rectangle reaches past the ridge; unclipped, each overhang hangs over the
 * other face, clipped each stops at the ridge. Also: the angle threshold, the
 * flatness gate, the off switch, and that set_options changes it per frame.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "gl_harness.h"
#include "harness.h"


static asp_error *ep(asp_error *e)
{
    return e;
}

enum { TW = 64, TH = 16, SIZE = 256 };

#define OVER 0.12        /* how far each rectangle reaches past the ridge, in runs */
#define OVER_ALPHA 30    /* alpha of the overhang: a basis function's tail, just above the 0.1 alpha test */

static const uint8_t colors[2][3] = {{220, 30, 30}, {30, 200, 30}};

/*
 * A roof along the y axis: A (red) left of the ridge x = 0, B (green) right
 * of it, each tilted theta degrees from horizontal (normals 2 theta apart), a
 * unit run from the ridge, with a rectangle reaching `over` past the ridge.
 */
static void make_roof(asp_dps_level *lv, asp_prim prims[2], uint32_t nbrs[2], double theta_deg, double over,
                      float curvature, int over_alpha)
{
    memset(lv, 0, sizeof *lv);
    double t = theta_deg * 3.14159265358979323846 / 180.0, c = cos(t), s = sin(t);
    for (int k = 0; k < 2; k++) {
        asp_prim *p = &prims[k];
        memset(p, 0, sizeof *p);
        double side = k == 0 ? -1.0 : 1.0; // A downhill to -x, B to +x
        double half = 0.5 * (1.0 + over);  // from -1 to +over along the slope, measured from the ridge
        double mid = side * (1.0 - over) * 0.5;
        // unit slope direction pointing away from the ridge: (side c, 0, -s)
        p->centre[0] = mid * c;
        p->centre[1] = 0;
        p->centre[2] = -0.5 * (1.0 - over) * s;
        p->axis_u[0] = (float)c;
        p->axis_u[2] = (float)(-side * s);
        p->axis_v[1] = 1.0f;
        // normal = axis_u x axis_v = (-u_z, 0, u_x): (side s, 0, c), pointing up
        p->normal[0] = (float)(side * s);
        p->normal[2] = (float)c;
        p->half_u = (float)half;
        p->half_v = 1.0f;
        p->texel = (float)(2 * half / TW);
        p->curvature = curvature;
        p->tex_x = (uint32_t)k * (TW + 2) + 1;
        p->tex_w = TW;
        p->tex_h = TH;
        p->points = 100;
        p->neighbour_first = (uint32_t)k;
        p->neighbour_count = 1;
        nbrs[k] = (uint32_t)(1 - k);
    }
    lv->prim_count = 2;
    lv->prims = prims;
    lv->neighbours = nbrs;
    lv->neighbour_total = 2;
    asp_error err;
    CHECK_OK(asp_image_init(&lv->atlas, 2 * (TW + 2), TH, &err), ep(&err));
    for (uint32_t j = 0; j < TH; j++)
        for (uint32_t i = 0; i < lv->atlas.width; i++) {
            uint8_t *q = lv->atlas.pixels + 4 * ((size_t)j * lv->atlas.width + i);
            int k = i < TW + 2 ? 0 : 1;
            memcpy(q, colors[k], 3);
            // texel column c of primitive k, clamped into its texture (the padding repeats the edge)
            int col = (int)i - k * (TW + 2) - 1;
            col = col < 0 ? 0 : col >= TW ? TW - 1 : col;
            // run from the ridge at the column centre: A's axis_u points to the ridge, B's away from it
            double u = -1.0 + (2.0 * col + 1.0) / TW; // -1..1 across the rectangle
            double run = k == 0 ? 1.0 - (u + 1.0) * 0.5 * (1.0 + over) : -over + (u + 1.0) * 0.5 * (1.0 + over);
            q[3] = (uint8_t)(run < 0 ? over_alpha : 255);
        }
}

/* Renders from +z (azimuth 0, elevation 0: +y up on screen, +x right), unlit, white background. */
static void render_top(asp_renderer *r, const asp_prim_render_options *o, asp_camera *cam, asp_image *img)
{
    asp_error err = {0, ""};
    CHECK_OK(asp_prim_renderer_set_options(r, o, &err), ep(&err));
    asp_camera_init(cam);
    const float c[3] = {0, 0, 0};
    asp_camera_fit(cam, c, 1.6f, 1.0f);
    asp_render_desc rd = {.width = SIZE, .height = SIZE, .flags = ASP_RENDER_UNLIT,
                          .background = {255, 255, 255, 255}};
    CHECK_OK(asp_render_to_image(gl, r, cam, &rd, img, &err), ep(&err));
}

/* Which of red (0), green (1) or neither (-1) the pixel under world point (x, y, z) shows. */
static int color_at(const asp_camera *cam, const asp_image *img, float x, float y, float z)
{
    float p[3] = {x, y, z}, w[3];
    if (!asp_camera_project(cam, p, SIZE, SIZE, w))
        return -2;
    uint32_t i = (uint32_t)w[0], j = (uint32_t)w[1];
    if (i >= SIZE || j >= SIZE)
        return -2;
    const uint8_t *q = img->pixels + 4 * ((size_t)j * SIZE + i);
    for (int k = 0; k < 2; k++)
        if (abs(q[0] - colors[k][0]) <= 3 && abs(q[1] - colors[k][1]) <= 3 && abs(q[2] - colors[k][2]) <= 3)
            return k;
    return -1;
}

/* The colours left and right of the ridge, half an overhang from it: a point on each face. */
static void sides(const asp_camera *cam, const asp_image *img, double theta_deg, int *left, int *right)
{
    double t = theta_deg * 3.14159265358979323846 / 180.0;
    float x = 0.5f * (float)OVER * (float)cos(t), z = -0.5f * (float)OVER * (float)sin(t);
    *left = color_at(cam, img, -x, 0.2f, z);
    *right = color_at(cam, img, x, 0.2f, z);
}

static void test_roof(void)
{
    static const struct {
        double theta;   /* roof slope: normals 2 theta apart */
        float curvature;
        float crease;   /* option; 0 = default 60 */
        int clipped;    /* expected */
        const char *what;
    } cases[] = {
        {45, 0.0f, 0, 1, "90 degree ridge, default angle"},
        {45, 0.0f, -1, 0, "90 degree ridge, clipping off"},
        {45, 0.0f, 200, 0, "90 degree ridge, angle >= 180 = off"},
        {45, 0.05f, 0, 0, "90 degree ridge between curved domains"},
        {20, 0.0f, 0, 0, "40 degree ridge, default angle 60"},
        {20, 0.0f, 30, 1, "40 degree ridge, angle 30"},
        {8, 0.0f, 10, 0, "16 degree ridge: below the 20 degree floor"},
        // about 11% of A's alpha past the ridge: more than a basis function's tail, so no crease
        {45, 0.0f, 0, 0, "90 degree ridge with an opaque overhang"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        asp_dps_level lv;
        asp_prim prims[2];
        uint32_t nbrs[2];
        make_roof(&lv, prims, nbrs, cases[c].theta, OVER, cases[c].curvature, c == 7 ? 255 : OVER_ALPHA);
        asp_error err = {0, ""};
        asp_renderer *r = NULL;
        CHECK_OK(asp_prim_renderer_create(gl, &lv, NULL, &r, &err), ep(&err));
        for (int m = 0; r && m < 4; m++) {
            static const asp_prim_render_method methods[4] = {ASP_PRIM_RENDER_NORMALIZED, ASP_PRIM_RENDER_PREFIX,
                                                              ASP_PRIM_RENDER_NO_BLEND, ASP_PRIM_RENDER_POLYGONS};
            // a thin depth window, so the blending methods show the front layer alone, not A and B mixed
            asp_prim_render_options o = {.method = methods[m], .crease_angle = cases[c].crease,
                                         .depth_window = 0.01f};
            asp_camera cam;
            asp_image img = {0};
            render_top(r, &o, &cam, &img);
            int left, right;
            sides(&cam, &img, cases[c].theta, &left, &right);
            const char *dir = getenv("ASP_TEST_CREASE_OUT");
            if (dir) {
                char path[512];
                snprintf(path, sizeof path, "%s/roof-%zu-%s.png", dir, c, asp_prim_render_method_name(methods[m]));
                asp_image_save_png(&img, path, NULL);
            }
            /* unclipped, each overhang rises above the other face (a convex ridge): green B over the
               left, red A over the right; clipped, each face shows its own colour */
            int clipped = cases[c].clipped;
            CHECK_MSG(left == (clipped ? 0 : 1) && right == (clipped ? 1 : 0),
                      "%s, %s: left %d, right %d of the ridge (0 red, 1 green, -1 neither), expected %s", cases[c].what,
                      asp_prim_render_method_name(methods[m]), left, right,
                      clipped ? "0, 1 (clipped)" : "1, 0 (overhangs)");
            asp_prim_render_options got;
            CHECK_OK(asp_prim_renderer_options(r, &got, &err), ep(&err));
            float want = cases[c].crease == 0 ? ASP_PRIM_CREASE_ANGLE_DEFAULT
                         : cases[c].crease < 0 || cases[c].crease >= 180 ? -1.0f
                                                                           : cases[c].crease;
            CHECK(got.crease_angle == want);
            asp_image_release(&img);
        }
        asp_renderer_destroy(r);
        asp_image_release(&lv.atlas);
    }
}

static void test_bad_option(void)
{
    asp_dps_level lv;
    asp_prim prims[2];
    uint32_t nbrs[2];
    make_roof(&lv, prims, nbrs, 45, OVER, 0, OVER_ALPHA);
    asp_error err = {0, ""};
    asp_renderer *r = NULL;
    CHECK_OK(asp_prim_renderer_create(gl, &lv, NULL, &r, &err), ep(&err));
    if (r) {
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.crease_angle = NAN}, &err) == ASP_EINVAL);
        CHECK(strstr(err.msg, "crease angle") != NULL);
    }
    asp_renderer_destroy(r);
    asp_image_release(&lv.atlas);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_roof), TEST_CASE(test_bad_option), TEST_FIXTURE(teardown))
