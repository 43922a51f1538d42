/*
 * amgsplat view: the interactive viewer in a window (GLFW), and its scripted
 * mode for tests and screenshots. Glue only: options go into an
 * asp_viewer_desc and asp_viewer_run does the rest; see docs/cli/view.md.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/hier_ooc.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat view FILE [--size WxH] [--view AZ,EL[,DIST]] [--renderer NAME] [--tolerance PX]\n"
    "                     [--color-by MODE] [--level L] [--method NAME] [--alpha-ref X] [--unlit]\n"
    "                     [--background R,G,B] [--texture IMG] [--hybrid] [--verbose]\n"
    "                     [--preset thesis|journal|pajarola|schwarz]\n"
    "                     [--frame-ms T] [--overlay | --no-overlay] [--edl | --no-edl] [--edl-strength S]\n"
    "                     [--memory SIZE]\n"
    "       amgsplat view FILE --frames N [--screenshot OUT.png] [--keys KEYS] [options above]\n"
    "       amgsplat view FILE --fly N [--frame-ms T] [--stats-json OUT.json] [options above]\n"
    "\n"
    "Opens a window on a point file (.ply, .xyz, .pts, .txt), an AMG decomposition (.amg,\n"
    "coloured by classifier or domains), domain primitives (.dps, one level at a time, blended\n"
    "by --method as in amgsplat render), a mesh (OBJ+MTL, PLY with faces, OFF, STL, glTF, 3DS;\n"
    "--texture as in amgsplat sample) or a scene of instances (docs/scene-format.md; the point\n"
    "renderer keys pick how its point sources are drawn). Left drag orbits, the wheel or right drag zooms, middle\n"
    "drag or shift + left drag pans; press h in the window for the keys (docs/cli/view.md).\n"
    "With --frames N the viewer draws N frames, pressing KEYS one per frame, saves the last\n"
    "frame to OUT.png and exits (needs a display: run under xvfb-run without one). --frame-ms T\n"
    "sets the screen tolerance every frame so a frame takes T ms (splat, square; without\n"
    "--renderer it draws with splat); --fly N draws N frames on a fixed path around the model.\n"
    "--color-by colours a point file by a field of its own (elevation, classification,\n"
    "intensity, return_number, any property) as render does; points without normals are\n"
    "shaded by eye-dome lighting unless --no-edl or --unlit. A streamed .hier (amgsplat convert)\n"
    "shows the cut of the view within --memory, and loads the new view's cut once the camera rests.";

/* The renderer options view takes (renderer_options.c). */
#define VIEW_OPTIONS                                                                                     \
    (CLI_RO_RENDERER | CLI_RO_TOLERANCE | CLI_RO_LEVEL | CLI_RO_COLOR_BY | CLI_RO_METHOD | CLI_RO_ALPHA_REF | \
     CLI_RO_HYBRID | CLI_RO_CULL | CLI_RO_DEPTH_LIMIT | CLI_RO_FRAME_MS | CLI_RO_UNLIT | CLI_RO_TEXTURE | CLI_RO_EDL)

struct view_opts {
    /* shared with render and eval: hybrid (docs/hybrid.md), cull_backfaces and depth_limit (seed 004
       3.2.2, 3.2.5), frame_ms (issue 18 item 5) */
    struct cli_renderer_opts r;
    const char *size;
    const char *view;
    const char *up;
    const char *background;
    const char *screenshot;
    const char *keys;
    const char *preset; /* --preset: applied by cli_parse (docs/seeds.md) */
    size_t frames;
    size_t fly;             /* --fly N: scripted fly-through of N frames */
    const char *stats_json;
    int overlay, no_overlay;
    int verbose;
    const char *memory; /* streamed .hier: --memory SIZE, as render */
};

static void log_line(void *user, const char *line)
{
    const struct cli_env *env = user;
    if (!env->quiet)
        fprintf(stderr, "%s\n", line);
}

