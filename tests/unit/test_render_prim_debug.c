/*
 * The thesis viewer's debug options and Domain Set (Reniers 2004, appendix C;
 * issue 17): the eigenvector and texel-midpoint drawings put their colours
 * where the axes and the covered texels project, one picked domain draws only
 * its own footprint, and a build with both domain sets renders either set
 * from one asp_dps, the strict one with disjoint domains covering every point.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"

enum { TW = 8, TH = 8, SIZE = 96 };

static asp_error *ep(asp_error *e)
{
    return e;
}

/* Two 2 x 2 squares facing +z at x = -1.2 and +1.2; grey texels, alpha 1 on the left half (i < TW/2), 0 right. */
typedef struct two_prims {
    asp_dps_level lv;
    asp_prim prims[2];
} two_prims;

static void make_two(two_prims *t)
{
    memset(t, 0, sizeof *t);
    t->lv.prim_count = 2;
    t->lv.prims = t->prims;
    asp_error err;
    CHECK_OK(asp_image_init(&t->lv.atlas, 2 * TW, TH, &err), ep(&err));
    for (int k = 0; k < 2; k++) {
        asp_prim *p = &t->prims[k];
        p->centre[0] = k ? 1.2 : -1.2;
        p->axis_u[0] = 1, p->axis_v[1] = 1, p->normal[2] = 1;
        p->half_u = p->half_v = 1;
        p->texel = 2.0f / TW;
        p->tex_x = (uint32_t)k * TW, p->tex_w = TW, p->tex_h = TH;
        p->points = 10;
    }
    if (!t->lv.atlas.pixels)
        return;
    for (uint32_t j = 0; j < TH; j++)
        for (uint32_t i = 0; i < 2 * TW; i++) {
            uint8_t *q = &t->lv.atlas.pixels[4 * (j * 2 * TW + i)];
            q[0] = q[1] = q[2] = 128;
            q[3] = i % TW < TW / 2 ? 255 : 0;
        }
}

/* Front view of the two squares (framed by both, whatever level is drawn), unlit, white background. */
static int draw(const asp_dps_level *lv, const asp_dps_level *frame_of, unsigned flags, asp_prim_render_method m,
                asp_image *img)
{
    asp_error err = {0, ""};
    float c[3], radius;
    CHECK_OK(asp_prim_level_bounding_sphere(frame_of, NULL, c, &radius, &err), ep(&err));
    asp_renderer *r = NULL;
    asp_prim_renderer_desc d = {.options = {.flags = flags, .method = m, .crease_angle = -1}};
    int rc = asp_prim_renderer_create(gl, lv, &d, &r, &err);
    CHECK_OK(rc, ep(&err));
    if (rc)
        return rc;
    asp_camera cam;
    asp_camera_init(&cam);
    asp_camera_fit(&cam, c, radius, 1.0f);
    asp_render_desc rd = {.width = SIZE, .height = SIZE, .flags = ASP_RENDER_UNLIT, .samples = 1,
                          .background = {255, 255, 255, 255}};
    rc = asp_render_to_image(gl, r, &cam, &rd, img, &err);
    CHECK_OK(rc, ep(&err));
    asp_renderer_destroy(r);
    return rc;
}

/* Pixels of exactly this colour in columns [x0, x1). */
static size_t count_rgb(const asp_image *img, uint8_t r, uint8_t g, uint8_t b, uint32_t x0, uint32_t x1)
{
    size_t n = 0;
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = x0; x < x1 && x < img->width; x++) {
            const uint8_t *p = &img->pixels[4 * ((size_t)y * img->width + x)];
            n += p[0] == r && p[1] == g && p[2] == b;
        }
    return n;
}

