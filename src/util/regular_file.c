/*
 * Refusing what is not a regular file before a reader opens it (see
 * regular_file.h). One place, so every reader says the same thing.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "util/regular_file.h"
#include "util/banned.h"

static const char *what_it_is(mode_t m)
{
    if (S_ISDIR(m))
        return "is a directory, expected a file";
    if (S_ISFIFO(m))
        return "not a regular file (a FIFO)";
    if (S_ISSOCK(m))
        return "not a regular file (a socket)";
    if (S_ISCHR(m) || S_ISBLK(m))
        return "not a regular file (a device)";
    return "not a regular file";
}

int asp__regular_file_check(const char *path, asp_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, what_it_is(st.st_mode));
    return 0;
}

FILE *asp__regular_file_open(const char *path, asp_error *err)
{
    if (asp__regular_file_check(path, err))
        return NULL;
    // O_NONBLOCK: a FIFO swapped in after the check must not wait for a writer; fstat then refuses it
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    if (fd < 0) {
        asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
        return NULL;
    }
    struct stat st;
    const char *bad = fstat(fd, &st) != 0 ? strerror(errno) : !S_ISREG(st.st_mode) ? what_it_is(st.st_mode) : NULL;
    if (bad) {
        asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, bad);
        close(fd);
        return NULL;
    }
    // a regular file never blocks, but leave the descriptor as fopen would have made it
    int flags = fcntl(fd, F_GETFL);
    if (flags >= 0)
        fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    FILE *fp = fdopen(fd, "rb");
    if (!fp) {
        asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
        close(fd);
    }
    return fp;
}

int asp__text_file_read(const char *path, size_t max, const char *what, char **text, size_t *len, asp_error *err)
{
    *text = NULL;
    *len = 0;
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return err ? err->code : ASP_EIO;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int rc = 0;
    for (;;) {
        if (n > max)
            break; /* reported below */
        if (n + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 8192;
            char *t = realloc(buf, cap);
            if (!t) {
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", path);
                break;
            }
            buf = t;
        }
        size_t got = fread(buf + n, 1, 4096, fp);
        n += got;
        if (got < 4096) {
            if (ferror(fp))
                rc = asp_error_set(err, ASP_EIO, "cannot read '%s'", path);
            break;
        }
    }
    fclose(fp);
    if (!rc && n > max)
        rc = asp_error_set(err, ASP_EFORMAT, "'%s': %s over %zu MiB", path, what, max >> 20);
    if (rc) {
        free(buf);
        return rc;
    }
    buf[n] = 0;
    *text = buf;
    *len = n;
    return 0;
}

int asp__dir_ensure(const char *dir, const char *what, asp_error *err)
{
    struct stat st;
    if (mkdir(dir, 0777) == 0)
        return 0;
    if (errno == EEXIST && stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    return asp_error_set(err, ASP_EIO, "cannot create %s '%s': %s", what, dir,
                         errno == EEXIST ? "a file of that name exists" : strerror(errno));
}
