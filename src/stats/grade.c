/*
 * Direction grading of the navigation tests (seed 004 2.4, Figs 2.1-2.2): every
 * sample that shows movement is compared with the optimal direction of the
 * path segment nearest to it. 100% along the path or toward its centre,
 * falling with the cosine to 0% at perpendicular, 0% backwards or out of
 * bounds; a run's grade is the mean. In the ground plane (x, z), y up: the
 * path is a polyline on the ground, and climbing or descending is not steering.
 */
#include <math.h>

#include "amgsplat/stats.h"
#include "util/banned.h"

/* Nearest point of the polyline to (x, z): unit tangent of its segment and the offset to it. */
static void nearest_segment(const float *path, size_t count, double x, double z, double tangent[2], double offset[2])
{
    double best = INFINITY;
    for (size_t i = 0; i + 1 < count; i++) {
        double ax = path[3 * i], az = path[3 * i + 2];
        double ex = path[3 * (i + 1)] - ax, ez = path[3 * (i + 1) + 2] - az;
        double len2 = ex * ex + ez * ez;
        if (len2 <= 0)
            continue; // repeated vertex: no direction
        double s = ((x - ax) * ex + (z - az) * ez) / len2;
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        double ox = ax + s * ex - x, oz = az + s * ez - z, d2 = ox * ox + oz * oz;
        if (d2 < best) {
            best = d2;
            double len = sqrt(len2);
            tangent[0] = ex / len;
            tangent[1] = ez / len;
            offset[0] = ox;
            offset[1] = oz;
        }
    }
    if (best == INFINITY) { // every vertex the same: no direction to grade against
        tangent[0] = tangent[1] = 0;
        offset[0] = path[0] - x;
        offset[1] = path[2] - z;
    }
}

static double distance_to_path(const float *path, size_t count, double x, double z)
{
    double t[2], o[2];
    nearest_segment(path, count, x, z, t, o);
    return hypot(o[0], o[1]);
}

/* The rules of Fig 2.1 for a step u (unit, ground plane) from `from` (xz) ending inside the bounds. */
static asp_grade_verdict grade_direction(const float *path, size_t count, double half_width, const double from[2],
                                         const double u[2], double *score)
{
    double t[2], o[2];
    nearest_segment(path, count, from[0], from[1], t, o);
    // c: unit vector toward the centre, without its component along the path
    double along = o[0] * t[0] + o[1] * t[1];
    double c[2] = {o[0] - along * t[0], o[1] - along * t[1]}, cl = hypot(c[0], c[1]);
    double k = 0;
    if (cl > 1e-9 * half_width) {
        c[0] /= cl;
        c[1] /= cl;
        k = cl / half_width; // more correction the farther from the centre: 45 degrees at the edge
    } else {
        c[0] = c[1] = 0;
    }
    double g[2] = {t[0] + k * c[0], t[1] + k * c[1]}, gl = hypot(g[0], g[1]);
    *score = 0;
    if (!(gl > 0)) // every path vertex the same: no direction to compare with
        return ASP_GRADE_OUT;
    g[0] /= gl;
    g[1] /= gl;
    double ug = u[0] * g[0] + u[1] * g[1], uc = u[0] * c[0] + u[1] * c[1];
    if (ug <= 0)
        return ASP_GRADE_BACKWARDS;
    if (k > 0 && uc >= 0) {
        *score = 1; // toward the centre, or exactly along the path
        return ASP_GRADE_ALONG;
    }
    // away from the centre: the cosine to g, scaled so straight along t is still 100%
    double tg = t[0] * g[0] + t[1] * g[1];
    *score = ug / tg > 1 ? 1 : ug / tg;
    return *score >= 1 - 1e-12 ? ASP_GRADE_ALONG : ASP_GRADE_AWAY;
}

double asp_stats_grade_step(const float *path, size_t count, double half_width, const double from[3],
                            const double to[3], asp_grade_verdict *verdict)
{
    ASP_ASSERT(path && count >= 2 && half_width > 0 && from && to);
    asp_grade_verdict v;
    double score = 0;
    double mx = to[0] - from[0], mz = to[2] - from[2], m = hypot(mx, mz);
    if (!(m > 1e-6 * half_width)) {
        // below a millionth of the path width a step is numerical noise, not movement
        v = ASP_GRADE_STILL;
        score = -1;
    } else if (!isfinite(m) || distance_to_path(path, count, to[0], to[2]) > half_width) {
        // out of bounds (or so far apart the difference overflows): 0%
        v = ASP_GRADE_OUT;
    } else {
        v = grade_direction(path, count, half_width, (const double[2]){from[0], from[2]},
                            (const double[2]){mx / m, mz / m}, &score);
    }
    if (verdict)
        *verdict = v;
    return score;
}

int asp_stats_grade_track(const float *path, size_t count, double half_width, const double *pos, size_t n,
                          asp_grade_result *out, asp_error *err)
{
    ASP_ASSERT(out && (pos || n == 0));
    if (!path || count < 2)
        return asp_error_set(err, ASP_EINVAL, "grading needs a path of at least 2 points, got %zu", path ? count : 0);
    if (!(half_width > 0) || !isfinite(half_width))
        return asp_error_set(err, ASP_EINVAL, "grading needs a positive half width, got %g", half_width);
    for (size_t i = 0; i < 3 * count; i++)
        if (!isfinite(path[i]))
            return asp_error_set(err, ASP_EINVAL, "path point %zu is not finite", i / 3);
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(pos[i]))
            return asp_error_set(err, ASP_EINVAL, "position of frame %zu is not finite", i / 3);
    asp_grade_result r = {.grade = NAN};
    double sum = 0;
    for (size_t i = 1; i < n; i++) {
        asp_grade_verdict v;
        double s = asp_stats_grade_step(path, count, half_width, pos + 3 * (i - 1), pos + 3 * i, &v);
        if (v == ASP_GRADE_STILL)
            continue;
        r.moving++;
        sum += s;
        r.along += v == ASP_GRADE_ALONG;
        r.away += v == ASP_GRADE_AWAY;
        r.backwards += v == ASP_GRADE_BACKWARDS;
        r.out += v == ASP_GRADE_OUT;
    }
    if (r.moving)
        r.grade = sum / (double)r.moving;
    *out = r;
    return 0;
}
