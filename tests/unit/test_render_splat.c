/*
 * Splat and square renderers on a real headless GL 4.5 context (llvmpipe in
 * CI): the 512x512 checker plane without holes and with every pixel between
 * the two checker colours at 1:1 to 8x (per-pixel normalisation, seed 001
 * 5.4); coverage equal to the disc renderer's; tau = 0 draws every leaf and
 * the count never grows with tau; the epsilon-z-buffer blends coplanar splats
 * but not a surface behind; squares of exact size; bad options.
 * Set ASP_TEST_DUMP=DIR to keep the rendered images as PNGs.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "harness.h"

static asp_gl_context *gl;
static asp_cloud *checker; // 512 x 512 synth checker plane, made once

static asp_error *ep(asp_error *e)
{
    return e;
}

static void dump(const asp_image *img, const char *name)
{
    const char *dir = getenv("ASP_TEST_DUMP");
    if (!dir || !img->pixels)
        return;
    char path[512];
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    asp_image_save_png(img, path, NULL);
}

static const uint8_t *px(const asp_image *img, uint32_t x, uint32_t y)
{
    return img->pixels + 4 * ((size_t)y * img->width + x);
}

/* Fibonacci sphere with outward normals, colours by octant and radii closing all gaps. */
static asp_cloud *make_sphere(size_t n)
{
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err), ep(&err));
    if (!c)
        return NULL;
    float disc = (float)sqrt(4.0 * 3.14159265358979323846 / (double)n);
    for (size_t i = 0; i < n; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / (double)n, rho = sqrt(1.0 - y * y), phi = (double)i * 2.399963229728653;
        float nrm[3] = {(float)(rho * cos(phi)), (float)y, (float)(rho * sin(phi))};
        memcpy(c->normals + 3 * i, nrm, sizeof nrm);
        memcpy(c->positions + 3 * i, nrm, sizeof nrm);
        c->colors[4 * i + 0] = nrm[0] > 0 ? 230 : 40;
        c->colors[4 * i + 1] = nrm[1] > 0 ? 200 : 90;
        c->colors[4 * i + 2] = nrm[2] > 0 ? 60 : 220;
        c->colors[4 * i + 3] = 255;
        c->radii[i] = disc;
    }
    return c;
}

/* Camera looking straight down -z at (x, y, 0) from far enough that the view is `width` units wide. */
static void top_camera(asp_camera *cam, float x, float y, float width)
{
    asp_camera_init(cam);
    cam->target[0] = x;
    cam->target[1] = y;
    cam->distance = 0.5f * width / tanf(20.0f * 3.14159265f / 180.0f);
    cam->z_near = 0.5f * cam->distance;
    cam->z_far = 2.0f * cam->distance;
}

static size_t covered(const asp_image *img)
{
    size_t n = 0;
    for (size_t i = 0; i < (size_t)img->width * img->height; i++)
        n += img->pixels[4 * i + 3] != 0;
    return n;
}

/*
 * Counts pixels outside the checker colour range (30..235 per channel, with a
 * tolerance of 2 levels) or of the wrong alpha, among pixels with mask set.
 */
static size_t checker_bad(const asp_image *img, int require_all, uint8_t worst[4])
{
    size_t bad = 0;
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = 0; x < img->width; x++) {
            const uint8_t *p = px(img, x, y);
            if (!require_all && p[3] == 0)
                continue;
            int ok = p[3] == 255 && p[0] >= 28 && p[0] <= 237 && p[0] == p[1] && p[1] == p[2];
            if (!ok) {
                if (!bad)
                    memcpy(worst, p, 4);
                bad++;
            }
        }
    return bad;
}

/*
 * Issue 6: the 512x512-point checker plane from 1:1 (one point spacing per
 * pixel) to 8x magnified, head-on and lit, is covered everywhere and every
 * pixel lies between the two checker colours: no hole, no black from a
 * missing weight, nothing over-bright from missing normalisation. Also with
 * multisampling and with the per-pixel and opaque modes.
 */
