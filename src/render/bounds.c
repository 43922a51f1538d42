/*
 * Framing a point set for rendering in the cloud's local frame: render's names
 * for the one framing of core (asp_cloud_frame, asp_cloud_default_radius). The
 * camera fitted to a recorded frame (asp_camera_frame) is GL-free maths in
 * src/geom/camera.c (camera.h), shared with eval and the no-GL build.
 */
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