static void test_debug_drawings(void)
{
    if (!gl)
        return;
    two_prims t;
    make_two(&t);
    asp_image plain = {0}, axes = {0}, texels = {0}, full = {0};
    draw(&t.lv, &t.lv, 0, ASP_PRIM_RENDER_NORMALIZED, &plain);
    draw(&t.lv, &t.lv, ASP_PRIM_RENDER_DEBUG_EIGENVECTORS, ASP_PRIM_RENDER_NORMALIZED, &axes);
    draw(&t.lv, &t.lv, ASP_PRIM_RENDER_DEBUG_TEXELS, ASP_PRIM_RENDER_NORMALIZED, &texels);
    draw(&t.lv, &t.lv, ASP_PRIM_RENDER_DEBUG_EIGENVECTORS | ASP_PRIM_RENDER_DEBUG_TEXELS, ASP_PRIM_RENDER_NORMALIZED,
         &full);
    test_save_sheet((asp_image[]){plain, axes, texels, full}, 4, "ASP_TEST_IMAGES", "prim_debug");
    if (plain.pixels && axes.pixels && texels.pixels) {
        uint32_t W = plain.width;
        // no debug colour without the flags
        CHECK(count_rgb(&plain, 255, 0, 0, 0, W) == 0 && count_rgb(&plain, 0, 255, 0, 0, W) == 0 &&
              count_rgb(&plain, 255, 0, 255, 0, W) == 0);
        // the drawn (left) halves span world x [-2.2, -1.2] and [0.2, 1.2]: the centres are their right edges
        uint32_t y = plain.height / 2, left_c = W, right_c = W;
        for (uint32_t x = 0; x + 1 < W; x++) {
            const uint8_t *p = &plain.pixels[4 * ((size_t)y * W + x)], *q = p + 4;
            int here = !(p[0] == 255 && p[1] == 255), next = !(q[0] == 255 && q[1] == 255);
            if (here && !next) // last covered column of each drawn half
                *(left_c == W ? &left_c : &right_c) = x;
        }
        CHECK_MSG(left_c < W && right_c < W && left_c < right_c, "centres at %u, %u", left_c, right_c);
        // eigenvectors: axis_u runs right from each centre (red on the centre row past the drawn half),
        // axis_v up (green); the normal points at the camera and projects to the centre
        size_t red = count_rgb(&axes, 255, 0, 0, 0, W), green = count_rgb(&axes, 0, 255, 0, 0, W);
        CHECK_MSG(red >= 10 && green >= 10, "red %zu, green %zu pixels", red, green);
        size_t red_row = 0;
        for (uint32_t dy = 0; dy < 3; dy++)
            for (uint32_t x = left_c + 3; x < left_c + 10 && x < W; x++) {
                const uint8_t *p = &axes.pixels[4 * ((size_t)(y - 1 + dy) * W + x)];
                red_row += p[0] == 255 && p[1] == 0 && p[2] == 0;
            }
        CHECK_MSG(red_row >= 5, "%zu red pixels right of the left centre", red_row);
        // texel midpoints: magenta over the covered halves (alpha > 0), none over the empty ones
        size_t mag_left = count_rgb(&texels, 255, 0, 255, 0, left_c + 1);
        size_t mag_gap = count_rgb(&texels, 255, 0, 255, left_c + 2, (left_c + right_c) / 2 - 4);
        size_t mag_all = count_rgb(&texels, 255, 0, 255, 0, W);
        CHECK_MSG(mag_left >= 8 && mag_all >= 2 * 16, "magenta: %zu left, %zu in all", mag_left, mag_all);
        CHECK_MSG(mag_gap == 0, "%zu magenta pixels over texels of alpha 0", mag_gap);
        // both together: the union of the two
        CHECK(count_rgb(&full, 255, 0, 255, 0, W) > 0 && count_rgb(&full, 0, 255, 0, 0, W) > 0);
    }
    asp_image_release(&plain), asp_image_release(&axes), asp_image_release(&texels), asp_image_release(&full);
    asp_image_release(&t.lv.atlas);
}

static size_t covered(const asp_image *img, uint32_t x0, uint32_t x1)
{
    size_t n = 0;
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = x0; x < x1; x++) {
            const uint8_t *p = &img->pixels[4 * ((size_t)y * img->width + x)];
            n += !(p[0] == 255 && p[1] == 255 && p[2] == 255);
        }
    return n;
}

