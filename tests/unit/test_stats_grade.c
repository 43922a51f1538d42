/*
 * Navigation grading (src/stats/grade.c; seed 004 2.4, Figs 2.1-2.2) on
 * synthetic tracks: along the path 100%, perpendicular 0%, backwards 0%, out
 * of bounds 0%, toward the centre 100%, away from it in between.
 */
#include "amgsplat/stats.h"
#include "harness.h"

/* A straight path along +x on the ground (y up), half width 5; and one with a right-angle bend. */
static const float straight[6] = {0, 0, 0, 100, 0, 0};
static const float bent[9] = {0, 0, 0, 50, 0, 0, 50, 0, 50};

static double step(const float *path, size_t n, const double from[3], const double to[3], asp_grade_verdict *v)
{
    return asp_stats_grade_step(path, n, 5.0, from, to, v);
}

static void test_rules(void)
{
    asp_grade_verdict v;
    // along the centre line
    CHECK_NEAR(step(straight, 2, (double[3]){10, 1.7, 0}, (double[3]){11, 1.7, 0}, &v), 1, 1e-12);
    CHECK(v == ASP_GRADE_ALONG);
    // along, off the centre but inside: still 100% (moving along the path)
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 3}, (double[3]){11, 0, 3}, &v), 1, 1e-12);
    CHECK(v == ASP_GRADE_ALONG);
    // perpendicular on the centre line
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 0}, (double[3]){10, 0, 1}, &v), 0, 1e-12);
    // backwards
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 0}, (double[3]){9, 0, 0}, &v), 0, 0);
    CHECK(v == ASP_GRADE_BACKWARDS);
    // straight toward the centre, from either side
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 3}, (double[3]){10, 0, 2}, &v), 1, 0);
    CHECK(v == ASP_GRADE_ALONG);
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, -3}, (double[3]){10.5, 0, -2}, &v), 1, 0);
    // out of bounds: 0 even when moving along
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 6}, (double[3]){11, 0, 6}, &v), 0, 0);
    CHECK(v == ASP_GRADE_OUT);
    // leaving the bounds in this step
    CHECK_NEAR(step(straight, 2, (double[3]){10, 0, 4.5}, (double[3]){11, 0, 5.5}, &v), 0, 0);
    // no movement, or only vertical movement: not graded
    CHECK(step(straight, 2, (double[3]){10, 0, 0}, (double[3]){10, 0, 0}, &v) == -1 && v == ASP_GRADE_STILL);
    CHECK(step(straight, 2, (double[3]){10, 0, 0}, (double[3]){10, 3, 0}, &v) == -1);
}

/*
 * Away from the centre: half way out (d = 2.5 of 5) the optimal direction is
 * g = normalize(1, -0.5) (toward the centre at z = 0); moving at 45 degrees
 * away, u = (1, 1)/sqrt 2, scores (u.g)/(t.g) = ((1 - 0.5)/sqrt 2)/1 = 0.35355.
 */
static void test_away_is_cosine(void)
{
    asp_grade_verdict v;
    double s = step(straight, 2, (double[3]){10, 0, 2.5}, (double[3]){10.01, 0, 2.51}, &v);
    CHECK(v == ASP_GRADE_AWAY);
    CHECK_NEAR(s, 0.5 / sqrt(2), 1e-9);
    // on the centre line the optimal direction is the path's: the plain cosine, 45 degrees = 0.7071
    s = step(straight, 2, (double[3]){10, 0, 0}, (double[3]){10.01, 0, 0.01}, &v);
    CHECK_NEAR(s, 1 / sqrt(2), 1e-9);
    // a smaller angle away scores more: monotone in the angle
    double s10 = step(straight, 2, (double[3]){10, 0, 2.5}, (double[3]){10 + cos(0.17), 0, 2.5 + sin(0.17)}, &v);
    double s30 = step(straight, 2, (double[3]){10, 0, 2.5}, (double[3]){10 + cos(0.52), 0, 2.5 + sin(0.52)}, &v);
    CHECK(s10 > s30 && s30 > 0 && s10 < 1);
    // perpendicular to g itself: 0
    double gx = 1 / sqrt(1.25), gz = -0.5 / sqrt(1.25);
    s = step(straight, 2, (double[3]){10, 0, 2.5}, (double[3]){10 - gz, 0, 2.5 + gx}, &v);
    CHECK_NEAR(s, 0, 1e-9);
}

/* The nearest segment gives the direction: after the bend the path runs along +z. */
static void test_bend(void)
{
    asp_grade_verdict v;
    CHECK_NEAR(step(bent, 3, (double[3]){50, 0, 20}, (double[3]){50, 0, 21}, &v), 1, 1e-12);
    CHECK_NEAR(step(bent, 3, (double[3]){50, 0, 20}, (double[3]){51, 0, 20}, &v), 0, 1e-12);
    CHECK_NEAR(step(bent, 3, (double[3]){20, 0, 0}, (double[3]){21, 0, 0}, &v), 1, 1e-12);
    CHECK_NEAR(step(bent, 3, (double[3]){50, 0, 20}, (double[3]){50, 0, 19}, &v), 0, 0);
}

/* A track: 8 steps along, 2 backwards and a pause: 80%, the pause not counted. */
static void test_track(void)
{
    double pos[12 * 3];
    double x = 10;
    const char *moves = "saaaaaaaabb";
    for (int i = 0; i < 12; i++) {
        if (i > 0)
            x += moves[i - 1] == 'a' ? 1 : moves[i - 1] == 'b' ? -1 : 0;
        pos[3 * i] = x;
        pos[3 * i + 1] = 1.7;
        pos[3 * i + 2] = 0;
    }
    asp_grade_result r;
    asp_error err = {0};
    CHECK_OK(asp_stats_grade_track(straight, 2, 5, pos, 12, &r, &err), &err);
    CHECK(r.moving == 10 && r.along == 8 && r.backwards == 2 && r.out == 0);
    CHECK_NEAR(r.grade, 0.8, 1e-12);
    // a track that never moves has no grade (NaN), not 0
    CHECK_OK(asp_stats_grade_track(straight, 2, 5, pos, 1, &r, &err), &err);
    CHECK(r.moving == 0 && isnan(r.grade));
    CHECK(asp_stats_grade_track(straight, 1, 5, pos, 12, &r, &err) == ASP_EINVAL);
    CHECK(asp_stats_grade_track(straight, 2, 0, pos, 12, &r, &err) == ASP_EINVAL);
    pos[4] = NAN;
    CHECK(asp_stats_grade_track(straight, 2, 5, pos, 12, &r, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "frame 1") != NULL);
}

TEST_MAIN(TEST_CASE(test_rules), TEST_CASE(test_away_is_cosine), TEST_CASE(test_bend), TEST_CASE(test_track))