static void test_checker_no_holes(void)
{
    if (!gl || !checker)
        return;
    const double spacing = 2.0 / 511.0;
    const uint32_t side = 96;
    struct {
        asp_splat_renderer_desc desc;
        const char *name;
    } kinds[] = {
        {{.lighting = ASP_SPLAT_LIGHT_GOURAUD}, "gouraud"},
        {{.lighting = ASP_SPLAT_LIGHT_PIXEL, .kernel_a = 1, .kernel_b = 1.5f, .kernel_n = 2}, "pixel-round"},
        {{.mode = ASP_SPLAT_OPAQUE}, "opaque"},
    };
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        asp_renderer *r = NULL;
        asp_error err;
        CHECK_OK(asp_splat_renderer_create(gl, checker, &kinds[k].desc, NULL, &r, &err), ep(&err));
        if (!r)
            continue;
        static const double zooms[] = {1, 2, 3, 5, 8};
        for (size_t z = 0; z < sizeof zooms / sizeof zooms[0]; z++) {
            for (uint32_t samples = 1; samples <= 4; samples += 3) {
                asp_camera cam;
                // off-centre, across a checker boundary (squares are 0.25 wide)
                top_camera(&cam, 0.25f + 0.013f, -0.5f + 0.007f, (float)(side * spacing / zooms[z]));
                asp_image img = {0, 0, NULL};
                asp_render_desc rd = {.width = side, .height = side, .samples = samples,
                                      .background = {255, 0, 255, 255}};
                CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), ep(&err));
                if (!img.pixels)
                    continue;
                uint8_t worst[4] = {0, 0, 0, 0};
                size_t bad = checker_bad(&img, 1, worst);
                CHECK_MSG(bad == 0, "%s zoom %g samples %u: %zu pixels outside the checker colours, e.g. %u,%u,%u,%u",
                          kinds[k].name, zooms[z], samples, bad, worst[0], worst[1], worst[2], worst[3]);
                // both colours are seen (the view straddles a boundary), and blended values only near it
                size_t dark = 0, light = 0;
                for (size_t i = 0; i < (size_t)side * side; i++) {
                    dark += img.pixels[4 * i] <= 32;
                    light += img.pixels[4 * i] >= 233;
                }
                CHECK_MSG(dark > side * side / 8 && light > side * side / 8, "%s zoom %g: dark %zu light %zu",
                          kinds[k].name, zooms[z], dark, light);
                char name[64];
                snprintf(name, sizeof name, "checker_%s_x%g_s%u", kinds[k].name, zooms[z], samples);
                dump(&img, name);
                asp_image_release(&img);
            }
        }
        asp_renderer_destroy(r);
    }
}

/*
 * The whole plane seen obliquely with a screen tolerance (coarse node splats
 * drawn): every pixel inside the plane's silhouette is covered and between
 * the colours; coverage matches the opaque disc renderer's.
 */
static void test_checker_oblique_lod(void)
{
    if (!gl || !checker)
        return;
    asp_camera cam;
    asp_camera_init(&cam);
    cam.elevation = 50.0f;
    cam.azimuth = 20.0f;
    const float center[3] = {0, 0, 0};
    asp_camera_fit(&cam, center, 1.45f, 1.0f);
    asp_render_desc rd = {.width = 128, .height = 128, .flags = ASP_RENDER_UNLIT};
    asp_error err;
    asp_renderer *disc = NULL;
    asp_image ref = {0, 0, NULL};
    CHECK_OK(asp_disc_renderer_create(gl, checker, NULL, &disc, &err), ep(&err));
    if (disc)
        CHECK_OK(asp_render_to_image(gl, disc, &cam, &rd, &ref, &err), ep(&err));
    asp_renderer_destroy(disc);
    if (!ref.pixels)
        return;
    dump(&ref, "checker_oblique_disc");
    static const float taus[] = {0, 1, 2};
    for (size_t t = 0; t < 3; t++) {
        asp_renderer *r = NULL;
        CHECK_OK(asp_splat_renderer_create(gl, checker, &(asp_splat_renderer_desc){.tolerance = taus[t]}, NULL, &r, &err),
                 ep(&err));
        if (!r)
            continue;
        asp_image img = {0, 0, NULL};
        CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), ep(&err));
        if (img.pixels) {
            uint8_t worst[4] = {0, 0, 0, 0};
            size_t bad = checker_bad(&img, 0, worst);
            CHECK_MSG(bad == 0, "tau %g: %zu pixels outside the checker colours, e.g. %u,%u,%u,%u", taus[t], bad,
                      worst[0], worst[1], worst[2], worst[3]);
            // holes: pixels the discs cover and the splats do not
            size_t holes = 0, extra = 0;
            for (size_t i = 0; i < 128 * 128; i++) {
                holes += ref.pixels[4 * i + 3] && !img.pixels[4 * i + 3];
                extra += !ref.pixels[4 * i + 3] && img.pixels[4 * i + 3];
            }
            size_t cov = covered(&ref);
            CHECK_MSG((double)(holes + extra) <= 0.005 * (double)cov + (taus[t] > 0 ? 0.01 * (double)cov : 0.0),
                      "tau %g: %zu holes and %zu extra pixels of %zu", taus[t], holes, extra, cov);
            char name[64];
            snprintf(name, sizeof name, "checker_oblique_tau%g", taus[t]);
            dump(&img, name);
            asp_image_release(&img);
        }
        asp_renderer_destroy(r);
    }
    asp_image_release(&ref);
}

