/*
 * Orbit camera: azimuth/elevation around a target and an up axis (y, z or x), perspective
 * projection, fitting a bounding sphere (or a recorded frame) to the view, and the
 * per-instance view maths of scenes. Pure math, no GL, so render, eval and the no-GL
 * build share it and it is unit-tested without a context (camera.h says why it is in
 * geom). Matrices follow OpenGL conventions (column-major, eye looks down -z, NDC z in -1..1).
 */
#include <math.h>
#include <string.h>

#include "amgsplat/camera.h"
#include "util/banned.h"

static const double deg = 3.14159265358979323846 / 180.0;

void asp_camera_init(asp_camera *cam)
{
    memset(cam, 0, sizeof *cam);
    cam->distance = 3.0f;
    cam->fov_y = 40.0f;
    cam->aspect = 1.0f;
    cam->z_near = 0.01f;
    cam->z_far = 100.0f;
}

/* Unit vector from target to eye, and the image "up" vector (d/d elevation of it). */
static void orbit_axes(const asp_camera *cam, double back[3], double up[3])
{
    double az = cam->azimuth * deg, el = cam->elevation * deg;
    back[0] = cos(el) * sin(az);
    back[1] = sin(el);
    back[2] = cos(el) * cos(az);
    // the derivative stays defined at el = +-90, where y-up lookAt breaks down
    up[0] = -sin(el) * sin(az);
    up[1] = cos(el);
    up[2] = -sin(el) * cos(az);
    // the y-up frame turned so its y lands on the chosen axis (right-handed rotations)
    asp_up_axis axis = cam->up >= ASP_UP_NEG_Y && cam->up <= ASP_UP_NEG_X ? cam->up - ASP_UP_NEG_Y : cam->up;
    for (int k = 0; k < 2; k++) {
        double *v = k ? up : back;
        if (axis != cam->up) { // a negative axis: first 180 degrees about z, y -> -y
            v[0] = -v[0];
            v[1] = -v[1];
        }
        double x = v[0], y = v[1], z = v[2];
        if (axis == ASP_UP_Z) { // 90 degrees about +x: y -> z, z -> -y
            v[1] = -z;
            v[2] = y;
        } else if (axis == ASP_UP_X) { // -90 degrees about +z: y -> x, x -> -y
            v[0] = y;
            v[1] = -x;
        }
    }
}

void asp_camera_eye(const asp_camera *cam, float eye[3])
{
    double back[3], up[3];
    orbit_axes(cam, back, up);
    for (int i = 0; i < 3; i++)
        eye[i] = (float)(cam->target[i] + cam->distance * back[i]);
}

float asp_camera_fit_distance(const asp_camera *cam, float radius)
{
    /*
     * A sphere at distance d subtends a cone of half-angle asin(r / d); it
     * touches the frustum sides when that equals the smaller half field of view.
     */
    double half_y = 0.5 * cam->fov_y * deg;
    double half_x = atan(tan(half_y) * (cam->aspect > 0 ? cam->aspect : 1.0));
    double half = half_x < half_y ? half_x : half_y;
    return (float)(radius / sin(half));
}

void asp_camera_clip_to_sphere(asp_camera *cam, const float center[3], float radius)
{
    float eye[3];
    asp_camera_eye(cam, eye);
    double dx = eye[0] - center[0], dy = eye[1] - center[1], dz = eye[2] - center[2];
    double d = sqrt(dx * dx + dy * dy + dz * dz);
    double r = radius > 0 ? radius : 0;
    double near_min = 1e-3 * (d + r); // keeps far / near <= 1000 for the 24-bit depth buffer
    double zn = 0.99 * (d - r);
    cam->z_near = (float)(zn > near_min ? zn : near_min);
    cam->z_far = (float)(1.01 * (d + r));
    if (!(cam->z_far > cam->z_near))
        cam->z_far = cam->z_near * 2.0f;
}

void asp_camera_fit(asp_camera *cam, const float center[3], float radius, float aspect)
{
    memcpy(cam->target, center, sizeof cam->target);
    cam->aspect = aspect > 0 ? aspect : 1.0f;
    cam->distance = asp_camera_fit_distance(cam, radius);
    asp_camera_clip_to_sphere(cam, center, radius);
}

void asp_camera_view_matrix(const asp_camera *cam, float m[16])
{
    double back[3], up[3];
    orbit_axes(cam, back, up);
    // right = up x back completes a right-handed eye frame (x right, y up, z towards the viewer)
    double right[3] = {up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2],
                       up[0] * back[1] - up[1] * back[0]};
    double eye[3];
    for (int i = 0; i < 3; i++)
        eye[i] = cam->target[i] + cam->distance * back[i];
    const double *rows[3] = {right, up, back};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[c * 4 + r] = (float)rows[r][c];
        m[12 + r] = (float)-(rows[r][0] * eye[0] + rows[r][1] * eye[1] + rows[r][2] * eye[2]);
        m[r * 4 + 3] = 0.0f;
    }
    m[15] = 1.0f;
}

void asp_camera_projection_matrix(const asp_camera *cam, float m[16])
{
    double f = 1.0 / tan(0.5 * cam->fov_y * deg);
    double n = cam->z_near, fa = cam->z_far;
    memset(m, 0, 16 * sizeof *m);
    m[0] = (float)(f / cam->aspect);
    m[5] = (float)f;
    m[10] = (float)((fa + n) / (n - fa));
    m[11] = -1.0f;
    m[14] = (float)(2.0 * fa * n / (n - fa));
}

