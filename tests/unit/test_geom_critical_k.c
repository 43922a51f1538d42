/*
 * Critical neighbourhood size (thesis 2.3, issue 17): on one flat sheet the
 * surface variation never jumps (every point gets k_max); on two parallel
 * sheets 3 spacings apart it jumps when the other sheet enters the
 * neighbourhood, at about pi 3^2 = 28 points of the own sheet for an inner
 * point (fewer at the rims, where the ball reaches further).
 */
#include <stdlib.h>

#include "amgsplat/geom.h"
#include "harness.h"

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static void sheets(int nsheets, float *pos)
{
    for (int s = 0; s < nsheets; s++)
        for (int j = 0; j < 30; j++)
            for (int i = 0; i < 30; i++) {
                size_t p = ((size_t)s * 30 + (size_t)j) * 30 + (size_t)i;
                pos[3 * p] = 0.02f * (float)i;
                pos[3 * p + 1] = 0.02f * (float)j;
                pos[3 * p + 2] = 0.06f * (float)s;
            }
}

static void test_sheets(void)
{
    static float pos[2 * 900 * 3];
    static uint32_t k[2 * 900];
    asp_error err;
    sheets(1, pos);
    CHECK_OK(asp_critical_neighbourhood(pos, 900, NULL, NULL, k, &err), &err);
    size_t flat = 0;
    for (size_t i = 0; i < 900; i++)
        flat += k[i] == 96;
    CHECK_MSG(flat == 900, "one sheet: %zu of 900 points without a jump", flat);
    sheets(2, pos);
    CHECK_OK(asp_critical_neighbourhood(pos, 1800, NULL, NULL, k, &err), &err);
    qsort(k, 1800, sizeof *k, cmp_u32);
    fprintf(stderr, "two sheets: critical k 10%% %u, median %u, 90%% %u\n", k[180], k[900], k[1619]);
    CHECK_MSG(k[900] >= 16 && k[900] <= 40, "median critical k %u, expected about 28", k[900]);
    CHECK(k[1799] < 96); // every point sees the other sheet before 96 neighbours
    CHECK(asp_critical_neighbourhood(pos, 1800, &(asp_critical_desc){.k_min = 2}, NULL, k, &err) == ASP_EINVAL);
    CHECK(asp_critical_neighbourhood(pos, 50, NULL, NULL, k, &err) == ASP_EDEGENERATE);
}

TEST_MAIN(TEST_CASE(test_sheets))