/* Coverage of the splat, opaque-splat and square renderers against discs, from several views. */
static void test_coverage_matches_discs(void)
{
    if (!gl)
        return;
    asp_cloud *c = make_sphere(6000);
    if (!c)
        return;
    asp_error err;
    asp_renderer *disc = NULL, *splat = NULL, *splat1 = NULL, *square = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &disc, &err), ep(&err));
    CHECK_OK(asp_splat_renderer_create(gl, c, NULL, NULL, &splat, &err), ep(&err));
    CHECK_OK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.tolerance = 1}, NULL, &splat1, &err), ep(&err));
    CHECK_OK(asp_square_renderer_create(gl, c, NULL, NULL, &square, &err), ep(&err));
    static const float views[][2] = {{0, 0}, {30, 20}, {135, -50}, {250, 80}};
    for (size_t v = 0; v < 4 && disc && splat && splat1 && square; v++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = views[v][0];
        cam.elevation = views[v][1];
        const float center[3] = {0, 0, 0};
        asp_camera_fit(&cam, center, 1.1f, 1.0f);
        asp_render_desc rd = {.width = 128, .height = 128};
        asp_image img[4] = {{0, 0, NULL}, {0, 0, NULL}, {0, 0, NULL}, {0, 0, NULL}};
        asp_renderer *rs[4] = {disc, splat, splat1, square};
        int ok = 1;
        for (int i = 0; i < 4; i++)
            if (asp_render_to_image(gl, rs[i], &cam, &rd, &img[i], &err) != 0)
                ok = 0;
        CHECK_MSG(ok, "render failed: %s", err.msg);
        if (ok) {
            double ref = (double)covered(&img[0]);
            double s0 = (double)covered(&img[1]), s1 = (double)covered(&img[2]), q = (double)covered(&img[3]);
            CHECK_MSG(fabs(s0 - ref) <= 0.005 * ref, "view %zu: splat coverage %g vs discs %g", v, s0, ref);
            CHECK_MSG(fabs(s1 - ref) <= 0.005 * ref, "view %zu: splat tau 1 coverage %g vs discs %g", v, s1, ref);
            // squares are larger than the discs they replace, but only at the silhouette
            // (by up to half a square, 1.3 px, around a 58 px radius)
            CHECK_MSG(q >= ref && q <= 1.15 * ref, "view %zu: square coverage %g vs discs %g", v, q, ref);
            // colours: blending smooths the octant boundaries, elsewhere the images agree
            double diff = 0;
            size_t both = 0;
            for (size_t i = 0; i < 128 * 128; i++)
                if (img[0].pixels[4 * i + 3] && img[1].pixels[4 * i + 3]) {
                    for (int ch = 0; ch < 3; ch++)
                        diff += abs((int)img[0].pixels[4 * i + ch] - (int)img[1].pixels[4 * i + ch]);
                    both++;
                }
            diff /= 3.0 * (double)(both ? both : 1);
            CHECK_MSG(diff < 8, "view %zu: mean colour difference of splats and discs %.2f levels", v, diff);
            // the blended image has no pixel darker than the ambient floor of the darkest octant colour
            size_t black = 0;
            for (size_t i = 0; i < 128 * 128; i++)
                if (img[1].pixels[4 * i + 3] && img[1].pixels[4 * i] < 8 && img[1].pixels[4 * i + 1] < 8 &&
                    img[1].pixels[4 * i + 2] < 8)
                    black++;
            CHECK_MSG(black == 0, "view %zu: %zu black pixels in the splat render", v, black);
        }
        static const char *names[4] = {"disc", "splat", "splat_tau1", "square"};
        for (int i = 0; i < 4; i++) {
            char name[64];
            snprintf(name, sizeof name, "sphere_v%zu_%s", v, names[i]);
            dump(&img[i], name);
            asp_image_release(&img[i]);
        }
    }
    asp_renderer_destroy(disc);
    asp_renderer_destroy(splat);
    asp_renderer_destroy(splat1);
    asp_renderer_destroy(square);
    asp_cloud_destroy(c);
}

