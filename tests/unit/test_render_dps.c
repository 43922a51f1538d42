/*
 * Domain-primitive renderer on small hand-made .dps levels whose pixels are
 * known (journal section 4, thesis chapter 4, Pajarola et al. 5.4): the seeds'
 * clamped sums and the over-bright spot, the per-pixel division, transparency
 * (journal section 6), overlap's locks, prefix's neighbour test, dark back
 * faces hard and soft, outlines, domain colours, normal-map relighting,
 * determinism and bad input. No AMG here (test_render_prim.c has the
 * decomposed octahedron), so it runs fast under ASan too.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"


static asp_error *ep(asp_error *e)
{
    return e;
}

static const uint8_t *px(const asp_image *img, uint32_t x, uint32_t y)
{
    return img->pixels + 4 * ((size_t)y * img->width + x);
}

/* ---- hand-made levels whose pixels are known ---- */

enum { TW = 8, TH = 8 }; /* texels per primitive */

/* A level of n primitives, each a TW x TH texture in one row of the atlas with one padding column each side. */
typedef struct test_level {
    asp_dps_level lv;
    asp_prim prims[4];
    uint32_t neighbours[12];
} test_level;

typedef void (*texel_fn)(int prim, int i, int j, uint8_t rgba[4]);

/*
 * Primitive k: square of half size h at (cx, cy, cz), facing +z (or -z when
 * back), texture from fn; the atlas holds a padding column copied from each
 * edge so linear filtering never reads another primitive's texels.
 */
static void set_prim(test_level *t, int k, double cx, double cy, double cz, float h, int back)
{
    asp_prim *p = &t->prims[k];
    memset(p, 0, sizeof *p);
    p->centre[0] = cx;
    p->centre[1] = cy;
    p->centre[2] = cz;
    p->axis_u[0] = back ? -1.0f : 1.0f; // axis_u x axis_v = normal
    p->axis_v[1] = 1.0f;
    p->normal[2] = back ? -1.0f : 1.0f;
    p->half_u = p->half_v = h;
    p->texel = 2 * h / TW;
    p->tex_x = (uint32_t)k * (TW + 2) + 1;
    p->tex_y = 0;
    p->tex_w = TW;
    p->tex_h = TH;
    p->points = 10;
}

static void make_level(test_level *t, int n, texel_fn fn)
{
    memset(&t->lv, 0, sizeof t->lv);
    t->lv.prim_count = (size_t)n;
    t->lv.prims = t->prims;
    t->lv.neighbours = t->neighbours;
    asp_error err;
    CHECK_OK(asp_image_init(&t->lv.atlas, (uint32_t)n * (TW + 2), TH, &err), ep(&err));
    for (int k = 0; k < n; k++)
        for (int j = 0; j < TH; j++)
            for (int i = -1; i <= TW; i++) {
                int ci = i < 0 ? 0 : i >= TW ? TW - 1 : i;
                fn(k, ci, j, t->lv.atlas.pixels + 4 * ((size_t)j * t->lv.atlas.width + (size_t)k * (TW + 2) + 1 + i));
            }
}

/* Makes primitives a and b neighbours (both lists; call in increasing a, then b order per primitive). */
static void link_all(test_level *t)
{
    size_t n = t->lv.prim_count, e = 0;
    for (size_t a = 0; a < n; a++) {
        t->prims[a].neighbour_first = (uint32_t)e;
        for (size_t b = 0; b < n; b++)
            if (b != a)
                t->neighbours[e++] = (uint32_t)b;
        t->prims[a].neighbour_count = (uint32_t)(n - 1);
    }
    t->lv.neighbour_total = e;
}

static void release_level(test_level *t)
{
    asp_image_release(&t->lv.atlas);
    asp_image_release(&t->lv.normal_atlas);
}

