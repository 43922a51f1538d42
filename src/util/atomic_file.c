/*
 * Atomic output files (see atomic_file.h): temporary name in the same
 * directory, then rename(2), which replaces the target in one step. The
 * temporaries being written are kept in a fixed table that a signal handler
 * can walk without locks or allocation, and that an output batch uses to
 * find the renames it deferred (issue #13).
 */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/output.h"
#include "util/atomic_file.h"
#include "util/banned.h"

/*
 * The table of live temporaries. A signal may arrive on any thread at any
 * moment, so the handler may only read what a slot's state publishes: the
 * writer fills tmp first, then stores LIVE with release order; the handler
 * loads the state with acquire order and calls unlink(2), which is
 * async-signal-safe (POSIX.1-2008 2.4.3). This is process-wide state by
 * nature (signals are), the one exception to STYLE.md 7.
 */
enum { LIVE_MAX = 128, SLOT_FREE = 0, SLOT_CLAIMED = 1, SLOT_LIVE = 2 };
typedef struct live_slot {
    atomic_int state;
    unsigned batch;   /* the output batch that owns the rename, 0 for none */
    size_t path_len;  /* tmp is path + ".tmp.<pid>": the target is its first path_len bytes */
    char tmp[4096 + 32];
} live_slot;
static live_slot live[LIVE_MAX];

static const int caught[] = {SIGINT, SIGTERM, SIGHUP};
static struct sigaction previous[3];
static atomic_int handlers_installed;

static void remove_live_temporaries(void)
{
    for (int i = 0; i < LIVE_MAX; i++)
        if (atomic_load_explicit(&live[i].state, memory_order_acquire) == SLOT_LIVE)
            unlink(live[i].tmp);
}

/* Removes every live temporary, then lets the signal do what it would have done without us. */
static void on_signal(int sig, siginfo_t *info, void *uctx)
{
    int saved = errno;
    remove_live_temporaries();
    for (int k = 0; k < 3; k++) {
        if (caught[k] != sig)
            continue;
        const struct sigaction *old = &previous[k];
        if (old->sa_flags & SA_SIGINFO) {
            old->sa_sigaction(sig, info, uctx);
        } else if (old->sa_handler != SIG_DFL && old->sa_handler != SIG_IGN) {
            old->sa_handler(sig);
        } else {
            // the default action (terminate) once this handler returns: the signal is blocked until then
            signal(sig, SIG_DFL);
            raise(sig);
        }
    }
    errno = saved;
}

/*
 * Installed once, on the first output. A signal the program ignores (nohup's
 * SIGHUP) stays ignored; a handler the program set is called after ours.
 */
