/*
 * On-disk hierarchy: exact round trip, and every kind of damage rejected with
 * a clear error (truncation at any length, flipped payload or header bytes,
 * bad magic, newer version, a consistent checksum over an inconsistent tree).
 */
#include <stdint.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/hier.h"
#include "harness.h"

static char tmpdir[512];

static void path_of(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", tmpdir, name);
}

static asp_cloud *small_cloud(size_t n)
{
    asp_cloud *c = NULL;
    asp_cloud_create(n, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, NULL);
    uint64_t s = 12345;
    for (size_t i = 0; i < 3 * n; i++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        c->positions[i] = (float)((s >> 33) % 10000) / 1000.0f;
    }
    for (size_t i = 0; i < n; i++) {
        c->normals[3 * i + 2] = 1;
        c->colors[4 * i] = (uint8_t)i;
        c->colors[4 * i + 3] = 255;
    }
    c->origin[0] = 1e6;
    c->origin[2] = -3.5;
    return c;
}

static uint8_t *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)n + 1);
    *size = fread(b, 1, (size_t)n, f);
    fclose(f);
    return b;
}

static uint64_t fnv(const uint8_t *p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ULL;
    }
    return h;
}

static void put64le(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put32le(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* recompute both checksums, as a forger would */
static void reseal(uint8_t *b, size_t size)
{
    put64le(b + 88, fnv(b + 128, size - 128));
    put64le(b + 120, fnv(b, 120));
}

static int same(const asp_hier *a, const asp_hier *b)
{
    size_t nn = asp_hier_node_count(a), np = asp_hier_point_count(a);
    double oa[3], ob[3];
    asp_hier_origin(a, oa);
    asp_hier_origin(b, ob);
    return nn == asp_hier_node_count(b) && np == asp_hier_point_count(b) && asp_hier_depth(a) == asp_hier_depth(b) &&
           asp_hier_flags(a) == asp_hier_flags(b) && asp_hier_leaf_size(a) == asp_hier_leaf_size(b) &&
           memcmp(oa, ob, sizeof oa) == 0 &&
           memcmp(asp_hier_nodes(a), asp_hier_nodes(b), nn * sizeof(asp_hier_node)) == 0 &&
           memcmp(asp_hier_splats(a), asp_hier_splats(b), (nn + np) * sizeof(asp_hier_splat)) == 0 &&
           memcmp(asp_hier_covariances(a), asp_hier_covariances(b), nn * 10 * sizeof(double)) == 0;
}

static asp_hier *built;
static uint8_t *image;
static size_t image_size;

static void test_round_trip(void)
{
    asp_cloud *cl = small_cloud(3000);
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_build(cl, &(asp_hier_desc){.leaf_size = 5}, NULL, &built, err), err);
    char path[600];
    path_of(path, sizeof path, "a.asph");
    CHECK_OK(asp_hier_save(built, path, err), err);
    asp_hier *back = NULL;
    CHECK_OK(asp_hier_load(path, NULL, &back, err), err);
    CHECK(back && same(built, back));
    image = read_all(path, &image_size);
    CHECK(image && image_size == 128 + asp_hier_node_count(built) * (48 + 64 + 80) + 3000 * 64);
    CHECK(image && memcmp(image, "ASPHIER", 8) == 0);
    /* the same bytes through memory */
    asp_hier *mem = NULL;
    CHECK_OK(asp_hier_load_memory(image, image_size, "mem", NULL, &mem, err), err);
    CHECK(mem && same(built, mem));
    asp_hier_destroy(mem);
    asp_hier_destroy(back);
    asp_cloud_destroy(cl);
}

static int load_bytes(const uint8_t *b, size_t n, asp_error *err)
{
    asp_hier *h = NULL;
    int rc = asp_hier_load_memory(b, n, "x.asph", NULL, &h, err);
    asp_hier_destroy(h);
    return rc;
}

static void test_truncated(void)
{
    if (!image)
        return;
    size_t bad = 0, vague = 0;
    asp_error err;
    /* every header length, then a spread of payload lengths */
    for (size_t n = 0; n < image_size; n = n < 200 ? n + 1 : n + image_size / 97 + 1) {
        memset(&err, 0, sizeof err);
        if (load_bytes(image, n, &err) != ASP_EFORMAT)
            bad++;
        else if (!strstr(err.msg, "x.asph") || (!strstr(err.msg, "truncated") && !strstr(err.msg, "magic")))
            vague++;
    }
    CHECK_MSG(bad == 0, "%zu truncations not rejected", bad);
    CHECK_MSG(vague == 0, "%zu truncation messages without file name or cause (last: %s)", vague, err.msg);
    /* a file on disk truncated: names the size */
    char path[600];
    path_of(path, sizeof path, "short.asph");
    FILE *f = fopen(path, "wb");
    fwrite(image, 1, image_size - 10, f);
    fclose(f);
    asp_hier *h = NULL;
    memset(&err, 0, sizeof err);
    CHECK(asp_hier_load(path, NULL, &h, &err) == ASP_EFORMAT && h == NULL);
    CHECK(strstr(err.msg, "truncated") != NULL);
    /* and a trailing byte is rejected too */
    uint8_t *longer = malloc(image_size + 1);
    memcpy(longer, image, image_size);
    longer[image_size] = 0;
    CHECK(load_bytes(longer, image_size + 1, &err) == ASP_EFORMAT);
    free(longer);
}

static void test_corrupted(void)
{
    if (!image)
        return;
    uint8_t *b = malloc(image_size);
    asp_error err;
    size_t bad = 0;
    /* any flipped byte: header or payload checksum catches it */
    for (size_t at = 0; at < image_size; at += at < 128 ? 1 : image_size / 211 + 1) {
        memcpy(b, image, image_size);
        b[at] ^= 0x20;
        memset(&err, 0, sizeof err);
        int rc = load_bytes(b, image_size, &err);
        if (rc != ASP_EFORMAT && !(rc == ASP_EUNSUPPORTED && at >= 8 && at < 12))
            bad++;
    }
    CHECK_MSG(bad == 0, "%zu flipped bytes not rejected", bad);
    memcpy(b, image, image_size);
    b[200] ^= 1;
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "checksum"));
    memcpy(b, image, image_size);
    b[0] = 'X';
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "magic"));
    /* a newer version, properly sealed */
    memcpy(b, image, image_size);
    b[8] = 2;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EUNSUPPORTED && strstr(err.msg, "version 2"));
    /* huge counts with a valid header checksum: refused before allocating */
    memcpy(b, image, image_size);
    put64le(b + 32, 1ULL << 40);
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT);
    free(b);
}

