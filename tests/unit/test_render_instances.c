/*
 * The scene renderer (scene_renderer.h) over scene files of instances
 * (instances.h) on a headless GL context: two cubes side by side both show,
 * with equal pixel counts; a near instance hides a far one whatever the file
 * order, for discs and blended splats; instances outside the frustum are
 * skipped; bad groups are refused without leaks.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/eval.h"
#include "amgsplat/instances.h"
#include "amgsplat/sample.h"
#include "amgsplat/scene_renderer.h"
#include "gl_harness.h"
#include "harness.h"

static asp_error *ep(asp_error *e)
{
    return e;
}

static char dir[] = "/tmp/asp_test_render_instances_XXXXXX";

static void path_in(char *out, size_t cap, const char *name)
{
    snprintf(out, cap, "%s/%s", dir, name);
}

static void write_text(const char *name, const char *text)
{
    char p[600];
    path_in(p, sizeof p, name);
    FILE *fp = fopen(p, "w");
    CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

/* A square of side x side points in z = 0, side 2, facing +z, one colour. */
static void save_plane(const char *name, const uint8_t rgb[3])
{
    int side = 60;
    asp_cloud *c = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_cloud_create((size_t)side * side, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err),
             ep(&err));
    if (!c)
        return;
    float h = 2.0f / (float)(side - 1);
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            size_t p = (size_t)j * side + i;
            c->positions[3 * p + 0] = -1.0f + (float)i * h;
            c->positions[3 * p + 1] = -1.0f + (float)j * h;
            c->positions[3 * p + 2] = 0.0f;
            c->normals[3 * p + 0] = c->normals[3 * p + 1] = 0.0f;
            c->normals[3 * p + 2] = 1.0f;
            memcpy(c->colors + 4 * p, rgb, 3);
            c->colors[4 * p + 3] = 255;
            c->radii[p] = 0.75f * h;
        }
    char p[600];
    path_in(p, sizeof p, name);
    CHECK_OK(asp_cloud_save(c, p, NULL, &err), ep(&err));
    asp_cloud_destroy(c);
}

static void setup_files(void)
{
    CHECK(mkdtemp(dir) != NULL);
    asp_cloud *c = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_synth(ASP_SYNTH_CUBE, &(asp_synth_desc){.points = 12000}, NULL, &c, &err), ep(&err));
    char p[600];
    path_in(p, sizeof p, "cube.ply");
    if (c)
        CHECK_OK(asp_cloud_save(c, p, NULL, &err), ep(&err));
    asp_cloud_destroy(c);
    save_plane("red.ply", (const uint8_t[3]){220, 20, 20});
    save_plane("blue.ply", (const uint8_t[3]){20, 20, 220});
}

static void remove_files(void)
{
    static const char *const names[] = {"cube.ply", "red.ply", "blue.ply", "two.json", "near_first.json",
                                        "far_first.json", "behind.json", "field.json"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char p[600];
        path_in(p, sizeof p, names[i]);
        unlink(p);
    }
    rmdir(dir);
}

/* Renders scene file name with the point renderer into *img (orbit view az, el when orbit). */
static int render(const char *name, const char *renderer, int orbit, asp_image *img, size_t *drawn)
{
    char p[600];
    path_in(p, sizeof p, name);
    asp_instance_scene s;
    asp_error err = {0, ""};
    int rc = asp_instance_scene_load(p, NULL, NULL, &s, &err);
    CHECK_OK(rc, ep(&err));
    if (rc)
        return rc;
    asp_renderer *r = NULL;
    asp_renderer_options o;
    memset(&o, 0, sizeof o);
    o.splat.tolerance = 0.5f;
    rc = asp_instance_scene_renderer_create(gl, &s, renderer, &o, NULL, &r, &err);
    CHECK_OK(rc, ep(&err));
    if (!rc) {
        asp_camera cam;
        asp_instance_scene_camera(&s, orbit, 1.0f, 40.0f, 0.0f, 0.0f, 0.0f, &cam);
        asp_render_desc d = {.width = 128, .height = 128, .samples = 1, .background = {255, 255, 255, 255}};
        rc = asp_render_to_image(gl, r, &cam, &d, img, &err);
        CHECK_OK(rc, ep(&err));
        if (drawn)
            *drawn = asp_scene_renderer_drawn(r);
    }
    asp_renderer_destroy(r);
    asp_instance_scene_release(&s);
    return rc;
}

