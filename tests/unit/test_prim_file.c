/*
 * The .dps file (issue 4 item 8): a save/load round trip keeps every field and
 * texel; damaged files (truncated, flipped byte, foreign, trailing bytes, a
 * texture rectangle outside its atlas) give a clear error and no result.
 * asp_dps_load_memory gives the same result as the path loader; a cut at every
 * byte and forged counts (with the CRC fixed, so the parser sees them) fail
 * cleanly, naming the file and field, without a large allocation.
 */
#include <stdio.h>
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "file_forge.h"
#include "harness.h"

#ifndef ASP_TEST_TMP_DIR
#define ASP_TEST_TMP_DIR "/tmp"
#endif

/* A wavy 30x30 patch cut into 4 overlapping domains. */
static int make_level(asp_cloud **cloud, asp_dps_level *lv)
{
    enum { G = 30 };
    asp_error err;
    asp_cloud *c = NULL;
    CHECK_OK(asp_cloud_create(G * G, ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII, NULL, &c, &err), &err);
    if (!c)
        return -1;
    c->origin[0] = 1000.5; /* centres are stored in world coordinates */
    for (size_t i = 0; i < G * G; i++) {
        float x = (float)(i % G) * 0.02f, y = (float)(i / G) * 0.02f;
        c->positions[3 * i] = x, c->positions[3 * i + 1] = y, c->positions[3 * i + 2] = 0.01f * sinf(10 * x);
        c->normals[3 * i + 2] = 1;
        c->radii[i] = 0.02f;
        c->colors[4 * i] = (uint8_t)(i * 7), c->colors[4 * i + 1] = 90, c->colors[4 * i + 2] = (uint8_t)(i / 4);
        c->colors[4 * i + 3] = 255;
    }
    asp_amg_csr *dom = NULL;
    CHECK_OK(asp_amg_csr_create(4, G * G, 4 * G * G, NULL, &dom, &err), &err);
    size_t k = 0;
    for (size_t r = 0; dom && r < 4; r++) {
        for (size_t i = 0; i < G * G; i++) {
            size_t x = i % G, y = i / G;
            if (((r & 1) ? x >= G / 2 - 3 : x < G / 2 + 3) && ((r & 2) ? y >= G / 2 - 3 : y < G / 2 + 3)) {
                dom->col[k] = (asp_index)i;
                dom->val[k++] = 0.3 + 0.1 * (double)r;
            }
        }
        dom->row_ptr[r + 1] = k;
    }
    int rc = dom ? asp_prim_build_level(c, dom, &(asp_prim_desc){.normal_map = 1}, NULL, lv, &err) : -1;
    CHECK_OK(rc, &err);
    asp_amg_csr_destroy(dom);
    *cloud = c;
    return rc;
}

static void copy_damaged(const char *src, const char *dst, long keep, long flip_at, const char *append)
{
    FILE *in = fopen(src, "rb"), *out = fopen(dst, "wb");
    long n = (long)forge_file_size(src);
    for (long i = 0; in && out && i < n && i < keep; i++) {
        int ch = fgetc(in);
        fputc(i == flip_at ? ch ^ 0x10 : ch, out);
    }
    if (append && out)
        fputs(append, out);
    if (in)
        fclose(in);
    if (out)
        fclose(out);
}

static void expect_bad(const char *path, const char *text)
{
    asp_dps *d = NULL;
    asp_error err = {0};
    int rc = asp_dps_load(path, NULL, &d, &err);
    CHECK_MSG(rc == ASP_EFORMAT, "%s: rc %d (%s)", path, rc, err.msg);
    CHECK_MSG(strstr(err.msg, text) != NULL && strstr(err.msg, path) != NULL, "%s: message '%s' lacks '%s'", path,
              err.msg, text);
    CHECK(d == NULL);
}

