/*
 * amgsplat render: draw a point file or the points of an .amg decomposition
 * (coloured by classifier or domains, journal Fig. 1b, 5) headlessly (EGL) to
 * PNG with discs, blended splats (Pajarola et al. 2003) or squares, or the
 * domain primitives of a .dps level (journal section 4, thesis chapter 4),
 * one view or a contact sheet. Glue only: loading, colouring and framing are the
 * one scene loader (scene.h), drawing the one renderer table (render.h); see docs/cli/render.md.
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "amgsplat/instances.h"
#include "amgsplat/scene_renderer.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat render IN.ply -o OUT.png [--size WxH] [--view AZ,EL[,DIST]] [--views N]\n"
    "                      [--renderer disc|splat|square] [--tolerance PX | --budget N] [--kernel A,B,N]\n"
    "                      [--epsilon X] [--lighting gouraud|pixel|flat] [--opaque] [--unlit] [--point-size PX]\n"
    "                      [--background R,G,B[,A] | --transparent] [--light AZ,EL]\n"
    "                      [--preset thesis|journal|pajarola|schwarz] [--kernel-rim 1|b] [--kernel-shape psi-e|psi-g]\n"
    "                      [--epsilon-uniform X] [--tolerance-area PCT] [--axes sqrt|lambda] [--cull-backfaces]\n"
    "                      [--depth-limit N] [--frame-ms T]\n"
    "       amgsplat render IN.amg -o OUT.png [--color-by classifier|domains|strict|input] [--level L-3] ...\n"
    "       amgsplat render MESH -o OUT.png [--flat] [--texture IMG] [--renderer mesh|disc] ...\n"
    "       amgsplat render IN.dps -o OUT.png [--method normalized|prefix|overlap|two-pass|dark-backface|\n"
    "                      dark-backface-soft|blend-all|no-blend|polygons] [--level L] [--alpha-ref X]\n"
    "                      [--domains thresholded|strict] [--debug eigenvectors,texels,triangulation]\n"
    "                      [--only-domain N] [--no-overlap-backfaces]\n"
    "                      [--transparency X] [--depth-window X] [--crease-angle DEG|off] [--outline]\n"
    "                      [--color-by domain] [--overlap-backfaces] [--hybrid] [--hybrid-points POINTS] ...\n"
    "       amgsplat render SCENE.json -o OUT.png [--renderer disc|splat|square] [--method M] ...\n"
    "\n"
    "Renders a point set (PLY, XYZ) or the points of an AMG decomposition (.amg) headlessly through\n"
    "EGL (a GPU, or Mesa llvmpipe without one) to a PNG. Renderers: disc (opaque discs in the tangent\n"
    "planes), splat (blended elliptical splats of the point hierarchy for a screen tolerance of PX\n"
    "pixels, Pajarola et al. 2003), square (screen-aligned squares of the hierarchy, the cheapest).\n"
    "Lambert shading by a light fixed to the camera. AZ turns around +y (0 looks from +z), EL is the\n"
    "angle above the horizon, both in degrees; DIST is the eye distance in bounding-sphere radii\n"
    "(default: the sphere fills the view). --views N renders N views at azimuths AZ + 360 i / N,\n"
    "elevation alternating +EL and -EL, into one contact sheet. A .dps input (amgsplat build) draws\n"
    "the textured domain primitives of one level, blended by --method (docs/render-methods.md);\n"
    "with --hybrid, its source points (or POINTS) stand in where a primitive fails (docs/hybrid.md).\n"
    "A mesh (OBJ+MTL, PLY with faces, OFF, STL, glTF/GLB, 3DS) is drawn as textured triangles with\n"
    "the same lighting and framing as the points sampled from it (amgsplat sample); a texture that\n"
    "cannot be found is drawn in its material colour, with a warning. A scene file of instances\n"
    "(docs/scene-format.md, amgsplat scene field) is drawn whole from its own camera. A streamed\n"
    "(out-of-core) .hier (amgsplat convert IN.ply -o OUT.hier) loads only the nodes of each view's\n"
    "cut, coarse first, until their point spacing is below --tolerance PX (default 1) or the points\n"
    "fill --memory (default 2G), and draws them as discs (or --renderer compute).";

enum { MAX_VIEWS = 256, MAX_SIDE = 16384 };

/* The renderer options render takes (renderer_options.c), every one of them. */
#define RENDER_OPTIONS                                                                                       \
    (CLI_RO_RENDERER | CLI_RO_TOLERANCE | CLI_RO_BUDGET | CLI_RO_LEVEL | CLI_RO_COLOR_BY | CLI_RO_METHOD |   \
     CLI_RO_ALPHA_REF | CLI_RO_CREASE | CLI_RO_HYBRID | CLI_RO_CULL | CLI_RO_DEPTH_LIMIT | CLI_RO_FRAME_MS | \
     CLI_RO_UNLIT | CLI_RO_TEXTURE | CLI_RO_EDL)

struct render_opts {
    /*
     * the options render shares with view and eval (renderer_options.c): budget 0 = tau decides;
     * cull_backfaces, depth_limit: seed 004 3.2.2, 3.2.5; frame_ms: simulated frame budget (issue 18
     * item 5), tau settled per view; unlit: ASP_RENDER_UNLIT; hybrid: docs/hybrid.md
     */
    struct cli_renderer_opts r;
    const char *output;
    const char *memory; /* streamed .hier: --memory SIZE, the budget of the points loaded */
    const char *size;
    const char *view;
    const char *background;
    const char *light;
    const char *kernel;
    const char *lighting;
    size_t views;
    size_t samples;
    int transparent;
    double fov;
    double radius_scale;
    double epsilon;
    double point_size;
    int opaque;
    const char *preset; /* --preset: applied by cli_parse (docs/seeds.md) */
    const char *kernel_shape, *kernel_rim, *axes; /* seed 001 eq. 11-12, eq. 5-6 (docs/seeds.md) */
    double sigma, epsilon_uniform, tolerance_area; /* NaN: not given */
    unsigned splat_flags, hier_flags;
    asp_splat_kernel kernel_kind;
    double transparency;
    double depth_window;
    const char *up;
    int flat;
    int outline;
    int no_normal_map;
    int overlap_backfaces;
    const char *hybrid_points; /* --hybrid-points: the points instead of the .dps's source */
    int no_overlap_backfaces; /* switches off a preset's --overlap-backfaces (issue 17) */
    const char *domains;      /* .dps: thresholded | strict (thesis appendix C "Domain Set") */
    const char *debug;        /* .dps: eigenvectors,texels (thesis appendix C debug drawings) */
    size_t only_domain;       /* .dps: draw this primitive only; SIZE_MAX = all */
    /* parsed */
    unsigned width, height;
    double az, el, dist; /* dist 0 = fit */
    double light_az, light_el;
    uint8_t bg[4];
    float kernel_abn[3];
    asp_splat_lighting light_mode;
    int amg_input;
    int dps_input;
    int mesh_input;
    asp_prim_render_options prim;
    asp_up_axis up_axis;
    double point_crease; /* point inputs: crease angle of the clip planes, degrees; 0 = no clipping */
    int point_crease_default; /* point_crease is the default (points without normals: no clipping) */
    const asp_context *ctx;
};


