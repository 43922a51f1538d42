/*
 * The experiment log reader (src/stats/log_read.c; docs/experiment-log.md):
 * a line cut off by a crash is a lost frame, never an error; a missing header
 * or a wrong format string is an error naming the file and line.
 */
#include <stdlib.h>
#include <sys/stat.h>

#include "amgsplat/stats.h"
#include "harness.h"

static char dir[64];

static const char *write_file(const char *name, const char *text)
{
    static char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "wb");
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
    return path;
}

#define HEADER                                                                                                         \
    "{\"type\":\"header\",\"format\":\"amgsplat-experiment-log 1\",\"subject\":\"S01\",\"group\":\"control\","         \
    "\"test\":\"lowspeed\",\"run\":\"A\",\"condition\":\"polygons\",\"seed\":3,\"version\":\"0.1.0\","                 \
    "\"observer\":true,\"screen\":[320,240],\"path\":[[0,0,0],[100,0,0]],\"half_width\":5,"                            \
    "\"drawn\":{\"triangles\":100,\"points\":0,\"primitives\":0}}\n"
#define FRAME(i, x)                                                                                                    \
    "{\"type\":\"frame\",\"i\":" #i ",\"t\":0." #i ",\"frame_ms\":12.5,\"pos\":[" #x ",1.7,0],\"dir\":[1,0,0],"        \
    "\"drawn\":100,\"keys\":\"W\"}\n"

#define OFF_PATH "{\"type\":\"event\",\"t\":0.15,\"what\":\"off_path\",\"text\":\"\"}\n"
#define CUT_FRAME "{\"type\":\"frame\",\"i\":3,\"t\":0.3,\"fra"

static void test_truncated_log(void)
{
    static const char cut[] = HEADER FRAME(0, 10) FRAME(1, 11) OFF_PATH FRAME(2, 12) CUT_FRAME;
    const char *p = write_file("cut.jsonl", cut);
    asp_stats_log log;
    asp_error err = {0};
    CHECK_OK(asp_stats_log_load(&log, p, &err), &err);
    CHECK(log.frame_count == 3 && log.event_count == 1);
    CHECK(log.lost_frames == 1 && log.first_lost_line == 6);
    CHECK(strcmp(log.subject, "S01") == 0 && strcmp(log.test, "lowspeed") == 0 && strcmp(log.run, "A") == 0);
    CHECK(log.path_count == 2 && log.half_width == 5 && log.path[3] == 100);
    CHECK(log.seed == 3 && log.observer == 1 && log.screen[0] == 320 && log.drawn_triangles == 100);
    CHECK_NEAR(log.frames[2].pos[0], 12, 0);
    CHECK_NEAR(log.frames[1].frame_ms, 12.5, 0);
    CHECK(strcmp(log.events[0].what, "off_path") == 0);
    asp_stats_log_release(&log);
    CHECK(log.frames == NULL && log.frame_count == 0);
    // a cut line glued to the next by an append after a crash: one lost line in the middle
    p = write_file("glued.jsonl", HEADER FRAME(0, 10) "{\"type\":\"frame\",\"i\":1,\"t\"" FRAME(2, 12) FRAME(3, 13));
    CHECK_OK(asp_stats_log_load(&log, p, &err), &err);
    CHECK(log.frame_count == 3 && log.lost_frames == 1 && log.first_lost_line == 3);
    asp_stats_log_release(&log);
    // a header alone is a log of no frames
    p = write_file("empty_run.jsonl", HEADER);
    CHECK_OK(asp_stats_log_load(&log, p, &err), &err);
    CHECK(log.frame_count == 0 && log.lost_frames == 0);
    asp_stats_log_release(&log);
}

static void expect_error(const char *name, const char *text, int code, const char *needle)
{
    const char *p = write_file(name, text);
    asp_stats_log log;
    asp_error err = {0};
    int rc = asp_stats_log_load(&log, p, &err);
    CHECK_MSG(rc == code, "%s: rc %d, expected %d (%s)", name, rc, code, err.msg);
    CHECK_MSG(strstr(err.msg, name) != NULL, "%s: message lacks the file name: %s", name, err.msg);
    CHECK_MSG(strstr(err.msg, needle) != NULL, "%s: message lacks '%s': %s", name, needle, err.msg);
    CHECK(log.frames == NULL && log.path == NULL);
}

