/*
 * Ellipse axis ratio of a hierarchy node (seed 001 eq. 5-6, issue 17): by
 * default sqrt(lambda_2 / lambda_1), the ratio of the point spread; with
 * ASP_HIER_BUILD_LAMBDA_AXES the seed's lambda_2 / lambda_1, its square.
 * A uniform 64 x 16 grid in one leaf (the root): b/a about 1/4, and 1/16 as written.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static double root_ratio(const asp_cloud *c, unsigned flags)
{
    asp_error err;
    asp_hier *h = NULL;
    CHECK_OK(asp_hier_build(c, &(asp_hier_desc){.leaf_size = 1024, .flags = flags}, NULL, &h, &err), &err);
    if (!h)
        return NAN;
    const asp_hier_splat *root = asp_hier_splats(h);
    double r = root->b / root->a;
    asp_hier_destroy(h);
    return r;
}

static void test_ratio(void)
{
    enum { W = 64, H = 16 };
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(W * H, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &c, &err), &err);
    if (!c)
        return;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            size_t p = (size_t)j * W + i;
            c->positions[3 * p] = (float)i * 0.01f;
            c->positions[3 * p + 1] = (float)j * 0.01f;
            c->normals[3 * p + 2] = 1;
            c->radii[p] = 0.002f; // small discs: the ratio is that of the centres
        }
    double sq = root_ratio(c, 0), lam = root_ratio(c, ASP_HIER_BUILD_LAMBDA_AXES);
    fprintf(stderr, "64 x 16 grid: root b/a %.4f (sqrt), %.4f (lambda)\n", sq, lam);
    CHECK_MSG(sq > 0.22 && sq < 0.28, "sqrt ratio %g, expected about 0.25", sq);
    CHECK_MSG(fabs(lam - sq * sq) < 0.01, "lambda ratio %g, expected the square of %g", lam, sq);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_ratio))
