/*
 * The frame budget (issue 18 item 5, src/render/frame_budget.c) against a
 * simulated renderer whose frame time is a fixed cost plus a cost per splat,
 * with as many splats as tau^-2 allows (a surface's cut) up to the point
 * count, and multiplicative noise like llvmpipe's: the controller holds the
 * target, follows a cost step, ends at the finest tau when everything fits,
 * falls back on the depth limit (seed 004 3.2.5) when tau cannot help, and
 * comes back from it. Then the GL side: renderers without a level of detail
 * refuse it, asp_frame_budget_settle on a real splat renderer.
 */
#include <math.h>
#include <stdint.h>

#include "amgsplat/sample.h"
#include "amgsplat/render.h"
#include "harness.h"

typedef struct model {
    double fixed_ms, ms_per_splat, points, splats_at_1px, noise;
    uint32_t depth;    /* hierarchy depth: a depth limit d keeps at most 8^(d-1) splats */
    uint64_t rng;
} model;

static double uniform(model *m)
{
    m->rng = m->rng * 6364136223846793005ull + 1442695040888963407ull; // Knuth's LCG: deterministic
    return (double)(m->rng >> 11) / 9007199254740992.0;
}

static double splats(const model *m, const asp_frame_budget *b)
{
    double n = fmin(m->points, m->splats_at_1px / ((double)b->tolerance * b->tolerance));
    if (b->depth_limit)
        n = fmin(n, pow(8.0, (double)b->depth_limit - 1));
    return n;
}

static double frame_ms(model *m, const asp_frame_budget *b)
{
    double f = m->fixed_ms + m->ms_per_splat * splats(m, b);
    return f * (1.0 + m->noise * (2.0 * uniform(m) - 1.0));
}

/* One frame of the model fed to the budget; returns its time. */
static double step(model *m, asp_frame_budget *b, int *changed)
{
    size_t n = (size_t)splats(m, b);
    double f = frame_ms(m, b);
    int c = asp_frame_budget_update(b, f, n);
    if (changed)
        *changed = c;
    return f;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Runs frames [from, to) and returns the median frame time of [from + skip, to). */
static double run(model *m, asp_frame_budget *b, size_t frames, size_t skip)
{
    double *ms = malloc(frames * sizeof *ms);
    for (size_t i = 0; i < frames; i++) {
        ms[i] = step(m, b, NULL);
    }
    double med = median(ms + skip, frames - skip);
    free(ms);
    return med;
}

/* 1M points, 110 ms at full detail, 40 ms wanted: tau settles near the model's 1.83 px, frame time at T. */
static void test_holds_target(void)
{
    model m = {.fixed_ms = 10, .ms_per_splat = 1e-4, .points = 1e6, .splats_at_1px = 1e6, .noise = 0.15, .rng = 1};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    CHECK_NEAR(b.tolerance, 4, 0); // the default start: coarse
    double med = run(&m, &b, 300, 20);
    CHECK_MSG(fabs(med / 40 - 1) < 0.05, "median %g ms", med);
    double tau_model = sqrt(1e6 * 1e-4 / 30.0);
    CHECK_MSG(fabs(b.tolerance / tau_model - 1) < 0.15, "tau %g, model %g", (double)b.tolerance, tau_model);
    CHECK(b.depth_limit == 0 && !b.saturated && !b.finest && b.frames == 300);
    // noise-free, it settles within 10 frames from tau 4 and then stays put (the dead band)
    model q = m;
    q.noise = 0;
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    for (int i = 0; i < 10; i++)
        step(&q, &b, NULL);
    CHECK_MSG(fabs(frame_ms(&q, &b) / 40 - 1) <= 0.05, "after 10 frames: %g ms", frame_ms(&q, &b));
    float settled = b.tolerance;
    for (int i = 0; i < 20; i++) {
        int changed = 1;
        step(&q, &b, &changed);
        CHECK(changed == 0);
    }
    CHECK(b.tolerance == settled);
}

/* The view comes closer (3x the splats at every tau): tau grows and the frame time is back at T. */
static void test_follows_cost_step(void)
{
    model m = {.fixed_ms = 10, .ms_per_splat = 1e-4, .points = 1e7, .splats_at_1px = 1e6, .noise = 0.1, .rng = 7};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    run(&m, &b, 100, 0);
    float before = b.tolerance;
    m.splats_at_1px *= 3;
    double med = run(&m, &b, 200, 20);
    CHECK_MSG(fabs(med / 40 - 1) < 0.05, "median after the step %g ms", med);
    CHECK_MSG(fabs(b.tolerance / before - sqrt(3.0)) < 0.25, "tau %g -> %g (x%g, model x1.73)", (double)before,
              (double)b.tolerance, (double)(b.tolerance / before));
}

/* Everything fits (10,000 points, all drawn from tau 10 px down): tau goes to its minimum and stays. */
static void test_full_detail_fits(void)
{
    model m = {.fixed_ms = 5, .ms_per_splat = 1e-5, .points = 1e4, .splats_at_1px = 1e6, .noise = 0.05, .rng = 3};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    run(&m, &b, 60, 0);
    CHECK_NEAR(b.tolerance, 0.25, 0);
    CHECK(b.finest && !b.saturated && b.depth_limit == 0);
    // the moves from 4 px down changed nothing (every point drawn): they must not pass for "coarser is
    // not faster" when the view gets expensive (205 ms at full detail): the budget answers at full speed
    m.ms_per_splat = 2e-2;
    double med = run(&m, &b, 40, 20);
    CHECK_MSG(!b.bound && fabs(med / 40 - 1) < 0.1, "bound %d, median %g ms", b.bound, med);
}

/* A fixed cost over T: tau rises to its maximum, then the depth limit falls to 1 (seed 004 Fig. 3.5). */
static void test_depth_fallback(void)
{
    model m = {.fixed_ms = 10, .ms_per_splat = 7.3e-3, .points = 1e6, .splats_at_1px = 1e8, .noise = 0.05, .rng = 5};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40, .tolerance_max = 64, .depth_max = 8,
                                                                 .min_count = 1},
                                   &err), &err);
    // at tau 64, 24414 splats take 188 ms; depth limit 5 keeps 8^4 = 4096 splats: 40 ms
    double med = run(&m, &b, 120, 60);
    CHECK_NEAR(b.tolerance, 64, 0);
    CHECK_MSG(b.depth_limit == 5, "depth limit %u", b.depth_limit);
    CHECK_MSG(fabs(med / 40 - 1) < 0.1, "median %g ms", med);
    // a fixed cost no depth helps with: saturated at depth 1
    model slow = m;
    slow.fixed_ms = 100;
    run(&slow, &b, 60, 0);
    CHECK(b.depth_limit == 1 && b.saturated);
    // cheap again: the depth limit goes first (back to none), only then tau falls
    model cheap = m;
    cheap.ms_per_splat = 1e-6;
    float tau_before = b.tolerance;
    int depth_first = 1;
    for (int i = 0; i < 80; i++) {
        step(&cheap, &b, NULL);
        if (b.tolerance < tau_before && b.depth_limit != 0)
            depth_first = 0;
    }
    CHECK(depth_first);
    CHECK(b.depth_limit == 0 && b.tolerance < tau_before);
    // with the default floor of 1000 primitives the same slow view stops at depth 5 (4096 splats):
    // depth 4 would keep 512, blobs
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40, .tolerance_max = 64, .depth_max = 8},
                                   &err), &err);
    run(&slow, &b, 120, 0);
    CHECK_MSG(b.depth_limit == 5 && b.saturated && splats(&slow, &b) >= 1000, "depth %u, %g splats",
              b.depth_limit, splats(&slow, &b));
    // and tau stops where the cut would fall under 1000 splats without a depth fallback
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40, .tolerance_max = 4096}, &err), &err);
    run(&slow, &b, 120, 0);
    CHECK_MSG(b.saturated && splats(&slow, &b) >= 990 && splats(&slow, &b) < 1100, "%g splats, tau %g",
              splats(&slow, &b), (double)b.tolerance);
}

