/*
 * kd-tree k-NN and radius queries against brute force: uniform, clustered,
 * duplicated and all-equal point sets, ties, tiny sets, strided input, thread
 * count independence, every asp_knn_all path (grouped scan, its fallbacks,
 * per-query search), the parallel build and malformed input.
 */
#include <stdint.h>

#include "amgsplat/geom.h"
#include "geom/kdtree_internal.h"
#include "harness.h"

static uint64_t rng_state = 88172645463325252ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

enum set_kind { SET_UNIFORM, SET_CLUSTERED, SET_DUPLICATES, SET_GRID, SET_EQUAL };

static float *make_set(enum set_kind kind, size_t n)
{
    float *p = malloc(3 * n * sizeof(float) + 1);
    for (size_t i = 0; i < n; i++) {
        float *x = p + 3 * i;
        switch (kind) {
        case SET_UNIFORM:
            for (int a = 0; a < 3; a++)
                x[a] = (float)(urand() * 2.0 - 1.0);
            break;
        case SET_CLUSTERED: {
            /* five tight clusters of very different scales */
            int c = (int)(urand() * 5);
            double s = c == 0 ? 1e-4 : c == 1 ? 1e-2 : 0.1;
            for (int a = 0; a < 3; a++)
                x[a] = (float)(c * 3.0 + (urand() - 0.5) * s);
            break;
        }
        case SET_DUPLICATES: {
            /* only 37 distinct positions */
            int c = (int)(urand() * 37);
            x[0] = (float)(c % 5);
            x[1] = (float)(c / 5 % 3) * 0.5f;
            x[2] = (float)c * 0.01f;
            break;
        }
        case SET_GRID:
            /* integer lattice: many exactly equal distances */
            x[0] = (float)(i % 7);
            x[1] = (float)(i / 7 % 7);
            x[2] = (float)(i / 49);
            break;
        case SET_EQUAL:
            x[0] = 0.25f;
            x[1] = -3.0f;
            x[2] = 7.5f;
            break;
        }
    }
    return p;
}

typedef struct pair {
    float d;
    asp_index i;
} pair;

static int cmp_pair(const void *a, const void *b)
{
    const pair *x = a, *y = b;
    if (x->d != y->d)
        return x->d < y->d ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

/* Brute force sorted by (distance, index), skipping index skip; the same float expression as the tree. */
static size_t brute(const float *p, size_t n, const float q[3], size_t skip, pair *out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (i == skip)
            continue;
        float dx = p[3 * i] - q[0], dy = p[3 * i + 1] - q[1], dz = p[3 * i + 2] - q[2];
        out[m++] = (pair){dx * dx + dy * dy + dz * dz, (asp_index)i};
    }
    qsort(out, m, sizeof(pair), cmp_pair);
    return m;
}

static int same_knn(const pair *ref, size_t m, const asp_index *idx, const float *d)
{
    for (size_t j = 0; j < m; j++)
        if (ref[j].i != idx[j] || (d && ref[j].d != d[j]))
            return 0;
    return 1;
}