/* Renders lv from +z (azimuth 0, elevation 0), fitted to its bounding sphere, unlit unless lit. */
static int render_level(asp_renderer *r, const asp_dps_level *lv, const asp_prim_render_options *o,
                        const uint8_t bg[4], int lit, asp_image *img)
{
    asp_error err = {0, ""};
    float c[3], radius;
    CHECK_OK(asp_prim_level_bounding_sphere(lv, NULL, c, &radius, &err), ep(&err));
    CHECK_OK(asp_prim_renderer_set_options(r, o, &err), ep(&err));
    asp_camera cam;
    asp_camera_init(&cam);
    asp_camera_fit(&cam, c, radius, 1.0f);
    asp_render_desc rd = {.width = 64, .height = 64, .flags = lit ? 0u : ASP_RENDER_UNLIT};
    memcpy(rd.background, bg, 4);
    int rc = asp_render_to_image(gl, r, &cam, &rd, img, &err);
    CHECK_OK(rc, ep(&err));
    return rc;
}

static double lin(double v)
{
    v /= 255.0;
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

static double srgb(double l)
{
    l = l < 0 ? 0 : l > 1 ? 1 : l;
    return 255.0 * (l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1 / 2.4) - 0.055);
}

static void texel_half(int k, int i, int j, uint8_t rgba[4])
{
    (void)k, (void)i, (void)j;
    rgba[0] = 200, rgba[1] = 100, rgba[2] = 50, rgba[3] = 128;
}

static const uint8_t black[4] = {0, 0, 0, 255}, white[4] = {255, 255, 255, 255}, clear[4] = {0, 0, 0, 0};

#define CHECK_RGB(p, r_, g_, b_, tol)   \
    do {                                \
        CHECK_NEAR((p)[0], (r_), (tol)); \
        CHECK_NEAR((p)[1], (g_), (tol)); \
        CHECK_NEAR((p)[2], (b_), (tol)); \
    } while (0)

