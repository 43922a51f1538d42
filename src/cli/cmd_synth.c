/*
 * amgsplat synth: synthetic point models with ground truth, e.g. the
 * 8-colour octahedron of Reniers & Telea 2006 Fig. 1 (labels = face id) and
 * the checkerboard plane of Pajarola et al. 2003.
 */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat synth octahedron|cube|sphere|torus|checker-plane|terrain -o OUT.ply [--points N] [--seed S]\n"
    "                      [--grid n] [--squares k] [--json]\n"
    "\n"
    "Writes a synthetic point model with exact normals, colours and radii that close all\n"
    "holes. octahedron (16000 points) and cube (24000) store the face id as the 'label'\n"
    "property; checker-plane is an n x n grid (512) on z = 0 with k x k squares (8).\n"
    "terrain (1000000 points, any number up to 10^10 and more) is a 1 km fractal landscape coloured by\n"
    "height, streamed to binary PLY (float xyz, uchar rgb; 15 bytes a point) with a working set of\n"
    "about 150 MB, for the out-of-core hierarchy (amgsplat convert IN.ply -o OUT.hier).";

/* The terrain never exists in memory: it goes to disk tile by tile (issue 28). */
static int synth_terrain(struct cli_env *env, const char *output, size_t points, size_t seed)
{
    asp_file_type type;
    if (asp_file_type_of_name(output, &type, NULL) != 0 || strcmp(type.format, "ply") != 0)
        return cli_usage_error(env, "terrain is written as binary PLY: expected -o OUT.ply, got '%s'", output);
    if (cli_check_output(env, output, NULL, 0, NULL, 0))
        return 2;
    if (!points)
        points = 1000000;
    asp_error err = {0};
    double t0 = asp_time_now();
    if (asp_synth_terrain_stream(output, points, seed, &env->ctx, &err))
        return cli_fail(env, &err);
    cli_progress_end(env);
    double s = asp_time_now() - t0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "shape", "terrain");
        cJSON_AddStringToObject(o, "output", output);
        cJSON_AddNumberToObject(o, "points", (double)points);
        cJSON_AddBoolToObject(o, "labels", 0);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.4f", s));
        return cli_json_print(env, o);
    } else if (!env->quiet) {
        printf("%s: terrain, %zu points (%.1f M points/s)\n", output, points, (double)points / s / 1e6);
    }
    return 0;
}

int cmd_synth(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL;
    size_t points = 0, seed = 0, grid = 512, squares = 8;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output point file (.ply, .xyz)"},
        {"points", 'n', CLI_SIZE, &points, "N", "number of points (default: per shape)"},
        {"seed", 's', CLI_SIZE, &seed, "S", "sequence seed (default 0)"},
        {"grid", 'g', CLI_SIZE, &grid, "n", "checker-plane: points per side (default 512)"},
        {"squares", 0, CLI_SIZE, &squares, "k", "checker-plane: squares per side (default 8)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one shape, got %d; see 'amgsplat synth -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o OUT.ply");
    if (strcmp(argv[0], "terrain") == 0)
        return synth_terrain(env, output, points, seed);
    asp_error err = {0};
    asp_synth_shape shape;
    if (asp_synth_shape_parse(argv[0], &shape, &err))
        return cli_usage_error(env, "%s", err.msg);
    if (cli_given(env, &points) && points == 0) // 0 would mean "the shape's default" (issue #31)
        return cli_usage_error(env, "--points expects at least 1, got 0");
    if (grid < 2 || grid > 65535)
        return cli_usage_error(env, "--grid must be 2 to 65535, got %zu", grid);
    if (squares < 1 || squares > grid)
        return cli_usage_error(env, "--squares must be 1 to the grid size, got %zu", squares);
    asp_synth_desc desc = {.points = points, .seed = seed, .grid = (uint32_t)grid, .squares = (uint32_t)squares};
    asp_cloud *cloud = NULL;
    double t0 = asp_time_now();
    if (asp_synth(shape, &desc, &env->ctx, &cloud, &err))
        return cli_fail(env, &err);
    rc = asp_cloud_save(cloud, output, NULL, &err);
    size_t count = cloud->count;
    int labels = cloud->labels != NULL;
    asp_cloud_destroy(cloud);
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "shape", asp_synth_shape_name(shape));
        cJSON_AddStringToObject(o, "output", output);
        cJSON_AddNumberToObject(o, "points", (double)count);
        cJSON_AddBoolToObject(o, "labels", labels);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.4f", asp_time_now() - t0));
        return cli_json_print(env, o);
    } else if (!env->quiet) {
        printf("%s: %s, %zu points%s\n", output, asp_synth_shape_name(shape), count, labels ? ", labels" : "");
    }
    return 0;
}
