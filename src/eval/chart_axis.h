/* A chart axis' range and ticks (src/eval/chart_axis.c); private to the eval module. */
#ifndef ASP_EVAL_CHART_AXIS_H
#define ASP_EVAL_CHART_AXIS_H

#include <stddef.h>

#include "amgsplat/eval.h"

enum { ASP__AXIS_MAX_TICKS = 32 };

struct asp__axis {
    double lo, hi;   /* the range drawn; log10 of the data on a log axis */
    int log;         /* set by the caller */
    int integer;     /* set by the caller: ticks at whole numbers only */
    int empty;       /* no usable value: the range is a default */
    double ticks[ASP__AXIS_MAX_TICKS]; /* in the units of lo and hi */
    int nticks;
    double step;     /* the linear step in data units; 0 for decade ticks */
};

/*
 * Sets a's range and ticks from the x (use_x) or y values of the series:
 * every finite value padded by 5%, error bars included, bars from 0, a fixed
 * range (fixed_lo < fixed_hi, y only), a single value widened. At least 3
 * ticks: an integer axis is widened to hold 3 whole numbers.
 */
void asp__axis_fit(struct asp__axis *a, const asp_chart_series *series, size_t n, const double *const *y_err,
                   int use_x, double fixed_lo, double fixed_hi, int bars, double bar_slot);
/* Tick t's label (PLplot text: exponents as #u..#d). */
void asp__axis_label(const struct asp__axis *a, double t, char *buf, size_t cap);

#endif