/* One primitive of colour (200, 100, 50) and alpha 128/255: the seeds' sums, the division, opacity, alpha tests. */
static void test_single_primitive(void)
{
    if (!gl)
        return;
    test_level t;
    make_level(&t, 1, texel_half);
    set_prim(&t, 0, 0, 0, 0, 1.0f, 0);
    asp_renderer *r = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
    if (!r) {
        release_level(&t);
        return;
    }
    double a = 128 / 255.0;
    asp_image img = {0};
    // the seeds' additive blending over black: colour x alpha (thesis 4.3)
    static const asp_prim_render_method seeds[] = {ASP_PRIM_RENDER_OVERLAP, ASP_PRIM_RENDER_TWO_PASS,
                                                   ASP_PRIM_RENDER_BLEND_ALL, ASP_PRIM_RENDER_DARK_BACKFACE,
                                                   ASP_PRIM_RENDER_DARK_BACKFACE_SOFT};
    for (size_t m = 0; m < sizeof seeds / sizeof seeds[0]; m++) {
        if (render_level(r, &t.lv, &(asp_prim_render_options){.method = seeds[m]}, black, 0, &img))
            continue;
        CHECK_RGB(px(&img, 32, 32), srgb(lin(200) * a), srgb(lin(100) * a), srgb(lin(50) * a), 2);
        CHECK_RGB(px(&img, 0, 0), 0, 0, 0, 0); // outside: the background
        asp_image_release(&img);
    }
    // normalized and prefix divide the alpha away (Pajarola et al. 5.4)
    for (int m = 0; m < 2; m++) {
        asp_prim_render_options o = {.method = m ? ASP_PRIM_RENDER_PREFIX : ASP_PRIM_RENDER_NORMALIZED};
        if (render_level(r, &t.lv, &o, black, 0, &img))
            continue;
        CHECK_RGB(px(&img, 32, 32), 200, 100, 50, 1);
        asp_image_release(&img);
        // transparency 0.5 over white (journal section 6)
        o.transparency = 0.5f;
        if (render_level(r, &t.lv, &o, white, 0, &img))
            continue;
        CHECK_RGB(px(&img, 32, 32), srgb(0.5 * lin(200) + 0.5), srgb(0.5 * lin(100) + 0.5), srgb(0.5 * lin(50) + 0.5),
                  2);
        asp_image_release(&img);
    }
    // seeds over a transparent background: straight alpha = the summed alpha, colour unchanged
    if (!render_level(r, &t.lv, &(asp_prim_render_options){.method = ASP_PRIM_RENDER_BLEND_ALL}, clear, 0, &img)) {
        const uint8_t *p = px(&img, 32, 32);
        CHECK_NEAR(p[3], 128, 1);
        CHECK_RGB(p, 200, 100, 50, 3);
        CHECK(px(&img, 0, 0)[3] == 0);
        asp_image_release(&img);
    }
    // no-blend: the alpha test decides; polygons ignore alpha
    if (!render_level(r, &t.lv, &(asp_prim_render_options){.method = ASP_PRIM_RENDER_NO_BLEND, .alpha_ref = 0.6f},
                      black, 0, &img)) {
        CHECK_RGB(px(&img, 32, 32), 0, 0, 0, 0);
        asp_image_release(&img);
    }
    static const asp_prim_render_method opaque[] = {ASP_PRIM_RENDER_NO_BLEND, ASP_PRIM_RENDER_POLYGONS};
    for (int m = 0; m < 2; m++)
        if (!render_level(r, &t.lv, &(asp_prim_render_options){.method = opaque[m], .alpha_ref = 0.4f}, black, 0,
                          &img)) {
            CHECK_RGB(px(&img, 32, 32), 200, 100, 50, 1);
            asp_image_release(&img);
        }
    // alpha 0.5 fails an alpha test of 0.6: normalized then has no front layer and draws nothing
    if (!render_level(r, &t.lv, &(asp_prim_render_options){.alpha_ref = 0.6f}, black, 0, &img)) {
        CHECK_RGB(px(&img, 32, 32), 0, 0, 0, 0);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    release_level(&t);
}

/* Two coplanar primitives whose alphas overlap: ramps summing to 1, or both 1 (the over-bright case). */
static int ramp_overlap; /* 0: ramps summing to 1; 1: alpha 1 on both */
static void texel_ramp(int k, int i, int j, uint8_t rgba[4])
{
    (void)j;
    rgba[0] = rgba[1] = rgba[2] = 100;
    // primitive 0 spans x in [-1.5, 0.5], primitive 1 [-0.5, 1.5]; they share x in [-0.5, 0.5] = texels 4..7 / 0..3
    double x = k == 0 ? -1.5 + (i + 0.5) * 0.25 : -0.5 + (i + 0.5) * 0.25, w;
    if (ramp_overlap)
        w = 1;
    else
        w = k == 0 ? (x < -0.5 ? 1 : 0.5 - x) : (x > 0.5 ? 1 : x + 0.5);
    rgba[3] = (uint8_t)lround(255 * fmin(1, fmax(0, w)));
}

static void test_partition_of_unity(void)
{
    if (!gl)
        return;
    for (ramp_overlap = 0; ramp_overlap < 2; ramp_overlap++) {
        test_level t;
        make_level(&t, 2, texel_ramp);
        set_prim(&t, 0, -0.5, 0, 0, 1.0f, 0);
        set_prim(&t, 1, 0.5, 0, 0, 1.0f, 0);
        link_all(&t);
        asp_renderer *r = NULL;
        asp_error err = {0, ""};
        CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
        static const asp_prim_render_method ms[] = {ASP_PRIM_RENDER_NORMALIZED, ASP_PRIM_RENDER_PREFIX,
                                                    ASP_PRIM_RENDER_OVERLAP, ASP_PRIM_RENDER_BLEND_ALL};
        for (size_t m = 0; r && m < 4; m++) {
            asp_image img = {0};
            if (render_level(r, &t.lv, &(asp_prim_render_options){.method = ms[m]}, black, 0, &img))
                continue;
            // along the middle row across the overlap: the sum of weights is 1 (or 2 where both are 1)
            double lo = 255, hi = 0;
            for (uint32_t x = 16; x < 48; x++) {
                lo = fmin(lo, px(&img, x, 32)[0]);
                hi = fmax(hi, px(&img, x, 32)[0]);
            }
            int normalized = m < 2;
            if (!ramp_overlap || normalized) {
                CHECK_MSG(lo >= 97 && hi <= 103, "%s, overlap %d: row spans %.0f..%.0f, expected 100",
                          asp_prim_render_method_name(ms[m]), ramp_overlap, lo, hi);
            } else {
                // the seeds' over-bright spot (thesis 5.3.1): twice the linear colour where both are 1
                CHECK_NEAR(hi, srgb(2 * lin(100)), 2);
                CHECK_NEAR(lo, 100, 2);
            }
            asp_image_release(&img);
        }
        asp_renderer_destroy(r);
        release_level(&t);
    }
}

/* Primitive 0 red, in front; primitive 1 blue, 0.05 behind it (within the default window). */
static void texel_red_blue(int k, int i, int j, uint8_t rgba[4])
{
    (void)i, (void)j;
    rgba[0] = k == 0 ? 200 : 0;
    rgba[1] = 0;
    rgba[2] = k == 0 ? 0 : 200;
    rgba[3] = 255;
}

/* Prefix blends only the front primitive's neighbours; overlap locks; blend-all and normalized mix what is near. */
static void test_visibility(void)
{
    if (!gl)
        return;
    for (int linked = 0; linked < 2; linked++) {
        test_level t;
        make_level(&t, 2, texel_red_blue);
        set_prim(&t, 0, 0, 0, 0, 1.0f, 0);
        set_prim(&t, 1, 0, 0, -0.05, 1.0f, 0);
        if (linked)
            link_all(&t);
        asp_renderer *r = NULL;
        asp_error err = {0, ""};
        CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
        if (!r) {
            release_level(&t);
            continue;
        }
        asp_prim_render_options got;
        CHECK_OK(asp_prim_renderer_options(r, &got, &err), ep(&err));
        CHECK(got.depth_window > 0.05f); // half the mean radius 1
        CHECK_NEAR(got.alpha_ref, 0.1, 1e-6);
        CHECK_NEAR(got.transparency, 1, 1e-6);
        struct {
            asp_prim_render_method m;
            int mixed; /* 1: red and blue summed/averaged, 0: red only */
        } cases[] = {{ASP_PRIM_RENDER_PREFIX, linked}, {ASP_PRIM_RENDER_NORMALIZED, 1},
                     {ASP_PRIM_RENDER_OVERLAP, linked}, {ASP_PRIM_RENDER_BLEND_ALL, 1},
                     {ASP_PRIM_RENDER_NO_BLEND, 0}, {ASP_PRIM_RENDER_TWO_PASS, 1}};
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            asp_image img = {0};
            if (render_level(r, &t.lv, &(asp_prim_render_options){.method = cases[c].m}, black, 0, &img))
                continue;
            const uint8_t *p = px(&img, 32, 32);
            CHECK_MSG(p[0] > 100 && (cases[c].mixed ? p[2] > 100 : p[2] == 0),
                      "%s, neighbours %d: centre %u,%u,%u", asp_prim_render_method_name(cases[c].m), linked, p[0],
                      p[1], p[2]);
            asp_image_release(&img);
        }
        // a window smaller than the gap separates the layers for normalized too
        asp_image img = {0};
        if (!render_level(r, &t.lv, &(asp_prim_render_options){.depth_window = 0.01f}, black, 0, &img)) {
            CHECK_RGB(px(&img, 32, 32), 200, 0, 0, 1);
            asp_image_release(&img);
        }
        asp_renderer_destroy(r);
        release_level(&t);
    }
}

