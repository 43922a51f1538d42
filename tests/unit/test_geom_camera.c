/*
 * Orbit camera math (src/geom/camera.c, camera.h; no GL, so the no-GL build
 * runs it too): view frame conventions, projection of known points to known
 * pixels, and asp_camera_fit keeping a bounding sphere inside the frustum
 * while touching its nearer sides.
 */
#include <math.h>

#include "amgsplat/camera.h"
#include "harness.h"

static const double deg = 3.14159265358979323846 / 180.0;

static void mul_point(const float m[16], const float p[3], double out[4])
{
    for (int r = 0; r < 4; r++)
        out[r] = (double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] + m[12 + r];
}

static void test_defaults(void)
{
    asp_camera cam;
    asp_camera_init(&cam);
    CHECK_NEAR(cam.fov_y, 40.0, 0);
    CHECK_NEAR(cam.aspect, 1.0, 0);
    CHECK(cam.distance > 0 && cam.z_near > 0 && cam.z_far > cam.z_near);
    float eye[3];
    asp_camera_eye(&cam, eye);
    // azimuth 0, elevation 0 looks from +z
    CHECK_NEAR(eye[0], 0, 1e-6);
    CHECK_NEAR(eye[1], 0, 1e-6);
    CHECK_NEAR(eye[2], cam.distance, 1e-6);
}

/* The view matrix is rigid, sends the eye to the origin and the target to (0, 0, -distance). */
static void test_view_frame(void)
{
    static const float angles[][2] = {{0, 0}, {90, 0}, {-30, 20}, {200, -45}, {10, 90}, {75, -90}};
    for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.target[0] = 1.5f, cam.target[1] = -2.0f, cam.target[2] = 0.25f;
        cam.azimuth = angles[a][0];
        cam.elevation = angles[a][1];
        cam.distance = 4.0f;
        float m[16], eye[3];
        asp_camera_view_matrix(&cam, m);
        asp_camera_eye(&cam, eye);
        double e[4], t[4];
        mul_point(m, eye, e);
        mul_point(m, cam.target, t);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(e[k], 0, 1e-5);
        CHECK_NEAR(t[0], 0, 1e-5);
        CHECK_NEAR(t[1], 0, 1e-5);
        CHECK_NEAR(t[2], -4.0, 1e-5);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double dot = 0;
                for (int k = 0; k < 3; k++)
                    dot += (double)m[k * 4 + i] * m[k * 4 + j];
                CHECK_NEAR(dot, i == j ? 1.0 : 0.0, 1e-6);
            }
        // elevation: the eye is above the target by distance * sin(el)
        CHECK_NEAR(eye[1] - cam.target[1], 4.0 * sin(angles[a][1] * deg), 1e-5);
    }
    // azimuth 90 looks from +x; world +y stays image up at elevation 0, and -z is to the right
    asp_camera cam;
    asp_camera_init(&cam);
    cam.azimuth = 90;
    float eye[3], m[16];
    asp_camera_eye(&cam, eye);
    CHECK_NEAR(eye[0], cam.distance, 1e-5);
    asp_camera_view_matrix(&cam, m);
    float minus_z[3] = {0, 0, -1}, plus_y[3] = {0, 1, 0};
    double r[4], u[4];
    mul_point(m, minus_z, r);
    mul_point(m, plus_y, u);
    CHECK(r[0] > 0.99 && u[1] > 0.99);
}

