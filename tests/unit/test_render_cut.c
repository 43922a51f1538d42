/*
 * The cut renderer (issue 18, docs/cut.md) on a decomposed synthetic torus
 * with four linked levels: at tolerance 0 it draws the finest level and
 * matches the prim renderer of that level (SSIM); a huge tolerance draws the
 * coarsest level; in between it mixes levels, and nearer views draw more;
 * two instances cover both halves of the image in one accumulation; a fade
 * between cuts draws both sides, then settles; a .dps without links is refused.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/eval.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"

enum { SIDE = 128 };

static asp_dps *dps;

static void make_dps(void)
{
    asp_error err;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_TORUS, &(asp_synth_desc){.points = 12000}, NULL, &cloud, &err), &err);
    if (cloud)
        CHECK_OK(asp_amg_decompose(cloud, NULL, NULL, &amg, &err), &err);
    if (amg) {
        size_t top = asp_amg_level_count(amg) - 1, levels[4];
        for (size_t i = 0; i < 4; i++)
            levels[i] = top - 6 + i; /* L-6 .. L-3 */
        CHECK_OK(asp_prim_build(amg, NULL, levels, 4, NULL, "torus", NULL, &dps, &err), &err);
    }
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
}

static void camera(asp_camera *cam, float distance_factor)
{
    float c[3] = {(float)dps->frame.center[0], (float)dps->frame.center[1], (float)dps->frame.center[2]};
    asp_camera_init(cam);
    cam->elevation = 35;
    asp_camera_fit(cam, c, (float)dps->frame.radius, 1.0f);
    cam->distance *= distance_factor;
    cam->z_far *= distance_factor * 2;
}

static int render(asp_renderer *r, const asp_camera *cam, asp_image *img)
{
    asp_error err;
    asp_render_desc d = {.width = SIDE, .height = SIDE, .background = {255, 255, 255, 255}};
    int rc = asp_render_to_image(gl, r, cam, &d, img, &err);
    CHECK_MSG(rc == 0, "render: %s", err.msg);
    return rc;
}

static size_t drawn(const asp_renderer *r)
{
    asp_renderer_stats st;
    asp_renderer_stats_get(r, &st);
    return st.count;
}

static void test_cut_levels(void)
{
    if (!gl)
        return;
    make_dps();
    if (!dps)
        return;
    CHECK(dps->level_count == 4 && asp_dps_has_links(dps));
    asp_error err;
    asp_renderer *cut = NULL, *prim = NULL;
    asp_cut_renderer_desc cd = {.tolerance = -1, .fade_seconds = -1};
    memcpy(cd.origin, dps->frame.center, sizeof cd.origin);
    asp_prim_renderer_desc pd = {0};
    memcpy(pd.origin, dps->frame.center, sizeof pd.origin);
    CHECK_OK(asp_cut_renderer_create(gl, dps, &cd, &cut, &err), &err);
    CHECK_OK(asp_prim_renderer_create(gl, &dps->levels[0], &pd, &prim, &err), &err);
    if (!cut || !prim)
        goto done;
    asp_camera cam;
    camera(&cam, 1);
    asp_image a = {0}, b = {0}, c = {0}, far = {0};
    render(cut, &cam, &a);
    CHECK(drawn(cut) == dps->levels[0].prim_count);
    render(prim, &cam, &b);
    double ssim = 0;
    if (a.pixels && b.pixels)
        CHECK_OK(asp_image_ssim(&a, &b, &ssim, &err), &err);
    fprintf(stderr, "tolerance 0: %zu primitives, SSIM against the prim renderer of the finest level %.4f\n",
            drawn(cut), ssim);
    CHECK_MSG(ssim > 0.95, "SSIM %g", ssim);
    /* a huge tolerance: the coarsest level alone */
    CHECK_OK(asp_renderer_set_lod(cut, 1e6f, 0, &err), &err);
    render(cut, &cam, &c);
    CHECK(drawn(cut) == dps->levels[3].prim_count);
    asp_renderer_stats st;
    asp_renderer_stats_get(cut, &st);
    CHECK(st.tolerance == 1e6f);
    /* a middle tolerance (4 px) mixes levels; the same view from 4x further draws fewer */
    CHECK_OK(asp_renderer_set_lod(cut, 4, 0, &err), &err);
    asp_image_release(&c);
    render(cut, &cam, &c);
    size_t near = drawn(cut);
    asp_camera cfar;
    camera(&cfar, 4);
    render(cut, &cfar, &far);
    size_t farn = drawn(cut);
    fprintf(stderr, "tolerance 4 px: %zu primitives near, %zu at 4x the distance\n", near, farn);
    CHECK(near < dps->levels[0].prim_count && near > dps->levels[3].prim_count);
    CHECK(farn < near);
    double ssim_mid = 0;
    if (a.pixels && c.pixels)
        CHECK_OK(asp_image_ssim(&a, &c, &ssim_mid, &err), &err);
    fprintf(stderr, "tolerance 4 px against tolerance 0: SSIM %.4f\n", ssim_mid);
    CHECK(ssim_mid > 0.9);
    asp_image tiles[3] = {a, c, far};
    test_save_sheet(tiles, 3, "ASP_TEST_IMAGES", "render_cut");
    asp_image_release(&a);
    asp_image_release(&b);
    asp_image_release(&c);
    asp_image_release(&far);
done:
    asp_renderer_destroy(cut);
    asp_renderer_destroy(prim);
}

