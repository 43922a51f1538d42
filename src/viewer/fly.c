/*
 * The viewer's scripted fly-through (issue 18 item 5): one fixed path around
 * and close to the model, so frame-budget runs (amgsplat view --fly N) see
 * the cut grow and shrink the same way every time. Pure math.
 */
#include <math.h>

#include "viewer/internal.h"
#include "util/banned.h"

void asp__viewer_fly(const asp_camera *start, double u, asp_camera *cam)
{
    const double pi = 3.14159265358979323846;
    *cam = *start;
    double az = fmod(start->azimuth + 360.0 * u + 180.0, 360.0);
    cam->azimuth = (float)((az < 0 ? az + 360.0 : az) - 180.0);
    double el = start->elevation + 25.0 * sin(2.0 * pi * u);
    cam->elevation = (float)(el > 89.0 ? 89.0 : el < -89.0 ? -89.0 : el);
    double s = sin(pi * u);
    cam->distance = (float)(start->distance * (1.0 - 0.65 * s * s));
}
