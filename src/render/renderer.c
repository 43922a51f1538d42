/*
 * The renderer interface's public calls (STYLE.md 9b): each only dispatches
 * through the renderer's own function table (asp__renderer_vtable, internal.h),
 * with the answer of "not supported" where an optional entry is NULL, so no
 * caller compares tables to learn which renderer it holds. And the one fold
 * of an instance's model into a frame that the scene renderer and every
 * draw_instances share (the maths is the camera's, camera.h).
 */
#include <math.h>
#include <string.h>

#include "render/internal.h"
#include "util/banned.h"

void asp_renderer_destroy(asp_renderer *r)
{
    if (!r)
        return;
    asp__gl_ensure_current(r->gl, NULL);
    r->vt->destroy(r);
}

const char *asp_renderer_name(const asp_renderer *r)
{
    return r->vt->name;
}

size_t asp_renderer_count(const asp_renderer *r)
{
    return r->count;
}

int asp_renderer_set_lod(asp_renderer *r, float tolerance, uint32_t depth_limit, asp_error *err)
{
    if (!r || !r->vt->set_lod)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer has no level of detail to set",
                             r ? asp_renderer_name(r) : "(null)");
    if (!(tolerance >= 0) || !isfinite(tolerance))
        return asp_error_set(err, ASP_EINVAL, "screen tolerance %g is not a finite number of pixels >= 0",
                             (double)tolerance);
    return r->vt->set_lod(r, tolerance, depth_limit, err);
}

int asp_renderer_set_budget(asp_renderer *r, size_t splats, asp_error *err)
{
    if (!r || !r->vt->set_budget)
        return asp_error_set(err, ASP_EUNSUPPORTED, "the %s renderer has no level of detail to cut to %zu splats",
                             r ? asp_renderer_name(r) : "(null)", splats);
    return r->vt->set_budget(r, splats, err);
}

void asp_renderer_stats_get(const asp_renderer *r, asp_renderer_stats *out)
{
    memset(out, 0, sizeof *out);
    out->count = r->count;
    out->points = r->count;
    if (r->vt->stats)
        r->vt->stats(r, out);
}

int asp__renderer_instanced(const asp_renderer *r)
{
    if (!r->vt->draw_instances)
        return 0;
    return r->vt->instanced ? r->vt->instanced(r) : 1;
}

void asp__frame_fold(const asp__frame *f, const float model[16], asp__frame *out)
{
    asp__frame local = *f;
    asp_camera_fold_model(f->view, f->eye, model, local.view, local.eye);
    *out = local;
}
