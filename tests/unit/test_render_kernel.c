/*
 * Seed 001's own kernel options in the splat renderer (issue 17): the psi_E
 * weight on the ellipse rim is exp(-a) with the seed's mapping (Fig. 11, rim
 * at r = b) and exp(-a / b^n) with amgsplat's (rim at r = 1); psi_G (eq. 11);
 * the renderer blends two overlapping splats with exactly those weights; one
 * uniform epsilon (5.3) separates or merges two layers by world distance.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static asp_gl_context *gl;

static void test_weights(void)
{
    CHECK_NEAR(asp_splat_kernel_weight(NULL, 0), 1.0, 1e-7);
    CHECK_NEAR(asp_splat_kernel_weight(NULL, 1), exp(-6.0 / (1.5 * 1.5 * 1.5)), 1e-6); // 0.169
    CHECK_NEAR(asp_splat_kernel_weight(NULL, 2), asp_splat_kernel_weight(NULL, 1), 0); // support ends at the rim
    const asp_splat_renderer_desc rim = {.flags = ASP_SPLAT_KERNEL_RIM_AT_B};
    CHECK_NEAR(asp_splat_kernel_weight(&rim, 1), exp(-6.0), 1e-7); // seed 001 eq. 12 at r = b: 0.00248
    CHECK_NEAR(asp_splat_kernel_weight(&rim, 0.5f), exp(-6.0 * 0.125), 1e-6);
    const asp_splat_renderer_desc rim2 = {.flags = ASP_SPLAT_KERNEL_RIM_AT_B, .kernel_a = 1, .kernel_n = 2};
    CHECK_NEAR(asp_splat_kernel_weight(&rim2, 1), exp(-1.0), 1e-6); // Fig. 18 a
    const asp_splat_renderer_desc g = {.kernel = ASP_SPLAT_KERNEL_PSI_G};
    CHECK_NEAR(asp_splat_kernel_weight(&g, 1), exp(-2.0), 1e-6); // sigma 0.5
    const asp_splat_renderer_desc g3 = {.kernel = ASP_SPLAT_KERNEL_PSI_G, .kernel_sigma = 0.3f,
                                        .flags = ASP_SPLAT_KERNEL_RIM_AT_B};
    CHECK_NEAR(asp_splat_kernel_weight(&g3, 0.2f), exp(-0.09 / 0.18), 1e-6); // r = 0.3 in the kernel's units
    CHECK(isnan(asp_splat_kernel_weight(&(asp_splat_renderer_desc){.kernel_a = -1}, 0.5f)));
    CHECK(isnan(asp_splat_kernel_weight(NULL, -0.5f)));
    CHECK_NEAR(asp_render_tolerance_from_area(0.01, 1000, 1000), 2.0 * sqrt(100.0 / 3.14159265358979), 1e-4);
    CHECK(asp_render_tolerance_from_area(0, 64, 64) == 0);
}

static double srgb_to_linear(uint8_t c)
{
    double v = c / 255.0;
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

static asp_cloud *plane_points(size_t n, const float *xyz, const uint8_t *rgb, float radius)
{
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err), &err);
    for (size_t i = 0; c && i < n; i++) {
        memcpy(c->positions + 3 * i, xyz + 3 * i, 3 * sizeof(float));
        c->normals[3 * i + 2] = 1;
        c->colors[4 * i] = rgb[3 * i], c->colors[4 * i + 1] = rgb[3 * i + 1], c->colors[4 * i + 2] = rgb[3 * i + 2];
        c->colors[4 * i + 3] = 255;
        c->radii[i] = radius;
    }
    return c;
}

/* Camera straight down -z at (x, y), the view `width` units wide. */
static void top_camera(asp_camera *cam, float x, float y, float width)
{
    asp_camera_init(cam);
    cam->target[0] = x;
    cam->target[1] = y;
    cam->distance = 0.5f * width / tanf(20.0f * 3.14159265f / 180.0f);
    cam->z_near = 0.5f * cam->distance;
    cam->z_far = 2.0f * cam->distance;
}

