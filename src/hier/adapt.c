/*
 * Adaptive traversal depth (seed 004 section 3.2.5, Fig. 3.5): from the last
 * frame time, keep rendering between f_min and f_max seconds per frame by
 * deepening the traversal after fast frames and cutting it after slow ones;
 * or, alternatively, by scaling the screen tolerance tau (seed 001 5.1).
 */
#include <math.h>

#include "hier/internal.h"
#include "util/banned.h"

int asp_hier_adapt_init(asp_hier_adapt *a, const asp_hier_adapt_desc *desc, asp_error *err)
{
    asp_hier_adapt_desc d = *desc;
    if (!(d.f_min > 0) || !(d.f_max >= d.f_min) || !isfinite(d.f_max))
        return asp_error_set(err, ASP_EINVAL, "invalid frame-time band [%g, %g]: need 0 < f_min <= f_max", d.f_min,
                             d.f_max);
    if (d.mode != ASP_HIER_ADAPT_DEPTH && d.mode != ASP_HIER_ADAPT_TAU)
        return asp_error_set(err, ASP_EINVAL, "invalid adaptation mode %d", d.mode);
    if (d.depth_max == 0)
        d.depth_max = 64;
    if (d.depth_min == 0)
        d.depth_min = 1;
    if (d.depth_min > d.depth_max)
        d.depth_min = d.depth_max;
    if (d.tau_min == 0)
        d.tau_min = 0.25f;
    if (d.tau_max == 0)
        d.tau_max = 1024.0f;
    if (d.tau == 0)
        d.tau = 1.0f;
    if (d.tau_step == 0)
        d.tau_step = 1.25f;
    if (!(d.tau_min > 0) || !(d.tau_max >= d.tau_min) || !(d.tau_step > 1) || !isfinite(d.tau_max) ||
        !isfinite(d.tau_step) || !(d.tau > 0))
        return asp_error_set(err, ASP_EINVAL, "invalid tau range [%g, %g] or step %g", (double)d.tau_min,
                             (double)d.tau_max, (double)d.tau_step);
    a->desc = d;
    a->depth_min = d.depth_min;
    a->depth = d.depth_min;
    a->tau = fminf(fmaxf(d.tau, d.tau_min), d.tau_max);
    a->refine = 1;
    return 0;
}

static void update_depth(asp_hier_adapt *a, double f, int event)
{
    const asp_hier_adapt_desc *d = &a->desc;
    if (f < d->f_min) {
        /* Fig. 3.5: increment k_min; k_0 = k_min */
        if (a->depth_min < d->depth_max)
            a->depth_min++;
        a->depth = a->depth_min;
    }
    if (f > d->f_max) {
        /* Fig. 3.5: decrement k_0; refine = false */
        if (a->depth > 1)
            a->depth--;
        /*
         * Not in Fig. 3.5, whose k_min only grows: an event would reset k_0 to
         * a k_min already known to be too slow, so k_min follows k_0 down.
         */
        if (a->depth_min > a->depth)
            a->depth_min = a->depth;
        a->refine = 0;
    }
    if (event)
        a->depth = a->depth_min;
}

static void update_tau(asp_hier_adapt *a, double f, int event)
{
    const asp_hier_adapt_desc *d = &a->desc;
    (void)event; /* tau needs no reset: it does not depend on where the last traversal stopped */
    if (f < d->f_min)
        a->tau = fmaxf(a->tau / d->tau_step, d->tau_min);
    if (f > d->f_max) {
        a->tau = fminf(a->tau * d->tau_step, d->tau_max);
        a->refine = 0;
    }
}

int asp_hier_adapt_update(asp_hier_adapt *a, double frame_time, int event)
{
    a->refine = 1;
    if (!isfinite(frame_time) || frame_time < 0)
        return a->refine; /* no usable measurement: keep the current setting */
    if (a->desc.mode == ASP_HIER_ADAPT_TAU)
        update_tau(a, frame_time, event);
    else
        update_depth(a, frame_time, event);
    return a->refine;
}

void asp_hier_adapt_apply(const asp_hier_adapt *a, asp_hier_view *view)
{
    if (a->desc.mode == ASP_HIER_ADAPT_TAU)
        view->tau = a->tau;
    else
        view->depth_limit = a->depth;
}
