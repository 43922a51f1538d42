/*
 * amgsplat build: domain primitives (textured support rectangles) for one or
 * more AMG levels, written as a .dps file (journal section 3, thesis ch. 3).
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat build IN.amg|IN.ply -o OUT.dps [--level L-5 | --level L-6..L | --primitives 400]\n"
    "                      [--texel-size X] [--method affine|radial] [--shape linear|constant|gaussian]\n"
    "                      [--width W] [--normalise positive|ge1] [--merge] [--normals] [--atlas X.png]\n"
    "                      [--preset thesis|journal] [--domains thresholded|strict|both] [--enlarge PCT]\n"
    "                      [--normalise-color | --no-normalise-color] [--no-model-colors] [--brightness X] [--gpu]\n"
    "\n"
    "Turns every domain of the chosen AMG level(s) into one planar rectangle (weighted PCA of\n"
    "its points) with a texture: colour = the points' colours, alpha = the domain's basis\n"
    "function. A .ply input is decomposed first (as 'amgsplat decompose'). Levels: L is the\n"
    "coarsest, L-3 three levels finer, an index, a list 'L-5,L-3' or a range 'L-6..L'.\n"
    "--primitives N picks the level whose domain count is nearest N and names it on stderr;\n"
    "--merge then joins domains, so the count drops below that level's. Prints per level the\n"
    "thesis Table 5.2 columns: primitives, texels, error, normalised error, basis time (cb)\n"
    "and construction time (dpc).";

static int add_level(size_t *levels, size_t *n, size_t cap, size_t l)
{
    for (size_t i = 0; i < *n; i++)
        if (levels[i] == l)
            return 0;
    if (*n >= cap)
        return -1;
    levels[(*n)++] = l;
    return 0;
}

/* "L-5", "L-6..L", "2,L-1": every named level, at most cap. */
static int parse_levels(const asp_amg *amg, const char *text, size_t *levels, size_t *n, size_t cap, asp_error *err)
{
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return asp_error_set(err, ASP_EINVAL, "level list '%.32s...' is too long", text);
    snprintf(buf, sizeof buf, "%s", text);
    char *item = buf;
    while (item && *item) {
        char *comma = strchr(item, ',');
        if (comma)
            *comma = 0;
        char *dots = strstr(item, "..");
        size_t a = 0, b = 0;
        if (dots) {
            *dots = 0;
            int rc = asp_amg_level_parse(amg, item, &a, err);
            if (!rc)
                rc = asp_amg_level_parse(amg, dots + 2, &b, err);
            if (rc)
                return rc;
            if (a > b) {
                size_t t = a;
                a = b;
                b = t;
            }
        } else {
            int rc = asp_amg_level_parse(amg, item, &a, err);
            if (rc)
                return rc;
            b = a;
        }
        for (size_t l = a; l <= b; l++)
            if (add_level(levels, n, cap, l))
                return asp_error_set(err, ASP_EINVAL, "at most %zu levels per file", cap);
        item = comma ? comma + 1 : NULL;
    }
    if (*n == 0)
        return asp_error_set(err, ASP_EINVAL, "empty level list '%s'", text);
    return 0;
}

static void print_table(const asp_dps *dps, const asp_dps_summary *rows)
{
    printf("level  name   domains      primitives    texels        error  normalised   cb (s)  dpc (s)  skipped  degenerate\n");
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_summary *s = &rows[i];
        printf("%5u  %-5s  %-11s %11zu %9llu  %11.6g  %10.3f  %7.3f  %7.3f  %7u  %10u\n", s->level, s->name,
               dps->levels[i].strict ? "strict" : "thresholded", s->primitives,
               (unsigned long long)s->texels, s->error, s->error_norm, s->t_basis, s->t_construct, s->skipped,
               s->degenerate);
    }
}

/* What --primitives N chose (issue 29: the choice is reported, not silent); requested 0: not given. */
struct pick {
    size_t requested, level, domains;
    char name[24];
};

static void amg_level_name(const asp_amg *amg, size_t level, char name[24])
{
    size_t top = asp_amg_level_count(amg) - 1; // same names as asp_dps_level_name: L the coarsest
    if (level == top)
        snprintf(name, 24, "L");
    else
        snprintf(name, 24, "L-%zu", top - level);
}

