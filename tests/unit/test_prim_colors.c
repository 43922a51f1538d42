/*
 * Thesis appendix C "Use Model Colors" and "Adjust Brightness" (issue 17):
 * with no_model_colors a red domain's texture is the default grey; with
 * brightness 0.1 its HSV value rises by 25.5 of 255 with hue and saturation
 * kept (R 200 -> 225.5, G and B 50 -> 56.4); bad values are refused.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static void centre_texel(const asp_dps_level *lv, uint8_t out[4])
{
    const asp_prim *p = &lv->prims[0];
    size_t o = 4 * ((size_t)(p->tex_y + p->tex_h / 2) * lv->atlas.width + p->tex_x + p->tex_w / 2);
    memcpy(out, lv->atlas.pixels + o, 4);
}

static void test_colors(void)
{
    enum { NX = 26, NY = 26 };
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
    for (size_t p = 0; p < n; p++) {
        c->positions[3 * p] = 0.04f * (float)(p % NX);
        c->positions[3 * p + 1] = 0.04f * (float)(p / NX);
        c->normals[3 * p + 2] = 1;
        c->radii[p] = 0.04f;
        const uint8_t red[4] = {200, 50, 50, 255};
        memcpy(c->colors + 4 * p, red, 4);
        dom->col[p] = (asp_index)p;
        dom->val[p] = 1.0;
    }
    dom->row_ptr[1] = n;
    const asp_prim_desc descs[3] = {{0}, {.no_model_colors = 1}, {.brightness = 0.1}};
    const double want[3][3] = {{200, 50, 50}, {200, 200, 200}, {225.5, 56.4, 56.4}};
    for (int k = 0; k < 3; k++) {
        asp_dps_level lv;
        memset(&lv, 0, sizeof lv);
        CHECK_OK(asp_prim_build_level(c, dom, &descs[k], NULL, &lv, &err), &err);
        if (lv.prim_count == 1) {
            uint8_t t[4];
            centre_texel(&lv, t);
            fprintf(stderr, "case %d: centre texel %u,%u,%u,%u\n", k, t[0], t[1], t[2], t[3]);
            for (int j = 0; j < 3; j++)
                CHECK_MSG(fabs(t[j] - want[k][j]) <= 1.5, "case %d channel %d: %u, expected %.1f", k, j, t[j],
                          want[k][j]);
        }
        asp_dps_level_release(&lv, NULL);
    }
    asp_dps_level bad;
    CHECK(asp_prim_build_level(c, dom, &(asp_prim_desc){.brightness = 1.5}, NULL, &bad, &err) == ASP_EINVAL);
    asp_amg_csr_destroy(dom);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_colors))
