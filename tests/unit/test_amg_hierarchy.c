/*
 * The stiffness matrix (journal eq. 5-7) and the AMG hierarchy (journal 2.3)
 * on the test models: A symmetric with zero row sums and non-positive
 * off-diagonals; every P^l and every basis Psi^l a partition of unity with
 * values in [0,1]; deterministic for any thread count; disconnected parts
 * stay apart. Prints the levels and per-level reduction factors.
 */
#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/sample.h"
#include "harness.h"

static asp_cloud *sample_model(const char *name, size_t points)
{
    char buf[1024];
    const char *path = asp_test_data(buf, sizeof buf, name);
    if (!path)
        return NULL;
    asp_error errbuf, *err = &errbuf;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    CHECK_OK(asp_mesh_load(path, NULL, NULL, &mesh, err), err);
    if (!mesh)
        return NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = points}, NULL, &cloud, NULL,
                             err),
             err);
    asp_mesh_destroy(mesh);
    return cloud;
}

static void check_matrix(const char *name, const asp_amg *amg)
{
    const asp_amg_csr *a = asp_amg_matrix(amg);
    asp_amg_matrix_check mc;
    asp_amg_csr_check_stiffness(a, &mc);
    /* scale: the largest diagonal entry */
    double scale = 0;
    for (size_t r = 0; r < a->rows; r++)
        for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++)
            if (a->col[k] == r && a->val[k] > scale)
                scale = a->val[k];
    CHECK_MSG(mc.max_asymmetry <= 1e-12 * scale, "%s: asymmetry %g", name, mc.max_asymmetry);
    CHECK_MSG(mc.max_row_sum <= 1e-10 * scale, "%s: row sum %g (scale %g)", name, mc.max_row_sum, scale);
    CHECK_MSG(mc.max_offdiag <= 0, "%s: positive off-diagonal %g", name, mc.max_offdiag);
    CHECK_MSG(mc.min_diag >= 0, "%s: negative diagonal %g", name, mc.min_diag);
    for (size_t r = 1; r < a->rows; r++)
        for (size_t k = a->row_ptr[r] + 1; k < a->row_ptr[r + 1]; k++)
            CHECK(a->col[k] > a->col[k - 1]);
}

/* Every P^l and Psi^l: rows sum to 1, values in [0,1]; returns the number of levels. */
static size_t check_levels(const char *name, const asp_amg *amg)
{
    asp_error errbuf, *err = &errbuf;
    size_t nl = asp_amg_level_count(amg), n = asp_amg_cloud(amg)->count;
    CHECK(nl >= 2);
    CHECK(asp_amg_level_size(amg, 0) == n);
    fprintf(stderr, "%s: %zu points, %zu levels:", name, n, nl);
    for (size_t l = 1; l < nl; l++) {
        const asp_amg_csr *p = asp_amg_prolongation(amg, l);
        CHECK(p && p->rows == asp_amg_level_size(amg, l - 1) && p->cols == asp_amg_level_size(amg, l));
        CHECK(asp_amg_level_size(amg, l) < asp_amg_level_size(amg, l - 1));
        double worst = 0, lo = 1, hi = 0;
        for (size_t r = 0; r < p->rows; r++) {
            double s = 0;
            for (size_t k = p->row_ptr[r]; k < p->row_ptr[r + 1]; k++) {
                s += p->val[k];
                lo = fmin(lo, p->val[k]);
                hi = fmax(hi, p->val[k]);
            }
            worst = fmax(worst, fabs(s - 1));
        }
        CHECK_MSG(worst < 1e-12 && lo >= 0 && hi <= 1, "%s: P^%zu rows off by %g, values [%g, %g]", name, l, worst, lo,
                  hi);
        fprintf(stderr, " %zu (/%.2f)", asp_amg_level_size(amg, l),
                (double)asp_amg_level_size(amg, l - 1) / (double)asp_amg_level_size(amg, l));
    }
    fprintf(stderr, "\n");
    CHECK(asp_amg_prolongation(amg, 0) == NULL && asp_amg_prolongation(amg, nl) == NULL);
    asp_amg_level_stats st[128];
    CHECK_OK(asp_amg_level_stats_all(amg, 0.05, NULL, st, err), err);
    for (size_t l = 0; l < nl; l++) {
        CHECK_MSG(st[l].max_pou_error < 1e-6, "%s level %zu: max |sum Psi - 1| = %g", name, l, st[l].max_pou_error);
        CHECK(st[l].unknowns == asp_amg_level_size(amg, l));
        CHECK(st[l].domains >= 1 && st[l].domains <= st[l].unknowns);
        CHECK(st[l].mean_domains_per_point >= 1.0 - 1e-12);
    }
    /* the direct basis of one middle level agrees: values in [0,1], rows sum to 1 */
    asp_amg_csr *psi = NULL;
    size_t mid = nl / 2;
    CHECK_OK(asp_amg_basis(amg, mid, NULL, &psi, err), err);
    if (psi) {
        double worst = 0;
        for (size_t r = 0; r < psi->rows; r++) {
            double s = 0;
            for (size_t k = psi->row_ptr[r]; k < psi->row_ptr[r + 1]; k++) {
                s += psi->val[k];
                CHECK(psi->val[k] >= 0 && psi->val[k] <= 1);
            }
            worst = fmax(worst, fabs(s - 1));
        }
        CHECK(worst < 1e-6);
        asp_amg_csr_destroy(psi);
    }
    CHECK(asp_amg_basis(amg, nl, NULL, &psi, err) == ASP_EINVAL);
    return nl;
}

