/*
 * BC3 atlases (issue 27 item 2; asp_dps_level_compress, src/prim/bc3_squish.cpp): the octahedron's
 * face level compressed round-trips through a .dps byte for byte (blocks and decoded texels), its GPU
 * bytes are 1 per texel of each atlas (docs/cli/fit.md), the file shrinks by 3 bytes a texel, and with GL its
 * render (BC3 blocks uploaded as GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT5_EXT) matches the uncompressed
 * level's by SSIM >= 0.95 on 4 views.
 */
#include <stdio.h>
#include <unistd.h>
#ifndef ASP_TEST_TMP_DIR
#define ASP_TEST_TMP_DIR "/tmp"
#endif
#ifdef ASP_HAVE_GL
#include <epoxy/gl.h>
#endif

#include "harness.h"
#include "test_fit_common.h"

/* A one-level file around lv (taken over; freed by asp_dps_destroy). */
static asp_dps *wrap(asp_dps_level *lv)
{
    asp_dps *d = calloc(1, sizeof *d);
    d->levels = calloc(1, sizeof *d->levels);
    d->levels[0] = *lv;
    d->level_count = 1;
    d->amg_levels = 1;
    d->source_points = 8000;
    d->mean_radius = 0.01;
    d->desc = (asp_prim_desc){.tau = 0.05, .texel_size = 1};
    snprintf(d->source, sizeof d->source, "octahedron");
    d->frame = (asp_frame){.radius = 1.05};
    return d;
}

static void test_round_trip(void)
{
    asp_dps_level lv, plain;
    if (octahedron_level(&lv)) {
        CHECK(0);
        return;
    }
    CHECK(copy_level(&lv, &plain) == 0);
    plain.prims = malloc(lv.prim_count * sizeof *plain.prims);
    memcpy(plain.prims, lv.prims, lv.prim_count * sizeof *plain.prims);
    plain.neighbours = malloc((lv.neighbour_total ? lv.neighbour_total : 1) * sizeof *plain.neighbours);
    memcpy(plain.neighbours, lv.neighbours, lv.neighbour_total * sizeof *plain.neighbours);
    plain.link_first = NULL, plain.link_parent = NULL, plain.link_weight = NULL, plain.link_total = 0;
    asp_error err = {0};
    asp_mesh_bytes b0, b1;
    asp_dps_level_gpu_bytes(&lv, &b0);
    CHECK_OK(asp_dps_level_compress(&lv, NULL, &err), &err);
    CHECK(lv.atlas_bc3 != NULL && lv.normal_bc3 == NULL && lv.atlas.height % 4 == 0);
    asp_dps_level_gpu_bytes(&lv, &b1);
    size_t side = (size_t)lv.atlas.width * lv.atlas.height;
    CHECK_MSG(b1.texture == side, "BC3 atlas %ux%u: %zu GPU bytes, expected 1 a texel (%zu)", lv.atlas.width,
              lv.atlas.height, b1.texture, side);
    CHECK(b0.texture == 4 * (size_t)plain.atlas.width * plain.atlas.height && b1.vertex == b0.vertex);
    fprintf(stderr, "atlas %ux%u: %zu -> %zu GPU bytes\n", lv.atlas.width, lv.atlas.height, b0.texture, b1.texture);
    // the decoded texels are close to the originals (BC3: 4 colours a block, 8 alphas)
    double err2 = 0;
    for (size_t y = 0; y < plain.atlas.height; y++)
        for (size_t x = 0; x < 4 * (size_t)plain.atlas.width; x++) {
            double d = (double)lv.atlas.pixels[y * 4 * lv.atlas.width + x] -
                       (double)plain.atlas.pixels[y * 4 * plain.atlas.width + x];
            err2 += d * d;
        }
    double rms = sqrt(err2 / (4.0 * plain.atlas.width * plain.atlas.height));
    fprintf(stderr, "BC3 RMS error %.2f of 255\n", rms);
    CHECK_MSG(rms > 0 && rms < 8, "RMS %.2f", rms);

    uint8_t *blocks = malloc(side);
    memcpy(blocks, lv.atlas_bc3, side);
    asp_dps *d = wrap(&lv);
    char path[256];
    snprintf(path, sizeof path, "%s/asp_test_fit_compress_%d.dps", ASP_TEST_TMP_DIR, (int)getpid());
    CHECK_OK(asp_dps_save(d, path, &err), &err);
    asp_dps *back = NULL;
    CHECK_OK(asp_dps_load(path, NULL, &back, &err), &err);
    if (back) {
        const asp_dps_level *r = &back->levels[0];
        CHECK(r->atlas_bc3 && memcmp(r->atlas_bc3, blocks, side) == 0);
        CHECK(r->atlas.width == lv.atlas.width && r->atlas.height == lv.atlas.height &&
              memcmp(r->atlas.pixels, d->levels[0].atlas.pixels, 4 * side) == 0);
        CHECK(asp_dps_level_gpu_bytes(r, NULL) == b1.total);
        asp_dps_summary s;
        CHECK(asp_dps_summarize(back, &s, 1) == 1 && s.compressed == 1);
        asp_dps_destroy(back);
    }
    // the file holds the blocks, not RGBA8: its size shrank by 3 bytes a texel
    FILE *f = fopen(path, "rb");
    long compressed_size = -1;
    if (f && fseek(f, 0, SEEK_END) == 0)
        compressed_size = ftell(f);
    if (f)
        fclose(f);
    asp_dps *p = wrap(&plain);
    CHECK_OK(asp_dps_save(p, path, &err), &err);
    f = fopen(path, "rb");
    long plain_size = -1;
    if (f && fseek(f, 0, SEEK_END) == 0)
        plain_size = ftell(f);
    if (f)
        fclose(f);
    CHECK_MSG(plain_size - compressed_size == 4 * (long)plain.atlas.width * plain.atlas.height - (long)side,
              "file sizes %ld (RGBA8) and %ld (BC3)", plain_size, compressed_size);
    remove(path);
    free(blocks);
    asp_dps_destroy(p);
    asp_dps_destroy(d);
}

