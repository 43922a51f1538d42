/*
 * One camera framing in every build (issue 26, "the no-GL build frames a
 * scene exactly as the GL build does"): the frame eval's scene loader gives a
 * point file, a .dps that records no frame and has lost its source (the
 * level's own bounds: the case the no-GL build used to refuse), and a scene of
 * instances, and the camera fitted to each (camera.h). The expected numbers
 * were printed by the GL build (ASP_CAMERA_PRINT=1 prints them again); this
 * test runs unchanged in the GL and the no-GL build, so both compute the same
 * cameras to float rounding.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/camera.h"
#include "amgsplat/instances.h"
#include "amgsplat/prim.h"
#include "amgsplat/scene.h"
#include "harness.h"

static asp_error *ep(asp_error *e)
{
    return e;
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

/* What a camera shows: the frame it was fitted to and the camera's own numbers. */
typedef struct pinned {
    double center[3], radius;
    float eye[3], distance, z_near, z_far;
    float view[3]; /* view matrix entries 0, 6 and 14: a rotation, and the translation along the view axis */
} pinned;

static void camera_figures(const asp_frame *f, const asp_camera *cam, pinned *out)
{
    memcpy(out->center, f->center, sizeof out->center);
    out->radius = f->radius;
    asp_camera_eye(cam, out->eye);
    out->distance = cam->distance;
    out->z_near = cam->z_near;
    out->z_far = cam->z_far;
    float v[16];
    asp_camera_view_matrix(cam, v);
    out->view[0] = v[0];
    out->view[1] = v[6];
    out->view[2] = v[14];
}

/* Equal to float rounding (relative 1e-6 of the scene's size); prints the figures on request. */
static void check_pinned(const char *what, const pinned *got, const pinned *want)
{
    if (getenv("ASP_CAMERA_PRINT"))
        printf("%s: {{%.9g, %.9g, %.9g}, %.9g, {%.9gf, %.9gf, %.9gf}, %.9gf, %.9gf, %.9gf, {%.9gf, %.9gf, %.9gf}}\n",
               what, got->center[0], got->center[1], got->center[2], got->radius, (double)got->eye[0],
               (double)got->eye[1], (double)got->eye[2], (double)got->distance, (double)got->z_near,
               (double)got->z_far, (double)got->view[0], (double)got->view[1], (double)got->view[2]);
    double tol = 1e-6 * (want->radius + fabs(want->distance));
    for (int k = 0; k < 3; k++) {
        CHECK_NEAR(got->center[k], want->center[k], tol);
        CHECK_NEAR(got->eye[k], want->eye[k], tol);
        CHECK_NEAR(got->view[k], want->view[k], tol);
    }
    CHECK_NEAR(got->radius, want->radius, tol);
    CHECK_NEAR(got->distance, want->distance, tol);
    CHECK_NEAR(got->z_near, want->z_near, tol);
    CHECK_NEAR(got->z_far, want->z_far, tol);
}

/* The orbit view of the scene tests: azimuth 30, elevation 20, a 3:2 image. */
static void orbit_camera(const asp_scene *s, asp_camera *cam)
{
    asp_camera_init(cam);
    cam->azimuth = 30;
    cam->elevation = 20;
    asp_camera_frame(cam, &s->frame, s->origin, 1.5f, 0.0f);
}

static void test_point_file(void)
{
    char dir[] = "/tmp/asp_test_scene_camera_XXXXXX", path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/p.ply", dir);
    write_text(path, "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                     "property float z\nproperty float radius\nend_header\n"
                     "1 2 3 0.1\n3 2 3 0.1\n2 4 3 0.2\n2 2 5 0.1\n2.5 3 4 0.1\n");
    asp_scene s;
    asp_error err = {0, ""};
    CHECK_OK(asp_scene_load(path, NULL, NULL, &s, &err), ep(&err));
    if (s.cloud) {
        asp_camera cam;
        orbit_camera(&s, &cam);
        pinned got;
        camera_figures(&s.frame, &cam, &got);
        // the bounds' centre; radius sqrt(3) (the corner points) plus the largest point radius 0.2
        static const pinned want = {{2, 3, 4}, 1.93205081, {4.65413284f, 4.9320507f, 8.59709358f}, 5.64893866f,
                                    3.67971921f, 7.65679979f, {0.866025388f, 0.342020154f, -10.8698826f}};
        check_pinned("point file", &got, &want);
    }
    asp_scene_release(&s);
    unlink(path);
    rmdir(dir);
}

/*
 * A .dps of one level of two primitives that records no frame (radius 0) and names a source that is
 * gone: framed by the level's own bounds (asp_prim_level_bounding_sphere, prim.h) in every build.
 */