static void check_set(enum set_kind kind, size_t n, const char *name)
{
    asp_error err_storage = {0}, *err = &err_storage;
    float *p = make_set(kind, n);
    asp_kdtree *t = NULL;
    CHECK_OK(asp_kdtree_create(p, n, 12, NULL, &t, err), err);
    if (!t) {
        free(p);
        return;
    }
    CHECK(asp_kdtree_count(t) == n);
    pair *ref = malloc((n + 1) * sizeof(pair));
    const size_t ks[] = {1, 2, 7, 16, 64, n, n + 5};
    asp_index idx[512];
    float d[512];
    int bad = 0;
    for (int qi = 0; qi < 60; qi++) {
        float q[3];
        if (qi % 2 == 0) {
            size_t s = (size_t)(urand() * (double)n);
            for (int a = 0; a < 3; a++)
                q[a] = p[3 * s + a];
        } else {
            for (int a = 0; a < 3; a++)
                q[a] = (float)(urand() * 16.0 - 4.0);
        }
        size_t m = brute(p, n, q, SIZE_MAX, ref);
        for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
            size_t k = ks[ki] > 512 ? 512 : ks[ki];
            size_t want = k < m ? k : m;
            size_t got = asp_kdtree_knn(t, q, k, idx, d);
            if (got != want || !same_knn(ref, want, idx, d))
                bad++;
            /* without distances too */
            got = asp_kdtree_knn(t, q, k, idx, NULL);
            if (got != want || !same_knn(ref, want, idx, NULL))
                bad++;
        }
        /* radius query: radius at the 10th neighbour, small capacity then full */
        float r = sqrtf(ref[m < 10 ? m - 1 : 9].d) * 1.0001f;
        size_t inside = 0;
        while (inside < m && ref[inside].d <= r * r)
            inside++;
        size_t total = asp_kdtree_radius(t, q, r, idx, d, 3);
        if (total != inside || !same_knn(ref, inside < 3 ? inside : 3, idx, d))
            bad++;
        size_t cap = inside < 512 ? inside : 512;
        total = asp_kdtree_radius(t, q, r, idx, NULL, cap);
        if (total != inside || !same_knn(ref, cap, idx, NULL))
            bad++;
        if (asp_kdtree_radius(t, q, r, NULL, NULL, 0) != inside)
            bad++;
    }
    CHECK_MSG(bad == 0, "%s: %d single queries differ from brute force", name, bad);

    /* all points, one and two threads */
    size_t k = n > 9 ? 9 : n - 1;
    if (k > 0) {
        asp_index *all1 = malloc(n * k * sizeof(asp_index)), *all2 = malloc(n * k * sizeof(asp_index));
        float *d1 = malloc(n * k * sizeof(float)), *d2 = malloc(n * k * sizeof(float));
        CHECK_OK(asp_knn_all(t, k, all1, d1, &(asp_context){.threads = 1}, err), err);
        CHECK_OK(asp_knn_all(t, k, all2, NULL, &(asp_context){.threads = 2}, err), err);
        CHECK(memcmp(all1, all2, n * k * sizeof(asp_index)) == 0);
        int bad_all = 0;
        for (size_t i = 0; i < n; i += (n > 400 ? 7 : 1)) {
            size_t m = brute(p, n, p + 3 * i, i, ref);
            if (m < k || !same_knn(ref, k, all1 + i * k, d1 + i * k))
                bad_all++;
        }
        CHECK_MSG(bad_all == 0, "%s: %d knn_all rows differ from brute force", name, bad_all);
        /* every internal path must give the same bits as the default */
        const asp__knn_tuning paths[] = {
            {.tree_only = 1},            /* one tree search per query */
            {.group_max = 1},            /* groups are single leaves */
            {.group_max = 4000},         /* one group for the whole set */
            {.cand_max = 1},             /* every gather overflows */
            {.reach = 1e-3},             /* gathers too small: queries fall back */
            {.guess = 1e-3f},            /* first scans too small: second scans */
            {.guess = 100.0f, .reach = 4.0}, /* first scans take everything */
        };
        for (size_t pi = 0; pi < sizeof paths / sizeof paths[0]; pi++) {
            CHECK_OK(asp__knn_all_tuned(t, k, all2, d2, &paths[pi], &(asp_context){.threads = 2}, err), err);
            CHECK_MSG(memcmp(all1, all2, n * k * sizeof(asp_index)) == 0 && memcmp(d1, d2, n * k * sizeof(float)) == 0,
                      "%s: knn_all path %zu differs", name, pi);
        }
        free(all1);
        free(all2);
        free(d1);
        free(d2);
    }
    /* k = 64 (or n - 1): the selection and sorting sizes of real use */
    size_t k64 = n > 65 ? 64 : n - 1;
    if (k64 > 0) {
        asp_index *all = malloc(n * k64 * sizeof(asp_index));
        float *dd = malloc(n * k64 * sizeof(float));
        CHECK_OK(asp_knn_all(t, k64, all, dd, &(asp_context){.threads = 2}, err), err);
        int bad64 = 0;
        for (size_t i = 0; i < n; i += (n > 400 ? 13 : 1)) {
            size_t m = brute(p, n, p + 3 * i, i, ref);
            if (m < k64 || !same_knn(ref, k64, all + i * k64, dd + i * k64))
                bad64++;
        }
        CHECK_MSG(bad64 == 0, "%s: %d knn_all rows (k = %zu) differ from brute force", name, bad64, k64);
        free(all);
        free(dd);
    }
    asp_kdtree_destroy(t);
    free(ref);
    free(p);
}

