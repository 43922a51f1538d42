/*
 * amgsplat export: domain primitives (.dps), point sets and hierarchies (.hier) as glTF 2.0
 * (asp_gltf_export_*, include/amgsplat/export.h), for engines, the web page in web/ and other
 * viewers. docs/cli/export.md.
 */
static const char usage[] =
    "usage: amgsplat export IN -o OUT.glb|OUT.gltf [--level L[,L...]|all] [--alpha-mode blend|mask]\n"
    "                       [--alpha-cutoff X] [--lit] [--no-normal-map] [--no-splats] [--plain]\n"
    "                       [--splat-codec meshopt|spz] [--json]\n"
    "       amgsplat export IN -o DIR --tiles [--tile-points N] [--memory SIZE] [--no-splats] [--plain]\n"
    "                       [--splat-codec meshopt|spz]\n"
    "\n"
    "Writes glTF 2.0: one binary .glb, or a .gltf with OUT.bin and OUT_<image>.png beside it.\n"
    "A .dps becomes one textured quad per domain primitive (its support rectangle, as amgsplat\n"
    "render draws it), the atlas as PNG in baseColorTexture, alpha blended (or masked), double-\n"
    "sided, unlit (KHR_materials_unlit) unless --lit, the normal map as normalTexture; each level\n"
    "a node and a scene named by level. A point set (.ply, .xyz, ...) or .hier becomes POINTS with\n"
    "POSITION, NORMAL, COLOR_0 and seed 001's splat ellipses as KHR_gaussian_splatting Gaussians,\n"
    "quantised (KHR_mesh_quantization) and compressed (EXT_meshopt_compression) unless --plain.\n"
    "--splat-codec spz writes the splats as one SPZ stream (KHR_gaussian_splatting_compression_spz_2),\n"
    "what CesiumJS draws as Gaussian splats.\n"
    "Positions are relative to the model's origin, kept in the node translation.\n"
    "--tiles writes a point set or .hier as a streamed 3D Tiles 1.1 tileset: DIR/tileset.json and\n"
    "one GLB a tile under DIR/tiles/ (docs/web.md). A point file is converted first to a streamed\n"
    "hierarchy (as amgsplat convert, within --memory) and tiled node by node, refine ADD, in bounded\n"
    "memory; a streamed .hier likewise; an in-memory .hier keeps its elliptical splats (REPLACE).";

#include <stdio.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

struct export_opts {
    const char *output, *level, *alpha_mode, *memory, *splat_codec;
    double alpha_cutoff;
    int lit, no_normal_map, no_splats, plain, tiles;
    size_t tile_points;
};

/* cmd_export_tiles.c: --tiles (asp_tiles_export_ooc, asp_tiles_export_hier, asp_tiles_export_dps) */
int export_tiles(struct cli_env *env, const char *in, asp_file_kind kind, const char *dir, size_t tile_points,
                 const char *memory, const asp_gltf_desc *gd);

/* --level "L-6,L" or "all" into indices of dps->levels; returns the count, 0 on error (printed). */
static int parse_levels(struct cli_env *env, const asp_dps *dps, const char *path, const char *text, size_t *out,
                        size_t *count)
{
    *count = 0;
    if (!text || strcmp(text, "all") == 0) {
        for (size_t i = 0; i < dps->level_count; i++)
            out[(*count)++] = i;
        return 0;
    }
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return cli_usage_error(env, "--level list is too long");
    memcpy(buf, text, strlen(text) + 1);
    char *s = buf;
    while (s) {
        char *comma = strchr(s, ',');
        if (comma)
            *comma = '\0';
        asp_error err = {0};
        size_t index = 0;
        if (asp_dps_level_parse(dps, s, &index, &err)) {
            fprintf(stderr, "amgsplat export: error: '%s': %s\n", path, err.msg);
            return 1;
        }
        for (size_t i = 0; i < *count; i++)
            if (out[i] == index)
                return cli_usage_error(env, "--level names level '%s' twice", s);
        if (*count >= dps->level_count)
            return cli_usage_error(env, "--level lists more levels than '%s' holds", path);
        out[(*count)++] = index;
        s = comma ? comma + 1 : NULL;
    }
    return 0;
}