static void test_project_known_points(void)
{
    asp_camera cam;
    asp_camera_init(&cam);
    cam.distance = 5.0f;
    cam.aspect = 2.0f;
    cam.z_near = 1.0f;
    cam.z_far = 10.0f;
    const uint32_t w = 200, h = 100;
    float out[3];
    float origin[3] = {0, 0, 0};
    CHECK(asp_camera_project(&cam, origin, w, h, out) == 1);
    CHECK_NEAR(out[0], 100.0, 1e-3);
    CHECK_NEAR(out[1], 50.0, 1e-3);
    // perspective depth of eye distance 5 with near 1, far 10
    double z_ndc = (10.0 + 1.0) / (10.0 - 1.0) - 2.0 * 10.0 * 1.0 / ((10.0 - 1.0) * 5.0);
    CHECK_NEAR(out[2], 0.5 * z_ndc + 0.5, 1e-5);
    // the top edge of the frustum at the target's depth is y = 5 tan(20 deg): pixel row 0
    float top[3] = {0, (float)(5.0 * tan(20 * deg)), 0};
    CHECK(asp_camera_project(&cam, top, w, h, out) == 1);
    CHECK_NEAR(out[0], 100.0, 1e-3);
    CHECK_NEAR(out[1], 0.0, 1e-3);
    // the right edge: x = aspect * 5 tan(20 deg) is column w; a quarter of the way is column 125
    float right[3] = {(float)(0.25 * 2.0 * 5.0 * tan(20 * deg)), 0, 0};
    CHECK(asp_camera_project(&cam, right, w, h, out) == 1);
    CHECK_NEAR(out[0], 125.0, 1e-3);
    CHECK_NEAR(out[1], 50.0, 1e-3);
    // on the near plane the window depth is 0, on the far plane 1
    float on_near[3] = {0, 0, 4.0f}, on_far[3] = {0, 0, -5.0f};
    CHECK(asp_camera_project(&cam, on_near, w, h, out) == 1);
    CHECK_NEAR(out[2], 0.0, 1e-5);
    CHECK(asp_camera_project(&cam, on_far, w, h, out) == 1);
    CHECK_NEAR(out[2], 1.0, 1e-5);
    // behind the eye: refused, out untouched
    float behind[3] = {0, 0, 6.0f};
    out[0] = -7.0f;
    CHECK(asp_camera_project(&cam, behind, w, h, out) == 0);
    CHECK(out[0] == -7.0f);
}

/* Samples the sphere densely; returns the largest distance of a projection from the image centre per axis. */
static void sphere_extent(const asp_camera *cam, const float c[3], float r, uint32_t w, uint32_t h, double *max_dx,
                          double *max_dy, int *inside)
{
    *max_dx = *max_dy = 0;
    *inside = 1;
    const int n = 20000;
    for (int i = 0; i < n; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / n, rho = sqrt(1.0 - y * y), phi = i * 2.399963229728653;
        float p[3] = {(float)(c[0] + r * rho * cos(phi)), (float)(c[1] + r * y), (float)(c[2] + r * rho * sin(phi))};
        float o[3];
        if (!asp_camera_project(cam, p, w, h, o)) {
            *inside = 0;
            continue;
        }
        if (o[0] < -1e-3 || o[0] > w + 1e-3 || o[1] < -1e-3 || o[1] > h + 1e-3 || o[2] <= 0 || o[2] >= 1)
            *inside = 0;
        *max_dx = fmax(*max_dx, fabs(o[0] - 0.5 * w));
        *max_dy = fmax(*max_dy, fabs(o[1] - 0.5 * h));
    }
}

static void test_fit_sphere_in_frustum(void)
{
    static const float cases[][3] = {{0, 0, 1}, {30, 20, 1}, {-120, -60, 2}, {45, 89, 0.5f}, {10, 10, 0.75f}};
    const float center[3] = {10.0f, -3.0f, 2.5f};
    const float radius = 2.0f;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = cases[k][0];
        cam.elevation = cases[k][1];
        float aspect = cases[k][2];
        asp_camera_fit(&cam, center, radius, aspect);
        CHECK_NEAR(cam.aspect, aspect, 0);
        CHECK_NEAR(cam.target[0], center[0], 0);
        uint32_t h = 300, w = (uint32_t)lround(300 * aspect);
        double dx, dy;
        int inside;
        sphere_extent(&cam, center, radius, w, h, &dx, &dy, &inside);
        CHECK_MSG(inside, "case %zu: sphere leaves the frustum", k);
        // the nearer pair of sides is touched (within the sampling density)
        double fill = aspect >= 1 ? dy / (0.5 * h) : dx / (0.5 * w);
        CHECK_MSG(fill > 0.99 && fill < 1.0 + 1e-4, "case %zu: sphere fills %.4f of the view", k, fill);
        CHECK_NEAR(cam.distance, asp_camera_fit_distance(&cam, radius), 1e-4);
    }
    // twice the distance: half the angular size, still inside
    asp_camera cam;
    asp_camera_init(&cam);
    asp_camera_fit(&cam, center, radius, 1.0f);
    double d0 = cam.distance;
    cam.distance *= 2.0f;
    asp_camera_clip_to_sphere(&cam, center, radius);
    double dx, dy;
    int inside;
    sphere_extent(&cam, center, radius, 100, 100, &dx, &dy, &inside);
    CHECK(inside);
    double expect = 50.0 * tan(asin(radius / (2 * d0))) / tan(20 * deg);
    CHECK_NEAR(dy, expect, 0.05);
}