static void test_round_trip_and_damage(void)
{
    asp_cloud *c = NULL;
    asp_dps_level lv;
    if (make_level(&c, &lv))
        return;
    CHECK(lv.prim_count == 4 && lv.neighbour_total == 12); /* the quadrants overlap pairwise */
    asp_dps dps = {.level_count = 1, .levels = &lv, .amg_levels = 7, .skipped_levels = 1, .source_points = c->count,
                   .mean_radius = 0.02, .desc = {.tau = 0.05, .texel_size = 1, .normal_map = 1}};
    snprintf(dps.source, sizeof dps.source, "patch.ply");
    CHECK_OK(asp_cloud_frame(c, &dps.frame, NULL), NULL);
    CHECK(dps.frame.radius > 0 && dps.frame.center[0] > 1000);
    lv.level = 4;
    char path[256], bad[300];
    snprintf(path, sizeof path, "%s/asp_test_prim_file_%d.dps", ASP_TEST_TMP_DIR, (int)getpid());
    asp_error err;
    CHECK_OK(asp_dps_save(&dps, path, &err), &err);
    asp_dps *back = NULL;
    CHECK_OK(asp_dps_load(path, NULL, &back, &err), &err);
    if (back) {
        CHECK(back->level_count == 1 && back->amg_levels == 7 && back->skipped_levels == 1);
        CHECK(strcmp(back->source, "patch.ply") == 0 && back->source_points == c->count);
        CHECK(back->desc.normal_map == 1 && back->desc.texel_size == 1);
        CHECK(memcmp(&back->frame, &dps.frame, sizeof dps.frame) == 0); /* bit for bit */
        const asp_dps_level *b = &back->levels[0];
        CHECK(b->level == 4 && b->prim_count == lv.prim_count && b->texels == lv.texels);
        CHECK(memcmp(b->prims, lv.prims, lv.prim_count * sizeof *lv.prims) == 0);
        CHECK(memcmp(b->neighbours, lv.neighbours, lv.neighbour_total * sizeof *lv.neighbours) == 0);
        CHECK(b->atlas.width == lv.atlas.width && b->atlas.height == lv.atlas.height);
        CHECK(memcmp(b->atlas.pixels, lv.atlas.pixels, 4 * (size_t)lv.atlas.width * lv.atlas.height) == 0);
        CHECK(memcmp(b->normal_atlas.pixels, lv.normal_atlas.pixels, 4 * (size_t)lv.atlas.width * lv.atlas.height) ==
              0);
        CHECK(fabs(b->prims[0].centre[0] - 1000.5) < 1); /* world coordinates */
        asp_dps_summary row;
        CHECK(asp_dps_summarize(back, &row, 1) == 1);
        asp_mesh_bytes bytes;
        size_t total = asp_dps_level_gpu_bytes(b, &bytes);
        CHECK(bytes.vertex == 4 * 128 && bytes.index == 4 * 24); // 4 primitives
        // colour and normal atlas, same size, RGBA8 as the renderer allocates them: one level, no mipmaps
        // (issue 27: what is really in GPU memory; the count had a 4/3 mip chain the upload never made)
        CHECK(bytes.texture == 2 * ((size_t)b->atlas.width * b->atlas.height * 4) && total == bytes.vertex +
              bytes.index + bytes.texture);
        size_t index = 9;
        CHECK(asp_dps_level_parse(back, "L-2", &index, NULL) == 0 && index == 0);
        CHECK(asp_dps_level_parse(back, "L-3", &index, NULL) == ASP_EINVAL && index == 0);
        CHECK(strcmp(row.name, "L-2") == 0 && row.primitives == 4 && row.neighbour_pairs == 6 && row.normal_map);
        asp_dps_destroy(back);
    }
    long n = (long)forge_file_size(path);
    snprintf(bad, sizeof bad, "%s.bad.dps", path);
    copy_damaged(path, bad, n - 100, -1, NULL);
    expect_bad(bad, "truncated");
    copy_damaged(path, bad, 40, -1, NULL);
    expect_bad(bad, "truncated");
    copy_damaged(path, bad, n, n / 2, NULL);
    expect_bad(bad, "checksum");
    copy_damaged(path, bad, n, -1, "xx");
    expect_bad(bad, "trailing");
    copy_damaged(path, bad, n, 0, NULL);
    expect_bad(bad, "not a .dps file");
    copy_damaged(path, bad, n, 8, NULL);
    expect_bad(bad, "version");
    /*
     * consistent checksum, inconsistent content: the reader checks rectangles and neighbour indices,
     * and the writer reads its file back (issue #13), so it refuses to write either and the damaged
     * file already at 'bad' stays as it was
     */
    lv.prims[2].tex_x = lv.atlas.width - 1;
    CHECK(asp_dps_save(&dps, bad, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "internal error: the written '") && strstr(err.msg, "primitive 2: texture"), "%s",
              err.msg);
    expect_bad(bad, "version");
    lv.prims[2].tex_x = 0;
    lv.neighbours[0] = 99;
    CHECK(asp_dps_save(&dps, bad, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "does not read back: ") && strstr(err.msg, "neighbour entry 0"), "%s", err.msg);
    expect_bad(bad, "version");
    asp_dps *d = NULL;
    CHECK(asp_dps_load("/nonexistent/x.dps", NULL, &d, &err) == ASP_EIO);
    remove(path);
    remove(bad);
    asp_dps_level_release(&lv, NULL);
    asp_cloud_destroy(c);
}