/* tau = 0 draws every leaf point; the count never grows with tau and falls far at large tau. */
static void test_count_and_tau(void)
{
    if (!gl || !checker)
        return;
    asp_error err;
    asp_renderer *r = NULL, *q = NULL;
    CHECK_OK(asp_splat_renderer_create(gl, checker, NULL, NULL, &r, &err), ep(&err));
    CHECK_OK(asp_square_renderer_create(gl, checker, NULL, NULL, &q, &err), ep(&err));
    if (!r || !q) {
        asp_renderer_destroy(r);
        asp_renderer_destroy(q);
        return;
    }
    CHECK(strcmp(asp_renderer_name(r), "splat") == 0 && strcmp(asp_renderer_name(q), "square") == 0);
    CHECK(asp_renderer_count(r) == checker->count); // before the first frame
    asp_camera cam;
    asp_camera_init(&cam);
    cam.elevation = 40.0f;
    const float center[3] = {0, 0, 0};
    asp_camera_fit(&cam, center, 1.45f, 1.0f);
    asp_render_desc rd = {.width = 64, .height = 64};
    static const float taus[] = {0, 0.5f, 1, 2, 3, 4, 8, 16, 32, 64};
    size_t prev = SIZE_MAX;
    for (size_t t = 0; t < sizeof taus / sizeof taus[0]; t++) {
        CHECK_OK(asp_renderer_set_lod(r, taus[t], 0, &err), ep(&err));
        CHECK_OK(asp_renderer_set_lod(q, taus[t], 0, &err), ep(&err));
        CHECK_OK(asp_render_frame(gl, r, &cam, &rd, &err), ep(&err));
        CHECK_OK(asp_render_frame(gl, q, &cam, &rd, &err), ep(&err));
        size_t n = asp_renderer_count(r);
        asp_renderer_stats st;
        asp_renderer_stats_get(r, &st);
        CHECK(st.count == n && st.points == checker->count && st.nodes > 0 && st.tolerance == taus[t]);
        CHECK(asp_renderer_count(q) == n); // the same cut
        if (t == 0)
            CHECK_MSG(n == checker->count, "tau 0 drew %zu of %zu leaves", n, checker->count);
        CHECK_MSG(n <= prev, "tau %g drew %zu splats, more than %zu at the smaller tau", taus[t], n, prev);
        if (t == sizeof taus / sizeof taus[0] - 1)
            CHECK_MSG(n < 100, "tau %g still drew %zu splats", taus[t], n);
        prev = n;
    }
    // a depth limit cuts as well
    CHECK_OK(asp_renderer_set_lod(r, 0, 3, &err), ep(&err));
    CHECK_OK(asp_render_frame(gl, r, &cam, &rd, &err), ep(&err));
    CHECK(asp_renderer_count(r) <= 64 && asp_renderer_count(r) >= 1);
    // a splat budget overrides tau and the depth limit: exactly the count, short by less than one
    // expansion (8 children or leaf points) at most; 0 hands the cut back to tau
    static const size_t budgets[] = {1, 9, 100, 1000, 5000};
    for (size_t k = 0; k < sizeof budgets / sizeof budgets[0]; k++) {
        CHECK_OK(asp_renderer_set_budget(r, budgets[k], &err), ep(&err));
        CHECK_OK(asp_renderer_set_budget(q, budgets[k], &err), ep(&err));
        CHECK_OK(asp_render_frame(gl, r, &cam, &rd, &err), ep(&err));
        CHECK_OK(asp_render_frame(gl, q, &cam, &rd, &err), ep(&err));
        size_t n = asp_renderer_count(r);
        asp_renderer_stats st;
        asp_renderer_stats_get(r, &st);
        CHECK(st.budget == budgets[k] && st.count == n && asp_renderer_count(q) == n);
        CHECK_MSG(n <= budgets[k] && n + 8 > budgets[k], "budget %zu drew %zu splats", budgets[k], n);
    }
    CHECK_OK(asp_renderer_set_budget(r, 0, &err), ep(&err));
    CHECK_OK(asp_render_frame(gl, r, &cam, &rd, &err), ep(&err));
    CHECK(asp_renderer_count(r) <= 64); // the depth limit again
    asp_renderer_destroy(r);
    asp_renderer_destroy(q);
}