static int print_json(const struct cli_env *env, const char *input, const char *output, const asp_dps *dps,
                      const asp_dps_summary *rows, double t_decompose, double t_total, int gpu, const struct pick *pick)
{
    cJSON *o = cJSON_CreateObject(), *levels = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "input", input);
    cJSON_AddStringToObject(o, "output", output);
    if (pick->requested) {
        cJSON *p = cJSON_AddObjectToObject(o, "primitives_pick");
        cJSON_AddNumberToObject(p, "requested", (double)pick->requested);
        cJSON_AddStringToObject(p, "level", pick->name);
        cJSON_AddNumberToObject(p, "domains", (double)pick->domains);
    }
    cJSON_AddNumberToObject(o, "points", (double)dps->source_points);
    cJSON_AddItemToObject(o, "mean_radius", cli_json_number("%.9g", dps->mean_radius));
    cJSON_AddStringToObject(o, "method", asp_prim_method_name(dps->desc.method));
    cJSON_AddItemToObject(o, "texel_size", cli_json_number("%g", dps->desc.texel_size));
    cJSON_AddBoolToObject(o, "gpu", gpu);
    cJSON_AddItemToObject(o, "decompose_seconds", cli_json_number("%.4f", t_decompose));
    cJSON_AddItemToObject(o, "total_seconds", cli_json_number("%.4f", t_total));
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_summary *s = &rows[i];
        cJSON *l = cJSON_CreateObject();
        cJSON_AddNumberToObject(l, "level", s->level);
        cJSON_AddStringToObject(l, "name", s->name);
        cJSON_AddStringToObject(l, "domains", dps->levels[i].strict ? "strict" : "thresholded");
        cJSON_AddNumberToObject(l, "primitives", (double)s->primitives);
        cJSON_AddNumberToObject(l, "texels", (double)s->texels);
        cJSON_AddItemToObject(l, "error", cli_json_number("%.9g", s->error));
        cJSON_AddItemToObject(l, "normalised_error", cli_json_number("%.6g", s->error_norm));
        cJSON_AddItemToObject(l, "cb_seconds", cli_json_number("%.4f", s->t_basis));
        cJSON_AddItemToObject(l, "dpc_seconds", cli_json_number("%.4f", s->t_construct));
        cJSON_AddNumberToObject(l, "skipped", s->skipped);
        cJSON_AddNumberToObject(l, "degenerate", s->degenerate);
        cJSON_AddNumberToObject(l, "capped", s->capped);
        cJSON_AddNumberToObject(l, "merges", s->merges);
        cJSON_AddItemToObject(l, "atlas", cJSON_CreateIntArray((const int[]){(int)s->atlas_width, (int)s->atlas_height}, 2));
        cJSON_AddNumberToObject(l, "neighbour_pairs", (double)s->neighbour_pairs);
        cJSON_AddItemToArray(levels, l);
    }
    cJSON_AddItemToObject(o, "levels", levels);
    return cli_json_print(env, o);
}

/* Atlas PNGs: X.png for one level, X-L-3.png for each of several. */
static int save_atlases(const char *path, const asp_dps *dps, const asp_dps_summary *rows, asp_error *err)
{
    asp_file_type t;
    int png = asp_file_type_of_name(path, &t, NULL) == 0 && strcmp(t.format, "png") == 0;
    for (size_t i = 0; i < dps->level_count; i++) {
        char name[4096];
        size_t n = strlen(path);
        const char *set = dps->levels[i].strict ? "-strict" : ""; // --domains both: one level in two sets
        if (dps->level_count == 1)
            snprintf(name, sizeof name, "%s", path);
        else if (png)
            snprintf(name, sizeof name, "%.*s-%s%s.png", (int)(n - 4), path, rows[i].name, set);
        else
            snprintf(name, sizeof name, "%s-%s%s.png", path, rows[i].name, set);
        int rc = asp_image_save_png(&dps->levels[i].atlas, name, err);
        if (rc)
            return rc;
    }
    return 0;
}

