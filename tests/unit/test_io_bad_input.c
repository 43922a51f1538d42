/*
 * Malformed point files: every file in tests/data/bad/ must fail to load with
 * a message containing the substring listed in expected.txt (or load, where
 * it says OK); every truncation of valid binary and ascii PLY files must
 * fail cleanly; and corrupted bytes must never crash or leak.
 */
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

static void test_bad_directory(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/data/bad/expected.txt", ASP_TEST_SRC);
    FILE *f = fopen(path, "r");
    CHECK_MSG(f != NULL, "cannot open %s", path);
    if (!f)
        return;
    char line[512];
    int files = 0, good = 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n')
            continue;
        line[strcspn(line, "\r\n")] = '\0';
        char *tab = strchr(line, '\t');
        CHECK_MSG(tab != NULL, "expected.txt line without a tab: %s", line);
        if (!tab)
            continue;
        *tab = '\0';
        const char *name = line, *want = tab + 1;
        snprintf(path, sizeof path, "%s/data/bad/%s", ASP_TEST_SRC, name);
        asp_cloud *sentinel = (asp_cloud *)&files, *c = sentinel;
        asp_error err_ = {0}, *err = &err_;
        int rc = asp_cloud_load(path, NULL, &c, err);
        files++;
        if (strcmp(want, "OK") == 0) {
            CHECK_MSG(rc == 0, "%s: should load, got: %s", name, err->msg);
            if (rc == 0) {
                CHECK(c != sentinel && c->count > 0);
                asp_cloud_destroy(c);
            }
            good++;
            continue;
        }
        CHECK_MSG(rc != 0, "%s: loaded, expected failure '%s'", name, want);
        if (rc == 0) {
            asp_cloud_destroy(c);
            continue;
        }
        CHECK_MSG(c == sentinel, "%s: output changed on failure", name);
        CHECK_MSG(strstr(err->msg, want) != NULL, "%s:\n   want '%s'\n   got  '%s'", name, want, err->msg);
        CHECK_MSG(strncmp(err->msg, "cannot read '", 13) == 0 && strstr(err->msg, name), "%s: '%s'", name, err->msg);
        int want_code = strstr(name, ".abc") ? ASP_EUNSUPPORTED : ASP_EFORMAT;
        CHECK_MSG(rc == want_code, "%s: code %s, want %s", name, asp_error_name(rc), asp_error_name(want_code));
    }
    fclose(f);
    CHECK(files >= 40 && good >= 3);
}

static unsigned char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *d = malloc((size_t)n + 1);
    *size = fread(d, 1, (size_t)n, f);
    fclose(f);
    return d;
}

static asp_cloud *small_cloud(void)
{
    asp_cloud *c = NULL;
    asp_error e = {0}, *err = &e;
    CHECK_OK(asp_cloud_create(5, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, err), err);
    for (size_t i = 0; c && i < 15; i++) {
        c->positions[i] = (float)i * 0.5f - 3.0f;
        c->normals[i] = (float)(i % 3 == 2);
    }
    asp_property *p;
    CHECK_OK(asp_cloud_add_property(c, "quality", ASP_SCALAR_FLOAT64, &p, err), err);
    uint32_t tri[] = {0, 1, 2, 2, 3, 4};
    CHECK_OK(asp_cloud_set_faces(c, tri, 2, err), err);
    CHECK_OK(asp_cloud_add_comment(c, "truncation test", err), err);
    return c;
}

/* Every proper prefix of a binary file is truncated somewhere: each must fail with EFORMAT. */
static void test_truncation_at_every_byte(void)
{
    asp_cloud *c = small_cloud();
    char path[256];
    snprintf(path, sizeof path, "/tmp/asp_test_bad_%ld.ply", (long)getpid());
    static const asp_ply_encoding encs[] = {ASP_PLY_BINARY_LE, ASP_PLY_BINARY_BE, ASP_PLY_ASCII};
    for (int e = 0; e < 3; e++) {
        asp_error err_ = {0}, *err = &err_;
        CHECK_OK(asp_ply_write(c, path, &(asp_save_desc){.encoding = encs[e]}, err), err);
        size_t size = 0;
        unsigned char *d = slurp(path, &size);
        CHECK(d && size > 100);
        if (!d)
            continue;
        /* ascii can only be caught before the last line starts: a cut number is still a number */
        size_t last_line = size - 1;
        while (last_line > 0 && d[last_line - 1] != '\n')
            last_line--;
        size_t limit = encs[e] == ASP_PLY_ASCII ? last_line : size;
        int bad = 0;
        for (size_t n = 0; n < limit; n++) {
            asp_cloud *out = NULL;
            int rc = asp_ply_read_memory(d, n, "cut.ply", NULL, &out, err);
            if (rc != ASP_EFORMAT || out != NULL || strncmp(err->msg, "cannot read 'cut.ply': ", 23) != 0) {
                if (!bad++)
                    fprintf(stderr, "encoding %d, prefix %zu of %zu: rc %d '%s'\n", (int)encs[e], n, size, rc,
                            err->msg);
                asp_cloud_destroy(out);
            }
        }
        CHECK_MSG(bad == 0, "%d prefixes misbehaved", bad);
        asp_cloud *full = NULL;
        CHECK_OK(asp_ply_read_memory(d, size, "full.ply", NULL, &full, err), err);
        CHECK(full && full->count == 5 && full->face_count == 2);
        asp_cloud_destroy(full);
        free(d);
    }
    remove(path);
    asp_cloud_destroy(c);
}

/* Deterministic corruption: flipped, inserted or zeroed bytes give an error or a cloud, never a crash. */
static void test_corrupted_bytes_do_not_crash(void)
{
    asp_cloud *c = small_cloud();
    char path[256];
    snprintf(path, sizeof path, "/tmp/asp_test_bad2_%ld.ply", (long)getpid());
    asp_error err_ = {0}, *err = &err_;
    CHECK_OK(asp_ply_write(c, path, &(asp_save_desc){.encoding = ASP_PLY_BINARY_LE}, err), err);
    size_t size = 0;
    unsigned char *d = slurp(path, &size);
    CHECK(d != NULL);
    uint32_t s = 7;
    int errors = 0, loads = 0, unexplained = 0;
    for (int round = 0; d && round < 3000; round++) {
        unsigned char *m = malloc(size);
        memcpy(m, d, size);
        for (int k = 0; k < 1 + round % 4; k++) {
            s = s * 1664525u + 1013904223u;
            size_t at = (s >> 8) % size;
            m[at] = (unsigned char)(round & 1 ? s >> 24 : m[at] ^ (1u << (s % 8)));
        }
        asp_cloud *out = NULL;
        int rc = asp_ply_read_memory(m, size, "m.ply", NULL, &out, err);
        if (rc == 0) {
            loads++;
            for (size_t i = 0; i < 3 * out->face_count; i++)
                CHECK(out->faces[i] < out->count);
            asp_cloud_destroy(out);
        } else {
            errors++;
            unexplained += out != NULL || strncmp(err->msg, "cannot read 'm.ply': ", 21) != 0;
        }
        free(m);
    }
    CHECK(errors > 100 && loads > 10 && unexplained == 0);
    free(d);
    remove(path);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_bad_directory), TEST_CASE(test_truncation_at_every_byte),
          TEST_CASE(test_corrupted_bytes_do_not_crash))
