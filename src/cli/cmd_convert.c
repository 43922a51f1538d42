/*
 * amgsplat convert: point files between PLY (binary little/big endian,
 * ascii), LAS (1.0-1.4 in, 1.2/1.4 out) and text XYZ/PTS/TXT, through
 * asp_cloud_load / asp_cloud_save.
 */
static const char usage[] =
    "usage: amgsplat convert [--ascii | --big-endian] [--las-format N] [--las-scale S] IN -o OUT\n"
    "       amgsplat convert [options] IN OUT\n"
    "\n"
    "Converts a point file; formats follow the extensions (.ply, .xyz, .pts, .txt, .las).\n"
    "PLY output is binary little endian unless --ascii or --big-endian is given.\n"
    "LAS output keeps the source's point format, scale, offset and VLRs when it was LAS;\n"
    "otherwise it is LAS 1.4 format 7 with colours, 6 without (8 with a 'nir' property), at\n"
    "a 0.001 scale. --las-format 0-3 (LAS 1.2) or 6-8 (LAS 1.4) and --las-scale override.\n"
    "Text output keeps positions, normals and colours only.\n"
    "\n"
    "OUT.hier builds the streamed (out-of-core) point hierarchy from a binary PLY or LAS file of any\n"
    "size with a working set of about --memory (default 2G): a counting sort into chunks, one octree\n"
    "per chunk, then the top (docs/hier.md). render draws it, loading only the nodes a view needs.\n"
    "With --in-memory, OUT.hier is the in-memory hierarchy instead: every node's splat ellipse\n"
    "(seed 001), what the splat renderer draws and export --tiles writes as Gaussian splats; the\n"
    "points must fit in memory.";

#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const struct {
    unsigned bit;
    const char *name;
} attr_names[] = {{ASP_ATTR_NORMALS, "normals"}, {ASP_ATTR_COLORS, "colors"}, {ASP_ATTR_RADII, "radii"},
                  {ASP_ATTR_UVS, "uvs"},         {ASP_ATTR_LABELS, "labels"}};

static void attr_list(const asp_cloud *c, char *out, size_t cap)
{
    unsigned attrs = asp_cloud_attrs(c);
    size_t len = 0;
    out[0] = '\0';
    for (size_t i = 0; i < sizeof attr_names / sizeof attr_names[0]; i++)
        if (attrs & attr_names[i].bit) {
            int n = snprintf(out + len, cap - len, "%s%s", len ? ", " : "", attr_names[i].name);
            if (n > 0 && (size_t)n < cap - len)
                len += (size_t)n;
        }
}

static int print_json(const struct cli_env *env, const asp_cloud *c, const char *in, const char *out,
                      const char *enc)
{
    cJSON *root = cJSON_CreateObject(), *attrs = cJSON_CreateArray();
    cJSON_AddStringToObject(root, "input", in);
    cJSON_AddStringToObject(root, "output", out);
    cJSON_AddStringToObject(root, "encoding", enc);
    cJSON_AddNumberToObject(root, "points", (double)c->count);
    cJSON_AddNumberToObject(root, "faces", (double)c->face_count);
    for (size_t i = 0; i < sizeof attr_names / sizeof attr_names[0]; i++)
        if (asp_cloud_attrs(c) & attr_names[i].bit)
            cJSON_AddItemToArray(attrs, cJSON_CreateString(attr_names[i].name));
    cJSON_AddItemToObject(root, "attributes", attrs);
    cJSON_AddNumberToObject(root, "properties", (double)c->property_count);
    return cli_json_print(env, root);
}

/* What a text file cannot hold, so the user is told instead of surprised. */
static void note_dropped(const struct cli_env *env, const asp_cloud *c, const char *out)
{
    char what[160] = "";
    size_t len = 0;
    const char *items[6];
    size_t n = 0;
    if (c->radii) items[n++] = "radii";
    if (c->uvs) items[n++] = "uvs";
    if (c->labels) items[n++] = "labels";
    if (c->face_count) items[n++] = "faces";
    if (c->comment_count || c->obj_info_count) items[n++] = "comments";
    int intensity_only = c->property_count == 1 && !c->normals && asp_cloud_find_property(c, "intensity");
    if (c->property_count && !intensity_only) items[n++] = "extra properties";
    for (size_t i = 0; i < n; i++) {
        int k = snprintf(what + len, sizeof what - len, "%s%s", i ? ", " : "", items[i]);
        if (k > 0 && (size_t)k < sizeof what - len)
            len += (size_t)k;
    }
    if (n)
        cli_info(env, "amgsplat convert: note: '%s' keeps only positions, normals and colours; dropped %s", out, what);
}

