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
    "Point file (.ply, .xyz, .pts, .txt, .las): points and faces, the attributes present (normals,\n"
    "colours, radii, texture coordinates, labels and extra properties with their types), the\n"
    "bounding box in world coordinates and the radius statistics; for LAS also the version,\n"
    "point format, header counts, scale, offset, header bounds and VLRs. Mesh (OBJ, PLY with faces,\n"
    "OFF, STL, glTF, 3DS ...): vertices, triangles, UV sets, vertex colours, materials with\n"
    "their colour and texture (a texture file that cannot be found is named as MISSING; info\n"
    "still succeeds), the bounds as 'sample' will see them and the up axis assumed. Primitive\n"
    "file (.dps, from 'amgsplat build'): per level primitives, texels, error, normalised error,\n"
    "cb and dpc times, atlas size and kind (domain primitives or billboards). Decomposition\n"
    "(.amg, from 'amgsplat decompose'): the points, their attributes and the unknowns of every\n"
    "AMG level. Hierarchy (.hier): nodes, points,\n"
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

/* The LAS header of a cloud read from LAS: version, format, counts, scale and offset, the header's bounds. */
static void print_las_text(const asp_las_meta *m)
{
    printf("las         version 1.%u, point format %u, %u-byte records, %llu points in the header\n",
           m->version_minor, m->point_format, m->record_length, (unsigned long long)m->point_count);
    printf("las scale   %.15g %.15g %.15g\n", m->scale[0], m->scale[1], m->scale[2]);
    printf("las offset  %.15g %.15g %.15g\n", m->offset[0], m->offset[1], m->offset[2]);
    printf("las bounds  %.15g %.15g %.15g  to  %.15g %.15g %.15g (header)\n", m->min[0], m->min[1], m->min[2],
           m->max[0], m->max[1], m->max[2]);
    printf("las system  '%s', software '%s', created day %u of %u\n", m->system_id, m->software, m->creation_day,
           m->creation_year);
    for (size_t i = 0; i < m->vlr_count; i++)
        printf("las %s '%s' %u: %zu bytes, '%s'\n", m->vlrs[i].extended ? "evlr" : "vlr ", m->vlrs[i].user_id,
               m->vlrs[i].record_id, m->vlrs[i].size, m->vlrs[i].description);
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
    if (c->las)
        print_las_text(c->las);
    if (c->radii)
        printf("radius      mean %.6g min %.6g max %.6g\n", r.mean, r.min, r.max);
    for (size_t i = 0; i < c->comment_count; i++)
        printf("comment     %s\n", c->comments[i]);
    for (size_t i = 0; i < c->obj_info_count; i++)
        printf("obj_info    %s\n", c->obj_info[i]);
}

static cJSON *las_json(const asp_las_meta *m)
{
    cJSON *o = cJSON_CreateObject(), *v = cJSON_CreateArray(), *br = cJSON_CreateArray();
    char version[8];
    snprintf(version, sizeof version, "1.%u", m->version_minor);
    cJSON_AddStringToObject(o, "version", version);
    cJSON_AddNumberToObject(o, "point_format", m->point_format);
    cJSON_AddNumberToObject(o, "record_length", m->record_length);
    cJSON_AddNumberToObject(o, "point_count", (double)m->point_count);
    for (int k = 0; k < 15; k++)
        cJSON_AddItemToArray(br, cJSON_CreateNumber((double)m->points_by_return[k]));
    cJSON_AddItemToObject(o, "points_by_return", br);
    cJSON_AddItemToObject(o, "scale", cli_json_doubles(m->scale, 3));
    cJSON_AddItemToObject(o, "offset", cli_json_doubles(m->offset, 3));
    cJSON_AddItemToObject(o, "min", cli_json_doubles(m->min, 3));
    cJSON_AddItemToObject(o, "max", cli_json_doubles(m->max, 3));
    cJSON_AddStringToObject(o, "system_id", m->system_id);
    cJSON_AddStringToObject(o, "software", m->software);
    cJSON_AddNumberToObject(o, "creation_day", m->creation_day);
    cJSON_AddNumberToObject(o, "creation_year", m->creation_year);
    for (size_t i = 0; i < m->vlr_count; i++) {
        cJSON *r = cJSON_CreateObject();
        cJSON_AddStringToObject(r, "user_id", m->vlrs[i].user_id);
        cJSON_AddNumberToObject(r, "record_id", m->vlrs[i].record_id);
        cJSON_AddStringToObject(r, "description", m->vlrs[i].description);
        cJSON_AddBoolToObject(r, "extended", m->vlrs[i].extended);
        cJSON_AddNumberToObject(r, "bytes", (double)m->vlrs[i].size);
        cJSON_AddItemToArray(v, r);
    }
    cJSON_AddItemToObject(o, "vlrs", v);
    return o;
}

