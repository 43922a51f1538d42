/*
 * The one check every reader makes before opening a path for reading (issue
 * #13): the path names a regular file. fopen blocks on a FIFO until a writer
 * comes and opens a directory on Linux, so both are refused by name first.
 * Not public API.
 */
#ifndef ASP_UTIL_REGULAR_FILE_H
#define ASP_UTIL_REGULAR_FILE_H

#include <stdio.h>

#include "amgsplat/core.h"

/*
 * 0 when path is a regular file (after following links). Otherwise fails
 * with ASP_EIO: "cannot open '<path>': <strerror>" when stat fails, "cannot
 * read '<path>': is a directory, expected a file" or "cannot read '<path>':
 * not a regular file (a FIFO|socket|device)".
 */
int asp__regular_file_check(const char *path, asp_error *err);

/*
 * asp__regular_file_check, then the file opened for reading in binary mode;
 * NULL with err filled on failure. The open is non-blocking and the opened
 * descriptor is checked again, so a FIFO that replaces the file between the
 * check and the open is refused too, never waited on.
 */
FILE *asp__regular_file_open(const char *path, asp_error *err);

/*
 * The whole of a small text file (scene lists, JSON): asp__regular_file_open,
 * then read into a new NUL-terminated buffer (*text, free() it; *len bytes
 * without the NUL). Fails with ASP_EFORMAT "'<path>': <what> over <max> MiB"
 * when the file is larger than max bytes, ASP_EIO, ASP_ENOMEM; *text is NULL
 * on failure.
 */
int asp__text_file_read(const char *path, size_t max, const char *what, char **text, size_t *len, asp_error *err);

/*
 * dir exists as a directory afterwards: created (mode 0777 less the umask) or already there.
 * Fails with ASP_EIO "cannot create <what> '<dir>': <strerror>" ("a file of that name exists"
 * when one is in the way).
 */
int asp__dir_ensure(const char *dir, const char *what, asp_error *err);

#endif
