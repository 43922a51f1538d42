/*
 * amgsplat viewer: the interactive application behind `amgsplat view`, a
 * module of its own above render (STYLE.md 9b), as sokol_app sits apart from
 * sokol_gfx: render draws into a framebuffer it is given and knows nothing of
 * files, keys or windows; the viewer owns the window's input, the keys and
 * the scene (scene.h) it shows.
 */
#ifndef AMGSPLAT_VIEWER_H
#define AMGSPLAT_VIEWER_H

#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* Interactive viewer (GLFW window; amgsplat view)                          */
/* ------------------------------------------------------------------------ */

/** Flags for asp_viewer_desc.flags; 0 is the default. */
enum asp_viewer_flags {
    ASP_VIEWER_UNLIT = 1 << 0,  /* start with lighting off (the l key toggles it) */
    ASP_VIEWER_VERBOSE = 1 << 1, /* log frame time and primitive count about once a second */
    ASP_VIEWER_OVERLAY = 1 << 2, /* start with the figures drawn over the frame (the i key toggles them; on by
                                    default with a frame budget) */
    ASP_VIEWER_NO_OVERLAY = 1 << 3 /* start without them, even with a frame budget */
};

/**
 * Receives one line of viewer output (no trailing newline): screenshot names,
 * key help, the current view, renderer switches that failed, and with
 * ASP_VIEWER_VERBOSE the frame statistics. Called on the viewer's thread.
 */
typedef void (*asp_viewer_log_fn)(void *user, const char *line);

/** Options of asp_viewer_run; the zero value means defaults. */
typedef struct asp_viewer_desc {
    uint32_t width, height;  /* window client area, 1..16384; 0 = 1280 x 800 */
    const char *renderer;    /* first renderer: a name of asp_viewer_renderer_name; NULL = "mesh" for a mesh,
                                "splat" for a .hier, else the first row that draws the input ("disc") */
    float tolerance;         /* screen tolerance tau in pixels for renderers that take one, >= 0 */
    int set_view;            /* nonzero: start at azimuth/elevation/distance below, else 30, 20, fitted */
    float azimuth;           /* degrees (asp_camera conventions) */
    float elevation;         /* degrees, -90..90 */
    float distance;          /* eye distance in bounding-sphere radii; 0 = the sphere fills the view */
    int set_up;              /* nonzero: show up below upright; 0: the file's recorded up axis (asp_frame.up:
                                z for LAS and the .amg/.dps/.hier made from it, else +y) */
    asp_up_axis up;          /* world axis shown upright (asp_camera.up) when set_up */
    unsigned amg_color;      /* .amg input: first colour mode, an asp_amg_color_mode (amg.h; 0 = classifier),
                                or 3 = the points' own colours (refused when they have none) */
    const char *amg_level;   /* .amg input: first level, "L", "L-2" or an index; NULL = "L";
                                .dps input: the level drawn, a name or index in the file; NULL = its finest */
    unsigned prim_method;    /* .dps input: first blending method, an asp_prim_render_method (0 = normalized) */
    float prim_alpha_ref;    /* .dps input: first alpha reference as asp_prim_render_options.alpha_ref
                                (0 = 0.1, < 0 = exactly 0, at most 1) */
    const char *texture;     /* mesh input: image used as the texture of materials that name none or whose
                                file is missing (asp_scene_desc.texture); NULL = none */
    uint8_t background[4];   /* sRGB; alpha 0 = default opaque white */
    size_t frames;           /* 0 = interactive until closed; N = scripted: draw N frames, then return */
    const char *screenshot;  /* scripted: PNG written from the last frame's back buffer; may be NULL */
    const char *keys;        /* keys pressed one per frame from the first frame on, e.g. "]]l" (see docs/cli/view.md) */
    unsigned flags;          /* asp_viewer_flags */
    unsigned lod_flags;      /* splat and square renderers: asp_splat_renderer_flags (ASP_SPLAT_CULL_BACKFACES,
                                seed 004 3.2.2) */
    uint32_t depth_limit;    /* splat and square renderers: traversal depth limit (seed 004 3.2.5); 0 = none */
    asp_viewer_log_fn log;   /* NULL = lines are dropped */
    void *log_user;
    double frame_ms;         /* > 0: frame budget (issue 18 item 5): each frame sets tau (and, at the coarsest
                                tau, the depth limit) of a renderer with a level of detail so the frame time
                                holds this many ms (asp_frame_budget); 0 = off */
    int fly;                 /* scripted: the camera flies around the model over the desc->frames frames
                                (asp_viewer_desc.frames; a full turn, up and down, in to 0.35 times the
                                first distance and out again), the same path every run */
    const char *stats_json;  /* scripted or not: JSON file written at the end with every frame's time, tau,
                                depth limit and count and their summary; NULL = none */
    const char *color_field; /* point file: colour the points by this scalar as asp_cloud_color_by does
                                (elevation along up, classification, intensity, return_number, a property);
                                NULL = their own colours */
    int edl;                 /* eye-dome lighting of the disc and square renderers (asp_edl_desc; the E key
                                toggles it): 0 = on when the points have no normals and ASP_VIEWER_UNLIT is
                                not set, > 0 = on, < 0 = off */
    float edl_strength;      /* asp_edl_desc.strength when on; 0 = 1 */
    size_t memory;           /* a streamed .hier (hier_ooc.h): bytes for the points of a view's cut, as
                                amgsplat render --memory (64 bytes a point); 0 = 2 GiB */
} asp_viewer_desc;

