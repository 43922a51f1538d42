/*
 * The viewer without a window: mouse interaction on the orbit camera (orbit
 * follows the drag, pan keeps the grabbed point under the cursor, dolly is
 * clamped), the tau ladder, the key table and option checking
 * (src/viewer/control.c, viewer.c). The .amg input: test_viewer_amg.c.
 */
#include <math.h>

#include "amgsplat/render.h"
#include "harness.h"
#include "viewer/internal.h"

static void camera_at(asp_camera *cam, float az, float el)
{
    asp_camera_init(cam);
    cam->azimuth = az;
    cam->elevation = el;
    cam->target[0] = 0.5f;
    cam->target[1] = -0.25f;
    cam->target[2] = 2.0f;
    cam->distance = 4.0f;
    cam->aspect = 4.0f / 3.0f;
    cam->z_near = 0.1f;
    cam->z_far = 50.0f;
}

/* Dragging right turns the object's front to the right, dragging down turns it down; distance is kept. */
static void test_orbit_follows_drag(void)
{
    static const float views[][2] = {{0, 0}, {30, 20}, {-120, -40}, {170, 60}};
    for (size_t i = 0; i < sizeof views / sizeof views[0]; i++) {
        asp_camera cam;
        camera_at(&cam, views[i][0], views[i][1]);
        float eye[3], front[3], before[3], after[3];
        asp_camera_eye(&cam, eye);
        // the point of a unit sphere around the target nearest to the eye
        for (int k = 0; k < 3; k++)
            front[k] = cam.target[k] + (eye[k] - cam.target[k]) / cam.distance;
        CHECK(asp_camera_project(&cam, front, 400, 300, before));
        asp__viewer_orbit(&cam, 8, 0);
        CHECK_NEAR(cam.azimuth, views[i][0] - 8 * ASP__VIEWER_ORBIT_DEG_PER_PX, 1e-4);
        CHECK(asp_camera_project(&cam, front, 400, 300, after));
        CHECK_MSG(after[0] > before[0] + 1, "view %zu: front x %g -> %g", i, before[0], after[0]);
        asp__viewer_orbit(&cam, -8, 8);
        CHECK(asp_camera_project(&cam, front, 400, 300, after));
        CHECK_MSG(after[1] > before[1] + 1, "view %zu: front y %g -> %g", i, before[1], after[1]);
        float eye2[3];
        asp_camera_eye(&cam, eye2);
        double d = sqrt(pow(eye2[0] - cam.target[0], 2) + pow(eye2[1] - cam.target[1], 2) +
                        pow(eye2[2] - cam.target[2], 2));
        CHECK_NEAR(d, 4.0, 1e-5);
    }
    asp_camera cam;
    camera_at(&cam, 170, 10);
    asp__viewer_orbit(&cam, 0, 1e6); // elevation clamps at the pole
    CHECK_NEAR(cam.elevation, 90, 0);
    asp__viewer_orbit(&cam, 0, -1e6);
    CHECK_NEAR(cam.elevation, -90, 0);
    asp__viewer_orbit(&cam, -100, 0); // 170 + 25 = 195 wraps to -165
    CHECK_NEAR(cam.azimuth, -165, 1e-4);
    for (int i = 0; i < 100; i++)
        asp__viewer_orbit(&cam, 977, 0);
    CHECK(cam.azimuth >= -180 && cam.azimuth < 180);
}

/* A point at the target's depth moves by exactly the cursor's motion in pixels. */
static void test_pan_keeps_point_under_cursor(void)
{
    static const float views[][2] = {{0, 0}, {30, 20}, {-120, -40}, {10, 90}, {75, -90}};
    static const double moves[][2] = {{10, 0}, {0, -7}, {-23.5, 41}};
    for (size_t i = 0; i < sizeof views / sizeof views[0]; i++) {
        for (size_t m = 0; m < sizeof moves / sizeof moves[0]; m++) {
            asp_camera cam;
            camera_at(&cam, views[i][0], views[i][1]);
            float grabbed[3] = {cam.target[0], cam.target[1], cam.target[2]}, before[3], after[3];
            CHECK(asp_camera_project(&cam, grabbed, 400, 300, before));
            CHECK_NEAR(before[0], 200, 1e-3);
            CHECK_NEAR(before[1], 150, 1e-3);
            asp__viewer_pan(&cam, moves[m][0], moves[m][1], 300);
            CHECK(asp_camera_project(&cam, grabbed, 400, 300, after));
            CHECK_NEAR(after[0] - before[0], moves[m][0], 1e-3);
            CHECK_NEAR(after[1] - before[1], moves[m][1], 1e-3);
            CHECK_NEAR(after[2], before[2], 1e-6); // same depth: the pan is parallel to the image
        }
    }
}

static void test_dolly_clamps(void)
{
    asp_camera cam;
    camera_at(&cam, 0, 0);
    asp__viewer_dolly(&cam, 0.5, 1.0f);
    CHECK_NEAR(cam.distance, 2.0, 1e-6);
    asp__viewer_dolly(&cam, 1e-9, 1.0f);
    CHECK_NEAR(cam.distance, 1e-3, 1e-9);
    asp__viewer_dolly(&cam, 1e12, 1.0f);
    CHECK_NEAR(cam.distance, 1e3, 1e-3);
    asp__viewer_dolly(&cam, NAN, 1.0f);
    asp__viewer_dolly(&cam, 0, 1.0f);
    asp__viewer_dolly(&cam, -2, 1.0f);
    CHECK_NEAR(cam.distance, 1e3, 1e-3);
}

