/*
 * The .amg file: a save/load round trip keeps the whole point set (positions,
 * origin, normals, colours, radii, uvs, labels), tangent normals, classifier
 * and every level's P exactly; truncated, corrupted, foreign, old-version and
 * missing files give a clear error and no crash. asp_amg_load_memory gives the
 * same result as the path loader, and a cut at every byte or a forged count
 * (with the CRC fixed so the parser sees it) fails cleanly without a large
 * allocation.
 */
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/sample.h"
#include "file_forge.h"
#include "harness.h"

static char path[512];

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
    if (c) {
        /* every attribute the file must keep, with a far origin (UTM-like) and uvs the synth does not make */
        CHECK_OK(asp_cloud_add_attrs(c, ASP_ATTR_UVS, err), err);
        for (size_t i = 0; i < c->count; i++) {
            c->uvs[2 * i] = (float)i / 7.0f;
            c->uvs[2 * i + 1] = -(float)i / 3.0f;
        }
        c->origin[0] = 512345.25;
        c->origin[1] = -5.5e6;
        c->origin[2] = 0.125;
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    }
    if (!amg) {
        asp_cloud_destroy(c);
        return;
    }
    CHECK_OK(asp_amg_save(amg, path, err), err);
    CHECK_OK(asp_amg_load(path, NULL, &back, err), err);
    if (back) {
        size_t n = c->count;
        CHECK(asp_amg_cloud(back)->count == n);
        const asp_cloud *b = asp_amg_cloud(back);
        CHECK(memcmp(b->origin, c->origin, sizeof c->origin) == 0);
        /* the recorded frame comes back bit for bit, and it is the source points' frame */
        asp_frame want;
        CHECK_OK(asp_cloud_frame(c, &want, err), err);
        CHECK(asp_amg_frame(amg)->radius > 0 && memcmp(asp_amg_frame(amg), &want, sizeof want) == 0);
        CHECK(memcmp(asp_amg_frame(back), asp_amg_frame(amg), sizeof want) == 0);
        CHECK(memcmp(b->positions, c->positions, 12 * n) == 0);
        /* the input had normals: they are kept, not replaced by the unoriented tangent normals */
        CHECK(asp_amg_has_input_normals(amg) && asp_amg_has_input_normals(back));
        CHECK(memcmp(asp_amg_cloud(amg)->normals, c->normals, 12 * n) == 0);
        CHECK(b->normals && memcmp(b->normals, c->normals, 12 * n) == 0);
        CHECK(b->colors && memcmp(b->colors, c->colors, 4 * n) == 0);
        CHECK(b->radii && memcmp(b->radii, c->radii, 4 * n) == 0);
        CHECK(b->uvs && memcmp(b->uvs, c->uvs, 8 * n) == 0);
        CHECK(b->labels && memcmp(b->labels, c->labels, 4 * n) == 0);
        CHECK(asp_cloud_attrs(b) == asp_cloud_attrs(asp_amg_cloud(amg)));
        CHECK(memcmp(asp_amg_tangent_normals(back), asp_amg_tangent_normals(amg), 12 * n) == 0);
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
    unsigned char *bytes = forge_slurp(path, &size);
    CHECK(size > 1000);
    char bad[600];
    snprintf(bad, sizeof bad, "%s.bad", path);
    /* truncated at many places, including inside the header */
    const size_t cuts[] = {0, 5, 40, 64, 67, 90, 100, size / 3, size / 2, size - 5, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        spit(bad, bytes, cuts[i]);
        back = NULL;
        int rc = asp_amg_load(bad, NULL, &back, err);
        CHECK_MSG(rc == ASP_EFORMAT && back == NULL, "cut at %zu: rc %d", cuts[i], rc);
        CHECK(strstr(err->msg, bad) != NULL);
        CHECK_MSG(cuts[i] < 96 + 4 || strstr(err->msg, "truncated") != NULL, "cut at %zu: %s", cuts[i], err->msg);
    }
    /* one flipped byte anywhere: the checksum catches it */
    const size_t flips[] = {70, 100, size / 2, size - 10};
    for (size_t i = 0; i < 4; i++) {
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
    /* version 1 (no point attributes) names the remedy */
    bytes[8] = 1;
    spit(bad, bytes, size);
    CHECK(asp_amg_load(bad, NULL, &back, err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err->msg, "version 1") != NULL && strstr(err->msg, "decompose") != NULL, "%s", err->msg);
    /* a huge count in the header is refused before anything is allocated */
    bytes[8] = 3;
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
}

/* asp_amg_load_memory for file_forge.h: *out goes in and comes back, so an unchanged sentinel shows. */
static int load_amg(const void *data, size_t size, const char *name, const asp_context *ctx, void **out, asp_error *err)
{
    asp_amg *a = *out;
    int rc = asp_amg_load_memory(data, size, name, ctx, &a, err);
    *out = a;
    return rc;
}

static void destroy_amg(void *a)
{
    asp_amg_destroy(a);
}

static const forge_format amg_format = {"amg", 32, load_amg, destroy_amg}; /* payload size at header byte 32 */

static int same_amg(const asp_amg *x, const asp_amg *y)
{
    const asp_cloud *a = asp_amg_cloud(x), *b = asp_amg_cloud(y);
    size_t n = a->count;
    int ok = b->count == n && asp_cloud_attrs(a) == asp_cloud_attrs(b) && !memcmp(a->origin, b->origin, 24) &&
             !memcmp(a->positions, b->positions, 12 * n) && !memcmp(a->normals, b->normals, 12 * n) &&
             (!a->colors || !memcmp(a->colors, b->colors, 4 * n)) &&
             !memcmp(asp_amg_tangent_normals(x), asp_amg_tangent_normals(y), 12 * n) &&
             !memcmp(asp_amg_classifier(x), asp_amg_classifier(y), 4 * n) &&
             asp_amg_has_input_normals(x) == asp_amg_has_input_normals(y) &&
             asp_amg_level_count(x) == asp_amg_level_count(y) &&
             asp_amg_get_info(x)->epsilon == asp_amg_get_info(y)->epsilon;
    for (size_t l = 0; ok && l < asp_amg_level_count(x); l++)
        ok = asp_amg_level_size(x, l) == asp_amg_level_size(y, l);
    for (size_t l = 1; ok && l < asp_amg_level_count(x); l++) {
        const asp_amg_csr *p = asp_amg_prolongation(x, l), *q = asp_amg_prolongation(y, l);
        size_t nnz = p->row_ptr[p->rows];
        ok = p->rows == q->rows && p->cols == q->cols &&
             !memcmp(p->row_ptr, q->row_ptr, (p->rows + 1) * sizeof(size_t)) &&
             !memcmp(p->col, q->col, nnz * sizeof *p->col) && !memcmp(p->val, q->val, nnz * sizeof *p->val);
    }
    return ok;
}

/* A small decomposition (60 points) loaded from memory and from its path; every cut and forged count. */
static void test_memory_cuts_and_forged_counts(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    asp_amg *amg = NULL;
    char p3[600];
    snprintf(p3, sizeof p3, "/tmp/asp_test_amg_mem_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 60}, NULL, &c, err), err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    if (!amg) {
        asp_cloud_destroy(c);
        return;
    }
    CHECK_OK(asp_amg_save(amg, p3, err), err);
    size_t size = 0;
    unsigned char *bytes = forge_slurp(p3, &size);
    CHECK(size > 68 && size < 20000);
    asp_amg *from_path = NULL, *from_mem = NULL;
    CHECK_OK(asp_amg_load(p3, NULL, &from_path, err), err);
    CHECK_OK(asp_amg_load_memory(bytes, size, p3, NULL, &from_mem, err), err);
    CHECK(from_path && from_mem && same_amg(from_path, from_mem) && same_amg(amg, from_mem));
    asp_amg_destroy(from_path);
    asp_amg_destroy(from_mem);

    forge_expect_cuts_fail(&amg_format, bytes, size);
    CHECK(asp_amg_load_memory(NULL, 0, NULL, NULL, &from_mem, err) == ASP_EFORMAT && strstr(err->msg, "<memory>"));

    /* forged counts behind a valid checksum */
    const uint64_t n = forge_get_le(bytes + 16, 8), nlevels = forge_get_le(bytes + 24, 8);
    const uint32_t attrs = (uint32_t)forge_get_le(bytes + 96 + 28 * n, 4);
    const uint64_t per_point = (attrs & ASP_ATTR_NORMALS ? 12u : 0u) + (attrs & ASP_ATTR_COLORS ? 4u : 0u) +
                               (attrs & ASP_ATTR_RADII ? 4u : 0u) + (attrs & ASP_ATTR_UVS ? 8u : 0u) +
                               (attrs & ASP_ATTR_LABELS ? 4u : 0u);
    const size_t nnz_at = (size_t)(96 + 28 * n + 8 + per_point * n + 128 + 8 * nlevels);
    CHECK(nlevels >= 2 && nnz_at + 8 < size);
    const struct {
        size_t at;
        uint64_t value;
        const char *field;
    } forged[] = {{16, 1ull << 40, "point count"},        {16, 0, "point count"},
                  {24, 1ull << 40, "level count"},        {nnz_at, 1ull << 60, "prolongation entry count"},
                  {nnz_at, (uint64_t)size / 12, "prolongation entry count"},
                  {nnz_at + 8 + 8 * n, 1ull << 62, "row pointer"},
                  {nnz_at + 8 + 8, (uint64_t)size, "row pointer"}}; /* row 0 would run past the entries */
    for (size_t i = 0; i < sizeof forged / sizeof forged[0]; i++)
        forge_expect_refused(&amg_format, bytes, size, forged[i].at, forged[i].value, 8, forged[i].field);
    /* a recorded frame that is not finite or has a negative radius names the field and its byte (64) */
    const double nan = strtod("nan", NULL), minus_one = -1;
    uint64_t nan_bits, minus_bits;
    memcpy(&nan_bits, &nan, 8);
    memcpy(&minus_bits, &minus_one, 8);
    forge_expect_refused(&amg_format, bytes, size, 88, minus_bits, 8, "byte 64: frame");
    forge_expect_refused(&amg_format, bytes, size, 72, nan_bits, 8, "byte 64: frame");
    free(bytes);
    remove(p3);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
}

/*
 * A version-2 file (64-byte header, no frame), forged from a version-3 one by
 * cutting the frame out: it still loads, its frame computed from the points
 * as decompose computes it, so it equals the recorded one bit for bit.
 */
static void test_version_2_without_frame(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *c = NULL;
    asp_amg *amg = NULL, *back = NULL;
    char p4[600];
    snprintf(p4, sizeof p4, "/tmp/asp_test_amg_v2_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 400}, NULL, &c, err), err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    if (!amg) {
        asp_cloud_destroy(c);
        return;
    }
    CHECK_OK(asp_amg_save(amg, p4, err), err);
    size_t size = 0;
    unsigned char *v3 = forge_slurp(p4, &size);
    CHECK(v3 && size > 100 && forge_get_le(v3 + 8, 4) == 3 && forge_get_le(v3 + 12, 4) == 96);
    if (v3 && size > 100) {
        unsigned char *v2 = malloc(size - 32);
        memcpy(v2, v3, 64);
        memcpy(v2 + 64, v3 + 96, size - 96);
        forge_put_le(v2 + 8, 2, 4);
        forge_put_le(v2 + 12, 64, 4);
        forge_fix_header(v2, size - 32, 32, 64);
        CHECK_OK(asp_amg_load_memory(v2, size - 32, "v2.amg", NULL, &back, err), err);
        if (back) {
            CHECK(asp_amg_frame(back)->radius > 0);
            CHECK(memcmp(asp_amg_frame(back), asp_amg_frame(amg), sizeof(asp_frame)) == 0);
            CHECK(same_amg(amg, back));
            asp_amg_destroy(back);
        }
        /* a version-2 header size on a version-3 file is refused */
        forge_put_le(v3 + 12, 64, 4);
        forge_fix(v3, size, 32);
        back = NULL;
        CHECK(asp_amg_load_memory(v3, size, "v3.amg", NULL, &back, err) == ASP_EFORMAT && back == NULL);
        CHECK_MSG(strstr(err->msg, "header size") != NULL, "%s", err->msg);
        free(v2);
    }
    free(v3);
    remove(p4);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
}

/* An input without normals or colours: the file stays small and the normals are the tangent ones. */
static void test_bare_positions(void)
{
    asp_error errbuf, *err = &errbuf;
    asp_cloud *full = NULL, *c = NULL;
    asp_amg *amg = NULL, *back = NULL;
    char p2[600];
    snprintf(p2, sizeof p2, "/tmp/asp_test_amg_bare_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_CUBE, &(asp_synth_desc){.points = 1200}, NULL, &full, err), err);
    if (!full)
        return;
    CHECK_OK(asp_cloud_create(full->count, 0, NULL, &c, err), err);
    if (c) {
        memcpy(c->positions, full->positions, 12 * full->count);
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, err), err);
    }
    if (amg) {
        const size_t n = c->count;
        CHECK(!asp_amg_has_input_normals(amg));
        CHECK(asp_cloud_attrs(asp_amg_cloud(amg)) == ASP_ATTR_NORMALS);
        CHECK(memcmp(asp_amg_cloud(amg)->normals, asp_amg_tangent_normals(amg), 12 * n) == 0);
        CHECK_OK(asp_amg_save(amg, p2, err), err);
        CHECK_OK(asp_amg_load(p2, NULL, &back, err), err);
        if (back) {
            const asp_cloud *b = asp_amg_cloud(back);
            CHECK(!asp_amg_has_input_normals(back));
            CHECK(asp_cloud_attrs(b) == ASP_ATTR_NORMALS);
            CHECK(!b->colors && !b->radii && !b->uvs && !b->labels);
            CHECK(memcmp(b->positions, c->positions, 12 * n) == 0);
            CHECK(memcmp(b->normals, asp_amg_tangent_normals(amg), 12 * n) == 0);
            /* no attribute arrays: header, 7 floats per point, the attribute set, options, levels, P, CRC */
            size_t expect = 96 + 28 * n + 8 + 128 + 8 * asp_amg_level_count(amg) + 4;
            for (size_t l = 1; l < asp_amg_level_count(amg); l++) {
                const asp_amg_csr *p = asp_amg_prolongation(amg, l);
                expect += 8 + 8 * (p->rows + 1) + 12 * p->row_ptr[p->rows];
            }
            CHECK_MSG(forge_file_size(p2) == expect, "size %zu, expected %zu", forge_file_size(p2), expect);
            asp_amg_destroy(back);
        }
    }
    remove(p2);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    asp_cloud_destroy(full);
    asp_amg_shutdown(); /* last test: MPI cannot start again in this process */
}

TEST_MAIN(TEST_CASE(test_round_trip_and_damage), TEST_CASE(test_memory_cuts_and_forged_counts),
          TEST_CASE(test_version_2_without_frame), TEST_CASE(test_bare_positions))
