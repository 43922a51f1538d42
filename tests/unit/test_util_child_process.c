/*
 * The contained reader (issue #31, util/child_process.h): a child's result
 * comes back through the pipe; its death by SIGSEGV becomes "the reader
 * (...) crashed with signal 11" naming the file; a blow-up past the memory
 * budget ends as out of memory (not under AddressSanitizer, whose shadow
 * memory leaves no room for an address-space cap); the parent's own error
 * kills the child and is what is reported.
 */
#include <signal.h>
#include <stdint.h>
#include <string.h>

#include "harness.h"
#include "util/child_process.h"

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

static void send_answer(void *user, int fd)
{
    (void)user;
    uint64_t v = 42;
    asp__fd_write_all(fd, &v, sizeof v);
}

static void crash(void *user, int fd)
{
    (void)user, (void)fd;
    raise(SIGSEGV);
}

/* Touches memory until malloc fails (the cap), then dies as assimp does on an uncaught bad_alloc. */
static void blow_up(void *user, int fd)
{
    (void)user, (void)fd;
    for (;;) {
        char *p = malloc((size_t)16 << 20);
        if (!p)
            abort();
        memset(p, 1, (size_t)16 << 20);
    }
}

static int receive(void *user, int fd, asp_error *err)
{
    (void)err;
    uint64_t *v = user;
    return asp__fd_read_all(fd, v, sizeof *v) ? ASP_ECHILD_STREAM : 0;
}

static int refuse(void *user, int fd, asp_error *err)
{
    (void)user, (void)fd;
    return asp_error_set(err, ASP_EINVAL, "the parent's own error");
}

static void test_result_and_crash(void)
{
    asp__child_desc d = {.path = "x.dae", .reader = "assimp", .memory_budget = (size_t)256 << 20, .cpu_seconds = 20};
    uint64_t v = 0;
    asp_error err = {0};
    CHECK_OK(asp__child_run(&d, send_answer, receive, &v, &err), &err);
    CHECK(v == 42);
    CHECK(asp__child_run(&d, crash, receive, &v, &err) == ASP_EFORMAT);
    // under AddressSanitizer its SEGV handler reports and exits with status 1 instead
    CHECK_MSG(strstr(err.msg, UNDER_ASAN ? "cannot read 'x.dae': the reader (assimp) crashed"
                                         : "cannot read 'x.dae': the reader (assimp) crashed with signal 11"),
              "%s", err.msg);
    CHECK(asp__child_run(&d, send_answer, refuse, &v, &err) == ASP_EINVAL);
    CHECK_MSG(strcmp(err.msg, "the parent's own error") == 0, "%s", err.msg);
}

static void test_blow_up_is_out_of_memory(void)
{
    if (UNDER_ASAN) { // no address-space cap beside AddressSanitizer's shadow memory: nothing to check there
        asp_test_skips++;
        return;
    }
    asp__child_desc d = {.path = "big.dae", .reader = "assimp", .memory_budget = (size_t)128 << 20, .cpu_seconds = 20};
    uint64_t v = 0;
    asp_error err = {0};
    CHECK(asp__child_run(&d, blow_up, receive, &v, &err) == ASP_ENOMEM);
    CHECK_MSG(strstr(err.msg, "cannot read 'big.dae': out of memory: the reader (assimp) reached its limit of 128 MB"),
              "%s", err.msg);
}

TEST_MAIN(TEST_CASE(test_result_and_crash), TEST_CASE(test_blow_up_is_out_of_memory))
