/*
 * Domain merging (thesis 3.4): four overlapping domains of one flat square
 * merge into one whose basis is the sum; a perpendicular domain that overlaps
 * them is kept apart (angle), and so is a bent one (flatness).
 */
#include "amgsplat/amg.h"
#include "prim/internal.h"
#include "harness.h"

enum { G = 40 };

static void test_merge_flat(void)
{
    /* G x G points on z = 0 plus G x 10 on the wall x = 0, z > 0 */
    size_t n = G * G + G * 10;
    float *pos = calloc(3 * n, sizeof *pos), *nrm = calloc(3 * n, sizeof *nrm);
    for (size_t i = 0; i < G * G; i++) {
        pos[3 * i] = (float)(i % G) * 0.025f;
        pos[3 * i + 1] = (float)(i / G) * 0.025f;
        nrm[3 * i + 2] = 1;
    }
    for (size_t i = 0; i < G * 10; i++) {
        size_t k = G * G + i;
        pos[3 * k + 1] = (float)(i % G) * 0.025f;
        pos[3 * k + 2] = (float)(i / G + 1) * 0.025f;
        nrm[3 * k] = 1;
    }
    /* rows: 4 quadrants overlapping by 4 columns/rows, Psi 0.5 on the overlap; row 4: the wall and the
     * floor's first 3 columns */
    asp_amg_csr *dom = NULL;
    asp_error err;
    CHECK_OK(asp_amg_csr_create(5, n, 4 * n, NULL, &dom, &err), &err);
    if (!dom)
        return;
    size_t k = 0;
    for (size_t r = 0; r < 5; r++) {
        for (size_t i = 0; i < n; i++) {
            int in;
            if (r < 4) {
                size_t x = i % G, y = i / G, qx = r & 1, qy = r >> 1;
                in = i < G * G && (qx ? x >= G / 2 - 2 : x < G / 2 + 2) && (qy ? y >= G / 2 - 2 : y < G / 2 + 2);
            } else {
                in = i >= G * G || (i % G) < 3;
            }
            if (in) {
                dom->col[k] = (asp_index)i;
                dom->val[k++] = 0.25;
            }
        }
        dom->row_ptr[r + 1] = k;
    }
    asp_amg_csr *out = NULL;
    uint32_t *first = NULL, *count = NULL, merges = 0;
    CHECK_OK(asp__prim_merge(dom, pos, nrm, 0.01, 15, NULL, &out, &first, &count, &merges, &err), &err);
    if (out) {
        CHECK_MSG(out->rows == 2 && merges == 3, "%zu rows after %u merges", out->rows, merges);
        CHECK(first[0] == 0 && count[0] == 4 && first[1] == 4 && count[1] == 1);
        /* merged row: every floor point once, Psi summed (0.25 x number of quadrants holding it) */
        CHECK(out->row_ptr[1] == G * G);
        double sum = 0;
        for (size_t q = 0; q < out->row_ptr[1]; q++)
            sum += out->val[q];
        double expect = 0;
        for (size_t r = 0; r < 4; r++)
            expect += 0.25 * (double)(dom->row_ptr[r + 1] - dom->row_ptr[r]);
        CHECK_NEAR(sum, expect, 1e-9);
        for (size_t q = 1; q < out->row_ptr[1]; q++)
            CHECK(out->col[q] > out->col[q - 1]);
        asp_amg_csr_destroy(out);
        asp_free(NULL, first);
        asp_free(NULL, count);
    }
    /* with criteria that accept anything the wall joins too: it was the angle and flatness that kept it apart */
    out = NULL;
    CHECK_OK(asp__prim_merge(dom, pos, nrm, 1.0 / 3, 180, NULL, &out, &first, &count, &merges, &err), &err);
    if (out) {
        CHECK(out->rows == 1 && merges == 4 && count[0] == 5);
        asp_amg_csr_destroy(out);
        asp_free(NULL, first);
        asp_free(NULL, count);
    }
    asp_amg_csr_destroy(dom);
    free(pos);
    free(nrm);
}

TEST_MAIN(TEST_CASE(test_merge_flat))
