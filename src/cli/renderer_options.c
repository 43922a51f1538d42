/*
 * The options that pick and steer a renderer, declared once for render, view and eval (issue 26;
 * STYLE.md 9b: one way to do each thing, as git has one parse-options for every builtin): their
 * names and old spellings, help lines and the checks that do not depend on the input.
 */
#include <math.h>
#include <string.h>

#include "cli/cli.h"
#include "util/banned.h"

void cli_renderer_opts_init(struct cli_renderer_opts *o)
{
    memset(o, 0, sizeof *o);
    o->tolerance = o->tau = o->alpha_ref = o->edl_strength = NAN;
}

void cli_renderer_rows(struct cli_renderer_opts *o, unsigned which, struct cli_option *rows, size_t cap)
{
    const struct {
        unsigned bit;
        struct cli_option row;
    } table[] = {
        {CLI_RO_RENDERER, {"renderer", 0, CLI_STRING, &o->renderer, "NAME", "how points are drawn: disc (default), splat, square, compute (compute shaders); meshes: mesh (default); .dps: prim (default), cut (levels mixed by view); in the viewer, h lists them"}},
        {CLI_RO_TOLERANCE, {"tolerance", 0, CLI_DOUBLE, &o->tolerance, "PX", "splat, square, cut: screen tolerance tau in pixels (render: default 1; view: 0; 0 = every point, finest level)"}},
        {CLI_RO_TOLERANCE, {"tau", 0, CLI_DOUBLE, &o->tau, "PX", "deprecated spelling of --tolerance"}},
        {CLI_RO_BUDGET, {"budget", 0, CLI_SIZE, &o->budget, "N", "splat, square: cut the hierarchy to N splats per view instead of a tolerance"}},
        {CLI_RO_COLOR_BY, {"color-by", 0, CLI_STRING, &o->color_by, "MODE", ".amg input: classifier, domains, strict or input (render: default input; view: classifier); .dps input (render): domain; point file: elevation, classification, intensity, return_number or any property (prop:NAME)"}},
        {CLI_RO_COLOR_BY, {"color", 0, CLI_STRING, &o->color, "MODE", "deprecated spelling of --color-by"}},
        {CLI_RO_LEVEL, {"level", 0, CLI_STRING, &o->level, "L", ".amg: level of the domain colours: L, L-2 or an index; .dps: level drawn (default the finest in the file)"}},
        {CLI_RO_METHOD, {"method", 0, CLI_STRING, &o->method, "NAME", ".dps: how primitives blend (default normalized; see docs/render-methods.md)"}},
        {CLI_RO_ALPHA_REF, {"alpha-ref", 0, CLI_DOUBLE, &o->alpha_ref, "X", ".dps: alpha test of the locks and the front layer, 0..1 (default 0.1)"}},
        {CLI_RO_CREASE, {"crease-angle", 0, CLI_STRING, &o->crease_angle, "DEG|off", "cut at creases sharper than DEG (default 60; off = as the seeds): .dps primitives; points with normals: discs, splats"}},
        {CLI_RO_HYBRID, {"hybrid", 0, CLI_FLAG, &o->hybrid, NULL, ".dps: the source points (seed 001 splats) where a primitive fails (docs/hybrid.md)"}},
        {CLI_RO_CULL, {"cull-backfaces", 0, CLI_FLAG, &o->cull_backfaces, NULL, "splat, square: drop subtrees whose normal cone faces away (seed 004 3.2.2)"}},
        {CLI_RO_DEPTH_LIMIT, {"depth-limit", 0, CLI_SIZE, &o->depth_limit, "N", "splat, square: traverse the hierarchy to depth N at most (seed 004 3.2.5; default 0: none)"}},
        {CLI_RO_FRAME_MS, {"frame-ms", 0, CLI_DOUBLE, &o->frame_ms, "T", "splat, square: frame budget: set tau (then the depth limit) so a frame takes T ms (0 = off)"}},
        {CLI_RO_UNLIT, {"unlit", 0, CLI_FLAG, &o->unlit, NULL, "colours as they are, no shading (the seeds' flat textured primitives; web viewer's light=off)"}},
        {CLI_RO_TEXTURE, {"texture", 0, CLI_STRING, &o->texture, "IMG", "mesh: texture of materials that name none or whose file is missing"}},
        {CLI_RO_EDL, {"edl", 0, CLI_FLAG, &o->edl, NULL, "disc, square: eye-dome lighting (default: on for points without normals, unless --unlit; in the viewer, E toggles)"}},
        {CLI_RO_EDL, {"no-edl", 0, CLI_FLAG, &o->no_edl, NULL, "disc, square: no eye-dome lighting"}},
        {CLI_RO_EDL, {"edl-strength", 0, CLI_DOUBLE, &o->edl_strength, "S", "eye-dome lighting strength, 0..100 (default 1; implies --edl)"}},
    };
    size_t n = 0;
    while (n < cap && rows[n].name)
        n++;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (table[i].bit & which) {
            ASP_ASSERT(n + 1 < cap);
            rows[n++] = table[i].row;
        }
    rows[n] = (struct cli_option){0};
}