/* The loaded file as the one scene loader gives it (scene.h), and the picked row of the renderer table. */
static int load_scene(const char *path, const struct render_opts *o, const struct cli_env *env, asp_scene *s,
                      asp_error *err)
{
    asp_scene_desc d = {.level = o->r.level, .crease_angle = (float)o->point_crease,
                        .crease_if_normals = o->point_crease_default, .texture = o->r.texture};
    if (o->amg_input && o->r.color_by) {
        d.amg_color = o->r.color_mode;
        if ((o->r.color_mode == ASP_SCENE_AMG_DOMAINS || o->r.color_mode == ASP_SCENE_AMG_STRICT) && !o->r.level)
            d.level = "L-3";
    }
    return asp_scene_load(path, &d, &env->ctx, s, err);
}

/*
 * Eye-dome lighting (asp_edl_desc) for the disc and square renderers: on when asked, or by default
 * when the points have no normals to light (CloudCompare and Potree turn it on for such scans), except
 * with --unlit, which asks for the colours as they are. Says once that estimate gives normals.
 */
static void edl_options(const struct render_opts *o, const asp_scene *s, const asp_renderer_kind *kind,
                        const struct cli_env *env, const char *path, asp_renderer_options *r)
{
    int points = s->cloud && !s->dps && (strcmp(kind->name, "disc") == 0 || strcmp(kind->name, "square") == 0);
    int no_normals = points && !s->cloud->normals;
    if (!points || o->r.no_edl || !(o->r.edl || !isnan(o->r.edl_strength) || (no_normals && !o->r.unlit)))
        return;
    asp_edl_desc e = {.strength = isnan(o->r.edl_strength) ? 1.0f : (float)o->r.edl_strength};
    r->disc.edl = r->square.edl = e;
    if (no_normals && s->type.kind == ASP_FILE_HIER) // a streamed .hier keeps no normals: estimate cannot help
        cli_info(env, "note: '%s' (streamed) has no normals: drawn with eye-dome lighting", path);
    else if (no_normals)
        cli_info(env, "hint: '%s' has no normals: drawn with eye-dome lighting; 'amgsplat estimate %s -o "
                      "WITH_NORMALS.ply' estimates them for lit discs", path, path);
}

static void renderer_options(const struct render_opts *o, asp_renderer_options *r)
{
    memset(r, 0, sizeof *r);
    r->disc.radius_scale = (float)o->radius_scale;
    r->splat = (asp_splat_renderer_desc){.kernel_a = o->kernel_abn[0], .kernel_b = o->kernel_abn[1],
                                         .kernel_n = o->kernel_abn[2],
                                         .epsilon = o->epsilon > 0 ? (float)o->epsilon : -1.0f, // 0 = no offset
                                         .tolerance = (float)o->r.tolerance, .radius_scale = (float)o->radius_scale,
                                         .lighting = o->light_mode,
                                         .mode = o->opaque ? ASP_SPLAT_OPAQUE : ASP_SPLAT_BLEND,
                                         .flags = o->splat_flags, .kernel = o->kernel_kind,
                                         .kernel_sigma = isnan(o->sigma) ? 0.0f : (float)o->sigma,
                                         .hier = {.flags = o->hier_flags}};
    if (!isnan(o->epsilon_uniform))
        r->splat.epsilon = (float)o->epsilon_uniform; // world units; 0 = the mean point splat
    r->square = (asp_square_renderer_desc){.point_size = (float)o->point_size, .tolerance = (float)o->r.tolerance,
                                           .radius_scale = (float)o->radius_scale, .hier = {.flags = o->hier_flags},
                                           .flags = o->r.cull_backfaces ? ASP_SPLAT_CULL_BACKFACES : 0u};
    if (o->r.cull_backfaces)
        r->splat.flags |= ASP_SPLAT_CULL_BACKFACES;
    if (!isnan(o->tolerance_area)) // seed 001 5.1: tau in percent of the window (one view's) area
        r->splat.tolerance = r->square.tolerance = asp_render_tolerance_from_area(o->tolerance_area, o->width, o->height);
    r->prim = o->prim;
    r->hybrid = (asp_hybrid_desc){.prim = o->prim, .splat = r->splat};
    // the cut across .dps levels (issue 18): the same tolerance in pixels; 0 = the finest level everywhere
    r->cut = (asp_cut_renderer_desc){.tolerance = o->r.tolerance > 0 ? (float)o->r.tolerance : -1.0f,
                                     .alpha_ref = o->prim.alpha_ref, .transparency = o->prim.transparency};
    r->mesh.flags = o->flat ? ASP_MESH_RENDER_FLAT : 0u;
}

/*
 * Domain Set (thesis appendix C): the level of the asked set built from the same AMG level as the one
 * --level names; a level of the other set given by hand is switched, and strict levels are drawn with
 * the thesis's no-blend method unless --method says otherwise.
 */
static int pick_domain_set(struct render_opts *o, asp_scene *s, asp_renderer_options *ropts, asp_error *err)
{
    int strict = o->domains && strcmp(o->domains, "strict") == 0;
    if (o->domains && (s->dps->levels[s->dps_level].strict != 0) != strict) {
        int rc = asp_dps_domain_set_pick(s->dps, s->dps_level, strict, &s->dps_level, err);
        if (rc)
            return rc;
    }
    if (s->dps->levels[s->dps_level].strict && !o->r.method)
        ropts->prim.method = o->prim.method = ASP_PRIM_RENDER_NO_BLEND;
    if (o->only_domain == SIZE_MAX)
        return 0;
    // the picked primitive replaces its level in the scene, so every method draws it alone
    asp_dps_level *lv = &s->dps->levels[s->dps_level], one;
    int rc = asp_dps_level_pick(lv, o->only_domain, &s->dps->ctx, &one, err);
    if (rc)
        return rc;
    asp_dps_level_release(lv, &s->dps->ctx);
    *lv = one;
    return 0;
}

/*
 * --debug triangulation (thesis appendix C): the affine triangles are not stored in the .dps, so the
 * library makes them again from the decomposition the file names (asp_dps_source_find).
 */
static int debug_triangles(const char *path, const asp_scene *s, asp_renderer *r, const struct cli_env *env,
                           asp_error *err)
{
    char use[4096];
    asp_file_type t;
    if (asp_dps_source_find(s->dps, path, use, sizeof use, &t, NULL) != 0 || t.kind != ASP_FILE_AMG)
        return asp_error_set(err, ASP_EUNSUPPORTED, "--debug triangulation needs the .amg '%s' was built from; it "
                             "names '%s' (build from an .amg: amgsplat decompose, then build)", path, s->dps->source);
    asp_amg *amg = NULL;
    float *lines = NULL;
    size_t n = 0;
    int rc = asp_amg_load(use, &env->ctx, &amg, err);
    if (!rc)
        rc = asp_prim_level_triangles(amg, s->dps, s->dps_level, s->origin, &env->ctx, &lines, &n, err);
    if (!rc)
        rc = asp_prim_renderer_set_debug_lines(r, lines, n, err);
    asp_free(&env->ctx, lines);
    asp_amg_destroy(amg);
    asp_amg_shutdown();
    return rc;
}

/* The library records textures it could not find; saying so is the command's job (STYLE.md 4). */
static void warn_missing_textures(const asp_scene *s)
{
    if (!s->mesh)
        return;
    for (size_t i = 0; i < s->mesh->material_count; i++) {
        const asp_material *m = &s->mesh->materials[i];
        if (m->texture_missing)
            fprintf(stderr, "warning: texture '%s' of material '%s' not found: drawn in its material colour\n",
                    m->texture_path, m->name);
    }
}

