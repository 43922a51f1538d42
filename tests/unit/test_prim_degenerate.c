/*
 * Degenerate domains (issue 4): a domain of 1 point, of 2 points, of
 * colinear points, of coincident points, an empty domain and an all-empty
 * level. They become small primitives flagged DEGENERATE (plane normal from
 * the point normals) or are skipped with a count; never a crash or NaN.
 */
#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "harness.h"

enum { GRID = 20 };

static asp_cloud *make_cloud(void)
{
    /* 1 + 2 + 10 + 5 + GRID^2 points */
    size_t n = 18 + GRID * GRID;
    asp_cloud *c = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err), &err);
    if (!c)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        float *p = &c->positions[3 * i], *nm = &c->normals[3 * i];
        if (i == 0) {
            nm[2] = 1;
        } else if (i < 3) {
            p[0] = 1 + 0.1f * (float)(i - 1);
            nm[1] = 1;
        } else if (i < 13) {
            p[0] = 0.05f * (float)(i - 3);
            p[1] = 2;
            nm[2] = -1;
        } else if (i < 18) {
            p[0] = p[1] = p[2] = 3;
            nm[0] = 1;
        } else {
            p[0] = 0.05f * (float)((i - 18) % GRID);
            p[1] = 0.05f * (float)((i - 18) / GRID);
            p[2] = 5;
            nm[2] = 1;
        }
        c->radii[i] = 0.05f;
        c->colors[4 * i] = (uint8_t)(40 * (i % 6));
        c->colors[4 * i + 1] = 100, c->colors[4 * i + 2] = 200, c->colors[4 * i + 3] = 255;
    }
    return c;
}

/* Rows: {0}, {1,2}, {3..12}, {}, {13..17}, {18..} with Psi = 1. */
static asp_amg_csr *make_domains(size_t n)
{
    asp_amg_csr *d = NULL;
    asp_error err;
    CHECK_OK(asp_amg_csr_create(6, n, n, NULL, &d, &err), &err);
    if (!d)
        return NULL;
    const size_t starts[7] = {0, 1, 3, 13, 13, 18, n};
    for (size_t r = 0; r <= 6; r++)
        d->row_ptr[r] = starts[r];
    for (size_t k = 0; k < n; k++) {
        d->col[k] = (asp_index)k;
        d->val[k] = 1.0;
    }
    return d;
}

static void test_degenerate_domains(void)
{
    asp_cloud *c = make_cloud();
    asp_amg_csr *dom = c ? make_domains(c->count) : NULL;
    if (!dom)
        return;
    asp_error err;
    asp_dps_level lv;
    for (int method = 0; method < 2; method++) {
        asp_prim_desc d = {.method = (asp_prim_method)method, .normal_map = 1};
        CHECK_OK(asp_prim_build_level(c, dom, &d, NULL, &lv, &err), &err);
        if (!lv.prims)
            continue;
        CHECK(lv.prim_count == 5);
        CHECK(lv.skipped == 1);
        CHECK_MSG(lv.degenerate == 4, "%u degenerate", lv.degenerate);
        const float want[5][3] = {{0, 0, 1}, {0, 1, 0}, {0, 0, -1}, {1, 0, 0}, {0, 0, 1}};
        for (size_t k = 0; k < lv.prim_count; k++) {
            const asp_prim *p = &lv.prims[k];
            CHECK(isfinite(p->centre[0] + p->centre[1] + p->centre[2] + p->half_u + p->half_v));
            double dt = p->normal[0] * want[k][0] + p->normal[1] * want[k][1] + p->normal[2] * want[k][2];
            CHECK_MSG(dt > 0.999, "method %d, primitive %zu: normal (%g %g %g)", method, k, p->normal[0],
                      p->normal[1], p->normal[2]);
            CHECK(((p->flags & ASP_PRIM_FLAG_DEGENERATE) != 0) == (k < 4));
            /* the points show: some texel of each texture is opaque */
            unsigned maxa = 0;
            for (uint32_t j = 0; j < p->tex_h; j++)
                for (uint32_t i = 0; i < p->tex_w; i++) {
                    unsigned a = lv.atlas.pixels[4 * ((size_t)(p->tex_y + j) * lv.atlas.width + p->tex_x + i) + 3];
                    maxa = a > maxa ? a : maxa;
                }
            CHECK_MSG(maxa >= 128, "method %d, primitive %zu: max alpha %u", method, k, maxa);
            /* small: the single point's rectangle is about its footprint */
            if (k == 0)
                CHECK(p->half_u <= 0.11f && p->half_v <= 0.11f && p->half_u >= 0.04f);
            if (k == 2) /* the colinear row is 0.45 long */
                CHECK(p->half_u > 0.2f && p->half_v < 0.11f);
        }
        asp_dps_level_release(&lv, NULL);
        CHECK(lv.prims == NULL);
    }
    asp_amg_csr_destroy(dom);
    asp_cloud_destroy(c);
}

static void test_empty_and_bad(void)
{
    asp_cloud *c = make_cloud();
    if (!c)
        return;
    asp_error err;
    asp_amg_csr *empty = NULL;
    CHECK_OK(asp_amg_csr_create(3, c->count, 0, NULL, &empty, &err), &err);
    asp_dps_level lv;
    memset(&lv, 0x55, sizeof lv);
    CHECK(asp_prim_build_level(c, empty, NULL, NULL, &lv, &err) == ASP_EDEGENERATE);
    CHECK(strstr(err.msg, "no domain") != NULL);
    CHECK(lv.prims == NULL && lv.prim_count == 0);
    asp_amg_csr_destroy(empty);

    asp_amg_csr *dom = make_domains(c->count);
    if (dom) {
        dom->val[5] = NAN;
        CHECK(asp_prim_build_level(c, dom, NULL, NULL, &lv, &err) == ASP_EINVAL);
        CHECK(strstr(err.msg, "entry 5") != NULL);
        dom->val[5] = 1;
        dom->col[7] = (asp_index)c->count;
        CHECK(asp_prim_build_level(c, dom, NULL, NULL, &lv, &err) == ASP_EINVAL);
        dom->col[7] = 7;
        dom->cols = 3;
        CHECK(asp_prim_build_level(c, dom, NULL, NULL, &lv, &err) == ASP_EINVAL);
        dom->cols = c->count;
        /* no radii: estimated, so the build still works */
        float *radii = c->radii;
        c->radii = NULL;
        CHECK_OK(asp_prim_build_level(c, dom, NULL, NULL, &lv, &err), &err);
        CHECK(lv.prim_count == 5);
        asp_dps_level_release(&lv, NULL);
        c->radii = radii;
        asp_amg_csr_destroy(dom);
    }
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_degenerate_domains), TEST_CASE(test_empty_and_bad))