static void test_clip_inside_sphere(void)
{
    asp_camera cam;
    asp_camera_init(&cam);
    const float c[3] = {0, 0, 0};
    cam.distance = 0.5f;
    asp_camera_clip_to_sphere(&cam, c, 2.0f);
    CHECK_NEAR(cam.z_near, 1e-3 * 2.5, 1e-7);
    CHECK_NEAR(cam.z_far, 1.01 * 2.5, 1e-6);
    cam.distance = 10.0f;
    asp_camera_clip_to_sphere(&cam, c, 2.0f);
    CHECK_NEAR(cam.z_near, 0.99 * 8.0, 1e-5);
    CHECK_NEAR(cam.z_far, 1.01 * 12.0, 1e-5);
}

/*
 * The up axis: at elevation 0 the chosen axis is image up, elevation raises
 * the eye along it, azimuth turns around it, and the frame stays orthonormal
 * and right-handed. Azimuth 0 looks from +z (y up, x up) or from -y (z up,
 * the front view of z-up tools).
 */
static void test_up_axis(void)
{
    static const struct {
        asp_up_axis up;
        float axis[3], front[3]; /* image up, and the eye direction at azimuth 0 */
    } cases[] = {
        {ASP_UP_Y, {0, 1, 0}, {0, 0, 1}},
        {ASP_UP_Z, {0, 0, 1}, {0, -1, 0}},
        {ASP_UP_X, {1, 0, 0}, {0, 0, 1}},
        {ASP_UP_NEG_Y, {0, -1, 0}, {0, 0, 1}},
        {ASP_UP_NEG_Z, {0, 0, -1}, {0, -1, 0}},
        {ASP_UP_NEG_X, {-1, 0, 0}, {0, 0, 1}},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.up = cases[c].up;
        float eye[3], m[16];
        asp_camera_eye(&cam, eye);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(eye[k], cam.distance * cases[c].front[k], 1e-5);
        asp_camera_view_matrix(&cam, m);
        double u[4];
        mul_point(m, cases[c].axis, u);
        CHECK_MSG(u[1] > 0.999, "up axis %d is not image up: %g %g %g", (int)cases[c].up, u[0], u[1], u[2]);
        // right-handed: right x up = back (rows 0, 1, 2 of the rotation)
        double x[3] = {m[0], m[4], m[8]}, y[3] = {m[1], m[5], m[9]}, z[3] = {m[2], m[6], m[10]};
        CHECK_NEAR(x[1] * y[2] - x[2] * y[1], z[0], 1e-6);
        CHECK_NEAR(x[2] * y[0] - x[0] * y[2], z[1], 1e-6);
        CHECK_NEAR(x[0] * y[1] - x[1] * y[0], z[2], 1e-6);
        // elevation 90 puts the eye on the up axis; any azimuth keeps it at the same height
        cam.elevation = 90;
        asp_camera_eye(&cam, eye);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(eye[k], cam.distance * cases[c].axis[k], 1e-5);
        cam.elevation = 30;
        for (float az = 0; az < 360; az += 45) {
            cam.azimuth = az;
            asp_camera_eye(&cam, eye);
            double h = eye[0] * cases[c].axis[0] + eye[1] * cases[c].axis[1] + eye[2] * cases[c].axis[2];
            CHECK_NEAR(h, cam.distance * 0.5, 1e-5);
        }
    }
}

