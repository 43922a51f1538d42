/*
 * The checks around every point writer (issue #31): the values are finite
 * before a byte is written, and the written temporary loads back before it
 * replaces the target. Not public API.
 */
#ifndef ASP_IO_CLOUD_CHECK_H
#define ASP_IO_CLOUD_CHECK_H

#include "amgsplat/cloud.h"

/*
 * 0, or ASP_EFORMAT "cannot write '<path>': point N: <value> is not finite;
 * nothing written" (asp_cloud_validate's checks and the world coordinates).
 */
int asp__cloud_output_check(const asp_cloud *cloud, const char *path, asp_error *err);

/* What asp__cloud_reads_back compares with: the cloud written and its format ("ply", "las", "xyz"). */
typedef struct asp__cloud_readback {
    const asp_cloud *cloud;
    const char *format;
} asp__cloud_readback;

/* An asp__atomic_check: the temporary reads with the format's reader, validates and has as many points. */
int asp__cloud_reads_back(const char *tmp, void *user, asp_error *err);

#endif