static int print_result(const struct cli_env *env, const char *in, const char *out, const char *kind,
                         const asp_gltf_stats *st, const asp_gltf_desc *d)
{
    if (env->json) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "input", in);
        cJSON_AddStringToObject(j, "output", out);
        cJSON_AddStringToObject(j, "kind", kind);
        cJSON_AddStringToObject(j, "format", asp_file_name_is(out, "gltf") ? "gltf" : "glb");
        cJSON_AddNumberToObject(j, "nodes", (double)st->nodes);
        cJSON_AddNumberToObject(j, "primitives", (double)st->primitives);
        cJSON_AddNumberToObject(j, "points", (double)st->points);
        cJSON_AddNumberToObject(j, "images", (double)st->images);
        cJSON_AddNumberToObject(j, "json_bytes", (double)st->json_bytes);
        cJSON_AddNumberToObject(j, "bin_bytes", (double)st->bin_bytes);
        cJSON_AddNumberToObject(j, "bytes", (double)st->file_bytes);
        cJSON_AddNumberToObject(j, "files", (double)st->files);
        cJSON *o = cJSON_AddArrayToObject(j, "origin");
        for (int k = 0; k < 3; k++)
            cJSON_AddItemToArray(o, cJSON_CreateNumber(st->origin[k]));
        if (st->primitives) {
            cJSON_AddStringToObject(j, "alpha_mode", d->alpha_mode == ASP_GLTF_ALPHA_MASK ? "mask" : "blend");
            cJSON_AddBoolToObject(j, "unlit", !(d->flags & ASP_GLTF_LIT));
        } else {
            cJSON_AddBoolToObject(j, "gaussian_splats", !(d->flags & ASP_GLTF_NO_SPLATS));
            cJSON_AddBoolToObject(j, "compressed", !(d->flags & ASP_GLTF_PLAIN));
            if (!(d->flags & (ASP_GLTF_PLAIN | ASP_GLTF_NO_SPLATS)))
                cJSON_AddStringToObject(j, "splat_codec", (d->flags & ASP_GLTF_SPZ) ? "spz" : "meshopt");
        }
        return cli_json_print(env, j);
    }
    if (!env->quiet) {
        if (st->primitives)
            printf("exported '%s' -> '%s': %zu level%s, %zu primitives, %zu images, %zu bytes in %zu file%s\n", in, out,
                   st->nodes, st->nodes == 1 ? "" : "s", st->primitives, st->images, st->file_bytes, st->files,
                   st->files == 1 ? "" : "s");
        else
            printf("exported '%s' -> '%s': %zu points%s, %zu bytes in %zu file%s\n", in, out, st->points,
                   (d->flags & ASP_GLTF_NO_SPLATS) ? "" : " with Gaussian splats", st->file_bytes, st->files,
                   st->files == 1 ? "" : "s");
        printf("origin %.17g %.17g %.17g (the node translation)\n", st->origin[0], st->origin[1], st->origin[2]);
    }
    return 0;
}