static void test_tolerance_ladder(void)
{
    float tau = 0;
    int steps = 0;
    for (;;) {
        float up = asp__viewer_tolerance_step(tau, +1);
        if (up == tau)
            break;
        CHECK(up > tau);
        tau = up;
        steps++;
    }
    CHECK(steps == 15);
    CHECK_NEAR(tau, 64, 0);
    while (tau > 0) {
        float down = asp__viewer_tolerance_step(tau, -1);
        CHECK(down < tau);
        tau = down;
        steps--;
    }
    CHECK(steps == 0);
    CHECK_NEAR(asp__viewer_tolerance_step(0, -1), 0, 0);
    CHECK_NEAR(asp__viewer_tolerance_step(5, +1), 6, 0);
    CHECK_NEAR(asp__viewer_tolerance_step(5, -1), 4, 0);
    CHECK_NEAR(asp__viewer_tolerance_step(100, +1), 100, 0);
    CHECK_NEAR(asp__viewer_tolerance_step(100, -1), 64, 0);
}

static void test_key_table(void)
{
    int seen[256] = {0};
    for (const asp__viewer_key *k = asp__viewer_keys; k->key; k++) {
        CHECK_MSG(!seen[(unsigned char)k->key], "key '%c' twice", k->key);
        seen[(unsigned char)k->key] = 1;
        CHECK(asp__viewer_key_find((unsigned char)k->key) == k);
    }
    CHECK(asp__viewer_key_find('q')->action == ASP__VIEWER_QUIT);
    CHECK(asp__viewer_key_find('s')->action == ASP__VIEWER_SCREENSHOT);
    CHECK(asp__viewer_key_find(']')->action == ASP__VIEWER_LEVEL_COARSER);
    CHECK(asp__viewer_key_find('2')->action == ASP__VIEWER_PICK_RENDERER && asp__viewer_key_find('2')->arg == 1);
    // .dps keys; zoom out moved from o to Z when o became the outline toggle
    CHECK(asp__viewer_key_find('o')->action == ASP__VIEWER_OUTLINE);
    CHECK(asp__viewer_key_find('Z')->action == ASP__VIEWER_ZOOM_OUT);
    CHECK(asp__viewer_key_find('m')->action == ASP__VIEWER_NEXT_METHOD);
    CHECK(asp__viewer_key_find(',')->action == ASP__VIEWER_ALPHA_DOWN);
    CHECK(asp__viewer_key_find('.')->action == ASP__VIEWER_ALPHA_UP);
    CHECK(asp__viewer_key_find('p')->action == ASP__VIEWER_POINTS);
    CHECK(strcmp(asp_viewer_renderer_name(3), "prim") == 0);
    CHECK(asp__viewer_key_find('Q') == NULL && asp__viewer_key_find(0x263A) == NULL);
    CHECK(strcmp(asp_viewer_renderer_name(0), "disc") == 0);
    size_t n = 0;
    while (asp_viewer_renderer_name(n))
        n++;
    CHECK(n >= 1 && n <= 9);
}

static void expect_invalid(const asp_viewer_desc *d, const char *text)
{
    asp_error err = {0, ""};
    CHECK(asp_viewer_desc_check(d, &err) == ASP_EINVAL);
    CHECK_MSG(strstr(err.msg, text) != NULL, "'%s' lacks '%s'", err.msg, text);
}

static void test_desc_check(void)
{
    asp_error err = {0, ""};
    CHECK_OK(asp_viewer_desc_check(&(asp_viewer_desc){0}, &err), &err);
    CHECK_OK(asp_viewer_desc_check(&(asp_viewer_desc){.frames = 3, .keys = "l]s", .screenshot = "a/b.PNG"}, &err),
             &err);
    expect_invalid(&(asp_viewer_desc){.renderer = "blob"}, "unknown renderer 'blob' (expected disc");
    expect_invalid(&(asp_viewer_desc){.keys = "lQ"}, "key 'Q' (character 2 of 'lQ')");
    expect_invalid(&(asp_viewer_desc){.frames = 2, .keys = "lll"}, "3 keys need at least as many frames, got 2");
    expect_invalid(&(asp_viewer_desc){.screenshot = "x.png"}, "needs a number of frames");
    expect_invalid(&(asp_viewer_desc){.frames = 1, .screenshot = "x.jpg"}, "'x.jpg' must end in .png");
    expect_invalid(&(asp_viewer_desc){.tolerance = -1}, "tolerance -1");
    expect_invalid(&(asp_viewer_desc){.tolerance = NAN}, "tolerance");
    expect_invalid(&(asp_viewer_desc){.set_view = 1, .elevation = 91}, "expected EL in -90..90");
    expect_invalid(&(asp_viewer_desc){.width = 20000, .height = 10}, "20000x10");
    expect_invalid(&(asp_viewer_desc){.amg_color = 4}, "colour mode 4");
    expect_invalid(&(asp_viewer_desc){.prim_method = 9}, "unknown .dps method 9");
    expect_invalid(&(asp_viewer_desc){.prim_alpha_ref = 1.5f}, "alpha reference 1.5");
    expect_invalid(&(asp_viewer_desc){.prim_alpha_ref = NAN}, "alpha reference");
    CHECK_OK(asp_viewer_desc_check(&(asp_viewer_desc){.prim_method = 8, .prim_alpha_ref = -1}, &err), &err);
}

TEST_MAIN(TEST_CASE(test_orbit_follows_drag), TEST_CASE(test_pan_keeps_point_under_cursor),
          TEST_CASE(test_dolly_clamps), TEST_CASE(test_tolerance_ladder), TEST_CASE(test_key_table),
          TEST_CASE(test_desc_check))