static void test_only_domain(void)
{
    two_prims t;
    make_two(&t);
    asp_error err = {0, ""};
    asp_dps_level one;
    memset(&one, 0x5a, sizeof one);
    CHECK(asp_dps_level_pick(&t.lv, 2, NULL, &one, &err) == ASP_EINVAL && strstr(err.msg, "domains 0..1"));
    CHECK_OK(asp_dps_level_pick(&t.lv, 1, NULL, &one, &err), ep(&err));
    CHECK(one.prim_count == 1 && one.neighbour_total == 0 && one.atlas.width == TW && one.atlas.height == TH);
    CHECK(one.prims[0].tex_x == 0 && one.prims[0].centre[0] == 1.2);
    int same = 1;
    for (uint32_t j = 0; j < TH; j++)
        same &= memcmp(&one.atlas.pixels[4 * j * TW], &t.lv.atlas.pixels[4 * (j * 2 * TW + TW)], 4 * TW) == 0;
    CHECK(same);
    if (gl) {
        asp_image all = {0}, mine = {0};
        draw(&t.lv, &t.lv, 0, ASP_PRIM_RENDER_NO_BLEND, &all);
        draw(&one, &t.lv, 0, ASP_PRIM_RENDER_NO_BLEND, &mine);
        if (all.pixels && mine.pixels) {
            uint32_t W = all.width;
            // the picked (right) primitive's footprint, pixel for pixel, and nothing of the left one
            size_t a = covered(&all, W / 2, W), m = covered(&mine, W / 2, W);
            CHECK_MSG(m == a && m > 100, "picked %zu pixels, full render %zu on its side", m, a);
            CHECK_MSG(covered(&mine, 0, W / 2) == 0 && covered(&all, 0, W / 2) > 100, "left side: %zu, %zu",
                      covered(&mine, 0, W / 2), covered(&all, 0, W / 2));
        }
        asp_image_release(&all), asp_image_release(&mine);
    }
    asp_dps_level_release(&one, NULL);
    asp_image_release(&t.lv.atlas);
}

