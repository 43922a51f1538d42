/*
 * amgsplat simplify: a mesh simplified to N triangles through meshoptimizer
 * (asp_mesh_simplify), written as OBJ+MTL or PLY (asp_mesh_save): the
 * polygon baseline issue #14 measures domain primitives against; or, with
 * --billboards, a mesh or point set turned into a billboard cloud (issue 30,
 * Decoret et al. 2003; billboard.h) written as a .dps level.
 */
static const char usage[] =
    "usage: amgsplat simplify MESH --triangles N -o OUT.obj|OUT.ply [--error X] [--texture FILE]\n"
    "                         [--up AXIS] [--sloppy] [--recompute-normals] [--lock-border] [--json]\n"
    "       amgsplat simplify MODEL --billboards --error X -o OUT.dps [--texel-size T | --texels N]\n"
    "                         [--planes N] [--normal-map] [--texture FILE] [--up AXIS] [--json]\n"
    "\n"
    "Simplifies a mesh (OBJ+MTL, PLY, OFF, STL, glTF/GLB, 3DS, ... via assimp) to about N\n"
    "triangles with meshoptimizer's edge collapse, keeping UVs (seams stay closed), vertex\n"
    "colours, normals, materials and textures. OUT.obj gets OUT.mtl and OUT.png beside it;\n"
    "OUT.ply holds faces, uvs and colours and names OUT.png. --error X stops once the error\n"
    "would exceed X (relative to the mesh extent, 0.01 = 1%). The collapse may stop above N\n"
    "to keep the topology; --sloppy then tries meshoptimizer's clustering simplifier, which\n"
    "reaches N but may tear UV seams. Prints triangles, vertices, the error and GPU bytes\n"
    "(vertex + index + mipmapped texture bytes, as in docs/cli/simplify.md).\n"
    "\n"
    "--billboards: a billboard cloud (Decoret et al. 2003; thesis 6.2): planes chosen greedily\n"
    "so that every face (or point of a point set, a disc of its radius) lies within X times\n"
    "the bounding-box diagonal of its plane, each textured with what it covers (binary alpha),\n"
    "written as a .dps level that render, view, eval and export draw alpha-tested.";

#include <stdio.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static cJSON *bytes_json(const asp_mesh_bytes *b)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "vertex", (double)b->vertex);
    cJSON_AddNumberToObject(o, "index", (double)b->index);
    cJSON_AddNumberToObject(o, "texture", (double)b->texture);
    cJSON_AddNumberToObject(o, "total", (double)b->total);
    return o;
}

static int print_json(const struct cli_env *env, const char *in, const char *out, const asp_mesh_simplify_stats *st,
                      const asp_mesh_bytes *bi, const asp_mesh_bytes *bo)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "input", in);
    cJSON_AddStringToObject(o, "output", out);
    cJSON_AddNumberToObject(o, "target_triangles", (double)st->target_triangles);
    cJSON_AddNumberToObject(o, "input_triangles", (double)st->input_triangles);
    cJSON_AddNumberToObject(o, "input_vertices", (double)st->input_vertices);
    cJSON_AddNumberToObject(o, "triangles", (double)st->output_triangles);
    cJSON_AddNumberToObject(o, "vertices", (double)st->output_vertices);
    cJSON_AddItemToObject(o, "error", cli_json_number("%.9g", st->error));
    cJSON_AddItemToObject(o, "error_world", cli_json_number("%.9g", st->error_world));
    cJSON_AddBoolToObject(o, "short_of_target", st->short_of_target);
    cJSON_AddBoolToObject(o, "sloppy", st->sloppy);
    cJSON_AddNumberToObject(o, "material_groups", (double)st->material_groups);
    cJSON_AddItemToObject(o, "input_bytes", bytes_json(bi));
    cJSON_AddItemToObject(o, "bytes", bytes_json(bo));
    return cli_json_print(env, o);
}

