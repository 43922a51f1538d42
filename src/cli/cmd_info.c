/*
 * amgsplat info: what any file amgsplat reads holds, its kind told by the one
 * recogniser (asp_file_recognise): a point file's counts, attributes, bounds and
 * radii; a mesh's vertices, faces, UV sets, materials, textures (found and
 * missing), bounds and the up axis assumed; the levels of a .dps or .amg; a
 * .hier's nodes; an image's size.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat info FILE [--json]\n"
    "\n"
    "Tells what FILE is (by its first bytes, else its extension in any case) and describes it.\n"
    "Point file (.ply, .xyz, .pts, .txt): points and faces, the attributes present (normals,\n"
    "colours, radii, texture coordinates, labels and extra properties with their types), the\n"
    "bounding box in world coordinates and the radius statistics. Mesh (OBJ, PLY with faces,\n"
    "OFF, STL, glTF, 3DS ...): vertices, triangles, UV sets, vertex colours, materials with\n"
    "their colour and texture (a texture file that cannot be found is named as MISSING; info\n"
    "still succeeds), the bounds as 'sample' will see them and the up axis assumed. Primitive\n"
    "file (.dps, from 'amgsplat build'): per level primitives, texels, error, normalised error,\n"
    "cb and dpc times, atlas size. Decomposition (.amg, from 'amgsplat decompose'): the points,\n"
    "their attributes and the unknowns of every AMG level. Hierarchy (.hier): nodes, points,\n"
    "depth, leaf size. .amg, .dps and .hier also show the recorded frame of their source\n"
    "points. Image: size and channels.";

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

/* The framing sphere recorded with a representation (asp_frame); radius 0 means the file predates it. */
static void print_frame_text(const asp_frame *f)
{
    if (f && f->radius > 0)
        printf("frame       centre %.9g %.9g %.9g radius %.9g\n", f->center[0], f->center[1], f->center[2],
               f->radius);
    else
        printf("frame       not recorded\n");
}

static void print_frame_json(const asp_frame *f)
{
    if (f && f->radius > 0)
        printf(", \"frame\": {\"center\": [%.17g, %.17g, %.17g], \"radius\": %.17g}", f->center[0], f->center[1],
               f->center[2], f->radius);
    else
        printf(", \"frame\": null");
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
        printf(", \"points\": %llu, \"mean_radius\": %.9g, \"method\": \"%s\", \"texel_size\": %g",
               (unsigned long long)dps->source_points, dps->mean_radius, asp_prim_method_name(dps->desc.method),
               dps->desc.texel_size);
        print_frame_json(&dps->frame);
        printf(", \"levels\": [");
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
        print_frame_text(&dps->frame);
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
               "\"labels\": %s",
               c->count, asp_amg_has_input_normals(amg) ? "input" : "tangent", c->colors ? "true" : "false",
               c->radii ? "true" : "false", c->uvs ? "true" : "false", c->labels ? "true" : "false");
        print_frame_json(asp_amg_frame(amg));
        printf(", \"levels\": [");
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
        print_frame_text(asp_amg_frame(amg));
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

/* A .hier file (asp_hier_save): the point hierarchy's shape (thesis chapter 4). */
static int info_hier(const char *path, struct cli_env *env)
{
    asp_hier *h = NULL;
    asp_error err = {0};
    if (asp_hier_load(path, &env->ctx, &h, &err))
        return cli_fail(env, &err);
    cli_progress_end(env);
    if (env->json) {
        printf("{\"file\": ");
        cli_json_string(stdout, path);
        printf(", \"kind\": \"hier\", \"nodes\": %zu, \"points\": %zu, \"depth\": %u, \"leaf_size\": %zu",
               asp_hier_node_count(h), asp_hier_point_count(h), asp_hier_depth(h), asp_hier_leaf_size(h));
        print_frame_json(asp_hier_frame(h));
        printf("}\n");
    } else {
        printf("file        %s\nkind        point hierarchy (.hier)\nnodes       %zu\npoints      %zu\n"
               "depth       %u\nleaf size   %zu\n",
               path, asp_hier_node_count(h), asp_hier_point_count(h), asp_hier_depth(h), asp_hier_leaf_size(h));
        print_frame_text(asp_hier_frame(h));
    }
    asp_hier_destroy(h);
    return 0;
}

