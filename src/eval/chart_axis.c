/*
 * A chart axis: its range from the data and its ticks (src/eval/chart.c draws
 * them). Every axis gets at least 3 labelled ticks (issue 29): "nice" 1-2-5
 * steps on linear axes, and on log axes decades, 1-2-5 or 1..9 per decade, or
 * plain linear steps when the data span less than a decade (a log axis from
 * 900 to 2000 primitives reads 1000, 1500, 2000, not one lone "1000"). A
 * single value or a constant series gets a range around it wide enough for 3
 * ticks.
 */
#include <math.h>
#include <stdio.h>

#include "eval/chart_axis.h"
#include "util/banned.h"

/* The 1-2-5 step just above (dir 1) or below (dir -1) step. */
static double step_next(double step, int dir)
{
    double mag = pow(10, floor(log10(step) + 1e-9)), f = step / mag;
    if (dir > 0)
        return (f < 1.5 ? 2 : f < 3.5 ? 5 : 10) * mag;
    return (f > 7.5 ? 5 : f > 3.5 ? 2 : f > 1.5 ? 1 : 0.5) * mag;
}

/* Ticks k * step inside [lo, hi] (data units; to_log: stored as log10). */
static int linear_ticks(struct asp__axis *a, double lo, double hi, double step, int to_log)
{
    a->nticks = 0;
    for (double k = ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step && a->nticks < ASP__AXIS_MAX_TICKS; k++) {
        double v = fabs(k * step) < 1e-12 * step ? 0 : k * step;
        if (to_log && !(v > 0))
            continue;
        a->ticks[a->nticks++] = to_log ? log10(v) : v;
    }
    a->step = step;
    return a->nticks;
}

/* Linear ticks: about 5 intervals, refined until at least 3 ticks lie inside (at most 12). */
static void ticks_linear(struct asp__axis *a, double lo, double hi, int to_log)
{
    double step = step_next((hi - lo) / 5.0, 1);
    step = step_next(step, -1); // the 1-2-5 step nearest range / 5, from above
    if (a->integer && step < 1)
        step = 1;
    for (int guard = 0; guard < 60 && linear_ticks(a, lo, hi, step, to_log) > 12; guard++)
        step = step_next(step, 1);
    for (int guard = 0; guard < 60 && a->nticks < 3 && !(a->integer && step <= 1); guard++)
        linear_ticks(a, lo, hi, step = step_next(step, -1), to_log);
}

/* Log ticks at the mantissas m[0..nm) of every decade inside [lo, hi] (log10 units). */
static int decade_ticks(struct asp__axis *a, const double *m, int nm, int every)
{
    a->nticks = 0;
    for (double d = floor(a->lo); d <= ceil(a->hi); d++) {
        if (fmod(fabs(d), (double)every) != 0)
            continue;
        for (int k = 0; k < nm && a->nticks < ASP__AXIS_MAX_TICKS; k++) {
            double v = d + log10(m[k]);
            if (v >= a->lo - 1e-9 && v <= a->hi + 1e-9)
                a->ticks[a->nticks++] = v;
        }
    }
    return a->nticks;
}

static void ticks_log(struct asp__axis *a)
{
    static const double one[1] = {1}, m125[3] = {1, 2, 5}, m19[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    a->step = 0;
    for (int every = 1; every <= 4; every++) // decades only, thinned to at most 8
        if (decade_ticks(a, one, 1, every) <= 8)
            break;
    if (a->nticks >= 3)
        return;
    if (decade_ticks(a, m125, 3, 1) >= 3 && a->nticks <= 10)
        return;
    if (decade_ticks(a, m19, 9, 1) >= 3 && a->nticks <= 10)
        return;
    // less than about half a decade: linear steps in data units, placed on the log scale
    ticks_linear(a, pow(10, a->lo), pow(10, a->hi), 1);
}

static int usable(double v, int log)
{
    return isfinite(v) && (!log || v > 0);
}

void asp__axis_fit(struct asp__axis *a, const asp_chart_series *series, size_t n, const double *const *y_err,
                   int use_x, double fixed_lo, double fixed_hi, int bars, double bar_slot)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t s = 0; s < n; s++)
        for (size_t i = 0; i < series[s].count; i++) {
            double v = use_x ? series[s].x[i] : series[s].y[i];
            double other = use_x ? series[s].y[i] : series[s].x[i];
            if (!usable(v, a->log) || !isfinite(other))
                continue;
            // error bars and bars (from 0) must fit inside the y range too
            double e = !use_x && y_err && y_err[s] && isfinite(y_err[s][i]) ? fabs(y_err[s][i]) : 0;
            double vlo = v - e, vhi = v + e;
            if (!use_x && bars)
                vlo = vlo < 0 ? vlo : 0;
            if (a->log) {
                vlo = usable(vlo, 1) ? log10(vlo) : log10(v);
                vhi = log10(vhi);
            }
            lo = vlo < lo ? vlo : lo;
            hi = vhi > hi ? vhi : hi;
        }
    a->empty = !(lo <= hi);
    if (use_x && bars && lo <= hi) {
        lo -= 0.5 * bar_slot;
        hi += 0.5 * bar_slot;
    }
    if (!use_x && fixed_lo < fixed_hi && !a->log) {
        lo = fixed_lo;
        hi = fixed_hi;
    } else if (!(lo <= hi)) {
        lo = 0;
        hi = 1;
    } else if (hi - lo < 1e-12 * (fabs(lo) + 1)) {
        // one value: a range around it (half a decade each side on a log axis)
        double w = a->log ? 0.5 : 0.5 * (fabs(lo) > 0 ? fabs(lo) : 1);
        lo -= w;
        hi += w;
    } else {
        double pad = 0.05 * (hi - lo);
        // a histogram's bars stand on the x axis: no padding below 0
        lo = bars && !use_x && lo == 0 ? 0 : lo - pad;
        hi += pad;
    }
    if (a->integer && hi - lo < 2.5) {
        // 3 whole-number ticks: the range holds the whole number nearest its middle and both neighbours
        double mid = round(0.5 * (lo + hi));
        lo = lo < mid - 1.25 ? lo : mid - 1.25;
        hi = hi > mid + 1.25 ? hi : mid + 1.25;
    }
    a->lo = lo;
    a->hi = hi;
    if (a->log)
        ticks_log(a);
    else
        ticks_linear(a, lo, hi, 0);
}

void asp__axis_label(const struct asp__axis *a, double t, char *buf, size_t cap)
{
    double v = a->log ? pow(10, t) : t;
    double av = fabs(v);
    if (v != 0 && (av >= 1e5 || av < 1e-3)) {
        // large and small numbers as m x 10^e (PLplot's #u ... #d raise and lower the exponent)
        int e = (int)floor(log10(av) + 1e-9);
        double m = v / pow(10, e);
        if (fabs(m - 1) < 1e-6)
            snprintf(buf, cap, "10#u%d#d", e);
        else
            snprintf(buf, cap, "%.3g×10#u%d#d", m, e);
        return;
    }
    if (a->step > 0) {
        // as many decimals as the step needs, the same on every tick: 0.0 0.5 1.0 1.5
        int dec = (int)-floor(log10(a->step) + 1e-9);
        snprintf(buf, cap, "%.*f", dec > 0 ? dec : 0, v);
        return;
    }
    snprintf(buf, cap, "%.6g", v);
}