static int print_json(const struct cli_env *env, const char *path, const asp_cloud *c, const double lo[3],
                      const double hi[3], struct radius_stats r)
{
    cJSON *o = cJSON_CreateObject(), *props = cJSON_CreateArray(), *comments = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "file", path);
    cJSON_AddNumberToObject(o, "points", (double)c->count);
    cJSON_AddNumberToObject(o, "faces", (double)c->face_count);
    cJSON_AddStringToObject(o, "position_type", asp_scalar_name(c->position_type));
    cJSON_AddBoolToObject(o, "normals", c->normals != NULL);
    cJSON_AddBoolToObject(o, "colors", c->colors != NULL);
    cJSON_AddBoolToObject(o, "radii", c->radii != NULL);
    cJSON_AddBoolToObject(o, "uvs", c->uvs != NULL);
    cJSON_AddBoolToObject(o, "labels", c->labels != NULL);
    for (size_t i = 0; i < c->property_count; i++) {
        cJSON *p = cJSON_CreateObject();
        cJSON_AddStringToObject(p, "name", c->properties[i].name);
        cJSON_AddStringToObject(p, "type", asp_scalar_name(c->properties[i].type));
        cJSON_AddItemToArray(props, p);
    }
    cJSON_AddItemToObject(o, "properties", props);
    cJSON_AddItemToObject(o, "origin", cli_json_doubles(c->origin, 3));
    cJSON_AddItemToObject(o, "bbox_min", cli_json_doubles(lo, 3));
    cJSON_AddItemToObject(o, "bbox_max", cli_json_doubles(hi, 3));
    if (c->radii) {
        cJSON_AddItemToObject(o, "radius_mean", cli_json_number("%.9g", r.mean));
        cJSON_AddItemToObject(o, "radius_min", cli_json_number("%.9g", r.min));
        cJSON_AddItemToObject(o, "radius_max", cli_json_number("%.9g", r.max));
    }
    for (size_t i = 0; i < c->comment_count; i++)
        cJSON_AddItemToArray(comments, cJSON_CreateString(c->comments[i]));
    cJSON_AddItemToObject(o, "comments", comments);
    if (c->las)
        cJSON_AddItemToObject(o, "las", las_json(c->las));
    return cli_json_print(env, o);
}

static const char *up_name(asp_up_axis up);

/* The framing sphere recorded with a representation (asp_frame); radius 0 means the file predates it. */
static void print_frame_text(const asp_frame *f)
{
    if (f && f->radius > 0)
        printf("frame       centre %.9g %.9g %.9g radius %.9g box %.6g %.6g %.6g up %s\n", f->center[0],
               f->center[1], f->center[2], f->radius, 2 * f->half[0], 2 * f->half[1], 2 * f->half[2],
               up_name(f->up));
    else
        printf("frame       not recorded\n");
}

static void add_frame_json(cJSON *o, const asp_frame *f)
{
    if (f && f->radius > 0) {
        cJSON *fr = cJSON_CreateObject();
        cJSON_AddItemToObject(fr, "center", cli_json_doubles(f->center, 3));
        cJSON_AddItemToObject(fr, "radius", cli_json_number("%.17g", f->radius));
        double box[3] = {2 * f->half[0], 2 * f->half[1], 2 * f->half[2]};
        cJSON_AddItemToObject(fr, "box", cli_json_doubles(box, 3)); // 0 0 0: not recorded (older files)
        cJSON_AddStringToObject(fr, "up", up_name(f->up));
        cJSON_AddItemToObject(o, "frame", fr);
    } else {
        cJSON_AddNullToObject(o, "frame");
    }
}