static int is_background(const uint8_t *p)
{
    return p[0] > 245 && p[1] > 245 && p[2] > 245;
}

/* Two cubes side by side, seen head on: both drawn, mirror images in pixel count. */
static void test_two_cubes(void)
{
    if (!gl)
        return;
    write_text("two.json", "{\"version\": 1, \"instances\": [{\"source\": \"cube.ply\", \"translate\": [-2, 0, 0]},"
                           "{\"source\": \"cube.ply\", \"translate\": [2, 0, 0]}]}");
    static const char *const renderers[] = {"disc", "splat"};
    for (int k = 0; k < 2; k++) {
        asp_image img = {0};
        size_t drawn = 0;
        if (render("two.json", renderers[k], 1, &img, &drawn))
            continue;
        size_t left = 0, right = 0;
        for (uint32_t y = 0; y < img.height; y++)
            for (uint32_t x = 0; x < img.width; x++)
                if (!is_background(img.pixels + 4 * ((size_t)y * img.width + x)))
                    *(x < img.width / 2 ? &left : &right) += 1;
        // each cube's front face spans about a fifth of the width: 0.2^2 of the pixels, and more for the sides
        CHECK_MSG(left > 400 && right > 400, "%s: left %zu, right %zu pixels", renderers[k], left, right);
        CHECK_MSG(fabs((double)left - (double)right) < 0.05 * (double)(left + right), "%s: left %zu, right %zu",
                  renderers[k], left, right);
        CHECK(drawn == 2);
        // the gap between them stays background
        CHECK(is_background(img.pixels + 4 * ((size_t)64 * img.width + 64)));
        asp_image_release(&img);
    }
}

/* A red square 5 units in front of a larger blue one: red covers the centre whatever the file order. */
static void test_occlusion(void)
{
    if (!gl)
        return;
    const char *cam = "\"camera\": {\"eye\": [0, 0, 10], \"target\": [0, 0, 0], \"fov\": 40}";
    char text[600];
    snprintf(text, sizeof text,
             "{\"version\": 1, \"instances\": [{\"source\": \"red.ply\"},"
             "{\"source\": \"blue.ply\", \"translate\": [0, 0, -5], \"scale\": 3}], %s}",
             cam);
    write_text("near_first.json", text);
    snprintf(text, sizeof text,
             "{\"version\": 1, \"instances\": [{\"source\": \"blue.ply\", \"translate\": [0, 0, -5], \"scale\": 3},"
             "{\"source\": \"red.ply\"}], %s}",
             cam);
    write_text("far_first.json", text);
    static const char *const files[] = {"near_first.json", "far_first.json"};
    static const char *const renderers[] = {"disc", "splat", "square"};
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < 3; k++) {
            asp_image img = {0};
            if (render(files[f], renderers[k], 0, &img, NULL))
                continue;
            const uint8_t *c = img.pixels + 4 * ((size_t)64 * img.width + 64);
            // half sides on screen: red 64 (1/10) / tan 20 = 17.6 px, blue 64 (3/15) / tan 20 = 35 px
            const uint8_t *b = img.pixels + 4 * ((size_t)64 * img.width + 64 + 26);
            CHECK_MSG(c[0] > 100 && c[2] < 60, "%s %s: centre %u,%u,%u (expected red)", files[f], renderers[k], c[0],
                      c[1], c[2]);
            CHECK_MSG(b[2] > 100 && b[0] < 60, "%s %s: side %u,%u,%u (expected blue)", files[f], renderers[k], b[0],
                      b[1], b[2]);
            asp_image_release(&img);
        }
}

/* An instance behind the eye is culled; the one in front is drawn. */
static void test_culling(void)
{
    if (!gl)
        return;
    write_text("behind.json", "{\"version\": 1, \"instances\": [{\"source\": \"red.ply\"},"
                              "{\"source\": \"blue.ply\", \"translate\": [0, 0, 20]}],"
                              "\"camera\": {\"eye\": [0, 0, 10], \"target\": [0, 0, 0]}}");
    asp_image img = {0};
    size_t drawn = 0;
    if (render("behind.json", "disc", 0, &img, &drawn) == 0) {
        CHECK(drawn == 1);
        const uint8_t *c = img.pixels + 4 * ((size_t)64 * img.width + 64);
        CHECK(c[0] > 100 && c[2] < 60);
    }
    asp_image_release(&img);
}