static void test_inconsistent_tree(void)
{
    if (!image || !built)
        return;
    uint8_t *b = malloc(image_size);
    asp_error err;
    size_t nn = asp_hier_node_count(built);
    /* node 0's first_child (bytes 24-27 of the record) pointing past the end */
    memcpy(b, image, image_size);
    put32le(b + 128 + 24, (uint32_t)nn + 5);
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "node 0"));
    /* a child that claims another parent */
    uint32_t c = asp_hier_nodes(built)[0].first_child;
    memcpy(b, image, image_size);
    b[128 + 48 * (size_t)c + 20] ^= 1;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "invalid hierarchy"));
    /* a NaN ellipse axis in a point splat */
    memcpy(b, image, image_size);
    size_t at = 128 + 48 * nn + 64 * (nn + 3) + 44;
    b[at] = 0xff;
    b[at + 1] = 0xff;
    b[at + 2] = 0xc0;
    b[at + 3] = 0x7f;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "point 3"));
    free(b);
}

static void test_io_errors(void)
{
    asp_hier *h = NULL;
    asp_error err = {0};
    char path[600];
    path_of(path, sizeof path, "missing.asph");
    CHECK(asp_hier_load(path, NULL, &h, &err) == ASP_EIO && h == NULL);
    CHECK(strstr(err.msg, "missing.asph") != NULL);
    CHECK(load_bytes(NULL, 0, &err) == ASP_EFORMAT);
    if (built) {
        path_of(path, sizeof path, "no/such/dir/x.asph");
        CHECK(asp_hier_save(built, path, &err) == ASP_EIO);
    }
}

static void cleanup(void)
{
    asp_hier_destroy(built);
    free(image);
}

int main(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/asp_hier_file_%ld", base ? base : "/tmp", (long)getpid());
    mkdir(tmpdir, 0700);
    static const asp_test_case cases[] = {TEST_CASE(test_round_trip), TEST_CASE(test_truncated),
                                          TEST_CASE(test_corrupted), TEST_CASE(test_inconsistent_tree),
                                          TEST_CASE(test_io_errors)};
    int rc = asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
    cleanup();
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
    return rc;
}
