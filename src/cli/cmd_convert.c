/*
 * amgsplat convert: point files between PLY (binary little/big endian,
 * ascii) and text XYZ/PTS/TXT, through asp_cloud_load / asp_cloud_save.
 */
static const char usage[] =
    "usage: amgsplat convert [--ascii | --big-endian] IN OUT\n"
    "\n"
    "Converts a point file; formats follow the extensions (.ply, .xyz, .pts, .txt).\n"
    "PLY output is binary little endian unless --ascii or --big-endian is given.\n"
    "Text output keeps positions, normals and colours only.";

#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static void attr_list(const asp_cloud *c, char *out, size_t cap, int json)
{
    static const struct {
        unsigned bit;
        const char *name;
    } names[] = {{ASP_ATTR_NORMALS, "normals"}, {ASP_ATTR_COLORS, "colors"}, {ASP_ATTR_RADII, "radii"},
                 {ASP_ATTR_UVS, "uvs"},         {ASP_ATTR_LABELS, "labels"}};
    unsigned attrs = asp_cloud_attrs(c);
    size_t len = 0;
    out[0] = '\0';
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (attrs & names[i].bit) {
            int n = snprintf(out + len, cap - len, json ? "%s\"%s\"" : "%s%s", len ? ", " : "", names[i].name);
            if (n > 0 && (size_t)n < cap - len)
                len += (size_t)n;
        }
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

int cmd_convert(int argc, char **argv, struct cli_env *env)
{
    int ascii = 0, big_endian = 0, npos = 0;
    const struct cli_option opts[] = {
        {"ascii", 0, CLI_FLAG, &ascii, NULL, "write PLY as ascii text"},
        {"big-endian", 0, CLI_FLAG, &big_endian, NULL, "write PLY as binary big endian"},
        {0},
    };
    int rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 2)
        return cli_usage_error(env, "expected an input and an output file, got %d argument%s; see 'amgsplat convert -h'",
                               npos, npos == 1 ? "" : "s");
    const char *in = argv[0], *out = argv[1];
    if (ascii && big_endian)
        return cli_usage_error(env, "--ascii and --big-endian exclude each other");
    if (cli_check_output(env, out, NULL, 0, (const char *const[]){in}, 1))
        return 2;
    asp_file_type out_type;
    const char *out_fmt = asp_file_type_of_name(out, &out_type, NULL) == 0 ? out_type.format : NULL;
    if ((ascii || big_endian) && out_fmt && strcmp(out_fmt, "ply") != 0)
        return cli_usage_error(env, "--%s applies to .ply output only, not '%s'", ascii ? "ascii" : "big-endian", out);

    asp_error err = {0};
    asp_cloud *cloud = NULL;
    if (asp_cloud_load(in, &env->ctx, &cloud, &err))
        return cli_fail(env, &err);
    asp_save_desc desc = {.encoding = ascii ? ASP_PLY_ASCII : big_endian ? ASP_PLY_BINARY_BE : ASP_PLY_BINARY_LE};
    if (asp_cloud_save(cloud, out, &desc, &err)) {
        asp_cloud_destroy(cloud);
        return cli_fail(env, &err);
    }
    cli_progress_end(env);
    const char *enc = !out_fmt || strcmp(out_fmt, "ply") != 0 ? "text"
                      : ascii                                 ? "ascii"
                      : big_endian                            ? "binary_big_endian"
                                                              : "binary_little_endian";
    char attrs[128];
    if (strcmp(enc, "text") == 0)
        note_dropped(env, cloud, out);
    if (env->json) {
        attr_list(cloud, attrs, sizeof attrs, 1);
        printf("{\"input\": ");
        cli_json_string(stdout, in);
        printf(", \"output\": ");
        cli_json_string(stdout, out);
        printf(", \"encoding\": \"%s\", \"points\": %zu, \"faces\": %zu, \"attributes\": [%s], \"properties\": %zu}\n",
               enc, cloud->count, cloud->face_count, attrs, cloud->property_count);
    } else if (!env->quiet) {
        attr_list(cloud, attrs, sizeof attrs, 0);
        printf("converted '%s' -> '%s' (%s): %zu points%s%s%s, %zu faces, %zu extra properties\n", in, out, enc,
               cloud->count, attrs[0] ? " (" : "", attrs, attrs[0] ? ")" : "", cloud->face_count,
               cloud->property_count);
    }
    asp_cloud_destroy(cloud);
    return 0;
}
