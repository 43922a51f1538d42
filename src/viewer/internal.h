/*
 * Private to the viewer module (src/viewer/): the key table, the camera
 * interaction math (no GL, unit-tested alone) and the keys on the scene.
 */
#ifndef ASP_VIEWER_INTERNAL_H
#define ASP_VIEWER_INTERNAL_H

#include "amgsplat/hier_ooc.h"
#include "amgsplat/instances.h"
#include "amgsplat/scene_renderer.h"
#include "amgsplat/scene.h"
#include "amgsplat/viewer.h"

/* What a key (or a character of asp_viewer_desc.keys) asks for. */
enum asp__viewer_action {
    ASP__VIEWER_NONE = 0,
    ASP__VIEWER_QUIT,
    ASP__VIEWER_RESET,
    ASP__VIEWER_LIGHT,
    ASP__VIEWER_NEXT_RENDERER,
    ASP__VIEWER_PICK_RENDERER, /* arg = index into the renderer table, 0-based */
    ASP__VIEWER_TAU_UP,
    ASP__VIEWER_TAU_DOWN,
    ASP__VIEWER_COLOR_MODE,
    ASP__VIEWER_LEVEL_FINER,
    ASP__VIEWER_LEVEL_COARSER,
    ASP__VIEWER_SCREENSHOT,
    ASP__VIEWER_HELP,
    ASP__VIEWER_PRINT_VIEW,
    ASP__VIEWER_ORBIT_LEFT,
    ASP__VIEWER_ORBIT_RIGHT,
    ASP__VIEWER_ORBIT_UP,
    ASP__VIEWER_ORBIT_DOWN,
    ASP__VIEWER_ZOOM_IN,
    ASP__VIEWER_ZOOM_OUT,
    /* .dps input (journal section 4): renderer options and the source points */
    ASP__VIEWER_NEXT_METHOD,
    ASP__VIEWER_ALPHA_DOWN,
    ASP__VIEWER_ALPHA_UP,
    ASP__VIEWER_OUTLINE,
    ASP__VIEWER_CREASES,
    ASP__VIEWER_POINTS,
    ASP__VIEWER_OVERLAY, /* the figures over the frame (frame time, tau, depth limit, counts) */
    /* thesis appendix C: the debug drawings and the Domain Set switch */
    ASP__VIEWER_DEBUG_EIGENVECTORS,
    ASP__VIEWER_DEBUG_TEXELS,
    ASP__VIEWER_DOMAIN_SET,
    ASP__VIEWER_PICK_DOMAIN, /* thesis appendix C: one picked domain only */
    ASP__VIEWER_EDL          /* eye-dome lighting of the disc and square renderers (Boucheny 2009) */
};

/* One printable key of the viewer; the table ends with key 0. */
typedef struct asp__viewer_key {
    char key;
    enum asp__viewer_action action;
    int arg;
    const char *help;
} asp__viewer_key;

extern const asp__viewer_key asp__viewer_keys[];

/* The table entry for character c, or NULL. */
const asp__viewer_key *asp__viewer_key_find(unsigned c);

/* ---- camera interaction (viewer_control.c; pure math, thread safe) ---- */

/* Degrees of orbit per pixel of mouse motion. */
#define ASP__VIEWER_ORBIT_DEG_PER_PX 0.25

/*
 * Orbits: dragging right by dx pixels turns the object right (the eye moves
 * left, azimuth decreases), dragging down raises the eye; elevation is clamped
 * to -90..90 and azimuth kept in [-180, 180).
 */
void asp__viewer_orbit(asp_camera *cam, double dx, double dy);

/*
 * Multiplies the eye distance by factor, clamped to [1e-3, 1e3] times the
 * scene radius so the view never collapses onto the target or loses it.
 */
void asp__viewer_dolly(asp_camera *cam, double factor, float radius);

/*
 * Pans by (dx, dy) pixels of a framebuffer height pixels tall: the target
 * moves in the image plane so that a point at the target's depth follows the
 * cursor exactly (dy > 0 is downwards, as in window coordinates).
 */
void asp__viewer_pan(asp_camera *cam, double dx, double dy, uint32_t height);

/*
 * The next screen tolerance on a fixed ladder 0, 0.25, 0.5, 1, 1.5, 2, 3, 4,
 * 6, 8, 12, 16, 24, 32, 48, 64 pixels: dir > 0 gives the smallest rung above
 * tau (tau itself at the top), dir < 0 the largest rung below (0 at the
 * bottom), so every value is reachable and 0 (every leaf) is one key away.
 */
float asp__viewer_tolerance_step(float tau, int dir);

/*
 * The scripted fly-through (fly.c; pure math): the camera at u in [0, 1] of
 * the path from start: azimuth start + 360 u, elevation start + 25 sin(2 pi u)
 * (within -89..89), distance start * (1 - 0.65 sin^2(pi u)), so the view
 * turns once around the model, passes above and below it and comes in to
 * 0.35 times the first distance half way, where the cut is largest.
 */
void asp__viewer_fly(const asp_camera *start, double u, asp_camera *cam);

/* ---- per-frame figures (frame_log.c): what --stats-json writes and the quantiles of asp_viewer_stats ---- */

typedef struct asp__viewer_frame {
    double frame_ms;       /* the whole frame: input, drawing, overlay, swap */
    double draw_ms;        /* asp_render_frame with glFinish only */
    float tolerance;       /* tau of the frame; NaN for renderers without a level of detail */
    uint32_t depth_limit;  /* 0 = none */
    size_t count;          /* primitives drawn */
    float azimuth, elevation, distance; /* the camera (distance in world units) */
} asp__viewer_frame;

typedef struct asp__viewer_frame_log {
    asp__viewer_frame *frames;
    size_t count, cap;
} asp__viewer_frame_log;