/* Two parallel planes: the epsilon-z-buffer blends coplanar splats only, never the plane behind. */
static void test_epsilon_z_buffer(void)
{
    if (!gl)
        return;
    const int side = 40;
    const float h = 0.05f;
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(2 * (size_t)side * side, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c,
                              &err),
             ep(&err));
    if (!c)
        return;
    for (int layer = 0; layer < 2; layer++)
        for (int j = 0; j < side; j++)
            for (int i = 0; i < side; i++) {
                size_t p = ((size_t)layer * side + j) * side + i;
                c->positions[3 * p + 0] = (i - 0.5f * (side - 1)) * h;
                c->positions[3 * p + 1] = (j - 0.5f * (side - 1)) * h;
                c->positions[3 * p + 2] = layer ? 0.0f : -0.5f; // red at z = 0 in front, blue behind
                c->normals[3 * p + 2] = 1.0f;
                uint8_t rgba[4] = {layer ? 255 : 0, 0, layer ? 0 : 255, 255};
                memcpy(c->colors + 4 * p, rgba, 4);
                c->radii[p] = 0.75f * h;
            }
    asp_camera cam;
    top_camera(&cam, 0, 0, 1.0f);
    cam.azimuth = 10.0f; // slightly oblique
    cam.elevation = 15.0f;
    asp_render_desc rd = {.width = 64, .height = 64, .flags = ASP_RENDER_UNLIT};
    // epsilon 1 (0.0375 units) keeps the layers apart; epsilon 20 (0.75 units) lets the blue layer blend in
    static const float eps[] = {0, 20};
    for (int e = 0; e < 2; e++) {
        asp_renderer *r = NULL;
        CHECK_OK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.epsilon = eps[e]}, NULL, &r, &err),
                 ep(&err));
        asp_image img = {0, 0, NULL};
        if (r)
            CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), ep(&err));
        if (img.pixels) {
            const uint8_t *p = px(&img, 32, 32);
            if (e == 0)
                CHECK_MSG(p[0] == 255 && p[2] == 0, "epsilon 1: centre %u,%u,%u", p[0], p[1], p[2]);
            else
                CHECK_MSG(p[0] > 120 && p[2] > 120, "epsilon 20: centre %u,%u,%u, expected red and blue mixed", p[0],
                          p[1], p[2]);
            dump(&img, e == 0 ? "layers_eps1" : "layers_eps20");
        }
        asp_image_release(&img);
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
}

