/*
 * Headless GL for the render tests: one context per test program, made by
 * the `setup` test case and freed by `teardown` (list them first and last in
 * TEST_MAIN). A machine without OpenGL 4.5 fails setup with the reason, and
 * the tests in between skip their GL work (gl stays NULL).
 */
#ifndef ASP_TESTS_GL_HARNESS_H
#define ASP_TESTS_GL_HARNESS_H

#include "amgsplat/render.h"
#include "harness.h"

static asp_gl_context *gl;

static void setup(void)
{
    asp_error err = {0, ""};
    int rc = asp_gl_context_create_headless(&(asp_gl_context_desc){.flags = ASP_GL_CONTEXT_DEBUG}, &gl, &err);
    CHECK_MSG(rc == 0, "no headless GL: %s", err.msg);
}

static void teardown(void)
{
    asp_gl_context_destroy(gl);
    gl = NULL;
}

#endif
