/*
 * The decomposition does not depend on the order of the input points
 * (issue 19): it numbers them along the Morton curve (src/amg/morton.c), the
 * numbering of the distributed decomposition. The same torus in its own order
 * and shuffled gives the same levels, and per point the same classifier,
 * tangent normal, row of P^1 and row of A^0 (columns mapped), bit for bit,
 * returned in each input's own order. Before, RS coarsening took its C points
 * in the input order and the shuffled torus gave other level sizes.
 */
#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "harness.h"

/* A copy of c with point i moved to perm[i] (positions, normals, colours, radii). */
static asp_cloud *shuffled(const asp_cloud *c, const size_t *perm)
{
    asp_cloud *s = NULL;
    asp_error err;
    if (asp_cloud_create(c->count, asp_cloud_attrs(c), NULL, &s, &err) != 0)
        return NULL;
    for (size_t i = 0; i < c->count; i++) {
        const size_t j = perm[i];
        memcpy(s->positions + 3 * j, c->positions + 3 * i, 3 * sizeof(float));
        if (c->normals)
            memcpy(s->normals + 3 * j, c->normals + 3 * i, 3 * sizeof(float));
        if (c->colors)
            memcpy(s->colors + 4 * j, c->colors + 4 * i, 4);
        if (c->radii)
            s->radii[j] = c->radii[i];
    }
    return s;
}

/* Row r of a and row perm[r] of b hold the same values at columns mapped by cmap (NULL: the same columns). */
static int same_row(const asp_amg_csr *a, size_t r, const asp_amg_csr *b, size_t rb, const size_t *cmap)
{
    size_t na = a->row_ptr[r + 1] - a->row_ptr[r], nb = b->row_ptr[rb + 1] - b->row_ptr[rb];
    if (na != nb)
        return 0;
    for (size_t k = a->row_ptr[r]; k < a->row_ptr[r + 1]; k++) {
        size_t want = cmap ? cmap[a->col[k]] : a->col[k];
        int found = 0;
        for (size_t q = b->row_ptr[rb]; q < b->row_ptr[rb + 1] && !found; q++)
            found = b->col[q] == want && b->val[q] == a->val[k];
        if (!found)
            return 0;
    }
    return 1;
}

static void test_shuffled_torus(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL, *s = NULL;
    asp_amg *a = NULL, *b = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_TORUS, &(asp_synth_desc){.points = 9000}, NULL, &c, err), err);
    if (!c)
        return;
    const size_t n = c->count;
    size_t *perm = malloc(n * sizeof *perm);
    for (size_t i = 0; i < n; i++)
        perm[i] = i;
    uint64_t x = 88172645463325252ull; /* xorshift: a fixed shuffle */
    for (size_t i = n - 1; i > 0; i--) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        size_t j = (size_t)(x % (i + 1)), t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    s = shuffled(c, perm);
    CHECK(s != NULL);
    const asp_amg_desc desc = {.keep_matrix = 1};
    CHECK_OK(asp_amg_decompose(c, &desc, NULL, &a, err), err);
    if (s)
        CHECK_OK(asp_amg_decompose(s, &desc, NULL, &b, err), err);
    if (a && b) {
        size_t nl = asp_amg_level_count(a);
        CHECK_MSG(nl == asp_amg_level_count(b), "levels %zu and %zu", nl, asp_amg_level_count(b));
        fprintf(stderr, "torus, %zu points, %zu levels:", n, nl);
        for (size_t l = 0; l < nl && l < asp_amg_level_count(b); l++) {
            fprintf(stderr, " %zu/%zu", asp_amg_level_size(a, l), asp_amg_level_size(b, l));
            CHECK(asp_amg_level_size(a, l) == asp_amg_level_size(b, l));
        }
        fprintf(stderr, "\n");
        size_t bad_cls = 0, bad_tan = 0, bad_p = 0, bad_a = 0;
        const asp_amg_csr *p1a = asp_amg_prolongation(a, 1), *p1b = asp_amg_prolongation(b, 1);
        const asp_amg_csr *ma = asp_amg_matrix(a), *mb = asp_amg_matrix(b);
        CHECK(p1a && p1b && ma && mb);
        for (size_t i = 0; i < n; i++) {
            const size_t j = perm[i];
            bad_cls += asp_amg_classifier(a)[i] != asp_amg_classifier(b)[j];
            bad_tan += memcmp(asp_amg_tangent_normals(a) + 3 * i, asp_amg_tangent_normals(b) + 3 * j, 12) != 0;
            if (p1a && p1b)
                bad_p += !same_row(p1a, i, p1b, j, NULL);
            if (ma && mb)
                bad_a += !same_row(ma, i, mb, j, perm);
        }
        CHECK_MSG(bad_cls == 0 && bad_tan == 0 && bad_p == 0 && bad_a == 0,
                  "points that differ: classifier %zu, tangent %zu, P^1 row %zu, A row %zu", bad_cls, bad_tan, bad_p,
                  bad_a);
        /* the result keeps each input's own order */
        CHECK(memcmp(asp_amg_cloud(b)->positions, s->positions, 12 * n) == 0);
    }
    asp_amg_destroy(a);
    asp_amg_destroy(b);
    asp_cloud_destroy(c);
    asp_cloud_destroy(s);
    free(perm);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_shuffled_torus))