static int check_options(struct cli_env *env, const struct export_opts *o, asp_gltf_desc *d)
{
    if (!o->output)
        return cli_usage_error(env, "missing -o OUT.glb or OUT.gltf");
    if (!o->tiles && !asp_file_name_is(o->output, "glb") && !asp_file_name_is(o->output, "gltf"))
        return cli_usage_error(env, "output '%s' must end in .glb or .gltf", o->output);
    if (o->alpha_mode) {
        if (strcmp(o->alpha_mode, "blend") == 0)
            d->alpha_mode = ASP_GLTF_ALPHA_BLEND;
        else if (strcmp(o->alpha_mode, "mask") == 0)
            d->alpha_mode = ASP_GLTF_ALPHA_MASK;
        else
            return cli_usage_error(env, "--alpha-mode expects blend or mask, got '%s'", o->alpha_mode);
    }
    if ((o->alpha_cutoff != 0 || cli_given(env, &o->alpha_cutoff)) && !(o->alpha_cutoff > 0 && o->alpha_cutoff < 1))
        return cli_usage_error(env, "--alpha-cutoff expects a value in (0, 1), got %g", o->alpha_cutoff);
    if (o->alpha_cutoff != 0 && d->alpha_mode != ASP_GLTF_ALPHA_MASK)
        return cli_usage_error(env, "--alpha-cutoff needs --alpha-mode mask");
    d->alpha_cutoff = (float)o->alpha_cutoff;
    d->flags = (o->lit ? ASP_GLTF_LIT : 0u) | (o->no_normal_map ? ASP_GLTF_NO_NORMAL_MAP : 0u) |
               (o->no_splats ? ASP_GLTF_NO_SPLATS : 0u) | (o->plain ? ASP_GLTF_PLAIN : 0u);
    if (o->splat_codec && strcmp(o->splat_codec, "spz") == 0) {
        if (o->plain || o->no_splats)
            return cli_usage_error(env, "--splat-codec spz writes compressed splats: not with %s",
                                   o->plain ? "--plain" : "--no-splats");
        d->flags |= ASP_GLTF_SPZ;
    } else if (o->splat_codec && strcmp(o->splat_codec, "meshopt") != 0)
        return cli_usage_error(env, "--splat-codec expects meshopt or spz, got '%s'", o->splat_codec);
    return 0;
}

static int export_dps(struct cli_env *env, const char *in, const struct export_opts *o, asp_gltf_desc *d)
{
    asp_error err = {0};
    asp_dps *dps = NULL;
    if (asp_dps_load(in, &env->ctx, &dps, &err))
        return cli_fail(env, &err);
    size_t levels[64], count = 0;
    size_t *list = dps->level_count <= 64 ? levels : NULL;
    int rc = list ? parse_levels(env, dps, in, o->level, list, &count) : 0;
    if (!list)
        rc = cli_usage_error(env, "'%s' holds %zu levels, more than export handles (64)", in, dps->level_count);
    if (rc) {
        asp_dps_destroy(dps);
        return rc;
    }
    d->levels = list;
    d->level_count = count;
    asp_gltf_stats st = {0};
    if (asp_gltf_export_dps(dps, o->output, d, &st, &err)) {
        asp_dps_destroy(dps);
        return cli_fail(env, &err);
    }
    asp_dps_destroy(dps);
    cli_progress_end(env);
    return print_result(env, in, o->output, "primitives", &st, d);
}

static int export_points(struct cli_env *env, const char *in, int hier_file, const struct export_opts *o,
                         const asp_gltf_desc *d)
{
    asp_error err = {0};
    asp_gltf_stats st = {0};
    int rc;
    if (hier_file) {
        asp_hier *h = NULL;
        rc = asp_hier_load(in, &env->ctx, &h, &err);
        if (!rc)
            rc = asp_gltf_export_hier(h, o->output, d, &st, &err);
        asp_hier_destroy(h);
    } else {
        asp_cloud *c = NULL;
        rc = asp_cloud_load(in, &env->ctx, &c, &err);
        if (!rc)
            rc = asp_gltf_export_cloud(c, o->output, d, &env->ctx, &st, &err);
        asp_cloud_destroy(c);
    }
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    return print_result(env, in, o->output, "points", &st, d);
}