/* Every build option a .dps records (version 3 stores them all; older files show 0 for the later ones). */
static cJSON *dps_build_json(const asp_prim_desc *d)
{
    cJSON *b = cJSON_CreateObject();
    cJSON_AddItemToObject(b, "tau", cli_json_number("%g", d->tau));
    cJSON_AddItemToObject(b, "texel_size", cli_json_number("%g", d->texel_size));
    cJSON_AddNumberToObject(b, "max_texture", d->max_texture);
    cJSON_AddStringToObject(b, "method", asp_prim_method_name(d->method));
    cJSON_AddStringToObject(b, "shape", asp_prim_shape_name(d->shape));
    cJSON_AddItemToObject(b, "width", cli_json_number("%g", d->width));
    cJSON_AddStringToObject(b, "normalise", asp_prim_normalise_name(d->normalise));
    cJSON_AddBoolToObject(b, "unweighted", d->unweighted);
    cJSON_AddBoolToObject(b, "project_radii", d->project_radii);
    cJSON_AddBoolToObject(b, "no_extend_color", d->no_extend_color);
    cJSON_AddBoolToObject(b, "normal_map", d->normal_map);
    cJSON_AddItemToObject(b, "neighbour_fraction", cli_json_number("%g", d->neighbour_fraction));
    cJSON_AddBoolToObject(b, "merge", d->merge);
    cJSON_AddItemToObject(b, "merge_flatness", cli_json_number("%g", d->merge_flatness));
    cJSON_AddItemToObject(b, "merge_angle", cli_json_number("%g", d->merge_angle));
    cJSON_AddNumberToObject(b, "padding", d->padding);
    cJSON_AddBoolToObject(b, "normalise_color", d->normalise_color);
    cJSON_AddBoolToObject(b, "no_model_colors", d->no_model_colors);
    cJSON_AddItemToObject(b, "brightness", cli_json_number("%g", d->brightness));
    cJSON_AddStringToObject(b, "domains", d->strict == 2 ? "both" : d->strict ? "strict" : "thresholded");
    cJSON_AddItemToObject(b, "enlarge", cli_json_number("%g", d->enlarge));
    return b;
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
    int rc = 0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject(), *levels = cJSON_CreateArray();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddStringToObject(o, "source", dps->source);
        cJSON_AddNumberToObject(o, "points", (double)dps->source_points);
        cJSON_AddItemToObject(o, "mean_radius", cli_json_number("%.9g", dps->mean_radius));
        cJSON_AddStringToObject(o, "method", asp_prim_method_name(dps->desc.method));
        cJSON_AddItemToObject(o, "texel_size", cli_json_number("%g", dps->desc.texel_size));
        add_frame_json(o, &dps->frame);
        cJSON_AddItemToObject(o, "build", dps_build_json(&dps->desc));
        cJSON_AddBoolToObject(o, "links", asp_dps_has_links(dps)); // a cut across levels is possible (issue 18)
        for (size_t i = 0; i < nl; i++) {
            cJSON *l = cJSON_CreateObject();
            cJSON_AddNumberToObject(l, "level", rows[i].level);
            cJSON_AddStringToObject(l, "name", rows[i].name);
            cJSON_AddNumberToObject(l, "primitives", (double)rows[i].primitives);
            cJSON_AddNumberToObject(l, "texels", (double)rows[i].texels);
            cJSON_AddItemToObject(l, "error", cli_json_number("%.9g", rows[i].error));
            cJSON_AddItemToObject(l, "normalised_error", cli_json_number("%.6g", rows[i].error_norm));
            cJSON_AddItemToObject(l, "cb_seconds", cli_json_number("%.4f", rows[i].t_basis));
            cJSON_AddItemToObject(l, "dpc_seconds", cli_json_number("%.4f", rows[i].t_construct));
            cJSON_AddNumberToObject(l, "skipped", rows[i].skipped);
            cJSON_AddNumberToObject(l, "degenerate", rows[i].degenerate);
            cJSON_AddNumberToObject(l, "capped", rows[i].capped);
            cJSON_AddNumberToObject(l, "merges", rows[i].merges);
            cJSON_AddItemToObject(l, "atlas",
                                  cJSON_CreateIntArray((const int[]){(int)rows[i].atlas_width, (int)rows[i].atlas_height},
                                                       2));
            cJSON_AddNumberToObject(l, "neighbour_pairs", (double)rows[i].neighbour_pairs);
            cJSON_AddBoolToObject(l, "normal_map", rows[i].normal_map);
            cJSON_AddStringToObject(l, "atlas_format", rows[i].compressed ? "bc3" : "rgba8");
            // what the level's primitives are: domain primitives, or billboard-cloud planes (atlas flags bit 2)
            cJSON_AddStringToObject(l, "kind", dps->levels[i].billboards ? "billboards" : "domains");
            cJSON_AddNumberToObject(l, "gpu_bytes", (double)asp_dps_level_gpu_bytes(&dps->levels[i], NULL));
            cJSON_AddBoolToObject(l, "strict", dps->levels[i].strict != 0);
            cJSON_AddNumberToObject(l, "links", (double)dps->levels[i].link_total);
            cJSON_AddItemToArray(levels, l);
        }
        cJSON_AddItemToObject(o, "levels", levels);
        rc = cli_json_print(env, o);
    } else {
        printf("file        %s\nsource      %s (%llu points, mean radius %.6g)\n", path, dps->source,
               (unsigned long long)dps->source_points, dps->mean_radius);
        printf("textures    %s, texel size %g\n", asp_prim_method_name(dps->desc.method), dps->desc.texel_size);
        print_frame_text(&dps->frame);
        const asp_prim_desc *d = &dps->desc;
        printf("build       tau %g, max texture %u, %s/%s width %g, normalise %s%s, %s domains, padding %u, "
               "neighbours %g%s%s%s%s%s%s, brightness %g, enlarge %g%%\n",
               d->tau, d->max_texture, asp_prim_method_name(d->method), asp_prim_shape_name(d->shape), d->width,
               asp_prim_normalise_name(d->normalise), d->normalise_color ? " (colour too)" : "",
               d->strict == 2 ? "both" : d->strict ? "strict" : "thresholded", d->padding, d->neighbour_fraction,
               d->unweighted ? ", unweighted" : "", d->project_radii ? ", projected radii" : "",
               d->no_extend_color ? ", no colour extension" : "", d->normal_map ? ", normal maps" : "",
               d->merge ? ", merged" : "", d->no_model_colors ? ", grey points" : "", d->brightness, d->enlarge);
        printf("links       %s\n", asp_dps_has_links(dps) ? "yes: levels can be mixed by view (render --renderer cut)"
                                    : dps->level_count > 1 ? "none (rebuild for a cut across levels)" : "one level");
        // GPU bytes: what the renderer allocates (asp_dps_level_gpu_bytes; BC3 atlases at 1 byte a texel)
        printf("level  name   primitives    texels        error  normalised   cb (s)  dpc (s)  atlas          "
               "GPU bytes  kind\n");
        for (size_t i = 0; i < nl; i++) {
            char atlas[40];
            snprintf(atlas, sizeof atlas, "%ux%u %s", rows[i].atlas_width, rows[i].atlas_height,
                     rows[i].compressed ? "BC3" : "RGBA8");
            printf("%5u  %-5s %11zu %9llu  %11.6g  %10.3f  %7.3f  %7.3f  %-15s %9zu  %s\n", rows[i].level,
                   rows[i].name, rows[i].primitives, (unsigned long long)rows[i].texels, rows[i].error,
                   rows[i].error_norm, rows[i].t_basis, rows[i].t_construct, atlas,
                   asp_dps_level_gpu_bytes(&dps->levels[i], NULL),
                   dps->levels[i].billboards ? "billboards" : "domains");
        }
    }
    asp_dps_destroy(dps);
    return rc;
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
    int rc = 0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject(), *levels = cJSON_CreateArray();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddNumberToObject(o, "points", (double)c->count);
        cJSON_AddStringToObject(o, "normals", asp_amg_has_input_normals(amg) ? "input" : "tangent");
        cJSON_AddBoolToObject(o, "colors", c->colors != NULL);
        cJSON_AddBoolToObject(o, "radii", c->radii != NULL);
        cJSON_AddBoolToObject(o, "uvs", c->uvs != NULL);
        cJSON_AddBoolToObject(o, "labels", c->labels != NULL);
        add_frame_json(o, asp_amg_frame(amg));
        for (size_t l = 0; l < nl; l++) {
            char name[32];
            snprintf(name, sizeof name, l == nl - 1 ? "L" : "L-%zu", nl - 1 - l);
            cJSON *lv = cJSON_CreateObject();
            cJSON_AddNumberToObject(lv, "level", (double)l);
            cJSON_AddStringToObject(lv, "name", name);
            cJSON_AddNumberToObject(lv, "unknowns", (double)asp_amg_level_size(amg, l));
            cJSON_AddItemToArray(levels, lv);
        }
        cJSON_AddItemToObject(o, "levels", levels);
        rc = cli_json_print(env, o);
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
    return rc;
}