static void test_uniform(void)
{
    check_set(SET_UNIFORM, 3000, "uniform");
    check_set(SET_UNIFORM, 13, "uniform-13");
}
static void test_clustered(void) { check_set(SET_CLUSTERED, 2500, "clustered"); }
static void test_duplicates(void) { check_set(SET_DUPLICATES, 2000, "duplicates"); }
static void test_grid_ties(void) { check_set(SET_GRID, 7 * 7 * 9, "grid"); }
static void test_all_equal(void) { check_set(SET_EQUAL, 1500, "equal"); }
static void test_tiny(void)
{
    check_set(SET_UNIFORM, 1, "n=1");
    check_set(SET_UNIFORM, 2, "n=2");
    check_set(SET_UNIFORM, 5, "n=5");
}

/* Many equal points must neither hang nor recurse deeply: 200k copies, k = 16. */
static void test_large_equal(void)
{
    size_t n = 200000, k = 16;
    float *p = make_set(SET_EQUAL, n);
    asp_kdtree *t = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    double t0 = asp_time_now();
    CHECK_OK(asp_kdtree_create(p, n, 12, NULL, &t, err), err);
    asp_index *idx = malloc(n * k * sizeof(asp_index));
    CHECK_OK(asp_knn_all(t, k, idx, NULL, NULL, err), err);
    double dt = asp_time_now() - t0;
    CHECK_MSG(dt < 10.0, "took %.1f s", dt);
    /* all distances tie: neighbours are the k smallest other indices */
    int bad = 0;
    for (size_t i = 0; i < n; i += 997)
        for (size_t j = 0, want = 0; j < k; j++, want++) {
            if (want == i)
                want++;
            bad += idx[i * k + j] != want;
        }
    CHECK(bad == 0);
    free(idx);
    asp_kdtree_destroy(t);
    free(p);
}

/* Half the points on one spot, half spread: mixed degenerate and regular cells. */
static void test_half_equal(void)
{
    size_t n = 4000;
    float *p = make_set(SET_UNIFORM, n);
    for (size_t i = 0; i < n; i += 2)
        p[3 * i] = p[3 * i + 1] = p[3 * i + 2] = 0.5f;
    asp_kdtree *t = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    CHECK_OK(asp_kdtree_create(p, n, 12, NULL, &t, err), err);
    size_t k = 5;
    asp_index *idx = malloc(n * k * sizeof(asp_index));
    pair *ref = malloc(n * sizeof(pair));
    CHECK_OK(asp_knn_all(t, k, idx, NULL, NULL, err), err);
    int bad = 0;
    for (size_t i = 0; i < n; i += 3) {
        brute(p, n, p + 3 * i, i, ref);
        bad += !same_knn(ref, k, idx + i * k, NULL);
    }
    CHECK(bad == 0);
    free(ref);
    free(idx);
    asp_kdtree_destroy(t);
    free(p);
}