/* asp_dps_load_memory for file_forge.h: *out goes in and comes back, so an unchanged sentinel shows. */
static int load_dps(const void *data, size_t size, const char *name, const asp_context *ctx, void **out, asp_error *err)
{
    asp_dps *d = *out;
    int rc = asp_dps_load_memory(data, size, name, ctx, &d, err);
    *out = d;
    return rc;
}

static void destroy_dps(void *d)
{
    asp_dps_destroy(d);
}

static const forge_format dps_format = {"dps", 24, load_dps, destroy_dps}; /* payload size at header byte 24 */

static int same_dps(const asp_dps *x, const asp_dps *y)
{
    int ok = x->level_count == y->level_count && x->amg_levels == y->amg_levels &&
             x->skipped_levels == y->skipped_levels && x->source_points == y->source_points &&
             x->mean_radius == y->mean_radius && !memcmp(&x->desc, &y->desc, sizeof x->desc) &&
             !strcmp(x->source, y->source) && !memcmp(&x->frame, &y->frame, sizeof x->frame);
    for (size_t i = 0; ok && i < x->level_count; i++) {
        const asp_dps_level *a = &x->levels[i], *b = &y->levels[i];
        size_t px = 4 * (size_t)a->atlas.width * a->atlas.height;
        ok = a->level == b->level && a->basis_count == b->basis_count && a->prim_count == b->prim_count &&
             a->neighbour_total == b->neighbour_total && a->texels == b->texels && a->error == b->error &&
             a->atlas.width == b->atlas.width && a->atlas.height == b->atlas.height &&
             a->normal_atlas.width == b->normal_atlas.width &&
             !memcmp(a->prims, b->prims, a->prim_count * sizeof *a->prims) &&
             !memcmp(a->neighbours, b->neighbours, a->neighbour_total * sizeof *a->neighbours) &&
             !memcmp(a->atlas.pixels, b->atlas.pixels, px) &&
             (!a->normal_atlas.width || !memcmp(a->normal_atlas.pixels, b->normal_atlas.pixels, px));
    }
    return ok;
}