/* Fitting a compressed level rewrites its texels: the stale blocks are dropped, the level is RGBA8 again. */
static void test_refit_drops_blocks(void)
{
    asp_dps_level lv;
    if (octahedron_level(&lv)) {
        CHECK(0);
        return;
    }
    asp_error err = {0};
    CHECK_OK(asp_dps_level_compress(&lv, NULL, &err), &err);
    asp_fit_view view;
    look(40, 30, 64, &view);
    asp_image ref = {0};
    CHECK_OK(asp_fit_render_cpu(&lv, (double[3]){0, 0, 0}, &view, NULL, &ref, &err), &err);
    size_t before = 0, after = 0;
    CHECK(lv.atlas_bc3 != NULL);
    CHECK_OK(asp_fit_alpha(&lv, (double[3]){0, 0, 0}, &view, &ref, 1, &(asp_fit_desc){.alpha_rounds = 1}, NULL,
                           &before, &after, &err), &err);
    CHECK(lv.atlas_bc3 == NULL && lv.normal_bc3 == NULL);
    CHECK(asp_dps_level_gpu_bytes(&lv, NULL) > 4 * (size_t)lv.atlas.width * lv.atlas.height);
    asp_image_release(&ref);
    asp_dps_level_release(&lv, NULL);
}

#ifdef ASP_HAVE_GL
/* The compressed level drawn by the prim renderer against the uncompressed one (normalized method). */
static void test_render_matches(void)
{
    asp_dps_level lv, bc;
    if (octahedron_level(&lv) || octahedron_level(&bc)) {
        CHECK(0);
        return;
    }
    asp_error err = {0};
    CHECK_OK(asp_dps_level_compress(&bc, NULL, &err), &err);
    asp_gl_context *gl = NULL;
    CHECK_OK(asp_gl_context_create_headless(NULL, NULL, &gl, &err), &err);
    const asp_renderer_kind *kind = NULL;
    asp_renderer *ra = NULL, *rb = NULL;
    asp_render_source sa = {.level = &lv}, sb = {.level = &bc};
    if (gl) {
        fprintf(stderr, "S3TC %d, sRGB %d\n", epoxy_has_gl_extension("GL_EXT_texture_compression_s3tc"),
                epoxy_has_gl_extension("GL_EXT_texture_sRGB"));
        CHECK_OK(asp_renderer_kind_find("prim", 0, &kind, &err), &err);
        // the GL takes the blocks as they are and samples what libsquish decodes (llvmpipe: S3TC present)
        GLuint tex = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, GL_COMPRESSED_RGBA_S3TC_DXT5_EXT, (GLsizei)bc.atlas.width,
                           (GLsizei)bc.atlas.height);
        glCompressedTextureSubImage2D(tex, 0, 0, 0, (GLsizei)bc.atlas.width, (GLsizei)bc.atlas.height,
                                      GL_COMPRESSED_RGBA_S3TC_DXT5_EXT,
                                      (GLsizei)((size_t)bc.atlas.width * bc.atlas.height), bc.atlas_bc3);
        GLint compressed = 0, stored = 0;
        glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_COMPRESSED, &compressed);
        glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_COMPRESSED_IMAGE_SIZE, &stored);
        size_t n = 4 * (size_t)bc.atlas.width * bc.atlas.height, far = 0;
        uint8_t *got = calloc(n, 1);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glGetTextureImage(tex, 0, GL_RGBA, GL_UNSIGNED_BYTE, (GLsizei)n, got);
        for (size_t i = 0; i < n; i++)
            far += abs((int)got[i] - (int)bc.atlas.pixels[i]) > 2;
        fprintf(stderr, "GL: compressed %d, %d bytes stored, %zu of %zu channels differ from libsquish by > 2\n",
                compressed, stored, far, n);
        CHECK(glGetError() == GL_NO_ERROR && compressed == GL_TRUE);
        CHECK_MSG(stored == (GLint)(n / 4), "%d bytes stored, expected %zu", stored, n / 4);
        CHECK_MSG(far * 1000 < n, "%zu of %zu channels differ by more than 2", far, n);
        free(got);
        glDeleteTextures(1, &tex);
    }
    if (kind) {
        CHECK_OK(kind->create(gl, &sa, NULL, NULL, &ra, &err), &err);
        CHECK_OK(kind->create(gl, &sb, NULL, NULL, &rb, &err), &err);
    }
    asp_frame frame = {.radius = 1.05};
    for (int v = 0; v < 4 && ra && rb; v++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.azimuth = 30.0f + 80.0f * (float)v;
        cam.elevation = v % 2 ? -25.0f : 35.0f;
        asp_camera_frame(&cam, &frame, NULL, 1.0f, 0.0f);
        asp_image a = {0}, b = {0};
        double ssim = 0;
        CHECK_OK(asp_render_to_image(gl, ra, &cam, &(asp_render_desc){.width = 128, .height = 128}, &a, &err), &err);
        CHECK_OK(asp_render_to_image(gl, rb, &cam, &(asp_render_desc){.width = 128, .height = 128}, &b, &err), &err);
        CHECK_OK(asp_image_ssim(&a, &b, &ssim, &err), &err);
        fprintf(stderr, "view %d: SSIM BC3 vs RGBA8 %.6f\n", v, ssim);
        CHECK_MSG(ssim >= 0.95 && ssim < 1.0, "view %d: SSIM %.4f", v, ssim);
        asp_image_release(&a), asp_image_release(&b);
    }
    asp_renderer_destroy(ra);
    asp_renderer_destroy(rb);
    asp_gl_context_destroy(gl);
    asp_dps_level_release(&lv, NULL);
    asp_dps_level_release(&bc, NULL);
}
#endif

int main(void)
{
    static const asp_test_case cases[] = {
        TEST_CASE(test_round_trip),
        TEST_CASE(test_refit_drops_blocks),
#ifdef ASP_HAVE_GL
        TEST_CASE(test_render_matches),
#endif
    };
    return asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
}
