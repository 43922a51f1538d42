/*
 * Sample summaries: the columns of seed 004 Tables 4.1 and 4.3-4.7 (average,
 * median, minimum, maximum, standard deviation), computed with GSL.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>

#include "amgsplat/stats.h"
#include "util/banned.h"

int asp_stats_summarize(const double *x, size_t n, asp_stats_summary *out, asp_error *err)
{
    ASP_ASSERT(out && (x || n == 0));
    for (size_t i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return asp_error_set(err, ASP_EINVAL, "value %zu of the sample is not finite", i);
    asp_stats_summary s = {.n = n, .mean = NAN, .median = NAN, .min = NAN, .max = NAN, .sd = NAN};
    if (n == 0) {
        *out = s;
        return 0;
    }
    double *sorted = malloc(n * sizeof *sorted);
    if (!sorted)
        return asp_error_set(err, ASP_ENOMEM, "out of memory summarising %zu values", n);
    memcpy(sorted, x, n * sizeof *sorted);
    gsl_sort(sorted, 1, n);
    s.mean = gsl_stats_mean(sorted, 1, n);
    s.median = gsl_stats_median_from_sorted_data(sorted, 1, n);
    s.min = sorted[0];
    s.max = sorted[n - 1];
    // GSL's sd divides by n - 1 (the sample sd the seed's s1, s2 are); one value has no spread
    s.sd = n > 1 ? gsl_stats_sd_m(sorted, 1, n, s.mean) : 0;
    free(sorted);
    *out = s;
    return 0;
}
