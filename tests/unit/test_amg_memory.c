/*
 * The decomposition's memory (issue 19): freed arrays go back to the system
 * although libsuperlu_dist (linked through hypre) turns glibc's mmap and trim
 * off at load time, and the library's own allocations stay within the
 * per-point budget at every stage (a counting allocator in the context, as
 * bench_decompose --mem measures them), less when the cloud is handed over.
 */
#include <stdatomic.h>

#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/sample.h"
#include "harness.h"

/* AddressSanitizer's allocator keeps freed blocks in quarantine: the RSS check means nothing there */
#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif
#if !defined(UNDER_ASAN) && defined(__linux__) && defined(__GLIBC__)
#define CHECK_RSS 1
#endif

#ifdef CHECK_RSS
/* VmRSS of this process in KiB, or -1 where /proc is not there. */
static long rss_kb(void)
{
    char line[256];
    long kb = -1;
    FILE *fp = fopen("/proc/self/status", "r");
    if (!fp)
        return -1;
    while (fgets(line, sizeof line, fp))
        if (strncmp(line, "VmRSS:", 6) == 0)
            kb = atol(line + 6);
    fclose(fp);
    return kb;
}
#endif

/* A freed 256 MiB array leaves the resident set (before the fix it stayed: mmap off, trim off). */
static void test_free_returns(void)
{
#ifdef CHECK_RSS
    const size_t size = (size_t)256 << 20;
    long before = rss_kb();
    char *p = malloc(size);
    CHECK(p != NULL);
    if (!p || before < 0)
        return;
    for (size_t i = 0; i < size; i += 4096)
        ((volatile char *)p)[i] = 1; // every page, through volatile so the stores stay
    long held = rss_kb();
    free(p);
    long after = rss_kb();
    fprintf(stderr, "RSS: %ld KiB before, %ld with 256 MiB, %ld after free\n", before, held, after);
    CHECK(held - before > 200 * 1024);
    CHECK_MSG(after - before < 32 * 1024, "%ld KiB still resident after free", after - before);
#else
    fprintf(stderr, "not glibc on Linux, or under AddressSanitizer: nothing to check\n");
    asp_test_skips++; // reported as skipped, not passed
#endif
}

typedef struct counter {
    atomic_size_t live, peak;
} counter;

enum { HDR = 64 };

static void *count_alloc(void *user, size_t size, size_t alignment)
{
    counter *c = user;
    (void)alignment;
    char *b = aligned_alloc(HDR, (size + 2 * HDR - 1) / HDR * HDR);
    if (!b)
        return NULL;
    memcpy(b, &size, sizeof size);
    size_t now = atomic_fetch_add(&c->live, size) + size, old = atomic_load(&c->peak);
    while (now > old && !atomic_compare_exchange_weak(&c->peak, &old, now))
        ;
    return b + HDR;
}

static void count_free(void *user, void *ptr)
{
    counter *c = user;
    char *b = (char *)ptr - HDR;
    size_t size;
    memcpy(&size, b, sizeof size);
    atomic_fetch_sub(&c->live, size);
    free(b);
}

/*
 * 200,000 bunny points: the library's peak, the input cloud included, stays
 * under 400 bytes per point (measured 372 at 1M, in the neighbour search; it
 * was 778 in the assembly before issue 19) and nothing is left after destroy.
 */
static void test_budget(void)
{
    static counter c;
    asp_context ctx = {.allocator = {count_alloc, count_free, &c}};
    asp_error errbuf, *err = &errbuf;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    if (asp_mesh_load(ASP_TEST_DATA "/stanford-bunny.obj", NULL, NULL, &mesh, err) != 0) {
        fprintf(stderr, "SKIP: %s\n", err->msg);
        asp_test_skips++;
        return;
    }
    const size_t n = 200000;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = n}, &ctx, &cloud, NULL, err),
             err);
    asp_mesh_destroy(mesh);
    if (!cloud)
        return;
    asp_cloud *given = NULL;
    CHECK_OK(asp_cloud_clone(cloud, &given, err), err);
    atomic_store(&c.peak, atomic_load(&c.live));
    asp_amg *amg = NULL;
    CHECK_OK(asp_amg_decompose(cloud, NULL, &ctx, &amg, err), err);
    double peak = (double)(atomic_load(&c.peak) - (given ? 28 * n : 0)) / (double)n; /* less the clone */
    fprintf(stderr, "library peak %.1f bytes/point over %zu points\n", peak, n);
    CHECK_MSG(peak < 400, "library peak %.1f bytes/point", peak);
    CHECK(amg && asp_amg_matrix(amg) == NULL); /* A^0 is not kept unless asked (keep_matrix) */
    asp_cloud_destroy(cloud);
    /* handing the cloud over: no copy of the points, the same hierarchy to the bit */
    if (given) {
        asp_amg *took = NULL;
        atomic_store(&c.peak, atomic_load(&c.live));
        size_t base = atomic_load(&c.live) - 28 * n; /* the result above is live; the given cloud counts */
        CHECK_OK(asp_amg_decompose_take(&given, NULL, &ctx, &took, err), err);
        CHECK(given == NULL);
        double peak_take = (double)(atomic_load(&c.peak) - base) / (double)n;
        fprintf(stderr, "library peak with the cloud handed over %.1f bytes/point\n", peak_take);
        CHECK_MSG(peak_take < peak - 20, "%.1f bytes/point handed over, %.1f copied", peak_take, peak);
        if (amg && took) {
            CHECK(asp_amg_level_count(amg) == asp_amg_level_count(took));
            CHECK(memcmp(asp_amg_classifier(amg), asp_amg_classifier(took), n * sizeof(float)) == 0);
            for (size_t l = 1; l < asp_amg_level_count(amg) && l < asp_amg_level_count(took); l++) {
                const asp_amg_csr *p1 = asp_amg_prolongation(amg, l), *p2 = asp_amg_prolongation(took, l);
                CHECK(p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows]);
                if (p1->row_ptr[p1->rows] == p2->row_ptr[p2->rows])
                    CHECK(memcmp(p1->val, p2->val, p1->row_ptr[p1->rows] * sizeof *p1->val) == 0);
            }
        }
        asp_amg_destroy(took);
    }
    asp_amg_destroy(amg);
    CHECK_MSG(atomic_load(&c.live) == 0, "%zu bytes still allocated", (size_t)atomic_load(&c.live));
}

/* A refused cloud is destroyed, and the pointer cleared, as documented. */
static void test_take_refused(void)
{
    asp_cloud *two = NULL;
    asp_error err;
    CHECK_OK(asp_cloud_create(2, 0, NULL, &two, &err), &err);
    asp_amg *amg = NULL;
    CHECK(asp_amg_decompose_take(&two, NULL, NULL, &amg, &err) == ASP_EDEGENERATE);
    CHECK(two == NULL && amg == NULL);
}

static void shutdown(void) { asp_amg_shutdown(); }

TEST_MAIN(TEST_CASE(test_free_returns), TEST_CASE(test_budget), TEST_CASE(test_take_refused), TEST_FIXTURE(shutdown))
