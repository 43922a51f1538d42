/*
 * Two-sample t tests from summary figures (seed 004 4.2: the pooled-variance
 * statistic with df = n1 + n2 - 2 and its one-sided p) and Welch's test with
 * Welch-Satterthwaite degrees of freedom, with confidence intervals. The t
 * distribution is GSL's; inputs are checked first so GSL's error handler
 * (which aborts by default) is never reached.
 */
#include <math.h>

#include <gsl/gsl_cdf.h>

#include "amgsplat/stats.h"
#include "util/banned.h"

static int figures_ok(const asp_stats_summary *s)
{
    return isfinite(s->mean) && isfinite(s->sd) && s->sd >= 0;
}

void asp_stats_mean_interval(const asp_stats_summary *s, double level, double *lo, double *hi)
{
    ASP_ASSERT(s && lo && hi);
    if (s->n < 2 || !(level > 0 && level < 1) || !figures_ok(s)) {
        *lo = *hi = NAN;
        return;
    }
    double h = gsl_cdf_tdist_Pinv(0.5 + 0.5 * level, (double)(s->n - 1)) * s->sd / sqrt((double)s->n);
    *lo = s->mean - h;
    *hi = s->mean + h;
}

int asp_stats_ttest(const asp_stats_summary *a, const asp_stats_summary *b, const asp_ttest_desc *desc,
                    asp_ttest_result *out, asp_error *err)
{
    ASP_ASSERT(a && b && out);
    asp_ttest_desc d = desc ? *desc : (asp_ttest_desc){0};
    if (d.level == 0)
        d.level = 0.95;
    if (!(d.level > 0 && d.level < 1))
        return asp_error_set(err, ASP_EINVAL, "confidence level %g is outside (0, 1)", d.level);
    if (!figures_ok(a) || !figures_ok(b))
        return asp_error_set(err, ASP_EINVAL, "sample %d has a non-finite mean or a negative or non-finite sd",
                             figures_ok(a) ? 2 : 1);
    if (a->n < 1 || b->n < 1)
        return asp_error_set(err, ASP_EINVAL, "sample %d is empty", a->n < 1 ? 1 : 2);
    double n1 = (double)a->n, n2 = (double)b->n, v1 = a->sd * a->sd, v2 = b->sd * b->sd;
    asp_ttest_result r = {.welch = d.welch != 0, .level = d.level, .diff = a->mean - b->mean};
    if (r.welch) {
        if (a->n < 2 || b->n < 2)
            return asp_error_set(err, ASP_EINVAL, "Welch's test needs n >= 2 in both samples, got %zu and %zu", a->n,
                                 b->n);
        double q1 = v1 / n1, q2 = v2 / n2;
        r.se = sqrt(q1 + q2);
        // Welch-Satterthwaite; when one sd is 0 the other sample alone carries the variance
        r.df = (q1 + q2) * (q1 + q2) / (q1 * q1 / (n1 - 1) + q2 * q2 / (n2 - 1));
    } else {
        if (a->n + b->n < 3)
            return asp_error_set(err, ASP_EINVAL, "the pooled test needs n1 + n2 >= 3, got %zu", a->n + b->n);
        r.df = n1 + n2 - 2;
        // seed 004 4.2: s^2 = ((n1 - 1) s1^2 + (n2 - 1) s2^2) / (n1 + n2 - 2)
        double s2 = ((n1 - 1) * v1 + (n2 - 1) * v2) / r.df;
        r.se = sqrt(s2 * (1 / n1 + 1 / n2));
    }
    if (!(r.se > 0) || !isfinite(r.df))
        return asp_error_set(err, ASP_EDEGENERATE, "standard error is 0: both samples have sd 0");
    r.t = r.diff / r.se;
    r.p_greater = gsl_cdf_tdist_Q(r.t, r.df);
    r.p_less = gsl_cdf_tdist_P(r.t, r.df);
    r.p_one = r.p_greater < r.p_less ? r.p_greater : r.p_less;
    r.p_two = 2 * r.p_one > 1 ? 1 : 2 * r.p_one;
    double h = gsl_cdf_tdist_Pinv(0.5 + 0.5 * d.level, r.df) * r.se;
    r.diff_lo = r.diff - h;
    r.diff_hi = r.diff + h;
    asp_stats_mean_interval(a, d.level, &r.mean_lo[0], &r.mean_hi[0]);
    asp_stats_mean_interval(b, d.level, &r.mean_lo[1], &r.mean_hi[1]);
    *out = r;
    return 0;
}

int asp_stats_ttest_one(const asp_stats_summary *a, double mu, const asp_ttest_desc *desc, asp_ttest_result *out,
                        asp_error *err)
{
    ASP_ASSERT(a && out);
    double level = desc && desc->level != 0 ? desc->level : 0.95;
    if (!(level > 0 && level < 1))
        return asp_error_set(err, ASP_EINVAL, "confidence level %g is outside (0, 1)", level);
    if (!figures_ok(a) || !isfinite(mu))
        return asp_error_set(err, ASP_EINVAL, "the sample has a non-finite mean or a negative or non-finite sd");
    if (a->n < 2)
        return asp_error_set(err, ASP_EINVAL, "a one-sample t test needs n >= 2, got %zu", a->n);
    asp_ttest_result r = {.level = level, .diff = a->mean - mu, .df = (double)(a->n - 1)};
    r.se = a->sd / sqrt((double)a->n);
    if (!(r.se > 0))
        return asp_error_set(err, ASP_EDEGENERATE, "standard error is 0: the sample has sd 0");
    r.t = r.diff / r.se;
    r.p_greater = gsl_cdf_tdist_Q(r.t, r.df);
    r.p_less = gsl_cdf_tdist_P(r.t, r.df);
    r.p_one = r.p_greater < r.p_less ? r.p_greater : r.p_less;
    r.p_two = 2 * r.p_one > 1 ? 1 : 2 * r.p_one;
    double h = gsl_cdf_tdist_Pinv(0.5 + 0.5 * level, r.df) * r.se;
    r.diff_lo = r.diff - h;
    r.diff_hi = r.diff + h;
    asp_stats_mean_interval(a, level, &r.mean_lo[0], &r.mean_hi[0]);
    r.mean_lo[1] = r.mean_hi[1] = NAN;
    *out = r;
    return 0;
}