/* Options of the hierarchy renderers and of .amg inputs. */
static int parse_splat_options(struct cli_env *env, struct render_opts *o)
{
    if (!(o->epsilon >= 0 && o->epsilon <= 1e6))
        return cli_usage_error(env, "--epsilon expects splat radii in 0..1e6, got %g", o->epsilon);
    if (!(o->point_size >= 0) || !(o->point_size <= 256))
        return cli_usage_error(env, "--point-size expects pixels in 0..256 (0 = projected size), got %g",
                               o->point_size);
    if (o->kernel) {
        double v[3] = {0, 0, 0};
        if (cli_parse_doubles(o->kernel, v, 3) != 3 || !(v[0] > 0 && v[1] > 0 && v[2] > 0) || !isfinite(v[0]) ||
            !isfinite(v[1]) || !isfinite(v[2]))
            return cli_usage_error(env, "--kernel expects A,B,N, three positive numbers (e.g. 6,1.5,3), got '%s'",
                                   o->kernel);
        for (int i = 0; i < 3; i++)
            o->kernel_abn[i] = (float)v[i];
    }
    if (o->kernel_shape && strcmp(o->kernel_shape, "psi-e") != 0 && strcmp(o->kernel_shape, "psi-g") != 0)
        return cli_usage_error(env, "--kernel-shape expects psi-e or psi-g, got '%s'", o->kernel_shape);
    o->kernel_kind = o->kernel_shape && strcmp(o->kernel_shape, "psi-g") == 0 ? ASP_SPLAT_KERNEL_PSI_G
                                                                              : ASP_SPLAT_KERNEL_PSI_E;
    if (!isnan(o->sigma) && !(o->sigma > 0))
        return cli_usage_error(env, "--sigma expects a number > 0, got %g", o->sigma);
    if (o->kernel_rim && strcmp(o->kernel_rim, "1") != 0 && strcmp(o->kernel_rim, "b") != 0)
        return cli_usage_error(env, "--kernel-rim expects 1 or b, got '%s'", o->kernel_rim);
    if (o->kernel_rim && strcmp(o->kernel_rim, "b") == 0)
        o->splat_flags |= ASP_SPLAT_KERNEL_RIM_AT_B;
    if (!isnan(o->epsilon_uniform) && !(o->epsilon_uniform >= 0))
        return cli_usage_error(env, "--epsilon-uniform expects world units >= 0 (0 = the mean splat), got %g",
                               o->epsilon_uniform);
    if (!isnan(o->epsilon_uniform))
        o->splat_flags |= ASP_SPLAT_EPSILON_UNIFORM;
    if (!isnan(o->tolerance_area) && !(o->tolerance_area >= 0 && o->tolerance_area <= 100))
        return cli_usage_error(env, "--tolerance-area expects a percentage in 0..100, got %g", o->tolerance_area);
    if (o->axes && strcmp(o->axes, "sqrt") != 0 && strcmp(o->axes, "lambda") != 0)
        return cli_usage_error(env, "--axes expects sqrt or lambda, got '%s'", o->axes);
    if (o->axes && strcmp(o->axes, "lambda") == 0)
        o->hier_flags |= ASP_HIER_BUILD_LAMBDA_AXES;
    static const char *const modes[] = {"gouraud", "pixel", "flat"};
    if (o->lighting) {
        int found = -1;
        for (int i = 0; i < 3; i++)
            if (strcmp(o->lighting, modes[i]) == 0)
                found = i;
        if (found < 0)
            return cli_usage_error(env, "--lighting expects gouraud, pixel or flat, got '%s'", o->lighting);
        o->light_mode = (asp_splat_lighting)found;
    }
    if (o->r.color_field && (o->dps_input || o->amg_input))
        return cli_usage_error(env, "%s expects classifier, domains, strict or input (.amg), or domain (.dps), got '%s'",
                               o->r.color_by_name, o->r.color_field);
    if (o->dps_input) {
        if (o->r.has_color && o->r.color_mode != ASP_SCENE_AMG_DOMAINS)
            return cli_usage_error(env, "%s on a .dps input expects domain, got '%s'", o->r.color_by_name,
                                   o->r.color_by);
        return 0;
    }
    if (o->r.has_color && !o->amg_input)
        return cli_usage_error(env, "%s needs an .amg input (amgsplat decompose makes one)", o->r.color_by_name);
    if (o->r.level && !(o->r.color_mode == ASP_SCENE_AMG_DOMAINS || o->r.color_mode == ASP_SCENE_AMG_STRICT))
        return cli_usage_error(env, "--level needs --color-by domains or strict");
    return 0;
}

/* Options of .dps inputs (asp_prim_render_options). */
static int parse_prim_options(struct cli_env *env, struct render_opts *o)
{
    // NaN marks "not given": the option parser refuses non-finite values, so no user value collides with it
    int given = o->r.method || o->domains || o->debug || o->only_domain != SIZE_MAX || !isnan(o->r.alpha_ref) || !isnan(o->transparency) || !isnan(o->depth_window) || o->outline ||
                o->no_normal_map || o->overlap_backfaces;
    if (!o->dps_input) {
        if (given)
            return cli_usage_error(env, "--method, --domains, --debug, --only-domain, --alpha-ref, --transparency, --depth-window, --outline, --overlap-backfaces and "
                                        "--no-normal-map need a .dps input (amgsplat build makes one)");
        if (!o->r.crease_angle) {
            // the default: discs and splats cut at creases sharper than 60 degrees, as the primitives
            // and eval's reference are, so one --view gives one silhouette whatever the file (issue 12:
            // octahedron points vs primitives IoU 0.936 unclipped, 0.981 clipped); points without
            // normals stay unclipped. The square and compute renderers do not clip.
            if (!(o->r.renderer && (strcmp(o->r.renderer, "square") == 0 || strcmp(o->r.renderer, "compute") == 0))) {
                o->point_crease = ASP_PRIM_CREASE_ANGLE_DEFAULT;
                o->point_crease_default = 1;
            }
            return 0;
        }
        if (o->r.crease < 0)
            return 0; // off
        if (!(o->r.crease < 90))
            return cli_usage_error(env, "--crease-angle expects degrees in (0, 90) or 'off' for points, got '%s'",
                                   o->r.crease_angle);
        if (o->r.renderer && (strcmp(o->r.renderer, "square") == 0 || strcmp(o->r.renderer, "compute") == 0))
            return cli_usage_error(env, "--crease-angle: the %s renderer does not clip (use disc or splat)",
                                   o->r.renderer);
        o->point_crease = o->r.crease;
        return 0;
    }
    asp_prim_render_options *p = &o->prim;
    if (o->r.method)
        p->method = o->r.method_kind;
    for (const char *d = o->debug; d && *d;) {
        size_t len = strcspn(d, ",");
        if (len == strlen("eigenvectors") && strncmp(d, "eigenvectors", len) == 0)
            p->flags |= ASP_PRIM_RENDER_DEBUG_EIGENVECTORS;
        else if (len == strlen("texels") && strncmp(d, "texels", len) == 0)
            p->flags |= ASP_PRIM_RENDER_DEBUG_TEXELS;
        else if (len == strlen("triangulation") && strncmp(d, "triangulation", len) == 0)
            p->flags |= ASP_PRIM_RENDER_DEBUG_TRIANGULATION;
        else
            return cli_usage_error(env, "--debug expects eigenvectors, texels, triangulation or several comma-separated, got '%.*s'",
                                   (int)len, d);
        d += len + (d[len] == ',');
    }
    if (o->domains && strcmp(o->domains, "thresholded") != 0 && strcmp(o->domains, "strict") != 0)
        return cli_usage_error(env, "--domains expects thresholded or strict, got '%s'", o->domains);
    if (!isnan(o->r.alpha_ref))
        p->alpha_ref = o->r.alpha_ref_lib;
    if (!isnan(o->transparency)) {
        if (!(o->transparency > 0 && o->transparency <= 1))
            return cli_usage_error(env, "--transparency expects an opacity in (0, 1], got %g", o->transparency);
        p->transparency = (float)o->transparency;
    }
    if (!isnan(o->depth_window)) {
        if (!(o->depth_window >= 0 && isfinite(o->depth_window)))
            return cli_usage_error(env, "--depth-window expects world units >= 0, got %g", o->depth_window);
        p->depth_window = o->depth_window > 0 ? (float)o->depth_window : -1.0f; // 0 = no window
    }
    if (o->r.crease_angle)
        p->crease_angle = (float)o->r.crease; // -1: off
    p->flags |= (o->outline ? ASP_PRIM_RENDER_OUTLINE : 0u) | (o->r.color_by ? ASP_PRIM_RENDER_COLOR_BY_DOMAIN : 0u) |
               (o->no_normal_map ? ASP_PRIM_RENDER_NO_NORMAL_MAP : 0u) |
               (o->overlap_backfaces ? ASP_PRIM_RENDER_OVERLAP_BACKFACES : 0u);
    return 0;
}