static void install_handlers(void)
{
    int expected = 0;
    if (!atomic_compare_exchange_strong(&handlers_installed, &expected, 1))
        return;
    for (int k = 0; k < 3; k++) {
        struct sigaction old;
        if (sigaction(caught[k], NULL, &old) != 0 || (!(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_IGN))
            continue;
        previous[k] = old;
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_sigaction = on_signal;
        sa.sa_flags = SA_SIGINFO | SA_RESTART;
        sigfillset(&sa.sa_mask); // no second signal runs the handler while it walks the table
        sigaction(caught[k], &sa, NULL);
    }
}

/* The output batch open on this thread (its id), 0 for none; ids never repeat. */
static _Thread_local unsigned thread_batch;
static atomic_uint next_batch = 1;

static int claim_slot(const char *tmp, size_t path_len)
{
    for (int i = 0; i < LIVE_MAX; i++) {
        int expected = SLOT_FREE;
        if (atomic_compare_exchange_strong(&live[i].state, &expected, SLOT_CLAIMED)) {
            snprintf(live[i].tmp, sizeof live[i].tmp, "%s", tmp);
            live[i].path_len = path_len;
            live[i].batch = thread_batch;
            atomic_store_explicit(&live[i].state, SLOT_LIVE, memory_order_release);
            return i;
        }
    }
    return -1;
}

static void release_slot(int i)
{
    if (i >= 0 && i < LIVE_MAX)
        atomic_store_explicit(&live[i].state, SLOT_FREE, memory_order_release);
}

size_t asp__atomic_live_count(void)
{
    size_t n = 0;
    for (int i = 0; i < LIVE_MAX; i++)
        n += atomic_load(&live[i].state) == SLOT_LIVE;
    return n;
}

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

/*
 * Files read as dependencies (issue #31: `render m.obj -o T.png` overwrote
 * the mesh's own texture T.png; the CLI's output-is-input check sees only
 * the files named on the command line). A fixed table of counted entries,
 * one count per object that holds what was read (a mesh's texture, until
 * asp_mesh_destroy), under a lock: loads may run on several threads.
 */
enum { PROTECTED_MAX = 256 };
static struct {
    dev_t dev;
    ino_t ino;
    unsigned refs;
    char role[40];
} protected_files[PROTECTED_MAX];
static size_t protected_count;
static atomic_flag protected_lock = ATOMIC_FLAG_INIT;

void asp__atomic_protect(const char *path, const char *role)
{
    struct stat st;
    if (!path || stat(path, &st) != 0)
        return;
    while (atomic_flag_test_and_set_explicit(&protected_lock, memory_order_acquire))
        ;
    size_t i = 0;
    while (i < protected_count && !(protected_files[i].dev == st.st_dev && protected_files[i].ino == st.st_ino))
        i++;
    if (i == protected_count && i < PROTECTED_MAX) {
        protected_files[i].dev = st.st_dev;
        protected_files[i].ino = st.st_ino;
        protected_files[i].refs = 0;
        snprintf(protected_files[i].role, sizeof protected_files[i].role, "%s", role);
        protected_count++;
    }
    if (i < protected_count)
        protected_files[i].refs++;
    atomic_flag_clear_explicit(&protected_lock, memory_order_release);
}

void asp__atomic_unprotect(const char *path)
{
    struct stat st;
    if (!path || stat(path, &st) != 0)
        return;
    while (atomic_flag_test_and_set_explicit(&protected_lock, memory_order_acquire))
        ;
    for (size_t i = 0; i < protected_count; i++)
        if (protected_files[i].dev == st.st_dev && protected_files[i].ino == st.st_ino) {
            if (--protected_files[i].refs == 0)
                protected_files[i] = protected_files[--protected_count];
            break;
        }
    atomic_flag_clear_explicit(&protected_lock, memory_order_release);
}

/* The role of path when it was read as a dependency, else NULL. */
static const char *protected_role(const struct stat *st)
{
    const char *role = NULL;
    while (atomic_flag_test_and_set_explicit(&protected_lock, memory_order_acquire))
        ;
    for (size_t i = 0; i < protected_count && !role; i++)
        if (protected_files[i].dev == st->st_dev && protected_files[i].ino == st->st_ino)
            role = protected_files[i].role;
    atomic_flag_clear_explicit(&protected_lock, memory_order_release);
    return role;
}

int asp__atomic_open(asp__atomic_file *f, const char *path, asp_error *err)
{
    memset(f, 0, sizeof *f);
    f->slot = -1;
    if (!path || !*path)
        return asp_error_set(err, ASP_EINVAL, "empty output path");
    if (strlen(path) >= sizeof f->path)
        return asp_error_set(err, ASP_EINVAL, "output path too long: '%.64s...'", path);
    // refused now, not at the rename: inside an output batch the renames come after every file is written
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return asp_error_set(err, ASP_EIO, "cannot write '%s': is a directory", path);
    const char *role = stat(path, &st) == 0 ? protected_role(&st) : NULL;
    if (role)
        return asp_error_set(err, ASP_EINVAL, "cannot write '%s': it was read as %s; write to another file", path,
                             role);
    snprintf(f->path, sizeof f->path, "%s", path);
    snprintf(f->tmp, sizeof f->tmp, "%s.tmp.%ld", path, (long)getpid());
    install_handlers();
    remove_stale(path);
    // registered before it exists: a signal between fopen and registration would leave it behind
    f->slot = claim_slot(f->tmp, strlen(path));
    if (f->slot < 0) {
        f->tmp[0] = '\0';
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %d outputs are already being written", path, LIVE_MAX);
    }
    f->fp = fopen(f->tmp, "wb");
    if (!f->fp) {
        int e = errno;
        release_slot(f->slot);
        f->slot = -1;
        return asp_error_set(err, ASP_EIO, "cannot create '%s': %s", f->tmp, strerror(e));
    }
    return 0;
}

/* Flushes, syncs and closes the temporary; on failure removes it. */
static int finish_temporary(asp__atomic_file *f, asp_error *err)
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
        asp__atomic_abort(f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", f->path, strerror(e));
    }
    f->fp = NULL;
    return 0;
}