/* Lighting modes on a sphere: the centre facing the headlight shows its colour, the limb is darker. */
static void test_lighting_modes(void)
{
    if (!gl)
        return;
    asp_cloud *c = make_sphere(4000);
    if (!c)
        return;
    for (int i = 0; i < 4000; i++)
        memcpy(c->colors + 4 * i, (uint8_t[4]){200, 160, 120, 255}, 4);
    asp_camera cam;
    asp_camera_init(&cam);
    const float center[3] = {0, 0, 0};
    asp_camera_fit(&cam, center, 1.1f, 1.0f);
    asp_renderer *disc = NULL;
    asp_image ref = {0, 0, NULL};
    asp_error derr;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &disc, &derr), ep(&derr));
    if (disc)
        CHECK_OK(asp_render_to_image(gl, disc, &cam, &(asp_render_desc){.width = 96, .height = 96}, &ref, &derr),
                 ep(&derr));
    asp_renderer_destroy(disc);
    if (!ref.pixels) {
        asp_cloud_destroy(c);
        return;
    }
    static const asp_splat_lighting modes[] = {ASP_SPLAT_LIGHT_GOURAUD, ASP_SPLAT_LIGHT_PIXEL, ASP_SPLAT_LIGHT_FLAT};
    for (int m = 0; m < 3; m++) {
        for (int tau = 0; tau <= 4; tau += 4) {
            asp_renderer *r = NULL;
            asp_error err;
            CHECK_OK(asp_splat_renderer_create(gl, c,
                                               &(asp_splat_renderer_desc){.lighting = modes[m], .tolerance = (float)tau}, NULL,
                                               &r, &err),
                     ep(&err));
            asp_image img = {0, 0, NULL};
            if (r)
                CHECK_OK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 96, .height = 96}, &img, &err),
                         ep(&err));
            if (img.pixels) {
                const uint8_t *mid = px(&img, 48, 48);
                CHECK_MSG(abs(mid[0] - 200) <= 4 && abs(mid[1] - 160) <= 4 && abs(mid[2] - 120) <= 4,
                          "mode %d tau %d: centre %u,%u,%u", m, tau, mid[0], mid[1], mid[2]);
                // along the horizontal diameter the shade falls towards the limb
                int prev = 256, monotonic = 1, x_limb = 48;
                for (int x = 48; x < 96 && px(&img, (uint32_t)x, 48)[3]; x++)
                    x_limb = x;
                for (int x = 48; x <= x_limb; x += 4) {
                    int v = px(&img, (uint32_t)x, 48)[0];
                    monotonic &= v <= prev + 3;
                    prev = v;
                }
                // the limb normals are at 70 degrees to the headlight axis (the eye is 2.9 radii away)
                CHECK_MSG(monotonic && prev < 185, "mode %d tau %d: limb %d, monotonic %d", m, tau, prev, monotonic);
                // the Lambert shading of the disc renderer, up to the smoothing
                double diff = 0;
                size_t both = 0, bright = 0;
                for (size_t i = 0; i < 96 * 96; i++)
                    if (img.pixels[4 * i + 3] && ref.pixels[4 * i + 3]) {
                        int d = (int)img.pixels[4 * i] - (int)ref.pixels[4 * i];
                        diff += abs(d);
                        bright += d > 25;
                        both++;
                    }
                diff /= (double)(both ? both : 1);
                CHECK_MSG(diff < 4, "mode %d tau %d: mean red difference to the disc render %.2f", m, tau, diff);
                // per-pixel lighting once made silhouette pixels bright: front and back normals cancelled
                CHECK_MSG(bright == 0, "mode %d tau %d: %zu pixels much brighter than the disc render", m, tau, bright);
                char name[64];
                snprintf(name, sizeof name, "light_mode%d_tau%d", m, tau);
                dump(&img, name);
            }
            asp_image_release(&img);
            asp_renderer_destroy(r);
        }
    }
    asp_image_release(&ref);
    asp_cloud_destroy(c);
}

