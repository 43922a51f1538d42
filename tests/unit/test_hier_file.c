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
#include "util/checksum.h"

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

/* recompute both checksums, as a forger would, for a header of hsize bytes (160; 128 in version 1) */
static void reseal_header(uint8_t *b, size_t size, size_t hsize)
{
    put64le(b + 88, asp__fnv1a64(ASP__FNV1A64_START, b + hsize, size - hsize));
    put64le(b + hsize - 8, asp__fnv1a64(ASP__FNV1A64_START, b, hsize - 8));
}

static void reseal(uint8_t *b, size_t size)
{
    reseal_header(b, size, 160);
}

static int same(const asp_hier *a, const asp_hier *b)
{
    size_t nn = asp_hier_node_count(a), np = asp_hier_point_count(a);
    double oa[3], ob[3];
    asp_hier_origin(a, oa);
    asp_hier_origin(b, ob);
    return nn == asp_hier_node_count(b) && np == asp_hier_point_count(b) && asp_hier_depth(a) == asp_hier_depth(b) &&
           asp_hier_flags(a) == asp_hier_flags(b) && asp_hier_leaf_size(a) == asp_hier_leaf_size(b) &&
           memcmp(oa, ob, sizeof oa) == 0 && memcmp(asp_hier_frame(a), asp_hier_frame(b), sizeof(asp_frame)) == 0 &&
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
    /* the recorded frame is the source points' frame, bit for bit */
    asp_frame want;
    CHECK_OK(asp_cloud_frame(cl, &want, err), err);
    CHECK(want.radius > 0 && memcmp(asp_hier_frame(built), &want, sizeof want) == 0);
    CHECK(back && memcmp(asp_hier_frame(back), &want, sizeof want) == 0);
    image = read_all(path, &image_size);
    CHECK(image && image_size == 160 + asp_hier_node_count(built) * (48 + 64 + 80) + 3000 * 64);
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

/*
 * The up axis and box of the frame (issue 29): a z-up cloud's hierarchy keeps ASP_UP_Z and the box
 * through save and load, bit for bit; a file from before them (bytes 128-139 zero) loads as y-up
 * with no box; an up axis code beyond -x is refused naming byte 128.
 */
static void test_up_axis(void)
{
    asp_cloud *cl = small_cloud(500);
    cl->up = ASP_UP_Z;
    asp_error errbuf = {0}, *err = &errbuf;
    asp_hier *h = NULL, *back = NULL;
    CHECK_OK(asp_hier_build(cl, NULL, NULL, &h, err), err);
    char path[600];
    path_of(path, sizeof path, "up.asph");
    CHECK_OK(asp_hier_save(h, path, err), err);
    CHECK_OK(asp_hier_load(path, NULL, &back, err), err);
    asp_frame want;
    CHECK_OK(asp_cloud_frame(cl, &want, err), err);
    CHECK(want.up == ASP_UP_Z && want.half[0] > 0 && want.half[1] > 0 && want.half[2] > 0);
    const asp_frame *got = back ? asp_hier_frame(back) : &want;
    CHECK_MSG(memcmp(got, &want, sizeof want) == 0, "up %d half %.17g %.17g %.17g, want up %d half %.17g %.17g %.17g",
              (int)got->up, got->half[0], got->half[1], got->half[2], (int)want.up, want.half[0], want.half[1],
              want.half[2]);
    asp_hier_destroy(back);
    back = NULL;
    size_t size = 0;
    uint8_t *b = read_all(path, &size);
    CHECK(b && size > 160 && b[128] == ASP_UP_Z + 1);
    if (b && size > 160) {
        memset(b + 128, 0, 12);
        reseal_header(b, size, 160);
        CHECK_OK(asp_hier_load_memory(b, size, "old.asph", NULL, &back, err), err);
        CHECK(back && asp_hier_frame(back)->up == ASP_UP_Y && asp_hier_frame(back)->half[0] == 0 &&
              asp_hier_frame(back)->radius == want.radius);
        asp_hier_destroy(back);
        b[128] = 7; // beyond ASP_UP_NEG_X + 1
        reseal_header(b, size, 160);
        CHECK(load_bytes(b, size, err) == ASP_EFORMAT && strstr(err->msg, "byte 128") != NULL);
    }
    free(b);
    asp_hier_destroy(h);
    asp_cloud_destroy(cl);
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
    for (size_t at = 0; at < image_size; at += at < 160 ? 1 : image_size / 211 + 1) {
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
    b[8] = 3;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EUNSUPPORTED && strstr(err.msg, "version 3"));
    /* huge counts with a valid header checksum: refused before allocating */
    memcpy(b, image, image_size);
    put64le(b + 32, 1ULL << 40);
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "byte 16: header"));
    /* a recorded frame that is not finite, or has a negative radius: refused naming its byte (96) */
    const double bad_values[2] = {-1.0, strtod("nan", NULL)};
    for (int k = 0; k < 2; k++) {
        memcpy(b, image, image_size);
        uint64_t bits;
        memcpy(&bits, &bad_values[k], 8);
        put64le(b + (k ? 104 : 120), bits);
        reseal(b, image_size);
        CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT);
        CHECK_MSG(strstr(err.msg, "x.asph") && strstr(err.msg, "byte 96: frame") && strstr(err.msg, "expected"), "%s",
                  err.msg);
    }
    free(b);
}

