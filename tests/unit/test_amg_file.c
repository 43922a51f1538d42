/*
 * The .amg file: a save/load round trip keeps points, classifier and every
 * level's P exactly; truncated, corrupted, foreign and missing files give a
 * clear error and no crash.
 */
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "harness.h"

static char path[512];

static size_t file_size(const char *p)
{
    FILE *fp = fopen(p, "rb");
    if (!fp)
        return 0;
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fclose(fp);
    return n < 0 ? 0 : (size_t)n;
}

static unsigned char *slurp(const char *p, size_t *n)
{
    *n = file_size(p);
    unsigned char *b = malloc(*n + 1);
    FILE *fp = fopen(p, "rb");
    if (fp) {
        if (fread(b, 1, *n, fp) != *n)
            *n = 0;
        fclose(fp);
    }
    return b;
}

static void spit(const char *p, const unsigned char *b, size_t n)
{
    FILE *fp = fopen(p, "wb");
    if (fp) {
        fwrite(b, 1, n, fp);
        fclose(fp);
    }
}

static void test_round_trip_and_damage(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    asp_amg *amg = NULL, *back = NULL;
    snprintf(path, sizeof path, "/tmp/asp_test_amg_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 3000}, NULL, &c, err), err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    if (!amg) {
        asp_cloud_destroy(c);
        return;
    }
    CHECK_OK(asp_amg_save(amg, path, err), err);
    CHECK_OK(asp_amg_load(path, NULL, &back, err), err);
    if (back) {
        size_t n = c->count;
        CHECK(asp_amg_cloud(back)->count == n);
        CHECK(memcmp(asp_amg_cloud(back)->positions, asp_amg_cloud(amg)->positions, 12 * n) == 0);
        CHECK(memcmp(asp_amg_cloud(back)->normals, asp_amg_cloud(amg)->normals, 12 * n) == 0);
        CHECK(memcmp(asp_amg_classifier(back), asp_amg_classifier(amg), 4 * n) == 0);
        CHECK(asp_amg_level_count(back) == asp_amg_level_count(amg));
        CHECK(asp_amg_matrix(back) == NULL);
        CHECK_NEAR(asp_amg_get_info(back)->epsilon, asp_amg_get_info(amg)->epsilon, 0);
        for (size_t l = 1; l < asp_amg_level_count(amg); l++) {
            const asp_amg_csr *p = asp_amg_prolongation(amg, l), *q = asp_amg_prolongation(back, l);
            CHECK(q && p->rows == q->rows && p->cols == q->cols && p->row_ptr[p->rows] == q->row_ptr[q->rows]);
            if (q && p->row_ptr[p->rows] == q->row_ptr[q->rows]) {
                CHECK(memcmp(p->col, q->col, p->row_ptr[p->rows] * sizeof *p->col) == 0);
                CHECK(memcmp(p->val, q->val, p->row_ptr[p->rows] * sizeof *p->val) == 0);
            }
        }
        /* the loaded file gives the same colours */
        uint8_t *c1 = malloc(4 * n), *c2 = malloc(4 * n);
        CHECK_OK(asp_amg_colorize(amg, ASP_AMG_COLOR_DOMAINS, 2, NULL, c1, err), err);
        CHECK_OK(asp_amg_colorize(back, ASP_AMG_COLOR_DOMAINS, 2, NULL, c2, err), err);
        CHECK(memcmp(c1, c2, 4 * n) == 0);
        free(c1);
        free(c2);
        asp_amg_destroy(back);
    }

    size_t size = 0;
    unsigned char *bytes = slurp(path, &size);
    CHECK(size > 1000);
    char bad[600];
    snprintf(bad, sizeof bad, "%s.bad", path);
    /* truncated at many places, including inside the header */
    const size_t cuts[] = {0, 5, 40, 64, 67, 100, size / 3, size / 2, size - 5, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        spit(bad, bytes, cuts[i]);
        back = NULL;
        int rc = asp_amg_load(bad, NULL, &back, err);
        CHECK_MSG(rc == ASP_EFORMAT && back == NULL, "cut at %zu: rc %d", cuts[i], rc);
        CHECK(strstr(err->msg, bad) != NULL);
        CHECK_MSG(cuts[i] < 64 + 4 || strstr(err->msg, "truncated") != NULL, "cut at %zu: %s", cuts[i], err->msg);
    }
    /* one flipped byte anywhere: the checksum catches it */
    const size_t flips[] = {70, size / 2, size - 10};
    for (size_t i = 0; i < 3; i++) {
        bytes[flips[i]] ^= 0x40;
        spit(bad, bytes, size);
        bytes[flips[i]] ^= 0x40;
        CHECK(asp_amg_load(bad, NULL, &back, err) == ASP_EFORMAT);
        CHECK_MSG(strstr(err->msg, "checksum") != NULL, "%s", err->msg);
    }
    /* a different magic / version */
    bytes[0] = 'X';
    spit(bad, bytes, size);
    CHECK(asp_amg_load(bad, NULL, &back, err) == ASP_EFORMAT);
    CHECK(strstr(err->msg, "not an .amg file") != NULL);
    bytes[0] = 'A';
    bytes[8] = 9;
    spit(bad, bytes, size);
    CHECK(asp_amg_load(bad, NULL, &back, err) == ASP_EFORMAT);
    CHECK(strstr(err->msg, "version 9") != NULL);
    /* a huge count in the header is refused before anything is allocated */
    bytes[8] = 1;
    memset(bytes + 16, 0xFF, 8);
    spit(bad, bytes, size);
    CHECK(asp_amg_load(bad, NULL, &back, err) == ASP_EFORMAT);
    free(bytes);
    CHECK(asp_amg_load("/nonexistent/dir/x.amg", NULL, &back, err) == ASP_EIO);
    CHECK(strstr(err->msg, "cannot open '/nonexistent/dir/x.amg'") != NULL);
    CHECK(asp_amg_save(amg, "/nonexistent/dir/x.amg", err) == ASP_EIO);
    remove(bad);
    remove(path);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_round_trip_and_damage))
