/*
 * Little-endian byte I/O of the binary formats (see byte_io.h). Values are
 * assembled byte by byte rather than copied, so the bytes on disk are the
 * same on any host.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "util/byte_io.h"
#include "util/regular_file.h"
#include "util/banned.h"

void asp__store_u32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

void asp__store_u64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

void asp__store_f64(uint8_t *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    asp__store_u64(p, u);
}

void asp__put_u32(asp__crc_writer *w, uint32_t v)
{
    uint8_t b[4];
    for (int k = 0; k < 4; k++)
        b[k] = (uint8_t)(v >> (8 * k));
    asp__crc_put(w, b, 4);
}

void asp__put_u64(asp__crc_writer *w, uint64_t v)
{
    asp__put_u32(w, (uint32_t)v);
    asp__put_u32(w, (uint32_t)(v >> 32));
}

void asp__put_f32(asp__crc_writer *w, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    asp__put_u32(w, u);
}

void asp__put_f64(asp__crc_writer *w, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    asp__put_u64(w, u);
}

int asp__byte_commit(asp__crc_writer *w, asp__atomic_file *f, const char *path, asp__atomic_check check, void *user,
                     asp_error *err)
{
    asp__put_u32(w, w->crc);
    if (w->failed) {
        int e = errno;
        asp__atomic_abort(f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", path, strerror(e));
    }
    return asp__atomic_commit_checked(f, check, user, err);
}

size_t asp__byte_left(const asp__byte_reader *r)
{
    return r->size - r->at;
}

int asp__byte_take(asp__byte_reader *r, void *dst, size_t len, const char *what)
{
    if (len > asp__byte_left(r))
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': byte %zu: truncated in %s (%zu bytes needed, %zu left)", r->path, r->at,
                             what, len, asp__byte_left(r));
    memcpy(dst, r->buf + r->at, len);
    r->at += len;
    return 0;
}

int asp__byte_bad(const asp__byte_reader *r, const char *what)
{
    return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': byte %zu: %s", r->path, r->at, what);
}

uint32_t asp__get_u32(asp__byte_reader *r)
{
    uint32_t v = 0;
    for (int k = 0; k < 4; k++)
        v |= (uint32_t)r->buf[r->at + k] << (8 * k);
    r->at += 4;
    return v;
}

uint64_t asp__get_u64(asp__byte_reader *r)
{
    const uint64_t lo = asp__get_u32(r); // its own statement: two calls in one expression are unsequenced
    return lo | (uint64_t)asp__get_u32(r) << 32;
}

float asp__get_f32(asp__byte_reader *r)
{
    uint32_t u = asp__get_u32(r);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

double asp__get_f64(asp__byte_reader *r)
{
    uint64_t u = asp__get_u64(r);
    double f;
    memcpy(&f, &u, 8);
    return f;
}

int asp__byte_slurp(const char *path, const asp_context *ctx, uint8_t **buf, size_t *size, asp_error *err)
{
    // checked before opening: fopen blocks on a FIFO until a writer comes, and a directory opens on Linux
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    off_t end = -1;
    if (fseeko(fp, 0, SEEK_END) == 0)
        end = ftello(fp);
    if (end < 0 || fseeko(fp, 0, SEEK_SET) != 0) {
        int e = errno;
        fclose(fp);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    // off_t may be wider than size_t (32-bit hosts), and n + 1 below must not wrap
    if ((uint64_t)end >= SIZE_MAX) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': %llu bytes do not fit in memory", path,
                             (unsigned long long)end);
    }
    const size_t n = (size_t)end;
    uint8_t *b = asp_alloc(ctx, n + 1);
    if (!b) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory for %zu bytes", path, n);
    }
    const size_t got = fread(b, 1, n, fp);
    const int failed = got != n || ferror(fp);
    const int e = ferror(fp) ? errno : 0; // before fclose, which may set errno
    fclose(fp);
    if (failed) {
        asp_free(ctx, b);
        if (e)
            return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
        return asp_error_set(err, ASP_EIO, "cannot read '%s': short read (%zu of %zu bytes): the file shrank while "
                             "reading", path, got, n);
    }
    *buf = b;
    *size = n;
    return 0;
}