/* Memory load = path load; a cut at every byte; forged counts behind a valid checksum. */
static void test_memory_cuts_and_forged_counts(void)
{
    asp_cloud *c = NULL;
    asp_dps_level lv;
    if (make_level(&c, &lv))
        return;
    /* a small level (coarse texels) keeps the byte-by-byte loop fast under ASan */
    asp_dps dps = {.level_count = 1, .levels = &lv, .amg_levels = 7, .source_points = c->count, .mean_radius = 0.02,
                   .desc = {.tau = 0.05, .texel_size = 1, .normal_map = 1}};
    snprintf(dps.source, sizeof dps.source, "patch.ply");
    CHECK_OK(asp_cloud_frame(c, &dps.frame, NULL), NULL);
    lv.level = 4;
    char path[256];
    snprintf(path, sizeof path, "%s/asp_test_prim_mem_%d.dps", ASP_TEST_TMP_DIR, (int)getpid());
    asp_error err;
    CHECK_OK(asp_dps_save(&dps, path, &err), &err);
    size_t size = 0;
    unsigned char *bytes = forge_slurp(path, &size);
    CHECK(bytes && size > 68);
    asp_dps *from_path = NULL, *from_mem = NULL;
    CHECK_OK(asp_dps_load(path, NULL, &from_path, &err), &err);
    CHECK_OK(asp_dps_load_memory(bytes, size, path, NULL, &from_mem, &err), &err);
    CHECK(from_path && from_mem && same_dps(from_path, from_mem) && same_dps(&dps, from_mem));
    asp_dps_destroy(from_path);
    asp_dps_destroy(from_mem);

    forge_expect_cuts_fail(&dps_format, bytes, size);
    CHECK(asp_dps_load_memory(NULL, 0, NULL, NULL, &from_mem, &err) == ASP_EFORMAT && strstr(err.msg, "<memory>"));

    /* forged counts: header level count, then level 0's primitive and neighbour counts and atlas size */
    const size_t level_at = 96 + 128 + 4 + strlen("patch.ply");
    const struct {
        size_t at;
        uint64_t value;
        int bytes;
        const char *field;
    } forged[] = {{16, 1ull << 40, 8, "level count"},
                  {level_at + 8, 1ull << 60, 8, "primitive count"},
                  {level_at + 8, (uint64_t)size / 124, 8, "primitive count"},
                  {level_at + 16, 1ull << 61, 8, "neighbour count"},
                  {level_at + 24, 16000, 4, "atlas"},
                  {level_at + 24, 1u << 30, 4, "atlas"},
                  {level_at, 9, 4, "AMG level"}};
    for (size_t i = 0; i < sizeof forged / sizeof forged[0]; i++)
        forge_expect_refused(&dps_format, bytes, size, forged[i].at, forged[i].value, forged[i].bytes, forged[i].field);
    /* a recorded frame that is not finite or has a negative radius names the field and its byte (64) */
    const double inf = strtod("inf", NULL), minus_one = -1;
    uint64_t inf_bits, minus_bits;
    memcpy(&inf_bits, &inf, 8);
    memcpy(&minus_bits, &minus_one, 8);
    forge_expect_refused(&dps_format, bytes, size, 88, minus_bits, 8, "byte 64: frame");
    forge_expect_refused(&dps_format, bytes, size, 64, inf_bits, 8, "byte 64: frame");

    /*
     * a version-1 file (64-byte header, no frame), forged by cutting the frame out and the 16 bytes of
     * links (version 3) from the one level's header, loads with radius 0
     */
    const size_t v1_size = size - 32 - 16, links_at = level_at + 96;
    unsigned char *v1 = malloc(v1_size);
    if (v1) {
        memcpy(v1, bytes, 64);
        memcpy(v1 + 64, bytes + 96, links_at - 96);
        memcpy(v1 + 64 + links_at - 96, bytes + links_at + 16, size - links_at - 16);
        forge_put_le(v1 + 8, 1, 4);
        forge_put_le(v1 + 12, 64, 4);
        forge_fix_header(v1, v1_size, 24, 64);
        asp_dps *old = NULL;
        CHECK_OK(asp_dps_load_memory(v1, v1_size, "v1.dps", NULL, &old, &err), &err);
        if (old) {
            const asp_frame zero = {.radius = 0};
            CHECK(memcmp(&old->frame, &zero, sizeof zero) == 0);
            old->frame = dps.frame; /* everything else is the same */
            CHECK(same_dps(&dps, old));
            asp_dps_destroy(old);
        }
        /* version 1 with the version-2 header size (and the reverse) is refused */
        forge_put_le(v1 + 12, 96, 4);
        forge_fix_header(v1, v1_size, 24, 96);
        old = NULL;
        CHECK(asp_dps_load_memory(v1, v1_size, "v1.dps", NULL, &old, &err) == ASP_EFORMAT && !old);
        CHECK_MSG(strstr(err.msg, "version 1 (header 96 bytes)") != NULL, "%s", err.msg);
        free(v1);
    }
    free(bytes);
    remove(path);
    asp_dps_level_release(&lv, NULL);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_round_trip_and_damage), TEST_CASE(test_memory_cuts_and_forged_counts))