/*
 * A version-1 file (128-byte header, no frame), forged from a version-2 one:
 * it loads, framed by the root bounding sphere as before the frame was
 * recorded; everything else is the same.
 */
static void test_version_1(void)
{
    if (!image || !built)
        return;
    const size_t size = image_size - 32;
    uint8_t *b = malloc(size);
    memcpy(b, image, 96);
    memset(b + 96, 0, 32);
    memcpy(b + 128, image + 160, image_size - 160);
    put32le(b + 8, 1);
    put32le(b + 12, 128);
    reseal_header(b, size, 128);
    asp_hier *h = NULL;
    asp_error errbuf = {0}, *err = &errbuf;
    CHECK_OK(asp_hier_load_memory(b, size, "v1.asph", NULL, &h, err), err);
    if (h) {
        double o[3];
        asp_hier_origin(h, o);
        const asp_hier_node *root = asp_hier_nodes(h);
        const asp_frame *f = asp_hier_frame(h);
        CHECK(f->radius == root->sphere[3] && f->center[0] == o[0] + root->sphere[0] &&
              f->center[2] == o[2] + root->sphere[2]);
        /* the root sphere bounds the points (loosely), so it encloses the recorded frame's points too */
        const asp_frame *want = asp_hier_frame(built);
        CHECK(f->radius >= 0.9 * want->radius && f->radius < 2 * want->radius);
        CHECK(memcmp(asp_hier_nodes(h), asp_hier_nodes(built), asp_hier_node_count(built) * sizeof(asp_hier_node)) == 0);
        asp_hier_destroy(h);
    }
    /* a version-1 header size on a version-2 file is refused (its header checksum sits elsewhere) */
    memcpy(b, image, size);
    put32le(b + 12, 128);
    reseal(b, size);
    h = NULL;
    CHECK(asp_hier_load_memory(b, size, "v2.asph", NULL, &h, err) == ASP_EFORMAT && h == NULL);
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
    put32le(b + 160 + 24, (uint32_t)nn + 5);
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "node 0"));
    CHECK_MSG(strstr(err.msg, "byte 160: ") != NULL, "%s", err.msg); /* node 0's record */
    /* a child that claims another parent */
    uint32_t c = asp_hier_nodes(built)[0].first_child;
    memcpy(b, image, image_size);
    b[160 + 48 * (size_t)c + 20] ^= 1;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "invalid hierarchy"));
    /* a NaN ellipse axis in a point splat */
    memcpy(b, image, image_size);
    size_t at = 160 + 48 * nn + 64 * (nn + 3) + 44;
    b[at] = 0xff;
    b[at + 1] = 0xff;
    b[at + 2] = 0xc0;
    b[at + 3] = 0x7f;
    reseal(b, image_size);
    CHECK(load_bytes(b, image_size, &err) == ASP_EFORMAT && strstr(err.msg, "point 3"));
    char where[40];
    snprintf(where, sizeof where, "byte %zu: ", at - 44);
    CHECK_MSG(strstr(err.msg, where) != NULL, "%s lacks %s", err.msg, where);
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
    /* a directory or a FIFO is refused at once (a FIFO would block a reader that opened it) */
    CHECK(asp_hier_load(tmpdir, NULL, &h, &err) == ASP_EIO && h == NULL && strstr(err.msg, "directory"));
    path_of(path, sizeof path, "fifo.asph");
    if (mkfifo(path, 0600) == 0) {
        CHECK(asp_hier_load(path, NULL, &h, &err) == ASP_EIO && h == NULL && strstr(err.msg, "not a regular file"));
        remove(path);
    }
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
                                          TEST_CASE(test_corrupted), TEST_CASE(test_version_1),
                                          TEST_CASE(test_inconsistent_tree),
                                          TEST_CASE(test_io_errors), TEST_CASE(test_up_axis)};
    int rc = asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
    cleanup();
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
    return rc;
}