/* A streamed .hier (issue 28): its header and node table, never its points. */
static int info_streamed_hier(const char *path, struct cli_env *env)
{
    asp_ooc *h = NULL;
    asp_error err = {0};
    if (asp_ooc_open(path, &env->ctx, &h, &err))
        return cli_fail(env, &err);
    cli_progress_end(env);
    const asp_ooc_node *root = asp_ooc_nodes(h);
    int rc = 0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddStringToObject(o, "kind", "hier");
        cJSON_AddStringToObject(o, "layout", "streamed");
        cJSON_AddNumberToObject(o, "nodes", (double)asp_ooc_node_count(h));
        cJSON_AddNumberToObject(o, "points", (double)asp_ooc_point_count(h));
        cJSON_AddNumberToObject(o, "depth", asp_ooc_depth(h));
        cJSON_AddNumberToObject(o, "root_points", root->point_count);
        add_frame_json(o, asp_ooc_frame(h));
        rc = cli_json_print(env, o);
    } else {
        printf("file        %s\nkind        point hierarchy (.hier, streamed layout)\nnodes       %zu\n"
               "points      %llu\ndepth       %u\nroot points %u\n",
               path, asp_ooc_node_count(h), (unsigned long long)asp_ooc_point_count(h), asp_ooc_depth(h),
               root->point_count);
        print_frame_text(asp_ooc_frame(h));
    }
    asp_ooc_close(h);
    return rc;
}

