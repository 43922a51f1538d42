/*
 * Transparent huge pages for the heavy commands where the kernel gives them
 * only on request (issue 19). A 1M-point decomposition first-touches about
 * 1.5 GB over its stages; most of it is hypre's and Open MPI's memory, which
 * asp_alloc's madvise never sees, and with 4 KB pages a fifth of the CPU time
 * went to page faults (perf). glibc (2.35 and later) advises every block it
 * maps when started with GLIBC_TUNABLES=glibc.malloc.hugetlb=1, and tunables
 * are read only at start-up, so the command starts itself again with it
 * (same process, same arguments; a few milliseconds). Measured, 1M points,
 * 2 threads, medians of 3 alternating runs (BENCHMARKS.md): 4.20 s -> 3.73 s wall, the same peak RSS.
 *
 * Only where THP is in "madvise" mode (in "always" mode every block gets huge
 * pages already, in "never" none can), only when the tunable is not set yet
 * (which also stops a second start), never under LD_PRELOAD (valgrind,
 * profilers) and never with ASP_HUGE_PAGES=0. If the start fails the command
 * goes on as it is.
 */
#define _DEFAULT_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"
#include "util/banned.h"

void cli_huge_pages_restart(char **argv)
{
#if defined(__linux__) && defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
    const char *off = getenv("ASP_HUGE_PAGES");
    const char *tunables = getenv("GLIBC_TUNABLES");
    if ((off && strcmp(off, "0") == 0) || (tunables && strstr(tunables, "glibc.malloc.hugetlb")) ||
        getenv("LD_PRELOAD"))
        return;
    FILE *fp = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!fp)
        return;
    char mode[128] = "";
    int ok = fgets(mode, sizeof mode, fp) != NULL;
    fclose(fp);
    if (!ok || !strstr(mode, "[madvise]"))
        return;
    char value[2048];
    int n = snprintf(value, sizeof value, "%s%sglibc.malloc.hugetlb=1", tunables ? tunables : "",
                     tunables && *tunables ? ":" : "");
    if (n < 0 || (size_t)n >= sizeof value || setenv("GLIBC_TUNABLES", value, 1) != 0)
        return;
    execv("/proc/self/exe", argv);
    /* not started again: go on as we are, with the caller's environment */
    if (tunables)
        setenv("GLIBC_TUNABLES", tunables, 1);
    else
        unsetenv("GLIBC_TUNABLES");
#else
    (void)argv;
#endif
}
