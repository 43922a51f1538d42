/*
 * Domain neighbours (journal section 4, Fig. 11): common points must exceed
 * the fraction of either domain's points; checked on hand-made domains at the
 * threshold's edge and against a brute-force count on random domains.
 */
#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "harness.h"

static asp_amg_csr *from_sets(const size_t *lo, const size_t *hi, size_t rows, size_t cols)
{
    /* row r: points lo[r] .. hi[r]-1 (two ranges per row: lo[2r].., lo[2r+1]..) */
    size_t nnz = 0;
    for (size_t r = 0; r < 2 * rows; r++)
        nnz += hi[r] - lo[r];
    asp_amg_csr *m = NULL;
    asp_error err;
    CHECK_OK(asp_amg_csr_create(rows, cols, nnz, NULL, &m, &err), &err);
    size_t k = 0;
    for (size_t r = 0; m && r < rows; r++) {
        for (size_t s = 2 * r; s < 2 * r + 2; s++)
            for (size_t p = lo[s]; p < hi[s]; p++) {
                m->col[k] = (asp_index)p;
                m->val[k++] = 0.5;
            }
        m->row_ptr[r + 1] = k;
    }
    return m;
}

static void test_threshold_edges(void)
{
    /* d0 = 0..99; d1 = 95..199 (5 common = 5% of d0, 4.8% of d1: not neighbours);
     * d2 = 0..9 + 1000..1189 (10 common: 10% of d0 though 5% of d2: neighbours); d3 = 94..99 + 2000..2093
     * (6 common = 6% of d0: neighbours); d4 disjoint */
    const size_t lo[10] = {0, 0, 95, 0, 0, 1000, 94, 2000, 3000, 0};
    const size_t hi[10] = {100, 0, 200, 0, 10, 1190, 100, 2094, 3050, 0};
    asp_amg_csr *m = from_sets(lo, hi, 5, 4000);
    if (!m)
        return;
    size_t first[6];
    uint32_t *list = NULL;
    size_t total = 0;
    asp_error err;
    CHECK_OK(asp_prim_neighbours(m, 0.05, NULL, first, &list, &total, &err), &err);
    if (list) {
        CHECK(total == 4);
        CHECK(first[1] - first[0] == 2 && list[first[0]] == 2 && list[first[0] + 1] == 3);
        CHECK(first[2] == first[1]);                          /* d1: none */
        CHECK(first[3] - first[2] == 1 && list[first[2]] == 0); /* d2: d0 */
        CHECK(first[4] - first[3] == 1 && list[first[3]] == 0); /* d3: d0 (d1 shares 5 of 100: 5%, not more) */
        CHECK(first[5] == first[4]);
        asp_free(NULL, list);
    }
    list = NULL;
    CHECK_OK(asp_prim_neighbours(m, 0.04, NULL, first, &list, &total, &err), &err);
    CHECK(total == 8); /* now d0-d1 (5%) and d1-d3 (5 of 100 = 5%) too */
    asp_free(NULL, list);
    CHECK(asp_prim_neighbours(m, 0, NULL, first, &list, &total, &err) == ASP_EINVAL);
    CHECK(asp_prim_neighbours(m, 1, NULL, first, &list, &total, &err) == ASP_EINVAL);
    asp_amg_csr_destroy(m);
}

static void test_brute_force(void)
{
    enum { ROWS = 60, COLS = 3000 };
    uint64_t s = 12345;
    size_t lo[2 * ROWS], hi[2 * ROWS];
    for (size_t r = 0; r < 2 * ROWS; r += 2) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        lo[r] = (size_t)(s >> 33) % (COLS - 200);
        hi[r] = lo[r] + 20 + (size_t)(s >> 20) % 180;
        lo[r + 1] = hi[r + 1] = 0;
    }
    asp_amg_csr *m = from_sets(lo, hi, ROWS, COLS);
    if (!m)
        return;
    size_t first[ROWS + 1], total = 0;
    uint32_t *list = NULL;
    asp_error err;
    asp_context two = {.threads = 2};
    CHECK_OK(asp_prim_neighbours(m, 0.05, &two, first, &list, &total, &err), &err);
    size_t expect = 0, wrong = 0;
    for (size_t a = 0; list && a < ROWS; a++)
        for (size_t b = 0; b < ROWS; b++) {
            if (a == b)
                continue;
            size_t x0 = lo[2 * a] > lo[2 * b] ? lo[2 * a] : lo[2 * b];
            size_t x1 = hi[2 * a] < hi[2 * b] ? hi[2 * a] : hi[2 * b];
            double common = x1 > x0 ? (double)(x1 - x0) : 0;
            int nb = common > 0.05 * (double)(hi[2 * a] - lo[2 * a]) || common > 0.05 * (double)(hi[2 * b] - lo[2 * b]);
            int found = 0;
            for (size_t q = first[a]; q < first[a + 1]; q++)
                found |= list[q] == b;
            expect += nb;
            wrong += nb != found;
        }
    CHECK(wrong == 0);
    CHECK(total == expect);
    CHECK(expect > 0);
    asp_free(NULL, list);
    asp_amg_csr_destroy(m);
}

TEST_MAIN(TEST_CASE(test_threshold_edges), TEST_CASE(test_brute_force))