/* Thesis 4.4.3: red front face over the left half; a back face of alpha 128 and a blue front face behind. */
static void texel_backface(int k, int i, int j, uint8_t rgba[4])
{
    (void)j;
    static const uint8_t rgb[3][3] = {{200, 0, 0}, {0, 0, 0}, {0, 0, 200}};
    memcpy(rgba, rgb[k], 3);
    rgba[3] = k == 0 ? (i < TW / 2 ? 255 : 0) : k == 1 ? 128 : 255;
}

static void test_dark_backface(void)
{
    if (!gl)
        return;
    test_level t;
    make_level(&t, 3, texel_backface);
    set_prim(&t, 0, 0, 0, 0, 1.0f, 0);
    set_prim(&t, 1, 0, 0, -0.3, 1.0f, 1);
    set_prim(&t, 2, 0, 0, -0.6, 1.0f, 0);
    asp_renderer *r = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
    asp_image img = {0};
    if (r && !render_level(r, &t.lv, &(asp_prim_render_options){.method = ASP_PRIM_RENDER_DARK_BACKFACE}, black, 0,
                           &img)) {
        CHECK_RGB(px(&img, 20, 32), 200, 0, 0, 1); // blue reset by the back face, then red added
        CHECK_RGB(px(&img, 44, 32), 0, 0, 0, 0);   // reset, nothing in front
        asp_image_release(&img);
    }
    if (r && !render_level(r, &t.lv, &(asp_prim_render_options){.method = ASP_PRIM_RENDER_DARK_BACKFACE_SOFT}, black,
                           0, &img)) {
        // blue minus the back face's alpha 128/255 in linear light, clamped at 0
        CHECK_RGB(px(&img, 44, 32), 0, 0, srgb(lin(200) - 128 / 255.0), 2);
        CHECK(px(&img, 44, 32)[2] < 200);
        asp_image_release(&img);
    }
    // blend-all ignores faces and depth: everything adds up
    if (r && !render_level(r, &t.lv, &(asp_prim_render_options){.method = ASP_PRIM_RENDER_BLEND_ALL}, black, 0, &img)) {
        CHECK(px(&img, 20, 32)[0] > 150 && px(&img, 20, 32)[2] > 150);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    release_level(&t);
}

static void texel_white(int k, int i, int j, uint8_t rgba[4])
{
    (void)k, (void)i, (void)j;
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 255;
}

/* Outlines, domain colours and relighting from a normal map (journal Fig. 12b, Fig. 5d, section 6). */
static void test_outline_colors_normal_map(void)
{
    if (!gl)
        return;
    test_level t;
    make_level(&t, 1, texel_white);
    set_prim(&t, 0, 0, 0, 0, 1.0f, 0);
    // normal map: every texel's normal tilted 60 degrees from +z towards +x
    asp_error err = {0, ""};
    CHECK_OK(asp_image_init(&t.lv.normal_atlas, t.lv.atlas.width, t.lv.atlas.height, &err), ep(&err));
    for (size_t i = 0; t.lv.normal_atlas.pixels && i < (size_t)t.lv.atlas.width * t.lv.atlas.height; i++) {
        uint8_t *p = t.lv.normal_atlas.pixels + 4 * i;
        p[0] = (uint8_t)lround(255 * (0.5 + 0.5 * sin(60 * 3.14159265358979 / 180)));
        p[1] = 128;
        p[2] = (uint8_t)lround(255 * (0.5 + 0.5 * cos(60 * 3.14159265358979 / 180)));
        p[3] = 255;
    }
    asp_renderer *r = NULL;
    CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
    if (!r) {
        release_level(&t);
        return;
    }
    asp_image img = {0};
    // lit by the headlight: 0.25 + 0.75 cos(60) = 0.625 with the normal map, 1 with the primitive normal
    if (!render_level(r, &t.lv, &(asp_prim_render_options){0}, black, 1, &img)) {
        CHECK_NEAR(px(&img, 32, 32)[0], srgb(0.625), 3);
        asp_image_release(&img);
    }
    if (!render_level(r, &t.lv, &(asp_prim_render_options){.flags = ASP_PRIM_RENDER_NO_NORMAL_MAP}, black, 1, &img)) {
        CHECK_NEAR(px(&img, 32, 32)[0], 255, 1);
        asp_image_release(&img);
    }
    // the first primitive takes the first palette colour
    if (!render_level(r, &t.lv, &(asp_prim_render_options){.flags = ASP_PRIM_RENDER_COLOR_BY_DOMAIN}, black, 0, &img)) {
        CHECK_RGB(px(&img, 32, 32), 230, 25, 75, 1);
        asp_image_release(&img);
    }
    // outlines: green pixels on the rectangle's border, none in its middle
    for (int m = 0; m < 2; m++) {
        asp_prim_render_options o = {.method = m ? ASP_PRIM_RENDER_POLYGONS : ASP_PRIM_RENDER_OVERLAP,
                                     .flags = ASP_PRIM_RENDER_OUTLINE};
        if (render_level(r, &t.lv, &o, black, 0, &img))
            continue;
        size_t green = 0;
        for (uint32_t y = 0; y < 64; y++)
            for (uint32_t x = 0; x < 64; x++) {
                const uint8_t *p = px(&img, x, y);
                green += p[0] < 10 && p[1] > 240 && p[2] < 10;
            }
        CHECK_MSG(green > 100, "%zu outline pixels", green);
        CHECK_RGB(px(&img, 32, 32), 255, 255, 255, 1);
        asp_image_release(&img);
    }
    asp_renderer_destroy(r);
    release_level(&t);
}

/* The same frame twice gives the same bytes. */
static void test_deterministic(void)
{
    if (!gl)
        return;
    test_level t;
    make_level(&t, 2, texel_ramp);
    set_prim(&t, 0, -0.5, 0, 0, 1.0f, 0);
    set_prim(&t, 1, 0.5, 0, -0.1, 1.0f, 0);
    link_all(&t);
    asp_renderer *r = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
    for (unsigned m = 0; r && asp_prim_render_method_name(m); m++) {
        asp_image a = {0}, b = {0};
        asp_prim_render_options o = {.method = (asp_prim_render_method)m};
        if (!render_level(r, &t.lv, &o, white, 1, &a) && !render_level(r, &t.lv, &o, white, 1, &b))
            CHECK_MSG(memcmp(a.pixels, b.pixels, 4 * 64 * 64) == 0, "%s", asp_prim_render_method_name(m));
        asp_image_release(&a);
        asp_image_release(&b);
    }
    asp_renderer_destroy(r);
    release_level(&t);
}

static void test_bad_input(void)
{
    asp_error err = {0, ""};
    asp_prim_render_method m;
    for (unsigned i = 0; asp_prim_render_method_name(i); i++) {
        CHECK_OK(asp_prim_render_method_parse(asp_prim_render_method_name(i), &m, &err), ep(&err));
        CHECK(m == (asp_prim_render_method)i);
    }
    CHECK(asp_prim_render_method_name(9) == NULL);
    CHECK(asp_prim_render_method_parse("overlaps", &m, &err) == ASP_EINVAL);
    CHECK_MSG(strstr(err.msg, "'overlaps'") && strstr(err.msg, "two-pass"), "%s", err.msg);

    test_level t;
    make_level(&t, 2, texel_white);
    set_prim(&t, 0, 0, 0, 0, 1.0f, 0);
    set_prim(&t, 1, 1, 0, 0, 1.0f, 0);
    link_all(&t);
    float c[3] = {9, 9, 9}, radius = 9;
    CHECK_OK(asp_prim_level_bounding_sphere(&t.lv, NULL, c, &radius, &err), ep(&err));
    CHECK_NEAR(c[0], 0.5, 1e-6);
    CHECK_NEAR(radius, sqrt(1.5 * 1.5 + 1), 1e-5);
    CHECK_OK(asp_prim_level_bounding_sphere(&t.lv, (double[3]){1, 0, 0}, c, &radius, &err), ep(&err));
    CHECK_NEAR(c[0], -0.5, 1e-6);
    if (!gl) {
        release_level(&t);
        return;
    }
    asp_renderer *r = NULL;
    struct {
        void (*spoil)(test_level *);
        int code;
        const char *word;
    } cases[4];
    (void)cases;
    // no primitives
    t.lv.prim_count = 0;
    CHECK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err) == ASP_EDEGENERATE && !r);
    CHECK(asp_prim_level_bounding_sphere(&t.lv, NULL, c, &radius, &err) == ASP_EDEGENERATE);
    t.lv.prim_count = 2;
    // a texture rectangle outside the atlas
    t.prims[1].tex_x = t.lv.atlas.width - 2;
    CHECK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err) == ASP_EFORMAT && !r);
    CHECK_MSG(strstr(err.msg, "primitive 1") && strstr(err.msg, "outside"), "%s", err.msg);
    t.prims[1].tex_x = TW + 3;
    // a neighbour index out of range
    t.neighbours[0] = 7;
    CHECK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err) == ASP_EFORMAT && !r);
    CHECK_MSG(strstr(err.msg, "neighbour entry 0 is 7"), "%s", err.msg);
    t.neighbours[0] = 1;
    // a NaN centre
    t.prims[0].centre[1] = NAN;
    CHECK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err) == ASP_EFORMAT && !r);
    CHECK_MSG(strstr(err.msg, "primitive 0"), "%s", err.msg);
    CHECK(asp_prim_level_bounding_sphere(&t.lv, NULL, c, &radius, &err) == ASP_EFORMAT);
    t.prims[0].centre[1] = 0;
    // bad options, at creation and later
    asp_prim_renderer_desc bad = {.options = {.transparency = 2}};
    CHECK(asp_prim_renderer_create(gl, &t.lv, &bad, &r, &err) == ASP_EINVAL && !r);
    CHECK_OK(asp_prim_renderer_create(gl, &t.lv, NULL, &r, &err), ep(&err));
    if (r) {
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.method = 9}, &err) == ASP_EINVAL);
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.alpha_ref = NAN}, &err) == ASP_EINVAL);
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.alpha_ref = 1.5f}, &err) == ASP_EINVAL);
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.depth_window = INFINITY}, &err) ==
              ASP_EINVAL);
        CHECK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.flags = 1u << 9}, &err) == ASP_EINVAL);
        // the renderer kept its options; negative values mean exactly 0
        asp_prim_render_options o;
        CHECK_OK(asp_prim_renderer_set_options(r, &(asp_prim_render_options){.alpha_ref = -1, .depth_window = -1},
                                               &err),
                 ep(&err));
        CHECK_OK(asp_prim_renderer_options(r, &o, &err), ep(&err));
        CHECK(o.alpha_ref == 0 && o.depth_window == 0 && o.outline_color[1] == 255);
        asp_renderer_destroy(r);
    }
    // a disc renderer has no primitive options
    asp_cloud *cloud = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 100}, NULL, &cloud, &err), ep(&err));
    asp_renderer *disc = NULL;
    if (cloud)
        CHECK_OK(asp_disc_renderer_create(gl, cloud, NULL, &disc, &err), ep(&err));
    if (disc) {
        CHECK(asp_prim_renderer_set_options(disc, &(asp_prim_render_options){0}, &err) == ASP_EUNSUPPORTED);
        CHECK_MSG(strstr(err.msg, "disc"), "%s", err.msg);
        asp_prim_render_options o;
        CHECK(asp_prim_renderer_options(disc, &o, &err) == ASP_EUNSUPPORTED);
    }
    asp_renderer_destroy(disc);
    asp_cloud_destroy(cloud);
    release_level(&t);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_single_primitive), TEST_CASE(test_partition_of_unity),
          TEST_CASE(test_visibility), TEST_CASE(test_dark_backface), TEST_CASE(test_outline_colors_normal_map),
          TEST_CASE(test_deterministic), TEST_CASE(test_bad_input), TEST_FIXTURE(teardown))
