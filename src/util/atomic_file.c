/*
 * Atomic output files (see atomic_file.h): temporary name in the same
 * directory, then rename(2), which replaces the target in one step.
 */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/banned.h"

/*
 * Removes "<path>.tmp.<pid>" files that a killed run left (issue #13: 2-15 MB
 * each, that nothing removed): only those whose process no longer exists
 * (kill(pid, 0) fails with ESRCH), so a concurrent writer's file is kept.
 * Best effort: a directory that cannot be listed is left alone.
 */
static void remove_stale(const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (slash)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path + (slash == path)), path);
    else
        snprintf(dir, sizeof dir, ".");
    const char *base = slash ? slash + 1 : path;
    size_t bl = strlen(base);
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *n = e->d_name;
        if (strncmp(n, base, bl) != 0 || strncmp(n + bl, ".tmp.", 5) != 0)
            continue;
        char *end = NULL;
        long pid = strtol(n + bl + 5, &end, 10);
        if (!end || *end || pid <= 0 || pid == (long)getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        char full[4096 + 256];
        snprintf(full, sizeof full, "%s/%s", dir, n);
        remove(full);
    }
    closedir(d);
}

int asp__atomic_open(asp__atomic_file *f, const char *path, asp_error *err)
{
    memset(f, 0, sizeof *f);
    if (!path || !*path)
        return asp_error_set(err, ASP_EINVAL, "empty output path");
    if (strlen(path) >= sizeof f->path)
        return asp_error_set(err, ASP_EINVAL, "output path too long: '%.64s...'", path);
    snprintf(f->path, sizeof f->path, "%s", path);
    snprintf(f->tmp, sizeof f->tmp, "%s.tmp.%ld", path, (long)getpid());
    remove_stale(path);
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