int asp_camera_project(const asp_camera *cam, const float p[3], uint32_t width, uint32_t height, float out[3])
{
    float v[16], pr[16];
    asp_camera_view_matrix(cam, v);
    asp_camera_projection_matrix(cam, pr);
    double e[4], c[4];
    for (int r = 0; r < 4; r++)
        e[r] = (double)v[r] * p[0] + (double)v[4 + r] * p[1] + (double)v[8 + r] * p[2] + v[12 + r];
    for (int r = 0; r < 4; r++)
        c[r] = pr[r] * e[0] + pr[4 + r] * e[1] + pr[8 + r] * e[2] + pr[12 + r] * e[3];
    if (!(c[3] > 0))
        return 0;
    double x = c[0] / c[3], y = c[1] / c[3], z = c[2] / c[3];
    out[0] = (float)((x * 0.5 + 0.5) * width);
    out[1] = (float)((0.5 - y * 0.5) * height); // image rows run top to bottom, NDC y bottom to top
    out[2] = (float)(z * 0.5 + 0.5);
    return 1;
}

/*
 * The eye distance at which the box centre +- half (world axes) fills the view as the camera
 * looks now: each corner, at view coordinates (x, y) and z towards the eye, lies d - z in front
 * of it and inside the frustum when |x| <= (d - z) tan(half fov x), likewise y. The largest such
 * d over the 8 corners is the tightest fit (the box is drawn from its centre, as the sphere is).
 */
static double box_fit_distance(const asp_camera *cam, const double half[3])
{
    double back[3], up[3];
    orbit_axes(cam, back, up);
    double right[3] = {up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2],
                       up[0] * back[1] - up[1] * back[0]};
    double ty = tan(0.5 * cam->fov_y * deg), tx = ty * (cam->aspect > 0 ? cam->aspect : 1.0);
    double d = 0;
    for (int i = 0; i < 8; i++) {
        double c[3] = {i & 1 ? half[0] : -half[0], i & 2 ? half[1] : -half[1], i & 4 ? half[2] : -half[2]};
        double x = c[0] * right[0] + c[1] * right[1] + c[2] * right[2];
        double y = c[0] * up[0] + c[1] * up[1] + c[2] * up[2];
        double z = c[0] * back[0] + c[1] * back[1] + c[2] * back[2];
        d = fmax(d, fmax(z + fabs(x) / tx, z + fabs(y) / ty));
    }
    return d;
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
        return;
    }
    /*
     * A flat, wide set (its side along the shown up axis at most a third of its longest other side:
     * a site, a terrain, a floor) fills a small part of its bounding sphere's view (issue 29: a
     * 60 x 40 m site filled a third of the image), so the camera comes as close as its box allows;
     * compact models and upright ones (a wall seen head on) keep the sphere fit, and the nearer of
     * the two is taken, so nothing the sphere fit showed is cut.
     */
    const double *h = frame->half;
    asp_up_axis axis = cam->up >= ASP_UP_NEG_Y && cam->up <= ASP_UP_NEG_X ? cam->up - ASP_UP_NEG_Y : cam->up;
    int u = axis == ASP_UP_Z ? 2 : axis == ASP_UP_X ? 0 : 1; // the index of the up axis in xyz
    double wide = fmax(h[(u + 1) % 3], h[(u + 2) % 3]);
    if (wide > 0 && 3.0 * h[u] <= wide && isfinite(wide + h[u])) {
        double d = box_fit_distance(cam, h);
        if (d > 0 && d < cam->distance) {
            cam->distance = (float)d;
            asp_camera_clip_to_sphere(cam, c, r);
        }
    }
}

/* out = a * b, column-major; out may alias a or b. */
static void mul4(const float a[16], const float b[16], float out[16])
{
    float r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            float s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * k + row] * b[4 * c + k];
            r[4 * c + row] = s;
        }
    memcpy(out, r, sizeof r);
}

void asp_camera_fold_model(const float view[16], const float eye[3], const float model[16], float view_out[16],
                           float eye_out[3])
{
    const float *m = model;
    // the eye in the local frame: m^-1 eye in double, so far instances keep their precision
    double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], k = m[10];
    double det = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g);
    double inv[9] = {(e * k - f * h) / det, (c * h - b * k) / det, (b * f - c * e) / det,
                     (f * g - d * k) / det, (a * k - c * g) / det, (c * d - a * f) / det,
                     (d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det};
    double p[3] = {(double)eye[0] - m[12], (double)eye[1] - m[13], (double)eye[2] - m[14]};
    float local[3];
    for (int r = 0; r < 3; r++)
        local[r] = (float)(inv[3 * r] * p[0] + inv[3 * r + 1] * p[1] + inv[3 * r + 2] * p[2]);
    mul4(view, model, view_out);
    memcpy(eye_out, local, sizeof local);
}

void asp_camera_frustum_planes(const float view[16], const float proj[16], float planes[6][4])
{
    float pv[16];
    mul4(proj, view, pv);
    for (int i = 0; i < 3; i++)
        for (int s = 0; s < 2; s++) {
            float *p = planes[2 * i + s];
            float sign = s ? -1.0f : 1.0f;
            for (int c = 0; c < 4; c++)
                p[c] = pv[4 * c + 3] + sign * pv[4 * c + i];
            float len = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            for (int c = 0; c < 4 && len > 0; c++)
                p[c] /= len;
        }
}