int cmd_build(int argc, char **argv, struct cli_env *env)
{
    const char *preset = NULL; /* applied by cli_parse */
    int norm_color = 0, no_norm_color = 0, no_colors = 0;
    double brightness = 0;
    const char *domain_set = "thresholded";
    const char *output = NULL, *level_text = NULL, *method = "affine", *shape = "linear", *norm = "positive";
    const char *atlas = NULL;
    size_t budget = SIZE_MAX, max_texture = 0, padding = 0; // SIZE_MAX: not given, so a given 0 is refused
    double texel = 0, width = 0, tau = 0, fraction = 0, flat = 0, angle = 0, enlarge = 0;
    int unweighted = 0, project = 0, no_extend = 0, normals = 0, merge = 0, gpu = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output primitives (.dps)"},
        {"preset", 0, CLI_STRING, &preset, "SEED", "the seed's options: thesis, journal (docs/seeds.md)"},
        {"level", 'l', CLI_STRING, &level_text, "L", "level(s): L, L-5, 3, 'L-5,L-3' or 'L-6..L' (default L-3)"},
        {"primitives", 'p', CLI_SIZE, &budget, "N", "the level with the domain count nearest N"},
        {"texel-size", 0, CLI_DOUBLE, &texel, "X", "texel edge in mean point radii (default 1)"},
        {"max-texture", 0, CLI_SIZE, &max_texture, "N", "cap on a texture's side in texels (default 512)"},
        {"method", 'm', CLI_STRING, &method, "M", "affine (default: Delaunay + barycentric) or radial"},
        {"shape", 0, CLI_STRING, &shape, "S", "radial shape: linear (default), constant, gaussian"},
        {"width", 'w', CLI_DOUBLE, &width, "W", "radial width factor (default 1)"},
        {"normalise", 0, CLI_STRING, &norm, "N", "radial: positive (f > 0, default) or ge1 (f >= 1)"},
        {"tau", 0, CLI_DOUBLE, &tau, "X", "domain threshold Psi > X (default 0.05)"},
        {"unweighted", 0, CLI_FLAG, &unweighted, NULL, "plain PCA instead of weighting by Psi"},
        {"project-radii", 0, CLI_FLAG, &project, NULL, "radius r |n_p . n| (thesis 3.1)"},
        {"no-extend-color", 0, CLI_FLAG, &no_extend, NULL, "leave uncovered texels black"},
        {"normals", 'n', CLI_FLAG, &normals, NULL, "also store a normal map per level"},
        {"neighbours", 0, CLI_DOUBLE, &fraction, "X", "neighbour threshold on shared points (default 0.05)"},
        {"merge", 0, CLI_FLAG, &merge, NULL, "merge flat, aligned, overlapping domains (thesis 3.4)"},
        {"merge-flatness", 0, CLI_DOUBLE, &flat, "X", "merge while l_min/sum l < X (default 0.01)"},
        {"merge-angle", 0, CLI_DOUBLE, &angle, "DEG", "and normals within DEG degrees (default 15)"},
        {"padding", 0, CLI_SIZE, &padding, "N", "atlas padding in texels (default 2)"},
        {"normalise-color", 0, CLI_FLAG, &norm_color, NULL, "radial: the --normalise criterion for colour too (thesis eq. 3.3 as written)"},
        {"no-normalise-color", 0, CLI_FLAG, &no_norm_color, NULL, "colour always divided by f (the default; turns off a preset's --normalise-color)"},
        {"no-model-colors", 0, CLI_FLAG, &no_colors, NULL, "grey points instead of the model's colours (thesis app. C)"},
        {"brightness", 0, CLI_DOUBLE, &brightness, "X", "add X (-1..1) to each point colour's HSV value (thesis app. C)"},
        {"domains", 0, CLI_STRING, &domain_set, "SET", "thresholded (default, Psi > tau), strict (thesis eq. 2.5; drawn with --method no-blend) or both (render/view --domains picks)"},
        {"enlarge", 0, CLI_DOUBLE, &enlarge, "PCT", "grow the points' rectangle by PCT % (thesis app. C; default: one footprint margin)"},
        {"gpu", 0, CLI_FLAG, &gpu, NULL, "fill the textures with a GL 4.5 compute shader (thesis 3.6; not with --normals)"},
        {"atlas", 0, CLI_STRING, &atlas, "X.png", "also write each level's atlas as PNG"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat build -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o OUT.dps");
    if (level_text && budget != SIZE_MAX && cli_from_preset(env, &level_text))
        level_text = NULL; /* --primitives given by hand wins over the preset's level */
    if (level_text && budget != SIZE_MAX)
        return cli_usage_error(env, "--level and --primitives exclude each other");
    if (budget == 0 || (budget != SIZE_MAX && budget > UINT32_MAX))
        return cli_usage_error(env, "--primitives expects 1..4294967295, got %zu", budget);
    {
        const char *const inputs[] = {argv[0], atlas};
        if (cli_check_output(env, output, "dps", 0, inputs, 2) || cli_check_output(env, atlas, "png", 1, inputs, 1))
            return 2;
    }
    if (max_texture > 8192 || padding > 64)
        return cli_usage_error(env, "--max-texture must be at most 8192 and --padding at most 64");
    if (!(brightness >= -1 && brightness <= 1))
        return cli_usage_error(env, "--brightness expects -1..1, got %g", brightness);
    static const char *const sets[] = {"thresholded", "strict", "both"}; // asp_prim_domain_set order
    int set = -1;
    for (int i = 0; i < 3; i++)
        if (strcmp(domain_set, sets[i]) == 0)
            set = i;
    if (set < 0)
        return cli_usage_error(env, "--domains expects thresholded, strict or both, got '%s'", domain_set);
    // a preset's flag can be switched off by hand (issue 17); both by hand contradict each other
    if (no_norm_color && norm_color && !cli_from_preset(env, &norm_color))
        return cli_usage_error(env, "--normalise-color and --no-normalise-color exclude each other");
    if (no_norm_color)
        norm_color = 0;
    if (!(enlarge >= 0 && enlarge <= 1000))
        return cli_usage_error(env, "--enlarge expects a percentage in 0..1000, got %g", enlarge);
    asp_error err = {0};
    asp_prim_desc desc = {.tau = tau, .texel_size = texel, .max_texture = (uint32_t)max_texture, .width = width,
                          .unweighted = unweighted, .project_radii = project, .no_extend_color = no_extend,
                          .normal_map = normals, .neighbour_fraction = fraction, .merge = merge,
                          .merge_flatness = flat, .merge_angle = angle, .padding = (uint32_t)padding,
                          .enlarge = enlarge, .normalise_color = norm_color,
                          .strict = set, .no_model_colors = no_colors,
                          .brightness = brightness};
    if (asp_prim_method_parse(method, &desc.method, &err) || asp_prim_shape_parse(shape, &desc.shape, &err) ||
        asp_prim_normalise_parse(norm, &desc.normalise, &err))
        return cli_usage_error(env, "%s", err.msg);
    if (texel < 0 || width < 0 || tau < 0 || fraction < 0 || flat < 0 || angle < 0)
        return cli_usage_error(env, "--%s must not be negative, got %g",
                               texel < 0   ? "texel-size"
                               : width < 0 ? "width"
                               : tau < 0   ? "tau"
                               : fraction < 0 ? "neighbours"
                               : flat < 0     ? "merge-flatness"
                                              : "merge-angle",
                               texel < 0 ? texel : width < 0 ? width : tau < 0 ? tau : fraction < 0 ? fraction : flat < 0 ? flat : angle);

#ifndef ASP_HAVE_GL
    if (gpu)
        return cli_usage_error(env, "--gpu needs OpenGL 4.5, and this amgsplat was built without it (ASP_WITH_GL=OFF)");
#endif
    if (gpu && normals)
        return cli_usage_error(env, "--gpu makes no normal maps: leave out --normals or --gpu");
    double t0 = asp_time_now(), t_dec = 0;
    asp_amg *amg = NULL;
    asp_cloud *cloud = NULL;
    asp_file_type type;
    rc = asp_file_recognise(argv[0], &type, &err);
    if (!rc && type.kind == ASP_FILE_AMG) {
        rc = asp_amg_load(argv[0], &env->ctx, &amg, &err);
    } else if (!rc) {
        /* asp_cloud_load names what anything else is (a mesh: "sample it to points first") */
        rc = asp_cloud_load(argv[0], &env->ctx, &cloud, &err);
        if (!rc)
            rc = asp_amg_decompose(cloud, NULL, &env->ctx, &amg, &err);
        t_dec = asp_time_now() - t0;
    }
    size_t levels[64], nlevels = 0;
    struct pick pick = {0};
    if (!rc && budget != SIZE_MAX && (rc = asp_prim_level_nearest(amg, budget, &levels[nlevels++], &err)) == 0) {
        size_t l = levels[0], nl = asp_amg_level_count(amg);
        pick = (struct pick){.requested = budget, .level = l, .domains = asp_amg_level_size(amg, l)};
        amg_level_name(amg, l, pick.name);
        // the neighbour on the other side of N, so the user sees what the other choice would have been
        size_t other = pick.domains > budget ? (l + 1 < nl ? l + 1 : l) : (l > 0 ? l - 1 : l);
        char oname[24];
        amg_level_name(amg, other, oname);
        if (other != l)
            cli_info(env, "build: --primitives %zu: level %s with %zu domains is the nearest (%s: %zu)", budget,
                     pick.name, pick.domains, oname, asp_amg_level_size(amg, other));
        else
            cli_info(env, "build: --primitives %zu: level %s with %zu domains is the nearest", budget, pick.name,
                     pick.domains);
    }
    else if (!rc)
        rc = parse_levels(amg, level_text ? level_text : "L-3", levels, &nlevels, 64, &err);
    asp_dps *dps = NULL;
#ifdef ASP_HAVE_GL
    asp_gl_context *gl = NULL;
    if (!rc && gpu && (rc = asp_gl_context_create_headless(NULL, &env->ctx, &gl, &err)) == 0) {
        asp_prim_gpu_fill_set(&desc, gl); // thesis 3.6: the fills on the graphics hardware
    }
#endif
    if (!rc)
        rc = asp_prim_build(amg, cloud, levels, nlevels, &desc, argv[0], &env->ctx, &dps, &err);
    // the .dps and its atlases appear all or none (issue #13): a failed atlas leaves the old .dps as it was
    asp_output_batch_begin(NULL);
    if (!rc)
        rc = asp_dps_save(dps, output, &err);
    asp_dps_summary rows[64];
    if (!rc)
        asp_dps_summarize(dps, rows, 64);
    if (!rc && atlas)
        rc = save_atlases(atlas, dps, rows, &err);
    if (rc)
        asp_output_batch_abort();
    else
        rc = asp_output_batch_commit(&err);
    double t_total = asp_time_now() - t0;
#ifdef ASP_HAVE_GL
    asp_gl_context_destroy(gl);
#endif
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
    cli_progress_end(env);
    if (rc) {
        asp_dps_destroy(dps);
        return cli_fail(env, &err);
    }
    for (size_t i = 0; i < dps->level_count; i++)
        if (rows[i].capped)
            cli_info(env, "warning: level %s: %u of %zu textures reached --max-texture %u; their texels are larger",
                     rows[i].name, rows[i].capped, rows[i].primitives, dps->desc.max_texture);
    if (pick.requested && merge && rows[0].primitives != pick.domains)
        cli_info(env, "build: --merge joined the %zu domains of %s into %zu primitives; --primitives %zu picks the "
                 "level before merging", pick.domains, pick.name, rows[0].primitives, pick.requested);
    int status = 0;
    if (env->json) {
        status = print_json(env, argv[0], output, dps, rows, t_dec, t_total, gpu, &pick);
    } else {
        if (!env->quiet)
            printf("%s: %llu points, %zu level(s), mean radius %.4g, %s textures, texel size %g%s, %.2f s\n", output,
                   (unsigned long long)dps->source_points, dps->level_count, dps->mean_radius,
                   asp_prim_method_name(dps->desc.method), dps->desc.texel_size,
                   t_dec > 0 ? " (decomposition included)" : "", t_total);
        print_table(dps, rows);
    }
    asp_dps_destroy(dps);
    return status;
}