/*
 * Fill-bound (blended splats close up): a floor of 60 ms that no cut changes. The controller finds that
 * coarser is not faster and stops there instead of dropping to the depth fallback; a later view
 * where detail costs again is found by its probes.
 */
static void test_fill_bound(void)
{
    model m = {.fixed_ms = 60, .ms_per_splat = 1e-7, .points = 1e6, .splats_at_1px = 1e6, .noise = 0.05, .rng = 13};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40, .depth_max = 8}, &err), &err);
    run(&m, &b, 300, 0);
    // probes that did not help were undone: after 300 frames (36 probes) tau is where coarsening stopped
    CHECK_MSG(b.bound && b.slope < 0.2 && b.depth_limit == 0 && b.tolerance < 16, "bound %d slope %g depth %u tau %g",
              b.bound, (double)b.slope, b.depth_limit, (double)b.tolerance);
    model v = {.fixed_ms = 10, .ms_per_splat = 1e-4, .points = 1e6, .splats_at_1px = 4e6, .noise = 0.05, .rng = 17};
    double med = run(&v, &b, 200, 100);
    CHECK_MSG(!b.bound && fabs(med / 40 - 1) < 0.1, "bound %d, median %g ms after the view changed", b.bound, med);
}

/* Spikes (another process takes the CPU) move tau by at most max_step, and the median holds. */
static void test_spikes(void)
{
    model m = {.fixed_ms = 10, .ms_per_splat = 1e-4, .points = 1e6, .splats_at_1px = 1e6, .noise = 0.05, .rng = 11};
    asp_frame_budget b;
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    double ms[300];
    for (size_t i = 0; i < 300; i++) {
        float before = b.tolerance;
        ms[i] = frame_ms(&m, &b) * (i % 37 == 20 ? 5.0 : 1.0);
        asp_frame_budget_update(&b, ms[i], (size_t)splats(&m, &b));
        CHECK(b.tolerance <= before * 2.0f * 1.0001f && b.tolerance >= before / 2.0f * 0.9999f);
    }
    double med = median(ms + 20, 280);
    CHECK_MSG(fabs(med / 40 - 1) < 0.1, "median with spikes %g ms", med);
}

