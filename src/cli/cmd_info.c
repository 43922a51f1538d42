/*
 * amgsplat info: what a point file holds — counts, attributes, bounds, radii —
 * and the levels of a .dps (primitives) or .amg (decomposition) file.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "amgsplat/amg.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat info FILE [--json]\n"
    "\n"
    "Prints the number of points and faces, the attributes present (normals, colours,\n"
    "radii, texture coordinates, labels and any extra properties with their types), the\n"
    "bounding box in world coordinates and the radius statistics of a point file\n"
    "(.ply, .xyz, .pts, .txt). For a primitive file (.dps, from 'amgsplat build') it prints\n"
    "per level: primitives, texels, error, normalised error, cb and dpc times, atlas size. For a\n"
    "decomposition (.amg, from 'amgsplat decompose') it prints the points, their attributes and\n"
    "the unknowns of every AMG level (domains per level: 'amgsplat decompose --stats').";

struct radius_stats {
    double mean, min, max;
};

static struct radius_stats radius_stats(const asp_cloud *c)
{
    struct radius_stats s = {0, 0, 0};
    if (!c->radii || c->count == 0)
        return s;
    double sum = 0; /* double: a float sum of 10^8 radii would lose digits */
    s.min = s.max = c->radii[0];
    for (size_t i = 0; i < c->count; i++) {
        double r = c->radii[i];
        sum += r;
        s.min = r < s.min ? r : s.min;
        s.max = r > s.max ? r : s.max;
    }
    s.mean = sum / (double)c->count;
    return s;
}

static void print_text(const char *path, const asp_cloud *c, const double lo[3], const double hi[3],
                       struct radius_stats r)
{
    printf("file        %s\n", path);
    printf("points      %zu\n", c->count);
    if (c->face_count)
        printf("faces       %zu\n", c->face_count);
    printf("attributes  positions(%s)%s%s%s%s%s", asp_scalar_name(c->position_type), c->normals ? " normals" : "",
           c->colors ? " colors" : "", c->radii ? " radii" : "", c->uvs ? " uvs" : "", c->labels ? " labels" : "");
    for (size_t i = 0; i < c->property_count; i++)
        printf(" %s(%s)", c->properties[i].name, asp_scalar_name(c->properties[i].type));
    printf("\n");
    printf("origin      %.9g %.9g %.9g\n", c->origin[0], c->origin[1], c->origin[2]);
    printf("bbox min    %.9g %.9g %.9g\n", lo[0], lo[1], lo[2]);
    printf("bbox max    %.9g %.9g %.9g\n", hi[0], hi[1], hi[2]);
    double d = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
    printf("diagonal    %.9g\n", d);
    if (c->radii)
        printf("radius      mean %.6g min %.6g max %.6g\n", r.mean, r.min, r.max);
    for (size_t i = 0; i < c->comment_count; i++)
        printf("comment     %s\n", c->comments[i]);
    for (size_t i = 0; i < c->obj_info_count; i++)
        printf("obj_info    %s\n", c->obj_info[i]);
}

static void print_json(const char *path, const asp_cloud *c, const double lo[3], const double hi[3],
                       struct radius_stats r)
{
    printf("{\"file\": ");
    cli_json_string(stdout, path);
    printf(", \"points\": %zu, \"faces\": %zu, \"position_type\": \"%s\"", c->count, c->face_count,
           asp_scalar_name(c->position_type));
    printf(", \"normals\": %s, \"colors\": %s, \"radii\": %s, \"uvs\": %s, \"labels\": %s",
           c->normals ? "true" : "false", c->colors ? "true" : "false", c->radii ? "true" : "false",
           c->uvs ? "true" : "false", c->labels ? "true" : "false");
    printf(", \"properties\": [");
    for (size_t i = 0; i < c->property_count; i++) {
        printf("%s{\"name\": ", i ? ", " : "");
        cli_json_string(stdout, c->properties[i].name);
        printf(", \"type\": \"%s\"}", asp_scalar_name(c->properties[i].type));
    }
    printf("], \"origin\": [%.17g, %.17g, %.17g]", c->origin[0], c->origin[1], c->origin[2]);
    printf(", \"bbox_min\": [%.17g, %.17g, %.17g], \"bbox_max\": [%.17g, %.17g, %.17g]", lo[0], lo[1], lo[2], hi[0],
           hi[1], hi[2]);
    if (c->radii)
        printf(", \"radius_mean\": %.9g, \"radius_min\": %.9g, \"radius_max\": %.9g", r.mean, r.min, r.max);
    printf(", \"comments\": [");
    for (size_t i = 0; i < c->comment_count; i++) {
        printf("%s", i ? ", " : "");
        cli_json_string(stdout, c->comments[i]);
    }
    printf("]}\n");
}