/** What a viewer run did, for scripts (amgsplat view --json). */
typedef struct asp_viewer_stats {
    size_t frames;            /* frames drawn */
    double mean_frame_ms;     /* mean time of asp_render_frame with ASP_RENDER_WAIT (drawing finished) */
    double last_frame_ms;
    size_t count;             /* primitives the renderer drew in the last frame */
    char renderer[32];        /* renderer of the last frame */
    uint32_t width, height;   /* framebuffer size of the last frame, pixels */
    size_t screenshots;       /* PNG files written (the s key and desc->screenshot) */
    char gl_renderer[128];    /* GL_RENDERER of the window's context */
    char title[320];          /* the window title at the end: file, renderer, count, frame time, tau, mode */
    /* Frame times: the whole frame, input to swap, as the user waits for it (not only the drawing of
     * mean_frame_ms), over every frame drawn */
    double median_frame_ms, p10_frame_ms, p90_frame_ms;
    float tolerance_min, tolerance_max; /* range of tau over the frames drawn by a level-of-detail renderer */
    size_t count_min, count_max;        /* range of primitives drawn per frame */
    int budget_applied;       /* desc->frame_ms > 0 and the last renderer took it (it has a level of detail) */
    char overlay[640];        /* the figures last drawn over the frame (the i key): file, renderer, level or
                                 method, colours, frame time, counts; "" when they were never shown */
    int edl;                  /* eye-dome lighting was on in the last frame */
    size_t stream_loads;      /* a streamed .hier: cuts loaded (the first view's included) */
    size_t stream_points;     /* a streamed .hier: points shown in the last frame's cut */
    uint64_t stream_point_count; /* a streamed .hier: points in the file */
} asp_viewer_stats;

/**
 * Name of renderer kind i of the viewer: row i of the renderer table
 * (asp_renderer_kind_at in render.h: "disc", "splat", "square", "prim" ...,
 * in the order the 1..9 keys pick them), or NULL when i is past the end. A
 * kind may fail to draw a given input, in which case the viewer skips it.
 * Thread safe.
 */
const char *asp_viewer_renderer_name(size_t i);

/**
 * Checks desc without opening anything: sizes, renderer name, tolerance,
 * view, colour mode, .dps method and alpha reference, keys (each must be a viewer key), that screenshot
 * ends in .png and is given only with frames > 0, the frame budget (0..1e6 ms) and that a fly-through
 * has frames. Returns 0 or ASP_EINVAL
 * naming the bad value, e.g. "unknown renderer 'x' (expected disc, splat)".
 * Thread safe.
 */
int asp_viewer_desc_check(const asp_viewer_desc *desc, asp_error *err);

/**
 * Opens a window on path, loaded by the one scene loader (asp_scene_load:
 * points, an .amg decomposition coloured by classifier or domains, a .hier
 * point hierarchy, or a .dps level of domain primitives
 * drawn by the "prim" renderer, its method, alpha reference, outlines and
 * domain colours on keys, its source points on p) and runs the viewer:
 * orbit with the left mouse button, zoom with the wheel or the right button,
 * pan with the middle button or shift + left; keys switch renderers, the
 * tolerance, lighting, colour mode and level (docs/cli/view.md lists them).
 * The window title shows the renderer, the primitive count and the frame time.
 * Interactive (desc->frames == 0) it returns when the window is closed or q /
 * Esc is pressed; scripted it draws desc->frames frames, pressing desc->keys
 * one per frame, writes desc->screenshot from the last frame and returns.
 *
 * The camera is framed as amgsplat render frames it (asp_camera_frame on
 * the scene's frame), so a scripted view matches render's --view. ctx gives
 * the allocator and threads for loading and colouring (NULL = defaults).
 * The file is loaded before the window opens, so a bad file fails without a
 * display. Must run on the main thread; opens and closes GLFW itself (no other
 * window context may be alive). stats may be NULL; it is filled on success.
 * Returns 0; ASP_EINVAL (desc, as asp_viewer_desc_check; a level out of
 * range); the loader's ASP_EIO / ASP_EFORMAT / ASP_EUNSUPPORTED naming the
 * file; ASP_EDEGENERATE (nothing to frame); ASP_EGL (no display or no OpenGL
 * 4.5: "no OpenGL 4.5 window: ..."); ASP_EIO (screenshot not written);
 * ASP_ENOMEM. Everything is freed on return.
 */
int asp_viewer_run(const char *path, const asp_viewer_desc *desc, const asp_context *ctx, asp_viewer_stats *stats,
                   asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
