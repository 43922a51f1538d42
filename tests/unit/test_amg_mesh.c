/*
 * The mesh stiffness matrix (journal eq. 4, issue 17): asp_amg_decompose_mesh
 * couples only vertices that share a mesh edge, keeps the matrix invariants
 * (symmetric, zero row sums) and, on a sheet folded at 90 degrees, a coarse
 * level keeps the two faces apart.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

enum { G = 41 }; /* vertices per side of each face */

/* Face 0: z = 0, x in [-1, 0]; face 1: x = 0 ... folded up: points (0, y, z), z in [0, 1]. */
static void fold(asp_cloud **cloud, uint32_t **tris, size_t *ntris)
{
    asp_error err;
    const size_t n = 2 * (size_t)G * G;
    CHECK_OK(asp_cloud_create(n, ASP_ATTR_NORMALS, NULL, cloud, &err), &err);
    *tris = malloc((2 * 2 * (G - 1) * (G - 1) + 2 * (G - 1)) * 3 * sizeof **tris);
    *ntris = 0;
    if (!*cloud || !*tris)
        return;
    for (int f = 0; f < 2; f++)
        for (int j = 0; j < G; j++)
            for (int i = 0; i < G; i++) {
                size_t p = ((size_t)f * G + (size_t)j) * G + (size_t)i;
                double u = (double)i / (G - 1), v = (double)j / (G - 1) * 2 - 1;
                float *x = (*cloud)->positions + 3 * p, *nm = (*cloud)->normals + 3 * p;
                if (f == 0) { // the face's last column is x = -1/(G-1): the crease is the edge between the faces
                    x[0] = (float)(-1 + u * (1 - 1.0 / (G - 1)) - 0.0), x[1] = (float)v, x[2] = 0;
                    nm[2] = 1;
                } else {
                    x[0] = 0, x[1] = (float)v, x[2] = (float)(u * (1 - 1.0 / (G - 1)) + 1.0 / (G - 1));
                    nm[0] = -1;
                }
            }
    uint32_t *t = *tris;
    for (int f = 0; f < 2; f++)
        for (int j = 0; j + 1 < G; j++)
            for (int i = 0; i + 1 < G; i++) {
                uint32_t a = (uint32_t)(((size_t)f * G + (size_t)j) * G + (size_t)i), b = a + 1, c = a + G, d = c + 1;
                uint32_t tri[6] = {a, b, d, a, d, c};
                memcpy(t + 3 * *ntris, tri, sizeof tri);
                *ntris += 2;
            }
    // the strip between the faces: face 0's last column (i = G-1) to face 1's first (i = 0)
    for (int j = 0; j + 1 < G; j++) {
        uint32_t a = (uint32_t)((size_t)j * G + G - 1), c = a + G;
        uint32_t b = (uint32_t)((size_t)G * G + (size_t)j * G), d = b + G;
        uint32_t tri[6] = {a, b, d, a, d, c};
        memcpy(t + 3 * *ntris, tri, sizeof tri);
        *ntris += 2;
    }
}

static int shares_edge(const uint32_t *tris, size_t ntris, uint32_t p, uint32_t q)
{
    for (size_t t = 0; t < ntris; t++) {
        const uint32_t *v = tris + 3 * t;
        int hp = v[0] == p || v[1] == p || v[2] == p, hq = v[0] == q || v[1] == q || v[2] == q;
        if (hp && hq)
            return 1;
    }
    return 0;
}

static void test_fold(void)
{
    asp_cloud *c = NULL;
    uint32_t *tris = NULL;
    size_t ntris = 0;
    fold(&c, &tris, &ntris);
    asp_error err;
    asp_amg *amg = NULL;
    if (c && tris)
        CHECK_OK(asp_amg_decompose_mesh(c, tris, ntris, &(asp_amg_desc){.keep_matrix = 1}, NULL, &amg, &err), &err);
    if (amg) {
        const asp_amg_csr *a = asp_amg_matrix(amg);
        asp_amg_matrix_check mc;
        asp_amg_csr_check_stiffness(a, &mc);
        CHECK(mc.max_asymmetry < 1e-9 && mc.max_row_sum < 1e-9 && mc.max_offdiag <= 0);
        size_t off = 0, bad = 0;
        for (size_t r = 0; r < a->rows; r += 7) // a sample of rows: shares_edge is a linear scan
            for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
                if (a->col[k] != r && a->val[k] != 0) {
                    off++;
                    bad += !shares_edge(tris, ntris, (uint32_t)r, a->col[k]);
                }
        CHECK_MSG(off > 0 && bad == 0, "%zu of %zu sampled couplings join vertices without a mesh edge", bad, off);
        // the coarsest level with at least 2 unknowns: each strict domain lies on one face
        size_t nl = asp_amg_level_count(amg), level = nl - 1;
        while (level > 0 && asp_amg_level_size(amg, level) < 2)
            level--;
        asp_amg_csr *psi = NULL;
        CHECK_OK(asp_amg_basis(amg, level, NULL, &psi, &err), &err);
        if (psi) {
            size_t nd = psi->cols;
            size_t *cnt = calloc(2 * nd, sizeof *cnt);
            asp_index *label = malloc(psi->rows * sizeof *label);
            asp_amg_strict_domains(psi, label);
            for (size_t p = 0; p < psi->rows; p++)
                cnt[2 * label[p] + (p >= (size_t)G * G)]++;
            size_t major = 0;
            for (size_t d = 0; d < nd; d++)
                major += cnt[2 * d] > cnt[2 * d + 1] ? cnt[2 * d] : cnt[2 * d + 1];
            double purity = (double)major / (double)psi->rows;
            fprintf(stderr, "fold mesh: %zu levels, level %zu has %zu unknowns, purity %.4f\n", nl, level, nd, purity);
            CHECK_MSG(purity > 0.97, "purity %.4f", purity);
            free(cnt);
            free(label);
        }
        asp_amg_csr_destroy(psi);
    }
    asp_amg *bad_amg = NULL;
    uint32_t wrong[3] = {0, 1, 999999};
    if (c)
        CHECK(asp_amg_decompose_mesh(c, wrong, 1, NULL, NULL, &bad_amg, &err) == ASP_EINVAL && !bad_amg);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    free(tris);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_fold))
