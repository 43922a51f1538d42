/*
 * Buffered input for the point readers (see buffered_source.h): whole-chunk
 * fread into a reusable window, so parsers never call fread per value and
 * binary PLY reads run at memory speed.
 */
#define _FILE_OFFSET_BITS 64
#include <errno.h>
#include <string.h>
#include <sys/types.h>

#include "io/buffered_source.h"
#include "util/regular_file.h"
#include "util/banned.h"

enum { WINDOW_BYTES = 4 << 20 };

static int slurp(asp__src *s, FILE *fp, asp_error *err)
{
    size_t cap = 1 << 16, len = 0;
    uint8_t *buf = asp_alloc(s->ctx, cap);
    for (;;) {
        if (!buf)
            return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", s->name);
        size_t got = fread(buf + len, 1, cap - len, fp);
        len += got;
        if (got == 0) {
            if (ferror(fp)) {
                int e = errno;
                asp_free(s->ctx, buf);
                return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", s->name, strerror(e ? e : EIO));
            }
            break;
        }
        if (len == cap) {
            uint8_t *grown = cap <= SIZE_MAX / 2 ? asp_realloc(s->ctx, buf, cap, 2 * cap) : NULL;
            if (!grown)
                asp_free(s->ctx, buf);
            buf = grown;
            cap *= 2;
        }
    }
    s->buf = buf;
    s->cap = cap;
    s->data = buf;
    s->len = len;
    s->size = len;
    return 0;
}

int asp__src_open_file(asp__src *s, const char *path, const asp_context *ctx, asp_error *err)
{
    memset(s, 0, sizeof *s);
    s->ctx = ctx;
    s->name = path;
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    off_t size = -1;
    if (fseeko(fp, 0, SEEK_END) == 0) {
        size = ftello(fp);
        if (fseeko(fp, 0, SEEK_SET) != 0)
            size = -1;
    }
    if (size < 0) {
        clearerr(fp);
        int rc = slurp(s, fp, err);
        fclose(fp);
        return rc;
    }
    s->size = (uint64_t)size;
    s->cap = s->size < WINDOW_BYTES ? (size_t)s->size + 1 : WINDOW_BYTES;
    s->buf = asp_alloc(ctx, s->cap);
    if (!s->buf) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", path);
    }
    s->data = s->buf;
    s->fp = fp;
    return 0;
}

void asp__src_open_memory(asp__src *s, const void *data, size_t size, const char *name, const asp_context *ctx)
{
    memset(s, 0, sizeof *s);
    s->ctx = ctx;
    s->name = name ? name : "<memory>";
    s->data = data;
    s->len = size;
    s->size = size;
}

void asp__src_close(asp__src *s)
{
    if (s->fp)
        fclose(s->fp);
    s->fp = NULL;
    asp_free(s->ctx, s->buf);
    s->buf = NULL;
    s->data = NULL;
    s->pos = s->len = 0;
}

size_t asp__src_fill(asp__src *s, size_t n)
{
    size_t avail = s->len - s->pos;
    if (avail >= n || !s->fp)
        return avail;
    memmove(s->buf, s->buf + s->pos, avail);
    s->base += s->pos;
    s->pos = 0;
    s->len = avail;
    if (n > s->cap) {
        size_t want = n > s->cap * 2 ? n : s->cap * 2;
        uint8_t *grown = asp_realloc(s->ctx, s->buf, s->cap, want);
        if (!grown) {
            s->nomem = 1;
            return avail;
        }
        s->buf = grown;
        s->data = grown;
        s->cap = want;
    }
    /* fill the whole window: few large reads keep binary parsing at memory speed */
    while (s->len < s->cap) {
        size_t got = fread(s->buf + s->len, 1, s->cap - s->len, s->fp);
        s->len += got;
        if (got == 0) {
            if (ferror(s->fp))
                s->io_errno = errno ? errno : EIO;
            fclose(s->fp);
            s->fp = NULL;
            break;
        }
    }
    return s->len - s->pos;
}

/* The first '\n', or with cr the first '\n' or '\r', in p[0..n). */
static const uint8_t *find_eol(const uint8_t *p, size_t n, int cr)
{
    if (!cr)
        return memchr(p, '\n', n);
    for (size_t i = 0; i < n; i++)
        if (p[i] == '\n' || p[i] == '\r')
            return p + i;
    return NULL;
}

int asp__src_line(asp__src *s, size_t max_len, const char **line, size_t *len)
{
    size_t scanned = 0;
    for (;;) {
        size_t avail = s->len - s->pos;
        const uint8_t *p = s->data + s->pos;
        const uint8_t *nl = avail > scanned ? find_eol(p + scanned, avail - scanned, s->cr_lines) : NULL;
        // a CR last in the window may be the first half of a CRLF: read on before deciding
        int split_crlf = nl && *nl == '\r' && nl + 1 == p + avail && s->fp && asp__src_remaining(s) > avail;
        if (split_crlf)
            nl = NULL;
        if (nl || (!s->fp && avail > 0) || avail > max_len) {
            size_t n = nl ? (size_t)(nl - p) : avail;
            if (n > max_len)
                return -1;
            size_t eol = !nl ? 0 : (*nl == '\r' && n + 1 < avail && nl[1] == '\n') ? 2 : 1;
            s->pos += n + eol;
            s->unterminated = !nl;
            if (n > 0 && p[n - 1] == '\r')
                n--;
            *line = (const char *)p;
            *len = n;
            return 1;
        }
        if (!s->fp)
            return s->io_errno || s->nomem ? -2 : 0;
        scanned = split_crlf ? avail - 1 : avail;
        size_t want = avail + 65536;
        uint64_t rem = asp__src_remaining(s);
        if (want > rem)
            want = rem > avail ? (size_t)rem : avail + 1;
        if (asp__src_fill(s, want) <= avail && (s->io_errno || s->nomem))
            return -2;
    }
}
