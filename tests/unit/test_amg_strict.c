/*
 * Strict domains as domain rows (thesis eq. 2.5, issue 17): disjoint, every
 * point in exactly one, namely the basis function of its largest Psi; built
 * as primitives (desc.strict) they give one primitive per non-empty strict
 * domain, alpha 1 inside.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

static void test_strict_rows(void)
{
    asp_error err;
    asp_cloud *cloud = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000}, NULL, &cloud, &err), &err);
    asp_amg *amg = NULL;
    if (cloud)
        CHECK_OK(asp_amg_decompose(cloud, NULL, NULL, &amg, &err), &err);
    if (!amg) {
        asp_cloud_destroy(cloud);
        return;
    }
    size_t level = asp_amg_level_count(amg) - 3;
    asp_amg_csr *psi = NULL, *rows = NULL;
    CHECK_OK(asp_amg_basis(amg, level, NULL, &psi, &err), &err);
    if (psi)
        CHECK_OK(asp_amg_strict_domain_rows(psi, NULL, &rows, &err), &err);
    if (psi && rows) {
        size_t n = psi->rows, nonempty = 0;
        unsigned char *seen = calloc(n, 1);
        asp_index *label = malloc(n * sizeof *label);
        asp_amg_strict_domains(psi, label);
        CHECK(rows->rows == psi->cols && rows->cols == n && rows->row_ptr[rows->rows] == n);
        for (size_t i = 0; i < rows->rows; i++) {
            nonempty += rows->row_ptr[i + 1] > rows->row_ptr[i];
            for (size_t k = rows->row_ptr[i]; k < rows->row_ptr[i + 1]; k++) {
                asp_index x = rows->col[k];
                CHECK(x < n && !seen[x]); // disjoint
                if (x < n) {
                    seen[x] = 1;
                    CHECK(label[x] == i);
                }
                CHECK(rows->val[k] == 1.0);
                if (k > rows->row_ptr[i])
                    CHECK(rows->col[k] > rows->col[k - 1]);
            }
        }
        size_t covered = 0;
        for (size_t x = 0; x < n; x++)
            covered += seen[x];
        CHECK_MSG(covered == n, "%zu of %zu points in a strict domain", covered, n);
        asp_dps *dps = NULL;
        CHECK_OK(asp_prim_build(amg, NULL, &level, 1, &(asp_prim_desc){.strict = 1}, NULL, NULL, &dps, &err), &err);
        if (dps) {
            fprintf(stderr, "level %zu: %zu basis functions, %zu non-empty strict domains, %zu primitives\n", level,
                    psi->cols, nonempty, dps->levels[0].prim_count);
            CHECK(dps->levels[0].prim_count == nonempty);
            CHECK(dps->levels[0].neighbour_total == 0); // strict domains share no point
        }
        asp_dps_destroy(dps);
        free(seen);
        free(label);
    }
    asp_amg_csr_destroy(rows);
    asp_amg_csr_destroy(psi);
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_strict_rows))