/* An instance placed by model seen through view: view * model on local points, and the eye moved into the local frame. */
/*
 * The box framing of a flat, wide set (issue 29): a 60 x 40 x 5 m z-up site seen with up z from
 * several views and aspects has every box corner inside the image and one on its edge (the box
 * fills the view), nearer than the sphere fit; the same box seen with up y (then it stands 40 m
 * tall: not flat along up), a compact box and a box of unknown sides keep the sphere distance.
 */
static void test_frame_flat_box(void)
{
    const asp_frame site = {.center = {500030, 4100020, 102.5}, .radius = 36.15, .half = {30, 20, 2.5},
                            .up = ASP_UP_Z};
    const double origin[3] = {500000, 4100000, 100};
    static const float views[][3] = {{30, 20, 1}, {30, 20, 16.0f / 9}, {0, 90, 1}, {-60, 45, 0.75f}};
    for (size_t v = 0; v < sizeof views / sizeof views[0]; v++) {
        asp_camera cam, sphere;
        asp_camera_init(&cam);
        cam.up = ASP_UP_Z;
        cam.azimuth = views[v][0];
        cam.elevation = views[v][1];
        sphere = cam;
        asp_camera_frame(&cam, &site, origin, views[v][2], 0.0f);
        float c[3] = {30, 20, 2.5f};
        asp_camera_fit(&sphere, c, (float)site.radius, views[v][2]);
        CHECK_MSG(cam.distance < sphere.distance, "view %zu: box distance %g, sphere %g", v, cam.distance,
                  sphere.distance);
        uint32_t w = (uint32_t)lround(300 * views[v][2]), h = 300;
        double margin = 1e9;
        for (int i = 0; i < 8; i++) {
            float p[3] = {c[0] + (i & 1 ? 30.0f : -30.0f), c[1] + (i & 2 ? 20.0f : -20.0f), c[2] + (i & 4 ? 2.5f : -2.5f)};
            float o[3];
            CHECK(asp_camera_project(&cam, p, w, h, o));
            CHECK_MSG(o[0] >= -0.01 && o[0] <= w + 0.01 && o[1] >= -0.01 && o[1] <= h + 0.01 && o[2] > 0 && o[2] < 1,
                      "view %zu: corner %d at (%g, %g, %g), outside the %ux%u view", v, i, o[0], o[1], o[2], w, h);
            margin = fmin(margin, fmin(fmin(o[0], w - o[0]), fmin(o[1], h - o[1])));
        }
        CHECK_MSG(margin < 0.01, "view %zu: the box is %g pixels from the nearest side, expected touching", v, margin);
    }
    static const asp_frame keep[] = {
        {.center = {0, 0, 0}, .radius = 36.15, .half = {30, 20, 2.5}, .up = ASP_UP_Y}, // up y: 40 m tall
        {.center = {0, 0, 0}, .radius = 1.7, .half = {1, 1, 0.8}, .up = ASP_UP_Y},     // compact
        {.center = {0, 0, 0}, .radius = 36.15, .up = ASP_UP_Z},                        // sides unknown
    };
    for (size_t k = 0; k < sizeof keep / sizeof keep[0]; k++) {
        asp_camera cam, sphere;
        asp_camera_init(&cam);
        cam.up = keep[k].up;
        cam.azimuth = 30;
        cam.elevation = 20;
        sphere = cam;
        asp_camera_frame(&cam, &keep[k], NULL, 1.0f, 0.0f);
        const float zero[3] = {0, 0, 0};
        asp_camera_fit(&sphere, zero, (float)keep[k].radius, 1.0f);
        CHECK_MSG(cam.distance == sphere.distance, "case %zu: distance %g, the sphere's %g", k, cam.distance,
                  sphere.distance);
    }
}