/* Domain Set both (thesis appendix C): one asp_dps, each level twice; strict disjoint and covering. */
static void test_domain_set_both(void)
{
#ifndef ASP_HAVE_HYPRE
    asp_test_skips++; // the library decomposes only with hypre
    fprintf(stderr, "skip: built without hypre, nothing to decompose\n");
    return;
#endif
    asp_error err = {0, ""};
    asp_cloud *oct = NULL;
    asp_amg *amg = NULL;
    asp_dps *dps = NULL, *thr = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 3000}, NULL, &oct, &err), ep(&err));
    if (oct)
        CHECK_OK(asp_amg_decompose(oct, NULL, NULL, &amg, &err), ep(&err));
    if (!amg) {
        asp_cloud_destroy(oct);
        return;
    }
    size_t nl = asp_amg_level_count(amg), levels[2] = {nl - 3, nl - 2};
    CHECK(asp_prim_build(amg, NULL, levels, 2, &(asp_prim_desc){.strict = 3}, NULL, NULL, &dps, &err) == ASP_EINVAL);
    CHECK_OK(asp_prim_build(amg, NULL, levels, 2, &(asp_prim_desc){.strict = ASP_PRIM_DOMAINS_BOTH}, NULL, NULL,
                            &dps, &err),
             ep(&err));
    CHECK_OK(asp_prim_build(amg, NULL, levels, 2, NULL, NULL, NULL, &thr, &err), ep(&err));
    if (dps && thr) {
        CHECK(dps->level_count == 4 && thr->level_count == 2);
        for (size_t i = 0; i < dps->level_count && dps->level_count == 4; i++) {
            const asp_dps_level *lv = &dps->levels[i];
            CHECK(lv->level == levels[i / 2] && lv->strict == (i % 2));
            if (lv->strict) {
                // disjoint and covering: each point in exactly one strict domain, no neighbours
                uint64_t pts = 0;
                for (size_t k = 0; k < lv->prim_count; k++)
                    pts += lv->prims[k].points;
                CHECK_MSG(pts == oct->count, "strict level %u: %llu points in %zu domains, expected %zu", lv->level,
                          (unsigned long long)pts, lv->prim_count, oct->count);
                CHECK(lv->neighbour_total == 0);
            } else {
                // the thresholded levels are the plain build's
                const asp_dps_level *p = &thr->levels[i / 2];
                CHECK(lv->prim_count == p->prim_count && lv->texels == p->texels &&
                      memcmp(lv->atlas.pixels, p->atlas.pixels, 4 * (size_t)p->atlas.width * p->atlas.height) == 0);
            }
        }
        // the affine triangulation of the thresholded level L-3 (thesis appendix C), drawn in cyan
        float *lines = NULL;
        size_t segs = 0;
        CHECK(asp_prim_level_triangles(amg, dps, 9, NULL, NULL, &lines, &segs, &err) == ASP_EINVAL);
        CHECK_OK(asp_prim_level_triangles(amg, dps, 0, NULL, NULL, &lines, &segs, &err), ep(&err));
        size_t pts = 0;
        for (size_t k = 0; k < dps->levels[0].prim_count; k++)
            pts += dps->levels[0].prims[k].points;
        // a Delaunay triangulation of n points has at most 2n triangles, 3 edges each; the cut ones go
        CHECK_MSG(segs > pts / 2 && segs <= 6 * pts, "%zu segments for %zu domain points", segs, pts);
        if (gl && lines) {
            asp_renderer *r = NULL;
            CHECK_OK(asp_prim_renderer_create(gl, &dps->levels[0], NULL, &r, &err), ep(&err));
            if (r) {
                CHECK_OK(asp_prim_renderer_set_debug_lines(r, lines, segs, &err), ep(&err));
                float c[3], rad;
                asp_camera cam;
                asp_prim_level_bounding_sphere(&dps->levels[0], NULL, c, &rad, &err);
                asp_camera_init(&cam);
                asp_camera_fit(&cam, c, rad, 1.0f);
                asp_render_desc rd = {.width = SIZE, .height = SIZE, .flags = ASP_RENDER_UNLIT, .samples = 1};
                asp_image off = {0}, on = {0};
                CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &off, &err), ep(&err));
                asp_prim_renderer_set_options(r, &(asp_prim_render_options){.flags = ASP_PRIM_RENDER_DEBUG_TRIANGULATION}, &err);
                CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &on, &err), ep(&err));
                if (off.pixels && on.pixels) {
                    size_t a0 = count_rgb(&off, 0, 255, 255, 0, off.width), a1 = count_rgb(&on, 0, 255, 255, 0, on.width);
                    CHECK_MSG(a0 == 0 && a1 > 200, "cyan pixels %zu without, %zu with the triangulation", a0, a1);
                }
                test_save_sheet((asp_image[]){off, on}, 2, "ASP_TEST_IMAGES", "prim_triangulation");
                asp_image_release(&off), asp_image_release(&on);
                asp_renderer_destroy(r);
            }
        }
        asp_free(NULL, lines);
        // the switch: level by level to the other set and back
        size_t idx = 99;
        CHECK_OK(asp_dps_domain_set_pick(dps, 2, 1, &idx, &err), ep(&err));
        CHECK(idx == 3);
        CHECK_OK(asp_dps_domain_set_pick(dps, 1, 0, &idx, &err), ep(&err));
        CHECK(idx == 0);
        idx = 99;
        CHECK(asp_dps_domain_set_pick(thr, 0, 1, &idx, &err) == ASP_EINVAL && idx == 99 && strstr(err.msg, "strict"));
        CHECK(asp_dps_domain_set_pick(dps, 4, 1, &idx, &err) == ASP_EINVAL);
        if (gl && dps->level_count == 4) {
            // both sets render from the one asp_dps: the same silhouette within a few pixels
            asp_image a = {0}, b = {0};
            draw(&dps->levels[0], &dps->levels[0], 0, ASP_PRIM_RENDER_NORMALIZED, &a);
            draw(&dps->levels[1], &dps->levels[0], 0, ASP_PRIM_RENDER_NO_BLEND, &b);
            if (a.pixels && b.pixels) {
                size_t ca = covered(&a, 0, a.width), cb = covered(&b, 0, b.width), diff = 0;
                for (size_t k = 0; k < (size_t)a.width * a.height; k++)
                    diff += memcmp(&a.pixels[4 * k], &b.pixels[4 * k], 3) != 0;
                CHECK_MSG(ca > 1000 && fabs((double)cb - (double)ca) < 0.1 * (double)ca,
                          "thresholded %zu pixels, strict %zu", ca, cb);
                CHECK_MSG(diff > 0, "the strict set drew the thresholded set's pixels");
            }
            test_save_sheet((asp_image[]){a, b}, 2, "ASP_TEST_IMAGES", "prim_domain_sets");
            asp_image_release(&a), asp_image_release(&b);
        }
    }
    asp_dps_destroy(dps);
    asp_dps_destroy(thr);
    asp_amg_destroy(amg);
    asp_cloud_destroy(oct);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_debug_drawings), TEST_CASE(test_only_domain),
          TEST_CASE(test_domain_set_both), TEST_FIXTURE(teardown))
