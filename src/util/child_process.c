/*
 * The contained run of a third-party reader (child_process.h). assimp is C++
 * of its own: a Collada file with count="-1" makes it write through a bad
 * pointer (issue #31, 16 crashes with SIGSEGV), and a lying count makes it
 * allocate gigabytes. Pre-checks catch what can be seen in the bytes; what
 * cannot runs here, where a crash is one child's death and a blow-up ends at
 * the address-space cap (malloc returns NULL, operator new throws
 * std::bad_alloc, which assimp turns into an error string).
 */
#if !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* wait4 (the child's peak memory), strsignal */
#endif
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "util/child_process.h"
#include "util/banned.h"

#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif
#ifndef UNDER_ASAN
#define UNDER_ASAN 0
#endif

int asp__fd_write_all(int fd, const void *buf, size_t len)
{
    const char *p = buf;
    while (len > 0) {
        ssize_t n = write(fd, p, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        len -= (size_t)n;
    }
    return 0;
}

int asp__fd_read_all(int fd, void *buf, size_t len)
{
    char *p = buf;
    while (len > 0) {
        ssize_t n = read(fd, p, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        len -= (size_t)n;
    }
    return 0;
}

/* The process's current address-space size in bytes (/proc/self/statm's first field), 0 if unknown. */
static size_t address_space_now(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return 0;
    unsigned long pages = 0;
    int ok = fscanf(f, "%lu", &pages) == 1;
    fclose(f);
    long page = sysconf(_SC_PAGESIZE);
    return ok && page > 0 ? (size_t)pages * (size_t)page : 0;
}

int asp__address_space_headroom(size_t need, const char *what, asp_error *err)
{
    struct rlimit r;
    if (UNDER_ASAN || getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY)
        return 0;
    size_t now = address_space_now(), limit = (size_t)r.rlim_cur;
    size_t left = now < limit ? limit - now : 0;
    if (now == 0 || left >= need)
        return 0;
    return asp_error_set(err, ASP_ENOMEM, "out of memory: %s needs about %zu MB of address space, the limit (ulimit -v "
                         "%zu MB) leaves %zu MB", what, need >> 20, limit >> 20, left >> 20);
}

static void cap(int resource, rlim_t value)
{
    struct rlimit r;
    if (getrlimit(resource, &r) != 0)
        return;
    if (r.rlim_max != RLIM_INFINITY && value > r.rlim_max)
        value = r.rlim_max;
    if (r.rlim_cur != RLIM_INFINITY && r.rlim_cur < value)
        return; // a tighter limit set by the user (ulimit) stays
    r.rlim_cur = value;
    setrlimit(resource, &r);
}

int asp__child_run(const asp__child_desc *desc, asp__child_work work, asp__child_receive receive, void *user,
                   asp_error *err)
{
    int fds[2];
    if (pipe(fds) != 0)
        return asp_error_set(err, ASP_EIO, "cannot read '%s': no pipe for the reader (%s): %s", desc->path,
                             desc->reader, strerror(errno));
    size_t vm = desc->memory_budget && !UNDER_ASAN ? address_space_now() : 0;
    fflush(NULL); // buffered output written once, not again by the child
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]);
        close(fds[1]);
        return asp_error_set(err, e == ENOMEM ? ASP_ENOMEM : ASP_EIO, "cannot read '%s': cannot start the reader (%s): %s",
                             desc->path, desc->reader, strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        if (vm)
            cap(RLIMIT_AS, (rlim_t)(vm + desc->memory_budget));
        if (desc->cpu_seconds)
            cap(RLIMIT_CPU, desc->cpu_seconds);
        work(user, fds[1]);
        close(fds[1]);
        _exit(0);
    }
    close(fds[1]);
    int rc = receive(user, fds[0], err);
    if (rc != 0 && rc != ASP_ECHILD_STREAM)
        kill(pid, SIGKILL); // the parent gave up (its own error): the child's rest is not wanted
    close(fds[0]);
    int status = 0;
    struct rusage ru = {0};
    while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR)
        ;
    if (rc != ASP_ECHILD_STREAM)
        return rc;
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        size_t peak = (size_t)ru.ru_maxrss * 1024;
        if (sig == SIGXCPU || (sig == SIGKILL && desc->cpu_seconds && (unsigned)ru.ru_utime.tv_sec + 1 >= desc->cpu_seconds))
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the reader (%s) ran out of time (%u s of CPU)",
                                 desc->path, desc->reader, desc->cpu_seconds);
        if (vm && peak >= desc->memory_budget / 2)
            return asp_error_set(err, ASP_ENOMEM,
                                 "cannot read '%s': out of memory: the reader (%s) reached its limit of %zu MB and "
                                 "died with signal %d (%s)",
                                 desc->path, desc->reader, desc->memory_budget >> 20, sig, strsignal(sig));
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the reader (%s) crashed with signal %d (%s)",
                             desc->path, desc->reader, sig, strsignal(sig));
    }
    // a sanitizer's handler turns the child's SIGSEGV into exit status 1 after its report
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code != 0)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the reader (%s) crashed (exit status %d)", desc->path,
                             desc->reader, code);
    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the reader (%s) ended without a result", desc->path,
                         desc->reader);
}