static int info_image(const char *path, const asp_file_type *type, struct cli_env *env)
{
    asp_image_header hd;
    asp_error err = {0};
    if (asp_image_probe(path, &hd, &err))
        return cli_fail(env, &err);
    static const char *const layout[] = {"", "grey", "grey+alpha", "RGB", "RGBA"};
    cli_progress_end(env);
    if (env->json) {
        printf("{\"file\": ");
        cli_json_string(stdout, path);
        printf(", \"kind\": \"image\", \"format\": \"%s\", \"width\": %u, \"height\": %u, \"channels\": %u}\n",
               type->format, hd.width, hd.height, hd.channels);
    } else {
        printf("file        %s\nkind        image (%s)\nsize        %ux%u\nchannels    %u (%s)\n", path, type->format,
               hd.width, hd.height, hd.channels, layout[hd.channels]);
    }
    return 0;
}

/* Mesh bounds in the y-up frame the loader turned it to: what 'sample' will produce. */
static void mesh_bounds(const asp_mesh *m, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            double x = m->origin[k] + m->positions[3 * v + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
}

static const char *up_name(asp_up_axis up)
{
    static const char *const names[] = {"y", "z", "x", "-y", "-z", "-x"};
    return (unsigned)up < 6 ? names[up] : "y";
}


/* Materials no triangle uses (assimp's OBJ reader always adds "DefaultMaterial") are left out: used_by[i]. */
static void print_mesh_text(const char *path, const asp_file_type *type, const asp_mesh *m, const double lo[3],
                            const double hi[3], const unsigned char *used_by, size_t used, size_t found,
                            size_t missing)
{
    printf("file        %s\nkind        mesh (%s)\n", path, type->format);
    printf("vertices    %zu\nfaces       %zu (triangles)\n", m->vertex_count, m->triangle_count);
    printf("uv sets     %u\ncolours     %s\n", m->uv_set_count, m->colors ? "per vertex" : "materials only");
    printf("materials   %zu\n", used);
    for (size_t i = 0; i < m->material_count; i++) {
        const asp_material *mt = &m->materials[i];
        if (!used_by[i])
            continue;
        printf("  %-20s", mt->name);
        if (mt->has_color)
            printf(" colour %.3g %.3g %.3g %.3g", mt->diffuse[0], mt->diffuse[1], mt->diffuse[2], mt->diffuse[3]);
        else
            printf(" colour (default)");
        if (mt->texture_missing)
            printf("  texture MISSING '%s'", mt->texture_path);
        else if (mt->texture.pixels)
            printf("  texture '%s' %ux%u", mt->texture_path, mt->texture.width, mt->texture.height);
        printf("\n");
    }
    printf("textures    %zu found, %zu missing\n", found, missing);
    for (size_t i = 0; i < m->material_count; i++)
        if (m->materials[i].texture_missing && used_by[i])
            printf("missing     %s (material '%s')\n", m->materials[i].texture_path, m->materials[i].name);
    printf("bbox min    %.9g %.9g %.9g\n", lo[0], lo[1], lo[2]);
    printf("bbox max    %.9g %.9g %.9g\n", hi[0], hi[1], hi[2]);
    printf("area        %.9g\n", asp_mesh_area(m));
    printf("up          %s (%s)\n", up_name(m->up), m->up_rule);
}

static void print_mesh_json(const char *path, const asp_file_type *type, const asp_mesh *m, const double lo[3],
                            const double hi[3], const unsigned char *used_by, size_t found, size_t missing)
{
    printf("{\"file\": ");
    cli_json_string(stdout, path);
    printf(", \"kind\": \"mesh\", \"format\": \"%s\", \"vertices\": %zu, \"faces\": %zu, \"uv_sets\": %u, "
           "\"vertex_colors\": %s, \"materials\": [",
           type->format, m->vertex_count, m->triangle_count, m->uv_set_count, m->colors ? "true" : "false");
    for (size_t i = 0, k = 0; i < m->material_count; i++) {
        const asp_material *mt = &m->materials[i];
        if (!used_by[i])
            continue;
        printf("%s{\"name\": ", k++ ? ", " : "");
        cli_json_string(stdout, mt->name);
        if (mt->has_color)
            printf(", \"color\": [%.6g, %.6g, %.6g, %.6g]", mt->diffuse[0], mt->diffuse[1], mt->diffuse[2],
                   mt->diffuse[3]);
        else
            printf(", \"color\": null");
        printf(", \"texture\": ");
        if (mt->texture_path[0])
            cli_json_string(stdout, mt->texture_path);
        else
            printf("null");
        printf(", \"texture_missing\": %s}", mt->texture_missing ? "true" : "false");
    }
    printf("], \"textures_found\": %zu, \"textures_missing\": [", found);
    for (size_t i = 0, k = 0; i < m->material_count; i++)
        if (m->materials[i].texture_missing && used_by[i]) {
            printf("%s", k++ ? ", " : "");
            cli_json_string(stdout, m->materials[i].texture_path);
        }
    printf("], \"textures_missing_count\": %zu, \"bbox_min\": [%.17g, %.17g, %.17g], "
           "\"bbox_max\": [%.17g, %.17g, %.17g], \"area\": %.9g",
           missing, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], asp_mesh_area(m));
    printf(", \"up\": \"%s\", \"up_rule\": ", up_name(m->up));
    cli_json_string(stdout, m->up_rule);
    printf("}\n");
}