static int parse_options(struct cli_env *env, struct render_opts *o)
{
    if (cli_renderer_check(env, &o->r, RENDER_OPTIONS))
        return 2;
    if (isnan(o->r.tolerance))
        o->r.tolerance = 1.0; // render's default tau, in pixels
    if (!o->output)
        return cli_usage_error(env, "missing -o OUT.png");
    if (o->up && cli_parse_up(o->up, &o->up_axis) != 0)
        return cli_usage_error(env, "--up expects x, y, z, -x, -y or -z, got '%s'", o->up);
    if (!asp_file_name_is(o->output, "png"))
        return cli_usage_error(env, "output '%s' must end in .png", o->output);
    if (o->size && (cli_parse_size2(o->size, &o->width, &o->height) != 0 || o->width == 0 || o->height == 0 ||
                    o->width > MAX_SIDE || o->height > MAX_SIDE))
        return cli_usage_error(env, "--size expects WxH with sides in 1..%d, got '%s'", MAX_SIDE, o->size);
    if (o->view && cli_parse_view(env, o->view, &o->az, &o->el, &o->dist))
        return 2;
    if (o->views < 1 || o->views > MAX_VIEWS)
        return cli_usage_error(env, "--views expects 1..%d, got %zu", MAX_VIEWS, o->views);
    if (o->samples > 64)
        return cli_usage_error(env, "--samples expects 0..64, got %zu", o->samples);
    if (o->transparent && o->background)
        return cli_usage_error(env, "--background and --transparent exclude each other");
    if (o->background && cli_parse_colour(env, "--background", o->background, 1, o->bg))
        return 2;
    if (o->transparent)
        memset(o->bg, 0, 4);
    if (o->light) {
        double v[2] = {0, 0};
        // AZ bounded as --view's (cli_parse_view): 1e300 degrees is no direction
        if (cli_parse_doubles(o->light, v, 2) != 2 || !(v[1] >= -90 && v[1] <= 90) || !(fabs(v[0]) <= 36000))
            return cli_usage_error(env, "--light expects AZ,EL in degrees with AZ in -36000..36000 and EL in -90..90, "
                                   "got '%s'", o->light);
        o->light_az = v[0];
        o->light_el = v[1];
    }
    if (!(o->fov > 0 && o->fov < 180))
        return cli_usage_error(env, "--fov expects degrees in (0, 180), got %g", o->fov);
    if (!(o->radius_scale > 0 && o->radius_scale <= 1e6))
        return cli_usage_error(env, "--radius-scale expects a value in (0, 1e6], got %g", o->radius_scale);
    if (parse_splat_options(env, o))
        return 2;
    return parse_prim_options(env, o);
}

/* What the views drew: primitives per view (the cut depends on the view) and the time per view. */
struct view_stats {
    size_t min_count, max_count, last_count;
    double seconds; /* all asp_render_to_image calls, read-back included */
    asp_frame_budget *budget;        /* --frame-ms: settled before each view, from the last view's state */
    asp_frame_budget_result settled; /* the last view's */
    const char *compute_path;        /* --renderer compute: the atomics that drew (asp_compute_renderer_path) */
};

/* Renders the views into tiles[0 .. views-1], every one framed by the scene's frame (asp_camera_frame). */
static int render_views(asp_gl_context *gl, asp_renderer *r, const asp_scene *s, const struct render_opts *o,
                        const struct cli_env *env, asp_image *tiles, struct view_stats *vs, asp_error *err)
{
    vs->min_count = SIZE_MAX;
    asp_render_desc desc = {.width = o->width, .height = o->height, .samples = (uint32_t)o->samples,
                            .light_azimuth = (float)o->light_az, .light_elevation = (float)o->light_el,
                            .flags = o->r.unlit ? ASP_RENDER_UNLIT : 0u};
    memcpy(desc.background, o->bg, 4);
    for (size_t i = 0; i < o->views; i++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.fov_y = (float)o->fov;
        cam.up = o->up_axis;
        cam.azimuth = (float)(o->az + 360.0 * (double)i / (double)o->views);
        cam.elevation = (float)(i % 2 ? -o->el : o->el);
        asp_camera_frame(&cam, &s->frame, s->origin, (float)o->width / (float)o->height, (float)o->dist);
        if (vs->budget) {
            int brc = asp_frame_budget_settle(gl, r, &cam, &desc, vs->budget, 0, 0, &vs->settled, err);
            if (brc)
                return brc;
        }
        double t0 = asp_time_now();
        int rc = asp_render_to_image(gl, r, &cam, &desc, &tiles[i], err);
        if (rc)
            return rc;
        vs->seconds += asp_time_now() - t0;
        vs->last_count = asp_renderer_count(r);
        vs->compute_path = asp_compute_renderer_path(r);
        vs->min_count = vs->last_count < vs->min_count ? vs->last_count : vs->min_count;
        vs->max_count = vs->last_count > vs->max_count ? vs->last_count : vs->max_count;
        rc = asp_progress(&env->ctx, "render", (double)(i + 1) / (double)o->views);
        if (rc)
            return asp_error_set(err, rc, "rendering canceled");
    }
    return 0;
}