/* A .hier file (asp_hier_save): the point hierarchy's shape (thesis chapter 4). */
static int info_hier(const char *path, struct cli_env *env)
{
    asp_hier *h = NULL;
    asp_error err = {0};
    if (asp_ooc_probe(path) == 1)
        return info_streamed_hier(path, env);
    if (asp_hier_load(path, &env->ctx, &h, &err))
        return cli_fail(env, &err);
    cli_progress_end(env);
    int rc = 0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddStringToObject(o, "kind", "hier");
        cJSON_AddNumberToObject(o, "nodes", (double)asp_hier_node_count(h));
        cJSON_AddNumberToObject(o, "points", (double)asp_hier_point_count(h));
        cJSON_AddNumberToObject(o, "depth", asp_hier_depth(h));
        cJSON_AddNumberToObject(o, "leaf_size", (double)asp_hier_leaf_size(h));
        add_frame_json(o, asp_hier_frame(h));
        rc = cli_json_print(env, o);
    } else {
        printf("file        %s\nkind        point hierarchy (.hier)\nnodes       %zu\npoints      %zu\n"
               "depth       %u\nleaf size   %zu\n",
               path, asp_hier_node_count(h), asp_hier_point_count(h), asp_hier_depth(h), asp_hier_leaf_size(h));
        print_frame_text(asp_hier_frame(h));
    }
    asp_hier_destroy(h);
    return rc;
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
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddStringToObject(o, "kind", "image");
        cJSON_AddStringToObject(o, "format", type->format);
        cJSON_AddNumberToObject(o, "width", hd.width);
        cJSON_AddNumberToObject(o, "height", hd.height);
        cJSON_AddNumberToObject(o, "channels", hd.channels);
        return cli_json_print(env, o);
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