/* Renders s with the splat renderer, instanced (one accumulation) or one draw per instance. */
static int render_splats(const asp_instance_scene *s, int one_by_one, asp_image *img)
{
    asp_error err = {0, ""};
    const asp_scene *sc = &s->sources[0].scene;
    asp_render_source src;
    asp_scene_render_source(sc, &src);
    asp_scene_renderer_group g = {.count = s->instance_count, .radius = (float)sc->frame.radius,
                                  .one_by_one = one_by_one};
    float *models = malloc(16 * s->instance_count * sizeof *models);
    CHECK(models != NULL);
    if (!models)
        return 1;
    asp_instance_scene_models(s, 0, models);
    g.models = models;
    int rc = asp_splat_renderer_create(gl, sc->cloud, &(asp_splat_renderer_desc){.tolerance = 1.0f}, NULL,
                                       &g.renderer, &err);
    CHECK_OK(rc, ep(&err));
    asp_renderer *r = NULL;
    if (!rc)
        rc = asp_scene_renderer_create(gl, &g, 1, &r, &err);
    free(models);
    if (!rc) {
        asp_camera cam;
        asp_instance_scene_camera(s, 0, 1.0f, 40.0f, 0.0f, 0.0f, 0.0f, &cam);
        asp_render_desc d = {.width = 128, .height = 128, .samples = 1, .background = {255, 255, 255, 255}};
        rc = asp_render_to_image(gl, r, &cam, &d, img, &err);
        CHECK_OK(rc, ep(&err));
    }
    asp_renderer_destroy(r);
    return rc;
}

/* The splats' instanced draw (one accumulation) shows what one draw per instance shows. */
static void test_instanced_matches(void)
{
    if (!gl)
        return;
    char p[600];
    path_in(p, sizeof p, "cube.ply");
    asp_scene model;
    asp_instance_scene field, s;
    asp_error err = {0, ""};
    CHECK_OK(asp_scene_load(p, NULL, NULL, &model, &err), ep(&err));
    CHECK_OK(asp_instance_field(&model, "cube.ply", &(asp_instance_field_desc){.instances = 12, .seed = 5}, &field,
                                &err),
             ep(&err));
    path_in(p, sizeof p, "field.json");
    CHECK_OK(asp_instance_scene_save(&field, p, &err), ep(&err));
    CHECK_OK(asp_instance_scene_load(p, NULL, NULL, &s, &err), ep(&err));
    asp_image a = {0}, b = {0};
    if (s.instance_count == 12 && render_splats(&s, 0, &a) == 0 && render_splats(&s, 1, &b) == 0) {
        double ssim = 0, psnr = 0;
        CHECK_OK(asp_image_ssim(&a, &b, &ssim, &err), ep(&err));
        CHECK_OK(asp_image_psnr(&a, &b, &psnr, &err), ep(&err));
        CHECK_MSG(ssim > 0.995 && psnr > 35, "instanced against one by one: SSIM %.4f, PSNR %.1f", ssim, psnr);
        size_t fg = 0;
        for (size_t i = 0; i < (size_t)a.width * a.height; i++)
            fg += a.pixels[4 * i] < 245 || a.pixels[4 * i + 2] < 245;
        CHECK_MSG(fg > 2000, "only %zu pixels drawn", fg); // the near cube alone fills a large part
    }
    asp_image_release(&a);
    asp_image_release(&b);
    asp_instance_scene_release(&s);
    asp_instance_scene_release(&field);
    asp_scene_release(&model);
}

/* Bad groups are refused, and the renderers handed over are freed (ASan watches). */
static void test_bad_groups(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_renderer *out = NULL;
    CHECK(asp_scene_renderer_create(gl, NULL, 0, &out, &err) == ASP_EINVAL);
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 500}, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    asp_renderer *disc = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &disc, &err), ep(&err));
    float models[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    models[16] = NAN;
    asp_scene_renderer_group g = {.renderer = disc, .models = models, .count = 2, .radius = 1.0f};
    CHECK(asp_scene_renderer_create(gl, &g, 1, &out, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "instance 1") != NULL);
    CHECK(out == NULL);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_FIXTURE(setup_files), TEST_CASE(test_two_cubes), TEST_CASE(test_occlusion),
          TEST_CASE(test_culling), TEST_CASE(test_instanced_matches), TEST_CASE(test_bad_groups), TEST_FIXTURE(remove_files), TEST_FIXTURE(teardown))