/* Point file -> streamed hierarchy, never holding the points (issue 28). */
static int convert_hier(struct cli_env *env, const char *in, const char *out, const char *memory, size_t node_points,
                        const char *temp_dir)
{
    asp_ooc_build_desc desc = {.node_points = node_points, .temp_dir = temp_dir};
    if (memory && cli_memory_option(env, memory, &desc.memory))
        return 2;
    if (cli_given(env, &node_points) && (node_points < 64 || node_points > 1000000))
        return cli_usage_error(env, "--node-points %zu: expected 64 to 1000000", node_points);
    asp_error err = {0};
    asp_ooc_build_stats st;
    double t0 = asp_time_now();
    if (asp_ooc_build(in, out, &desc, &env->ctx, &st, &err))
        return cli_fail(env, &err);
    double s = asp_time_now() - t0;
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", in);
        cJSON_AddStringToObject(o, "output", out);
        cJSON_AddStringToObject(o, "encoding", "hier-streamed");
        cJSON_AddNumberToObject(o, "points", (double)st.points);
        cJSON_AddNumberToObject(o, "nodes", (double)st.nodes);
        cJSON_AddNumberToObject(o, "chunks", (double)st.chunks);
        cJSON_AddNumberToObject(o, "depth", st.depth);
        cJSON_AddNumberToObject(o, "grid", st.grid);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.3f", s));
        cJSON_AddItemToObject(o, "seconds_bounds", cli_json_number("%.3f", st.seconds_bounds));
        cJSON_AddItemToObject(o, "seconds_count", cli_json_number("%.3f", st.seconds_count));
        cJSON_AddItemToObject(o, "seconds_distribute", cli_json_number("%.3f", st.seconds_distribute));
        cJSON_AddItemToObject(o, "seconds_index", cli_json_number("%.3f", st.seconds_index));
        cJSON_AddItemToObject(o, "points_per_second", cli_json_number("%.0f", (double)st.points / s));
        return cli_json_print(env, o);
    }
    if (!env->quiet)
        printf("converted '%s' -> '%s' (streamed hierarchy): %llu points, %zu nodes, depth %u, %zu chunks, "
               "%.2f s (%.2f M points/s; bounds %.1f s, count %.1f s, distribute %.1f s, index %.1f s)\n",
               in, out, (unsigned long long)st.points, st.nodes, st.depth, st.chunks, s, (double)st.points / s / 1e6,
               st.seconds_bounds, st.seconds_count, st.seconds_distribute, st.seconds_index);
    return 0;
}

/* Point file -> in-memory hierarchy with seed 001's ellipses (asp_hier_build, asp_hier_save). */
static int convert_hier_in_memory(struct cli_env *env, const char *in, const char *out)
{
    asp_error err = {0};
    asp_cloud *c = NULL;
    asp_hier *h = NULL;
    double t0 = asp_time_now();
    int rc = asp_cloud_load(in, &env->ctx, &c, &err);
    if (!rc)
        rc = asp_hier_build(c, NULL, &env->ctx, &h, &err);
    asp_cloud_destroy(c);
    if (!rc)
        rc = asp_hier_save(h, out, &err);
    double s = asp_time_now() - t0;
    size_t nodes = h ? asp_hier_node_count(h) : 0, points = h ? asp_hier_point_count(h) : 0;
    asp_hier_destroy(h);
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", in);
        cJSON_AddStringToObject(o, "output", out);
        cJSON_AddStringToObject(o, "encoding", "hier");
        cJSON_AddNumberToObject(o, "points", (double)points);
        cJSON_AddNumberToObject(o, "nodes", (double)nodes);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.3f", s));
        return cli_json_print(env, o);
    }
    if (!env->quiet)
        printf("converted '%s' -> '%s' (in-memory hierarchy): %zu points, %zu nodes, %.2f s\n", in, out, points, nodes, s);
    return 0;
}

