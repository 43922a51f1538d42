/*
 * A frame budget (issue 18 item 5): the screen tolerance tau that holds a
 * target frame time, set each frame from the last frame's time by integral
 * control on log tau (seed 001 5.1: tau decides how deep the hierarchy is
 * traversed), with seed 004 section 3.2.5's adaptive traversal depth (Fig.
 * 3.5) as the fallback once tau is as coarse as it may get. No GL.
 */
#include <math.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

/* Depth steps wait this many frames, so the frames after one step show its effect before the next. */
enum { DEPTH_HOLD = 2, PROBE_EVERY = 8 };

/*
 * Below this slope coarsening is futile: halving the detail (tau x 1.41, half the splats) would save
 * under 7% of the frame. Measured close up on llvmpipe: tau 128 -> 256 px saved ~5%.
 */
static const double futile_slope = 0.2;

int asp_frame_budget_init(asp_frame_budget *b, const asp_frame_budget_desc *desc, asp_error *err)
{
    ASP_ASSERT(b && desc);
    asp_frame_budget_desc d = *desc;
    if (!(d.target_ms > 0) || !isfinite(d.target_ms))
        return asp_error_set(err, ASP_EINVAL, "frame budget %g ms is not a time > 0", d.target_ms);
    d.tolerance_min = d.tolerance_min == 0 ? 0.25f : d.tolerance_min;
    d.tolerance_max = d.tolerance_max == 0 ? 256.0f : d.tolerance_max;
    d.tolerance = d.tolerance == 0 ? 4.0f : d.tolerance;
    d.gain = d.gain == 0 ? 0.35f : d.gain;
    d.deadband = d.deadband == 0 ? 0.05f : d.deadband < 0 ? 0.0f : d.deadband;
    d.max_step = d.max_step == 0 ? 2.0f : d.max_step;
    d.min_count = d.min_count == 0 ? 1000 : d.min_count;
    if (!(d.tolerance_min > 0) || !(d.tolerance_max >= d.tolerance_min) || !isfinite(d.tolerance_max))
        return asp_error_set(err, ASP_EINVAL, "frame budget tolerance range [%g, %g] px is invalid (need 0 < min <= max)",
                             (double)d.tolerance_min, (double)d.tolerance_max);
    if (!(d.tolerance > 0) || !isfinite(d.tolerance))
        return asp_error_set(err, ASP_EINVAL, "frame budget start tolerance %g px is not > 0", (double)d.tolerance);
    if (!(d.gain > 0 && d.gain <= 1))
        return asp_error_set(err, ASP_EINVAL, "frame budget gain %g is outside (0, 1]", (double)d.gain);
    if (!(d.deadband < 1))
        return asp_error_set(err, ASP_EINVAL, "frame budget dead band %g is not < 1", (double)d.deadband);
    if (!(d.max_step > 1) || !isfinite(d.max_step))
        return asp_error_set(err, ASP_EINVAL, "frame budget step %g is not a factor > 1", (double)d.max_step);
    memset(b, 0, sizeof *b);
    b->desc = d;
    b->tolerance = fminf(fmaxf(d.tolerance, d.tolerance_min), d.tolerance_max);
    b->slope = 1.0f;
    return 0;
}

/* Too slow at the coarsest tau: one level shallower (seed 004 Fig. 3.5, "decrement k_0"). */
static int depth_coarser(asp_frame_budget *b, size_t count)
{
    uint32_t max = b->desc.depth_max;
    if (max == 0 || b->hold > 0)
        return 0;
    if (count > 0 && count / 8 < b->desc.min_count) // one level shallower keeps an eighth at worst
        return 0;
    uint32_t d = b->depth_limit ? b->depth_limit : max;
    if (d <= 1)
        return 0;
    b->depth_limit = d - 1;
    b->hold = DEPTH_HOLD;
    b->last_move = 1.0;
    return 1;
}

/* Fast with a depth limit on: one level deeper first (Fig. 3.5, "increment k_min"); at depth_max, none. */
static int depth_finer(asp_frame_budget *b)
{
    if (b->depth_limit == 0 || b->hold > 0)
        return 0;
    b->depth_limit = b->depth_limit + 1 >= b->desc.depth_max ? 0 : b->depth_limit + 1;
    b->hold = DEPTH_HOLD;
    b->last_move = -1.0;
    return 1;
}

