/*
 * amgsplat instance scenes (issue 18 item 4): a JSON file placing instances
 * of point sets, .amg, .hier, .dps files and meshes with transforms, so
 * render, view and eval draw a whole scene, e.g. a field of models receding
 * to the horizon (seed 004's large scenes, seed 001's view-dependent detail).
 * Every distinct source is loaded once with asp_scene_load (scene.h, the one
 * loader) and shared by its instances. The format: docs/scene-format.md.
 */
#ifndef AMGSPLAT_INSTANCES_H
#define AMGSPLAT_INSTANCES_H

#include "camera.h"
#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Most instances a scene file may place (refused above: a typo of 1e9 must not allocate gigabytes). */
#define ASP_INSTANCE_SCENE_MAX_INSTANCES 1000000
/** Most distinct source files of one scene. */
#define ASP_INSTANCE_SCENE_MAX_SOURCES 1024
/** Largest magnitude of a translation, matrix entry or camera coordinate accepted. */
#define ASP_INSTANCE_SCENE_MAX_COORD 1e9

/** One instance: which source, and where. */
typedef struct asp_instance {
    size_t source;     /* index into asp_instance_scene.sources */
    double model[16];  /* source world coordinates to scene world coordinates, column-major, affine */
} asp_instance;

/** One distinct source file of a scene. */
typedef struct asp_instance_source {
    char name[512];  /* as the scene file writes it (relative to the scene file's folder unless absolute) */
    char path[1024]; /* resolved: the file opened */
    asp_scene scene; /* loaded by asp_instance_scene_load; zeroed after asp_instance_scene_parse */
} asp_instance_source;

/** The default view of a scene file ("camera"). */
typedef struct asp_instance_camera {
    int given;        /* 0: none in the file; the caller frames the scene (asp_instance_scene_camera) */
    double eye[3];    /* scene world coordinates */
    double target[3]; /* looked at; differs from eye */
    float fov_y;      /* degrees in (0, 180); 0 = the caller's */
} asp_instance_camera;

/** A scene of instances; release with asp_instance_scene_release. */
typedef struct asp_instance_scene {
    char path[512];              /* the scene file as given */
    size_t source_count;
    asp_instance_source *sources;
    size_t instance_count;
    asp_instance *instances;
    asp_instance_camera camera;
    int has_background;          /* 1: "background" given */
    uint8_t background[4];       /* sRGB RGBA */
    asp_frame frame;             /* after asp_instance_scene_load: world sphere around every instance (the one
                                    framing of the whole scene); radius 0 before */
    asp_context ctx;             /* allocator of sources and instances (the default one) */
} asp_instance_scene;

/**
 * Parses and validates scene file text (len bytes, need not be
 * NUL-terminated) read from path (names in messages; sources are resolved
 * against its folder). Loads no source. Strict: the root must be an object
 * with "version": 1 and a non-empty "instances" array; each instance an
 * object with a non-empty "source" string and either "matrix" (16 numbers,
 * column-major, affine: last row 0 0 0 1) or any of "translate" [3],
 * "rotate_deg" [3] (Euler angles about x, then y, then z), "rotate_axis_angle"
 * [4] (axis, degrees; not with rotate_deg) and "scale" (a number or [3], each
 * > 0), composed as translate * rotate * scale. Optional "camera" {"eye",
 * "target", "fov"} and "background" [R,G,B(,A)] in 0..255. Unknown keys,
 * non-finite or out-of-range numbers (|x| <= ASP_INSTANCE_SCENE_MAX_COORD),
 * singular or mirroring (negative determinant) transforms, more than
 * ASP_INSTANCE_SCENE_MAX_INSTANCES instances or
 * ASP_INSTANCE_SCENE_MAX_SOURCES sources are refused. Returns 0 and *out
 * (zeroed or released before); ASP_EFORMAT "'f.json' instance 3: 'scale' must
 * be a number > 0 or three of them" naming the file, the instance and the
 * field; ASP_ENOMEM. *out is unchanged on failure. Reentrant.
 */
int asp_instance_scene_parse(const char *text, size_t len, const char *path, asp_instance_scene *out,
                             asp_error *err);

/**
 * Reads path (a regular file of at most 64 MiB) and parses it as
 * asp_instance_scene_parse. Errors as that, plus ASP_EIO.
 */
