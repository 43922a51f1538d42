/*
 * amgsplat sample: turn a triangle mesh into a point set (vertices as in
 * QSplat, area-stratified samples, or the voxel sampler of Schwarz 2004 3.1).
 */
#include <math.h>
#include <stdio.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat sample MESH -o OUT.ply [--method area|vertices|voxel] [--points N] [--grid n]\n"
    "                       [--texture FILE] [--seed S] [--radius-scale X] [--up AXIS] [--uvs] [--labels]\n"
    "                       [--json]\n"
    "\n"
    "Samples a mesh (OBJ+MTL, PLY, OFF, STL, glTF/GLB, 3DS, ... via assimp) to points with\n"
    "normals, radii that close all holes, and colours from the texture, vertex colours or\n"
    "material. Methods: area (default) spreads N points evenly over the surface; vertices\n"
    "makes one point per vertex; voxel makes one point per occupied cell of an n^3 grid.\n"
    "--texture applies an image to materials without a texture (e.g. Spot's OBJ).\n"
    "The points come out y-up, as render shows them by default. The file's own\n"
    "coordinates are taken as y-up for every format (3DS too: assimp's z-up turn is\n"
    "undone); --up z (or x, -y ...) names the file's up axis for files that differ.";

/*
 * Memory per voxel sample: two 16-byte cell hits while sorting plus the
 * cloud's position, normal, radius and colour (about 32 bytes), rounded up.
 */
#define VOXEL_BYTES_PER_POINT 64.0

/*
 * --grid is bounded by what the machine can hold (issue #13: --grid 10000 on
 * a 4-triangle mesh took 6.4 GB). The estimate is a lower bound: a surface
 * of area A crosses at least A / h^2 cells of side h = 2 D / n, D the largest
 * distance of a vertex from the mean vertex per axis (the library's cube,
 * Schwarz 2004 3.1.1). Refused when it needs more than half the memory free
 * now, or more points than a cloud can index.
 */
static int check_voxel_grid(const struct cli_env *env, const char *path, const asp_mesh *m, size_t grid)
{
    double mean[3] = {0, 0, 0}, dmax = 0;
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int a = 0; a < 3; a++)
            mean[a] += m->positions[3 * v + a];
    for (int a = 0; a < 3; a++)
        mean[a] /= (double)(m->vertex_count ? m->vertex_count : 1);
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int a = 0; a < 3; a++)
            dmax = fmax(dmax, fabs(m->positions[3 * v + a] - mean[a]));
    if (!(dmax > 0))
        return 0; // the library names the degenerate mesh
    double h = 2 * dmax / (double)grid, points = asp_mesh_area(m) / (h * h), bytes = points * VOXEL_BYTES_PER_POINT;
    long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    double avail = pages > 0 && page > 0 ? (double)pages * (double)page : INFINITY;
    if (points >= 4294967295.0 || bytes > 0.5 * avail) {
        asp_error e = {0};
        asp_error_set(&e, ASP_EINVAL,
                      "--grid %zu on '%s' makes at least %.3g points needing %.3g GB; this machine has %.3g GB free "
                      "(at most half used, and fewer than 2^32 points); try --grid %.0f or less",
                      grid, path, points, bytes / 1e9, avail / 1e9,
                      floor((double)grid * sqrt(fmin(4294967294.0, 0.5 * avail / VOXEL_BYTES_PER_POINT) / points)));
        return cli_fail(env, &e);
    }
    return 0;
}

