/*
 * The interactive viewer behind `amgsplat view`: a GLFW window, an orbit
 * camera driven by the mouse, keys that switch renderers (opaque discs,
 * Pajarola et al. 2003 section 5; splats and squares, seed 004 3.2.6; the
 * textured domain primitives of a .dps level, journal section 4), the screen
 * tolerance, the .amg colouring, the .dps blending options, and a scripted
 * mode for tests; with a frame budget (issue 18 item 5) each frame sets the
 * tolerance that holds the frame time, and the figures show over the frame.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "viewer/internal.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "util/banned.h"

/* ---- renderer kinds: the rows of the one renderer table; the 1..9 keys pick them in this order ---- */

typedef struct viewer viewer;

static const asp_renderer_kind *K(size_t i)
{
    return asp_renderer_kind_at(i);
}

const char *asp_viewer_renderer_name(size_t i)
{
    const asp_renderer_kind *k = asp_renderer_kind_at(i);
    return k ? k->name : NULL;
}

/* Index of the row named name, or asp_renderer_kind_count() when there is none. */
static size_t find_renderer(const char *name)
{
    size_t n = asp_renderer_kind_count();
    for (size_t i = 0; i < n; i++)
        if (strcmp(K(i)->name, name) == 0)
            return i;
    return n;
}

/* ---- options ---- */

enum { MAX_SIDE = 16384, QUEUE_CAP = 64, LOG_CAP = 512 };


int asp_viewer_desc_check(const asp_viewer_desc *desc, asp_error *err)
{
    if (desc->width > MAX_SIDE || desc->height > MAX_SIDE)
        return asp_error_set(err, ASP_EINVAL, "window size %ux%u is outside 1..%d", desc->width, desc->height,
                             MAX_SIDE);
    const asp_renderer_kind *found;
    if (desc->renderer && asp_renderer_kind_find(desc->renderer, 0, &found, err))
        return ASP_EINVAL;
    if (!(desc->tolerance >= 0) || !isfinite(desc->tolerance))
        return asp_error_set(err, ASP_EINVAL, "tolerance %g is not a number of pixels >= 0", desc->tolerance);
    if (desc->set_view && (!isfinite(desc->azimuth) || !(desc->elevation >= -90 && desc->elevation <= 90) ||
                           !(desc->distance >= 0) || !isfinite(desc->distance)))
        return asp_error_set(err, ASP_EINVAL,
                             "view %g,%g,%g is invalid (expected EL in -90..90 and DIST >= 0 radii)", desc->azimuth,
                             desc->elevation, desc->distance);
    if ((unsigned)desc->up > ASP_UP_NEG_X)
        return asp_error_set(err, ASP_EINVAL, "unknown up axis %u (expected 0..5: y, z, x, -y, -z, -x)",
                             (unsigned)desc->up);
    if (!asp_prim_render_method_name((asp_prim_render_method)desc->prim_method))
        return asp_error_set(err, ASP_EINVAL, "unknown .dps method %u (expected 0..%u)", desc->prim_method,
                             (unsigned)ASP_PRIM_RENDER_POLYGONS);
    if (!(desc->prim_alpha_ref <= 1))
        return asp_error_set(err, ASP_EINVAL, "alpha reference %g is not a number <= 1", desc->prim_alpha_ref);
    int rc = asp__viewer_scene_check_desc(desc, err);
    if (rc)
        return rc;
    if (desc->keys) {
        for (const char *k = desc->keys; *k; k++)
            if (!asp__viewer_key_find((unsigned char)*k))
                return asp_error_set(err, ASP_EINVAL, "key '%c' (character %zu of '%s') is not a viewer key", *k,
                                     (size_t)(k - desc->keys) + 1, desc->keys);
        if (desc->frames > 0 && strlen(desc->keys) > desc->frames)
            return asp_error_set(err, ASP_EINVAL, "%zu keys need at least as many frames, got %zu",
                                 strlen(desc->keys), desc->frames);
    }
    if (desc->screenshot && desc->frames == 0)
        return asp_error_set(err, ASP_EINVAL, "a screenshot file needs a number of frames (scripted mode)");
    if (desc->screenshot && !asp_file_name_is(desc->screenshot, "png"))
        return asp_error_set(err, ASP_EINVAL, "screenshot '%s' must end in .png", desc->screenshot);
    if (!(desc->edl_strength >= 0 && desc->edl_strength <= 100))
        return asp_error_set(err, ASP_EINVAL, "eye-dome lighting strength %g is outside 0..100",
                             (double)desc->edl_strength);
    if (!(desc->frame_ms >= 0 && desc->frame_ms <= 1e6))
        return asp_error_set(err, ASP_EINVAL, "frame budget %g ms is outside 0..1e6", desc->frame_ms);
    if (desc->fly && desc->frames == 0)
        return asp_error_set(err, ASP_EINVAL, "a fly-through needs a number of frames (scripted mode)");
    return 0;
}

/* ---- viewer state ---- */

typedef struct action {
    enum asp__viewer_action what;
    int arg;
} action;

struct viewer {
    const asp_viewer_desc *desc;
    const char *path;
    asp_scene scene;
    asp_instance_scene instances; /* a scene file: its instances; scene is then a stand-in holding its frame */
    int is_scene;
    char status[96];       /* the scene's title text (asp__viewer_scene_status) */
    float center[3];       /* the scene's frame in its renderers' local frame (scene.origin) */
    float radius;
    asp_context ctx;
    asp_gl_context *gl;
    GLFWwindow *window;
    asp_renderer *r;
    size_t kind;           /* row of the renderer table (asp_renderer_kind_at) of r */
    asp_hier *hier;        /* point hierarchy of scene.cloud, built when a renderer first needs it */
    float tolerance;
    uint32_t depth_limit;  /* desc->depth_limit, kept across tau changes */
    int unlit;
    asp_prim_render_options prim; /* .dps: options of the prim renderer, kept while the points are shown */
    size_t picked;                /* .dps: the one primitive drawn (thesis appendix C), SIZE_MAX = every one */
    asp_camera cam;
    int quit;
    int dirty;             /* something changed: draw a frame */
    int screenshot_wanted; /* the s key: save after the next draw */
    unsigned screenshot_seq;
    /* mouse */
    int buttons;           /* bit per GLFW mouse button held */
    int shift;             /* shift was held when the drag started */
    double mx, my;
    /* keys pressed in callbacks, applied by the loop (which can report errors) */
    action queue[QUEUE_CAP];
    size_t queued;
    /* statistics */
    size_t frames;
    double total_ms, last_ms;
    double window_start;   /* verbose: start of the current one-second window */
    size_t window_frames;
    double window_ms;
    double title_time;
    double frame_last_ms;  /* the whole last frame (input to swap), what the budget holds */
    int title_stale;       /* the last frame's figures are not in the title yet */
    asp_viewer_stats stats;
    size_t kind_prim;      /* row of the "prim" renderer */
    /* frame budget (desc->frame_ms > 0) and the figures over the frame */
    int budget_on;
    asp_frame_budget budget;
    int budget_ok;            /* the current renderer took the budget's tau */
    size_t budget_told;       /* 1 + the renderer kind the log was last told about (no level of detail) */
    int overlay_on;
    asp_text_overlay *overlay;
    double frame_top;         /* when the current frame began (after any idle wait) */
    asp_camera fly_start;     /* the first view: the fly-through's path starts there */
    asp__viewer_frame_log flog;
    int edl_on;               /* eye-dome lighting for the disc and square renderers (desc->edl, the E key) */
    int help_on;              /* the h key: the keys drawn over the frame */
    asp__viewer_stream *stream; /* a streamed .hier: its cuts replace scene.cloud as the camera rests */
};

