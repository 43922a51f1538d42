/*
 * The renderer of a scene of instances (issue 18 item 4): one renderer of the
 * table per distinct source, handed with its instances' models to the scene
 * renderer of render (scene_renderer.h), so render, view and eval build it alike;
 * and the default camera of a scene (instances.h), which needs no GL.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/instances.h"
#include "amgsplat/scene_renderer.h"
#include "util/banned.h"

/* The scene camera is pure maths (camera.h), so it is here in every build, the no-GL one too. */
static const double deg = 3.14159265358979323846 / 180.0;

void asp_instance_scene_camera(const asp_instance_scene *s, int orbit, float aspect, float fov_y_default,
                               float azimuth, float elevation, float distance_radii, asp_camera *cam)
{
    asp_camera_init(cam);
    int file = s->camera.given && !orbit;
    cam->fov_y = file && s->camera.fov_y > 0 ? s->camera.fov_y : fov_y_default;
    const float zero[3] = {0, 0, 0};
    if (!file) {
        cam->azimuth = azimuth;
        cam->elevation = elevation;
        static const double origin[3];
        asp_frame f = s->frame;
        memset(f.center, 0, sizeof f.center); // the scene's frame is centred on s->frame.center
        asp_camera_frame(cam, &f, origin, aspect, distance_radii);
        return;
    }
    // the orbit camera that puts its eye at "eye" looking at "target" (render.h: eye = target + d (..))
    double d[3], len = 0;
    for (int a = 0; a < 3; a++) {
        d[a] = s->camera.eye[a] - s->camera.target[a];
        len += d[a] * d[a];
        cam->target[a] = (float)(s->camera.target[a] - s->frame.center[a]);
    }
    len = sqrt(len);
    cam->distance = (float)len;
    cam->elevation = (float)(asin(fmax(-1.0, fmin(1.0, d[1] / len))) / deg);
    cam->azimuth = (float)(atan2(d[0], d[2]) / deg);
    cam->aspect = aspect > 0 ? aspect : 1.0f;
    asp_camera_clip_to_sphere(cam, zero, (float)s->frame.radius);
}

#ifndef ASP_HAVE_GL
int asp_instance_scene_renderer_create(asp_gl_context *gl, const asp_instance_scene *s, const char *point_renderer,
                                       const asp_renderer_options *options, const asp_context *ctx,
                                       asp_renderer **out, asp_error *err)
{
    (void)gl, (void)s, (void)point_renderer, (void)options, (void)ctx, (void)out;
    return asp_error_set(err, ASP_EUNSUPPORTED, "this amgsplat was built without OpenGL (ASP_WITH_GL=OFF)");
}
#else

/* The row of the renderer table drawing source sc. */
static int pick_kind(const asp_scene *sc, const char *point_renderer, const asp_renderer_kind **out, asp_error *err)
{
    unsigned inputs = asp_scene_inputs(sc);
    // a .hier holds splats without their points: discs cannot draw it, the splats do
    int splats_only = sc->hier && !sc->cloud;
    // a .dps with linked levels is drawn as its view-dependent cut, so far instances take coarse levels
    // (issue 18; docs/cut.md); a single level as it is
    const char *name = sc->dps    ? (sc->dps->level_count > 1 && asp_dps_has_links(sc->dps) ? "cut" : "prim")
                       : sc->mesh ? "mesh"
                       : point_renderer && !(splats_only && strcmp(point_renderer, "disc") == 0) ? point_renderer
                       : splats_only ? "splat"
                                     : "disc";
    return asp_renderer_kind_find(name, inputs, out, err);
}

int asp_instance_scene_renderer_create(asp_gl_context *gl, const asp_instance_scene *s, const char *point_renderer,
                                       const asp_renderer_options *options, const asp_context *ctx,
                                       asp_renderer **out, asp_error *err)
{
    ASP_ASSERT(gl && s && out);
    asp_context actx = s->ctx;
    asp_scene_renderer_group *groups = asp_calloc(&actx, s->source_count, sizeof *groups);
    if (!groups)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu sources", s->source_count);
    int rc = 0;
    size_t made = 0;
    for (size_t i = 0; i < s->source_count && !rc; i++) {
        const asp_scene *sc = &s->sources[i].scene;
        asp_scene_renderer_group *g = &groups[i];
        const asp_renderer_kind *kind = NULL;
        asp_error e = {0, ""};
        rc = pick_kind(sc, point_renderer, &kind, &e);
        if (!rc) {
            asp_render_source src;
            asp_scene_render_source(sc, &src);
            rc = kind->create(gl, &src, options, ctx, &g->renderer, &e);
        }
        if (rc) {
            asp_error_set(err, rc, "source '%s': %s", s->sources[i].name, e.msg);
            break;
        }
        made++;
        g->count = asp_instance_scene_count(s, i);
        float *models = asp_alloc(&actx, 16 * (g->count ? g->count : 1) * sizeof(float));
        if (!models) {
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu instances", g->count);
            break;
        }
        asp_instance_scene_models(s, i, models);
        g->models = models;
        // the source's frame in its renderer's local frame: the sphere the instances are culled by
        for (int a = 0; a < 3; a++)
            g->center[a] = (float)(sc->frame.center[a] - sc->origin[a]);
        g->radius = (float)sc->frame.radius;
    }
    if (rc) {
        for (size_t i = 0; i < made; i++)
            asp_renderer_destroy(groups[i].renderer);
    } else {
        // the scene renderer owns the source renderers from here on, also when it fails
        rc = asp_scene_renderer_create(gl, groups, s->source_count, out, err);
    }
    for (size_t i = 0; i < s->source_count; i++)
        asp_free(&actx, (void *)groups[i].models);
    asp_free(&actx, groups);
    return rc;
}
#endif
