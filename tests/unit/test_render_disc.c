/*
 * Disc renderer on a real headless GL 4.5 context (Mesa llvmpipe in CI; it
 * must run, not skip): sphere silhouette against the exact projected circle,
 * uniform Lambert shading of a plane, exact sRGB colours, depth order, image
 * orientation, defaults for missing attributes, determinism and bad input.
 */
#include <math.h>
#include <string.h>

#include <epoxy/gl.h>

#include "amgsplat/eval.h"
#include "amgsplat/render.h"
#include "gl_harness.h"
#include "harness.h"

static const double deg = 3.14159265358979323846 / 180.0;

/* Passes an error through a call, as CHECK_OK tests its pointer for NULL (-Waddress). */
static asp_error *ep(asp_error *e)
{
    return e;
}

/* Fibonacci sphere: near-uniform points with outward normals and hole-closing radii. */
static asp_cloud *make_sphere(size_t n, float radius, int with_radii)
{
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | (with_radii ? ASP_ATTR_RADII : 0), NULL, &c,
                              &err),
             ep(&err));
    if (!c)
        return NULL;
    // disc radius = sqrt(area per point) > 0.62 sqrt(area per point), which covers a hexagonal packing
    float disc = radius * (float)sqrt(4.0 * 3.14159265358979323846 / (double)n);
    for (size_t i = 0; i < n; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / (double)n, rho = sqrt(1.0 - y * y), phi = (double)i * 2.399963229728653;
        float nrm[3] = {(float)(rho * cos(phi)), (float)y, (float)(rho * sin(phi))};
        for (int k = 0; k < 3; k++) {
            c->normals[3 * i + k] = nrm[k];
            c->positions[3 * i + k] = radius * nrm[k];
        }
        // colour by octant, so orientation mistakes change pixels
        c->colors[4 * i + 0] = nrm[0] > 0 ? 230 : 40;
        c->colors[4 * i + 1] = nrm[1] > 0 ? 200 : 90;
        c->colors[4 * i + 2] = nrm[2] > 0 ? 60 : 220;
        c->colors[4 * i + 3] = 255;
        if (with_radii)
            c->radii[i] = disc;
    }
    return c;
}

/* Grid of side x side points in the plane z = z0, spacing h, facing +z, one colour. */
static asp_cloud *make_plane(int side, float h, float cx, float cy, float z0, const uint8_t rgb[3])
{
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create((size_t)side * side, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err),
             ep(&err));
    if (!c)
        return NULL;
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            size_t p = (size_t)j * side + i;
            c->positions[3 * p + 0] = cx + (i - 0.5f * (side - 1)) * h;
            c->positions[3 * p + 1] = cy + (j - 0.5f * (side - 1)) * h;
            c->positions[3 * p + 2] = z0;
            c->normals[3 * p + 2] = 1.0f;
            memcpy(c->colors + 4 * p, rgb, 3);
            c->colors[4 * p + 3] = 255;
            c->radii[p] = 0.75f * h; // > h / sqrt(2): a square grid is covered
        }
    return c;
}

static const uint8_t *px(const asp_image *img, uint32_t x, uint32_t y)
{
    return img->pixels + 4 * ((size_t)y * img->width + x);
}

static int render(asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc, asp_image *img)
{
    asp_error err = {0, ""};
    int rc = asp_render_to_image(gl, r, cam, desc, img, ep(&err));
    CHECK_OK(rc, ep(&err));
    return rc;
}

static void test_context(void)
{
    CHECK(gl != NULL);
    if (!gl)
        return;
    CHECK(strlen(asp_gl_context_renderer(gl)) > 0);
    CHECK(strncmp(asp_gl_context_backend(gl), "egl-", 4) == 0);
    asp_error err;
    CHECK_OK(asp_gl_context_check(gl, &err), ep(&err));
    // headless contexts have no window: these are no-ops
    uint32_t w = 7, h = 7;
    asp_gl_context_framebuffer_size(gl, &w, &h);
    CHECK(w == 0 && h == 0);
    CHECK(asp_gl_context_should_close(gl) == 0);
}

