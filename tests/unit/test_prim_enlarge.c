/*
 * The support rectangle's size (issue 17, thesis appendix C "Enlarge Bounding
 * Rectangle"): by default the points' bounding rectangle plus one point
 * footprint on every side; with desc.enlarge = P its sides grown by P
 * percent. A flat 2 x 1 domain of points with radius 0.02 (texel 0.02): the
 * rectangle is 2.04 (default), 2.2 (10 %) or 3 (50 %) long, up to one texel
 * of rounding.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static void test_enlarge(void)
{
    enum { NX = 101, NY = 51 };
    const size_t n = (size_t)NX * NY;
    asp_error err;
    asp_cloud *c = NULL;
    asp_amg_csr *dom = NULL;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_RADII, NULL, &c, &err), &err);
    CHECK_OK(asp_amg_csr_create(1, n, n, NULL, &dom, &err), &err);
    if (!c || !dom) {
        asp_cloud_destroy(c);
        asp_amg_csr_destroy(dom);
        return;
    }
    for (size_t j = 0; j < NY; j++)
        for (size_t i = 0; i < NX; i++) {
            size_t p = j * NX + i;
            c->positions[3 * p] = -1.0f + 0.02f * (float)i;
            c->positions[3 * p + 1] = -0.5f + 0.02f * (float)j;
            c->normals[3 * p + 2] = 1;
            c->radii[p] = 0.02f;
            dom->col[p] = (asp_index)p;
            dom->val[p] = 1.0;
        }
    dom->row_ptr[1] = n;
    const double pct[] = {0, 10, 50}, want_u[] = {2.04, 2.2, 3.0}, want_v[] = {1.04, 1.1, 1.5};
    for (int k = 0; k < 3; k++) {
        asp_dps_level lv;
        memset(&lv, 0, sizeof lv);
        CHECK_OK(asp_prim_build_level(c, dom, &(asp_prim_desc){.enlarge = pct[k]}, NULL, &lv, &err), &err);
        if (lv.prim_count == 1) {
            const asp_prim *p = &lv.prims[0];
            double lu = 2 * p->half_u, lvv = 2 * p->half_v;
            fprintf(stderr, "enlarge %g%%: %.4f x %.4f, texel %.4f\n", pct[k], lu, lvv, p->texel);
            CHECK_MSG(lu >= want_u[k] - 1e-4 && lu <= want_u[k] + p->texel + 1e-4, "enlarge %g: length %g", pct[k], lu);
            CHECK_MSG(lvv >= want_v[k] - 1e-4 && lvv <= want_v[k] + p->texel + 1e-4, "enlarge %g: width %g", pct[k],
                      lvv);
        } else {
            CHECK_MSG(0, "enlarge %g: %zu primitives, expected 1", pct[k], lv.prim_count);
        }
        asp_dps_level_release(&lv, NULL);
    }
    asp_dps_level bad;
    CHECK(asp_prim_build_level(c, dom, &(asp_prim_desc){.enlarge = -5}, NULL, &bad, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "enlargement") != NULL);
    asp_amg_csr_destroy(dom);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_enlarge))
