/*
 * Minimal unit-test harness (STYLE.md section 11): CHECK macros that stay on
 * whatever NDEBUG says, a per-file list of tests, and a summary line that
 * ctest's log and a human can read. A failing CHECK records the failure and
 * continues, so one run reports every broken invariant.
 */
#ifndef ASP_TESTS_HARNESS_H
#define ASP_TESTS_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/core.h"

static int asp_test_failures;
static int asp_test_checks;
static int asp_test_skips;

/*
 * Exit status of a test program that could not run all of its cases (models from ../shared/data
 * missing). CMakeLists.txt gives every test SKIP_RETURN_CODE 77 (the automake convention), so
 * ctest lists it as "Skipped", never as passed with the checks it could not make.
 */
enum { ASP_TEST_SKIP = 77 };

#define CHECK(cond)                                                                  \
    do {                                                                             \
        asp_test_checks++;                                                           \
        if (!(cond)) {                                                               \
            asp_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                            \
    } while (0)

#define CHECK_MSG(cond, ...)                                                         \
    do {                                                                             \
        asp_test_checks++;                                                           \
        if (!(cond)) {                                                               \
            asp_test_failures++;                                                     \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                            \
            fputc('\n', stderr);                                                     \
        }                                                                            \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                   \
    do {                                                                                        \
        double asp_a_ = (double)(a), asp_b_ = (double)(b);                                      \
        asp_test_checks++;                                                                      \
        if (!(fabs(asp_a_ - asp_b_) <= (tol))) {                                                \
            asp_test_failures++;                                                                \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g, tol %.3g\n",       \
                    __FILE__, __LINE__, #a, asp_a_, #b, asp_b_, (double)(tol));                 \
        }                                                                                       \
    } while (0)

/* The message of an optional error (a function, so &err does not trip -Waddress). */
static inline const char *asp_test_error_text(const asp_error *e)
{
    return e ? e->msg : "";
}

/* Asserts a library call succeeded; prints its message otherwise. */
#define CHECK_OK(call, errp)                                                                  \
    do {                                                                                      \
        int asp_rc_ = (call);                                                                 \
        asp_test_checks++;                                                                    \
        if (asp_rc_ != 0) {                                                                   \
            asp_test_failures++;                                                              \
            fprintf(stderr, "%s:%d: %s returned %d: %s\n", __FILE__, __LINE__, #call, asp_rc_, \
                    asp_test_error_text(errp));                                               \
        }                                                                                     \
    } while (0)

/*
 * Path of the test model `name` in ASP_TEST_DATA (../shared/data, CMake's ASP_SHARED_DATA) in
 * buf, or NULL when it cannot be read: then the caller returns from its test case, and the
 * program ends with ASP_TEST_SKIP unless a check failed.
 */
static inline const char *asp_test_data(char *buf, size_t cap, const char *name)
{
#ifdef ASP_TEST_DATA
    snprintf(buf, cap, "%s/%s", ASP_TEST_DATA, name);
#else
    snprintf(buf, cap, "%s", name);
#endif
    if (access(buf, R_OK) == 0)
        return buf;
    asp_test_skips++;
    fprintf(stderr, "skip: test model '%s' not found\n", buf);
    return NULL;
}

typedef void (*asp_test_fn)(void);
typedef struct { const char *name; asp_test_fn fn; int fixture; } asp_test_case;

#define TEST_CASE(fn) { #fn, fn, 0 }
/*
 * A setup or teardown step (a GL context, a temporary directory): it runs in its place in the
 * list but is no test, so it is not reported as one unless a check of it fails. A TEST_CASE
 * that makes no check and skips nothing fails: a test that cannot fail is a defect (issue 26).
 */
#define TEST_FIXTURE(fn) { #fn, fn, 1 }

static inline int asp_test_run(const char *file, const asp_test_case *cases, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        int before = asp_test_failures;
        int skips = asp_test_skips;
        int checks = asp_test_checks;
        cases[i].fn();
        if (!cases[i].fixture && asp_test_checks == checks && asp_test_skips == skips) {
            asp_test_failures++;
            fprintf(stderr, "%s: no checks made: a test that cannot fail is a defect (TEST_FIXTURE for a setup)\n",
                    cases[i].name);
        }
        if (cases[i].fixture && asp_test_failures == before)
            continue;
        fprintf(stderr, "%s %s\n",
                asp_test_failures != before ? "FAIL" : asp_test_skips != skips ? "skip" : "ok  ", cases[i].name);
    }
    fprintf(stderr, "%s: %d checks, %d failed, %d skipped\n", file, asp_test_checks, asp_test_failures,
            asp_test_skips);
    if (asp_test_failures)
        return 1;
    if (asp_test_checks == 0 && asp_test_skips == 0) {
        fprintf(stderr, "%s: no checks made: a test that cannot fail is a defect\n", file);
        return 1;
    }
    return asp_test_skips ? ASP_TEST_SKIP : 0;
}

#define TEST_MAIN(...)                                                                 \
    int main(void)                                                                     \
    {                                                                                  \
        static const asp_test_case cases_[] = {__VA_ARGS__};                           \
        return asp_test_run(__FILE__, cases_, sizeof cases_ / sizeof cases_[0]);       \
    }

#endif
