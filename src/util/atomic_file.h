/*
 * Atomic output files: write to "<path>.tmp.<pid>" and rename over path on
 * commit, so a failure or crash never leaves a partial output (DEVELOPERS.md
 * "Errors"). Shared by every module that writes files; not public API.
 *
 * Issue #13 adds three guarantees: SIGINT, SIGTERM and SIGHUP remove the
 * temporary files that are being written (a fixed table of live temporaries
 * and an async-signal-safe handler); a writer can have its file read back
 * and validated before it replaces the target (asp__atomic_commit_checked);
 * and the outputs of one command appear all or none (asp_output_batch, which
 * defers every rename of the calling thread to the batch's commit).
 */
#ifndef ASP_UTIL_ATOMIC_FILE_H
#define ASP_UTIL_ATOMIC_FILE_H

#include <stdio.h>
#include "amgsplat/core.h"

typedef struct asp__atomic_file {
    FILE *fp;
    char path[4096];
    char tmp[4096 + 32];
    int slot; /* index in the table of live temporaries, -1 when none */
} asp__atomic_file;

/**
 * Opens the temporary file for binary writing and registers it for removal
 * on SIGINT/SIGTERM/SIGHUP; removes stale temporaries of dead processes.
 */
int asp__atomic_open(asp__atomic_file *f, const char *path, asp_error *err);
/** Flushes, fsyncs and renames into place; on any failure removes the temporary and reports. */
int asp__atomic_commit(asp__atomic_file *f, asp_error *err);

/**
 * Reads back what was written: check(tmp, user, err) runs on the closed
 * temporary file and returns 0 when the format's own reader accepts it.
 */
typedef int (*asp__atomic_check)(const char *tmp, void *user, asp_error *err);
/**
 * As asp__atomic_commit, but check runs on the closed temporary before the
 * rename. When it fails the temporary is removed, the target is untouched,
 * and err says "internal error: the written 'PATH' does not read back: ...".
 */
int asp__atomic_commit_checked(asp__atomic_file *f, asp__atomic_check check, void *user, asp_error *err);
/**
 * Records path (when it exists) as read by this process in role ("the
 * texture of material 'skin' of 'm.obj'"): asp__atomic_open then refuses to
 * write over it, with "cannot write '<path>': it was read as <role>; write to
 * another file". For the files a reader opens that the command line does not
 * name (textures): the object holding what was read calls
 * asp__atomic_unprotect when it goes (asp_mesh_destroy), so a later save in
 * the same process may write there again. Counted, up to 256 files; thread safe.
 */
void asp__atomic_protect(const char *path, const char *role);
void asp__atomic_unprotect(const char *path);

/** Closes and removes the temporary file (after a failure). Safe to call twice. */
void asp__atomic_abort(asp__atomic_file *f);

/** The number of temporaries registered for removal on a signal (tests). */
size_t asp__atomic_live_count(void);

#endif
