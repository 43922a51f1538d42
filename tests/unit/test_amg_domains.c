/*
 * Domains (journal eq. 8, thesis 2.5) on the synthetic models whose faces are
 * known (labels = face id): the octahedron must have a level with exactly 8
 * domains, one per face, and the cube one with 6, with at least 98% of each
 * face's points having their largest Psi in that face's domain (journal
 * Fig. 1c, 5c). Also: thresholded domains against Psi, and level names.
 */
#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "harness.h"

/* Finds a level with exactly `faces` unknowns whose strict domains match the faces; returns the worst purity. */
static double face_purity(asp_synth_shape shape, size_t faces, size_t *level_out)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    asp_amg *amg = NULL;
    double result = -1;
    CHECK_OK(asp_synth(shape, NULL, NULL, &c, err), err);
    if (!c)
        return -1;
    CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    for (size_t l = 0; amg && l < asp_amg_level_count(amg); l++) {
        if (asp_amg_level_size(amg, l) != faces)
            continue;
        asp_amg_csr *psi = NULL;
        CHECK_OK(asp_amg_basis(amg, l, NULL, &psi, err), err);
        if (!psi)
            break;
        asp_index *label = malloc(c->count * sizeof *label);
        asp_amg_strict_domains(psi, label);
        size_t count[8][8] = {{0}};
        for (size_t i = 0; i < c->count; i++)
            count[c->labels[i]][label[i]]++;
        /* each face's majority domain, distinct across faces, holding >= 98% of the face */
        double worst = 1;
        unsigned used = 0;
        for (size_t f = 0; f < faces; f++) {
            size_t best = 0, total = 0, arg = 0;
            for (size_t d = 0; d < faces; d++) {
                total += count[f][d];
                if (count[f][d] > best) {
                    best = count[f][d];
                    arg = d;
                }
            }
            CHECK_MSG(!(used & (1u << arg)), "face %zu shares domain %zu with another face", f, arg);
            used |= 1u << arg;
            worst = fmin(worst, (double)best / (double)total);
        }
        /* thresholded domains (tau = 0.05) cover every point and are a superset of the strict ones */
        asp_amg_csr *dom = NULL;
        CHECK_OK(asp_amg_domains(psi, 0.05, NULL, &dom, err), err);
        if (dom) {
            CHECK(dom->rows == faces && dom->cols == c->count);
            unsigned char *seen = calloc(c->count, 1);
            for (size_t d = 0; d < dom->rows; d++)
                for (size_t k = dom->row_ptr[d]; k < dom->row_ptr[d + 1]; k++) {
                    CHECK(dom->val[k] > 0.05);
                    if (label[dom->col[k]] == d)
                        seen[dom->col[k]] = 1;
                }
            size_t covered = 0;
            for (size_t i = 0; i < c->count; i++)
                covered += seen[i];
            CHECK(covered == c->count); /* the strict winner always exceeds 1/faces > 0.05 */
            free(seen);
            asp_amg_csr_destroy(dom);
        }
        free(label);
        asp_amg_csr_destroy(psi);
        result = worst;
        *level_out = l;
        break;
    }
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    return result;
}

static void test_octahedron_faces(void)
{
    size_t level = 0;
    double p = face_purity(ASP_SYNTH_OCTAHEDRON, 8, &level);
    fprintf(stderr, "octahedron: level %zu has 8 domains, worst face purity %.4f\n", level, p);
    CHECK_MSG(p >= 0.98, "no level with 8 face domains of >= 98%% purity (got %g)", p);
}

static void test_cube_faces(void)
{
    size_t level = 0;
    double p = face_purity(ASP_SYNTH_CUBE, 6, &level);
    fprintf(stderr, "cube: level %zu has 6 domains, worst face purity %.4f\n", level, p);
    CHECK_MSG(p >= 0.98, "no level with 6 face domains of >= 98%% purity (got %g)", p);
}

static void test_domains_small(void)
{
    /* hand-made Psi: 3 points, 2 functions */
    asp_error errbuf, *err = &errbuf;
    asp_amg_csr *psi = NULL, *d = NULL;
    CHECK_OK(asp_amg_csr_create(3, 2, 4, NULL, &psi, err), err);
    if (!psi)
        return;
    size_t rp[4] = {0, 1, 3, 4};
    asp_index col[4] = {0, 0, 1, 1};
    double val[4] = {1.0, 0.5, 0.5, 1.0};
    memcpy(psi->row_ptr, rp, sizeof rp);
    memcpy(psi->col, col, sizeof col);
    memcpy(psi->val, val, sizeof val);
    CHECK_OK(asp_amg_domains(psi, 0.05, NULL, &d, err), err);
    if (d) {
        CHECK(d->rows == 2 && d->row_ptr[1] == 2 && d->row_ptr[2] == 4);
        CHECK(d->col[0] == 0 && d->col[1] == 1 && d->col[2] == 1 && d->col[3] == 2);
        asp_amg_csr_destroy(d);
    }
    d = NULL;
    CHECK_OK(asp_amg_domains(psi, 0.5, NULL, &d, err), err); /* strictly greater: the 0.5 entries drop out */
    if (d) {
        CHECK(d->row_ptr[2] == 2);
        asp_amg_csr_destroy(d);
    }
    CHECK(asp_amg_domains(psi, 1.0, NULL, &d, err) == ASP_EINVAL);
    CHECK(asp_amg_domains(psi, -0.1, NULL, &d, err) == ASP_EINVAL);
    CHECK(strstr(err->msg, "threshold") != NULL);
    asp_index label[3];
    asp_amg_strict_domains(psi, label);
    CHECK(label[0] == 0 && label[1] == 0 && label[2] == 1); /* tie at point 1: the smaller index */
    asp_amg_csr_destroy(psi);
}

static void test_level_names(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    asp_amg *amg = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 3000}, NULL, &c, err), err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    if (amg) {
        size_t top = asp_amg_level_count(amg) - 1, l = 999;
        CHECK(top >= 5);
        CHECK_OK(asp_amg_level_parse(amg, "L", &l, err), err);
        CHECK(l == top);
        CHECK_OK(asp_amg_level_parse(amg, "L-3", &l, err), err);
        CHECK(l == top - 3);
        CHECK_OK(asp_amg_level_parse(amg, "2", &l, err), err);
        CHECK(l == 2);
        CHECK_OK(asp_amg_level_parse(amg, "L-0", &l, err), err);
        CHECK(l == top);
        CHECK(asp_amg_level_parse(amg, "L-99", &l, err) == ASP_EINVAL);
        CHECK(strstr(err->msg, "L-99") != NULL);
        CHECK(asp_amg_level_parse(amg, "99", &l, err) == ASP_EINVAL);
        CHECK(asp_amg_level_parse(amg, "L+1", &l, err) == ASP_EINVAL);
        CHECK(asp_amg_level_parse(amg, "", &l, err) == ASP_EINVAL);
        CHECK(asp_amg_level_parse(amg, "3x", &l, err) == ASP_EINVAL);
        CHECK(l == top); /* unchanged on failure */
    }
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_octahedron_faces), TEST_CASE(test_cube_faces), TEST_CASE(test_domains_small),
          TEST_CASE(test_level_names))