static void test_fold_model(void)
{
    asp_camera cam;
    asp_camera_init(&cam);
    cam.azimuth = 40;
    cam.elevation = 25;
    cam.distance = 7;
    float view[16], eye[3];
    asp_camera_view_matrix(&cam, view);
    asp_camera_eye(&cam, eye);
    // model: scale 2, turn 90 degrees about +y, move by (3, -1, 5)
    const float model[16] = {0, 0, -2, 0, 0, 2, 0, 0, 2, 0, 0, 0, 3, -1, 5, 1};
    float folded[16], local_eye[3];
    asp_camera_fold_model(view, eye, model, folded, local_eye);
    const float p[3] = {0.5f, -1.0f, 2.0f};
    double world[4], a[4], b[4];
    mul_point(model, p, world);
    const float w[3] = {(float)world[0], (float)world[1], (float)world[2]};
    mul_point(view, w, a);
    mul_point(folded, p, b);
    for (int k = 0; k < 4; k++)
        CHECK_NEAR(b[k], a[k], 1e-5);
    // the local eye maps back onto the world eye
    double back[4];
    mul_point(model, local_eye, back);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(back[k], eye[k], 1e-5);
    // in place, as the scene renderer calls it
    asp_camera_fold_model(view, eye, model, view, eye);
    for (int k = 0; k < 16; k++)
        CHECK_NEAR(view[k], folded[k], 0);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(eye[k], local_eye[k], 0);
}

/* The frustum planes keep what projects inside the clip cube and cut what does not, each plane its side. */
static void test_frustum_planes(void)
{
    asp_camera cam;
    asp_camera_init(&cam);
    cam.azimuth = -20;
    cam.elevation = 10;
    cam.aspect = 2.0f;
    float view[16], proj[16], planes[6][4];
    asp_camera_view_matrix(&cam, view);
    asp_camera_projection_matrix(&cam, proj);
    asp_camera_frustum_planes(view, proj, planes);
    for (int i = 0; i < 6; i++)
        CHECK_NEAR(sqrt(planes[i][0] * planes[i][0] + planes[i][1] * planes[i][1] + planes[i][2] * planes[i][2]), 1.0,
                   1e-5);
    // the target is inside every plane
    for (int i = 0; i < 6; i++)
        CHECK(planes[i][0] * cam.target[0] + planes[i][1] * cam.target[1] + planes[i][2] * cam.target[2] +
                  planes[i][3] > 0);
    // a point just past the left, right, bottom, top, near and far side is outside exactly that plane
    double t = tan(0.5 * cam.fov_y * deg), d = cam.distance;
    const double ndc[6][3] = {{-1.1, 0, 0}, {1.1, 0, 0}, {0, -1.1, 0}, {0, 1.1, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int i = 0; i < 6; i++) {
        // eye coordinates of the probe: at depth d, scaled past the side; near and far along the axis
        double z = i == 4 ? 0.5 * cam.z_near : i == 5 ? 1.1 * cam.z_far : d;
        double e[3] = {ndc[i][0] * t * cam.aspect * z, ndc[i][1] * t * z, -z};
        // back to world: the view matrix is rigid, so world = R^T (e - translation)
        float x[3];
        for (int k = 0; k < 3; k++)
            x[k] = (float)(view[4 * k] * (e[0] - view[12]) + view[4 * k + 1] * (e[1] - view[13]) +
                           view[4 * k + 2] * (e[2] - view[14]));
        for (int j = 0; j < 6; j++) {
            double s = planes[j][0] * x[0] + planes[j][1] * x[1] + planes[j][2] * x[2] + planes[j][3];
            CHECK_MSG(j == i ? s < 0 : s > 0, "probe %d, plane %d: %g", i, j, s);
        }
    }
}

TEST_MAIN(TEST_CASE(test_defaults), TEST_CASE(test_view_frame), TEST_CASE(test_project_known_points),
          TEST_CASE(test_fit_sphere_in_frustum), TEST_CASE(test_clip_inside_sphere), TEST_CASE(test_up_axis),
          TEST_CASE(test_fold_model), TEST_CASE(test_frustum_planes), TEST_CASE(test_frame_flat_box))