int asp_instance_scene_read(const char *path, asp_instance_scene *out, asp_error *err);

/**
 * Reads path and loads every distinct source once with asp_scene_load (desc
 * and ctx as there; NULL = defaults), then sets out->frame: the centre of the
 * bounding box of the instances' spheres (each source's frame moved by its
 * model, radius times the model's largest axis scale) and the largest
 * distance from it to a sphere's far side. A source that is itself a scene
 * file is refused (no recursion). Returns 0; the errors of
 * asp_instance_scene_read; a source's loader error prefixed with
 * "'f.json' instance I source 'name': "; ASP_EUNSUPPORTED (a scene inside a
 * scene, an image); ASP_ENOMEM. *out is unchanged on failure.
 */
int asp_instance_scene_load(const char *path, const asp_scene_desc *desc, const asp_context *ctx,
                            asp_instance_scene *out, asp_error *err);

/**
 * Writes s as a scene file (version 1; each instance's "matrix" as 16
 * numbers, sources by name, the camera and background when given) through
 * the atomic writer. Reading it back gives the same instances (numbers are
 * printed with 17 significant digits). Returns 0, ASP_ENOMEM or ASP_EIO.
 */
int asp_instance_scene_save(const asp_instance_scene *s, const char *path, asp_error *err);

/**
 * The float model matrices the scene renderer draws instances of source
 * with: for every instance of that source (in file order), the map from the
 * source renderer's local frame (s->sources[source].scene.origin) to the
 * scene world centred on s->frame.center, 16 floats each, into dst
 * (capacity 16 * asp_instance_scene_count(s, source)). Returns the number
 * of instances written. Pure.
 */
size_t asp_instance_scene_models(const asp_instance_scene *s, size_t source, float *dst);

/** Instances of source in s. Pure. */
size_t asp_instance_scene_count(const asp_instance_scene *s, size_t source);

/**
 * The camera of a scene: its "camera" when given and orbit is 0 (eye,
 * target, fov_y or fov_y_default), else asp_camera_frame of s->frame at
 * azimuth and elevation (degrees) and distance_radii (0 = fit), fov_y_default. The frame of the returned camera is
 * the scene's world centred on s->frame.center (the origin the scene
 * renderer draws in: pass it to asp_instance_scene_models). Near and far
 * planes hold the whole scene (asp_camera_clip_to_sphere). Pure (camera.h
 * maths, no GL: the same camera in every build).
 */
void asp_instance_scene_camera(const asp_instance_scene *s, int orbit, float aspect, float fov_y_default,
                               float azimuth, float elevation, float distance_radii, asp_camera *cam);

/** Options of asp_instance_field; the zero value means defaults. */
typedef struct asp_instance_field_desc {
    size_t instances; /* how many; 0 = 100 */
    uint64_t seed;    /* yaw and jitter; the same seed gives the same file */
    double spacing;   /* grid step in model diameters (2 x the model frame's radius); 0 = 1.5 */
    double jitter;    /* random offset in grid steps, uniform in +-jitter/2; 0 = 0.3; < 0 = none */
} asp_instance_field_desc;

/**
 * A field of desc->instances instances of model (a loaded asp_scene, named
 * source_name in the file) standing on the ground plane y = 0 (world, +y
 * up): a grid desc->spacing model diameters apart, roughly twice as deep as
 * wide, each turned by a random yaw about +y and moved by a small jitter
 * (seeded, so deterministic), scaled 1, its lowest point on the ground.
 * The default camera stands at the near edge of the field at the eye height
 * of half a model, looking along it, so near instances show large and far ones
 * tiny. Fills *out (zeroed or released before) without loading anything;
 * out->sources[0].scene stays zeroed. Returns 0; ASP_EINVAL (instances above
 * ASP_INSTANCE_SCENE_MAX_INSTANCES, a bad spacing or jitter, a source name of
 * 512 bytes or more); ASP_EDEGENERATE (a model without a frame); ASP_ENOMEM.
 */
int asp_instance_field(const asp_scene *model, const char *source_name, const asp_instance_field_desc *desc,
                       asp_instance_scene *out, asp_error *err);

