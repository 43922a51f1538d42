/*
 * Headless GL for the render tests: one context per test program, made by
 * the `setup` test case and freed by `teardown` (list them first and last in
 * TEST_MAIN). A machine without OpenGL 4.5 fails setup with the reason, and
 * the tests in between skip their GL work (gl stays NULL).
 */
#ifndef ASP_TESTS_GL_HARNESS_H
#define ASP_TESTS_GL_HARNESS_H

#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/image.h"
#include "amgsplat/render.h"
#include "harness.h"

static asp_gl_context *gl;

static inline void setup(void)
{
    asp_error err = {0, ""};
    int rc = asp_gl_context_create_headless(&(asp_gl_context_desc){.flags = ASP_GL_CONTEXT_DEBUG}, NULL, &gl, &err);
    CHECK_MSG(rc == 0, "no headless GL: %s", err.msg);
}

static inline void teardown(void)
{
    asp_gl_context_destroy(gl);
    gl = NULL;
}

/* The views of `amgsplat render --views n --view 30,20`: azimuth 30 + 360 i / n, elevation +-20. */
static inline void test_view_camera(asp_camera *cam, size_t i, size_t n, const float center[3], float radius)
{
    asp_camera_init(cam);
    cam->azimuth = 30.0f + 360.0f * (float)i / (float)n;
    cam->elevation = i % 2 ? -20.0f : 20.0f;
    asp_camera_fit(cam, center, radius, 1.0f);
}

/* Saves n tiles as a contact sheet DIR/name.png when the environment variable env names a DIR. */
static inline void test_save_sheet(const asp_image *tiles, size_t n, const char *env, const char *name)
{
    const char *dir = getenv(env);
    if (!dir)
        return;
    asp_image sheet = {0};
    asp_error err;
    char path[512];
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    if (asp_image_contact_sheet(tiles, n, 0, &sheet, &err) == 0)
        asp_image_save_png(&sheet, path, &err);
    asp_image_release(&sheet);
}

#endif
