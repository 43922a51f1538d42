/*
 * amgsplat estimate: adds PCA normals (consistently oriented by an MST of the
 * k-NN graph, Hoppe et al. 1992, or towards a viewpoint) and splat radii to a
 * raw scan, through asp_cloud_estimate.
 */
#include <stdio.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat estimate IN -o OUT [--k 16] [--normals] [--radii] [--force]\n"
    "                         [--orient-to x,y,z | --keep-orientation] [--radius-k 16]\n"
    "                         [--radius-factor 1] [--json]\n"
    "\n"
    "Estimates the normals and/or splat radii a point file lacks (both when neither\n"
    "--normals nor --radii is given) and writes the result. Normals come from PCA of\n"
    "each point's k nearest neighbours, oriented consistently along a minimum spanning\n"
    "tree (outwards on closed surfaces) or towards a viewpoint; radii are the distance\n"
    "to the 16th nearest neighbour, which leaves no holes on uniformly sampled surfaces.";

int cmd_estimate(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *orient_to = NULL;
    size_t k = 16, radius_k = 16;
    double radius_factor = 1.0;
    int normals = 0, radii = 0, force = 0, keep = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output point file (.ply, .xyz)"},
        {"k", 'k', CLI_SIZE, &k, "N", "neighbours for normal estimation (default 16)"},
        {"normals", 0, CLI_FLAG, &normals, NULL, "estimate normals"},
        {"radii", 0, CLI_FLAG, &radii, NULL, "estimate radii"},
        {"force", 'f', CLI_FLAG, &force, NULL, "recompute attributes the input already has"},
        {"orient-to", 0, CLI_STRING, &orient_to, "x,y,z", "turn normals towards this world point"},
        {"keep-orientation", 0, CLI_FLAG, &keep, NULL, "with --force: keep the signs of the input normals"},
        {"radius-k", 0, CLI_SIZE, &radius_k, "N", "radius = distance to the N-th neighbour (default 16)"},
        {"radius-factor", 0, CLI_DOUBLE, &radius_factor, "X", "radius multiplier (default 1)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat estimate -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o OUT");
    if (cli_check_output(env, output, NULL, 0, (const char *const[]){argv[0]}, 1))
        return 2;
    // 1024: the k-NN graph takes n k entries; the neighbourhoods a tangent plane needs are tens
    if (k < 1 || k > 1024)
        return cli_usage_error(env, "--k expects 1..1024, got %zu", k);
    if (radius_k < 1 || radius_k > 1024)
        return cli_usage_error(env, "--radius-k expects 1..1024, got %zu", radius_k);
    if (!(radius_factor > 0.0) || radius_factor > 1e6)
        return cli_usage_error(env, "--radius-factor must be in (0, 1e6], got %g", radius_factor);
    double view[3] = {0, 0, 0};
    if (orient_to && cli_parse_doubles(orient_to, view, 3) != 3)
        return cli_usage_error(env, "--orient-to expects x,y,z, got '%s'", orient_to);
    if (orient_to && keep)
        return cli_usage_error(env, "--orient-to and --keep-orientation exclude each other");
    if (!normals && !radii)
        normals = radii = 1;
    const char *input = argv[0];

    asp_error err = {0};
    asp_cloud *cloud = NULL;
    double t0 = asp_time_now();
    if (asp_cloud_load(input, &env->ctx, &cloud, &err))
        return cli_fail(env, &err);
    int had_normals = cloud->normals != NULL, had_radii = cloud->radii != NULL;
    if (keep && !had_normals) {
        asp_cloud_destroy(cloud);
        return cli_usage_error(env, "--keep-orientation needs normals in '%s'", input);
    }
    asp_estimate_desc desc = {
        .k = k,
        .normals = normals,
        .radii = radii,
        .force = force,
        .orient = orient_to ? ASP_ORIENT_VIEWPOINT : keep ? ASP_ORIENT_EXISTING : ASP_ORIENT_MST,
        /* the library works relative to the cloud's origin */
        .viewpoint = {(float)(view[0] - cloud->origin[0]), (float)(view[1] - cloud->origin[1]),
                      (float)(view[2] - cloud->origin[2])},
        .radius_k = radius_k,
        .radius_factor = (float)radius_factor,
    };
    rc = asp_cloud_estimate(cloud, &desc, &err);
    if (rc == 0)
        rc = asp_cloud_save(cloud, output, NULL, &err);
    size_t count = cloud->count;
    asp_cloud_destroy(cloud);
    if (rc)
        return cli_fail(env, &err);
    int did_normals = normals && (force || !had_normals);
    int did_radii = radii && (force || !had_radii);
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", input);
        cJSON_AddStringToObject(o, "output", output);
        cJSON_AddNumberToObject(o, "points", (double)count);
        cJSON_AddStringToObject(o, "normals", did_normals ? "estimated" : had_normals ? "kept" : "none");
        cJSON_AddStringToObject(o, "radii", did_radii ? "estimated" : had_radii ? "kept" : "none");
        cJSON_AddNumberToObject(o, "k", (double)k);
        cJSON_AddNumberToObject(o, "radius_k", (double)radius_k);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.4f", asp_time_now() - t0));
        return cli_json_print(env, o);
    } else if (!env->quiet) {
        printf("%s: %zu points, normals %s, radii %s\n", output, count,
               did_normals ? "estimated" : had_normals ? "kept" : "none",
               did_radii ? "estimated" : had_radii ? "kept" : "none");
    }
    return 0;
}