/**
 * Makes the scene renderer (scene_renderer.h) of a loaded scene: per source
 * one renderer of the table (render.h) with options (NULL = defaults) and ctx,
 * and all its instances (asp_instance_scene_models), culled by the source's
 * frame. The row is point_renderer ("disc", "splat", "square") for sources
 * with points (point files, .amg, .hier; NULL = "disc"; a .hier, which has
 * no points for discs, is drawn by "splat" then), "prim" for .dps files and
 * "mesh" for meshes. Draw with a camera of
 * asp_instance_scene_camera. s must outlive the renderer (hierarchies are
 * shared). Makes gl current. Returns 0; ASP_EINVAL (an unknown
 * point_renderer); a source renderer's errors prefixed with its name;
 * ASP_EUNSUPPORTED (a build without GL); ASP_ENOMEM. *out is unchanged on
 * failure.
 */
int asp_instance_scene_renderer_create(asp_gl_context *gl, const asp_instance_scene *s, const char *point_renderer,
                                       const asp_renderer_options *options, const asp_context *ctx,
                                       asp_renderer **out, asp_error *err);

/** Options of asp_instance_scene_eval; the zero value means defaults. */
typedef struct asp_instance_eval_desc {
    uint32_t width, height;    /* image size; 0 = 256 x 256 */
    size_t frames;             /* timed frames per row, median; 0 = 3 */
    const float *tolerances;   /* splat tolerances tau in pixels measured against the reference; NULL = 1, 2, 4, 8 */
    size_t tolerance_count;
    const asp_renderer_options *options; /* NULL = defaults; splat.tolerance and square.tolerance are set per row */
    int orbit;                 /* 1: view from azimuth/elevation (degrees) instead of the file's camera */
    float azimuth, elevation;
} asp_instance_eval_desc;

/** One representation of the whole scene against the reference (asp_instance_scene_eval). */
typedef struct asp_instance_eval_row {
    char renderer[16];      /* "splat", "disc", "square" */
    float tolerance;        /* tau in pixels (splat, square); 0 for disc */
    size_t primitives;      /* splats or discs drawn in the last frame, over all instances */
    size_t instances_drawn; /* after frustum culling */
    double psnr, ssim, iou; /* against the reference image (asp_image_psnr, _ssim, _silhouette_iou) */
    double frame_ms;        /* median over desc->frames frames: draw, resolve and read back */
    asp_image image;        /* the row's render (owned by the result) */
} asp_instance_eval_row;

/** What asp_instance_scene_eval measured; free with asp_instance_eval_result_destroy. */
typedef struct asp_instance_eval_result {
    size_t row_count;
    asp_instance_eval_row *rows; /* rows[0] is the reference itself: splats at tau 0 (every point of every instance) */
    const char *gl_renderer;     /* GL_RENDERER of the context used; static storage of the result */
    char gl_renderer_text[128];
} asp_instance_eval_result;

/**
 * issue 18's scene measure: renders the whole scene s (loaded) from its
 * camera (or desc's orbit view) as the reference, blended splats at tau 0
 * (full detail), then as discs (every point), as splats at each tolerance
 * and as squares at the largest, and compares each image with the
 * reference (PSNR, SSIM, silhouette IoU on white) and times it (median
 * frame in ms). Makes its own headless GL context. Returns 0 and *out;
 * ASP_EINVAL (a negative or non-finite tolerance, more than 32); the
 * renderers' and metrics' errors; ASP_EUNSUPPORTED without GL; ASP_ENOMEM.
 */
int asp_instance_scene_eval(const asp_instance_scene *s, const asp_instance_eval_desc *desc, const asp_context *ctx,
                            asp_instance_eval_result **out, asp_error *err);

/**
 * Writes res as JSON (scene, gl_renderer, and per row renderer, tolerance,
 * primitives, instances_drawn, psnr (null when identical), ssim, iou,
 * frame_ms) to path through the atomic writer. Returns 0, ASP_ENOMEM or
 * ASP_EIO.
 */
int asp_instance_eval_save_json(const asp_instance_eval_result *res, const char *scene, const char *path,
                                asp_error *err);

/** Frees a result of asp_instance_scene_eval; NULL is accepted. */
void asp_instance_eval_result_destroy(asp_instance_eval_result *r);

/** Frees everything s owns (the loaded sources too) and zeroes it; a zeroed scene is accepted. */
void asp_instance_scene_release(asp_instance_scene *s);

#ifdef __cplusplus
}
#endif
#endif
