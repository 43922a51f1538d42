/*
 * The colour fit (src/fit, issue 27) on a small case: the octahedron's 8 face
 * domains as primitives. A "truth" level with other texel colours is drawn by
 * the CPU rasteriser from training and held-out views; fitting the original
 * level to those images must lower the training loss, lower the held-out
 * loss, leave geometry and alpha (the basis functions, so the partition of
 * unity) unchanged, and give the same bytes for 1 and 2 threads. With GL, the
 * CPU rasteriser must agree with the prim renderer's normalized method.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amgsplat.h"
#include "harness.h"
#include "test_fit_common.h"

enum { NV = 24, NH = 8, SIZE = 96 };

static void test_fit_improves(void)
{
    asp_dps_level lv;
    if (octahedron_level(&lv)) {
        CHECK(0);
        return;
    }
    CHECK(lv.prim_count == 8);
    // the truth: a smooth colour ramp over each texture instead of the face colour
    asp_dps_level truth;
    CHECK(copy_level(&lv, &truth) == 0);
    for (size_t i = 0; i < truth.prim_count; i++) {
        const asp_prim *p = &truth.prims[i];
        for (uint32_t y = p->tex_y; y < p->tex_y + p->tex_h; y++)
            for (uint32_t x = p->tex_x; x < p->tex_x + p->tex_w; x++) {
                uint8_t *px = truth.atlas.pixels + 4 * ((size_t)y * truth.atlas.width + x);
                px[0] = (uint8_t)(40 + 200 * (x - p->tex_x) / p->tex_w);
                px[1] = (uint8_t)(40 + 200 * (y - p->tex_y) / p->tex_h);
                px[2] = (uint8_t)(60 + 20 * i);
            }
    }
    asp_fit_view views[NV + NH];
    asp_image refs[NV + NH];
    float az[NV + NH], el[NV + NH];
    asp_fit_directions(NV, 1, az, el);
    asp_fit_directions(NH, 7, az + NV, el + NV);
    double origin[3] = {0, 0, 0};
    asp_error err = {0};
    for (size_t v = 0; v < NV + NH; v++) {
        look(az[v], el[v], SIZE, &views[v]);
        memset(&refs[v], 0, sizeof refs[v]);
        CHECK_OK(asp_fit_render_cpu(&truth, origin, &views[v], NULL, &refs[v], &err), &err);
    }
    asp_dps_level one, two;
    CHECK(copy_level(&lv, &one) == 0 && copy_level(&lv, &two) == 0);
    asp_fit_stats s1 = {0}, s2 = {0};
    asp_context c1 = {.threads = 1}, c2 = {.threads = 2};
    asp_fit_desc desc = {.iterations = 80};
    CHECK_OK(asp_fit_color(&one, origin, views, refs, NV, views + NV, refs + NV, NH, &desc, &c1, &s1, &err), &err);
    CHECK_OK(asp_fit_color(&two, origin, views, refs, NV, views + NV, refs + NV, NH, &desc, &c2, &s2, &err), &err);
    fprintf(stderr, "train %.5g -> %.5g, held-out %.5g -> %.5g, %zu texels seen, %u iterations\n", s1.train_before,
            s1.train_after, s1.holdout_before, s1.holdout_after, s1.texels_seen, s1.iterations);
    CHECK(s1.train_before > 0.01);
    CHECK_MSG(s1.train_after < 0.1 * s1.train_before, "training loss %g -> %g", s1.train_before, s1.train_after);
    CHECK_MSG(s1.holdout_after < 0.2 * s1.holdout_before, "held-out loss %g -> %g", s1.holdout_before,
              s1.holdout_after);
    size_t bytes = 4 * (size_t)lv.atlas.width * lv.atlas.height;
    CHECK(memcmp(one.atlas.pixels, two.atlas.pixels, bytes) == 0); // any thread count, the same bytes
    // alpha (the basis functions) and geometry untouched: the level's partition of unity is the unfitted one
    size_t alpha_diff = 0, colour_diff = 0;
    for (size_t t = 0; t < bytes / 4; t++) {
        alpha_diff += one.atlas.pixels[4 * t + 3] != lv.atlas.pixels[4 * t + 3];
        colour_diff += memcmp(one.atlas.pixels + 4 * t, lv.atlas.pixels + 4 * t, 3) != 0;
    }
    CHECK(alpha_diff == 0);
    CHECK(colour_diff > 0);
    CHECK(memcmp(one.prims, lv.prims, lv.prim_count * sizeof *lv.prims) == 0);
    // a wrong-sized reference is refused, and the atlas is left as it was
    asp_image small = {0};
    CHECK_OK(asp_image_init(&small, 8, 8, &err), &err);
    asp_image bad[1] = {small};
    CHECK(asp_fit_color(&two, origin, views, bad, 1, NULL, NULL, 0, &desc, &c1, NULL, &err) == ASP_EINVAL);
    CHECK(memcmp(one.atlas.pixels, two.atlas.pixels, bytes) == 0);
    asp_image_release(&small);
    for (size_t v = 0; v < NV + NH; v++)
        asp_image_release(&refs[v]);
    free(one.atlas.pixels), free(two.atlas.pixels), free(truth.atlas.pixels);
    asp_dps_level_release(&lv, NULL);
}

#ifdef ASP_HAVE_GL
/* The CPU rasteriser against the prim renderer (normalized, no crease clipping) on the same cameras. */
static void test_raster_matches_gl(void)
{
    asp_dps_level lv;
    if (octahedron_level(&lv)) {
        CHECK(0);
        return;
    }
    asp_error err = {0};
    asp_gl_context *gl = NULL;
    CHECK_OK(asp_gl_context_create_headless(NULL, NULL, &gl, &err), &err);
    const asp_renderer_kind *kind = NULL;
    asp_renderer *r = NULL;
    asp_render_source src = {.level = &lv};
    asp_renderer_options o = {.prim = {.crease_angle = -1}};
    if (gl)
        CHECK_OK(asp_renderer_kind_find("prim", 0, &kind, &err), &err);
    if (kind)
        CHECK_OK(kind->create(gl, &src, &o, NULL, &r, &err), &err);
    asp_frame frame = {.radius = 1.05};
    for (int v = 0; v < 4 && r; v++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = 30.0f + 80.0f * (float)v;
        cam.elevation = v % 2 ? -25.0f : 35.0f;
        asp_camera_frame(&cam, &frame, NULL, 1.0f, 0.0f);
        asp_fit_view fv = {.width = 128, .height = 128, .light = {0, 0, 1}};
        asp_camera_view_matrix(&cam, fv.view);
        asp_camera_projection_matrix(&cam, fv.proj);
        asp_image a = {0}, b = {0};
        double ssim = 0;
        CHECK_OK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 128, .height = 128}, &a, &err), &err);
        CHECK_OK(asp_fit_render_cpu(&lv, (double[3]){0, 0, 0}, &fv, NULL, &b, &err), &err);
        CHECK_OK(asp_image_ssim(&a, &b, &ssim, &err), &err);
        fprintf(stderr, "view %d: SSIM CPU vs GL %.4f\n", v, ssim);
        CHECK_MSG(ssim >= 0.98, "view %d: SSIM %.4f", v, ssim);
        asp_image_release(&a), asp_image_release(&b);
    }
    asp_renderer_destroy(r);
    asp_gl_context_destroy(gl);
    asp_dps_level_release(&lv, NULL);
}
#endif

int main(void)
{
    static const asp_test_case cases[] = {
        TEST_CASE(test_fit_improves),
#ifdef ASP_HAVE_GL
        TEST_CASE(test_raster_matches_gl),
#endif
    };
    return asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
}