/* Mean luma difference from white of the left and right halves. */
static void half_coverage(const asp_image *img, double *left, double *right)
{
    size_t nl = 0, nr = 0;
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = 0; x < img->width; x++) {
            const uint8_t *p = img->pixels + 4 * ((size_t)y * img->width + x);
            int covered = p[0] < 250 || p[1] < 250 || p[2] < 250;
            if (x < img->width / 2)
                nl += covered;
            else
                nr += covered;
        }
    *left = (double)nl / (img->width * img->height / 2.0);
    *right = (double)nr / (img->width * img->height / 2.0);
}

static void test_cut_instances(void)
{
    if (!gl || !dps)
        return;
    asp_error err;
    asp_renderer *cut = NULL;
    asp_cut_renderer_desc cd = {.tolerance = 1, .fade_seconds = -1};
    memcpy(cd.origin, dps->frame.center, sizeof cd.origin);
    CHECK_OK(asp_cut_renderer_create(gl, dps, &cd, &cut, &err), &err);
    if (!cut)
        return;
    float r = (float)dps->frame.radius;
    float models[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1.1f * r, 0, 0, 1,
                        1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1.1f * r, 0, 0, 1};
    asp_camera cam;
    asp_camera_init(&cam);
    asp_camera_fit(&cam, (float[3]){0, 0, 0}, 2.2f * r, 1.0f);
    asp_image one = {0}, two = {0};
    render(cut, &cam, &one); /* one instance at the identity, centred */
    size_t single = drawn(cut);
    CHECK_OK(asp_cut_renderer_set_instances(cut, models, 2, &err), &err);
    render(cut, &cam, &two);
    double l1 = 0, r1 = 0, l2 = 0, r2 = 0;
    if (one.pixels && two.pixels) {
        half_coverage(&one, &l1, &r1);
        half_coverage(&two, &l2, &r2);
    }
    fprintf(stderr, "instances: one covers %.3f / %.3f of the halves (%zu primitives), two %.3f / %.3f (%zu)\n", l1,
            r1, single, l2, r2, drawn(cut));
    CHECK(l2 > 0.1 && r2 > 0.1 && fabs(l2 - r2) < 0.05);
    CHECK(drawn(cut) > single);
    /* a prim renderer has no instances of a cut */
    asp_image_release(&one);
    asp_image_release(&two);
    asp_renderer_destroy(cut);
}

/* A change of the cut fades in over 0.25 s of the caller's clock. */
static void test_cut_fade(void)
{
    if (!gl || !dps)
        return;
    asp_error err;
    asp_renderer *cut = NULL;
    asp_cut_renderer_desc cd = {.tolerance = 2};
    memcpy(cd.origin, dps->frame.center, sizeof cd.origin);
    CHECK_OK(asp_cut_renderer_create(gl, dps, &cd, &cut, &err), &err);
    if (!cut)
        return;
    asp_camera nearc, farc;
    camera(&nearc, 1);
    camera(&farc, 4);
    asp_image img = {0};
    CHECK_OK(asp_cut_renderer_set_time(cut, 0, &err), &err);
    render(cut, &farc, &img);
    asp_image_release(&img);
    size_t before = drawn(cut);
    CHECK_OK(asp_cut_renderer_set_time(cut, 0.1, &err), &err);
    render(cut, &nearc, &img);
    asp_image_release(&img);
    size_t during = drawn(cut);
    CHECK_OK(asp_cut_renderer_set_time(cut, 0.4, &err), &err);
    render(cut, &nearc, &img);
    asp_image_release(&img);
    size_t after = drawn(cut);
    fprintf(stderr, "fade: %zu primitives far, %zu during the fade to near, %zu after\n", before, during, after);
    CHECK(during > after && during > before); /* both cuts drawn while fading */
    CHECK(after > before);
    asp_renderer_destroy(cut);
}

static void test_cut_needs_links(void)
{
    if (!gl || !dps)
        return;
    asp_error err;
    asp_renderer *cut = NULL;
    uint32_t *keep = dps->levels[1].link_first;
    dps->levels[1].link_first = NULL;
    CHECK(asp_cut_renderer_create(gl, dps, NULL, &cut, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "no links") != NULL);
    CHECK(cut == NULL);
    dps->levels[1].link_first = keep;
    asp_dps_destroy(dps);
    dps = NULL;
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_cut_levels), TEST_CASE(test_cut_instances), TEST_CASE(test_cut_fade),
          TEST_CASE(test_cut_needs_links), TEST_FIXTURE(teardown))
