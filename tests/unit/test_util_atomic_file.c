/*
 * Atomic outputs (issue #13): a file that does not read back never replaces
 * its target, a signal during a write removes the temporary and still kills
 * the process, an output batch renames all of its files or none, and a
 * directory is refused as a target before anything is written.
 */
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "amgsplat/output.h"
#include "harness.h"
#include "util/atomic_file.h"

static char dir[256];

static void path_of(char *buf, size_t cap, const char *name)
{
    snprintf(buf, cap, "%s/%s", dir, name);
}

static void put_text(const char *p, const char *text)
{
    FILE *fp = fopen(p, "w");
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

/* The file's first line, or "" when it cannot be read. */
static const char *text_of(const char *p)
{
    static char line[128];
    line[0] = '\0';
    FILE *fp = fopen(p, "r");
    if (fp) {
        if (!fgets(line, sizeof line, fp))
            line[0] = '\0';
        fclose(fp);
    }
    return line;
}

/* Files in dir whose name holds ".tmp.". */
static int temporaries(void)
{
    char cmd[400];
    snprintf(cmd, sizeof cmd, "ls -a '%s' | grep -c '\\.tmp\\.'", dir);
    FILE *p = popen(cmd, "r");
    int n = -1;
    if (p) {
        if (fscanf(p, "%d", &n) != 1)
            n = -1;
        pclose(p);
    }
    return n;
}

static int write_text(const char *p, const char *text, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, p, err);
    if (rc)
        return rc;
    fputs(text, f.fp);
    return asp__atomic_commit(&f, err);
}

static int refuse(const char *tmp, void *user, asp_error *err)
{
    CHECK(strstr(tmp, ".tmp.") != NULL); // the check reads the temporary, not the target
    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %s", tmp, (const char *)user);
}

static int accept_if_written(const char *tmp, void *user, asp_error *err)
{
    (void)user;
    struct stat st;
    if (stat(tmp, &st) != 0 || st.st_size != 6) // closed and flushed before the check runs
        return asp_error_set(err, ASP_EFORMAT, "the temporary has %lld bytes, expected 6", (long long)st.st_size);
    return 0;
}

static void test_read_back(void)
{
    char p[320];
    asp_error err = {0};
    path_of(p, sizeof p, "checked.txt");
    put_text(p, "old\n");
    asp__atomic_file f;
    CHECK_OK(asp__atomic_open(&f, p, &err), &err);
    if (f.fp)
        fputs("bytes\n", f.fp);
    int rc = asp__atomic_commit_checked(&f, refuse, "weight 1.5, above 1", &err);
    CHECK(rc == ASP_EFORMAT);
    char want[800];
    snprintf(want, sizeof want, "internal error: the written '%s' does not read back: cannot read '%s.tmp.", p, p);
    CHECK_MSG(strncmp(err.msg, want, strlen(want)) == 0, "%s", err.msg);
    CHECK(strstr(err.msg, "weight 1.5, above 1") != NULL);
    CHECK(strcmp(text_of(p), "old\n") == 0);
    CHECK(temporaries() == 0);
    CHECK(asp__atomic_live_count() == 0);
    // a check that accepts: the target is replaced
    CHECK_OK(asp__atomic_open(&f, p, &err), &err);
    if (f.fp)
        fputs("bytes\n", f.fp);
    CHECK_OK(asp__atomic_commit_checked(&f, accept_if_written, NULL, &err), &err);
    CHECK(strcmp(text_of(p), "bytes\n") == 0);
    CHECK(asp__atomic_live_count() == 0);
}

static void test_directory_target(void)
{
    char p[320];
    asp_error err = {0};
    path_of(p, sizeof p, "adir.png");
    mkdir(p, 0777);
    CHECK(write_text(p, "x\n", &err) == ASP_EIO);
    CHECK_MSG(strstr(err.msg, "is a directory") != NULL, "%s", err.msg);
    CHECK(temporaries() == 0);
    rmdir(p);
}

/* A child writes half a file and gets sig: it must die of sig and leave no temporary. */
static void signal_during_write(int sig)
{
    char p[320];
    path_of(p, sizeof p, "signalled.txt");
    put_text(p, "old\n");
    pid_t pid = fork();
    if (pid == 0) {
        asp__atomic_file f;
        if (asp__atomic_open(&f, p, NULL) != 0)
            _exit(3);
        fputs("half a file", f.fp);
        fflush(f.fp);
        raise(sig);
        _exit(4); // not reached: the signal's default action ends the process
    }
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == sig, "signal %d: status 0x%x", sig, status);
    CHECK(temporaries() == 0);
    CHECK(strcmp(text_of(p), "old\n") == 0);
}

static void test_signals(void)
{
    signal_during_write(SIGINT);
    signal_during_write(SIGTERM);
    signal_during_write(SIGHUP);
}

static void test_batch(void)
{
    char a[320], b[320];
    asp_error err = {0};
    path_of(a, sizeof a, "a.txt");
    path_of(b, sizeof b, "b.txt");
    put_text(a, "old a\n");
    unlink(b);
    // abort: neither target changes, no temporary stays
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(write_text(a, "new a\n", &err), &err);
    CHECK_OK(write_text(b, "new b\n", &err), &err);
    CHECK(strcmp(text_of(a), "old a\n") == 0 && access(b, F_OK) != 0); // written, not yet in place
    CHECK(asp__atomic_live_count() == 2);
    asp_output_batch_abort();
    CHECK(strcmp(text_of(a), "old a\n") == 0 && access(b, F_OK) != 0);
    CHECK(temporaries() == 0 && asp__atomic_live_count() == 0);
    // commit: both appear
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(write_text(a, "new a\n", &err), &err);
    CHECK_OK(write_text(b, "new b\n", &err), &err);
    CHECK_OK(asp_output_batch_commit(&err), &err);
    CHECK(strcmp(text_of(a), "new a\n") == 0 && strcmp(text_of(b), "new b\n") == 0);
    CHECK(temporaries() == 0 && asp__atomic_live_count() == 0);
    // nested: an inner abort voids the outer batch, whose commit then says so and renames nothing
    put_text(a, "old a\n");
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(write_text(a, "newer a\n", &err), &err);
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(write_text(b, "newer b\n", &err), &err);
    asp_output_batch_abort();
    CHECK(asp_output_batch_commit(&err) == ASP_ECANCELED);
    CHECK(strcmp(text_of(a), "old a\n") == 0 && strcmp(text_of(b), "new b\n") == 0);
    CHECK(temporaries() == 0 && asp__atomic_live_count() == 0);
    // nested commits: only the outermost renames
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(asp_output_batch_begin(&err), &err);
    CHECK_OK(write_text(b, "inner b\n", &err), &err);
    CHECK_OK(asp_output_batch_commit(&err), &err);
    CHECK(strcmp(text_of(b), "new b\n") == 0);
    CHECK_OK(asp_output_batch_commit(&err), &err);
    CHECK(strcmp(text_of(b), "inner b\n") == 0);
    CHECK(asp_output_batch_commit(&err) == ASP_EINVAL); // none open
    // a write outside any batch goes straight into place
    CHECK_OK(write_text(a, "plain a\n", &err), &err);
    CHECK(strcmp(text_of(a), "plain a\n") == 0);
}

static void cleanup(void)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "cannot remove '%s'\n", dir);
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/asp_test_atomic_%ld", (long)getpid());
    mkdir(dir, 0777);
}

static void test_all(void)
{
    setup();
    test_read_back();
    test_directory_target();
    test_signals();
    test_batch();
    cleanup();
}

TEST_MAIN(TEST_CASE(test_all))