/* Large k: single queries sort more keys than the distribution sort handles at once. */
static void test_large_k(void)
{
    size_t n = 3000, k = 1500;
    float *p = make_set(SET_CLUSTERED, n);
    asp_kdtree *t = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    CHECK_OK(asp_kdtree_create(p, n, 12, NULL, &t, err), err);
    pair *ref = malloc(n * sizeof(pair));
    asp_index *idx = malloc(k * sizeof(asp_index));
    float *d = malloc(k * sizeof(float));
    int bad = 0;
    for (int qi = 0; qi < 5; qi++) {
        const float *q = p + 3 * (size_t)(qi * 577);
        brute(p, n, q, SIZE_MAX, ref);
        bad += asp_kdtree_knn(t, q, k, idx, d) != k || !same_knn(ref, k, idx, d);
    }
    CHECK(bad == 0);
    /* all points with k = 300: grouped path with long rows */
    size_t ka = 300;
    asp_index *all = malloc(n * ka * sizeof(asp_index));
    CHECK_OK(asp_knn_all(t, ka, all, NULL, &(asp_context){.threads = 2}, err), err);
    bad = 0;
    for (size_t i = 0; i < n; i += 61) {
        brute(p, n, p + 3 * i, i, ref);
        bad += !same_knn(ref, ka, all + i * ka, NULL);
    }
    CHECK(bad == 0);
    free(all);
    free(idx);
    free(d);
    free(ref);
    asp_kdtree_destroy(t);
    free(p);
}

/*
 * Above 65536 points the tree's top levels are split serially and the
 * subtrees built in parallel: the tree, hence every answer, must not depend
 * on the thread count, and must match brute force. Surface-like data (a
 * sphere) with a block of duplicates, as users have.
 */
static void test_parallel_build(void)
{
    size_t n = 70000, k = 16;
    float *p = make_set(SET_UNIFORM, n);
    for (size_t i = 0; i < n; i++) {
        float *x = p + 3 * i;
        float r = sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        for (int a = 0; a < 3 && r > 0.0f; a++)
            x[a] /= r;
        if (i % 10 == 3) /* duplicates of a few positions */
            memcpy(x, p + 3 * (i % 50), 3 * sizeof(float));
    }
    asp_kdtree *t1 = NULL, *t2 = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    CHECK_OK(asp_kdtree_create(p, n, 12, &(asp_context){.threads = 1}, &t1, err), err);
    CHECK_OK(asp_kdtree_create(p, n, 12, &(asp_context){.threads = 2}, &t2, err), err);
    asp_index *a1 = malloc(n * k * sizeof(asp_index)), *a2 = malloc(n * k * sizeof(asp_index));
    float *d1 = malloc(n * k * sizeof(float)), *d2 = malloc(n * k * sizeof(float));
    CHECK_OK(asp_knn_all(t1, k, a1, d1, &(asp_context){.threads = 1}, err), err);
    CHECK_OK(asp_knn_all(t2, k, a2, d2, &(asp_context){.threads = 2}, err), err);
    CHECK(memcmp(a1, a2, n * k * sizeof(asp_index)) == 0);
    CHECK(memcmp(d1, d2, n * k * sizeof(float)) == 0);
    pair *ref = malloc(n * sizeof(pair));
    int bad = 0;
    for (size_t i = 0; i < n; i += 1999) {
        brute(p, n, p + 3 * i, i, ref);
        bad += !same_knn(ref, k, a2 + i * k, d2 + i * k);
    }
    CHECK(bad == 0);
    float q[3] = {0.3f, -0.2f, 0.9f};
    asp_index i1[64], i2[64];
    CHECK(asp_kdtree_knn(t1, q, 64, i1, NULL) == 64 && asp_kdtree_knn(t2, q, 64, i2, NULL) == 64);
    CHECK(memcmp(i1, i2, sizeof i1) == 0);
    free(ref);
    free(a1);
    free(a2);
    free(d1);
    free(d2);
    asp_kdtree_destroy(t1);
    asp_kdtree_destroy(t2);
    free(p);
}

