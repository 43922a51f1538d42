/*
 * A camera as the view a cut is selected for (asp_hier_view): what the streamed readers of
 * render and view (asp_ooc_select) and any other caller of asp_hier_select build from one camera.
 */
#include <string.h>

#include "amgsplat/camera.h"
#include "amgsplat/hier.h"
#include "util/banned.h"

void asp_hier_view_of_camera(const asp_camera *cam, uint32_t width, uint32_t height, float tau, asp_hier_view *out)
{
    memset(out, 0, sizeof *out);
    asp_camera_view_matrix(cam, out->view);
    asp_camera_projection_matrix(cam, out->proj);
    asp_camera_eye(cam, out->eye);
    out->width = width;
    out->height = height;
    out->tau = tau;
}