int asp_frame_budget_update(asp_frame_budget *b, double frame_ms, size_t count)
{
    if (!(frame_ms >= 0) || !isfinite(frame_ms))
        return 0;
    const asp_frame_budget_desc *d = &b->desc;
    // a frame of 0 ms (a timer too coarse) counts as very fast, not as -infinity
    double lf = log(fmax(frame_ms, 1e-3));
    // a move that left the cut as it was (tau below the leaves' size, a view with nothing to refine)
    int cut_changed = count == 0 || b->last_count == 0 || fabs(log((double)count / (double)b->last_count)) > 0.1;
    double s = NAN;
    if (b->frames > 0 && fabs(b->last_move) >= 0.1 && cut_changed) {
        /*
         * The response of the last move. One frame's noise (0.1 in ln f on llvmpipe, 0.3 under a load of
         * 12 on two cores) over a move of 0.1-0.7 is large: moves under 0.1 are not used, the EMA damps
         * the rest, and a clamp at -0.5 keeps a few noisy samples from passing for futility.
         */
        s = -(lf - b->last_log_ms) / b->last_move;
        s = s < -0.5 ? -0.5 : s > 3 ? 3 : s;
        b->slope = (float)(0.7 * b->slope + 0.3 * s);
    }
    b->last_log_ms = lf;
    b->last_count = count;
    b->prev_move = b->last_move;
    b->last_move = 0;
    b->last_ms = frame_ms;
    b->frames++;
    if (b->hold > 0)
        b->hold--;
    double e = lf - log(d->target_ms);
    b->saturated = b->finest = 0;
    if (e <= d->deadband)
        b->bound = 0;
    if (b->probing) {
        b->probing = 0;
        // a probe that left the frame slow without helping is undone, so probes never creep to the blobs
        // of depth 1; the way back says nothing new (last_move stays 0)
        if (e > d->deadband && !(s >= futile_slope)) {
            int changed = b->tolerance != b->probe_tau || b->depth_limit != b->probe_depth;
            b->tolerance = b->probe_tau;
            b->depth_limit = b->probe_depth;
            b->bound = 1;
            return changed;
        }
    }
    if (fabs(e) <= d->deadband)
        return 0;
    float old_tau = b->tolerance;
    uint32_t old_depth = b->depth_limit;
    double step = d->gain * e, cap = log(d->max_step);
    step = step > cap ? cap : step < -cap ? -cap : step;
    // the last move in this direction left the cut as it was (tau below the leaves' size): cross the
    // range where tau changes nothing at the largest step instead of creeping through it
    if (!cut_changed && b->frames > 1 && b->prev_move * e > 0)
        step = e > 0 ? cap : -cap;
    if (e > 0 && count > 0) {
        // a cut's count goes as tau^-2: the largest step that keeps about min_count primitives
        double room = 0.5 * log((double)count / (double)d->min_count);
        step = step < room ? step : room;
    }
    if (e > 0) {
        b->bound = b->slope < futile_slope;
        if (b->bound && ++b->since_probe < PROBE_EVERY)
            return 0;
        b->since_probe = 0;
        if (b->bound) {
            b->probing = 1;
            b->probe_tau = old_tau;
            b->probe_depth = old_depth;
        }
        if (b->tolerance < d->tolerance_max && step > 0.01)
            b->tolerance = fminf((float)(b->tolerance * exp(step)), d->tolerance_max);
        else if ((b->tolerance < d->tolerance_max && step <= 0.01) || !depth_coarser(b, count))
            b->saturated = b->hold == 0; // nothing coarser left (a hold only delays the next depth step)
    } else if (!depth_finer(b) && b->depth_limit == 0) {
        if (b->tolerance > d->tolerance_min)
            b->tolerance = fmaxf((float)(b->tolerance * exp(step)), d->tolerance_min);
        else
            b->finest = 1;
    }
    if (b->tolerance != old_tau)
        b->last_move = log((double)b->tolerance / old_tau);
    b->probing = b->probing && (b->tolerance != old_tau || b->depth_limit != old_depth);
    return b->tolerance != old_tau || b->depth_limit != old_depth;
}

int asp_frame_budget_apply(const asp_frame_budget *b, asp_renderer *r, asp_error *err)
{
    return asp_renderer_set_lod(r, b->tolerance, b->depth_limit, err);
}