static int parse_into(struct cli_env *env, const char *path, struct view_opts *o, asp_viewer_desc *d)
{
    if (o->size && (cli_parse_size2(o->size, &d->width, &d->height) != 0 || d->width == 0 || d->height == 0 ||
                    d->width > 16384 || d->height > 16384))
        return cli_usage_error(env, "--size expects WxH with sides in 1..16384, got '%s'", o->size);
    if (o->view) {
        double az, el, dist;
        if (cli_parse_view(env, o->view, &az, &el, &dist))
            return 2;
        d->set_view = 1;
        d->azimuth = (float)az;
        d->elevation = (float)el;
        d->distance = (float)dist;
    }
    if (o->up && cli_parse_up(o->up, &d->up) != 0)
        return cli_usage_error(env, "--up expects x, y, z, -x, -y or -z, got '%s'", o->up);
    d->set_up = o->up != NULL; // else the file's own: z for LAS and what was made from it (asp_frame.up)
    if (cli_renderer_check(env, &o->r, VIEW_OPTIONS))
        return 2;
    d->tolerance = isnan(o->r.tolerance) ? 0.0f : (float)o->r.tolerance;
    if (o->r.has_color) // the viewer's modes in the order its c key cycles them (asp_viewer_desc.amg_color)
        d->amg_color = o->r.color_mode == ASP_SCENE_AMG_INPUT ? 3u : (unsigned)o->r.color_mode - 1u;
    if (o->background && cli_parse_colour(env, "--background", o->background, 0, d->background))
        return 2;
    asp_file_type type = {ASP_FILE_UNKNOWN, "", 0};
    if (asp_file_recognise(path, &type, NULL) != 0)
        asp_file_type_of_name(path, &type, NULL);
    // a point file's own fields, coloured as render --color-by colours them (asp_cloud_color_by)
    if (o->r.color_field && type.kind != ASP_FILE_POINTS && type.kind != ASP_FILE_UNKNOWN)
        return cli_usage_error(env, "%s expects classifier, domains, strict or input, got '%s' (a field such as "
                                    "elevation or classification colours a point file's points, not %s input)",
                               o->r.color_by_name, o->r.color_field, asp_file_kind_name(type.kind));
    d->color_field = o->r.color_field;
    d->edl = o->r.no_edl ? -1 : o->r.edl || !isnan(o->r.edl_strength) ? 1 : 0;
    d->edl_strength = isnan(o->r.edl_strength) ? 0.0f : (float)o->r.edl_strength;
    int dps = type.kind == ASP_FILE_DPS || type.kind == ASP_FILE_SCENE; // a scene's .dps sources take them
    if (o->r.hybrid && type.kind == ASP_FILE_SCENE)
        return cli_usage_error(env, "--hybrid draws one .dps with its points, not a scene");
    if (o->r.hybrid && (!dps || o->r.renderer))
        return cli_usage_error(env, "--hybrid needs a .dps input and no --renderer (it is the renderer)");
    if ((o->r.method || !isnan(o->r.alpha_ref)) && !dps)
        return cli_usage_error(env, "--method and --alpha-ref need a .dps input (amgsplat build makes one)");
    if (o->r.method)
        d->prim_method = (unsigned)o->r.method_kind;
    if (!isnan(o->r.alpha_ref))
        d->prim_alpha_ref = o->r.alpha_ref_lib;
    d->lod_flags = o->r.cull_backfaces ? ASP_SPLAT_CULL_BACKFACES : 0u;
    d->depth_limit = (uint32_t)o->r.depth_limit;
    d->renderer = o->r.hybrid ? "hybrid" : o->r.renderer;
    d->amg_level = o->r.level;
    d->texture = o->r.texture;
    d->frames = o->frames;
    d->screenshot = o->screenshot;
    d->keys = o->keys;
    d->flags = (o->r.unlit ? ASP_VIEWER_UNLIT : 0u) | (o->verbose ? ASP_VIEWER_VERBOSE : 0u) |
               (o->overlay ? ASP_VIEWER_OVERLAY : 0u) | (o->no_overlay ? ASP_VIEWER_NO_OVERLAY : 0u);
    if (o->overlay && o->no_overlay)
        return cli_usage_error(env, "--overlay and --no-overlay exclude each other");
    if (o->fly) {
        if (o->frames && o->frames != o->fly)
            return cli_usage_error(env, "--fly %zu draws %zu frames; --frames %zu disagrees", o->fly, o->fly, o->frames);
        d->frames = o->fly;
        d->fly = 1;
    }
    d->frame_ms = o->r.frame_ms;
    if (o->memory) {
        if (type.kind != ASP_FILE_HIER || asp_ooc_probe(path) != 1)
            return cli_usage_error(env, "--memory applies to a streamed .hier (amgsplat convert IN -o OUT.hier), not '%s'",
                                   path);
        if (cli_memory_option(env, o->memory, &d->memory))
            return 2;
    }
    if (o->stats_json && cli_check_output(env, o->stats_json, NULL, 0, (const char *const[]){path}, 1))
        return 2;
    d->stats_json = o->stats_json;
    // what the library would refuse is a usage error too (renderer names, keys, screenshot)
    asp_error err = {0, ""};
    if (asp_viewer_desc_check(d, &err))
        return cli_usage_error(env, "%s", err.msg);
    return 0;
}

