/*
 * What the tests look like: the first-person camera of the navigation tests,
 * the turning object camera of the recognition tests (seed 004 2.3), and one
 * frame of a condition drawn offscreen and read back, which is all the
 * machine observer sees and what the screenshots and reference frames are.
 */
#include <math.h>
#include <string.h>

#include "experiment/internal.h"
#include "util/banned.h"

const uint8_t asp__exp_sky[4] = {150, 190, 230, 255};      /* navigation background: bluish, never sandy */
const uint8_t asp__exp_backdrop[4] = {40, 40, 48, 255};    /* recognition background */

/* the first-person camera: eye at eye (world), heading yaw (0 = +z), pitch (negative looks down) */
void asp__exp_first_person(asp_camera *cam, const double origin[3], const float eye[3], float yaw, float pitch,
                           float aspect, float far_plane)
{
    asp_camera_init(cam);
    float f[3] = {cosf(pitch) * sinf(yaw), sinf(pitch), cosf(pitch) * cosf(yaw)};
    for (int k = 0; k < 3; k++)
        cam->target[k] = (float)(eye[k] - origin[k]) + f[k];
    cam->distance = 1.0f;
    cam->azimuth = yaw / DEG + 180.0f;  // the eye sits at target - f
    cam->elevation = -pitch / DEG;
    cam->fov_y = 50.0f;
    cam->aspect = aspect;
    cam->z_near = 0.05f;
    cam->z_far = far_plane;
}

void asp__exp_object_camera(asp_camera *cam, const exp_prepared *p, const double origin[3], float yaw, float pitch,
                            float distance_radii, float aspect)
{
    asp_camera_init(cam);
    cam->azimuth = yaw;
    cam->elevation = pitch;
    cam->fov_y = 40.0f;
    asp_camera_frame(cam, &p->frame, origin, aspect, distance_radii);
}

/* draws one frame of condition c and reads it back (the observer's only input); blank = background only */
int asp__exp_draw(exp_study *st, exp_prepared *p, asp_experiment_condition c, const asp_camera *cam,
                  const uint8_t bg[4], asp_image *img, double *ms, size_t *drawn, asp_error *err)
{
    asp_image_release(img);
    double t0 = asp_time_now();
    int rc = 0;
    if (c == ASP_EXPERIMENT_BLANK) {
        rc = asp_image_init(img, st->width, st->height, err);
        if (!rc)
            asp_image_fill(img, bg);
        *drawn = 0;
    } else {
        if (c == ASP_EXPERIMENT_POINTS && p->adapting) {
            rc = asp_renderer_set_lod(p->renderer[c], p->tau, p->adapt.depth, err);
            if (rc)
                return rc;
        }
        asp_render_desc rd = {.width = st->width, .height = st->height, .light_elevation = 45.0f};
        memcpy(rd.background, bg, 4);
        rc = asp_render_to_image(st->gl, p->renderer[c], cam, &rd, img, err);
        *drawn = rc ? 0 : asp_renderer_count(p->renderer[c]);
    }
    *ms = 1000.0 * (asp_time_now() - t0);
    if (!rc && c == ASP_EXPERIMENT_POINTS && p->adapting)
        asp_hier_adapt_update(&p->adapt, *ms / 1000.0, 1); // every frame of a run moves the view: an event
    return rc;
}
