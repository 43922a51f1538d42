/*
 * Crease clipping in the disc and splat renderers (Botsch et al. 2005 clip
 * lines; planes from asp_crease_clip_planes): a single disc cut by one and two
 * planes covers exactly the kept half and quarter (with and without
 * multisampling); two samplings of the octahedron (seeds 0 and 7) drawn with
 * clipping agree far better (SSIM) than without; clipped renders match the
 * exact projected octahedron (no pixel more than 1 px inside it left empty,
 * almost none more than 1 px outside covered); the hierarchy entry point and
 * the opaque mode clip too. Set ASP_TEST_CREASE_OUT=<dir> to keep contact
 * sheets of the clipped and unclipped renders.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/geom.h"
#include "amgsplat/hier.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"


static asp_error *ep(asp_error *e)
{
    return e;
}

enum { KIND_DISC, KIND_SPLAT };
static const char *const kind_names[] = {"discs", "splats"};

static asp_renderer *make_renderer(int kind, const asp_cloud *c, const float *planes)
{
    asp_error err = {0, ""};
    asp_renderer *r = NULL;
    if (kind == KIND_DISC)
        CHECK_OK(asp_disc_renderer_create(gl, c, &(asp_disc_renderer_desc){.clip_planes = planes}, &r, &err),
                 ep(&err));
    else
        CHECK_OK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.clip_planes = planes}, NULL, &r, &err),
                 ep(&err));
    return r;
}

static const uint8_t white[3] = {255, 255, 255};

static int is_bg(const asp_image *img, uint32_t x, uint32_t y)
{
    const uint8_t *p = img->pixels + 4 * ((size_t)y * img->width + x);
    return p[0] == 255 && p[1] == 255 && p[2] == 255;
}

/* ---- one disc, cut by planes through its centre ---- */

/*
 * A disc of radius 0.5 at the origin facing +z, seen from +z (x to the right,
 * y up): kept half planes x >= 0 and y >= 0 leave the right half and the upper
 * right quarter, and nothing on the other sides of the centre lines.
 */