static int print_json(const struct cli_env *env, const char *path, const asp_viewer_desc *d,
                      const asp_viewer_stats *s)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "input", path);
    cJSON_AddNumberToObject(o, "frames", (double)s->frames);
    cJSON_AddItemToObject(o, "mean_frame_ms", cli_json_number("%.3f", s->mean_frame_ms));
    cJSON_AddItemToObject(o, "last_frame_ms", cli_json_number("%.3f", s->last_frame_ms));
    cJSON_AddNumberToObject(o, "count", (double)s->count);
    cJSON_AddStringToObject(o, "renderer", s->renderer);
    cJSON_AddNumberToObject(o, "width", s->width);
    cJSON_AddNumberToObject(o, "height", s->height);
    cJSON_AddNumberToObject(o, "screenshots", (double)s->screenshots);
    if (d->screenshot)
        cJSON_AddStringToObject(o, "screenshot", d->screenshot);
    else
        cJSON_AddNullToObject(o, "screenshot");
    cJSON_AddStringToObject(o, "gl_renderer", s->gl_renderer);
    cJSON_AddStringToObject(o, "title", s->title);
    cJSON_AddItemToObject(o, "median_frame_ms", cli_json_number("%.3f", s->median_frame_ms));
    cJSON_AddItemToObject(o, "p10_frame_ms", cli_json_number("%.3f", s->p10_frame_ms));
    cJSON_AddItemToObject(o, "p90_frame_ms", cli_json_number("%.3f", s->p90_frame_ms));
    if (d->frame_ms > 0)
        cJSON_AddNumberToObject(o, "budget_ms", d->frame_ms);
    else
        cJSON_AddNullToObject(o, "budget_ms");
    cJSON_AddBoolToObject(o, "budget_applied", s->budget_applied);
    cJSON_AddItemToObject(o, "tolerance_min", cli_json_number("%g", s->tolerance_min));
    cJSON_AddItemToObject(o, "tolerance_max", cli_json_number("%g", s->tolerance_max));
    cJSON_AddNumberToObject(o, "count_min", (double)s->count_min);
    cJSON_AddNumberToObject(o, "count_max", (double)s->count_max);
    cJSON_AddBoolToObject(o, "edl", s->edl);
    cJSON_AddStringToObject(o, "overlay", s->overlay);
    if (s->stream_loads) {
        cJSON_AddNumberToObject(o, "stream_loads", (double)s->stream_loads);
        cJSON_AddNumberToObject(o, "stream_points", (double)s->stream_points);
        cJSON_AddNumberToObject(o, "stream_point_count", (double)s->stream_point_count);
    }
    return cli_json_print(env, o);
}

