/*
 * The two forms of the stiffness matrix (issue 17; journal eq. 5-7, thesis
 * 2.4): clamped (amgsplat's default) has no positive off-diagonal; unclamped
 * (the seeds') keeps exactly the positive entries the clamped form counted,
 * with the same negative entries, and both stay symmetric with zero row sums.
 * The hierarchy of either is a partition of unity.
 */
#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "harness.h"

static double entry(const asp_amg_csr *a, size_t r, asp_index c)
{
    for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
        if (a->col[k] == c)
            return a->val[k];
    return 0;
}

static void test_forms(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *cloud = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000}, NULL, &cloud, err), err);
    if (!cloud)
        return;
    asp_amg *amg[2] = {NULL, NULL};
    for (int f = 0; f < 2; f++)
        CHECK_OK(asp_amg_decompose(cloud, &(asp_amg_desc){.stiffness = (asp_amg_stiffness)f, .keep_matrix = 1}, NULL, &amg[f], err), err);
    if (amg[0] && amg[1]) {
        const asp_amg_csr *c = asp_amg_matrix(amg[0]), *u = asp_amg_matrix(amg[1]);
        asp_amg_matrix_check mc, mu;
        asp_amg_csr_check_stiffness(c, &mc);
        asp_amg_csr_check_stiffness(u, &mu);
        size_t npos = asp_amg_get_info(amg[1])->positive_offdiag;
        fprintf(stderr, "octahedron 4000: %zu positive couplings, largest %g\n", npos, mu.max_offdiag);
        CHECK(npos == asp_amg_get_info(amg[0])->positive_offdiag);
        CHECK(npos > 0); /* the sampled octahedron has obtuse fans, else this test shows nothing */
        CHECK(mc.max_offdiag <= 0);
        CHECK(mu.max_offdiag > 0);
        CHECK(mu.max_asymmetry <= 1e-12 && mu.max_row_sum <= 1e-9);
        size_t upper_pos = 0, same_neg = 0, neg = 0;
        for (size_t r = 0; r < u->rows; r++)
            for (size_t k = u->row_ptr[r]; k < u->row_ptr[r + 1]; k++) {
                asp_index j = u->col[k];
                if (j == r)
                    continue;
                if (u->val[k] > 0) {
                    upper_pos += j > r;
                    CHECK(entry(c, r, j) == 0);
                } else {
                    neg++;
                    same_neg += entry(c, r, j) == u->val[k];
                }
            }
        CHECK_MSG(upper_pos == npos, "%zu positive entries above the diagonal, info counts %zu", upper_pos, npos);
        CHECK(same_neg == neg);
        /* the unclamped hierarchy is still a partition of unity with values in [0,1] */
        size_t nl = asp_amg_level_count(amg[1]);
        asp_amg_csr *psi = NULL;
        CHECK_OK(asp_amg_basis(amg[1], nl - 1, NULL, &psi, err), err);
        double worst = 0, lo = 0, hi = 1;
        for (size_t r = 0; psi && r < psi->rows; r++) {
            double s = 0;
            for (size_t k = psi->row_ptr[r]; k < psi->row_ptr[r + 1]; k++) {
                s += psi->val[k];
                lo = psi->val[k] < lo ? psi->val[k] : lo;
                hi = psi->val[k] > hi ? psi->val[k] : hi;
            }
            worst = fabs(s - 1) > worst ? fabs(s - 1) : worst;
        }
        CHECK_MSG(worst < 1e-6 && lo >= 0 && hi <= 1, "unclamped Psi^L: |sum-1| %g, range [%g, %g]", worst, lo, hi);
        asp_amg_csr_destroy(psi);
    }
    asp_amg *bad = NULL;
    CHECK(asp_amg_decompose(cloud, &(asp_amg_desc){.stiffness = (asp_amg_stiffness)2}, NULL, &bad, err) == ASP_EINVAL);
    CHECK(bad == NULL);
    asp_amg_destroy(amg[0]);
    asp_amg_destroy(amg[1]);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_forms))