int cmd_convert(int argc, char **argv, struct cli_env *env)
{
    int ascii = 0, big_endian = 0, npos = 0, las_format = -1, in_memory = 0;
    double las_scale = 0;
    const char *output = NULL, *memory = NULL, *temp_dir = NULL;
    size_t node_points = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "OUT", "output point file (.ply, .las, .xyz, .pts, .txt); or OUT as the second argument"},
        {"ascii", 0, CLI_FLAG, &ascii, NULL, "write PLY as ascii text"},
        {"big-endian", 0, CLI_FLAG, &big_endian, NULL, "write PLY as binary big endian"},
        {"las-format", 0, CLI_INT, &las_format, "N", "LAS point data record format: 0-3 or 6-8"},
        {"las-scale", 0, CLI_DOUBLE, &las_scale, "S", "LAS coordinate step (default: the source's, else 0.001)"},
        {"memory", 0, CLI_STRING, &memory, "SIZE", ".hier output: working-set budget, e.g. 512M, 2G (default 2G)"},
        {"node-points", 0, CLI_SIZE, &node_points, "N", ".hier output: most points in a leaf node (default 32768)"},
        {"temp-dir", 0, CLI_STRING, &temp_dir, "DIR", ".hier output: directory for the chunk files (default: next to OUT)"},
        {"in-memory", 0, CLI_FLAG, &in_memory, NULL, ".hier output: the in-memory hierarchy with splat ellipses (the points must fit in memory)"},
        {0},
    };
    int rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    // -o OUT as in every other command (issue 29); IN OUT as before
    if (output && npos != 1)
        return cli_usage_error(env, "with -o %s expected one input file, got %d argument%s; see 'amgsplat convert -h'",
                               output, npos, npos == 1 ? "" : "s");
    if (!output && npos != 2)
        return cli_usage_error(env, "expected an input and an output file, got %d argument%s; see 'amgsplat convert -h'",
                               npos, npos == 1 ? "" : "s");
    const char *in = argv[0], *out = output ? output : argv[1];
    if (ascii && big_endian)
        return cli_usage_error(env, "--ascii and --big-endian exclude each other");
    if (cli_check_output(env, out, NULL, 0, (const char *const[]){in}, 1))
        return 2;
    asp_file_type out_type;
    int hier_out = asp_file_type_of_name(out, &out_type, NULL) == 0 && out_type.kind == ASP_FILE_HIER;
    if (in_memory && !hier_out)
        return cli_usage_error(env, "--in-memory applies to .hier output only, not '%s'", out);
    if (in_memory && (memory || node_points || temp_dir))
        return cli_usage_error(env, "--memory, --node-points and --temp-dir are for the streamed layout, not --in-memory");
    if (in_memory)
        return convert_hier_in_memory(env, in, out);
    if (hier_out)
        return convert_hier(env, in, out, memory, node_points, temp_dir);
    if (memory || node_points || temp_dir)
        return cli_usage_error(env, "--memory, --node-points and --temp-dir apply to .hier output only, not '%s'", out);
    const char *out_fmt = asp_file_type_of_name(out, &out_type, NULL) == 0 ? out_type.format : NULL;
    if ((ascii || big_endian) && out_fmt && strcmp(out_fmt, "ply") != 0)
        return cli_usage_error(env, "--%s applies to .ply output only, not '%s'", ascii ? "ascii" : "big-endian", out);
    int las_out = out_fmt && strcmp(out_fmt, "las") == 0;
    // given values are checked even where they equal the "not given" defaults -1 and 0 (issue #31)
    int given_format = cli_given(env, &las_format), given_scale = cli_given(env, &las_scale);
    if ((given_format || given_scale) && !las_out)
        return cli_usage_error(env, "--%s applies to .las output only, not '%s'",
                               given_format ? "las-format" : "las-scale", out);
    if (given_format && (las_format < 0 || las_format > 8 || las_format == 4 || las_format == 5))
        return cli_usage_error(env, "--las-format %d: expected 0, 1, 2, 3, 6, 7 or 8 (waveform formats are not written)",
                               las_format);
    if ((given_scale && !(las_scale > 0)) || las_scale < 0 || !(las_scale <= 1e6))
        return cli_usage_error(env, "--las-scale %g: expected a positive step up to 1e6", las_scale);

    asp_error err = {0};
    asp_cloud *cloud = NULL;
    if (asp_cloud_load(in, &env->ctx, &cloud, &err))
        return cli_fail(env, &err);
    asp_save_desc desc = {.encoding = ascii ? ASP_PLY_ASCII : big_endian ? ASP_PLY_BINARY_BE : ASP_PLY_BINARY_LE,
                          .las_format = las_format >= 0 ? ASP_LAS_FORMAT(las_format) : 0,
                          .las_scale = las_scale};
    if (asp_cloud_save(cloud, out, &desc, &err)) {
        asp_cloud_destroy(cloud);
        return cli_fail(env, &err);
    }
    cli_progress_end(env);
    const char *enc = las_out                                 ? "las"
                      : !out_fmt || strcmp(out_fmt, "ply") != 0 ? "text"
                      : ascii                                 ? "ascii"
                      : big_endian                            ? "binary_big_endian"
                                                              : "binary_little_endian";
    char attrs[128];
    if (strcmp(enc, "text") == 0)
        note_dropped(env, cloud, out);
    else if (las_out && (cloud->uvs || cloud->face_count || cloud->comment_count || cloud->obj_info_count))
        cli_info(env, "amgsplat convert: note: '%s' (LAS) does not keep%s%s%s", out, cloud->uvs ? " uvs" : "",
                 cloud->face_count ? " faces" : "", cloud->comment_count || cloud->obj_info_count ? " comments" : "");
    if (env->json) {
        rc = print_json(env, cloud, in, out, enc);
    } else if (!env->quiet) {
        attr_list(cloud, attrs, sizeof attrs);
        printf("converted '%s' -> '%s' (%s): %zu points%s%s%s, %zu faces, %zu extra properties\n", in, out, enc,
               cloud->count, attrs[0] ? " (" : "", attrs, attrs[0] ? ")" : "", cloud->face_count,
               cloud->property_count);
    }
    asp_cloud_destroy(cloud);
    return rc;
}