static void test_single_disc(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    CHECK_OK(asp_cloud_create(2, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    // a second, tiny point far behind, so the splat hierarchy has extent; it never reaches the image centre
    c->positions[5] = -40.0f;
    c->normals[2] = c->normals[5] = 1.0f;
    c->radii[0] = 0.5f;
    c->radii[1] = 1e-3f;
    const float half[16] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const float quarter[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    enum { W = 128 };
    asp_camera cam;
    asp_camera_init(&cam);
    cam.z_far = 100.0f;
    for (int kind = 0; kind < 2; kind++) {
        for (uint32_t samples = 1; samples <= 4; samples += 3) {
            asp_render_desc rd = {.width = W, .height = W, .background = {255, 255, 255, 255}, .samples = samples,
                                  .flags = ASP_RENDER_UNLIT};
            const float *sets[3] = {NULL, half, quarter};
            size_t fg[3] = {0}, wrong[3] = {0};
            for (int s = 0; s < 3; s++) {
                asp_renderer *r = make_renderer(kind, c, sets[s]);
                asp_image img = {0};
                if (r)
                    CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img, &err), ep(&err));
                asp_renderer_destroy(r);
                if (!img.pixels)
                    continue;
                for (uint32_t y = 0; y < W; y++)
                    for (uint32_t x = 0; x < W; x++) {
                        if (is_bg(&img, x, y))
                            continue;
                        fg[s]++;
                        // pixel centres x + 0.5 left of W / 2 are x < 0; rows below W / 2 are y < 0
                        wrong[s] += (s >= 1 && x < W / 2) || (s == 2 && y >= W / 2);
                    }
                asp_image_release(&img);
            }
            fprintf(stderr, "single %s, %u samples: %zu, %zu, %zu pixels (whole, half, quarter)\n", kind_names[kind],
                    samples, fg[0], fg[1], fg[2]);
            CHECK(fg[0] > 1000);
            CHECK_MSG(wrong[1] == 0 && wrong[2] == 0, "%s: %zu, %zu pixels on the clipped side", kind_names[kind],
                      wrong[1], wrong[2]);
            CHECK_NEAR((double)fg[1] / (double)fg[0], 0.5, 0.03);
            CHECK_NEAR((double)fg[2] / (double)fg[0], 0.25, 0.03);
        }
    }
    asp_cloud_destroy(c);
}

/* ---- the octahedron, two samplings ---- */

/* ASan and UBSan slow the CPU side; the GL work is the same, so the full 16 views stay affordable. */
enum { VIEWS = 16, SIZE = 256 };

static void view_camera(asp_camera *cam, size_t i, const float center[3], float radius)
{
    test_view_camera(cam, i, VIEWS, center, radius);
}

static void render_views(asp_renderer *r, const float center[3], float radius, asp_image *img)
{
    asp_error err = {0, ""};
    asp_render_desc rd = {.width = SIZE, .height = SIZE, .background = {255, 255, 255, 255}};
    for (size_t v = 0; r && v < VIEWS; v++) {
        asp_camera cam;
        view_camera(&cam, v, center, radius);
        CHECK_OK(asp_render_to_image(gl, r, &cam, &rd, &img[v], &err), ep(&err));
    }
}

static void save_sheet(const asp_image *tiles, const char *name)
{
    test_save_sheet(tiles, VIEWS, "ASP_TEST_CREASE_OUT", name);
}

/*
 * The exact silhouette of the octahedron |x| + |y| + |z| = 1 in view v: the
 * convex hull of its six projected vertices. dist[] gets, per pixel centre,
 * the signed distance in pixels to the hull's boundary (positive inside).
 */
static void exact_silhouette(size_t v, const float center[3], float radius, float *dist)
{
    asp_camera cam;
    view_camera(&cam, v, center, radius);
    double p[6][2];
    for (int i = 0; i < 6; i++) {
        float w[3] = {0, 0, 0}, o[3];
        w[i / 2] = i % 2 ? -1.0f : 1.0f;
        asp_camera_project(&cam, w, SIZE, SIZE, o);
        p[i][0] = o[0];
        p[i][1] = o[1];
    }
    // gift wrapping: fine for six points
    int hull[7], h = 0, start = 0;
    for (int i = 1; i < 6; i++)
        if (p[i][0] < p[start][0])
            start = i;
    int cur = start;
    do {
        hull[h++] = cur;
        int next = (cur + 1) % 6;
        for (int i = 0; i < 6; i++) {
            double cr = (p[next][0] - p[cur][0]) * (p[i][1] - p[cur][1]) -
                        (p[next][1] - p[cur][1]) * (p[i][0] - p[cur][0]);
            if (cr < 0)
                next = i;
        }
        cur = next;
    } while (cur != start && h < 6);
    // which side is inside depends on the image's y-down axis: ask the hull's centroid
    double mid[2] = {0, 0};
    for (int e = 0; e < h; e++) {
        mid[0] += p[hull[e]][0] / h;
        mid[1] += p[hull[e]][1] / h;
    }
    const double *a0 = p[hull[0]], *b0 = p[hull[1 % h]];
    double side = ((mid[0] - a0[0]) * (b0[1] - a0[1]) - (mid[1] - a0[1]) * (b0[0] - a0[0])) < 0 ? -1.0 : 1.0;
    for (uint32_t y = 0; y < SIZE; y++)
        for (uint32_t x = 0; x < SIZE; x++) {
            double q[2] = {x + 0.5, y + 0.5}, d = INFINITY;
            for (int e = 0; e < h; e++) {
                const double *a = p[hull[e]], *b = p[hull[(e + 1) % h]];
                double ex = b[0] - a[0], ey = b[1] - a[1], len = sqrt(ex * ex + ey * ey);
                d = fmin(d, side * ((q[0] - a[0]) * ey - (q[1] - a[1]) * ex) / len);
            }
            dist[(size_t)y * SIZE + x] = (float)d;
        }
}

typedef struct silhouette_stats {
    double iou;        /* rendered foreground vs pixel centres inside the exact silhouette */
    size_t holes;      /* background pixels more than 1 px inside */
    size_t overhang;   /* foreground pixels more than 1 px outside */
} silhouette_stats;

static silhouette_stats compare_exact(const asp_image *img, const float *dist)
{
    silhouette_stats st = {0, 0, 0};
    size_t inter = 0, uni = 0;
    for (uint32_t y = 0; y < SIZE; y++)
        for (uint32_t x = 0; x < SIZE; x++) {
            float d = dist[(size_t)y * SIZE + x];
            int fg = !is_bg(img, x, y), in = d > 0;
            inter += fg && in;
            uni += fg || in;
            st.holes += !fg && d > 1.0f;
            st.overhang += fg && d < -1.0f;
        }
    st.iou = uni ? (double)inter / (double)uni : 1.0;
    return st;
}

static void release(asp_image *img)
{
    for (size_t v = 0; v < VIEWS; v++)
        asp_image_release(&img[v]);
}

static double mean_ssim(const asp_image *a, const asp_image *b, double *worst)
{
    asp_error err = {0, ""};
    double mean = 0;
    *worst = 1;
    for (size_t v = 0; v < VIEWS; v++) {
        double s = 0;
        if (a[v].pixels && b[v].pixels)
            CHECK_OK(asp_image_ssim(&a[v], &b[v], &s, &err), ep(&err));
        *worst = fmin(*worst, s);
        mean += s / VIEWS;
    }
    return mean;
}

/*
 * Bars measured on llvmpipe (SSIM of seed 0 vs seed 7, mean and worst of the
 * 16 views): discs 0.9201 / 0.9026 unclipped, 0.9931 / 0.9894 clipped; splats
 * 0.9191 / 0.9001 unclipped, 0.9931 / 0.9896 clipped. Exact-silhouette IoU
 * (worst view) 0.9448 unclipped, 0.9969 clipped.
 */
static void check_kind(int kind, asp_cloud *const oct[2], float *const planes[2], const float center[3],
                       float radius)
{
    static asp_image plain[2][VIEWS], cut[2][VIEWS];
    for (int s = 0; s < 2; s++) {
        asp_renderer *r = make_renderer(kind, oct[s], NULL);
        render_views(r, center, radius, plain[s]);
        asp_renderer_destroy(r);
        r = make_renderer(kind, oct[s], planes[s]);
        render_views(r, center, radius, cut[s]);
        asp_renderer_destroy(r);
    }
    double plain_worst, cut_worst;
    double plain_mean = mean_ssim(plain[0], plain[1], &plain_worst);
    double cut_mean = mean_ssim(cut[0], cut[1], &cut_worst);
    fprintf(stderr, "octahedron %-6s seed 0 vs 7: SSIM mean %.4f, worst %.4f unclipped; %.4f, %.4f clipped\n",
            kind_names[kind], plain_mean, plain_worst, cut_mean, cut_worst);
    CHECK_MSG(cut_mean >= 0.98 && cut_worst >= 0.975, "%s clipped: SSIM mean %.4f, worst %.4f", kind_names[kind],
              cut_mean, cut_worst);
    CHECK_MSG(cut_mean >= plain_mean + 0.05, "%s: clipping gains only %.4f SSIM", kind_names[kind],
              cut_mean - plain_mean);

    asp_error err = {0, ""};
    static float dist[SIZE * SIZE];
    double iou_plain = 1, iou_cut = 1, iou_pair = 1;
    size_t holes[2] = {0, 0}, overhang[2] = {0, 0};
    for (size_t v = 0; v < VIEWS; v++) {
        exact_silhouette(v, center, radius, dist);
        for (int s = 0; s < 2; s++) {
            if (!plain[s][v].pixels || !cut[s][v].pixels)
                continue;
            silhouette_stats p = compare_exact(&plain[s][v], dist), c = compare_exact(&cut[s][v], dist);
            iou_plain = fmin(iou_plain, p.iou);
            iou_cut = fmin(iou_cut, c.iou);
            holes[0] += p.holes;
            holes[1] += c.holes;
            overhang[0] += p.overhang;
            overhang[1] += c.overhang;
            double iou = 0;
            CHECK_OK(asp_image_silhouette_iou(&plain[s][v], &cut[s][v], white, &iou, &err), ep(&err));
            iou_pair = fmin(iou_pair, iou);
        }
    }
    fprintf(stderr,
            "octahedron %-6s exact-silhouette IoU >= %.4f unclipped, %.4f clipped (clipped vs unclipped %.4f); "
            "pixels > 1 px inside left empty: %zu, %zu; > 1 px outside covered: %zu, %zu\n",
            kind_names[kind], iou_plain, iou_cut, iou_pair, holes[0], holes[1], overhang[0], overhang[1]);
    CHECK_MSG(holes[1] == 0, "%s: %zu background pixels inside the clipped octahedron", kind_names[kind], holes[1]);
    CHECK_MSG(iou_cut >= 0.99 && iou_cut > iou_plain, "%s: exact-silhouette IoU %.4f clipped, %.4f unclipped",
              kind_names[kind], iou_cut, iou_plain);
    CHECK_MSG(overhang[1] * 20 < overhang[0], "%s: %zu pixels overhang the silhouette clipped, %zu unclipped",
              kind_names[kind], overhang[1], overhang[0]);

    char name[64];
    snprintf(name, sizeof name, "octahedron-%s-unclipped", kind_names[kind]);
    save_sheet(plain[0], name);
    snprintf(name, sizeof name, "octahedron-%s-clipped", kind_names[kind]);
    save_sheet(cut[0], name);
    for (int s = 0; s < 2; s++) {
        release(plain[s]);
        release(cut[s]);
    }
}

static void test_octahedron(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_cloud *oct[2] = {NULL, NULL};
    float *planes[2] = {NULL, NULL};
    const uint64_t seeds[2] = {0, 7};
    for (int s = 0; s < 2; s++) {
        CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.seed = seeds[s]}, NULL, &oct[s], &err),
                 ep(&err));
        if (!oct[s])
            goto done;
        planes[s] = malloc(8 * oct[s]->count * sizeof(float));
        size_t clipped = 0;
        CHECK_OK(asp_crease_clip_planes(oct[s], NULL, NULL, planes[s], &clipped, &err), ep(&err));
        CHECK(clipped > 1000);
    }
    float center[3], radius;
    CHECK_OK(asp_render_bounding_sphere(oct[0], center, &radius, &err), ep(&err));
    for (int kind = 0; kind < 2; kind++)
        check_kind(kind, oct, planes, center, radius);