static int print_mesh_json(const struct cli_env *env, const char *path, const asp_file_type *type,
                           const asp_mesh *m, const double lo[3], const double hi[3], const unsigned char *used_by,
                           size_t found, size_t missing)
{
    cJSON *o = cJSON_CreateObject(), *mats = cJSON_CreateArray(), *miss = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "file", path);
    cJSON_AddStringToObject(o, "kind", "mesh");
    cJSON_AddStringToObject(o, "format", type->format);
    cJSON_AddNumberToObject(o, "vertices", (double)m->vertex_count);
    cJSON_AddNumberToObject(o, "faces", (double)m->triangle_count);
    cJSON_AddNumberToObject(o, "uv_sets", m->uv_set_count);
    cJSON_AddBoolToObject(o, "vertex_colors", m->colors != NULL);
    for (size_t i = 0; i < m->material_count; i++) {
        const asp_material *mt = &m->materials[i];
        if (!used_by[i])
            continue;
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "name", mt->name);
        if (mt->has_color) {
            cJSON *col = cJSON_CreateArray();
            for (int k = 0; k < 4; k++)
                cJSON_AddItemToArray(col, cli_json_number("%.6g", mt->diffuse[k]));
            cJSON_AddItemToObject(j, "color", col);
        } else {
            cJSON_AddNullToObject(j, "color");
        }
        if (mt->texture_path[0])
            cJSON_AddStringToObject(j, "texture", mt->texture_path);
        else
            cJSON_AddNullToObject(j, "texture");
        cJSON_AddBoolToObject(j, "texture_missing", mt->texture_missing);
        cJSON_AddItemToArray(mats, j);
    }
    cJSON_AddItemToObject(o, "materials", mats);
    cJSON_AddNumberToObject(o, "textures_found", (double)found);
    for (size_t i = 0; i < m->material_count; i++)
        if (m->materials[i].texture_missing && used_by[i])
            cJSON_AddItemToArray(miss, cJSON_CreateString(m->materials[i].texture_path));
    cJSON_AddItemToObject(o, "textures_missing", miss);
    cJSON_AddNumberToObject(o, "textures_missing_count", (double)missing);
    cJSON_AddItemToObject(o, "bbox_min", cli_json_doubles(lo, 3));
    cJSON_AddItemToObject(o, "bbox_max", cli_json_doubles(hi, 3));
    cJSON_AddItemToObject(o, "area", cli_json_number("%.9g", asp_mesh_area(m)));
    cJSON_AddStringToObject(o, "up", up_name(m->up));
    cJSON_AddStringToObject(o, "up_rule", m->up_rule);
    return cli_json_print(env, o);
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
    int rc = 0;
    if (env->json)
        rc = print_json(env, path, c, lo, hi, r);
    else
        print_text(path, c, lo, hi, r);
    asp_cloud_destroy(c);
    return rc;
}

/* A mesh, loaded as 'sample' would but tolerating missing textures, so they can be named. */
/*
 * A glTF whose vertex data the mesh reader cannot decode (export's compact GLB: issue #32), or one of
 * points only: what its JSON says, checked as asp_mesh_load checks it, so every file amgsplat writes
 * is one info describes.
 */