/* Appends f (growing the log). Returns 0 or ASP_ENOMEM (the log keeps what it had). */
int asp__viewer_frame_log_add(asp__viewer_frame_log *log, const asp_context *ctx, const asp__viewer_frame *f,
                              asp_error *err);
/* Fills the quantiles and ranges of st from the log (zeros when it is empty); ctx: scratch. */
void asp__viewer_frame_log_summary(const asp__viewer_frame_log *log, const asp_context *ctx, asp_viewer_stats *st);
/* Writes the log, st and the budget of d as JSON to path (atomically). Returns 0, ASP_EIO or ASP_ENOMEM. */
int asp__viewer_frame_log_save(const asp__viewer_frame_log *log, const asp_viewer_stats *st,
                               const asp_viewer_desc *d, const char *input, const char *path, asp_error *err);
void asp__viewer_frame_log_release(asp__viewer_frame_log *log, const asp_context *ctx);

/* ---- what is shown (scene_actions.c, over the one scene loader of scene.h) ---- */

/* Checks the scene parts of desc that need no file (colour mode). */
int asp__viewer_scene_check_desc(const asp_viewer_desc *desc, asp_error *err);

/* Loads path with asp_scene_load in the viewer's first colour mode and level. On failure s stays zeroed. */
int asp__viewer_scene_load(asp_scene *s, const char *path, const asp_viewer_desc *desc, const asp_context *ctx,
                           asp_error *err);

/*
 * A key on the scene (colour mode, level, source points). Returns 1 when what
 * is drawn changed (renderers must be made again; for ASP__VIEWER_POINTS:
 * s->cloud holds the source points), 0 when nothing changed (note says why,
 * or is empty when the key does not apply), or a negative ASP_E* with s
 * unchanged.
 */
int asp__viewer_scene_action(asp_scene *s, enum asp__viewer_action a, char *note, size_t note_cap, asp_error *err);

/* ---- a streamed .hier (stream.c): the cut of the resting camera, loaded by a second thread ---- */

typedef struct asp__viewer_stream asp__viewer_stream;

/*
 * Opens the streamed hierarchy at path for viewing: cuts of at most memory / 64 points (memory 0 =
 * 2 GiB, as render), refined to tau pixels of projected spacing (0 = 1). scripted: loads happen in
 * the frame after the camera stops, in the caller's thread, so runs repeat exactly. Returns 0 or
 * asp_ooc_open's errors, ASP_ENOMEM.
 */
int asp__viewer_stream_open(const char *path, size_t memory, float tau, int scripted, const asp_context *ctx,
                            asp__viewer_stream **out, asp_error *err);
/* The source's frame and the hierarchy's origin into scene (what framing and the renderers use). */
void asp__viewer_stream_frame(const asp__viewer_stream *s, asp_scene *scene);
/* Loads the cut of cam (w x h pixels) into scene->cloud, synchronously: the first picture. */
int asp__viewer_stream_first(asp__viewer_stream *s, const asp_camera *cam, uint32_t w, uint32_t h, asp_scene *scene,
                             asp_error *err);
/*
 * Called once per loop turn with the camera of the frame: when it has rested (REST_SECONDS, or one
 * frame when scripted) and its cut names other nodes than those shown, loads them (in a thread
 * unless scripted). *fresh = a new cloud to show instead (the caller owns it) or NULL. Returns 0 or
 * the selection's or load's error (the shown points stay valid).
 */
int asp__viewer_stream_update(asp__viewer_stream *s, const asp_camera *cam, uint32_t w, uint32_t h, double now,
                              asp_cloud **fresh, asp_error *err);
/* Sets the projected spacing cuts refine to (the + and - keys); the next turn chooses the cut again. */
void asp__viewer_stream_set_tolerance(asp__viewer_stream *s, float tau);
/* 1 while a load runs or a resting camera is still to be checked: the loop should poll, not sleep. */
int asp__viewer_stream_busy(const asp__viewer_stream *s);
void asp__viewer_stream_counts(const asp__viewer_stream *s, size_t *loads, size_t *nodes, size_t *node_count,
                               uint64_t *point_count);
/* Waits for a running load, frees everything; NULL is accepted. */
void asp__viewer_stream_close(asp__viewer_stream *s);

/* ---- scenes of instances (instances_view.c, instances.h) ---- */

/*
 * When path is a scene file: loads it into *is and fills *stand_in (zeroed
 * first) with its kind, path and frame, origin = the frame's centre (what the
 * scene renderer draws in), and returns 1. Returns 0 for any other file
 * (nothing touched), or the loader's negative error.
 */
int asp__viewer_instances_load(asp_instance_scene *is, asp_scene *stand_in, const char *path,
                               const asp_viewer_desc *desc, const asp_context *ctx, asp_error *err);

/* The scene renderer of is with point_renderer ("disc", "splat", "square") for its point sources. */
int asp__viewer_instances_renderer(asp_gl_context *gl, const asp_instance_scene *is, const char *point_renderer,
                                   const asp_renderer_options *o, const asp_context *ctx, asp_renderer **out,
                                   asp_error *err);

/* Title text, "scene of 1000 instances of 1 source". */
void asp__viewer_instances_status(const asp_instance_scene *is, char *status, size_t cap);

/* Title text for the scene, e.g. "domains, level 3 (L-2), 40 domains" or "level 2 (L-1)"; "" for points. */
void asp__viewer_scene_status(const asp_scene *s, char *status, size_t cap);
/* .dps: switches to the other domain set's level (thesis appendix C "Domain Set"; a file built with
 * --domains both). Returns 1 when the level changed, 0 with a note. */
int asp__viewer_scene_domain_set(asp_scene *s, char *note, size_t cap);

#endif