int cmd_sample(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *method_name = "area", *texture = NULL, *up = NULL;
    size_t points = 100000, grid = 256, seed = 0;
    double radius_scale = 1.0;
    int uvs = 0, labels = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output point file (.ply, .xyz)"},
        {"method", 'm', CLI_STRING, &method_name, "M", "area (default), vertices or voxel"},
        {"points", 'n', CLI_SIZE, &points, "N", "area: number of points (default 100000; 2e5, 1M accepted)"},
        {"grid", 'g', CLI_SIZE, &grid, "n", "voxel: cells per axis (default 256)"},
        {"texture", 't', CLI_STRING, &texture, "FILE", "texture for materials that have none"},
        {"seed", 's', CLI_SIZE, &seed, "S", "area: sequence seed (default 0)"},
        {"radius-scale", 0, CLI_DOUBLE, &radius_scale, "X", "multiply every radius (default 1)"},
        {"up", 0, CLI_STRING, &up, "AXIS", "the file's up axis: y (default), z, x, -y, -z or -x"},
        {"uvs", 0, CLI_FLAG, &uvs, NULL, "also write texture coordinates"},
        {"labels", 0, CLI_FLAG, &labels, NULL, "also write the source triangle of each point"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one mesh file, got %d; see 'amgsplat sample -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o OUT.ply");
    asp_error err = {0};
    asp_sample_method method;
    if (asp_sample_method_parse(method_name, &method, &err))
        return cli_usage_error(env, "%s", err.msg);
    if (points < 2 || points >= 4294967295u)
        return cli_usage_error(env, "--points must be 2 to 4294967294, got %zu", points);
    if (grid < 1 || grid > (1u << 20))
        return cli_usage_error(env, "--grid must be 1 to 1048576, got %zu", grid);
    if (!(radius_scale > 0.0) || radius_scale > 1e6)
        return cli_usage_error(env, "--radius-scale expects a value in (0, 1e6], got %g", radius_scale);
    {
        const char *const inputs[] = {argv[0], texture};
        if (cli_check_output(env, output, NULL, 0, inputs, 2))
            return 2;
    }

    asp_up_axis up_axis = ASP_UP_Y;
    if (up && cli_parse_up(up, &up_axis) != 0)
        return cli_usage_error(env, "--up expects x, y, z, -x, -y or -z, got '%s'", up);

    double t0 = asp_time_now();
    asp_mesh *mesh = NULL;
    if (asp_mesh_load(argv[0], &(asp_mesh_load_desc){.texture_override = texture, .up = up_axis}, &env->ctx, &mesh,
                      &err))
        return cli_fail(env, &err);
    double t_load = asp_time_now() - t0;
    if (method == ASP_SAMPLE_VOXEL && (rc = check_voxel_grid(env, argv[0], mesh, grid)) != 0) {
        asp_mesh_destroy(mesh);
        return rc;
    }
    asp_sample_desc desc = {.method = method, .points = points, .grid = (uint32_t)grid, .seed = seed,
                            .radius_scale = (float)radius_scale, .with_uvs = uvs, .with_labels = labels};
    asp_cloud *cloud = NULL;
    asp_sample_stats st = {0};
    if (asp_sample_mesh(mesh, &desc, &env->ctx, &cloud, &st, &err)) {
        asp_mesh_destroy(mesh);
        return cli_fail(env, &err);
    }
    size_t nv = mesh->vertex_count, nt = mesh->triangle_count;
    asp_mesh_destroy(mesh);
    char comment[160];
    snprintf(comment, sizeof comment, "amgsplat sample --method %s (%zu points)", method_name, cloud->count);
    asp_cloud_add_comment(cloud, comment, NULL);
    double t1 = asp_time_now();
    rc = asp_cloud_save(cloud, output, NULL, &err);
    double t_save = asp_time_now() - t1;
    int has_colors = cloud->colors != NULL;
    asp_cloud_destroy(cloud);
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    if (env->json) {
        cJSON *o = cJSON_CreateObject(), *sec = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "mesh", argv[0]);
        cJSON_AddStringToObject(o, "output", output);
        cJSON_AddStringToObject(o, "method", method_name);
        cJSON_AddNumberToObject(o, "vertices", (double)nv);
        cJSON_AddNumberToObject(o, "triangles", (double)nt);
        cJSON_AddNumberToObject(o, "points", (double)st.points);
        cJSON_AddItemToObject(o, "area", cli_json_number("%.9g", st.area));
        cJSON_AddItemToObject(o, "mean_radius", cli_json_number("%.9g", st.mean_radius));
        cJSON_AddBoolToObject(o, "colors", has_colors);
        cJSON_AddItemToObject(sec, "load", cli_json_number("%.4f", t_load));
        cJSON_AddItemToObject(sec, "sample", cli_json_number("%.4f", st.sample_seconds));
        cJSON_AddItemToObject(sec, "radii", cli_json_number("%.4f", st.radii_seconds));
        cJSON_AddItemToObject(sec, "save", cli_json_number("%.4f", t_save));
        cJSON_AddItemToObject(o, "seconds", sec);
        return cli_json_print(env, o);
    } else if (!env->quiet) {
        printf("%s: %zu points (%s) from %zu triangles, area %.6g, mean radius %.4g%s, %.2f s\n", output, st.points,
               method_name, nt, st.area, st.mean_radius, has_colors ? ", coloured" : "",
               t_load + st.sample_seconds + st.radii_seconds + t_save);
    }
    return 0;
}