/* A point file (or a PLY's vertices): counts, attributes, bounds, radii. */
static int info_points(const char *path, struct cli_env *env)
{
    asp_cloud *c = NULL;
    asp_error err = {0};
    if (asp_cloud_load(path, &env->ctx, &c, &err))
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
        print_json(path, c, lo, hi, r);
    else
        print_text(path, c, lo, hi, r);
    asp_cloud_destroy(c);
    return 0;
}

/* A mesh, loaded as 'sample' would but tolerating missing textures, so they can be named. */
static int info_mesh(const char *path, const asp_file_type *type, struct cli_env *env)
{
    asp_mesh *m = NULL;
    asp_error err = {0};
    if (asp_mesh_load(path, &(asp_mesh_load_desc){.allow_missing_textures = 1}, &env->ctx, &m, &err)) {
        if (strcmp(type->format, "ply") != 0)
            return cli_fail(env, &err);
        /* our PLY reader takes more than assimp's (double coordinates, odd types): show the vertices at least */
        cli_info(env, "amgsplat info: note: %s; describing its vertices as points", err.msg);
        return info_points(path, env);
    }
    double lo[3], hi[3];
    mesh_bounds(m, lo, hi);
    unsigned char *used_by = calloc(m->material_count, 1);
    if (!used_by) {
        asp_mesh_destroy(m);
        asp_error_set(&err, ASP_ENOMEM, "out of memory for %zu materials", m->material_count);
        return cli_fail(env, &err);
    }
    for (size_t t = 0; t < m->triangle_count; t++)
        used_by[m->material_ids[t]] = 1; /* ids are in range: asp_mesh_validate checked them */
    size_t used = 0, found = 0, missing = 0;
    for (size_t i = 0; i < m->material_count; i++) {
        if (!used_by[i])
            continue;
        used++;
        found += m->materials[i].texture.pixels != NULL;
        missing += m->materials[i].texture_missing != 0;
    }
    cli_progress_end(env);
    if (env->json)
        print_mesh_json(path, type, m, lo, hi, used_by, found, missing);
    else
        print_mesh_text(path, type, m, lo, hi, used_by, used, found, missing);
    free(used_by);
    asp_mesh_destroy(m);
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
    const char *path = argv[0];
    asp_file_type type;
    asp_error err = {0};
    if (asp_file_recognise(path, &type, &err))
        return cli_fail(env, &err);
    switch (type.kind) {
    case ASP_FILE_DPS:
        return info_dps(path, env);
    case ASP_FILE_AMG:
        return info_amg(path, env);
    case ASP_FILE_HIER:
        return info_hier(path, env);
    case ASP_FILE_IMAGE:
        return info_image(path, &type, env);
    case ASP_FILE_MESH:
        return info_mesh(path, &type, env);
    case ASP_FILE_POINTS:
    case ASP_FILE_UNKNOWN:
        break;
    }
    return info_points(path, env);
}