static int print_json(const struct cli_env *env, const struct render_opts *o, size_t count, const asp_scene *s,
                      asp_gl_context *gl, const char *renderer, const asp_image *img, const struct view_stats *vs,
                      double seconds, const asp_hybrid_counts *hc)
{
    cJSON *j = cJSON_CreateObject(), *frame = cJSON_CreateArray();
    cJSON_AddStringToObject(j, "output", o->output);
    cJSON_AddNumberToObject(j, "width", img->width);
    cJSON_AddNumberToObject(j, "height", img->height);
    cJSON_AddNumberToObject(j, "tile_width", o->width);
    cJSON_AddNumberToObject(j, "tile_height", o->height);
    cJSON_AddNumberToObject(j, "views", (double)o->views);
    cJSON_AddNumberToObject(j, "points", (double)count);
    cJSON_AddStringToObject(j, "renderer", renderer);
    if (o->dps_input) {
        cJSON_AddStringToObject(j, "method", o->r.hybrid ? "hybrid" : asp_prim_render_method_name(o->prim.method));
        cJSON_AddStringToObject(j, "domains", asp_scene_dps_level(s)->strict ? "strict" : "thresholded");
        cJSON_AddNumberToObject(j, "level", asp_scene_dps_level(s)->level);
    }
    cJSON_AddStringToObject(j, "gl_renderer", asp_gl_context_renderer(gl));
    cJSON_AddStringToObject(j, "gl_backend", asp_gl_context_backend(gl));
    if (vs->compute_path)
        cJSON_AddStringToObject(j, "compute_path", vs->compute_path);
    int lod = strcmp(renderer, "disc") && strcmp(renderer, "prim") && strcmp(renderer, "mesh");
    cJSON_AddNumberToObject(j, "primitives", (double)vs->last_count);
    cJSON_AddNumberToObject(j, "primitives_min", (double)vs->min_count);
    cJSON_AddNumberToObject(j, "primitives_max", (double)vs->max_count);
    cJSON_AddItemToObject(j, "tolerance", cli_json_number("%g", lod && !o->r.budget ? o->r.tolerance : 0.0));
    cJSON_AddNumberToObject(j, "budget", (double)o->r.budget);
    cJSON_AddItemToObject(j, "view_ms", cli_json_number("%.3f", 1e3 * vs->seconds / (double)o->views));
    // the camera's sphere, so two inputs of one model can be checked to frame alike
    for (int k = 0; k < 3; k++)
        cJSON_AddItemToArray(frame, cli_json_number("%.9g", s->frame.center[k]));
    cJSON_AddItemToArray(frame, cli_json_number("%.9g", s->frame.radius));
    cJSON_AddItemToObject(j, "frame", frame);
    cJSON_AddItemToObject(j, "seconds", cli_json_number("%.3f", seconds));
    if (hc) {
        cJSON *h = cJSON_AddObjectToObject(j, "hybrid");
        cJSON_AddNumberToObject(h, "primitives_kept", (double)hc->prims_kept);
        cJSON_AddNumberToObject(h, "primitives_replaced", (double)hc->prims_replaced);
        cJSON_AddNumberToObject(h, "points_drawn", (double)hc->points_drawn);
        cJSON_AddNumberToObject(h, "points_total", (double)hc->points_total);
    }
    if (vs->budget) { // the last view's simulated budget
        cJSON *b = cJSON_CreateObject();
        cJSON_AddNumberToObject(b, "target_ms", o->r.frame_ms);
        cJSON_AddItemToObject(b, "median_ms", cli_json_number("%.3f", vs->settled.median_ms));
        cJSON_AddItemToObject(b, "p10_ms", cli_json_number("%.3f", vs->settled.p10_ms));
        cJSON_AddItemToObject(b, "p90_ms", cli_json_number("%.3f", vs->settled.p90_ms));
        cJSON_AddItemToObject(b, "tolerance", cli_json_number("%g", vs->settled.tolerance));
        cJSON_AddNumberToObject(b, "depth_limit", vs->settled.depth_limit);
        cJSON_AddNumberToObject(b, "frames", (double)vs->settled.frames);
        cJSON_AddBoolToObject(b, "settled", vs->settled.settled);
        cJSON_AddBoolToObject(b, "held", vs->settled.held);
        cJSON_AddNumberToObject(b, "count", (double)vs->settled.count);
        cJSON_AddItemToObject(j, "frame_budget", b);
    }
    return cli_json_print(env, j);
}

/* The scene's own camera, or orbit views around its frame when --view or --views asks for them. */
static void scene_camera(const asp_instance_scene *s, const struct render_opts *o, size_t i, asp_camera *cam)
{
    int orbit = o->view != NULL || o->views > 1;
    float az = (float)(o->az + 360.0 * (double)i / (double)o->views), el = (float)(i % 2 ? -o->el : o->el);
    asp_instance_scene_camera(s, orbit, (float)o->width / (float)o->height, (float)o->fov, az, el, (float)o->dist,
                              cam);
}

static int print_scene_json(const struct cli_env *env, const struct render_opts *o, const asp_instance_scene *s,
                            asp_gl_context *gl, const asp_image *img, const struct view_stats *vs, size_t drawn,
                            double seconds)
{
    cJSON *j = cJSON_CreateObject(), *frame = cJSON_CreateArray();
    cJSON_AddStringToObject(j, "output", o->output);
    cJSON_AddNumberToObject(j, "width", img->width);
    cJSON_AddNumberToObject(j, "height", img->height);
    cJSON_AddNumberToObject(j, "views", (double)o->views);
    cJSON_AddNumberToObject(j, "instances", (double)s->instance_count);
    cJSON_AddNumberToObject(j, "sources", (double)s->source_count);
    cJSON_AddNumberToObject(j, "instances_drawn", (double)drawn);
    cJSON_AddStringToObject(j, "renderer", "scene");
    cJSON_AddStringToObject(j, "gl_renderer", asp_gl_context_renderer(gl));
    cJSON_AddNumberToObject(j, "primitives", (double)vs->last_count);
    cJSON_AddNumberToObject(j, "primitives_min", (double)vs->min_count);
    cJSON_AddNumberToObject(j, "primitives_max", (double)vs->max_count);
    cJSON_AddItemToObject(j, "view_ms", cli_json_number("%.3f", 1e3 * vs->seconds / (double)o->views));
    for (int k = 0; k < 3; k++)
        cJSON_AddItemToArray(frame, cli_json_number("%.9g", s->frame.center[k]));
    cJSON_AddItemToArray(frame, cli_json_number("%.9g", s->frame.radius));
    cJSON_AddItemToObject(j, "frame", frame);
    cJSON_AddItemToObject(j, "seconds", cli_json_number("%.3f", seconds));
    return cli_json_print(env, j);
}

