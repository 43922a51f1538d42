/*
 * ASP_ASSERT (STYLE.md section 4): a programmer error aborts with file:line and the condition on
 * stderr, in every build type (this file is compiled with NDEBUG in Release too), and evaluates
 * its condition once. Each failure runs in a forked child so the abort is observed, not suffered.
 */
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "amgsplat/cloud.h"
#include "amgsplat/image.h"
#include "harness.h"

/* Runs fn in a child with stderr captured; returns its wait status and the captured text in buf. */
static int run_child(void (*fn)(void), char *buf, size_t cap)
{
    int fd[2];
    buf[0] = '\0';
    if (pipe(fd) != 0)
        return -1;
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], 2);
        fn();
        _exit(0); // reached only when the assertion did not fire
    }
    close(fd[1]);
    size_t len = 0;
    ssize_t got;
    while (len + 1 < cap && (got = read(fd[0], buf + len, cap - 1 - len)) > 0)
        len += (size_t)got;
    buf[len] = '\0';
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    return status;
}

static void validate_null(void)
{
    asp_cloud_validate(NULL, NULL);
}

static void image_init_null(void)
{
    asp_image_init(NULL, 4, 4, NULL);
}

static void check_aborts(void (*fn)(void), const char *file, const char *cond)
{
    char text[4096];
    int status = run_child(fn, text, sizeof text);
    CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT, "status %#x, stderr: %s", status, text);
    char want[256];
    snprintf(want, sizeof want, "%s:", file);
    CHECK_MSG(strstr(text, want) != NULL, "stderr lacks '%s': %s", want, text);
    snprintf(want, sizeof want, "assertion failed: %s\n", cond);
    CHECK_MSG(strstr(text, want) != NULL, "stderr lacks '%s': %s", want, text);
}

static void test_null_aborts(void)
{
    check_aborts(validate_null, "src/core/cloud.c", "c");
    check_aborts(image_init_null, "src/core/image.c", "img");
}

static void test_condition_once(void)
{
    int n = 0;
    ASP_ASSERT(++n == 1);
    CHECK(n == 1);
    ASP_ASSERT(n++ >= 0 && n == 2);
    CHECK(n == 2);
}

/* Valid calls pass the entry assertions and keep their documented error returns. */
static void test_valid_calls_unchanged(void)
{
    asp_image img;
    asp_error err;
    CHECK(asp_image_init(&img, 0, 4, &err) == ASP_EINVAL);
    CHECK(asp_image_init(&img, 2, 2, &err) == 0);
    asp_image_release(&img);
    asp_image_release(NULL); // documented: NULL accepted
    asp_cloud_destroy(NULL);
}

TEST_MAIN(TEST_CASE(test_null_aborts), TEST_CASE(test_condition_once), TEST_CASE(test_valid_calls_unchanged))