static void run_model(const char *name, asp_cloud *cloud)
{
    if (!cloud)
        return;
    asp_error errbuf, *err = &errbuf;
    asp_amg *amg = NULL;
    CHECK_OK(asp_amg_decompose(cloud, &(asp_amg_desc){.keep_matrix = 1}, NULL, &amg, err), err);
    if (amg) {
        const asp_amg_info *in = asp_amg_get_info(amg);
        fprintf(stderr, "%s: epsilon %g, |N| %.1f, fan %.2f, %zu positive off-diagonals clamped, %zu isolated\n", name,
                in->epsilon, in->mean_neighbourhood, in->mean_fan, in->positive_offdiag, in->isolated_points);
        CHECK(in->mean_fan > 4.5 && in->mean_fan < 7.5); /* a surface's Delaunay fans have about 6 triangles */
        check_matrix(name, amg);
        check_levels(name, amg);
    }
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
}

static void test_bunny(void) { run_model("bunny", sample_model("stanford-bunny.obj", 12000)); }
static void test_fandisk(void) { run_model("fandisk", sample_model("fandisk.obj", 12000)); }
static void test_cow(void) { run_model("cow", sample_model("cow.obj", 12000)); }

static void test_octahedron(void)
{
    asp_cloud *c = NULL;
    asp_error errbuf, *err = &errbuf;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, NULL, NULL, &c, err), err);
    run_model("octahedron", c);
}

/* Two octahedra far apart: no coupling between them, no domain may span both. */
static void test_disconnected(void)
{
    asp_cloud *a = NULL, *two = NULL;
    asp_error errbuf, *err = &errbuf;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 4000}, NULL, &a, err), err);
    if (!a)
        return;
    CHECK_OK(asp_cloud_create(2 * a->count, 0, NULL, &two, err), err);
    for (size_t i = 0; i < a->count; i++)
        for (int k = 0; k < 3; k++) {
            two->positions[3 * i + k] = a->positions[3 * i + k];
            two->positions[3 * (a->count + i) + k] = a->positions[3 * i + k] + (k == 0 ? 10.0f : 0.0f);
        }
    asp_amg *amg = NULL;
    CHECK_OK(asp_amg_decompose(two, &(asp_amg_desc){.keep_matrix = 1}, NULL, &amg, err), err);
    if (amg) {
        check_matrix("two octahedra", amg);
        const asp_amg_csr *m = asp_amg_matrix(amg);
        for (size_t r = 0; r < m->rows; r++)
            for (size_t k = m->row_ptr[r]; k < m->row_ptr[r + 1]; k++)
                CHECK((r < a->count) == (m->col[k] < a->count));
        size_t nl = check_levels("two octahedra", amg);
        CHECK(asp_amg_level_size(amg, nl - 1) >= 2);
        asp_amg_csr *psi = NULL;
        CHECK_OK(asp_amg_basis(amg, nl - 1, NULL, &psi, err), err);
        if (psi) {
            /* no basis function of the coarsest level touches both parts */
            unsigned char *side = calloc(psi->cols, 1);
            for (size_t r = 0; r < psi->rows; r++)
                for (size_t k = psi->row_ptr[r]; k < psi->row_ptr[r + 1]; k++)
                    side[psi->col[k]] |= r < a->count ? 1 : 2;
            for (size_t c = 0; c < psi->cols; c++)
                CHECK(side[c] == 1 || side[c] == 2);
            free(side);
            asp_amg_csr_destroy(psi);
        }
    }
    asp_amg_destroy(amg);
    asp_cloud_destroy(a);
    asp_cloud_destroy(two);
}

