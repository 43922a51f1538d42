/*
 * Forging the checksummed binary files (.amg, .dps) for their reader tests: an
 * independent CRC-32, little-endian fields, whole-file reads, an allocator that
 * counts what one load asks for, and the two checks both readers must pass: a
 * cut at every byte, and a forged count behind a valid checksum. Static inline
 * like harness.h, since each tests/unit/test_*.c is a program of its own.
 */
#ifndef ASP_TESTS_FILE_FORGE_H
#define ASP_TESTS_FILE_FORGE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/core.h"
#include "harness.h"

/*
 * Both formats: a header (96 bytes since the frame was recorded, 64 before),
 * then the payload, then a 4-byte CRC-32 of everything before it.
 */
enum { FORGE_HEADER_BYTES = 96, FORGE_TRAILER_BYTES = 4 };

/* The size of a file in bytes, 0 when it cannot be read. */
static inline size_t forge_file_size(const char *file)
{
    FILE *fp = fopen(file, "rb");
    if (!fp)
        return 0;
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fclose(fp);
    return n < 0 ? 0 : (size_t)n;
}

/* The whole file in a malloc'd buffer of *n bytes; NULL and *n = 0 when it is empty or cannot be read. */
static inline unsigned char *forge_slurp(const char *file, size_t *n)
{
    size_t len = forge_file_size(file);
    unsigned char *b = len > 0 ? malloc(len) : NULL;
    FILE *fp = fopen(file, "rb");
    *n = 0;
    if (b && fp && fread(b, 1, len, fp) == len)
        *n = len;
    if (fp)
        fclose(fp);
    if (*n == 0) {
        free(b);
        b = NULL;
    }
    return b;
}

/* Independent CRC-32 (IEEE, reflected 0xEDB88320), so a forged file can carry a valid checksum. */
static inline uint32_t forge_crc32(const unsigned char *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

static inline void forge_put_le(unsigned char *p, uint64_t v, int bytes)
{
    for (int k = 0; k < bytes; k++)
        p[k] = (unsigned char)(v >> (8 * k));
}

static inline uint64_t forge_get_le(const unsigned char *p, int bytes)
{
    uint64_t v = 0;
    for (int k = 0; k < bytes; k++)
        v |= (uint64_t)p[k] << (8 * k);
    return v;
}

/*
 * Makes b (n >= header + 4 bytes) self-consistent: the 8-byte payload size at
 * header byte payload_at and the CRC trailer.
 */
static inline void forge_fix_header(unsigned char *b, size_t n, size_t payload_at, size_t header)
{
    forge_put_le(b + payload_at, n - header - FORGE_TRAILER_BYTES, 8);
    forge_put_le(b + n - FORGE_TRAILER_BYTES, forge_crc32(b, n - FORGE_TRAILER_BYTES), FORGE_TRAILER_BYTES);
}

/* forge_fix_header for the current versions' header. */
static inline void forge_fix(unsigned char *b, size_t n, size_t payload_at)
{
    forge_put_le(b + payload_at, n - FORGE_HEADER_BYTES - FORGE_TRAILER_BYTES, 8);
    forge_put_le(b + n - FORGE_TRAILER_BYTES, forge_crc32(b, n - FORGE_TRAILER_BYTES), FORGE_TRAILER_BYTES);
}

/* An allocator that counts what one load asks for. */
typedef struct forge_tally {
    size_t total;
} forge_tally;

static inline void *forge_tally_alloc(void *user, size_t size, size_t align)
{
    ((forge_tally *)user)->total += size;
    return aligned_alloc(align, (size + align - 1) / align * align);
}

static inline void forge_tally_free(void *user, void *ptr)
{
    (void)user;
    free(ptr);
}

/*
 * A reader under test. load parses memory like asp_<x>_load_memory into *out,
 * which it must leave as it was on failure; destroy frees what load made. The
 * names in messages are "cut.<ext>" and "forged.<ext>".
 */
typedef struct forge_format {
    const char *ext;
    size_t payload_at; /* header byte of the 8-byte payload size */
    int (*load)(const void *data, size_t size, const char *name, const asp_context *ctx, void **out, asp_error *err);
    void (*destroy)(void *obj);
} forge_format;

/* A cut at every byte, as is and with the payload size and CRC fixed so the parser itself meets the end. */
static inline void forge_expect_cuts_fail(const forge_format *f, const unsigned char *bytes, size_t size)
{
    char name[32], quoted[40];
    snprintf(name, sizeof name, "cut.%s", f->ext);
    snprintf(quoted, sizeof quoted, "'%s'", name);
    unsigned char *cut = malloc(size ? size : 1);
    int cut_fail = 0;
    for (size_t k = 0; bytes && cut && k < size; k++) {
        for (int fixed = 0; fixed < 2; fixed++) {
            if (fixed && k < FORGE_HEADER_BYTES + FORGE_TRAILER_BYTES)
                continue;
            memcpy(cut, bytes, k);
            if (fixed)
                forge_fix(cut, k, f->payload_at);
            void *obj = NULL;
            asp_error e = {0};
            int rc = f->load(cut, k, name, NULL, &obj, &e);
            if (rc != ASP_EFORMAT || obj != NULL || !strstr(e.msg, quoted)) {
                if (cut_fail++ < 5)
                    CHECK_MSG(0, "%s: cut at %zu (fixed %d): rc %d, '%s'", f->ext, k, fixed, rc, e.msg);
                if (obj)
                    f->destroy(obj);
            }
        }
    }
    CHECK_MSG(cut && cut_fail == 0, "%s: %d cuts did not fail cleanly", f->ext, cut_fail);
    free(cut);
}

/*
 * Writes value (width bytes) at byte `at` of a copy of the file, fixes the CRC
 * and loads it: ASP_EFORMAT naming the file, the field and what was expected,
 * the output unchanged, and no allocation beyond a few times the file.
 */
static inline void forge_expect_refused(const forge_format *f, const unsigned char *bytes, size_t size, size_t at,
                                        uint64_t value, int width, const char *field)
{
    unsigned char *b = malloc(size ? size : 1);
    CHECK(b && size >= at + (size_t)width);
    if (!b || size < at + (size_t)width) {
        free(b);
        return;
    }
    memcpy(b, bytes, size);
    forge_put_le(b + at, value, width);
    forge_fix(b, size, f->payload_at);
    char name[32];
    snprintf(name, sizeof name, "forged.%s", f->ext);
    forge_tally t = {0};
    asp_context ctx = {.threads = 1, .allocator = {forge_tally_alloc, forge_tally_free, &t}};
    asp_error err = {0};
    void *obj = &t; /* a sentinel: must stay unchanged */
    int rc = f->load(b, size, name, &ctx, &obj, &err);
    CHECK_MSG(rc == ASP_EFORMAT && obj == &t, "%s: rc %d", field, rc);
    CHECK_MSG(strstr(err.msg, name) && strstr(err.msg, field) && strstr(err.msg, "expected"),
              "message '%s' lacks the file, '%s' or what was expected", err.msg, field);
    CHECK_MSG(t.total <= 4 * size + 65536, "%s: %zu bytes allocated for a %zu-byte file", field, t.total, size);
    free(b);
}

#endif