/* A scene of instances (instances.h): every source drawn by its row of the table, all in one frame. */
static int render_instance_scene(const char *path, struct render_opts *o, struct cli_env *env)
{
    if (o->r.budget)
        return cli_usage_error(env, "--budget is per model; a scene takes --tolerance (every instance's cut)");
    if (o->r.hybrid || o->hybrid_points)
        return cli_usage_error(env, "--hybrid draws one .dps with its points; a scene's sources are drawn one by one");
    if (o->r.frame_ms > 0)
        return cli_usage_error(env, "--frame-ms settles one model's cut; a scene takes --tolerance (every instance's cut)");
    const asp_renderer_kind *kind = NULL;
    asp_error err = {0, ""};
    if (o->r.renderer && asp_renderer_kind_find(o->r.renderer, ASP_RENDER_INPUT_POINTS, &kind, &err))
        return cli_usage_error(env, "--renderer is the scene's point sources' renderer: %s", err.msg);
    if (o->up)
        return cli_usage_error(env, "--up: a scene is y-up (turn its instances with rotate_deg instead)");
    double t0 = asp_time_now();
    asp_instance_scene s;
    memset(&s, 0, sizeof s);
    asp_gl_context *gl = NULL;
    asp_renderer *r = NULL;
    asp_image tiles[MAX_VIEWS];
    asp_image sheet = {0, 0, NULL};
    memset(tiles, 0, sizeof tiles);
    struct view_stats vs = {SIZE_MAX, 0, 0, 0, NULL, {0}, NULL};
    asp_renderer_options ropts;
    renderer_options(o, &ropts);
    asp_scene_desc d = {.level = o->r.level, .texture = o->r.texture};
    int rc = asp_instance_scene_load(path, &d, &env->ctx, &s, &err);
    for (size_t i = 0; !rc && i < s.source_count; i++)
        warn_missing_textures(&s.sources[i].scene);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, &env->ctx, &gl, &err);
    if (!rc)
        rc = asp_instance_scene_renderer_create(gl, &s, o->r.renderer, &ropts, &env->ctx, &r, &err);
    if (!rc && o->r.depth_limit)
        rc = asp_renderer_set_lod(r, ropts.splat.tolerance, (uint32_t)o->r.depth_limit, &err);
    asp_render_desc desc = {.width = o->width, .height = o->height, .samples = (uint32_t)o->samples,
                            .light_azimuth = (float)o->light_az, .light_elevation = (float)o->light_el,
                            .flags = o->r.unlit ? ASP_RENDER_UNLIT : 0u};
    memcpy(desc.background, s.has_background && !o->background && !o->transparent ? s.background : o->bg, 4);
    for (size_t i = 0; !rc && i < o->views; i++) {
        asp_camera cam;
        scene_camera(&s, o, i, &cam);
        double tv = asp_time_now();
        rc = asp_render_to_image(gl, r, &cam, &desc, &tiles[i], &err);
        vs.seconds += asp_time_now() - tv;
        if (rc)
            break;
        vs.last_count = asp_renderer_count(r);
        vs.min_count = vs.last_count < vs.min_count ? vs.last_count : vs.min_count;
        vs.max_count = vs.last_count > vs.max_count ? vs.last_count : vs.max_count;
        if ((rc = asp_progress(&env->ctx, "render", (double)(i + 1) / (double)o->views)) != 0)
            asp_error_set(&err, rc, "rendering canceled");
    }
    if (!rc && o->views > 1)
        rc = asp_image_contact_sheet(tiles, o->views, 0, &sheet, &err);
    const asp_image *result = o->views > 1 ? &sheet : &tiles[0];
    if (!rc)
        rc = asp_image_save_png(result, o->output, &err);
    size_t drawn = asp_scene_renderer_drawn(r);
    int status = 0;
    if (rc) {
        status = cli_fail(env, &err);
    } else {
        cli_progress_end(env);
        if (env->json)
            status = print_scene_json(env, o, &s, gl, result, &vs, drawn, asp_time_now() - t0);
        else
            cli_info(env,
                     "rendered %zu view%s of a scene of %zu instances of %zu source%s (%zu instances and %zu "
                     "primitives in the last view, %.1f ms per view, %s) to '%s' (%ux%u) in %.2f s\n",
                     o->views, o->views > 1 ? "s" : "", s.instance_count, s.source_count,
                     s.source_count == 1 ? "" : "s", drawn, vs.last_count, 1e3 * vs.seconds / (double)o->views,
                     asp_gl_context_renderer(gl), o->output, result->width, result->height, asp_time_now() - t0);
    }
    asp_image_release(&sheet);
    for (size_t i = 0; i < o->views; i++)
        asp_image_release(&tiles[i]);
    asp_renderer_destroy(r);
    asp_gl_context_destroy(gl);
    asp_instance_scene_release(&s);
    return status;
}