static int info_gltf_summary(const char *path, const asp_file_type *type, const asp_gltf_summary *gs,
                             struct cli_env *env)
{
    const asp_gltf_summary s = *gs;
    asp_error err = {0};
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        if (!o || !cJSON_AddStringToObject(o, "file", path) || !cJSON_AddStringToObject(o, "format", type->format) ||
            !cJSON_AddStringToObject(o, "kind", "gltf") || !cJSON_AddNumberToObject(o, "primitives", (double)s.primitives) ||
            !cJSON_AddNumberToObject(o, "points", (double)s.points) ||
            !cJSON_AddNumberToObject(o, "vertices", (double)s.vertices) ||
            !cJSON_AddStringToObject(o, "extensions_required", s.required) ||
            !cJSON_AddBoolToObject(o, "mesh_reader_decodes", s.decodable)) {
            cJSON_Delete(o);
            asp_error_set(&err, ASP_ENOMEM, "out of memory describing '%s'", path);
            return cli_fail(env, &err);
        }
        return cli_json_print(env, o);
    }
    printf("%s: %s, glTF 2.0, %zu primitives: %zu points, %zu other vertices\n", path, type->format, s.primitives,
           s.points, s.vertices);
    if (!s.decodable)
        printf("  requires %s: described from its JSON; the mesh reader (assimp) cannot decode it, so sample, "
               "render and decompose refuse it (export --plain writes plain glTF)\n", s.required);
    else
        printf("  points only, no triangles: described from its JSON (a point GLB is a viewer's file, not a mesh "
               "to sample)%s%s\n", s.required[0] ? "; requires " : "", s.required);
    return 0;
}

static int info_mesh(const char *path, const asp_file_type *type, struct cli_env *env)
{
    asp_mesh *m = NULL;
    asp_error err = {0};
    if (asp_mesh_load(path, &(asp_mesh_load_desc){.allow_missing_textures = 1}, &env->ctx, &m, &err)) {
        asp_gltf_summary gs;
        asp_error e2 = {0};
        // a glTF of points only (export's point GLB) or one the mesh reader cannot decode: described from its JSON
        if ((strcmp(type->format, "glb") == 0 || strcmp(type->format, "gltf") == 0) &&
            asp_gltf_summary_load(path, &env->ctx, &gs, &e2) == 0 &&
            (!gs.decodable || (gs.points > 0 && gs.vertices == 0)))
            return info_gltf_summary(path, type, &gs, env);
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
    int rc = 0;
    if (env->json)
        rc = print_mesh_json(env, path, type, m, lo, hi, used_by, found, missing);
    else
        print_mesh_text(path, type, m, lo, hi, used_by, used, found, missing);
    free(used_by);
    asp_mesh_destroy(m);
    return rc;
}

/* A scene of instances: parsed and validated, sources named, nothing loaded (instances.h). */
static int info_scene(const char *path, struct cli_env *env)
{
    asp_instance_scene s;
    asp_error err = {0};
    if (asp_instance_scene_read(path, &s, &err))
        return cli_fail(env, &err);
    int rc = 0;
    if (env->json) {
        cJSON *j = cJSON_CreateObject(), *srcs = cJSON_CreateArray();
        cJSON_AddStringToObject(j, "file", path);
        cJSON_AddStringToObject(j, "kind", "scene");
        cJSON_AddNumberToObject(j, "instances", (double)s.instance_count);
        for (size_t i = 0; i < s.source_count; i++) {
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "source", s.sources[i].name);
            cJSON_AddNumberToObject(o, "instances", (double)asp_instance_scene_count(&s, i));
            cJSON_AddItemToArray(srcs, o);
        }
        cJSON_AddItemToObject(j, "sources", srcs);
        cJSON_AddBoolToObject(j, "camera", s.camera.given);
        rc = cli_json_print(env, j);
    } else {
        printf("%s: scene of %zu instances of %zu source%s%s\n", path, s.instance_count, s.source_count,
               s.source_count == 1 ? "" : "s", s.camera.given ? ", with a camera" : "");
        for (size_t i = 0; i < s.source_count; i++)
            printf("  %s: %zu instances\n", s.sources[i].name, asp_instance_scene_count(&s, i));
    }
    asp_instance_scene_release(&s);
    return rc;
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
    case ASP_FILE_SCENE:
        return info_scene(path, env);
    case ASP_FILE_POINTS:
    case ASP_FILE_UNKNOWN:
        break;
    }
    return info_points(path, env);
}