/* KHR_debug errors are collected and reported once by the next check. */
static void test_debug_errors_collected(void)
{
    if (!gl)
        return;
    CHECK_OK(asp_gl_context_make_current(gl, NULL), (asp_error *)NULL);
    glEnable(0x1234); // not a capability: GL_INVALID_ENUM
    asp_error err = {0, ""};
    CHECK(asp_gl_context_check(gl, &err) == ASP_EGL);
    CHECK(err.code == ASP_EGL);
    CHECK_MSG(strstr(err.msg, "GL_INVALID_ENUM") != NULL, "message '%s'", err.msg);
    CHECK(asp_gl_context_check(gl, &err) == 0);
}

/* The silhouette of a sphere seen centred in a perspective view is the circle of radius tan(asin(R/d)). */
static void test_sphere_silhouette_iou(void)
{
    if (!gl)
        return;
    asp_cloud *c = make_sphere(20000, 1.0f, 1);
    if (!c)
        return;
    asp_renderer *r = NULL;
    asp_error err;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    if (!r) {
        asp_cloud_destroy(c);
        return;
    }
    CHECK(asp_renderer_count(r) == 20000);
    CHECK(strcmp(asp_renderer_name(r), "disc") == 0);
    const uint32_t size = 128;
    static const float views[][2] = {{0, 0}, {30, 20}, {135, -50}};
    for (size_t v = 0; v < 3; v++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = views[v][0];
        cam.elevation = views[v][1];
        const float center[3] = {0, 0, 0};
        asp_camera_fit(&cam, center, 1.0f, 1.0f);
        cam.distance *= 1.5f;
        asp_camera_clip_to_sphere(&cam, center, 1.0f);
        asp_image img = {0, 0, NULL};
        if (render(r, &cam, &(asp_render_desc){.width = size, .height = size}, &img))
            continue;
        double rho = 0.5 * size * tan(asin(1.0 / cam.distance)) / tan(0.5 * cam.fov_y * deg);
        asp_image analytic = {0, 0, NULL};
        CHECK_OK(asp_image_init(&analytic, size, size, &err), ep(&err));
        for (uint32_t y = 0; y < size && analytic.pixels; y++)
            for (uint32_t x = 0; x < size; x++) {
                double dx = x + 0.5 - 0.5 * size, dy = y + 0.5 - 0.5 * size;
                analytic.pixels[4 * ((size_t)y * size + x) + 3] = dx * dx + dy * dy <= rho * rho ? 255 : 0;
            }
        double iou = 0;
        CHECK_OK(asp_image_silhouette_iou(&img, &analytic, NULL, &iou, &err), ep(&err));
        fprintf(stderr, "view %zu: silhouette IoU %.4f\n", v, iou);
        CHECK_MSG(iou >= 0.98, "view %zu: IoU %.4f against the analytic circle of radius %.2f px", v, iou, rho);
        asp_image_release(&analytic);
        // no holes: every pixel well inside the circle is covered
        size_t holes = 0;
        for (uint32_t y = 0; y < size; y++)
            for (uint32_t x = 0; x < size; x++) {
                double dx = x + 0.5 - 0.5 * size, dy = y + 0.5 - 0.5 * size;
                if (dx * dx + dy * dy < (rho - 2) * (rho - 2) && px(&img, x, y)[3] != 255)
                    holes++;
            }
        CHECK_MSG(holes == 0, "view %zu: %zu uncovered pixels inside the sphere", v, holes);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    asp_cloud_destroy(c);
}

/* A plane facing the camera under a directional light has one colour; facing the light it is the point colour. */
static void test_plane_uniformly_lit(void)
{
    if (!gl)
        return;
    const uint8_t rgb[3] = {180, 120, 60};
    asp_cloud *c = make_plane(40, 0.05f, 0, 0, 0, rgb);
    asp_renderer *r = NULL;
    asp_error err;
    if (!c)
        return;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    if (!r) {
        asp_cloud_destroy(c);
        return;
    }
    asp_camera cam;
    asp_camera_init(&cam);
    cam.distance = 2.0f; // the 2 x 2 plane overfills a 40 degree view from 2 units
    static const float light_az[] = {0, 60};
    for (int l = 0; l < 2; l++) {
        asp_image img = {0, 0, NULL};
        if (render(r, &cam,
                   &(asp_render_desc){.width = 96, .height = 64, .background = {0, 0, 0, 255},
                                      .light_azimuth = light_az[l]},
                   &img))
            continue;
        CHECK(img.width == 96 && img.height == 64);
        double shade = 0.25 + 0.75 * cos(light_az[l] * deg);
        size_t bad = 0;
        for (uint32_t y = 0; y < img.height; y++)
            for (uint32_t x = 0; x < img.width; x++) {
                const uint8_t *p = px(&img, x, y);
                for (int k = 0; k < 3; k++) {
                    double lin = pow((rgb[k] / 255.0 + 0.055) / 1.055, 2.4) * shade;
                    double expect = 255.0 * (1.055 * pow(lin, 1 / 2.4) - 0.055);
                    // headlight: exactly the point colour; otherwise within the rounding of 8-bit sRGB
                    if (l == 0 ? p[k] != rgb[k] : fabs(p[k] - expect) > 1.0)
                        bad++;
                }
                bad += p[3] != 255;
                bad += memcmp(p, px(&img, 0, 0), 4) != 0;
            }
        CHECK_MSG(bad == 0, "light azimuth %g: %zu pixel values differ from the uniform expected colour", light_az[l],
                  bad);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    asp_cloud_destroy(c);
}

/* Depth decides visibility whatever the drawing order; +x is right and +y is up in the image. */
static void test_depth_and_orientation(void)
{
    if (!gl)
        return;
    const uint8_t red[3] = {255, 0, 0}, blue[3] = {0, 0, 255};
    asp_cloud *near_red = make_plane(10, 0.02f, 0.25f, 0.25f, 0.5f, red);   // small, upper right, in front
    asp_cloud *far_blue = make_plane(60, 0.04f, 0.0f, 0.0f, -0.5f, blue);   // large, behind
    asp_cloud *both[2] = {NULL, NULL};
    asp_error err;
    if (!near_red || !far_blue)
        goto done;
    // two clouds, the same points in both orders
    for (int order = 0; order < 2; order++) {
        asp_cloud *first = order ? far_blue : near_red, *second = order ? near_red : far_blue;
        CHECK_OK(asp_cloud_create(first->count + second->count, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII,
                                  NULL, &both[order], &err),
                 ep(&err));
        if (!both[order])
            goto done;
        asp_cloud *b = both[order];
        memcpy(b->positions, first->positions, 12 * first->count);
        memcpy(b->positions + 3 * first->count, second->positions, 12 * second->count);
        memcpy(b->normals, first->normals, 12 * first->count);
        memcpy(b->normals + 3 * first->count, second->normals, 12 * second->count);
        memcpy(b->colors, first->colors, 4 * first->count);
        memcpy(b->colors + 4 * first->count, second->colors, 4 * second->count);
        memcpy(b->radii, first->radii, 4 * first->count);
        memcpy(b->radii + first->count, second->radii, 4 * second->count);
    }
    asp_image img[2] = {{0, 0, NULL}, {0, 0, NULL}};
    for (int order = 0; order < 2; order++) {
        asp_renderer *r = NULL;
        CHECK_OK(asp_disc_renderer_create(gl, both[order], NULL, &r, &err), ep(&err));
        if (!r)
            continue;
        asp_camera cam;
        asp_camera_init(&cam);
        cam.distance = 3.0f;
        render(r, &cam, &(asp_render_desc){.width = 64, .height = 64, .flags = ASP_RENDER_UNLIT}, &img[order]);
        asp_renderer_destroy(r);
    }
    if (img[0].pixels && img[1].pixels) {
        CHECK(memcmp(img[0].pixels, img[1].pixels, 4 * 64 * 64) == 0);
        // the red patch projects to the upper right quadrant, around pixel (32 + 0.25 / (2.5 tan 20) 32, ...)
        double off = 32.0 * 0.25 / (2.5 * tan(20 * deg));
        uint32_t rx = (uint32_t)lround(32 + off), ry = (uint32_t)lround(32 - off);
        const uint8_t *p = px(&img[0], rx, ry);
        CHECK_MSG(p[0] == 255 && p[1] == 0 && p[2] == 0, "pixel (%u, %u) = %u %u %u, expected red", rx, ry, p[0],
                  p[1], p[2]);
        p = px(&img[0], 64 - rx, 64 - ry);
        CHECK_MSG(p[0] == 0 && p[2] == 255, "mirrored pixel is %u %u %u, expected blue", p[0], p[1], p[2]);
        size_t red_px = 0, red_wrong = 0;
        for (uint32_t y = 0; y < 64; y++)
            for (uint32_t x = 0; x < 64; x++)
                if (px(&img[0], x, y)[0] == 255) {
                    red_px++;
                    red_wrong += x < 32 || y >= 32;
                }
        CHECK(red_px > 20 && red_wrong == 0);
    }
    asp_image_release(&img[0]);
    asp_image_release(&img[1]);
done:
    asp_cloud_destroy(both[0]);
    asp_cloud_destroy(both[1]);
    asp_cloud_destroy(near_red);
    asp_cloud_destroy(far_blue);
}

/* Positions only: discs face the eye, radius estimated, light grey; background exact. */
static void test_missing_attributes(void)
{
    if (!gl)
        return;
    asp_cloud *s = make_sphere(5000, 1.0f, 0), *c = NULL;
    asp_error err;
    if (!s)
        return;
    CHECK_OK(asp_cloud_create(s->count, 0, NULL, &c, &err), ep(&err));
    if (c) {
        memcpy(c->positions, s->positions, 12 * s->count);
        // A = 3 * 2 * 2 = 12 for the sphere's 2 x 2 x 2 box
        CHECK_NEAR(asp_render_default_radius(c), 2.0 * sqrt(12.0 / (3.14159265358979323846 * 5000)), 1e-3);
        float center[3], radius;
        CHECK_OK(asp_render_bounding_sphere(c, center, &radius, &err), ep(&err));
        CHECK_NEAR(radius, 1.0 + asp_render_default_radius(c), 1e-3);
        CHECK_NEAR(center[1], 0.0, 1e-3);
        asp_renderer *r = NULL;
        CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
        asp_camera cam;
        asp_camera_init(&cam);
        asp_camera_fit(&cam, center, radius, 1.0f);
        asp_image img = {0, 0, NULL};
        const uint8_t bg[4] = {10, 20, 30, 255};
        if (r && !render(r, &cam, &(asp_render_desc){.width = 64, .height = 64, .background = {10, 20, 30, 255}},
                         &img)) {
            const uint8_t *mid = px(&img, 32, 32);
            CHECK_MSG(mid[0] == 200 && mid[1] == 200 && mid[2] == 200, "centre is %u %u %u", mid[0], mid[1], mid[2]);
            CHECK(memcmp(px(&img, 0, 0), bg, 4) == 0);
            CHECK(memcmp(px(&img, 63, 63), bg, 4) == 0);
            asp_image_release(&img);
        }
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
    asp_cloud_destroy(s);
}

/* Transparent background: alpha 0 outside, straight (not darkened) colours at multisampled edges. */
static void test_transparent_multisampled(void)
{
    if (!gl)
        return;
    const uint8_t rgb[3] = {200, 100, 50};
    asp_cloud *c = make_plane(20, 0.05f, 0, 0, 0, rgb);
    asp_renderer *r = NULL;
    asp_error err;
    if (!c)
        return;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    asp_camera cam;
    asp_camera_init(&cam);
    cam.distance = 4.0f;
    cam.azimuth = 20.0f; // slanted edges give partial coverage
    asp_image img = {0, 0, NULL};
    if (r && !render(r, &cam,
                     &(asp_render_desc){.width = 64, .height = 64, .samples = 4, .flags = ASP_RENDER_UNLIT}, &img)) {
        size_t partial = 0, off = 0, zero = 0;
        for (size_t i = 0; i < 64 * 64; i++) {
            const uint8_t *p = img.pixels + 4 * i;
            if (p[3] == 0) {
                zero++;
                off += p[0] || p[1] || p[2];
            } else if (p[3] < 255) {
                partial++;
                off += abs(p[0] - rgb[0]) > 3 || abs(p[1] - rgb[1]) > 3 || abs(p[2] - rgb[2]) > 3;
            }
        }
        CHECK(zero > 0);
        CHECK_MSG(partial > 0, "no partially covered pixels: multisampling is off");
        CHECK_MSG(off == 0, "%zu pixels have colours that are not the straight disc colour or transparent", off);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    asp_cloud_destroy(c);
}

/*
 * Sub-pixel discs with multisampling: a fragment shaded at the pixel centre
 * would discard samples its disc covers, letting the background through a
 * closed surface. A dense plane facing the camera must cover every pixel.
 */
static void test_multisampled_subpixel_discs(void)
{
    if (!gl)
        return;
    const uint8_t rgb[3] = {50, 200, 50};
    asp_cloud *c = make_plane(300, 0.01f, 0, 0, 0, rgb); // 3 x 3 units; disc radius 0.17 px at 48 px
    asp_renderer *r = NULL;
    asp_error err;
    if (!c)
        return;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    asp_camera cam;
    asp_camera_init(&cam);
    cam.distance = 3.0f; // the plane overfills the view
    static const uint32_t samples[] = {1, 4};
    for (int s = 0; s < 2 && r; s++) {
        asp_image img = {0, 0, NULL};
        if (render(r, &cam,
                   &(asp_render_desc){.width = 48, .height = 48, .samples = samples[s], .flags = ASP_RENDER_UNLIT},
                   &img))
            continue;
        size_t bad = 0;
        for (size_t i = 0; i < 48 * 48; i++)
            bad += memcmp(img.pixels + 4 * i, (uint8_t[4]){50, 200, 50, 255}, 4) != 0;
        CHECK_MSG(bad == 0, "%u samples: %zu of %d pixels are not the plane colour", samples[s], bad, 48 * 48);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    asp_cloud_destroy(c);
}

static void test_deterministic(void)
{
    if (!gl)
        return;
    asp_cloud *c = make_sphere(20000, 1.0f, 1);
    if (!c)
        return;
    asp_camera cam;
    asp_camera_init(&cam);
    cam.azimuth = 33.0f;
    cam.elevation = 12.0f;
    const float center[3] = {0, 0, 0};
    asp_camera_fit(&cam, center, 1.0f, 1.0f);
    asp_image img[3] = {{0, 0, NULL}, {0, 0, NULL}, {0, 0, NULL}};
    asp_render_desc desc = {.width = 96, .height = 96, .samples = 4, .background = {255, 255, 255, 255}};
    asp_error err;
    asp_renderer *r = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    if (r) {
        render(r, &cam, &desc, &img[0]);
        render(r, &cam, &desc, &img[1]);
        asp_renderer_destroy(r);
    }
    r = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    if (r) {
        render(r, &cam, &desc, &img[2]);
        asp_renderer_destroy(r);
    }
    if (img[0].pixels && img[1].pixels && img[2].pixels) {
        CHECK(memcmp(img[0].pixels, img[1].pixels, 4 * 96 * 96) == 0);
        CHECK(memcmp(img[0].pixels, img[2].pixels, 4 * 96 * 96) == 0);
    }
    for (int i = 0; i < 3; i++)
        asp_image_release(&img[i]);
    asp_cloud_destroy(c);
}

static void test_bad_input(void)
{
    if (!gl)
        return;
    asp_error err;
    asp_renderer *r = NULL;
    asp_cloud *c = NULL;
    // empty
    CHECK_OK(asp_cloud_create(0, 0, NULL, &c, &err), ep(&err));
    if (c) {
        CHECK(asp_disc_renderer_create(gl, c, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
        float center[3] = {9, 9, 9}, radius = 9;
        CHECK(asp_render_bounding_sphere(c, center, &radius, &err) == ASP_EDEGENERATE);
        CHECK(center[0] == 9 && radius == 9);
        CHECK(asp_render_default_radius(c) == 0.0f);
        asp_cloud_destroy(c);
        c = NULL;
    }
    // all points equal, no radii
    CHECK_OK(asp_cloud_create(50, 0, NULL, &c, &err), ep(&err));
    if (c) {
        CHECK(asp_disc_renderer_create(gl, c, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
        CHECK_MSG(strstr(err.msg, "same position") != NULL, "message '%s'", err.msg);
        float center[3], radius;
        CHECK(asp_render_bounding_sphere(c, center, &radius, &err) == ASP_EDEGENERATE);
        // a NaN coordinate is named
        c->positions[3 * 7 + 1] = NAN;
        CHECK(asp_disc_renderer_create(gl, c, NULL, &r, &err) == ASP_EFORMAT && r == NULL);
        CHECK_MSG(strstr(err.msg, "point 7") != NULL, "message '%s'", err.msg);
        asp_cloud_destroy(c);
        c = NULL;
    }
    // bad radius scale, oversized image, broken camera
    c = make_sphere(500, 1.0f, 1);
    if (!c)
        return;
    CHECK(asp_disc_renderer_create(gl, c, &(asp_disc_renderer_desc){.radius_scale = -1}, &r, &err) == ASP_EINVAL);
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &r, &err), ep(&err));
    if (r) {
        asp_camera cam;
        asp_camera_init(&cam);
        asp_image img = {0, 0, NULL};
        CHECK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 100000, .height = 10}, &img, &err) ==
              ASP_EINVAL);
        CHECK(img.pixels == NULL);
        cam.z_near = 0;
        CHECK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 16, .height = 16}, &img, &err) ==
              ASP_EINVAL);
        CHECK_MSG(strstr(err.msg, "camera") != NULL, "message '%s'", err.msg);
        CHECK(img.pixels == NULL);
        CHECK(asp_render_frame(gl, r, &cam, &(asp_render_desc){.width = 16, .height = 16}, &err) == ASP_EINVAL);
        asp_camera_init(&cam);
        CHECK_OK(asp_render_frame(gl, r, &cam, &(asp_render_desc){.width = 16, .height = 16, .flags = ASP_RENDER_WAIT},
                                  &err),
                 ep(&err));
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
    asp_renderer_destroy(NULL);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_context), TEST_CASE(test_debug_errors_collected),
          TEST_CASE(test_sphere_silhouette_iou), TEST_CASE(test_plane_uniformly_lit),
          TEST_CASE(test_depth_and_orientation), TEST_CASE(test_missing_attributes),
          TEST_CASE(test_transparent_multisampled),
          TEST_CASE(test_multisampled_subpixel_discs), TEST_CASE(test_deterministic), TEST_CASE(test_bad_input),
          TEST_FIXTURE(teardown))
