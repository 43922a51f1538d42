/*
 * Refusing what is not a regular file before a reader opens it (see
 * regular_file.h). One place, so every reader says the same thing.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
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
