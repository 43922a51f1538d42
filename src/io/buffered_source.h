/*
 * Buffered input for the point readers: a window over a file (big fread
 * chunks, 64-bit offsets) or over caller memory, with line access for
 * headers and text bodies. Private to src/io; not public API.
 */
#ifndef ASP_IO_BUFFERED_SOURCE_H
#define ASP_IO_BUFFERED_SOURCE_H

#include <stdint.h>
#include <stdio.h>

#include "amgsplat/core.h"

typedef struct asp__src {
    FILE *fp;             /* file mode while bytes remain unread; NULL for memory */
    uint8_t *buf;         /* owned window (file mode, or a slurped stream) */
    size_t cap;           /* bytes allocated at buf */
    const uint8_t *data;  /* window base: buf or the caller's memory */
    size_t pos, len;      /* unread window bytes are data[pos, len) */
    uint64_t base;        /* input offset of data[0] */
    uint64_t size;        /* total input size in bytes */
    int io_errno;         /* errno of a failed read, else 0 */
    int nomem;            /* a window could not grow */
    int cr_lines;         /* asp__src_line also ends a line at a lone CR (old Mac text; set by the text readers) */
    int unterminated;     /* the line asp__src_line returned last ended at the end of the input, without '\n' */
    const asp_context *ctx;
    const char *name;     /* for messages */
} asp__src;

/*
 * Opens path for reading. Regular files are read in chunks; streams that
 * cannot seek (pipes) are read whole first, so the size is always known
 * before any count in the file is trusted. Returns 0, ASP_EIO or ASP_ENOMEM.
 */
int asp__src_open_file(asp__src *s, const char *path, const asp_context *ctx, asp_error *err);
/* Wraps caller memory (borrowed until close). Never fails. */
void asp__src_open_memory(asp__src *s, const void *data, size_t size, const char *name, const asp_context *ctx);
/* Closes the file and frees the window; safe twice. */
void asp__src_close(asp__src *s);

/*
 * Makes at least n unread bytes available at asp__src_ptr and returns how
 * many are available: fewer than n only at the end of the input, after a read
 * error (io_errno set) or when the window could not grow (nomem set).
 */
size_t asp__src_fill(asp__src *s, size_t n);

/*
 * Next line: *line points into the window (valid until the next fill or
 * line call), *len excludes the '\n' and a trailing '\r'. Returns 1 for a
 * line, 0 at the end of input, -1 when a line exceeds max_len bytes, -2 on a
 * read error or out of memory.
 */
int asp__src_line(asp__src *s, size_t max_len, const char **line, size_t *len);

static inline const uint8_t *asp__src_ptr(const asp__src *s) { return s->data + s->pos; }
static inline uint64_t asp__src_offset(const asp__src *s) { return s->base + s->pos; }
static inline uint64_t asp__src_remaining(const asp__src *s) { return s->size - (s->base + s->pos); }
static inline void asp__src_skip(asp__src *s, size_t n) { s->pos += n; }

#endif