/* Fixed-size squares: each point is exactly N x N pixels of its colour. */
static void test_square_fixed_size(void)
{
    if (!gl)
        return;
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(3, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    for (int i = 0; i < 3; i++) {
        c->positions[3 * i + 0] = (i - 1) * 0.5f;
        c->normals[3 * i + 2] = 1.0f;
        memcpy(c->colors + 4 * i, (uint8_t[4]){20, 180, 90, 255}, 4);
        c->radii[i] = 0.01f;
    }
    static const float sizes[] = {1, 5, 8};
    for (int s = 0; s < 3; s++) {
        asp_renderer *r = NULL;
        CHECK_OK(asp_square_renderer_create(gl, c, &(asp_square_renderer_desc){.point_size = sizes[s]}, NULL, &r, &err),
                 ep(&err));
        asp_camera cam;
        top_camera(&cam, 0, 0, 2.0f);
        asp_image img = {0, 0, NULL};
        if (r)
            CHECK_OK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 64, .height = 64}, &img, &err),
                     ep(&err));
        if (img.pixels) {
            size_t n = covered(&img), exact = 0;
            for (size_t i = 0; i < 64 * 64; i++)
                exact += memcmp(img.pixels + 4 * i, (uint8_t[4]){20, 180, 90, 255}, 4) == 0;
            CHECK_MSG(n == (size_t)(3 * sizes[s] * sizes[s]) && exact == n, "size %g: %zu pixels (%zu exact)",
                      sizes[s], n, exact);
        }
        asp_image_release(&img);
        asp_renderer_destroy(r);
    }
    CHECK(asp_square_renderer_create(gl, c, &(asp_square_renderer_desc){.point_size = 1e9f}, NULL, &(asp_renderer *){NULL},
                                     &err) == ASP_EINVAL);
    asp_cloud_destroy(c);
}

/* Same image twice and from a second renderer; the hierarchy variant draws the same as the cloud one. */
static void test_deterministic_and_hier(void)
{
    if (!gl)
        return;
    asp_cloud *c = make_sphere(3000);
    if (!c)
        return;
    asp_error err;
    asp_hier *h = NULL;
    CHECK_OK(asp_hier_build(c, NULL, NULL, &h, &err), ep(&err));
    asp_renderer *r1 = NULL, *r2 = NULL;
    asp_splat_renderer_desc d = {.tolerance = 2};
    CHECK_OK(asp_splat_renderer_create(gl, c, &d, NULL, &r1, &err), ep(&err));
    if (h)
        CHECK_OK(asp_splat_renderer_create_hier(gl, h, &d, &r2, &err), ep(&err));
    asp_camera cam;
    asp_camera_init(&cam);
    cam.azimuth = 33;
    cam.elevation = 12;
    const float center[3] = {0, 0, 0};
    asp_camera_fit(&cam, center, 1.1f, 1.0f);
    asp_render_desc rd = {.width = 80, .height = 80, .samples = 4};
    asp_image img[3] = {{0, 0, NULL}, {0, 0, NULL}, {0, 0, NULL}};
    if (r1 && r2) {
        CHECK_OK(asp_render_to_image(gl, r1, &cam, &rd, &img[0], &err), ep(&err));
        CHECK_OK(asp_render_to_image(gl, r1, &cam, &rd, &img[1], &err), ep(&err));
        CHECK_OK(asp_render_to_image(gl, r2, &cam, &rd, &img[2], &err), ep(&err));
        if (img[0].pixels && img[1].pixels && img[2].pixels) {
            CHECK(memcmp(img[0].pixels, img[1].pixels, 4 * 80 * 80) == 0);
            CHECK(memcmp(img[0].pixels, img[2].pixels, 4 * 80 * 80) == 0);
        }
    }
    for (int i = 0; i < 3; i++)
        asp_image_release(&img[i]);
    asp_renderer_destroy(r1);
    asp_renderer_destroy(r2);
    asp_hier_destroy(h);
    asp_cloud_destroy(c);
}