done:
    for (int s = 0; s < 2; s++) {
        free(planes[s]);
        asp_cloud_destroy(oct[s]);
    }
}

/*
 * asp_splat_renderer_create_hier takes the planes by input point index, and
 * the opaque mode clips too: on a hierarchy built here, the clipped opaque
 * render keeps to the exact silhouette, and blended renders equal those of
 * asp_splat_renderer_create (same hierarchy, same planes).
 */
static void test_hier_and_opaque(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    asp_hier *h = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, NULL, NULL, &c, &err), ep(&err));
    if (c)
        CHECK_OK(asp_hier_build(c, NULL, NULL, &h, &err), ep(&err));
    float *planes = c ? malloc(8 * c->count * sizeof(float)) : NULL;
    if (!h || !planes)
        goto done;
    CHECK_OK(asp_crease_clip_planes(c, NULL, NULL, planes, NULL, &err), ep(&err));
    float center[3], radius;
    CHECK_OK(asp_render_bounding_sphere(c, center, &radius, &err), ep(&err));
    static float dist[SIZE * SIZE];
    asp_render_desc rd = {.width = SIZE, .height = SIZE, .background = {255, 255, 255, 255}};
    asp_renderer *plain = NULL, *cut = NULL, *blend_hier = NULL, *blend_cloud = NULL;
    CHECK_OK(asp_splat_renderer_create_hier(gl, h, &(asp_splat_renderer_desc){.mode = ASP_SPLAT_OPAQUE}, &plain,
                                            &err),
             ep(&err));
    CHECK_OK(asp_splat_renderer_create_hier(
                 gl, h, &(asp_splat_renderer_desc){.mode = ASP_SPLAT_OPAQUE, .clip_planes = planes}, &cut, &err),
             ep(&err));
    CHECK_OK(asp_splat_renderer_create_hier(gl, h, &(asp_splat_renderer_desc){.clip_planes = planes}, &blend_hier,
                                            &err),
             ep(&err));
    blend_cloud = make_renderer(KIND_SPLAT, c, planes);
    size_t over_plain = 0, over_cut = 0, holes = 0, differ = 0;
    for (size_t v = 0; plain && cut && blend_hier && blend_cloud && v < VIEWS; v += 5) {
        asp_camera cam;
        view_camera(&cam, v, center, radius);
        exact_silhouette(v, center, radius, dist);
        asp_image a = {0}, b = {0}, e = {0}, f = {0};
        CHECK_OK(asp_render_to_image(gl, plain, &cam, &rd, &a, &err), ep(&err));
        CHECK_OK(asp_render_to_image(gl, cut, &cam, &rd, &b, &err), ep(&err));
        CHECK_OK(asp_render_to_image(gl, blend_hier, &cam, &rd, &e, &err), ep(&err));
        CHECK_OK(asp_render_to_image(gl, blend_cloud, &cam, &rd, &f, &err), ep(&err));
        if (a.pixels && b.pixels && e.pixels && f.pixels) {
            silhouette_stats sa = compare_exact(&a, dist), sb = compare_exact(&b, dist);
            over_plain += sa.overhang;
            over_cut += sb.overhang;
            holes += sb.holes;
            differ += memcmp(e.pixels, f.pixels, (size_t)SIZE * SIZE * 4) != 0;
        }
        asp_image_release(&a);
        asp_image_release(&b);
        asp_image_release(&e);
        asp_image_release(&f);
    }
    fprintf(stderr, "opaque splats on a hierarchy: %zu pixels > 1 px outside unclipped, %zu clipped\n", over_plain,
            over_cut);
    CHECK(over_plain > 1000 && over_cut * 20 < over_plain);
    CHECK(holes == 0);
    CHECK_MSG(differ == 0, "%zu views differ between create_hier and create", differ);
    asp_renderer_destroy(plain);
    asp_renderer_destroy(cut);
    asp_renderer_destroy(blend_hier);
    asp_renderer_destroy(blend_cloud);
done:
    free(planes);
    asp_hier_destroy(h);
    asp_cloud_destroy(c);
}

static void test_bad_planes(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 800}, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    float *planes = calloc(8 * c->count, sizeof(float));
    planes[8 * 123 + 5] = NAN;
    asp_renderer *r = NULL;
    CHECK(asp_disc_renderer_create(gl, c, &(asp_disc_renderer_desc){.clip_planes = planes}, &r, &err) ==
          ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "point 123") != NULL, "message '%s'", err.msg);
    CHECK(asp_splat_renderer_create(gl, c, &(asp_splat_renderer_desc){.clip_planes = planes}, NULL, &r, &err) ==
          ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "point 123") != NULL, "message '%s'", err.msg);
    CHECK(r == NULL);
    free(planes);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_single_disc), TEST_CASE(test_octahedron), TEST_CASE(test_hier_and_opaque),
          TEST_CASE(test_bad_planes),
          TEST_FIXTURE(teardown))
