/*
 * amgsplat scene renderer (issue 18 item 4): one asp_renderer drawing many
 * instances of several source renderers, each placed by a model matrix, in
 * one frame with one shared depth buffer, so render, view and eval draw a
 * scene of instances (instances.h, eval) like a single model. Render knows no
 * files: the caller hands over renderers and matrices, so this header
 * includes render's own headers only (tests/cli/layers.sh checks it).
 */
#ifndef AMGSPLAT_SCENE_RENDERER_H
#define AMGSPLAT_SCENE_RENDERER_H

#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One source renderer and the instances of it (asp_scene_renderer_create). */
typedef struct asp_scene_renderer_group {
    asp_renderer *renderer; /* made from gl; the scene renderer takes ownership (also on failure) */
    const float *models;    /* 16 floats per instance, column-major: renderer-local to scene coordinates; copied */
    size_t count;           /* instances; 0 is allowed (the renderer is only kept) */
    float center[3];        /* bounding sphere of what renderer draws, in its local frame: instances whose */
    float radius;           /* moved sphere lies outside the view frustum are skipped; radius 0 = never skip */
    int one_by_one;         /* 1: one draw per instance even when the renderer has an instanced draw (the
                               reference path of tests and benchmarks) */
} asp_scene_renderer_group;

/**
 * Makes a renderer that draws, per frame, every instance of every group whose
 * sphere meets the view frustum. A source renderer with its own
 * instanced draw (the renderer interface's draw_instances) gets all its
 * visible models in one call; any other draws once per instance with the
 * model folded into the view matrix and the eye moved into its local frame,
 * in far-to-near order of the instances' spheres, so renderers whose final
 * pass paints over the frame without a depth test (domain primitives)
 * still show near instances in front of far ones. Every draw shares the
 * frame's depth buffer. asp_renderer_count gives the sum of the source
 * renderers' counts over the instances drawn in the last frame;
 * asp_renderer_set_lod passes to every source renderer that has a level of
 * detail (the others are left alone; ASP_EUNSUPPORTED when none has one).
 * Returns 0; ASP_EINVAL (no group, a NULL renderer, a renderer of another
 * context, a non-finite model or sphere); ASP_ENOMEM. The groups' renderers
 * belong to the scene renderer from the call on: destroyed with it, or at
 * once on failure. *out is unchanged on failure.
 */
int asp_scene_renderer_create(asp_gl_context *gl, const asp_scene_renderer_group *groups, size_t group_count,
                              asp_renderer **out, asp_error *err);

/** Instances the scene renderer drew in its last frame (the rest were outside the frustum); 0 for others. */
size_t asp_scene_renderer_drawn(const asp_renderer *r);

#ifdef __cplusplus
}
#endif
#endif
