/*
 * GPU texture construction (thesis 3.6, issue 17; "_prim" in the name: it decomposes, so ASan builds
 * unwind it fully for the MPI suppressions, CMakeLists.txt): asp_prim_build with the
 * compute-shader fill (asp_prim_gpu_fill_set) makes the CPU build's atlases, texel
 * for texel, for the affine method and every radial shape and criterion; a
 * fill's error reaches the caller; normal maps are refused.
 */
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"

static asp_error *ep(asp_error *e)
{
    return e;
}

static asp_cloud *cloud;
static asp_amg *amg;

static void decompose(void)
{
#ifndef ASP_HAVE_HYPRE
    asp_test_skips++; // the library decomposes only with hypre; the comparison needs a decomposition
    fprintf(stderr, "skip: built without hypre, nothing to decompose\n");
    return;
#endif
    asp_error err = {0, ""};
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000}, NULL, &cloud, &err), ep(&err));
    if (cloud)
        CHECK_OK(asp_amg_decompose(cloud, NULL, NULL, &amg, &err), ep(&err));
}

/* Per byte of the atlases: the largest and the mean |difference|, colour (RGB) and alpha apart. */
static void compare(const asp_dps *a, const asp_dps *b, const char *what, int *max_c, int *max_a)
{
    *max_c = *max_a = 255;
    CHECK(a->level_count == b->level_count);
    if (a->level_count != b->level_count)
        return;
    int mc = 0, ma = 0;
    double sc = 0, sa = 0, nt = 0;
    for (size_t i = 0; i < a->level_count; i++) {
        const asp_image *x = &a->levels[i].atlas, *y = &b->levels[i].atlas;
        CHECK(x->width == y->width && x->height == y->height && a->levels[i].prim_count == b->levels[i].prim_count);
        if (x->width != y->width || x->height != y->height)
            return;
        for (size_t t = 0; t < (size_t)x->width * x->height; t++) {
            for (int c = 0; c < 4; c++) {
                int d = abs((int)x->pixels[4 * t + (size_t)c] - (int)y->pixels[4 * t + (size_t)c]);
                if (c < 3)
                    mc = d > mc ? d : mc, sc += d;
                else
                    ma = d > ma ? d : ma, sa += d;
            }
            nt++;
        }
    }
    *max_c = mc, *max_a = ma;
    printf("  %-28s %8.0f texels: colour max %d mean %.2g, alpha max %d mean %.2g (of 255)\n", what, nt, mc,
           sc / (3 * nt), ma, sa / nt);
}

static void test_gpu_equals_cpu(void)
{
    if (!gl || !amg)
        return;
    asp_error err = {0, ""};
    size_t nl = asp_amg_level_count(amg), levels[3] = {nl - 4, nl - 3, nl - 1};
    static const struct {
        const char *what;
        asp_prim_desc d;
    } cases[] = {
        {"affine", {.method = ASP_PRIM_AFFINE}},
        {"radial linear", {.method = ASP_PRIM_RADIAL}},
        {"radial constant w 1.5", {.method = ASP_PRIM_RADIAL, .shape = ASP_PRIM_CONSTANT, .width = 1.5}},
        {"radial gaussian ge1 + colour", {.method = ASP_PRIM_RADIAL, .shape = ASP_PRIM_GAUSSIAN,
                                          .normalise = ASP_PRIM_NORM_GE1, .normalise_color = 1}},
        {"affine strict, texel 0.5", {.method = ASP_PRIM_AFFINE, .strict = 1, .texel_size = 0.5}},
        {"radial, no extend colour", {.method = ASP_PRIM_RADIAL, .no_extend_color = 1, .merge = 1}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        asp_prim_desc cpu = cases[k].d, gpu = cases[k].d;
        asp_prim_gpu_fill_set(&gpu, gl);
        asp_dps *a = NULL, *b = NULL;
        CHECK_OK(asp_prim_build(amg, NULL, levels, 3, &cpu, NULL, NULL, &a, &err), ep(&err));
        CHECK_OK(asp_prim_build(amg, NULL, levels, 3, &gpu, NULL, NULL, &b, &err), ep(&err));
        if (a && b) {
            int mc, ma;
            compare(a, b, cases[k].what, &mc, &ma);
            // the fills agree but for rounding: the same samples in the same order, in double precision; the
            // Gaussian's exp is single precision on the GPU (GLSL has no double exp), a relative 1e-7
            int bound = cases[k].d.shape == ASP_PRIM_GAUSSIAN ? 2 : 1;
            CHECK_MSG(mc <= bound && ma <= bound, "%s: colour %d, alpha %d of 255", cases[k].what, mc, ma);
            CHECK(b->desc.fill == NULL && b->desc.fill_user == NULL);
        }
        asp_dps_destroy(a);
        asp_dps_destroy(b);
    }
}

static int failing_fill(void *user, const asp_prim_fill_batch *b, float *acc, float *f, uint8_t *covered,
                        asp_error *err)
{
    (void)acc, (void)f, (void)covered;
    size_t *calls = user;
    ++*calls;
    // every primitive's samples, texels and (affine) triangles are in the batch
    CHECK(b->prim_count > 0 && b->sample_first[b->prim_count] > 0 && b->texel_first[b->prim_count] > 0);
    CHECK(b->method != ASP_PRIM_AFFINE || b->tri_first[b->prim_count] > 0);
    return asp_error_set(err, ASP_EGL, "the device is gone");
}

static void test_fill_errors(void)
{
    if (!amg)
        return;
    asp_error err = {0, ""};
    size_t level = asp_amg_level_count(amg) - 3, calls = 0;
    asp_dps *d = NULL;
    CHECK(asp_prim_build(amg, NULL, &level, 1, &(asp_prim_desc){.fill = failing_fill, .fill_user = &calls}, NULL, NULL,
                         &d, &err) == ASP_EGL);
    CHECK(!d && calls == 1 && strstr(err.msg, "device is gone"));
    CHECK(asp_prim_build(amg, NULL, &level, 1, &(asp_prim_desc){.fill = failing_fill, .normal_map = 1}, NULL, NULL,
                         &d, &err) == ASP_EUNSUPPORTED);
    CHECK(!d && strstr(err.msg, "normal map"));
}

static void cleanup(void)
{
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(decompose), TEST_CASE(test_gpu_equals_cpu), TEST_CASE(test_fill_errors),
          TEST_FIXTURE(cleanup), TEST_FIXTURE(teardown))
