/*
 * amgsplat experiment ttest: the two-sample t test of seed 004 4.2 (pooled
 * variance) or Welch's, from summary figures, so anyone can re-check the
 * seed's Tables 4.3, 4.5 and 4.7 (asp_stats_ttest; docs/experiment-analysis.md).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <cjson/cJSON.h>

#include "amgsplat/stats.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat experiment ttest N1,MEAN1,SD1 N2,MEAN2,SD2 [--welch] [--level P] [--json]\n"
    "       amgsplat experiment ttest N,MEAN,SD [--mu M] [--level P] [--json]\n"
    "\n"
    "Two-sample t test of MEAN1 - MEAN2 from summary figures (SD: sample standard deviations).\n"
    "By default the pooled-variance test of seed 004 section 4.2 (df = N1 + N2 - 2); --welch\n"
    "gives Welch's test (Welch-Satterthwaite df), which does not assume equal variances.\n"
    "Prints t, df, the one-sided p-values of both alternatives and the two-sided one, and\n"
    "P-level confidence intervals (default 0.95) of the difference and of each mean.\n"
    "With one sample: the one-sample t test of MEAN - M (default M = 0, df = N - 1), which on\n"
    "per-subject differences B - A is the paired test (did run B differ from run A?).\n"
    "Example (seed 004 Table 4.7): amgsplat experiment ttest 5,7.6,5.0 6,-8.9,23.6";

/* "N,MEAN,SD" with N a whole number >= 1 and SD >= 0 */
static int parse_sample(struct cli_env *env, const char *s, int which, asp_stats_summary *out)
{
    double v[3];
    if (cli_parse_doubles(s, v, 3) != 3 || !(v[0] >= 1 && v[0] <= 1e12 && v[0] == floor(v[0])) || !isfinite(v[1]) ||
        !(v[2] >= 0 && isfinite(v[2])))
        return cli_usage_error(env, "sample %d: expected N,MEAN,SD (N a whole number >= 1, SD >= 0), got '%s'", which,
                               s);
    *out = (asp_stats_summary){.n = (size_t)v[0], .mean = v[1], .sd = v[2], .median = NAN, .min = NAN, .max = NAN};
    return 0;
}

/* the one t-test object of src/stats (asp_stats_ttest_json), as the analysis report writes it */
static int print_json(const struct cli_env *env, const asp_stats_summary s[2], int nsamples, double mu,
                      const asp_ttest_result *r)
{
    const asp_ttest_json_desc d = {.test = nsamples == 1 ? "one-sample" : NULL, .one_sample = nsamples == 1,
                                   .mu = mu, .samples = s};
    cJSON *o = NULL;
    asp_error err = {0};
    if (asp_stats_ttest_json(r, &d, &o, &err))
        return cli_fail(env, &err);
    return cli_json_print(env, o);
}

int cmd_experiment_ttest(int argc, char **argv, struct cli_env *env)
{
    int welch = 0;
    double level = 0.95, mu = 0;
    const struct cli_option opts[] = {
        {"welch", 'w', CLI_FLAG, &welch, NULL, "Welch's test (unequal variances) instead of the pooled one"},
        {"level", 0, CLI_DOUBLE, &level, "P", "confidence level of the intervals, 0 < P < 1 (default 0.95)"},
        {"mu", 0, CLI_DOUBLE, &mu, "M", "one sample: the mean it is tested against (default 0)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1 && npos != 2)
        return cli_usage_error(env, "expected one or two samples N,MEAN,SD, got %d; see 'amgsplat experiment ttest -h'",
                               npos);
    if (npos == 1 && welch)
        return cli_usage_error(env, "--welch compares two samples; one was given");
    if (!isfinite(mu))
        return cli_usage_error(env, "--mu expects a finite number");
    if (!(level > 0 && level < 1))
        return cli_usage_error(env, "--level expects a probability between 0 and 1, got %g", level);
    asp_stats_summary s[2];
    for (int k = 0; k < npos; k++)
        if ((rc = parse_sample(env, argv[k], k + 1, &s[k])) != 0)
            return rc;
    asp_ttest_result r;
    asp_error err = {0};
    const asp_ttest_desc desc = {.welch = welch, .level = level};
    if (npos == 1 ? asp_stats_ttest_one(&s[0], mu, &desc, &r, &err) : asp_stats_ttest(&s[0], &s[1], &desc, &r, &err))
        return cli_fail(env, &err);
    if (env->json)
        return print_json(env, s, npos, mu, &r);
    if (npos == 1) {
        printf("one-sample t test: mean - %.6g = %.6g (standard error %.6g)\n", mu, r.diff, r.se);
        printf("t = %.4f, df = %.0f\n", r.t, r.df);
        printf("one-sided p = %.4g (alternative mean %s %.6g); two-sided p = %.4g\n", r.p_one,
               r.p_greater <= r.p_less ? ">" : "<", mu, r.p_two);
        printf("%g%% interval of the mean: %.6g .. %.6g\n", 100 * level, r.mean_lo[0], r.mean_hi[0]);
        return 0;
    }
    printf("%s: mean1 - mean2 = %.6g (standard error %.6g)\n",
           welch ? "Welch's t test" : "pooled two-sample t test (seed 004 4.2)", r.diff, r.se);
    printf("t = %.4f, df = %.*f\n", r.t, welch ? 2 : 0, r.df);
    printf("one-sided p = %.4g (alternative mean1 %s mean2); P(T >= t) = %.4g, P(T <= t) = %.4g\n", r.p_one,
           r.p_greater <= r.p_less ? ">" : "<", r.p_greater, r.p_less);
    printf("two-sided p = %.4g\n", r.p_two);
    printf("%g%% interval of mean1 - mean2: %.6g .. %.6g\n", 100 * level, r.diff_lo, r.diff_hi);
    for (int k = 0; k < 2; k++) {
        if (isfinite(r.mean_lo[k]))
            printf("%g%% interval of mean%d: %.6g .. %.6g\n", 100 * level, k + 1, r.mean_lo[k], r.mean_hi[k]);
        else
            printf("%g%% interval of mean%d: none (n = 1)\n", 100 * level, k + 1);
    }
    return 0;
}