static void test_bad_input(void)
{
    if (!gl)
        return;
    asp_error err;
    asp_renderer *r = NULL;
    asp_cloud *c = NULL;
    CHECK_OK(asp_cloud_create(0, 0, NULL, &c, &err), ep(&err));
    if (c) {
        CHECK(asp_splat_renderer_create(gl, c, NULL, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
        CHECK(asp_square_renderer_create(gl, c, NULL, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
        asp_cloud_destroy(c);
        c = NULL;
    }
    // all points equal, no radii: nothing has a size
    CHECK_OK(asp_cloud_create(50, 0, NULL, &c, &err), ep(&err));
    if (c) {
        CHECK(asp_splat_renderer_create(gl, c, NULL, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
        CHECK_MSG(strstr(err.msg, "same position") != NULL, "message '%s'", err.msg);
        c->positions[3 * 7 + 1] = NAN;
        CHECK(asp_splat_renderer_create(gl, c, NULL, NULL, &r, &err) == ASP_EINVAL && r == NULL);
        asp_cloud_destroy(c);
        c = NULL;
    }
    c = make_sphere(300);
    if (!c)
        return;
    CHECK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.kernel_a = -1}, NULL, &r, &err) == ASP_EINVAL);
    CHECK_MSG(strstr(err.msg, "kernel_a") != NULL, "message '%s'", err.msg);
    CHECK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.kernel_n = NAN}, NULL, &r, &err) == ASP_EINVAL);
    CHECK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.tolerance = INFINITY}, NULL, &r, &err) ==
          ASP_EINVAL);
    CHECK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.lighting = 7}, NULL, &r, &err) == ASP_EINVAL);
    CHECK(asp_square_renderer_create(gl, c, &(asp_square_renderer_desc){.point_size = -2}, NULL, &r, &err) == ASP_EINVAL);
    CHECK(r == NULL);
    // set_lod: only hierarchy renderers; tau must be a number >= 0
    asp_renderer *disc = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &disc, &err), ep(&err));
    if (disc) {
        CHECK(asp_renderer_set_lod(disc, 1, 0, &err) == ASP_EUNSUPPORTED);
        CHECK_MSG(strstr(err.msg, "disc") != NULL, "message '%s'", err.msg);
        CHECK(asp_renderer_set_budget(disc, 10, &err) == ASP_EUNSUPPORTED);
        CHECK_MSG(strstr(err.msg, "disc") != NULL, "message '%s'", err.msg);
        asp_renderer_stats st;
        asp_renderer_stats_get(disc, &st);
        CHECK(st.count == 300 && st.nodes == 0);
        asp_renderer_destroy(disc);
    }
    CHECK_OK(asp_splat_renderer_create(gl, c, NULL, NULL, &r, &err), ep(&err));
    if (r) {
        CHECK(asp_renderer_set_lod(r, NAN, 0, &err) == ASP_EINVAL);
        CHECK(asp_renderer_set_lod(r, -1, 0, &err) == ASP_EINVAL);
        // looking away: everything culled, the background stays
        asp_camera cam;
        asp_camera_init(&cam);
        cam.target[2] = -10.0f; // the eye at z = -5 looks towards -z, the sphere is behind it
        cam.distance = 5.0f;
        asp_image img = {0, 0, NULL};
        CHECK_OK(asp_render_to_image(gl, r, &cam, &(asp_render_desc){.width = 16, .height = 16}, &img, &err),
                 ep(&err));
        CHECK(asp_renderer_count(r) == 0);
        if (img.pixels)
            CHECK(covered(&img) == 0);
        asp_image_release(&img);
        asp_renderer_destroy(r);
    }
    asp_cloud_destroy(c);
}

static void setup(void)
{
    asp_error err = {0, ""};
    int rc = asp_gl_context_create_headless(&(asp_gl_context_desc){.flags = ASP_GL_CONTEXT_DEBUG}, NULL, &gl, ep(&err));
    CHECK_MSG(rc == 0, "no headless GL: %s", err.msg);
    CHECK_OK(asp_synth(ASP_SYNTH_CHECKER_PLANE, NULL, NULL, &checker, &err), ep(&err));
}

static void teardown(void)
{
    asp_cloud_destroy(checker);
    checker = NULL;
    asp_gl_context_destroy(gl);
    gl = NULL;
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_checker_no_holes), TEST_CASE(test_checker_oblique_lod),
          TEST_CASE(test_coverage_matches_discs), TEST_CASE(test_count_and_tau), TEST_CASE(test_epsilon_z_buffer),
          TEST_CASE(test_lighting_modes), TEST_CASE(test_square_fixed_size), TEST_CASE(test_deterministic_and_hier),
          TEST_CASE(test_bad_input), TEST_FIXTURE(teardown))