static int publish(asp__atomic_file *f, asp_error *err)
{
    // inside an output batch the rename waits for asp_output_batch_commit; the slot keeps the temporary
    if (f->slot >= 0 && live[f->slot].batch && live[f->slot].batch == thread_batch) {
        f->slot = -1;
        f->tmp[0] = '\0';
        return 0;
    }
    if (rename(f->tmp, f->path) != 0) {
        int e = errno;
        asp__atomic_abort(f);
        return asp_error_set(err, ASP_EIO, "cannot rename '%s.tmp.%ld' to '%s': %s", f->path, (long)getpid(),
                             f->path, strerror(e));
    }
    release_slot(f->slot);
    f->slot = -1;
    f->tmp[0] = '\0';
    return 0;
}

int asp__atomic_commit(asp__atomic_file *f, asp_error *err)
{
    int rc = finish_temporary(f, err);
    return rc ? rc : publish(f, err);
}

int asp__atomic_commit_checked(asp__atomic_file *f, asp__atomic_check check, void *user, asp_error *err)
{
    int rc = finish_temporary(f, err);
    if (rc)
        return rc;
    asp_error why = {0};
    if (check && (rc = check(f->tmp, user, &why)) != 0) {
        asp__atomic_abort(f);
        return asp_error_set(err, rc, "internal error: the written '%s' does not read back: %s", f->path, why.msg);
    }
    return publish(f, err);
}

void asp__atomic_abort(asp__atomic_file *f)
{
    if (f->fp) {
        fclose(f->fp);
        f->fp = NULL;
    }
    // a zeroed, never opened file has no temporary and no slot of its own (slot 0 may be another's)
    if (f->tmp[0]) {
        remove(f->tmp);
        release_slot(f->slot);
    }
    f->tmp[0] = '\0';
    f->slot = -1;
}

/* ---- output batches (amgsplat/output.h) ---- */

/*
 * Batches nest (a command's batch holds asp_mesh_save's OBJ+MTL+PNG batch):
 * only the outermost commit renames. An inner abort removes the files of the
 * whole batch and marks it failed, so the outer commit cannot publish half.
 */
static _Thread_local unsigned thread_depth;
static _Thread_local int thread_failed;

int asp_output_batch_begin(asp_error *err)
{
    if (thread_depth == UINT32_MAX)
        return asp_error_set(err, ASP_EINVAL, "output batches nested too deeply");
    if (thread_depth++ == 0) {
        thread_failed = 0;
        thread_batch = atomic_fetch_add(&next_batch, 1);
        if (!thread_batch) // after 2^32 batches: 0 means "none"
            thread_batch = atomic_fetch_add(&next_batch, 1);
    }
    return 0;
}

static void drop_batch(unsigned id)
{
    for (int i = 0; i < LIVE_MAX; i++)
        if (atomic_load(&live[i].state) == SLOT_LIVE && live[i].batch == id) {
            unlink(live[i].tmp);
            release_slot(i);
        }
}

int asp_output_batch_commit(asp_error *err)
{
    if (!thread_depth)
        return asp_error_set(err, ASP_EINVAL, "no output batch is open on this thread");
    if (--thread_depth)
        return thread_failed ? asp_error_set(err, ASP_ECANCELED, "the output batch was aborted") : 0;
    const unsigned id = thread_batch;
    thread_batch = 0;
    if (thread_failed)
        return asp_error_set(err, ASP_ECANCELED, "the output batch was aborted: no output written");
    size_t done = 0;
    for (int i = 0; i < LIVE_MAX; i++) {
        live_slot *s = &live[i];
        if (atomic_load(&s->state) != SLOT_LIVE || s->batch != id)
            continue;
        char path[sizeof s->tmp];
        snprintf(path, sizeof path, "%.*s", (int)s->path_len, s->tmp);
        if (rename(s->tmp, path) != 0) {
            int e = errno;
            drop_batch(id);
            // renames cannot be undone: say how many outputs did appear
            return asp_error_set(err, ASP_EIO, "cannot rename '%s' to '%s': %s (%zu other outputs were already in "
                                 "place, the rest removed)", s->tmp, path, strerror(e), done);
        }
        release_slot(i);
        done++;
    }
    return 0;
}

void asp_output_batch_abort(void)
{
    if (!thread_depth)
        return;
    drop_batch(thread_batch);
    thread_failed = 1;
    if (--thread_depth == 0)
        thread_batch = 0;
}
