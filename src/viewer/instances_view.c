/*
 * The viewer on a scene of instances (instances.h, issue 18 item 4): the
 * scene loaded once, and a stand-in asp_scene holding only its kind, path
 * and frame, so the viewer's camera, framing and keys work unchanged; the
 * point renderer picked by the keys draws every point source of the scene.
 */
#include <stdio.h>
#include <string.h>

#include "viewer/internal.h"
#include "util/banned.h"

int asp__viewer_instances_load(asp_instance_scene *is, asp_scene *stand_in, const char *path,
                               const asp_viewer_desc *desc, const asp_context *ctx, asp_error *err)
{
    asp_file_type type;
    if (asp_file_recognise(path, &type, NULL) != 0 || type.kind != ASP_FILE_SCENE)
        return 0;
    asp_scene_desc d = {.level = desc->amg_level, .texture = desc->texture};
    int rc = asp_instance_scene_load(path, &d, ctx, is, err);
    if (rc)
        return rc;
    memset(stand_in, 0, sizeof *stand_in);
    stand_in->type = type;
    snprintf(stand_in->path, sizeof stand_in->path, "%s", path);
    // the scene renderer draws centred on the scene's frame (asp_instance_scene_models)
    stand_in->frame = is->frame;
    memcpy(stand_in->origin, is->frame.center, sizeof stand_in->origin);
    if (ctx)
        stand_in->ctx = *ctx;
    return 1;
}

int asp__viewer_instances_renderer(asp_gl_context *gl, const asp_instance_scene *is, const char *point_renderer,
                                   const asp_renderer_options *o, const asp_context *ctx, asp_renderer **out,
                                   asp_error *err)
{
    return asp_instance_scene_renderer_create(gl, is, point_renderer, o, ctx, out, err);
}

void asp__viewer_instances_status(const asp_instance_scene *is, char *status, size_t cap)
{
    snprintf(status, cap, "scene of %zu instances of %zu source%s", is->instance_count, is->source_count,
             is->source_count == 1 ? "" : "s");
}