static int print_billboards(const struct cli_env *env, const char *in, const char *out,
                            const asp_billboard_stats *st, const asp_dps *dps)
{
    asp_mesh_bytes b;
    asp_dps_level_gpu_bytes(&dps->levels[0], &b);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", in);
        cJSON_AddStringToObject(o, "output", out);
        cJSON_AddNumberToObject(o, "elements", (double)st->elements);
        cJSON_AddNumberToObject(o, "planes", (double)st->planes);
        cJSON_AddNumberToObject(o, "uncovered", (double)st->uncovered);
        cJSON_AddNumberToObject(o, "fallback_planes", (double)st->fallbacks);
        cJSON_AddItemToObject(o, "error_world", cli_json_number("%.9g", st->eps));
        cJSON_AddItemToObject(o, "max_distance", cli_json_number("%.9g", st->max_distance));
        cJSON_AddItemToObject(o, "texel", cli_json_number("%.9g", st->texel));
        cJSON_AddNumberToObject(o, "texels", (double)st->texels);
        cJSON_AddNumberToObject(o, "atlas_width", dps->levels[0].atlas.width);
        cJSON_AddNumberToObject(o, "atlas_height", dps->levels[0].atlas.height);
        cJSON_AddItemToObject(o, "t_search", cli_json_number("%.4f", st->t_search));
        cJSON_AddItemToObject(o, "t_texture", cli_json_number("%.4f", st->t_texture));
        cJSON_AddItemToObject(o, "bytes", bytes_json(&b));
        return cli_json_print(env, o);
    }
    if (!env->quiet) {
        printf("billboards '%s' -> '%s': %zu elements on %zu planes (%zu own-plane fallbacks)%s\n", in, out,
               st->elements, st->planes, st->fallbacks, st->uncovered ? ", some left uncovered" : "");
        printf("error bound %.4g world units, largest distance %.4g; texel %.4g, %llu texels (%ux%u atlas)\n",
               st->eps, st->max_distance, st->texel, (unsigned long long)st->texels, dps->levels[0].atlas.width,
               dps->levels[0].atlas.height);
        printf("plane search %.2f s, textures %.2f s; GPU bytes %zu\n", st->t_search, st->t_texture, b.total);
    }
    if (st->uncovered)
        cli_info(env, "amgsplat simplify: note: --planes %zu left %zu of %zu elements uncovered (not drawn)",
                 st->planes, st->uncovered, st->elements);
    return 0;
}

/* simplify --billboards: a mesh's faces or a point set's discs to a billboard cloud .dps. */
static int billboards(const char *in, const char *output, const asp_billboard_desc *d, const char *texture,
                      asp_up_axis up, struct cli_env *env)
{
    asp_error err = {0};
    asp_file_type ft = {0};
    int rc = asp_file_recognise(in, &ft, &err);
    if (rc)
        return cli_fail(env, &err);
    asp_dps *dps = NULL;
    asp_billboard_stats st = {0};
    if (ft.kind == ASP_FILE_POINTS) {
        asp_cloud *cloud = NULL;
        rc = asp_cloud_load(in, &env->ctx, &cloud, &err);
        if (!rc)
            rc = asp_billboard_cloud(cloud, d, in, &env->ctx, &dps, &st, &err);
        asp_cloud_destroy(cloud);
    } else {
        asp_mesh *mesh = NULL;
        rc = asp_mesh_load(in, &(asp_mesh_load_desc){.texture_override = texture, .up = up}, &env->ctx, &mesh, &err);
        if (!rc)
            rc = asp_billboard_mesh(mesh, d, in, &env->ctx, &dps, &st, &err);
        asp_mesh_destroy(mesh);
    }
    if (!rc)
        rc = asp_dps_save(dps, output, &err);
    if (rc) {
        asp_dps_destroy(dps);
        return cli_fail(env, &err);
    }
    cli_progress_end(env);
    int status = print_billboards(env, in, output, &st, dps);
    asp_dps_destroy(dps);
    return status;
}

