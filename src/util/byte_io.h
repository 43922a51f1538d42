/*
 * Little-endian byte I/O for the checksummed binary formats (.amg, .dps):
 * fixed-width values written through the CRC writer and committed with their
 * CRC-32 trailer, a bounds-checked reader over the file bytes whose errors
 * name the file and the byte offset, and whole-file reading. Not public API.
 */
#ifndef ASP_UTIL_BYTE_IO_H
#define ASP_UTIL_BYTE_IO_H

#include <stddef.h>
#include <stdint.h>

#include "amgsplat/core.h"
#include "util/atomic_file.h"
#include "util/checksum.h"

/* ---- writing: explicit little-endian bytes, so a format does not depend on the host ---- */

void asp__put_u32(asp__crc_writer *w, uint32_t v);
void asp__put_u64(asp__crc_writer *w, uint64_t v);
void asp__put_f32(asp__crc_writer *w, float v);
void asp__put_f64(asp__crc_writer *w, double v);

/* The same little-endian bytes stored at p, for headers assembled in memory (.hier, GLB). */
void asp__store_u32(uint8_t *p, uint32_t v);
void asp__store_u64(uint8_t *p, uint64_t v);
void asp__store_f64(uint8_t *p, double v);

/*
 * Appends the CRC-32 trailer (of everything written before it), reads the
 * file back with check (asp__atomic_commit_checked; NULL: no check) and
 * renames f into place. After any write failure removes the temporary
 * instead and reports "cannot write '<path>': <strerror>" (ASP_EIO).
 */
int asp__byte_commit(asp__crc_writer *w, asp__atomic_file *f, const char *path, asp__atomic_check check, void *user,
                     asp_error *err);

/* ---- reading ---- */

/*
 * The file bytes, consumed front to back (at is the next one). Offsets are
 * size_t, and a format compares every count with asp__byte_left() (by
 * division, so nothing overflows) before it sizes an allocation.
 */
typedef struct asp__byte_reader {
    const uint8_t *buf;
    size_t size, at; /* size excludes the CRC trailer once it has been checked */
    const char *path;
    asp_error *err;
} asp__byte_reader;

/* Bytes between at and size. */
size_t asp__byte_left(const asp__byte_reader *r);

/*
 * Copies len bytes to dst and advances, or fails (ASP_EFORMAT) with "cannot
 * read '<path>': byte <at>: truncated in <what> (<len> bytes needed, <n> left)".
 */
int asp__byte_take(asp__byte_reader *r, void *dst, size_t len, const char *what);

/* Fails with "cannot read '<path>': byte <at>: <what>" (ASP_EFORMAT); returns the code. */
int asp__byte_bad(const asp__byte_reader *r, const char *what);

/*
 * Little-endian values read at r->at, which advances past them. Unchecked:
 * the caller has made sure that enough bytes are left.
 */
uint32_t asp__get_u32(asp__byte_reader *r);
uint64_t asp__get_u64(asp__byte_reader *r);
float asp__get_f32(asp__byte_reader *r);
double asp__get_f64(asp__byte_reader *r);

/*
 * Reads the whole file at path into *buf (allocated through ctx with one
 * spare byte, so an empty file still gets a buffer; free with asp_free(ctx,
 * *buf)) and its length into *size. Errors: ASP_EIO (open, seek or read
 * failed; a directory, FIFO or other file that is not regular, refused
 * before opening so that a FIFO never blocks), ASP_ENOMEM (the file does not fit in memory); on failure *buf and
 * *size stay unchanged.
 */
int asp__byte_slurp(const char *path, const asp_context *ctx, uint8_t **buf, size_t *size, asp_error *err);

#endif
