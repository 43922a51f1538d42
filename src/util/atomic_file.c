/*
 * Atomic output files (see atomic_file.h): temporary name in the same
 * directory, then rename(2), which replaces the target in one step.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/banned.h"

int asp__atomic_open(asp__atomic_file *f, const char *path, asp_error *err)
{
    memset(f, 0, sizeof *f);
    if (!path || !*path)
        return asp_error_set(err, ASP_EINVAL, "empty output path");
    if (strlen(path) >= sizeof f->path)
        return asp_error_set(err, ASP_EINVAL, "output path too long: '%.64s...'", path);
    snprintf(f->path, sizeof f->path, "%s", path);
    snprintf(f->tmp, sizeof f->tmp, "%s.tmp.%ld", path, (long)getpid());
    f->fp = fopen(f->tmp, "wb");
    if (!f->fp)
        return asp_error_set(err, ASP_EIO, "cannot create '%s': %s", f->tmp, strerror(errno));
    return 0;
}

int asp__atomic_commit(asp__atomic_file *f, asp_error *err)
{
    if (!f->fp)
        return asp_error_set(err, ASP_EIO, "cannot write '%s': file not open", f->path);
    int bad = ferror(f->fp);
    if (fflush(f->fp) != 0 || bad) {
        int e = errno;
        asp__atomic_abort(f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", f->path, strerror(e ? e : EIO));
    }
    fsync(fileno(f->fp));
    if (fclose(f->fp) != 0) {
        int e = errno;
        f->fp = NULL;
        remove(f->tmp);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", f->path, strerror(e));
    }
    f->fp = NULL;
    if (rename(f->tmp, f->path) != 0) {
        int e = errno;
        remove(f->tmp);
        return asp_error_set(err, ASP_EIO, "cannot rename '%s' to '%s': %s", f->tmp, f->path, strerror(e));
    }
    return 0;
}

void asp__atomic_abort(asp__atomic_file *f)
{
    if (f->fp) {
        fclose(f->fp);
        f->fp = NULL;
    }
    if (f->tmp[0])
        remove(f->tmp);
    f->tmp[0] = '\0';
}