/* A .dps file (amgsplat build): the thesis Table 5.2 columns per stored level. */
static int info_dps(const char *path, struct cli_env *env)
{
    asp_dps *dps = NULL;
    asp_error err = {0};
    if (asp_dps_load(path, &env->ctx, &dps, &err))
        return cli_fail(env, &err);
    asp_dps_summary rows[64];
    size_t nl = dps->level_count < 64 ? dps->level_count : 64;
    asp_dps_summarize(dps, rows, 64);
    cli_progress_end(env);
    if (env->json) {
        printf("{\"file\": ");
        cli_json_string(stdout, path);
        printf(", \"source\": ");
        cli_json_string(stdout, dps->source);
        printf(", \"points\": %llu, \"mean_radius\": %.9g, \"method\": \"%s\", \"texel_size\": %g, \"levels\": [",
               (unsigned long long)dps->source_points, dps->mean_radius, asp_prim_method_name(dps->desc.method),
               dps->desc.texel_size);
        for (size_t i = 0; i < nl; i++)
            printf("%s{\"level\": %u, \"name\": \"%s\", \"primitives\": %zu, \"texels\": %llu, \"error\": %.9g, "
                   "\"normalised_error\": %.6g, \"cb_seconds\": %.4f, \"dpc_seconds\": %.4f, \"skipped\": %u, "
                   "\"degenerate\": %u, \"capped\": %u, \"merges\": %u, \"atlas\": [%u, %u], "
                   "\"neighbour_pairs\": %zu, \"normal_map\": %s}",
                   i ? ", " : "", rows[i].level, rows[i].name, rows[i].primitives, (unsigned long long)rows[i].texels,
                   rows[i].error, rows[i].error_norm, rows[i].t_basis, rows[i].t_construct, rows[i].skipped,
                   rows[i].degenerate, rows[i].capped, rows[i].merges, rows[i].atlas_width, rows[i].atlas_height,
                   rows[i].neighbour_pairs, rows[i].normal_map ? "true" : "false");
        printf("]}\n");
    } else {
        printf("file        %s\nsource      %s (%llu points, mean radius %.6g)\n", path, dps->source,
               (unsigned long long)dps->source_points, dps->mean_radius);
        printf("textures    %s, texel size %g\n", asp_prim_method_name(dps->desc.method), dps->desc.texel_size);
        printf("level  name   primitives    texels        error  normalised   cb (s)  dpc (s)  atlas\n");
        for (size_t i = 0; i < nl; i++)
            printf("%5u  %-5s %11zu %9llu  %11.6g  %10.3f  %7.3f  %7.3f  %ux%u\n", rows[i].level, rows[i].name,
                   rows[i].primitives, (unsigned long long)rows[i].texels, rows[i].error, rows[i].error_norm,
                   rows[i].t_basis, rows[i].t_construct, rows[i].atlas_width, rows[i].atlas_height);
    }
    asp_dps_destroy(dps);
    return 0;
}

/* An .amg file (amgsplat decompose): the stored points and the size of every level (journal section 2). */
static int info_amg(const char *path, struct cli_env *env)
{
    asp_amg *amg = NULL;
    asp_error err = {0};
    if (asp_amg_load(path, &env->ctx, &amg, &err))
        return cli_fail(env, &err);
    const asp_cloud *c = asp_amg_cloud(amg);
    const size_t nl = asp_amg_level_count(amg);
    const char *normals = asp_amg_has_input_normals(amg) ? "input" : "tangent planes (unoriented)";
    cli_progress_end(env);
    if (env->json) {
        printf("{\"file\": ");
        cli_json_string(stdout, path);
        printf(", \"points\": %zu, \"normals\": \"%s\", \"colors\": %s, \"radii\": %s, \"uvs\": %s, "
               "\"labels\": %s, \"levels\": [",
               c->count, asp_amg_has_input_normals(amg) ? "input" : "tangent", c->colors ? "true" : "false",
               c->radii ? "true" : "false", c->uvs ? "true" : "false", c->labels ? "true" : "false");
        for (size_t l = 0; l < nl; l++) {
            char name[32];
            snprintf(name, sizeof name, l == nl - 1 ? "L" : "L-%zu", nl - 1 - l);
            printf("%s{\"level\": %zu, \"name\": \"%s\", \"unknowns\": %zu}", l ? ", " : "", l, name,
                   asp_amg_level_size(amg, l));
        }
        printf("]}\n");
    } else {
        printf("file        %s\npoints      %zu\nnormals     %s\nattributes ", path, c->count, normals);
        printf("%s%s%s%s\n", c->colors ? " colours" : "", c->radii ? " radii" : "", c->uvs ? " uvs" : "",
               c->labels ? " labels" : "");
        printf("level  name   unknowns  reduction\n");
        for (size_t l = 0; l < nl; l++) {
            char name[32];
            snprintf(name, sizeof name, l == nl - 1 ? "L" : "L-%zu", nl - 1 - l);
            const size_t n = asp_amg_level_size(amg, l);
            printf("%5zu  %-5s %9zu  %9.2f\n", l, name, n,
                   l ? (double)asp_amg_level_size(amg, l - 1) / (double)n : 1.0);
        }
    }
    asp_amg_destroy(amg);
    return 0;
}

int cmd_info(int argc, char **argv, struct cli_env *env)
{
    const struct cli_option opts[] = {{0}};
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one file, got %d; see 'amgsplat info -h'", npos);
    size_t len = strlen(argv[0]);
    if (len >= 4 && strcmp(argv[0] + len - 4, ".dps") == 0)
        return info_dps(argv[0], env);
    if (len >= 4 && strcmp(argv[0] + len - 4, ".amg") == 0)
        return info_amg(argv[0], env);
    asp_cloud *c = NULL;
    asp_error err = {0};
    if (asp_cloud_load(argv[0], &env->ctx, &c, &err))
        return cli_fail(env, &err);
    float flo[3], fhi[3];
    double lo[3], hi[3];
    if (asp_cloud_bounds(c, flo, fhi, &err)) {
        asp_cloud_destroy(c);
        return cli_fail(env, &err);
    }
    for (int k = 0; k < 3; k++) {
        lo[k] = c->origin[k] + flo[k];
        hi[k] = c->origin[k] + fhi[k];
    }
    struct radius_stats r = radius_stats(c);
    cli_progress_end(env);
    if (env->json)
        print_json(argv[0], c, lo, hi, r);
    else
        print_text(argv[0], c, lo, hi, r);
    asp_cloud_destroy(c);
    return 0;
}
