/*
 * The frame budget offline (amgsplat render --frame-ms): the same controller
 * as the viewer's (frame_budget.c) run over repeated draws of one view until
 * the frame time holds the target, so an image shows what the budget would
 * draw at that view (issue 18 item 5).
 */
#include <math.h>
#include <string.h>

#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>

#include "render/internal.h"
#include "util/banned.h"

/* Median, 10th and 90th percentiles of the n values ending at the newest of a ring of cap. */
static void window_quantiles(const double *ring, size_t cap, size_t total, size_t n, double *scratch,
                             asp_frame_budget_result *out)
{
    for (size_t i = 0; i < n; i++)
        scratch[i] = ring[(total - n + i) % cap];
    gsl_sort(scratch, 1, n);
    out->median_ms = gsl_stats_median_from_sorted_data(scratch, 1, n);
    out->p10_ms = gsl_stats_quantile_from_sorted_data(scratch, 1, n, 0.1);
    out->p90_ms = gsl_stats_quantile_from_sorted_data(scratch, 1, n, 0.9);
}

int asp_frame_budget_settle(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam,
                            const asp_render_desc *desc, asp_frame_budget *b, size_t max_frames, size_t window,
                            asp_frame_budget_result *out, asp_error *err)
{
    ASP_ASSERT(gl && r && cam && b && out);
    max_frames = max_frames ? max_frames : 200;
    window = window ? window : 9;
    window = window > max_frames ? max_frames : window;
    asp_render_desc d = desc ? *desc : (asp_render_desc){0};
    d.flags |= ASP_RENDER_WAIT; // the time of a frame is the drawing finished, not the commands queued
    double *ms = asp_alloc(&gl->actx, 2 * window * sizeof *ms);
    float *taus = asp_alloc(&gl->actx, window * sizeof *taus);
    if (!ms || !taus) {
        asp_free(&gl->actx, ms);
        asp_free(&gl->actx, taus);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a frame budget of %zu frames", window);
    }
    asp_frame_budget_result res;
    memset(&res, 0, sizeof res);
    // tolerance band of "held": the dead band, but never tighter than 10% (llvmpipe's frame-to-frame noise)
    double band = fmax(0.10, (double)b->desc.deadband);
    int rc = 0;
    size_t i = 0, pinned_run = 0;
    for (; i < max_frames && !rc; i++) {
        rc = asp_frame_budget_apply(b, r, err);
        if (rc)
            break;
        taus[i % window] = b->tolerance;
        double t0 = asp_time_now();
        rc = asp_render_frame(gl, r, cam, &d, err);
        if (rc)
            break;
        double f = 1e3 * (asp_time_now() - t0);
        ms[i % window] = f;
        asp_frame_budget_update(b, f, asp_renderer_count(r));
        // at the finest or coarsest setting, or where coarser is not faster, the budget cannot do better;
        // believed once it lasted two windows (and two probes), not from one noisy frame
        pinned_run = b->finest || b->saturated || b->bound ? pinned_run + 1 : 0;
        if (i + 1 < window)
            continue;
        window_quantiles(ms, window, i + 1, window, ms + window, &res);
        float lo = taus[0], hi = taus[0];
        for (size_t k = 1; k < window; k++) {
            lo = fminf(lo, taus[k]);
            hi = fmaxf(hi, taus[k]);
        }
        res.held = fabs(log(res.median_ms / b->desc.target_ms)) <= log1p(band);
        int pinned = pinned_run >= 2 * window && pinned_run >= 17;
        if ((res.held && hi <= lo * 1.1f) || pinned) {
            res.settled = 1;
            i++;
            break;
        }
    }
    if (!rc && i < window && i > 0) {
        window_quantiles(ms, window, i, i, ms + window, &res);
        res.held = fabs(log(res.median_ms / b->desc.target_ms)) <= log1p(band);
    }
    asp_free(&gl->actx, ms);
    asp_free(&gl->actx, taus);
    if (!rc) // the renderer keeps the reached state for the caller's final image
        rc = asp_frame_budget_apply(b, r, err);
    if (rc)
        return rc;
    res.frames = i;
    res.tolerance = b->tolerance;
    res.depth_limit = b->depth_limit;
    res.count = asp_renderer_count(r);
    *out = res;
    return 0;
}
