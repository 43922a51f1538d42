/*
 * amgsplat camera: the orbit camera, the one framing of a model (a recorded
 * asp_frame fitted to the view) and the per-instance maths of a scene (a
 * model folded into the view, the frustum planes). Pure maths, no GL.
 *
 * Why here, in geom (src/geom/camera.c), and not in render: STYLE.md 9b puts
 * the maths that needs no GL below render, so the no-GL build, eval and the
 * web export frame a scene with the very code the renderers draw it with. It
 * needs only core's asp_frame and asp_up_axis (cloud.h), so geom, the lowest
 * module of geometry maths and always built, owns it. It is a header of its
 * own so render.h reaches it without geom.h (which includes mesh.h, io) and
 * so the camera is found by its name.
 */
#ifndef AMGSPLAT_CAMERA_H
#define AMGSPLAT_CAMERA_H

#include "cloud.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Orbit camera around target, y up. The eye sits at
 *   target + distance * (cos(el) sin(az), sin(el), cos(el) cos(az))
 * so azimuth 0, elevation 0 looks from +z towards -z with +x to the right;
 * azimuth turns counter-clockwise seen from +y (90 looks from +x), elevation is
 * the angle above the horizon (90 looks straight down; the image "up" then
 * points away from the azimuth direction, so no singularity). Perspective
 * projection with vertical field of view fov_y. Caller-owned plain struct.
 */
/* asp_up_axis (which world axis points up) is declared in cloud.h: mesh loading records it too. */

typedef struct asp_camera {
    float target[3];
    float azimuth;    /* degrees */
    float elevation;  /* degrees, -90..90 */
    float distance;   /* eye to target, world units, > 0 */
    float fov_y;      /* vertical field of view, degrees, in (0, 180) */
    float aspect;     /* viewport width / height, > 0 */
    float z_near, z_far;
    asp_up_axis up;   /* world axis shown upright at elevation 0; azimuth turns around it */
} asp_camera;

/** Defaults: target 0, azimuth 0, elevation 0, distance 3, fov_y 40, aspect 1, near 0.01, far 100, up +y. */
void asp_camera_init(asp_camera *cam);

/**
 * Points the camera at a bounding sphere (center, radius > 0) and sets distance
 * so the sphere exactly fills the view: its silhouette cone touches the nearer
 * pair of frustum sides (top/bottom when aspect >= 1). Keeps azimuth,
 * elevation and fov_y, sets aspect, and sets near/far with
 * asp_camera_clip_to_sphere. To move closer or further afterwards, change
 * distance and call asp_camera_clip_to_sphere again.
 */
void asp_camera_fit(asp_camera *cam, const float center[3], float radius, float aspect);

/**
 * The one camera framing of every representation of a model (points, .amg,
 * .dps, .hier, and later meshes): fits cam to frame (a world-space sphere,
 * asp_frame in cloud.h, recorded in the files) seen in a renderer whose local
 * frame is centred on origin (the cloud's origin, asp_prim_renderer_desc.origin;
 * NULL = world origin), as asp_camera_fit with aspect; a flat, wide set
 * (frame->half known, its side along cam->up at most a third of its longest
 * other side) is then brought as close as its box allows in this view, so a
 * wide site fills the image. distance_radii > 0 puts the eye at that many frame radii from the
 * centre instead of fitting. Keeps azimuth, elevation, fov_y and up (set
 * cam->up first, e.g. to frame->up). frame->radius must be > 0. Thread safe.
 */
void asp_camera_frame(asp_camera *cam, const asp_frame *frame, const double origin[3], float aspect,
                      float distance_radii);

/** The distance asp_camera_fit would choose for radius with cam's fov_y and aspect. */
float asp_camera_fit_distance(const asp_camera *cam, float radius);

/**
 * Sets z_near/z_far so the sphere (center, radius) lies between them from the
 * current eye, with 1% slack; if the eye is inside, z_near = 0.001 * (distance
 * to center + radius) so the 24-bit depth buffer keeps its precision.
 */
void asp_camera_clip_to_sphere(asp_camera *cam, const float center[3], float radius);

/** Eye position in world units. */
void asp_camera_eye(const asp_camera *cam, float eye[3]);

/** View matrix (world to eye; eye looks down -z), column-major: m[col * 4 + row]. */
void asp_camera_view_matrix(const asp_camera *cam, float m[16]);

/** OpenGL perspective matrix (eye to clip, NDC z in -1..1), column-major. */
void asp_camera_projection_matrix(const asp_camera *cam, float m[16]);

/**
 * Projects world point p into a width x height image: out[0] = x in pixels
 * from the left edge, out[1] = y in pixels from the top edge (pixel (i, j)
 * covers [i, i+1) x [j, j+1), matching asp_image rows), out[2] = window depth
 * in 0..1 (0 on the near plane). Returns 1 if p is in front of the eye (then
 * out is filled, even when outside the image), else 0 and out is unchanged.
 */
int asp_camera_project(const asp_camera *cam, const float p[3], uint32_t width, uint32_t height, float out[3]);

/* ---- the maths of placing instances in a view (the scene renderer, draw_instances) ---- */

/**
 * The view of an instance placed by model (instance-local to world, affine,
 * column-major): view_out = view * model, and eye_out = model^-1 eye (the
 * world eye in the instance's local frame, inverted in double). view_out and
 * eye_out may alias view and eye. Pure.
 */
void asp_camera_fold_model(const float view[16], const float eye[3], const float model[16], float view_out[16],
                           float eye_out[3]);

/**
 * The six planes of the frustum clip = proj * view (Gribb and Hartmann 2001),
 * normalised: a world point x is inside where n . x + d >= 0 for every plane
 * (nx, ny, nz, d), in the order left, right, bottom, top, near, far. Pure.
 */
void asp_camera_frustum_planes(const float view[16], const float proj[16], float planes[6][4]);

#ifdef __cplusplus
}
#endif
#endif