static void test_bad_options(void)
{
    asp_frame_budget b;
    memset(&b, 0x5a, sizeof b);
    unsigned char before[sizeof b];
    memcpy(before, &b, sizeof b);
    static const asp_frame_budget_desc bad[] = {
        {.target_ms = 0}, {.target_ms = -5}, {.target_ms = INFINITY}, {.target_ms = 40, .gain = 2},
        {.target_ms = 40, .max_step = 1}, {.target_ms = 40, .tolerance_min = 8, .tolerance_max = 2},
        {.target_ms = 40, .tolerance = -1}, {.target_ms = 40, .deadband = 1},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        asp_error err = {0, ""};
        CHECK_MSG(asp_frame_budget_init(&b, &bad[i], &err) == ASP_EINVAL && err.msg[0], "case %zu", i);
    }
    CHECK(memcmp(before, &b, sizeof b) == 0);
    asp_error err = {0, ""};
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40}, &err), &err);
    CHECK(asp_frame_budget_update(&b, NAN, 0) == 0 && asp_frame_budget_update(&b, -1, 0) == 0 && b.frames == 0);
    CHECK(asp_frame_budget_update(&b, 0, 0) == 1 && b.tolerance < 4); // 0 ms: as fast as can be
}

/* GL: disc has no level of detail; splat follows the budget; settle reaches the finest tau of a cheap scene. */
static void test_renderers(void)
{
    asp_error err = {0, ""};
    asp_gl_context *gl = NULL;
    int rc = asp_gl_context_create_headless(NULL, NULL, &gl, &err);
    CHECK_MSG(rc == 0, "no headless GL: %s", err.msg);
    if (rc)
        return;
    asp_cloud *c = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 4000}, NULL, &c, &err), &err);
    asp_renderer *disc = NULL, *splat = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, c, NULL, &disc, &err), &err);
    CHECK_OK(asp_splat_renderer_create(gl, c, NULL, NULL, &splat, &err), &err);
    asp_frame_budget b;
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 40, .tolerance = 12}, &err), &err);
    CHECK(asp_frame_budget_apply(&b, disc, &err) == ASP_EUNSUPPORTED && strstr(err.msg, "disc"));
    CHECK_OK(asp_frame_budget_apply(&b, splat, &err), &err);
    asp_renderer_stats st;
    asp_renderer_stats_get(splat, &st);
    CHECK_NEAR(st.tolerance, 12, 0);
    // 4000 splats at 64x64 take well under 10 s: the budget refines to the finest tau and stops there
    asp_camera cam;
    asp_camera_init(&cam);
    float center[3], radius;
    CHECK_OK(asp_render_bounding_sphere(c, center, &radius, &err), &err);
    asp_camera_fit(&cam, center, radius, 1);
    CHECK_OK(asp_frame_budget_init(&b, &(asp_frame_budget_desc){.target_ms = 10000, .tolerance = 12}, &err), &err);
    asp_frame_budget_result res;
    CHECK_OK(asp_frame_budget_settle(gl, splat, &cam, &(asp_render_desc){.width = 64, .height = 64}, &b, 60, 5, &res,
                                     &err), &err);
    CHECK_MSG(res.settled && res.tolerance == 0.25f && b.finest, "settled %d tau %g", res.settled,
              (double)res.tolerance);
    CHECK(res.frames >= 5 && res.frames < 60 && res.median_ms > 0 && res.p10_ms <= res.median_ms &&
          res.median_ms <= res.p90_ms);
    CHECK(res.count == asp_renderer_count(splat) && res.count > 3000);
    asp_renderer_stats_get(splat, &st);
    CHECK_NEAR(st.tolerance, 0.25, 0); // the reached state stays applied for the final image
    CHECK(asp_frame_budget_settle(gl, disc, &cam, NULL, &b, 10, 3, &res, &err) == ASP_EUNSUPPORTED);
    // the overlay draws over a frame without errors, and refuses an over-long text
    asp_text_overlay *ov = NULL;
    CHECK_OK(asp_text_overlay_create(gl, &ov, &err), &err);
    CHECK_OK(asp_text_overlay_draw(ov, "40.0 ms\ntau 1.5 px", NULL, &err), &err);
    char *long_text = malloc(5000);
    memset(long_text, 'a', 4999);
    long_text[4999] = 0;
    CHECK(asp_text_overlay_draw(ov, long_text, NULL, &err) == ASP_EINVAL);
    free(long_text);
    asp_text_overlay_destroy(ov);
    asp_renderer_destroy(disc);
    asp_renderer_destroy(splat);
    asp_cloud_destroy(c);
    asp_gl_context_destroy(gl);
}

TEST_MAIN(TEST_CASE(test_holds_target), TEST_CASE(test_follows_cost_step), TEST_CASE(test_full_detail_fits),
          TEST_CASE(test_depth_fallback), TEST_CASE(test_fill_bound), TEST_CASE(test_spikes), TEST_CASE(test_bad_options),
          TEST_CASE(test_renderers))