int cmd_render(int argc, char **argv, struct cli_env *env)
{
    // NaN marks the .dps numbers as not given
    struct render_opts o = {.views = 1, .samples = 4, .fov = 40.0, .radius_scale = 1.0, .width = 512, .height = 512,
                            .az = 30.0, .el = 20.0, .epsilon = 1.0,
                            .sigma = NAN, .epsilon_uniform = NAN, .tolerance_area = NAN,
                            .transparency = NAN, .depth_window = NAN, .only_domain = SIZE_MAX, .bg = {255, 255, 255, 255}, .ctx = &env->ctx};
    cli_renderer_opts_init(&o.r);
    struct cli_option opts[80] = {
        {"output", 'o', CLI_STRING, &o.output, "OUT.png", "output PNG (required)"},
        {"preset", 0, CLI_STRING, &o.preset, "SEED", "the seed's options: thesis, journal, pajarola, schwarz (docs/seeds.md)"},
        {"size", 0, CLI_STRING, &o.size, "WxH", "image size of one view (default 512x512)"},
        {"memory", 0, CLI_STRING, &o.memory, "SIZE", "streamed .hier: memory for the points loaded, e.g. 1G (default 2G)"},
        {"view", 0, CLI_STRING, &o.view, "AZ,EL[,DIST]", "camera azimuth, elevation (degrees), distance in radii (default 30,20)"},
        {"views", 0, CLI_SIZE, &o.views, "N", "N views around the object in a contact sheet (default 1)"},
        {"kernel", 0, CLI_STRING, &o.kernel, "A,B,N", "splat: kernel exp(-A (r/B)^N) (default 6,1.5,3)"},
        {"epsilon", 0, CLI_DOUBLE, &o.epsilon, "X", "splat: depth offset in splat radii for blending (default 1; 0 = none)"},
        {"epsilon-uniform", 0, CLI_DOUBLE, &o.epsilon_uniform, "X", "splat: one depth offset for all splats in world units, seed 001 5.3 (0 = the mean splat)"},
        {"kernel-shape", 0, CLI_STRING, &o.kernel_shape, "K", "splat: psi-e (default, seed 001 eq. 12) or psi-g (eq. 11, --sigma)"},
        {"sigma", 0, CLI_DOUBLE, &o.sigma, "X", "splat: psi-g's sigma in kernel radii (default 0.5)"},
        {"kernel-rim", 0, CLI_STRING, &o.kernel_rim, "1|b", "splat: the ellipse rim is the kernel's r = 1 (default) or r = b (seed 001 Fig. 11)"},
        {"tolerance-area", 0, CLI_DOUBLE, &o.tolerance_area, "PCT", "splat, square: tau in percent of the view's area (seed 001 5.1); replaces --tolerance"},
        {"axes", 0, CLI_STRING, &o.axes, "A", "splat, square: ellipse axis ratio sqrt (default) or lambda (seed 001 eq. 5-6)"},
        {"lighting", 0, CLI_STRING, &o.lighting, "MODE", "splat: gouraud (default), pixel or flat"},
        {"opaque", 0, CLI_FLAG, &o.opaque, NULL, "splat: opaque ellipses, no blending"},
        {"point-size", 0, CLI_DOUBLE, &o.point_size, "PX", "square: fixed side in pixels (default 0: projected size)"},
        {"transparency", 0, CLI_DOUBLE, &o.transparency, "X", ".dps: global opacity scaling alpha, (0, 1] (default 1)"},
        {"depth-window", 0, CLI_DOUBLE, &o.depth_window, "X", ".dps: depth offset / window in world units (default: half the mean primitive radius)"},
        {"outline", 0, CLI_FLAG, &o.outline, NULL, ".dps: draw the support rectangles' edges in green"},
        {"no-normal-map", 0, CLI_FLAG, &o.no_normal_map, NULL, ".dps: light with the primitive normals even when the file has normal maps"},
        {"hybrid-points", 0, CLI_STRING, &o.hybrid_points, "POINTS", ".dps: --hybrid with these points (point file or .amg) instead of the file's source"},
        {"domains", 0, CLI_STRING, &o.domains, "SET", ".dps built with --domains both: thresholded (default) or strict (drawn no-blend unless --method)"},
        {"debug", 0, CLI_STRING, &o.debug, "LIST", ".dps: debug drawings (thesis app. C): eigenvectors, texels, triangulation (needs the source .amg), comma-separated"},
        {"only-domain", 0, CLI_SIZE, &o.only_domain, "N", ".dps: draw primitive N of the level only (thesis app. C)"},
        {"overlap-backfaces", 0, CLI_FLAG, &o.overlap_backfaces, NULL, ".dps, overlap: also draw back-facing neighbours, as journal Fig. 10's pseudocode"},
        {"no-overlap-backfaces", 0, CLI_FLAG, &o.no_overlap_backfaces, NULL, ".dps, overlap: cull back faces (the default; turns off a preset's --overlap-backfaces)"},
        {"background", 0, CLI_STRING, &o.background, "R,G,B[,A]", "background colour, 0..255 or #RRGGBB[AA] (default 255,255,255)"},
        {"transparent", 0, CLI_FLAG, &o.transparent, NULL, "transparent background"},
        {"light", 0, CLI_STRING, &o.light, "AZ,EL", "light direction relative to the view (default 0,0: headlight)"},
        {"samples", 0, CLI_SIZE, &o.samples, "N", "multisamples per pixel, 0..64 (default 4)"},
        {"fov", 0, CLI_DOUBLE, &o.fov, "DEG", "vertical field of view (default 40)"},
        {"up", 0, CLI_STRING, &o.up, "AXIS", "world axis shown upright: y, z (scans, CAD), x, -y, -z or -x (default: the file's, z for LAS and what was made from it, else y)"},
        {"flat", 0, CLI_FLAG, &o.flat, NULL, "mesh: light each triangle by its face normal (default: smooth vertex normals)"},
        {"radius-scale", 0, CLI_DOUBLE, &o.radius_scale, "X", "multiply every disc, ellipse or square size by X (default 1)"},
        {0},
    };
    cli_renderer_rows(&o.r, RENDER_OPTIONS, opts, sizeof opts / sizeof opts[0]);
    int npos = 0;
    int prc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (prc)
        return prc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat render -h'", npos);
    // the file's kind decides which options apply; a file that cannot be read fails in the loader
    asp_file_type type = {ASP_FILE_UNKNOWN, "", 0};
    if (asp_file_recognise(argv[0], &type, NULL) != 0)
        asp_file_type_of_name(argv[0], &type, NULL);
    o.amg_input = type.kind == ASP_FILE_AMG;
    // a scene takes the .dps options for its .dps sources (and its point sources stay unclipped)
    o.dps_input = type.kind == ASP_FILE_DPS || type.kind == ASP_FILE_SCENE;
    // a preset names the options of every input kind; those that do not fit this input are dropped
    if (!o.dps_input && cli_from_preset(env, &o.r.method))
        o.r.method = NULL;
    if (!o.dps_input && cli_from_preset(env, &o.overlap_backfaces))
        o.overlap_backfaces = 0;
    if (o.no_overlap_backfaces && o.overlap_backfaces && !cli_from_preset(env, &o.overlap_backfaces))
        return cli_usage_error(env, "--overlap-backfaces and --no-overlap-backfaces exclude each other");
    if (o.no_overlap_backfaces)
        o.overlap_backfaces = 0;
    if ((o.dps_input || type.kind == ASP_FILE_MESH) && cli_from_preset(env, &o.r.renderer))
        o.r.renderer = NULL;
    if (parse_options(env, &o))
        return 2;
    if (type.kind == ASP_FILE_SCENE)
        return render_instance_scene(argv[0], &o, env);
    if (o.hybrid_points)
        o.r.hybrid = 1;
    if (o.r.hybrid && !o.dps_input)
        return cli_usage_error(env, "--hybrid needs a .dps input (amgsplat build makes one)");
    o.mesh_input = type.kind == ASP_FILE_MESH;
    // issue 28: a streamed .hier is drawn from the points of its cut, like a point file
    int streamed = type.kind == ASP_FILE_HIER && asp_ooc_probe(argv[0]) == 1;
    size_t memory = 0;
    if (o.memory && !streamed)
        return cli_usage_error(env, "--memory applies to a streamed .hier (amgsplat convert IN -o OUT.hier), not '%s'",
                               argv[0]);
    if (o.memory && cli_memory_option(env, o.memory, &memory))
        return 2;
    if (o.r.color_field && (o.mesh_input || type.kind == ASP_FILE_HIER))
        return cli_usage_error(env, "%s %s colours a point file's points (PLY, XYZ, LAS), not a %s", o.r.color_by_name,
                               o.r.color_field, o.mesh_input ? "mesh" : ".hier");
    if ((o.flat || o.r.texture) && !o.mesh_input)
        return cli_usage_error(env, "--flat and --texture need a mesh input (OBJ, PLY with faces, OFF, STL, glTF, 3DS)");
    asp_error err = {0, ""};
    const asp_renderer_kind *kind = NULL;
    if (o.dps_input && o.r.renderer && asp_renderer_kind_find(o.r.renderer, ASP_RENDER_INPUT_PRIMS, &kind, NULL))
        return cli_usage_error(env, "--renderer is for point inputs; a .dps input is drawn with --method, or with "
                                    "its levels mixed by view with --renderer cut");
    // a .hier is a hierarchy without its points: the splats draw it
    const char *dflt = streamed ? "disc" : type.kind == ASP_FILE_HIER ? "splat" : o.mesh_input ? "mesh" : "disc";
    unsigned inputs = o.dps_input    ? (unsigned)ASP_RENDER_INPUT_PRIMS
                      : o.mesh_input ? (unsigned)(ASP_RENDER_INPUT_MESH | ASP_RENDER_INPUT_POINTS)
                                     : (unsigned)ASP_RENDER_INPUT_POINTS;
    if (asp_renderer_kind_find(o.r.hybrid ? "hybrid" : o.dps_input ? (o.r.renderer ? o.r.renderer : "prim") : o.r.renderer ? o.r.renderer : dflt, inputs, &kind, &err))
        return cli_usage_error(env, "%s", err.msg);
    // a PLY with faces holds its vertices as points; other meshes hold triangles only
    if (o.mesh_input && !(kind->inputs & ASP_RENDER_INPUT_MESH) && strcmp(type.format, "ply") != 0)
        return cli_usage_error(env, "renderer '%s' draws points; sample the mesh to points first (amgsplat sample "
                                    "'%s' -o points.ply) or draw it with --renderer mesh",
                               kind->name, argv[0]);
    if ((o.r.edl || !isnan(o.r.edl_strength)) && strcmp(kind->name, "disc") != 0 && strcmp(kind->name, "square") != 0)
        return cli_usage_error(env, "--edl and --edl-strength need --renderer disc or square (points drawn opaque)");
    if ((o.r.depth_limit || o.r.cull_backfaces) && !kind->has_lod)
        return cli_usage_error(env, "--depth-limit and --cull-backfaces need --renderer splat or square");
    if (o.r.budget && !kind->has_lod)
        return cli_usage_error(env, "--budget needs --renderer splat or square (the %s renderer draws every %s)",
                               kind->name, o.dps_input ? "primitive" : "point");
    if (o.r.frame_ms > 0 && o.r.budget)
        return cli_usage_error(env, "--frame-ms sets the tolerance every frame: give no --budget");
    asp_frame_budget frame_budget;
    int no_lod = 0; // --frame-ms on a renderer without a level of detail: a usage error, found once it exists

    double t0 = asp_time_now();
    asp_scene s;
    memset(&s, 0, sizeof s);
    asp_gl_context *gl = NULL;
    asp_renderer *r = NULL;
    asp_image tiles[MAX_VIEWS];
    asp_image sheet = {0, 0, NULL};
    memset(tiles, 0, sizeof tiles);
    struct view_stats vs = {0, 0, 0, 0, NULL, {0}, NULL};
    asp_renderer_options ropts;
    renderer_options(&o, &ropts);
    asp_render_source src;
    struct cli_streamed_stats sst = {0};
    int rc = streamed ? cli_render_streamed(argv[0],
                                            &(struct cli_streamed_view){.views = o.views, .az = o.az, .el = o.el,
                                                                        .dist = o.dist, .fov = o.fov,
                                                                        .tau = o.r.tolerance > 0 ? o.r.tolerance : 1.0,
                                                                        .up = o.up_axis, .up_given = o.up != NULL,
                                                                        .width = o.width,
                                                                        .height = o.height, .memory = memory},
                                            &env->ctx, &s, &sst, &err)
                      : load_scene(argv[0], &o, env, &s, &err);
    if (!rc)
        warn_missing_textures(&s);
    // the file's up axis unless --up says otherwise: z for LAS (ASPRS LAS 1.4: Z is the elevation of its
    // CRS) and the .amg/.dps/.hier made from it, which record it (asp_frame.up)
    if (!rc && !o.up)
        o.up_axis = s.frame.up;
    // --color-by a scalar field: the library colours the points (elevation along the shown up axis)
    if (!rc && o.r.color_field && s.cloud && (rc = asp_cloud_color_by(s.cloud, o.r.color_field, o.up_axis, &err))) {
        if (rc == ASP_EINVAL) {
            asp_scene_release(&s);
            return cli_usage_error(env, "%s expects classifier, domains, strict or input (.amg), domain (.dps), or a "
                                        "point field: %s", o.r.color_by_name, err.msg);
        }
    }
    if (!rc && o.r.hybrid)
        rc = asp_scene_load_source_from(&s, o.hybrid_points, &err);
    if (!rc && s.dps && (rc = pick_domain_set(&o, &s, &ropts, &err)) != 0) {
        asp_error e = err;
        asp_error_set(&err, e.code, "'%s': %s", argv[0], e.msg);
    }
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, &env->ctx, &gl, &err);
    if (!rc) {
        asp_scene_render_source(&s, &src);
        edl_options(&o, &s, kind, env, argv[0], &ropts);
        rc = kind->create(gl, &src, &ropts, &env->ctx, &r, &err);
    }
    if (!rc && (o.prim.flags & ASP_PRIM_RENDER_DEBUG_TRIANGULATION))
        rc = debug_triangles(argv[0], &s, r, env, &err);
    if (!rc && o.r.budget)
        rc = asp_renderer_set_budget(r, o.r.budget, &err);
    if (!rc && o.r.depth_limit)
        rc = asp_renderer_set_lod(r, kind->has_lod ? ropts.splat.tolerance : 0.0f, (uint32_t)o.r.depth_limit, &err);
    if (!rc && o.r.frame_ms > 0) {
        rc = asp_frame_budget_init(&frame_budget, &(asp_frame_budget_desc){.target_ms = o.r.frame_ms}, &err);
        if (!rc && (rc = asp_frame_budget_apply(&frame_budget, r, &err)) == ASP_EUNSUPPORTED)
            no_lod = 1;
        vs.budget = &frame_budget;
    }
    if (!rc)
        rc = render_views(gl, r, &s, &o, env, tiles, &vs, &err);
    if (!rc && o.views > 1)
        rc = asp_image_contact_sheet(tiles, o.views, 0, &sheet, &err);
    const asp_image *result = o.views > 1 ? &sheet : &tiles[0];
    if (!rc)
        rc = asp_image_save_png(result, o.output, &err);
    double seconds = asp_time_now() - t0;
    int mesh_drawn = strcmp(kind->name, "mesh") == 0;
    size_t count = s.dps ? asp_scene_dps_level(&s)->prim_count
                   : mesh_drawn && s.mesh ? s.mesh->triangle_count
                   : s.cloud ? s.cloud->count : 0;
    int status = 0;
    if (no_lod) {
        status = cli_usage_error(env, "--frame-ms needs a renderer with a level of detail (splat, square): %s", err.msg);
    } else if (rc) {
        status = cli_fail(env, &err);
    } else {
        cli_progress_end(env);
        asp_hybrid_counts hc = {0};
        int hybrid = o.r.hybrid && asp_hybrid_renderer_counts(r, &hc, NULL) == 0;
        if (env->json)
            status = print_json(env, &o, count, &s, gl, kind->name, result, &vs, seconds, hybrid ? &hc : NULL);
        else
            cli_info(env,
                     "rendered %zu view%s of %zu %s (%s, %zu primitives in the last view, %.1f ms per view, %s) "
                     "to '%s' (%ux%u) in %.2f s\n",
                     o.views, o.views > 1 ? "s" : "", count,
                     o.dps_input ? "domain primitives" : mesh_drawn ? "triangles" : "points",
                     o.r.hybrid ? "hybrid" : o.dps_input ? asp_prim_render_method_name(o.prim.method) : kind->name,
                     vs.last_count,
                     1e3 * vs.seconds / (double)o.views, asp_gl_context_renderer(gl), o.output, result->width,
                     result->height, seconds);
        if (!env->json && streamed)
            cli_info(env, "streamed: %zu of %zu nodes, %llu of %llu points loaded in %.2f s (budget %llu points)",
                     sst.nodes, sst.node_count, (unsigned long long)sst.points, (unsigned long long)sst.point_count,
                     sst.load_seconds, (unsigned long long)sst.budget);
        if (!env->json && hybrid)
            cli_info(env, "hybrid: %zu of %zu primitives kept, %zu of %zu points drawn as splats (docs/hybrid.md)",
                     hc.prims_kept, hc.prims_kept + hc.prims_replaced, hc.points_drawn, hc.points_total);
        if (!env->json && vs.budget)
            cli_info(env, "frame budget %g ms%s: tau %g px, %zu primitives, median %.1f ms (p10 %.1f, p90 %.1f) over the "
                          "last frames of %zu\n", o.r.frame_ms,
                     !vs.settled.settled ? " (not settled)"
                     : vs.settled.held   ? ""
                     : frame_budget.finest ? " (full detail is faster)"
                                           : " (not held: the coarsest useful cut is slower)",
                     (double)vs.settled.tolerance, vs.settled.count, vs.settled.median_ms, vs.settled.p10_ms,
                     vs.settled.p90_ms, vs.settled.frames);
    }
    asp_image_release(&sheet);
    for (size_t i = 0; i < o.views; i++)
        asp_image_release(&tiles[i]);
    asp_renderer_destroy(r);
    asp_gl_context_destroy(gl);
    asp_scene_release(&s);
    return status;
}
