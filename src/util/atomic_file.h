/*
 * Atomic output files: write to "<path>.tmp.<pid>" and rename over path on
 * commit, so a failure or crash never leaves a partial output (DEVELOPERS.md
 * "Errors"). Shared by every module that writes files; not public API.
 */
#ifndef ASP_UTIL_ATOMIC_FILE_H
#define ASP_UTIL_ATOMIC_FILE_H

#include <stdio.h>
#include "amgsplat/core.h"

typedef struct asp__atomic_file {
    FILE *fp;
    char path[4096];
    char tmp[4096 + 32];
} asp__atomic_file;

/** Opens the temporary file for binary writing. */
int asp__atomic_open(asp__atomic_file *f, const char *path, asp_error *err);
/** Flushes, fsyncs and renames into place; on any failure removes the temporary and reports. */
int asp__atomic_commit(asp__atomic_file *f, asp_error *err);
/** Closes and removes the temporary file (after a failure). Safe to call twice. */
void asp__atomic_abort(asp__atomic_file *f);

#endif