/* Red splat at x = 0, blue at x = 0.9, radius 1: at the blue centre, red weighs w(0.93) against w(0.04). */
static void test_blend_weights(void)
{
    if (!gl)
        return;
    const float xyz[6] = {0, 0, 0, 0.9f, 0, 0};
    const uint8_t rgb[6] = {255, 0, 0, 0, 0, 255};
    asp_cloud *c = plane_points(2, xyz, rgb, 1.0f);
    if (!c)
        return;
    asp_camera cam;
    top_camera(&cam, 0.9f, 0, 4.0f);
    const asp_render_desc rd = {.width = 64, .height = 64, .flags = ASP_RENDER_UNLIT};
    // pixel (32, 31) has its centre half a pixel (4 / 64 / 2 units) right of and above the blue centre
    const double h = 4.0 / 64 / 2, ra = sqrt((0.9 + h) * (0.9 + h) + h * h), rb = sqrt(2.0) * h;
    const asp_splat_renderer_desc descs[] = {{0},
                                             {.flags = ASP_SPLAT_KERNEL_RIM_AT_B},
                                             {.kernel = ASP_SPLAT_KERNEL_PSI_G},
                                             {.kernel = ASP_SPLAT_KERNEL_PSI_G, .kernel_sigma = 0.8f}};
    const char *names[] = {"psi_E rim 1", "psi_E rim b", "psi_G 0.5", "psi_G 0.8"};
    for (size_t k = 0; k < sizeof descs / sizeof descs[0]; k++) {
        asp_error err;
        asp_renderer *r = NULL;
        asp_splat_renderer_desc d = descs[k];
        d.tolerance = 0;
        CHECK_OK(asp_splat_renderer_create(gl, c, &d, NULL, &r, &err), &err);
        asp_image img = {0, 0, NULL};
        if (r)
            CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), &err);
        if (img.pixels) {
            double wa = asp_splat_kernel_weight(&d, (float)ra), wb = asp_splat_kernel_weight(&d, (float)rb);
            double want = wa / (wa + wb);
            const uint8_t *p = img.pixels + 4 * (31 * 64 + 32);
            double red = srgb_to_linear(p[0]), blue = srgb_to_linear(p[2]);
            fprintf(stderr, "%s: red share %.4f, expected %.4f\n", names[k], red, want);
            CHECK_MSG(fabs(red - want) < 0.01 + 0.05 * want && fabs(red + blue - 1) < 0.02,
                      "%s: pixel %u,%u,%u: red %.4f blue %.4f, expected red %.4f", names[k], p[0], p[1], p[2], red,
                      blue, want);
        }
        asp_image_release(&img);
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
}

/* Two 40 x 40 layers 0.5 apart seen from the top: a uniform epsilon of 0.1 keeps them apart, 0.8 merges them. */
static void test_uniform_epsilon(void)
{
    if (!gl)
        return;
    enum { SIDE = 40 };
    const float h = 0.05f;
    static float xyz[2 * SIDE * SIDE * 3];
    static uint8_t rgb[2 * SIDE * SIDE * 3];
    for (int layer = 0; layer < 2; layer++)
        for (int j = 0; j < SIDE; j++)
            for (int i = 0; i < SIDE; i++) {
                size_t p = ((size_t)layer * SIDE + j) * SIDE + i;
                xyz[3 * p] = (i - 0.5f * (SIDE - 1)) * h;
                xyz[3 * p + 1] = (j - 0.5f * (SIDE - 1)) * h;
                xyz[3 * p + 2] = layer ? 0.0f : -0.5f;
                rgb[3 * p] = layer ? 255 : 0;
                rgb[3 * p + 2] = layer ? 0 : 255;
            }
    asp_cloud *c = plane_points(2 * SIDE * SIDE, xyz, rgb, 0.75f * h);
    if (!c)
        return;
    asp_camera cam;
    top_camera(&cam, 0, 0, 1.0f);
    const asp_render_desc rd = {.width = 64, .height = 64, .flags = ASP_RENDER_UNLIT};
    const float eps[] = {0.1f, 0.8f};
    for (int e = 0; e < 2; e++) {
        asp_error err;
        asp_renderer *r = NULL;
        CHECK_OK(asp_splat_renderer_create(
                     gl, c, &(asp_splat_renderer_desc){.epsilon = eps[e], .flags = ASP_SPLAT_EPSILON_UNIFORM}, NULL,
                     &r, &err),
                 &err);
        asp_image img = {0, 0, NULL};
        if (r)
            CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), &err);
        if (img.pixels) {
            const uint8_t *p = img.pixels + 4 * (32 * 64 + 32);
            if (e == 0)
                CHECK_MSG(p[0] == 255 && p[2] == 0, "uniform epsilon 0.1: centre %u,%u,%u", p[0], p[1], p[2]);
            else
                CHECK_MSG(p[0] > 120 && p[2] > 120, "uniform epsilon 0.8: centre %u,%u,%u, expected a mix", p[0],
                          p[1], p[2]);
        }
        asp_image_release(&img);
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
}

static void setup(void)
{
    asp_error err = {0, ""};
    int rc = asp_gl_context_create_headless(&(asp_gl_context_desc){.flags = ASP_GL_CONTEXT_DEBUG}, NULL, &gl, &err);
    CHECK_MSG(rc == 0, "no headless GL: %s", err.msg);
}

static void teardown(void)
{
    asp_gl_context_destroy(gl);
    gl = NULL;
}

TEST_MAIN(TEST_CASE(test_weights), TEST_FIXTURE(setup), TEST_CASE(test_blend_weights), TEST_CASE(test_uniform_epsilon),
          TEST_FIXTURE(teardown))