static void test_dps_without_frame(void)
{
    char dir[] = "/tmp/asp_test_scene_camera_XXXXXX", path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/l.dps", dir);
    asp_error err = {0, ""};
    asp_prim prims[2];
    uint32_t neighbours[2] = {1, 0};
    memset(prims, 0, sizeof prims);
    for (int k = 0; k < 2; k++) {
        asp_prim *p = &prims[k];
        p->centre[0] = 100.0 + 3.0 * k;
        p->centre[1] = -20.0;
        p->centre[2] = 7.0 + k;
        p->axis_u[0] = 1.0f;
        p->axis_v[1] = 1.0f;
        p->normal[2] = 1.0f;
        p->half_u = 1.0f;
        p->half_v = 0.5f + k;
        p->texel = 0.25f;
        p->points = 10;
        p->basis = (uint32_t)k;
        p->merged = 1;
        p->tex_x = 4u * (uint32_t)k;
        p->tex_w = p->tex_h = 4;
        p->neighbour_first = (uint32_t)k;
        p->neighbour_count = 1;
    }
    asp_dps_level lv;
    memset(&lv, 0, sizeof lv);
    lv.basis_count = 2;
    lv.prim_count = 2;
    lv.prims = prims;
    lv.neighbour_total = 2;
    lv.neighbours = neighbours;
    lv.texels = 32; // two 4 x 4 rectangles (the file checks the sum)
    CHECK_OK(asp_image_init(&lv.atlas, 8, 4, &err), ep(&err));
    memset(lv.atlas.pixels, 255, 8 * 4 * 4);
    asp_dps dps;
    memset(&dps, 0, sizeof dps);
    dps.level_count = 1;
    dps.levels = &lv;
    dps.amg_levels = 1;
    dps.source_points = 20;
    dps.mean_radius = 0.1;
    snprintf(dps.source, sizeof dps.source, "%s/gone.ply", dir);
    CHECK_OK(asp_dps_save(&dps, path, &err), ep(&err));
    asp_image_release(&lv.atlas);

    asp_scene s;
    int rc = asp_scene_load(path, NULL, NULL, &s, &err);
    CHECK_OK(rc, ep(&err));
    if (rc == 0) {
        asp_camera cam;
        orbit_camera(&s, &cam);
        pinned got;
        camera_figures(&s.frame, &cam, &got);
        // corners span x 99..104, y -21.5..-18.5, z 7..8: centre (101.5, -20, 7.5), radius sqrt(8.75)
        static const pinned want = {{101.5, -20, 7.5}, 2.95804, {4.06357384f, 2.95804f, 7.03831673f}, 8.64873028f,
                                    5.63378334f, 11.7228384f, {0.866025388f, 0.342020154f, -8.64873028f}};
        check_pinned(".dps without a frame", &got, &want);
    }
    asp_scene_release(&s);
    unlink(path);
    rmdir(dir);
}

/* A scene of two instances of the point file: its default camera (instances.h), orbit and file camera. */
static void test_instance_scene(void)
{
    char dir[] = "/tmp/asp_test_scene_camera_XXXXXX", ply[64], scene[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(ply, sizeof ply, "%s/p.ply", dir);
    snprintf(scene, sizeof scene, "%s/s.json", dir);
    write_text(ply, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    write_text(scene, "{\"version\": 1, \"instances\": [{\"source\": \"p.ply\"},"
                      "{\"source\": \"p.ply\", \"translate\": [6, 0, -2], \"scale\": 2}]}");
    asp_instance_scene s;
    asp_error err = {0, ""};
    int rc = asp_instance_scene_load(scene, NULL, NULL, &s, &err);
    CHECK_OK(rc, ep(&err));
    if (rc == 0) {
        asp_camera cam;
        asp_instance_scene_camera(&s, 1, 1.5f, 40.0f, 30.0f, 20.0f, 0.0f, &cam);
        pinned got;
        camera_figures(&s.frame, &cam, &got);
        static const pinned want = {{4.67161522, 1, -1}, 6.30443808, {8.66065025f, 6.30443811f, 15.0006866f},
                                    18.4329433f, 12.0072203f, 24.9847546f, {0.866025388f, 0.342020154f, -18.4329433f}};
        check_pinned("instance scene", &got, &want);
    }
    asp_instance_scene_release(&s);
    unlink(ply);
    unlink(scene);
    rmdir(dir);
}

TEST_MAIN(TEST_CASE(test_point_file), TEST_CASE(test_dps_without_frame), TEST_CASE(test_instance_scene))