/* Bit-identical hierarchy for 1 and 2 threads. */
static void test_threads(void)
{
    asp_cloud *c = NULL;
    asp_error errbuf, *err = &errbuf;
    CHECK_OK(asp_synth(ASP_SYNTH_CUBE, &(asp_synth_desc){.points = 6000}, NULL, &c, err), err);
    if (!c)
        return;
    asp_amg *one = NULL, *two = NULL;
    CHECK_OK(asp_amg_decompose(c, &(asp_amg_desc){.keep_matrix = 1}, &(asp_context){.threads = 1}, &one, err), err);
    CHECK_OK(asp_amg_decompose(c, &(asp_amg_desc){.keep_matrix = 1}, &(asp_context){.threads = 2}, &two, err), err);
    if (one && two) {
        const asp_amg_csr *a1 = asp_amg_matrix(one), *a2 = asp_amg_matrix(two);
        CHECK(a1->row_ptr[a1->rows] == a2->row_ptr[a2->rows]);
        if (a1->row_ptr[a1->rows] == a2->row_ptr[a2->rows]) {
            CHECK(memcmp(a1->col, a2->col, a1->row_ptr[a1->rows] * sizeof *a1->col) == 0);
            CHECK(memcmp(a1->val, a2->val, a1->row_ptr[a1->rows] * sizeof *a1->val) == 0);
        }
        CHECK(memcmp(asp_amg_classifier(one), asp_amg_classifier(two), c->count * sizeof(float)) == 0);
        CHECK(asp_amg_level_count(one) == asp_amg_level_count(two));
        for (size_t l = 1; l < asp_amg_level_count(one) && l < asp_amg_level_count(two); l++) {
            const asp_amg_csr *p1 = asp_amg_prolongation(one, l), *p2 = asp_amg_prolongation(two, l);
            CHECK(p1->cols == p2->cols && p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows]);
            if (p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows])
                CHECK(memcmp(p1->val, p2->val, p1->row_ptr[p1->rows] * sizeof *p1->val) == 0);
        }
    }
    /* the default frees A^0 and F^0 inside the hierarchy (issue 19): the same hierarchy, no matrix kept */
    asp_amg *lean = NULL;
    CHECK_OK(asp_amg_decompose(c, NULL, &(asp_context){.threads = 2}, &lean, err), err);
    if (one && lean) {
        CHECK(asp_amg_matrix(lean) == NULL);
        CHECK(asp_amg_get_info(lean)->matrix_nnz == asp_amg_matrix(one)->row_ptr[c->count]);
        CHECK(asp_amg_level_count(one) == asp_amg_level_count(lean));
        for (size_t l = 1; l < asp_amg_level_count(one) && l < asp_amg_level_count(lean); l++) {
            const asp_amg_csr *p1 = asp_amg_prolongation(one, l), *p2 = asp_amg_prolongation(lean, l);
            CHECK(p1->cols == p2->cols && p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows]);
            if (p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows]) {
                CHECK(memcmp(p1->col, p2->col, p1->row_ptr[p1->rows] * sizeof *p1->col) == 0);
                CHECK(memcmp(p1->val, p2->val, p1->row_ptr[p1->rows] * sizeof *p1->val) == 0);
            }
        }
    }
    asp_amg_destroy(lean);
    asp_amg_destroy(one);
    asp_amg_destroy(two);
    asp_cloud_destroy(c);
}

static void shutdown(void) { asp_amg_shutdown(); }

TEST_MAIN(TEST_CASE(test_octahedron), TEST_CASE(test_bunny), TEST_CASE(test_fandisk), TEST_CASE(test_cow),
          TEST_CASE(test_disconnected), TEST_CASE(test_threads), TEST_FIXTURE(shutdown))
