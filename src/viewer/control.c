/*
 * Viewer interaction without GL: the key table, orbit / dolly / pan of the
 * asp_camera from mouse motion, and the tolerance ladder for the tau keys
 * (seed 004 3.2: the screen tolerance that decides how deep the point
 * hierarchy is traversed, Pajarola et al. 2003 section 5.1).
 */
#include <math.h>
#include <stddef.h>

#include "viewer/internal.h"
#include "util/banned.h"

const asp__viewer_key asp__viewer_keys[] = {
    {'q', ASP__VIEWER_QUIT, 0, "quit (also Esc)"},
    {'r', ASP__VIEWER_RESET, 0, "reset the view (also Home)"},
    {'l', ASP__VIEWER_LIGHT, 0, "toggle lighting"},
    {'n', ASP__VIEWER_NEXT_RENDERER, 0, "next renderer (also Tab)"},
    {'1', ASP__VIEWER_PICK_RENDERER, 0, "renderer 1 (disc)"},
    {'2', ASP__VIEWER_PICK_RENDERER, 1, "renderer 2"},
    {'3', ASP__VIEWER_PICK_RENDERER, 2, "renderer 3"},
    {'4', ASP__VIEWER_PICK_RENDERER, 3, "renderer 4"},
    {'5', ASP__VIEWER_PICK_RENDERER, 4, "renderer 5"},
    {'+', ASP__VIEWER_TAU_UP, 0, "raise the screen tolerance tau (also =)"},
    {'=', ASP__VIEWER_TAU_UP, 0, NULL},
    {'-', ASP__VIEWER_TAU_DOWN, 0, "lower the screen tolerance tau"},
    {'c', ASP__VIEWER_COLOR_MODE, 0, ".amg: next colour mode; .dps: toggle a colour per domain"},
    {'[', ASP__VIEWER_LEVEL_FINER, 0, ".amg, .dps: finer level"},
    {']', ASP__VIEWER_LEVEL_COARSER, 0, ".amg, .dps: coarser level"},
    {'m', ASP__VIEWER_NEXT_METHOD, 0, ".dps: next blending method"},
    {',', ASP__VIEWER_ALPHA_DOWN, 0, ".dps: lower the alpha reference by 0.05"},
    {'.', ASP__VIEWER_ALPHA_UP, 0, ".dps: raise the alpha reference by 0.05"},
    {'o', ASP__VIEWER_OUTLINE, 0, ".dps: toggle the primitives' outlines"},
    {'k', ASP__VIEWER_CREASES, 0, ".dps: toggle crease clipping (primitives meeting at > 60 degrees)"},
    {'p', ASP__VIEWER_POINTS, 0, ".dps: source points (discs) / primitives; mesh: its points / the mesh"},
    {'e', ASP__VIEWER_DEBUG_EIGENVECTORS, 0, ".dps: toggle the primitives' PCA axes (thesis appendix C)"},
    {'t', ASP__VIEWER_DEBUG_TEXELS, 0, ".dps: toggle the texel midpoints (thesis appendix C)"},
    {'g', ASP__VIEWER_PICK_DOMAIN, 0, ".dps: the next domain alone, then every one (thesis appendix C)"},
    {'D', ASP__VIEWER_DOMAIN_SET, 0, ".dps with --domains both: thresholded / strict domains (appendix C)"},
    {'s', ASP__VIEWER_SCREENSHOT, 0, "screenshot to <input>-NNN.png in the current directory"},
    {'v', ASP__VIEWER_PRINT_VIEW, 0, "print the view as --view AZ,EL,DIST"},
    {'E', ASP__VIEWER_EDL, 0, "toggle eye-dome lighting (disc, square: shading without normals)"},
    {'i', ASP__VIEWER_OVERLAY, 0, "toggle the figures: file, renderer, level, method, frame time, tau, counts"},
    {'h', ASP__VIEWER_HELP, 0, "show these keys over the frame and print them (also ?)"},
    {'?', ASP__VIEWER_HELP, 0, NULL},
    {'a', ASP__VIEWER_ORBIT_LEFT, 0, "orbit left (also Left)"},
    {'d', ASP__VIEWER_ORBIT_RIGHT, 0, "orbit right (also Right)"},
    {'w', ASP__VIEWER_ORBIT_UP, 0, "orbit up (also Up)"},
    {'x', ASP__VIEWER_ORBIT_DOWN, 0, "orbit down (also Down)"},
    {'z', ASP__VIEWER_ZOOM_IN, 0, "zoom in (also Page Up)"},
    {'Z', ASP__VIEWER_ZOOM_OUT, 0, "zoom out (also Page Down)"},
    {0, ASP__VIEWER_NONE, 0, NULL},
};

const asp__viewer_key *asp__viewer_key_find(unsigned c)
{
    for (const asp__viewer_key *k = asp__viewer_keys; k->key; k++)
        if ((unsigned char)k->key == c)
            return k;
    return NULL;
}

void asp__viewer_orbit(asp_camera *cam, double dx, double dy)
{
    double az = cam->azimuth - dx * ASP__VIEWER_ORBIT_DEG_PER_PX;
    az = fmod(az + 180.0, 360.0);
    if (az < 0)
        az += 360.0;
    cam->azimuth = (float)(az - 180.0);
    double el = cam->elevation + dy * ASP__VIEWER_ORBIT_DEG_PER_PX;
    cam->elevation = (float)(el > 90.0 ? 90.0 : el < -90.0 ? -90.0 : el);
}

void asp__viewer_dolly(asp_camera *cam, double factor, float radius)
{
    if (!(factor > 0) || !isfinite(factor))
        return;
    double d = cam->distance * factor, lo = 1e-3 * radius, hi = 1e3 * radius;
    cam->distance = (float)(d < lo ? lo : d > hi ? hi : d);
}

void asp__viewer_pan(asp_camera *cam, double dx, double dy, uint32_t height)
{
    if (height == 0)
        return;
    float view[16];
    asp_camera_view_matrix(cam, view);
    /*
     * World units per pixel in the plane through the target perpendicular to
     * the view direction: the frustum is 2 d tan(fov/2) tall there. The rows of
     * the view rotation are the camera's right and up axes in world space.
     */
    double s = 2.0 * cam->distance * tan(cam->fov_y * 3.14159265358979323846 / 360.0) / height;
    for (int k = 0; k < 3; k++) {
        double right = view[k * 4 + 0], up = view[k * 4 + 1];
        cam->target[k] = (float)(cam->target[k] - right * dx * s + up * dy * s);
    }
}

float asp__viewer_tolerance_step(float tau, int dir)
{
    static const float ladder[] = {0, 0.25f, 0.5f, 1, 1.5f, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
    enum { N = sizeof ladder / sizeof ladder[0] };
    if (dir > 0) {
        for (int i = 0; i < N; i++)
            if (ladder[i] > tau)
                return ladder[i];
        return tau > ladder[N - 1] ? tau : ladder[N - 1];
    }
    if (dir < 0) {
        for (int i = N - 1; i >= 0; i--)
            if (ladder[i] < tau)
                return ladder[i];
        return 0;
    }
    return tau;
}