int cmd_export(int argc, char **argv, struct cli_env *env)
{
    struct export_opts o = {0};
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &o.output, "OUT", "output: .glb (one binary file) or .gltf (+ .bin + .png files)"},
        {"level", 0, CLI_STRING, &o.level, "L[,L..]", ".dps: levels to export, e.g. L-6,L, or all (default all)"},
        {"alpha-mode", 0, CLI_STRING, &o.alpha_mode, "MODE", ".dps: blend (default) or mask"},
        {"alpha-cutoff", 0, CLI_DOUBLE, &o.alpha_cutoff, "X", ".dps, mask: cutoff in (0, 1) (default 0.1, the alpha reference of render)"},
        {"lit", 0, CLI_FLAG, &o.lit, NULL, ".dps: PBR material (lit by the viewer) instead of KHR_materials_unlit"},
        {"no-normal-map", 0, CLI_FLAG, &o.no_normal_map, NULL, ".dps: leave the normal map out"},
        {"no-splats", 0, CLI_FLAG, &o.no_splats, NULL, "points: plain POINTS without the KHR_gaussian_splatting ellipses"},
        {"plain", 0, CLI_FLAG, &o.plain, NULL, "points: float attributes, uncompressed, in input order (default: "
                                                "quantised, meshopt-compressed)"},
        {"splat-codec", 0, CLI_STRING, &o.splat_codec, "C", "points: meshopt (default) or spz (KHR_gaussian_"
                                                               "splatting_compression_spz_2, what CesiumJS draws)"},
        {"tiles", 0, CLI_FLAG, &o.tiles, NULL, "points: a 3D Tiles 1.1 tileset in directory OUT (tileset.json, tiles/*.glb)"},
        {"tile-points", 0, CLI_SIZE, &o.tile_points, "N", "--tiles: most splats in a tile (default 32768; a point "
                                                           "file: most points in a leaf node)"},
        {"memory", 0, CLI_STRING, &o.memory, "SIZE", "--tiles, point file: working set of the conversion, e.g. 512M "
                                                      "(default 2G)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat export -h'", npos);
    const char *in = argv[0];
    asp_gltf_desc d = {0};
    rc = check_options(env, &o, &d);
    if (rc)
        return rc;
    const char *inputs[1] = {in};
    if (!o.tiles && cli_check_output(env, o.output, asp_file_name_is(o.output, "glb") ? "glb" : "gltf", 0, inputs, 1))
        return 2;
    asp_error err = {0};
    asp_file_type type;
    if (asp_file_recognise(in, &type, &err))
        return cli_fail(env, &err);
    int is_dps = type.kind == ASP_FILE_DPS;
    if (!is_dps && type.kind != ASP_FILE_POINTS && type.kind != ASP_FILE_HIER)
        return cli_usage_error(env, "'%s' is %s; export takes a .dps, a point file or a .hier", in,
                               type.kind == ASP_FILE_AMG ? "an .amg decomposition (build a .dps from it first)"
                                                         : "not one of those");
    if (!is_dps && (o.level || o.alpha_mode || o.alpha_cutoff != 0 || o.lit || o.no_normal_map))
        return cli_usage_error(env, "--level, --alpha-mode, --alpha-cutoff, --lit and --no-normal-map are for .dps "
                                    "inputs");
    if (is_dps && o.no_splats)
        return cli_usage_error(env, "--no-splats is for point inputs");
    if (is_dps && o.splat_codec)
        return cli_usage_error(env, "--splat-codec is for point inputs");
    if (is_dps && o.plain)
        return cli_usage_error(env, "--plain is for point inputs (primitive levels are always written plain)");
    if ((o.tile_points || o.memory) && !o.tiles)
        return cli_usage_error(env, "%s needs --tiles", o.tile_points ? "--tile-points" : "--memory");
    if (o.tiles && is_dps && o.level)
        return cli_usage_error(env, "--level: a .dps tileset holds every level, one tile each (coarse first)");
    if (o.tiles && is_dps && (o.tile_points || o.memory))
        return cli_usage_error(env, "%s: the tiles of a .dps are its levels", o.tile_points ? "--tile-points" : "--memory");
    if (o.tiles)
        return export_tiles(env, in, type.kind, o.output, o.tile_points, o.memory, &d);
    return is_dps ? export_dps(env, in, &o, &d) : export_points(env, in, type.kind == ASP_FILE_HIER, &o, &d);
}