static void vlog(const viewer *v, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void vlog(const viewer *v, const char *fmt, ...)
{
    if (!v->desc->log)
        return;
    char line[LOG_CAP];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    v->desc->log(v->desc->log_user, line);
}

static void push(viewer *v, enum asp__viewer_action what, int arg)
{
    if (v->queued < QUEUE_CAP)
        v->queue[v->queued++] = (action){what, arg};
}

/* ---- camera ---- */

static void reset_view(viewer *v)
{
    const asp_viewer_desc *d = v->desc;
    float aspect = v->cam.aspect > 0 ? v->cam.aspect : 1.0f;
    asp_camera_init(&v->cam);
    v->cam.up = d->set_up ? d->up : v->scene.frame.up; // the file's own (asp_frame.up: z for a LAS scan)
    v->cam.azimuth = d->set_view ? d->azimuth : 30.0f;
    v->cam.elevation = d->set_view ? d->elevation : 20.0f;
    // the one framing of amgsplat render, so a scripted view matches its --view
    asp_camera_frame(&v->cam, &v->scene.frame, v->scene.origin, aspect, d->set_view ? d->distance : 0.0f);
    if (v->is_scene && !d->set_view) // the scene file's own camera, when it has one
        asp_instance_scene_camera(&v->instances, 0, aspect, v->cam.fov_y, v->cam.azimuth, v->cam.elevation, 0.0f,
                                  &v->cam);
    v->dirty = 1;
}

/* ---- GLFW callbacks: they only record input; the loop acts on it ---- */

static viewer *from_window(GLFWwindow *w)
{
    return glfwGetWindowUserPointer(w);
}

static void on_char(GLFWwindow *w, unsigned codepoint)
{
    viewer *v = from_window(w);
    const asp__viewer_key *k = asp__viewer_key_find(codepoint);
    if (k)
        push(v, k->action, k->arg);
}

static void on_key(GLFWwindow *w, int key, int scancode, int act, int mods)
{
    (void)scancode;
    (void)mods;
    viewer *v = from_window(w);
    if (act == GLFW_RELEASE)
        return;
    // keys without a character; printable keys arrive through on_char (layout-aware)
    static const struct {
        int key;
        enum asp__viewer_action what;
    } special[] = {
        {GLFW_KEY_ESCAPE, ASP__VIEWER_QUIT},        {GLFW_KEY_TAB, ASP__VIEWER_NEXT_RENDERER},
        {GLFW_KEY_HOME, ASP__VIEWER_RESET},         {GLFW_KEY_F1, ASP__VIEWER_HELP},
        {GLFW_KEY_LEFT, ASP__VIEWER_ORBIT_LEFT},    {GLFW_KEY_RIGHT, ASP__VIEWER_ORBIT_RIGHT},
        {GLFW_KEY_UP, ASP__VIEWER_ORBIT_UP},        {GLFW_KEY_DOWN, ASP__VIEWER_ORBIT_DOWN},
        {GLFW_KEY_PAGE_UP, ASP__VIEWER_ZOOM_IN},    {GLFW_KEY_PAGE_DOWN, ASP__VIEWER_ZOOM_OUT},
    };
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        if (special[i].key == key && (act == GLFW_PRESS || key != GLFW_KEY_ESCAPE))
            push(v, special[i].what, 0);
}

static void on_button(GLFWwindow *w, int button, int act, int mods)
{
    viewer *v = from_window(w);
    if (button < 0 || button > 7)
        return;
    if (act == GLFW_PRESS) {
        v->buttons |= 1 << button;
        v->shift = (mods & GLFW_MOD_SHIFT) != 0; // shift chooses pan for the whole drag
    } else {
        v->buttons &= ~(1 << button);
    }
    glfwGetCursorPos(w, &v->mx, &v->my);
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    viewer *v = from_window(w);
    double dx = x - v->mx, dy = y - v->my;
    v->mx = x;
    v->my = y;
    int left = v->buttons & (1 << GLFW_MOUSE_BUTTON_LEFT), right = v->buttons & (1 << GLFW_MOUSE_BUTTON_RIGHT);
    int middle = v->buttons & (1 << GLFW_MOUSE_BUTTON_MIDDLE);
    if (middle || (left && v->shift)) {
        int ww = 0, wh = 0;
        glfwGetWindowSize(w, &ww, &wh); // cursor positions are in screen units, not framebuffer pixels
        asp__viewer_pan(&v->cam, dx, dy, wh > 0 ? (uint32_t)wh : 1);
    } else if (left) {
        asp__viewer_orbit(&v->cam, dx, dy);
    } else if (right) {
        asp__viewer_dolly(&v->cam, exp(0.01 * dy), v->radius); // drag up to come closer
    } else {
        return;
    }
    v->dirty = 1;
}

static void on_scroll(GLFWwindow *w, double xoff, double yoff)
{
    (void)xoff;
    viewer *v = from_window(w);
    asp__viewer_dolly(&v->cam, pow(0.85, yoff), v->radius);
    v->dirty = 1;
}

static void on_redraw(GLFWwindow *w)
{
    from_window(w)->dirty = 1;
}

static void on_resize(GLFWwindow *w, int width, int height)
{
    (void)width;
    (void)height;
    from_window(w)->dirty = 1;
}

/* ---- renderers ---- */

/* The splat and square renderers share one hierarchy, so switching between them is instant. */
static int ensure_hier(viewer *v, asp_error *err)
{
    if (v->hier || v->scene.hier || !v->scene.cloud)
        return 0;
    double t0 = asp_time_now();
    int rc = asp_hier_build(v->scene.cloud, NULL, &v->ctx, &v->hier, err);
    if (rc)
        return rc;
    vlog(v, "built the point hierarchy: %zu nodes over %zu points in %.2f s", asp_hier_node_count(v->hier),
         asp_hier_point_count(v->hier), asp_time_now() - t0);
    return 0;
}

static int make_renderer(viewer *v, size_t k, asp_renderer **out, asp_error *err)
{
    if (K(k)->has_lod) {
        int rc = ensure_hier(v, err);
        if (rc)
            return rc;
    }
    asp_render_source src;
    asp_scene_render_source(&v->scene, &src);
    if (v->hier)
        src.hier = v->hier;
    asp_renderer_options o;
    memset(&o, 0, sizeof o);
    o.disc.radius_scale = 1;
    o.splat.tolerance = v->tolerance;
    o.square.tolerance = v->tolerance;
    o.splat.flags = o.square.flags = v->desc->lod_flags;
    if (v->edl_on && !v->is_scene) // the renderers without the pass ignore it
        o.disc.edl = o.square.edl = (asp_edl_desc){.strength = v->desc->edl_strength > 0 ? v->desc->edl_strength : 1.0f};
    o.prim = v->prim;
    // thesis appendix C "one picked domain only": a copy of the level holding that primitive alone
    asp_dps_level one;
    memset(&one, 0, sizeof one);
    if (src.level && v->picked != SIZE_MAX) {
        int rc = asp_dps_level_pick(src.level, v->picked, &v->ctx, &one, err);
        if (rc)
            return rc;
        src.level = &one;
    }
    int rc = v->is_scene ? asp__viewer_instances_renderer(v->gl, &v->instances, K(k)->name, &o, &v->ctx, out, err)
                         : K(k)->create(v->gl, &src, &o, &v->ctx, out, err);
    if (!rc && v->depth_limit && K(k)->has_lod && (rc = asp_renderer_set_lod(*out, v->tolerance, v->depth_limit, err))) {
        asp_renderer_destroy(*out);
        *out = NULL;
    }
    if (one.prim_count)
        asp_dps_level_release(&one, &v->ctx);
    return rc;
}

/* A .dps whose source points were loaded (p) can be drawn by the point renderers too. */
static int kind_accepts(const viewer *v, size_t k)
{
    if (v->is_scene) // the point renderers pick how a scene's point sources are drawn
        return (K(k)->inputs & ASP_RENDER_INPUT_POINTS) != 0;
    return (K(k)->inputs & asp_scene_inputs(&v->scene)) != 0;
}

static size_t first_accepted(const viewer *v)
{
    for (size_t k = 0; k < asp_renderer_kind_count(); k++)
        if (kind_accepts(v, k))
            return k;
    return 0;
}

/* Makes renderer kind k for the scene; replaces the current one only on success. */
static int switch_renderer(viewer *v, size_t k, asp_error *err)
{
    if (!kind_accepts(v, k))
        return asp_error_set(err, ASP_EUNSUPPORTED, "renderer '%s' cannot draw %s input", K(k)->name,
                             asp_file_kind_name(v->scene.type.kind));
    asp_renderer *r = NULL;
    int rc = make_renderer(v, k, &r, err);
    if (rc)
        return rc;
    asp_renderer_destroy(v->r);
    v->r = r;
    v->kind = k;
    v->dirty = 1;
    return 0;
}

/*
 * After the scene's points changed (new colours): the current renderer is
 * made again from them, with a new hierarchy if it needs one. The old renderer
 * and hierarchy stay in use until the new ones exist.
 */
static int rebuild_renderer(viewer *v, asp_error *err)
{
    asp_hier *old_hier = v->hier;
    v->hier = NULL;
    int rc = switch_renderer(v, v->kind, err);
    if (rc) {
        asp_hier_destroy(v->hier);
        v->hier = old_hier;
        return rc;
    }
    asp_hier_destroy(old_hier); // the old renderer that referenced it is gone
    return 0;
}

/* Interactive switch: a renderer that cannot be made is reported and skipped, never fatal. */
static void try_renderer(viewer *v, size_t k)
{
    asp_error e = {0, ""};
    if (switch_renderer(v, k, &e))
        vlog(v, "renderer '%s' unavailable: %s", K(k)->name, e.msg);
}

static void next_renderer(viewer *v)
{
    for (size_t step = 1; step < asp_renderer_kind_count(); step++) {
        size_t k = (v->kind + step) % asp_renderer_kind_count();
        if (!kind_accepts(v, k))
            continue;
        asp_error e = {0, ""};
        if (switch_renderer(v, k, &e) == 0)
            return;
        vlog(v, "renderer '%s' unavailable: %s", K(k)->name, e.msg);
    }
    vlog(v, "no other renderer for this input; still '%s'", K(v->kind)->name);
}

/* ---- actions ---- */

/* "k  what it does" for key k of the table, the renderer keys with their renderer's name; 0 = not listed. */
static int key_line(const asp__viewer_key *k, char *line, size_t cap)
{
    const char *name = k->action == ASP__VIEWER_PICK_RENDERER ? asp_viewer_renderer_name((size_t)k->arg) : NULL;
    if (!k->help || (k->action == ASP__VIEWER_PICK_RENDERER && !name))
        return 0;
    if (name)
        snprintf(line, cap, "%c  renderer %s", k->key, name);
    else
        snprintf(line, cap, "%c  %s", k->key, k->help);
    return 1;
}

static void print_help(const viewer *v)
{
    vlog(v, "mouse: left drag orbit, wheel or right drag zoom, middle drag or shift + left drag pan");
    char line[160];
    for (const asp__viewer_key *k = asp__viewer_keys; k->key; k++)
        if (key_line(k, line, sizeof line))
            vlog(v, "  %s", line);
}

static void print_view(const viewer *v)
{
    const asp_camera *c = &v->cam;
    vlog(v, "view: --view %.1f,%.1f,%.3f (target %.4g,%.4g,%.4g, scene centre %.4g,%.4g,%.4g)", c->azimuth,
         c->elevation, c->distance / v->radius, c->target[0], c->target[1], c->target[2],
         v->center[0], v->center[1], v->center[2]);
}

static void change_tolerance(viewer *v, int dir)
{
    if (v->budget_on) {
        vlog(v, "tau is set by the frame budget of %g ms (--frame-ms): %g px now", v->desc->frame_ms,
             (double)v->tolerance);
        return;
    }
    float old = v->tolerance;
    v->tolerance = asp__viewer_tolerance_step(old, dir);
    if (v->stream) { // a streamed .hier: tau is the projected spacing its cut refines to
        asp__viewer_stream_set_tolerance(v->stream, v->tolerance);
        vlog(v, "tau %g px: the streamed cut refines to %g px of point spacing", v->tolerance,
             v->tolerance > 0 ? v->tolerance : 1.0);
        if (!K(v->kind)->has_lod)
            return;
    }
    if (!K(v->kind)->has_lod) {
        vlog(v, "tau %g px (renderer '%s' draws every point; tau applies to the hierarchy renderers)", v->tolerance,
             K(v->kind)->name);
        return;
    }
    asp_error e = {0, ""};
    if (asp_renderer_set_lod(v->r, v->tolerance, v->depth_limit, &e)) {
        vlog(v, "cannot change tau to %g px: %s", v->tolerance, e.msg);
        v->tolerance = old;
    }
}

static int is_dps(const viewer *v)
{
    return v->scene.dps != NULL;
}

/* Applies v->prim to the prim renderer when it is the one drawing; restores old on failure. */
static void set_prim_options(viewer *v, const asp_prim_render_options *old)
{
    asp_error e = {0, ""};
    if (v->kind == v->kind_prim && asp_prim_renderer_set_options(v->r, &v->prim, &e)) {
        vlog(v, "cannot change the .dps options: %s", e.msg);
        v->prim = *old;
    }
}

/* The alpha reference as the renderer resolves it (asp_prim_render_options.alpha_ref). */
static double alpha_ref_of(const asp_prim_render_options *o)
{
    return o->alpha_ref == 0 ? 0.1 : o->alpha_ref < 0 ? 0.0 : o->alpha_ref;
}

/* m, ',', '.', o and c on a .dps: blending options of journal section 4 / thesis 4.4 */
static void prim_action(viewer *v, enum asp__viewer_action a)
{
    if (!is_dps(v)) {
        vlog(v, "methods, alpha reference and outlines apply to .dps input only");
        return;
    }
    asp_prim_render_options old = v->prim;
    switch (a) {
    case ASP__VIEWER_NEXT_METHOD: {
        unsigned m = (unsigned)v->prim.method + 1;
        if (!asp_prim_render_method_name((asp_prim_render_method)m))
            m = 0;
        v->prim.method = (asp_prim_render_method)m;
        vlog(v, "method %s", asp_prim_render_method_name(v->prim.method));
        break;
    }
    case ASP__VIEWER_ALPHA_DOWN:
    case ASP__VIEWER_ALPHA_UP: {
        // on the 0.05 grid, so repeated steps land on the same values as --alpha-ref
        double x = round(alpha_ref_of(&v->prim) / 0.05) + (a == ASP__VIEWER_ALPHA_UP ? 1 : -1);
        x = x < 0 ? 0 : x > 20 ? 1 : x * 0.05;
        v->prim.alpha_ref = x > 0 ? (float)x : -1.0f; // -1: exactly 0
        vlog(v, "alpha reference %.2f", x);
        break;
    }
    case ASP__VIEWER_OUTLINE:
        v->prim.flags ^= ASP_PRIM_RENDER_OUTLINE;
        vlog(v, "outlines %s", v->prim.flags & ASP_PRIM_RENDER_OUTLINE ? "on" : "off");
        break;
    case ASP__VIEWER_CREASES:
        // the zero value is the default angle; -1 turns clipping off (render.h)
        v->prim.crease_angle = v->prim.crease_angle < 0 ? 0.0f : -1.0f;
        vlog(v, "crease clipping %s", v->prim.crease_angle < 0 ? "off" : "on");
        break;
    case ASP__VIEWER_DEBUG_EIGENVECTORS:
    case ASP__VIEWER_DEBUG_TEXELS: {
        unsigned flag = a == ASP__VIEWER_DEBUG_TEXELS ? ASP_PRIM_RENDER_DEBUG_TEXELS : ASP_PRIM_RENDER_DEBUG_EIGENVECTORS;
        v->prim.flags ^= flag;
        vlog(v, "%s %s", flag == ASP_PRIM_RENDER_DEBUG_TEXELS ? "texel midpoints" : "eigenvectors",
             v->prim.flags & flag ? "on" : "off");
        break;
    }
    case ASP__VIEWER_PICK_DOMAIN: {
        // the next primitive alone, then every one again (thesis appendix C)
        const asp_dps_level *lv = asp_scene_dps_level(&v->scene);
        size_t n = lv ? lv->prim_count : 0, was = v->picked;
        v->picked = v->picked == SIZE_MAX ? 0 : v->picked + 1 < n ? v->picked + 1 : SIZE_MAX;
        asp_error e = {0, ""};
        if (v->kind == v->kind_prim && switch_renderer(v, v->kind, &e)) {
            vlog(v, "cannot draw one domain: %s", e.msg);
            v->picked = was;
            return;
        }
        if (v->picked == SIZE_MAX)
            vlog(v, "every domain");
        else
            vlog(v, "domain %zu of %zu only", v->picked, n);
        return;
    }
    case ASP__VIEWER_COLOR_MODE:
        v->prim.flags ^= ASP_PRIM_RENDER_COLOR_BY_DOMAIN;
        vlog(v, "%s", v->prim.flags & ASP_PRIM_RENDER_COLOR_BY_DOMAIN ? "a colour per domain" : "texture colours");
        break;
    default: return;
    }
    if (v->kind != v->kind_prim)
        vlog(v, "(the primitives are hidden: p shows them with these options)");
    set_prim_options(v, &old);
}

/*
 * p on a .dps: the source points (loaded once, drawn as discs) or the primitives again; on a mesh:
 * points sampled from it (ASP_SCENE_MESH_POINTS, once) or the mesh again, one model in one frame.
 */
static void toggle_points(viewer *v)
{
    if (!is_dps(v) && !v->scene.mesh) {
        vlog(v, "p applies to .dps input only, and to meshes");
        return;
    }
    size_t main_kind = is_dps(v) ? v->kind_prim : find_renderer("mesh");
    const char *main_name = is_dps(v) ? "primitives" : "mesh";
    size_t to = main_kind;
    if (v->kind == main_kind) {
        char note[LOG_CAP] = "";
        asp_error e = {0, ""};
        int had_points = v->scene.cloud != NULL;
        double t0 = asp_time_now();
        int rc = asp__viewer_scene_action(&v->scene, ASP__VIEWER_POINTS, note, sizeof note, &e);
        if (rc <= 0) {
            vlog(v, "%s", rc < 0 ? e.msg : note);
            return;
        }
        if (!had_points && v->scene.mesh)
            vlog(v, "sampled %zu points from the mesh in %.2f s", v->scene.cloud->count, asp_time_now() - t0);
        to = find_renderer("disc");
    }
    asp_error e = {0, ""};
    if (switch_renderer(v, to, &e))
        vlog(v, "renderer '%s' unavailable: %s", K(to)->name, e.msg);
    else
        vlog(v, "showing the %s", to == main_kind ? main_name : is_dps(v) ? "source points" : "points");
}

static void scene_action(viewer *v, enum asp__viewer_action a)
{
    if (a == ASP__VIEWER_COLOR_MODE && is_dps(v)) {
        prim_action(v, a);
        return;
    }
    if (!v->scene.amg && !v->scene.dps) {
        vlog(v, "colour modes and levels apply to .amg and .dps input only");
        return;
    }
    char note[160] = "";
    asp_error e = {0, ""};
    int rc = a == ASP__VIEWER_DOMAIN_SET ? asp__viewer_scene_domain_set(&v->scene, note, sizeof note)
                                         : asp__viewer_scene_action(&v->scene, a, note, sizeof note, &e);
    if (rc < 0) {
        vlog(v, "%s", e.msg);
        return;
    }
    if (rc == 0) {
        if (note[0])
            vlog(v, "%s", note);
        return;
    }
    asp__viewer_scene_status(&v->scene, v->status, sizeof v->status);
    if (is_dps(v)) {
        // a new level: only the prim renderer draws it (the source points stay)
        if (v->kind == v->kind_prim && switch_renderer(v, v->kind_prim, &e))
            vlog(v, "cannot draw the new level: %s", e.msg);
        vlog(v, "%s, %zu primitives", v->status, asp_scene_dps_level(&v->scene)->prim_count);
        return;
    }
    // the points' colours changed: upload them again
    if (rebuild_renderer(v, &e))
        vlog(v, "cannot redraw with the new colours: %s", e.msg);
    vlog(v, "%s", v->status);
}

/* The disc and square renderers draw eye-dome lighting (asp_edl_desc); the others ignore it. */
static int edl_applies(const viewer *v, size_t k)
{
    return !v->is_scene && (strcmp(K(k)->name, "disc") == 0 || strcmp(K(k)->name, "square") == 0);
}

/* E: eye-dome lighting on or off; the renderer is made again with it when it draws it. */
static void toggle_edl(viewer *v)
{
    v->edl_on = !v->edl_on;
    asp_error e = {0, ""};
    if (edl_applies(v, v->kind) && switch_renderer(v, v->kind, &e)) {
        vlog(v, "cannot switch eye-dome lighting: %s", e.msg);
        v->edl_on = !v->edl_on;
        return;
    }
    vlog(v, "eye-dome lighting %s%s", v->edl_on ? "on" : "off",
         edl_applies(v, v->kind) ? "" : " (the disc and square renderers draw it)");
}

static void apply(viewer *v, const action *a)
{
    const double step_px = 10.0 / ASP__VIEWER_ORBIT_DEG_PER_PX; // 10 degrees per key press
    switch (a->what) {
    case ASP__VIEWER_NONE: break;
    case ASP__VIEWER_QUIT: v->quit = 1; break;
    case ASP__VIEWER_RESET: reset_view(v); break;
    case ASP__VIEWER_LIGHT: v->unlit = !v->unlit; break;
    case ASP__VIEWER_NEXT_RENDERER: next_renderer(v); break;
    case ASP__VIEWER_PICK_RENDERER:
        if ((size_t)a->arg < asp_renderer_kind_count())
            try_renderer(v, (size_t)a->arg);
        else
            vlog(v, "no renderer %d (this build has %d)", a->arg + 1, (int)asp_renderer_kind_count());
        break;
    case ASP__VIEWER_TAU_UP: change_tolerance(v, +1); break;
    case ASP__VIEWER_TAU_DOWN: change_tolerance(v, -1); break;
    case ASP__VIEWER_COLOR_MODE:
    case ASP__VIEWER_LEVEL_FINER:
    case ASP__VIEWER_LEVEL_COARSER:
    case ASP__VIEWER_DOMAIN_SET: scene_action(v, a->what); break;
    case ASP__VIEWER_NEXT_METHOD:
    case ASP__VIEWER_ALPHA_DOWN:
    case ASP__VIEWER_ALPHA_UP:
    case ASP__VIEWER_OUTLINE:
    case ASP__VIEWER_CREASES:
    case ASP__VIEWER_DEBUG_EIGENVECTORS:
    case ASP__VIEWER_DEBUG_TEXELS:
    case ASP__VIEWER_PICK_DOMAIN: prim_action(v, a->what); break;
    case ASP__VIEWER_POINTS: toggle_points(v); break;
    case ASP__VIEWER_SCREENSHOT: v->screenshot_wanted = 1; break;
    case ASP__VIEWER_OVERLAY: v->overlay_on = !v->overlay_on; break;
    case ASP__VIEWER_HELP:
        v->help_on = !v->help_on;
        if (v->help_on)
            print_help(v);
        break;
    case ASP__VIEWER_EDL: toggle_edl(v); break;
    case ASP__VIEWER_PRINT_VIEW: print_view(v); break;
    case ASP__VIEWER_ORBIT_LEFT: asp__viewer_orbit(&v->cam, -step_px, 0); break;
    case ASP__VIEWER_ORBIT_RIGHT: asp__viewer_orbit(&v->cam, step_px, 0); break;
    case ASP__VIEWER_ORBIT_UP: asp__viewer_orbit(&v->cam, 0, -step_px); break;
    case ASP__VIEWER_ORBIT_DOWN: asp__viewer_orbit(&v->cam, 0, step_px); break;
    case ASP__VIEWER_ZOOM_IN: asp__viewer_dolly(&v->cam, 0.85, v->radius); break;
    case ASP__VIEWER_ZOOM_OUT: asp__viewer_dolly(&v->cam, 1 / 0.85, v->radius); break;
    }
    v->dirty = 1;
}

/* ---- screenshots ---- */

/* The window's back buffer (what the frame just drew, before the swap) into a PNG. */
static int save_back_buffer(viewer *v, const char *path, asp_error *err)
{
    asp_image img = {0, 0, NULL};
    int rc = asp_gl_context_read_window(v->gl, &img, err);
    if (!rc)
        rc = asp_image_save_png(&img, path, err);
    if (!rc) {
        v->stats.screenshots++;
        vlog(v, "wrote '%s' (%ux%u)", path, img.width, img.height);
    }
    asp_image_release(&img);
    return rc;
}

/* "<dir>/<stem>-NNN.png" for the s key: the input's name without extension, first free number. */
static int next_screenshot_name(viewer *v, char *out, size_t cap)
{
    const char *base = strrchr(v->path, '/');
    base = base ? base + 1 : v->path;
    const char *dot = strrchr(base, '.');
    int stem = (int)(dot && dot != base ? (size_t)(dot - base) : strlen(base));
    if (stem > 200)
        stem = 200;
    while (v->screenshot_seq < 9999) {
        v->screenshot_seq++;
        snprintf(out, cap, "%.*s-%03u.png", stem, base, v->screenshot_seq);
        if (access(out, F_OK) != 0)
            return 0;
    }
    return -1;
}

/* ---- frame budget and the figures over the frame (issue 18 item 5) ---- */

/* The budget starts from --tau when given (else its coarse default); the depth fallback needs a hierarchy. */
static int budget_start(viewer *v, asp_error *err)
{
    const asp_hier *h = v->hier ? v->hier : v->scene.hier;
    asp_frame_budget_desc bd = {.target_ms = v->desc->frame_ms, .tolerance = v->desc->tolerance,
                                .depth_max = h ? asp_hier_depth(h) + 1 : 0};
    int rc = asp_frame_budget_init(&v->budget, &bd, err);
    if (rc)
        return rc;
    v->budget_on = 1;
    v->budget_told = 0;
    vlog(v, "frame budget %g ms: tau starts at %g px", v->desc->frame_ms, (double)v->budget.tolerance);
    return 0;
}

/* Applies the budget's tau and depth limit to the current renderer; says once per renderer when it has none. */
static void budget_before_frame(viewer *v)
{
    if (!v->budget_on)
        return;
    asp_error e = {0, ""};
    int rc = asp_frame_budget_apply(&v->budget, v->r, &e);
    v->budget_ok = rc == 0;
    if (rc == 0) {
        v->tolerance = v->budget.tolerance;
        v->depth_limit = v->budget.depth_limit;
        v->budget_told = 0;
        return;
    }
    if (v->budget_told != v->kind + 1)
        vlog(v, "frame budget: %s; --frame-ms has no effect on this renderer", e.msg);
    v->budget_told = v->kind + 1;
}

/* Feeds the whole frame's time; a changed tau asks for another frame, so an idle window settles too. */
static void budget_after_frame(viewer *v, double frame_ms, size_t count)
{
    if (!v->budget_on || !v->budget_ok)
        return;
    if (asp_frame_budget_update(&v->budget, frame_ms, count))
        v->dirty = 1;
}

/* Appends to text (cap bytes, *n used): what fits, always terminated. */
static void append(char *text, size_t cap, size_t *n, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static void append(char *text, size_t cap, size_t *n, const char *fmt, ...)
{
    if (*n + 1 >= cap)
        return;
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(text + *n, cap - *n, fmt, ap);
    va_end(ap);
    *n = w < 0 ? *n : *n + (size_t)w < cap ? *n + (size_t)w : cap - 1;
}

/*
 * The figures over the frame (the i key): what is shown (file, renderer, method or level, colours),
 * then how fast (frame and draw time, budget, tau, counts). Frame times are of the previous frame,
 * which the overlay of this one cannot know; the first frame has none yet and its drawing includes
 * the driver's one-time work (shader compilation, buffer uploads), so it says so.
 */
static void overlay_text(viewer *v, char *text, size_t cap)
{
    asp_renderer_stats rs;
    asp_renderer_stats_get(v->r, &rs);
    const char *base = strrchr(v->path, '/');
    base = base ? base + 1 : v->path;
    size_t n = 0;
    append(text, cap, &n, "%s", base);
    if (v->kind == v->kind_prim)
        append(text, cap, &n, "\nrenderer prim: %s, alpha-ref %.2f%s%s", asp_prim_render_method_name(v->prim.method),
               alpha_ref_of(&v->prim), v->prim.flags & ASP_PRIM_RENDER_OUTLINE ? ", outline" : "",
               v->prim.flags & ASP_PRIM_RENDER_COLOR_BY_DOMAIN ? ", domain colours" : "");
    else
        append(text, cap, &n, "\nrenderer %s%s%s", K(v->kind)->name, v->unlit ? ", unlit" : "",
               v->edl_on && edl_applies(v, v->kind) ? ", eye-dome lighting" : "");
    if (v->status[0])
        append(text, cap, &n, "\n%s", v->status);
    if (v->desc->color_field)
        append(text, cap, &n, "\ncolour by %s", v->desc->color_field);
    if (v->frames <= 1)
        append(text, cap, &n, "\nframe -- ms  first draw %.1f ms (with GL warm-up)", v->last_ms);
    else
        append(text, cap, &n, "\nframe %.1f ms  draw %.1f ms", v->frame_last_ms, v->last_ms);
    if (v->budget_on)
        append(text, cap, &n, "\nbudget %g ms%s", v->desc->frame_ms,
               !v->budget_ok         ? " (no level of detail here)"
               : v->budget.saturated ? " (coarsest: cannot hold it)"
               : v->budget.bound     ? " (coarser is not faster here)"
               : v->budget.finest    ? " (full detail fits)"
                                     : "");
    if (K(v->kind)->has_lod || v->budget_ok) {
        char depth[32] = "none";
        if (v->depth_limit)
            snprintf(depth, sizeof depth, "%u", v->depth_limit);
        append(text, cap, &n, "\ntau %.2f px  depth limit %s", (double)v->tolerance, depth);
    }
    append(text, cap, &n, "\n%zu / %zu %s", rs.count, rs.points ? rs.points : rs.count, K(v->kind)->noun);
}

/* The key list for the h key, the lines print_help logs. */
static void help_text(char *text, size_t cap)
{
    size_t n = 0;
    text[0] = '\0';
    append(text, cap, &n, "keys (h hides them)\nmouse: left drag orbit, wheel or right drag zoom,\n"
                          "       middle drag or shift + left drag pan");
    char line[160];
    for (const asp__viewer_key *k = asp__viewer_keys; k->key; k++)
        if (key_line(k, line, sizeof line))
            append(text, cap, &n, "\n%s", line);
}

/* Twice the font where text fits the room left, else 1.5 times or the font's own size (small windows). */
static float fit_scale(const char *text, float room_w, float room_h)
{
    float w, h, scale = 2.0f;
    asp_text_overlay_measure(text, 2.0f, &w, &h);
    while (scale > 1.0f && (w * scale / 2 > room_w || h * scale / 2 > room_h))
        scale -= 0.5f;
    return scale;
}

static int draw_overlay(viewer *v, uint32_t width, uint32_t height, asp_error *err)
{
    if (!v->overlay) {
        int rc = asp_text_overlay_create(v->gl, &v->overlay, err);
        if (rc)
            return rc;
    }
    float top = 8;
    if (v->overlay_on) {
        overlay_text(v, v->stats.overlay, sizeof v->stats.overlay);
        float scale = fit_scale(v->stats.overlay, (float)width - 16, (float)height - 16);
        asp_text_overlay_desc od = {.x = 8, .y = top, .scale = scale};
        int rc = asp_text_overlay_draw(v->overlay, v->stats.overlay, &od, err);
        if (rc)
            return rc;
        float w, h;
        asp_text_overlay_measure(v->stats.overlay, scale, &w, &h);
        top += h + 8;
    }
    if (!v->help_on)
        return 0;
    char help[4096];
    help_text(help, sizeof help);
    float room_w = (float)width - 16, room_h = (float)height - top - 8;
    float one = fit_scale(help, room_w, room_h);
    // too tall for the window at the font's size or more: the lines' second half in a second column
    size_t lines = 1;
    for (const char *c = help; *c; c++)
        lines += *c == '\n';
    char *mid = help; // the first character of line (lines + 1) / 2
    for (size_t seen = 0; *mid && seen < (lines + 1) / 2; mid++)
        seen += *mid == '\n';
    float full_w, full_h;
    asp_text_overlay_measure(help, one, &full_w, &full_h);
    if (*mid) {
        mid[-1] = '\0';
        float w1, h1, w2, h2, two = 2.0f;
        asp_text_overlay_measure(help, 2.0f, &w1, &h1);
        asp_text_overlay_measure(mid, 2.0f, &w2, &h2);
        while (two > 1.0f && ((w1 + w2 + 8) * two / 2 > room_w || (h1 > h2 ? h1 : h2) * two / 2 > room_h))
            two -= 0.5f;
        // two columns when they allow a larger font, or when one column runs off the bottom anyway,
        // as long as they fit side by side; a window too small for both gets the lines that fit below
        int side_by_side = (w1 + w2 + 8) * two / 2 <= room_w;
        if (side_by_side && (two > one || full_h > room_h)) {
            asp_text_overlay_desc a = {.x = 8, .y = top, .scale = two}, b = a;
            b.x = 8 + w1 * two / 2 + 8;
            int rc = asp_text_overlay_draw(v->overlay, help, &a, err);
            return rc ? rc : asp_text_overlay_draw(v->overlay, mid, &b, err);
        }
        mid[-1] = '\n';
    }
    if (full_h > room_h) { // cut at the last line that fits, and say where the rest is (print_help logged it)
        float lw, h1, h2; // the line pitch, without the panel's margins
        asp_text_overlay_measure("X", one, &lw, &h1);
        asp_text_overlay_measure("X\nX", one, &lw, &h2);
        float pitch = h2 - h1, margin = h1 - pitch;
        size_t fit = pitch > 0 && room_h - margin > pitch ? (size_t)((room_h - margin) / pitch) : 1, seen = 0;
        char *cut = help;
        while (*cut && seen + 1 < fit)
            seen += *cut++ == '\n';
        if (*cut && seen + 1 == fit && cut > help) {
            size_t left = lines - seen;
            snprintf(cut, sizeof help - (size_t)(cut - help), "... %zu more lines: the terminal lists them all", left);
        }
    }
    asp_text_overlay_desc hd = {.x = 8, .y = top, .scale = one};
    return asp_text_overlay_draw(v->overlay, help, &hd, err);
}

/* ---- the loop ---- */

static void update_title(viewer *v, double now, int force)
{
    if (!force && now - v->title_time < 0.25) { // setting a title is a round trip to the window system
        v->title_stale = 1;
        return;
    }
    v->title_time = now;
    v->title_stale = 0;
    const char *base = strrchr(v->path, '/');
    base = base ? base + 1 : v->path;
    char tau[96] = "";
    if (K(v->kind)->has_lod)
        snprintf(tau, sizeof tau, " | tau %g px", v->tolerance);
    else if (v->kind == v->kind_prim)
        snprintf(tau, sizeof tau, " | %s, alpha-ref %.2f%s%s%s", asp_prim_render_method_name(v->prim.method),
                 alpha_ref_of(&v->prim), v->prim.crease_angle < 0 ? ", no creases" : "",
                 v->prim.flags & ASP_PRIM_RENDER_OUTLINE ? ", outline" : "",
                 v->prim.flags & ASP_PRIM_RENDER_COLOR_BY_DOMAIN ? ", domain colours" : "");
    char budget[96] = "";
    if (v->budget_on)
        snprintf(budget, sizeof budget, " | budget %g ms%s%s", v->desc->frame_ms,
                 !v->budget_ok ? " (no level of detail)" : "",
                 v->budget_ok && v->depth_limit ? ", depth limit" : "");
    if (v->budget_on && v->budget_ok && v->depth_limit)
        snprintf(budget + strlen(budget), sizeof budget - strlen(budget), " %u", v->depth_limit);
    char *title = v->stats.title;
    // a long path or status shortens the title; the test on the result tells gcc that is meant
    if (snprintf(title, sizeof v->stats.title, "amgsplat view: %s | %s | %zu %s | %.1f ms (%.0f fps)%s%s | %s%s%s", base,
             K(v->kind)->name, v->r ? asp_renderer_count(v->r) : 0,
             K(v->kind)->noun, v->last_ms,
             v->last_ms > 0 ? 1000.0 / v->last_ms : 0.0, tau, budget, v->unlit ? "unlit" : "lit",
             v->status[0] ? " | " : "", v->status) >= (int)sizeof v->stats.title)
        title[sizeof v->stats.title - 1] = 0;
    glfwSetWindowTitle(v->window, title);
}

static void account_frame(viewer *v, double ms, double now)
{
    v->frames++;
    v->total_ms += ms;
    v->last_ms = ms;
    v->window_frames++;
    v->window_ms += ms;
    if ((v->desc->flags & ASP_VIEWER_VERBOSE) && now - v->window_start >= 1.0) {
        asp_renderer_stats rs;
        asp_renderer_stats_get(v->r, &rs);
        char lod[96] = "";
        if (K(v->kind)->has_lod)
            snprintf(lod, sizeof lod, ", tau %g px, cut %.2f ms", v->tolerance, 1000.0 * rs.select_seconds);
        vlog(v, "%zu frames in %.1f s: %.2f ms per frame drawn, %zu %s (%s%s)", v->window_frames,
             now - v->window_start, v->window_ms / (double)v->window_frames, rs.count,
             K(v->kind)->noun, K(v->kind)->name, lod);
        v->window_start = now;
        v->window_frames = 0;
        v->window_ms = 0;
    }
}

static int draw(viewer *v, int last, asp_error *err)
{
    uint32_t w = 0, h = 0;
    asp_gl_context_framebuffer_size(v->gl, &w, &h);
    if (w == 0 || h == 0) // minimised
        return 0;
    v->cam.aspect = (float)w / (float)h;
    asp_camera_clip_to_sphere(&v->cam, v->center, v->radius);
    const uint8_t *bg = v->desc->background;
    asp_render_desc rd = {.flags = ASP_RENDER_WAIT | (v->unlit ? ASP_RENDER_UNLIT : 0u)};
    if (bg[3])
        memcpy(rd.background, bg, 4);
    else
        memset(rd.background, 255, 4);
    budget_before_frame(v);
    asp__viewer_frame rec = {.tolerance = K(v->kind)->has_lod || v->budget_ok ? v->tolerance : NAN,
                             .depth_limit = v->depth_limit, .azimuth = v->cam.azimuth,
                             .elevation = v->cam.elevation, .distance = v->cam.distance};
    double t0 = asp_time_now();
    int rc = asp_render_frame(v->gl, v->r, &v->cam, &rd, err);
    if (rc)
        return rc;
    double now = asp_time_now();
    rec.draw_ms = 1000.0 * (now - t0);
    rec.count = asp_renderer_count(v->r);
    account_frame(v, rec.draw_ms, now);
    if (v->overlay_on || v->help_on) {
        asp_error e = {0, ""};
        if (draw_overlay(v, w, h, &e)) {
            vlog(v, "cannot draw text over the frame: %s", e.msg);
            v->overlay_on = v->help_on = 0;
        }
    }
    if (v->screenshot_wanted) {
        v->screenshot_wanted = 0;
        char name[256];
        asp_error e = {0, ""};
        if (next_screenshot_name(v, name, sizeof name))
            vlog(v, "no free screenshot name in the current directory");
        else if (save_back_buffer(v, name, &e))
            vlog(v, "%s", e.msg);
    }
    if (last && v->desc->screenshot) {
        rc = save_back_buffer(v, v->desc->screenshot, err);
        if (rc)
            return rc;
    }
    v->stats.width = w;
    v->stats.height = h;
    asp_gl_context_swap_buffers(v->gl);
    update_title(v, now, v->frames == 1);
    rec.frame_ms = 1000.0 * (asp_time_now() - v->frame_top);
    v->frame_last_ms = rec.frame_ms;
    rc = asp__viewer_frame_log_add(&v->flog, &v->ctx, &rec, err);
    if (rc)
        return rc;
    budget_after_frame(v, rec.frame_ms, rec.count);
    return 0;
}

/* The title's note on a streamed .hier: how much of it is shown. */
static void stream_status(viewer *v)
{
    size_t loads, nodes, node_count;
    uint64_t total;
    asp__viewer_stream_counts(v->stream, &loads, &nodes, &node_count, &total);
    snprintf(v->status, sizeof v->status, "streamed: %zu of %llu points, %zu of %zu nodes",
             v->scene.cloud ? v->scene.cloud->count : 0, (unsigned long long)total, nodes, node_count);
}

/* A streamed .hier: once the camera rests, its cut's points replace those shown (stream.c). */
static int stream_step(viewer *v, asp_error *err)
{
    uint32_t w = 0, h = 0;
    asp_gl_context_framebuffer_size(v->gl, &w, &h);
    if (w == 0 || h == 0)
        return 0;
    asp_cloud *fresh = NULL;
    int rc = asp__viewer_stream_update(v->stream, &v->cam, w, h, asp_time_now(), &fresh, err);
    if (rc || !fresh)
        return rc;
    asp_cloud *old = v->scene.cloud;
    v->scene.cloud = fresh;
    if ((rc = rebuild_renderer(v, err)) != 0) { // keep drawing the old points
        v->scene.cloud = old;
        asp_cloud_destroy(fresh);
        return rc;
    }
    asp_cloud_destroy(old);
    stream_status(v);
    v->title_stale = 1;
    vlog(v, "streamed: %s", v->status + 10);
    return 0;
}

static int loop(viewer *v, asp_error *err)
{
    const asp_viewer_desc *d = v->desc;
    const char *keys = d->keys ? d->keys : "";
    size_t nkeys = strlen(keys);
    for (size_t i = 0;; i++) {
        int scripted = d->frames > 0;
        if (scripted && i >= d->frames)
            return 0;
        v->frame_top = asp_time_now();
        if (scripted || v->dirty || v->queued || i < nkeys) {
            glfwPollEvents();
        } else {
            if (v->title_stale)
                update_title(v, asp_time_now(), 1);
            // idle: sleep until input instead of redrawing (briefly while a streamed cut is pending)
            glfwWaitEventsTimeout(v->stream && asp__viewer_stream_busy(v->stream) ? 0.05 : 0.5);
            v->frame_top = asp_time_now(); // the frame begins when the input arrived, not while idle
        }
        if (scripted && d->fly) {
            asp__viewer_fly(&v->fly_start, (double)i / (double)d->frames, &v->cam);
            v->dirty = 1;
        }
        if (i < nkeys) {
            const asp__viewer_key *k = asp__viewer_key_find((unsigned char)keys[i]);
            push(v, k->action, k->arg);
        }
        for (size_t q = 0; q < v->queued && !v->quit; q++)
            apply(v, &v->queue[q]);
        v->queued = 0;
        if (v->quit || glfwWindowShouldClose(v->window))
            return 0;
        if (v->stream) {
            asp_error e = {0, ""};
            if (stream_step(v, &e))
                vlog(v, "cannot load the view's points: %s", e.msg); // the shown points stay
        }
        if (!scripted && !v->dirty && !v->screenshot_wanted)
            continue;
        v->dirty = 0;
        int rc = draw(v, scripted && i + 1 == d->frames, err);
        if (rc)
            return rc;
    }
}

static int open_window(viewer *v, asp_error *err)
{
    const asp_viewer_desc *d = v->desc;
    const char *base = strrchr(v->path, '/');
    char title[256];
    snprintf(title, sizeof title, "amgsplat view: %s", base ? base + 1 : v->path);
    int rc = asp_gl_context_create_window(&(asp_gl_context_desc){.width = d->width, .height = d->height, .title = title},
                                          &v->ctx, &v->gl, err);
    if (rc)
        return rc;
    v->window = asp_gl_context_window(v->gl);
    glfwSetWindowUserPointer(v->window, v);
    glfwSetCharCallback(v->window, on_char);
    glfwSetKeyCallback(v->window, on_key);
    glfwSetMouseButtonCallback(v->window, on_button);
    glfwSetCursorPosCallback(v->window, on_cursor);
    glfwSetScrollCallback(v->window, on_scroll);
    glfwSetWindowRefreshCallback(v->window, on_redraw);
    glfwSetFramebufferSizeCallback(v->window, on_resize);
    // scripted runs go as fast as they can; interactive ones wait for the display's refresh
    glfwSwapInterval(d->frames > 0 ? 0 : 1);
    snprintf(v->stats.gl_renderer, sizeof v->stats.gl_renderer, "%s", asp_gl_context_renderer(v->gl));
    return 0;
}

int asp_viewer_run(const char *path, const asp_viewer_desc *desc, const asp_context *ctx, asp_viewer_stats *stats,
                   asp_error *err)
{
    static const asp_viewer_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    int rc = asp_viewer_desc_check(desc, err);
    if (rc)
        return rc;
    viewer v;
    memset(&v, 0, sizeof v);
    v.desc = desc;
    v.path = path;
    v.tolerance = desc->tolerance;
    v.picked = SIZE_MAX; // every domain
    v.depth_limit = desc->depth_limit;
    v.unlit = (desc->flags & ASP_VIEWER_UNLIT) != 0;
    v.overlay_on = (desc->flags & ASP_VIEWER_OVERLAY) ||
                   (desc->frame_ms > 0 && !(desc->flags & ASP_VIEWER_NO_OVERLAY));
    v.prim.method = (asp_prim_render_method)desc->prim_method;
    v.prim.alpha_ref = desc->prim_alpha_ref;
    if (ctx)
        v.ctx = *ctx;
    if (asp_ooc_probe(path) == 1) { // a streamed .hier: the first view's cut (stream.c)
        rc = asp__viewer_stream_open(path, desc->memory, desc->tolerance, desc->frames > 0, ctx, &v.stream, err);
        if (rc)
            return rc;
        asp_file_type_of_name(path, &v.scene.type, NULL);
        snprintf(v.scene.path, sizeof v.scene.path, "%s", path);
        v.scene.ctx = v.ctx;
        asp__viewer_stream_frame(v.stream, &v.scene);
        uint32_t w = desc->width ? desc->width : 1280, h = desc->height ? desc->height : 800;
        v.cam.aspect = (float)w / (float)h;
        reset_view(&v);
        if ((rc = asp__viewer_stream_first(v.stream, &v.cam, w, h, &v.scene, err)) != 0) {
            asp__viewer_stream_close(v.stream);
            return rc;
        }
    } else {
        rc = asp__viewer_instances_load(&v.instances, &v.scene, path, desc, ctx, err);
        v.is_scene = rc == 1;
        if (rc == 0)
            rc = asp__viewer_scene_load(&v.scene, path, desc, ctx, err);
        if (rc < 0)
            return rc;
    }
    if (v.stream)
        stream_status(&v);
    else if (v.is_scene)
        asp__viewer_instances_status(&v.instances, v.status, sizeof v.status);
    else
        asp__viewer_scene_status(&v.scene, v.status, sizeof v.status);
    for (int k = 0; k < 3; k++)
        v.center[k] = (float)(v.scene.frame.center[k] - v.scene.origin[k]);
    v.radius = (float)v.scene.frame.radius;
    v.kind_prim = find_renderer("prim");
    // a .hier holds splats without their points: the splat renderer draws it; a mesh is drawn as one
    v.kind = desc->renderer ? find_renderer(desc->renderer)
             : v.scene.hier ? find_renderer("splat")
             : v.scene.mesh ? find_renderer("mesh")
                            : first_accepted(&v);
    // a frame budget steers tau, so without --renderer it picks the first renderer with a level of detail
    if (!desc->renderer && desc->frame_ms > 0 && !K(v.kind)->has_lod) {
        size_t k = 0;
        while (k < asp_renderer_kind_count() && !(K(k)->has_lod && kind_accepts(&v, k)))
            k++;
        if (k < asp_renderer_kind_count()) {
            vlog(&v, "frame budget %g ms: drawing with the %s renderer, whose tau it steers (the %s renderer has "
                     "no level of detail)", desc->frame_ms, K(k)->name, K(v.kind)->name);
            v.kind = k;
        }
    }
    // points without normals cannot be lit: eye-dome lighting shades them (Boucheny 2009), as in CloudCompare
    int no_normals = !v.is_scene && v.scene.cloud && !v.scene.cloud->normals && !v.scene.dps;
    v.edl_on = desc->edl > 0 || (desc->edl == 0 && no_normals && !v.unlit);
    // a streamed .hier keeps positions and colours only: estimate cannot give it normals, so no hint
    if (no_normals && !v.stream && (K(v.kind)->inputs & ASP_RENDER_INPUT_POINTS))
        vlog(&v, "hint: '%s' has no normals%s; 'amgsplat estimate %s -o WITH_NORMALS.ply' estimates them for lit "
                 "discs", path, v.edl_on && edl_applies(&v, v.kind) ? ": drawn with eye-dome lighting (E toggles it)" : "",
             path);
    // the scene loader records missing textures; the viewer says so through its log (issue 14)
    for (size_t i = 0; v.scene.mesh && i < v.scene.mesh->material_count; i++)
        if (v.scene.mesh->materials[i].texture_missing)
            vlog(&v, "warning: texture '%s' of material '%s' not found: drawn in its material colour",
                 v.scene.mesh->materials[i].texture_path, v.scene.mesh->materials[i].name);
    rc = open_window(&v, err);
    if (!rc) {
        uint32_t w = 0, h = 0;
        asp_gl_context_framebuffer_size(v.gl, &w, &h);
        v.cam.aspect = w && h ? (float)w / (float)h : 1.0f;
        reset_view(&v);
        v.fly_start = v.cam;
        v.window_start = v.title_time = asp_time_now();
        rc = switch_renderer(&v, v.kind, err);
    }
    if (!rc && desc->frame_ms > 0)
        rc = budget_start(&v, err);
    if (!rc)
        rc = loop(&v, err);
    if (!rc && v.title_stale)
        update_title(&v, asp_time_now(), 1);
    if (!rc) {
        v.stats.budget_applied = v.budget_on && v.budget_ok;
        v.stats.edl = v.edl_on && edl_applies(&v, v.kind);
        snprintf(v.stats.renderer, sizeof v.stats.renderer, "%s", K(v.kind)->name);
        v.stats.mean_frame_ms = v.frames ? v.total_ms / (double)v.frames : 0;
        asp__viewer_frame_log_summary(&v.flog, &v.ctx, &v.stats);
        if (desc->stats_json)
            rc = asp__viewer_frame_log_save(&v.flog, &v.stats, desc, path, desc->stats_json, err);
    }
    if (!rc && stats) {
        v.stats.frames = v.frames;
        v.stats.mean_frame_ms = v.frames ? v.total_ms / (double)v.frames : 0;
        v.stats.last_frame_ms = v.last_ms;
        v.stats.count = asp_renderer_count(v.r);
        snprintf(v.stats.renderer, sizeof v.stats.renderer, "%s", K(v.kind)->name);
        if (v.stream) {
            size_t nodes, node_count;
            asp__viewer_stream_counts(v.stream, &v.stats.stream_loads, &nodes, &node_count, &v.stats.stream_point_count);
            v.stats.stream_points = v.scene.cloud ? v.scene.cloud->count : 0;
        }
        *stats = v.stats;
    }
    asp_text_overlay_destroy(v.overlay);
    asp__viewer_frame_log_release(&v.flog, &v.ctx);
    asp_renderer_destroy(v.r);
    asp_hier_destroy(v.hier);
    asp_gl_context_destroy(v.gl);
    asp__viewer_stream_close(v.stream);
    asp_scene_release(&v.scene);
    asp_instance_scene_release(&v.instances);
    return rc;
}