#ifndef ASP_HAVE_GL
int cmd_view(int argc, char **argv, struct cli_env *env)
{
    (void)argc;
    (void)argv;
    asp_error err = {ASP_EUNSUPPORTED, "this amgsplat was built without OpenGL (ASP_WITH_GL=OFF)"};
    return cli_fail(env, &err);
}
#else
int cmd_view(int argc, char **argv, struct cli_env *env)
{
    struct view_opts o = {0};
    cli_renderer_opts_init(&o.r);
    struct cli_option opts[48] = {
        {"size", 0, CLI_STRING, &o.size, "WxH", "window size (default 1280x800)"},
        {"preset", 0, CLI_STRING, &o.preset, "SEED", "the seed's options: thesis, journal, pajarola, schwarz (docs/seeds.md)"},
        {"view", 0, CLI_STRING, &o.view, "AZ,EL[,DIST]", "first view as in 'amgsplat render' (default 30,20)"},
        {"up", 0, CLI_STRING, &o.up, "AXIS", "world axis shown upright: y, z (scans, CAD), x, -y, -z or -x (default: the file's, z for LAS and what was made from it, else y)"},
        {"background", 0, CLI_STRING, &o.background, "R,G,B", "background colour, 0..255 or #RRGGBB (default 255,255,255)"},
        {"verbose", 'v', CLI_FLAG, &o.verbose, NULL, "print frame time and primitive count once a second"},
        {"frames", 0, CLI_SIZE, &o.frames, "N", "scripted: draw N frames, then exit"},
        {"screenshot", 0, CLI_STRING, &o.screenshot, "OUT.png", "scripted: save the last frame"},
        {"keys", 0, CLI_STRING, &o.keys, "KEYS", "press these keys, one per frame, from the first frame on"},
        {"fly", 0, CLI_SIZE, &o.fly, "N", "scripted: N frames on a fixed path around and close to the model"},
        {"stats-json", 0, CLI_STRING, &o.stats_json, "OUT.json", "write every frame's time, tau, depth limit and count, with median, p10, p90"},
        {"overlay", 0, CLI_FLAG, &o.overlay, NULL, "start with the figures over the frame (i toggles; on with --frame-ms)"},
        {"no-overlay", 0, CLI_FLAG, &o.no_overlay, NULL, "start without them"},
        {"memory", 0, CLI_STRING, &o.memory, "SIZE", "streamed .hier: memory for the points loaded, e.g. 1G (default 2G)"},
        {0},
    };
    cli_renderer_rows(&o.r, VIEW_OPTIONS, opts, sizeof opts / sizeof opts[0]);
    int npos = 0;
    int prc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (prc)
        return prc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat view -h'", npos);
    // a preset names the options of every input kind; those that do not fit this input are dropped
    asp_file_type ft = {ASP_FILE_UNKNOWN, "", 0};
    if (asp_file_recognise(argv[0], &ft, NULL) != 0)
        asp_file_type_of_name(argv[0], &ft, NULL);
    if (ft.kind != ASP_FILE_DPS && cli_from_preset(env, &o.r.method))
        o.r.method = NULL;
    if ((ft.kind == ASP_FILE_DPS || ft.kind == ASP_FILE_MESH) && cli_from_preset(env, &o.r.renderer))
        o.r.renderer = NULL;
    asp_viewer_desc desc = {.log = log_line, .log_user = env};
    if (parse_into(env, argv[0], &o, &desc))
        return 2;
    asp_error err = {0, ""};
    asp_viewer_stats stats;
    if (asp_viewer_run(argv[0], &desc, &env->ctx, &stats, &err)) {
        // a field the file does not have is a bad option value, as in render (the viewer's message names the file)
        if (desc.color_field && err.code == ASP_EINVAL && strncmp(err.msg, "cannot colour '", 15) == 0)
            return cli_usage_error(env, "%s expects classifier, domains, strict or input (.amg), or a point field: %s",
                                   o.r.color_by_name, err.msg);
        return cli_fail(env, &err);
    }
    if (env->json)
        return print_json(env, argv[0], &desc, &stats);
    cli_info(env, "drew %zu frames of '%s' (%s, %zu %s, %.2f ms per frame)\n", stats.frames, argv[0], stats.renderer,
             stats.count, "primitives", stats.mean_frame_ms);
    if (desc.frame_ms > 0)
        cli_info(env, "frame budget %g ms%s: median %.1f ms (p10 %.1f, p90 %.1f), tau %g..%g px, %zu..%zu primitives\n",
                 desc.frame_ms, stats.budget_applied ? "" : " (not applied: no level of detail)", stats.median_frame_ms,
                 stats.p10_frame_ms, stats.p90_frame_ms, (double)stats.tolerance_min, (double)stats.tolerance_max,
                 stats.count_min, stats.count_max);
    return 0;
}
#endif