/* "--a" or "--b", the spelling given; a usage error when both were. */
static int pick_spelling(const struct cli_env *env, int a_given, int b_given, const char *a, const char *b,
                         const char **name)
{
    if (a_given && b_given)
        return cli_usage_error(env, "%s and %s are the same option; give one", a, b);
    *name = b_given ? b : a;
    if (b_given) // one vocabulary across commands (issue 29): the old spelling still works, and says so
        cli_info(env, "amgsplat %s: %s is deprecated; use %s", env->cmd, b, a);
    return 0;
}

static int check_color(const struct cli_env *env, struct cli_renderer_opts *o)
{
    if (pick_spelling(env, o->color_by != NULL, o->color != NULL, "--color-by", "--color", &o->color_by_name))
        return 2;
    const char *v = o->color ? o->color : o->color_by;
    if (!v)
        return 0;
    // "domain" is render's .dps spelling, "domains" the .amg one: one mode, two spellings
    static const struct {
        const char *name;
        asp_scene_amg_color mode;
    } modes[] = {{"classifier", ASP_SCENE_AMG_CLASSIFIER}, {"domains", ASP_SCENE_AMG_DOMAINS},
                 {"domain", ASP_SCENE_AMG_DOMAINS},       {"strict", ASP_SCENE_AMG_STRICT},
                 {"input", ASP_SCENE_AMG_INPUT}};
    for (size_t i = 0; i < sizeof modes / sizeof modes[0]; i++)
        if (strcmp(v, modes[i].name) == 0) {
            o->color_by = v;
            o->color_mode = modes[i].mode;
            o->has_color = 1;
            return 0;
        }
    // any other name is a point file's scalar field, checked against the file once it is read
    o->color_field = v;
    return 0;
}

int cli_renderer_check(const struct cli_env *env, struct cli_renderer_opts *o, unsigned which)
{
    if ((which & CLI_RO_TOLERANCE) &&
        pick_spelling(env, !isnan(o->tolerance), !isnan(o->tau), "--tolerance", "--tau", &o->tolerance_name))
        return 2;
    if (!isnan(o->tau))
        o->tolerance = o->tau;
    // bounded: the renderers take floats, and 1e300 became "tolerance inf" (issue #13)
    if (!isnan(o->tolerance) && !(o->tolerance >= 0 && o->tolerance <= 1e6))
        return cli_usage_error(env, "%s expects pixels in 0..1e6, got %g", o->tolerance_name, o->tolerance);
    if ((which & CLI_RO_COLOR_BY) && check_color(env, o))
        return 2;
    asp_error err = {0, ""};
    if (o->method && asp_prim_render_method_parse(o->method, &o->method_kind, &err))
        return cli_usage_error(env, "--method: %s", err.msg);
    if (!isnan(o->alpha_ref)) {
        if (!(o->alpha_ref >= 0 && o->alpha_ref <= 1))
            return cli_usage_error(env, "--alpha-ref expects a number in 0..1, got %g", o->alpha_ref);
        o->alpha_ref_lib = o->alpha_ref > 0 ? (float)o->alpha_ref : -1.0f; // the library's "exactly 0"
    }
    if (o->crease_angle) {
        double deg = 0;
        if (strcmp(o->crease_angle, "off") == 0)
            o->crease = -1;
        else if (cli_parse_doubles(o->crease_angle, &deg, 1) == 1 && deg > 0 && deg < 180)
            o->crease = deg;
        else
            return cli_usage_error(env, "--crease-angle expects degrees in (0, 180) or 'off', got '%s'",
                                   o->crease_angle);
    }
    if (o->depth_limit > 64)
        return cli_usage_error(env, "--depth-limit expects 0..64, got %zu", o->depth_limit);
    if (!(o->frame_ms >= 0 && o->frame_ms <= 1e6))
        return cli_usage_error(env, "--frame-ms expects milliseconds in 0..1e6 (0 = off), got %g", o->frame_ms);
    if (o->no_edl && (o->edl || !isnan(o->edl_strength)))
        return cli_usage_error(env, "--no-edl excludes --edl and --edl-strength");
    if (!isnan(o->edl_strength) && !(o->edl_strength > 0 && o->edl_strength <= 100))
        return cli_usage_error(env, "--edl-strength expects a number in (0, 100], got %g", o->edl_strength);
    return 0;
}
