/*
 * Framing a point set for rendering in the cloud's local frame: thin wrappers
 * over the one framing of core (asp_cloud_frame, asp_cloud_default_radius),
 * and the camera fitted to a recorded frame (asp_camera_frame).
 */
#include <math.h>

#include "render/internal.h"
#include "util/banned.h"

float asp_render_default_radius(const asp_cloud *cloud)
{
    return asp_cloud_default_radius(cloud);
}

int asp_render_bounding_sphere(const asp_cloud *cloud, float center[3], float *radius, asp_error *err)
{
    asp_frame f;
    int rc = asp_cloud_frame(cloud, &f, err);
    if (rc)
        return rc;
    for (int k = 0; k < 3; k++)
        center[k] = (float)(f.center[k] - cloud->origin[k]);
    *radius = (float)f.radius;
    return 0;
}

void asp_camera_frame(asp_camera *cam, const asp_frame *frame, const double origin[3], float aspect,
                      float distance_radii)
{
    float c[3];
    for (int k = 0; k < 3; k++)
        c[k] = (float)(frame->center[k] - (origin ? origin[k] : 0.0));
    float r = (float)frame->radius;
    asp_camera_fit(cam, c, r, aspect);
    if (distance_radii > 0) {
        cam->distance = distance_radii * r;
        asp_camera_clip_to_sphere(cam, c, r);
    }
}