int cmd_simplify(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *texture = NULL, *up = NULL;
    size_t triangles = 0;
    double max_error = 0.0;
    int sloppy = 0, recompute = 0, lock_border = 0, bb = 0, normal_map = 0;
    double texel_size = 0.0;
    size_t texels = 0, planes = 0;
    const struct cli_option opts[] = {
        {"triangles", 'n', CLI_SIZE, &triangles, "N", "target triangle count (1 to the mesh's count - 1)"},
        {"output", 'o', CLI_STRING, &output, "FILE", "output mesh (.obj with .mtl and .png, or .ply)"},
        {"error", 'e', CLI_DOUBLE, &max_error, "X", "largest error relative to the extent (0 < X <= 1)"},
        {"texture", 't', CLI_STRING, &texture, "FILE", "texture for materials that have none (e.g. Spot's OBJ)"},
        {"up", 0, CLI_STRING, &up, "AXIS", "the file's up axis: y (default), z, x, -y, -z or -x"},
        {"sloppy", 0, CLI_FLAG, &sloppy, NULL, "fall back to clustering when the collapse stops above N"},
        {"recompute-normals", 0, CLI_FLAG, &recompute, NULL, "normals of the simplified surface"},
        {"lock-border", 0, CLI_FLAG, &lock_border, NULL, "keep open borders where they are"},
        {"billboards", 0, CLI_FLAG, &bb, NULL, "a billboard cloud (.dps) within --error instead of a mesh"},
        {"texel-size", 0, CLI_DOUBLE, &texel_size, "T", "billboards: texel edge as a fraction of the diagonal (default 1/512)"},
        {"texels", 0, CLI_SIZE, &texels, "N", "billboards: texel edge chosen so the textures hold about N texels"},
        {"planes", 0, CLI_SIZE, &planes, "N", "billboards: at most N planes (the rest is left out)"},
        {"normal-map", 0, CLI_FLAG, &normal_map, NULL, "billboards: also a normal atlas"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one mesh file, got %d; see 'amgsplat simplify -h'", npos);
    asp_up_axis up_axis = ASP_UP_Y;
    if (up && cli_parse_up(up, &up_axis) != 0)
        return cli_usage_error(env, "--up expects x, y, z, -x, -y or -z, got '%s'", up);
    if (bb) {
        if (!output || !asp_file_name_is(output, "dps"))
            return cli_usage_error(env, "--billboards writes a .dps: give -o OUT.dps");
        if (triangles || sloppy || recompute || lock_border)
            return cli_usage_error(env, "--billboards takes --error, --texel-size or --texels, --planes and "
                                   "--normal-map, not the mesh simplifier's options");
        if (!(max_error > 0.0 && max_error <= 1.0))
            return cli_usage_error(env, "--billboards needs --error X in (0, 1] (a fraction of the diagonal), got %g",
                                   max_error);
        if (texel_size && texels)
            return cli_usage_error(env, "give --texel-size or --texels, not both");
        if (texel_size < 0.0 || texel_size > 1.0)
            return cli_usage_error(env, "--texel-size must be in (0, 1] (a fraction of the diagonal), got %g",
                                   texel_size);
        asp_billboard_desc d = {.error = max_error, .texel_size = texel_size, .texels = texels,
                                .max_planes = planes, .normal_map = normal_map};
        return billboards(argv[0], output, &d, texture, up_axis, env);
    }
    if (texel_size || texels || planes || normal_map)
        return cli_usage_error(env, "--texel-size, --texels, --planes and --normal-map need --billboards");
    if (!output)
        return cli_usage_error(env, "missing -o OUT.obj or OUT.ply");
    if (!asp_file_name_is(output, "obj") && !asp_file_name_is(output, "ply"))
        return cli_usage_error(env, "output '%s' must end in .obj or .ply", output);
    if (triangles == 0 && max_error == 0.0)
        return cli_usage_error(env, "missing --triangles N (or --error X)");
    if (max_error < 0.0 || max_error > 1.0)
        return cli_usage_error(env, "--error must be in 0..1 (a fraction of the mesh extent), got %g", max_error);

    asp_error err = {0};
    asp_mesh *mesh = NULL;
    if (asp_mesh_load(argv[0], &(asp_mesh_load_desc){.texture_override = texture, .up = up_axis}, &env->ctx, &mesh,
                      &err))
        return cli_fail(env, &err);
    if (triangles && triangles >= mesh->triangle_count) {
        size_t have = mesh->triangle_count;
        asp_mesh_destroy(mesh);
        return cli_usage_error(env, "--triangles must be 1 to %zu ('%s' has %zu triangles), got %zu",
                               have > 1 ? have - 1 : 1, argv[0], have, triangles);
    }
    asp_mesh_simplify_desc desc = {
        .target_triangles = triangles,
        .target_error = max_error,
        .flags = (sloppy ? ASP_MESH_SIMPLIFY_SLOPPY_FALLBACK : 0u) |
                 (recompute ? ASP_MESH_SIMPLIFY_RECOMPUTE_NORMALS : 0u) |
                 (lock_border ? ASP_MESH_SIMPLIFY_LOCK_BORDER : 0u),
    };
    asp_mesh *simple = NULL;
    asp_mesh_simplify_stats st = {0};
    if (asp_mesh_simplify(mesh, &desc, &env->ctx, &simple, &st, &err) ||
        asp_mesh_save(simple, output, NULL, &err)) {
        asp_mesh_destroy(simple);
        asp_mesh_destroy(mesh);
        return cli_fail(env, &err);
    }
    cli_progress_end(env);
    asp_mesh_bytes bi, bo;
    asp_mesh_gpu_bytes(mesh, &bi);
    asp_mesh_gpu_bytes(simple, &bo);
    int status = 0;
    if (env->json) {
        status = print_json(env, argv[0], output, &st, &bi, &bo);
    } else if (!env->quiet) {
        printf("simplified '%s' -> '%s': %zu -> %zu triangles (target %zu), %zu -> %zu vertices\n", argv[0],
               output, st.input_triangles, st.output_triangles, st.target_triangles, st.input_vertices,
               st.output_vertices);
        printf("error %.3g of the extent (%.3g world units)%s\n", st.error, st.error_world,
               st.sloppy ? ", sloppy fallback (UV seams may tear)" : "");
        printf("GPU bytes %zu -> %zu (vertex %zu, index %zu, texture %zu)\n", bi.total, bo.total, bo.vertex, bo.index,
               bo.texture);
    }
    if (st.short_of_target)
        cli_info(env, "amgsplat simplify: note: stopped at %zu triangles, more than 5%% above the target %zu (%s)%s",
                 st.output_triangles, st.target_triangles,
                 max_error > 0.0 ? "--error or the topology" : "the topology and UV seams",
                 sloppy ? "; the sloppy fallback got no closer" : "; --sloppy can go further");
    asp_mesh_destroy(simple);
    asp_mesh_destroy(mesh);
    return status;
}