static void test_stride(void)
{
    size_t n = 500;
    float *packed = make_set(SET_UNIFORM, n);
    float *wide = malloc(n * 5 * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        memcpy(wide + 5 * i, packed + 3 * i, 3 * sizeof(float));
        wide[5 * i + 3] = NAN; /* other attributes: must be ignored */
        wide[5 * i + 4] = -1.0f;
    }
    asp_kdtree *a = NULL, *b = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    CHECK_OK(asp_kdtree_create(packed, n, 12, NULL, &a, err), err);
    CHECK_OK(asp_kdtree_create(wide, n, 20, NULL, &b, err), err);
    asp_index ia[8], ib[8];
    float q[3] = {0.1f, 0.2f, -0.3f};
    CHECK(asp_kdtree_knn(a, q, 8, ia, NULL) == 8);
    CHECK(asp_kdtree_knn(b, q, 8, ib, NULL) == 8);
    CHECK(memcmp(ia, ib, sizeof ia) == 0);
    asp_kdtree_destroy(a);
    asp_kdtree_destroy(b);
    free(packed);
    free(wide);
}

static void test_errors(void)
{
    asp_error err_storage = {0}, *err = &err_storage;
    asp_kdtree *t = NULL;
    float p[9] = {0, 0, 0, 1, 1, 1, 2, NAN, 2};
    CHECK(asp_kdtree_create(p, 0, 12, NULL, &t, err) == ASP_EINVAL);
    CHECK(t == NULL);
    CHECK(asp_kdtree_create(p, 3, 12, NULL, &t, err) == ASP_EINVAL);
    CHECK(t == NULL);
    CHECK_MSG(strstr(err->msg, "point 2") && strstr(err->msg, "coordinate y"), "%s", err->msg);
    CHECK(asp_kdtree_create(p, 2, 8, NULL, &t, err) == ASP_EINVAL);
    CHECK(asp_kdtree_create(NULL, 2, 12, NULL, &t, err) == ASP_EINVAL);
    CHECK(asp_kdtree_create(p, 2, 12, NULL, NULL, err) == ASP_EINVAL);
    CHECK_OK(asp_kdtree_create(p, 2, 12, NULL, &t, err), err);
    asp_index idx[4];
    CHECK(asp_knn_all(t, 2, idx, NULL, NULL, err) == ASP_EINVAL);
    CHECK_MSG(strstr(err->msg, "k must be"), "%s", err->msg);
    CHECK(asp_knn_all(t, 0, idx, NULL, NULL, err) == ASP_EINVAL);
    CHECK_OK(asp_knn_all(t, 1, idx, NULL, NULL, err), err);
    CHECK(idx[0] == 1 && idx[1] == 0);
    float q[3] = {0, 0, 0};
    CHECK(asp_kdtree_knn(t, q, 0, idx, NULL) == 0);
    CHECK(asp_kdtree_radius(t, q, -1.0f, idx, NULL, 4) == 0);
    CHECK(asp_kdtree_radius(t, q, 0.0f, idx, NULL, 4) == 1 && idx[0] == 0);
    asp_kdtree_destroy(t);
    asp_kdtree_destroy(NULL);
}

static int cancel_cb(void *user, const char *stage, double f)
{
    (void)stage;
    (void)f;
    (*(int *)user)++;
    return 1;
}

static void test_cancel(void)
{
    size_t n = 70000;
    float *p = make_set(SET_UNIFORM, n);
    asp_kdtree *t = NULL;
    asp_error err_storage = {0}, *err = &err_storage;
    CHECK_OK(asp_kdtree_create(p, n, 12, NULL, &t, err), err);
    asp_index *idx = malloc(n * 4 * sizeof(asp_index));
    int calls = 0;
    asp_context ctx = {.progress = cancel_cb, .progress_user = &calls};
    CHECK(asp_knn_all(t, 4, idx, NULL, &ctx, err) == ASP_ECANCELED);
    CHECK(calls == 1);
    free(idx);
    asp_kdtree_destroy(t);
    free(p);
}

TEST_MAIN(TEST_CASE(test_uniform), TEST_CASE(test_clustered), TEST_CASE(test_duplicates),
          TEST_CASE(test_grid_ties), TEST_CASE(test_all_equal), TEST_CASE(test_tiny), TEST_CASE(test_large_equal),
          TEST_CASE(test_half_equal), TEST_CASE(test_large_k), TEST_CASE(test_parallel_build), TEST_CASE(test_stride), TEST_CASE(test_errors), TEST_CASE(test_cancel))