static void test_bad_logs(void)
{
    expect_error("noheader.jsonl", FRAME(0, 10) FRAME(1, 11), ASP_EFORMAT, "line 1: expected the header");
    expect_error("format.jsonl",
                 "{\"type\":\"header\",\"format\":\"amgsplat-experiment-log 2\",\"subject\":\"S\",\"test\":\"far\","
                 "\"run\":\"A\",\"condition\":\"points\"}\n",
                 ASP_EFORMAT, "expected format 'amgsplat-experiment-log 1', got 'amgsplat-experiment-log 2'");
    expect_error("empty.jsonl", "", ASP_EFORMAT, "line 1");
    expect_error("cutheader.jsonl", "{\"type\":\"header\",\"form", ASP_EFORMAT, "line 1");
    expect_error("nopos.jsonl", HEADER FRAME(0, 10) "{\"type\":\"frame\",\"i\":1,\"t\":0.1,\"frame_ms\":3}\n",
                 ASP_EFORMAT, "line 3: frame lacks 'pos'");
    expect_error("twoheaders.jsonl", HEADER FRAME(0, 10) HEADER, ASP_EFORMAT, "line 3: a second header");
    expect_error("nowidth.jsonl",
                 "{\"type\":\"header\",\"format\":\"amgsplat-experiment-log 1\",\"subject\":\"S\",\"test\":\"far\","
                 "\"run\":\"A\",\"condition\":\"points\",\"path\":[[0,0,0],[1,0,0]]}\n",
                 ASP_EFORMAT, "half_width");
    asp_stats_log log;
    asp_error err = {0};
    CHECK(asp_stats_log_load(&log, dir, &err) == ASP_EIO); // a directory
    CHECK(asp_stats_log_load(&log, "/nonexistent/x.jsonl", &err) == ASP_EIO);
}

static void test_naming(void)
{
    const char *p =
        write_file("far.jsonl",
                   "{\"type\":\"header\",\"format\":\"amgsplat-experiment-log 1\",\"subject\":\"S02\",\"test\":\"far\","
                   "\"run\":\"B\",\"condition\":\"points\",\"answer_expected\":\"cat\"}\n" FRAME(
                       0, 0) "{\"type\":\"event\",\"t\":2.5,\"what\":\"recognised\",\"text\":\"\"}\n"
                             "{\"type\":\"event\",\"t\":3.75,\"what\":\"answer\",\"text\":\" CAT \"}\n");
    asp_stats_log log;
    asp_error err = {0};
    CHECK_OK(asp_stats_log_load(&log, p, &err), &err);
    asp_stats_naming n;
    asp_stats_log_naming(&log, &n);
    CHECK(n.answered && n.correct);
    CHECK_NEAR(n.recognition_s, 2.5, 0);
    CHECK_NEAR(n.naming_s, 1.25, 1e-12);
    snprintf(log.answer_expected, sizeof log.answer_expected, "horse");
    asp_stats_log_naming(&log, &n);
    CHECK(n.answered && !n.correct);
    log.event_count = 1; // Enter pressed, then the crash: no answer
    asp_stats_log_naming(&log, &n);
    CHECK(!n.answered && isnan(n.naming_s));
    asp_stats_log_release(&log);
}

/* The committed study: its one truncated log reads, with one lost frame and the grade it was built with. */
static void test_study_log(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/data/experiment/study/S02/lowspeed-B.jsonl", ASP_TEST_SRC);
    asp_stats_log log;
    asp_error err = {0};
    CHECK_OK(asp_stats_log_load(&log, path, &err), &err);
    CHECK(log.lost_frames == 1 && log.frame_count == 11);
    double pos[11 * 3];
    for (size_t i = 0; i < log.frame_count && i < 11; i++)
        memcpy(pos + 3 * i, log.frames[i].pos, sizeof log.frames[i].pos);
    asp_grade_result g;
    CHECK_OK(asp_stats_grade_track(log.path, log.path_count, log.half_width, pos, 11, &g, &err), &err);
    CHECK_NEAR(g.grade, 0.8, 1e-12);
    asp_stats_log_release(&log);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/asp_test_stats_log_XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    static const asp_test_case cases[] = {TEST_CASE(test_truncated_log), TEST_CASE(test_bad_logs),
                                          TEST_CASE(test_naming), TEST_CASE(test_study_log)};
    int rc = asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return rc;
}
