/*
 * Thesis eq. 3.3 as written (issue 17, desc.normalise_color): with the
 * radial method and the f >= 1 criterion, a texel where f < 1 keeps
 * c = sum phi g undivided, so at a domain's border the colour darkens with
 * alpha; by default colour, stored straight, is always divided by f. Inside
 * (f >= 1) both are the same. A flat 2 x 1 domain of grey (200) points.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static void test_colour_criterion(void)
{
    enum { NX = 51, NY = 26 };
    const size_t n = (size_t)NX * NY;
    asp_error err;
    asp_cloud *c = NULL;
    asp_amg_csr *dom = NULL;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_RADII | ASP_ATTR_COLORS, NULL, &c, &err), &err);
    CHECK_OK(asp_amg_csr_create(1, n, n, NULL, &dom, &err), &err);
    if (!c || !dom) {
        asp_cloud_destroy(c);
        asp_amg_csr_destroy(dom);
        return;
    }
    for (size_t j = 0; j < NY; j++)
        for (size_t i = 0; i < NX; i++) {
            size_t p = j * NX + i;
            c->positions[3 * p] = -1.0f + 0.04f * (float)i;
            c->positions[3 * p + 1] = -0.5f + 0.04f * (float)j;
            c->normals[3 * p + 2] = 1;
            c->radii[p] = 0.04f;
            memset(c->colors + 4 * p, 200, 3);
            c->colors[4 * p + 3] = 255;
            dom->col[p] = (asp_index)p;
            dom->val[p] = 1.0;
        }
    dom->row_ptr[1] = n;
    asp_dps_level lv[2];
    memset(lv, 0, sizeof lv);
    for (int k = 0; k < 2; k++)
        CHECK_OK(asp_prim_build_level(c, dom,
                                      &(asp_prim_desc){.method = ASP_PRIM_RADIAL, .normalise = ASP_PRIM_NORM_GE1,
                                                       .texel_size = 0.25, .normalise_color = k},
                                      NULL, &lv[k], &err),
                 &err);
    if (lv[0].prim_count == 1 && lv[1].prim_count == 1) {
        const asp_prim *p = &lv[0].prims[0];
        size_t border = 0, darker = 0, inside = 0, same = 0;
        for (uint32_t j = 0; j < p->tex_h; j++)
            for (uint32_t i = 0; i < p->tex_w; i++) {
                size_t o = 4 * ((size_t)(p->tex_y + j) * lv[0].atlas.width + p->tex_x + i);
                const uint8_t *a = lv[0].atlas.pixels + o, *b = lv[1].atlas.pixels + o;
                CHECK(a[3] == b[3]); // alpha follows the criterion either way
                if (a[3] == 255) {
                    inside++;
                    same += a[0] == b[0];
                } else if (a[3] > 25 && a[3] < 200) {
                    border++;
                    darker += b[0] + 10 < a[0];
                }
            }
        fprintf(stderr, "border texels %zu (%zu darker), inside %zu (%zu equal)\n", border, darker, inside, same);
        CHECK(border > 20 && darker == border);
        CHECK(inside > 100 && same == inside);
    } else {
        CHECK_MSG(0, "expected one primitive per build, got %zu and %zu", lv[0].prim_count, lv[1].prim_count);
    }
    asp_dps_level_release(&lv[0], NULL);
    asp_dps_level_release(&lv[1], NULL);
    asp_amg_csr_destroy(dom);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_colour_criterion))
