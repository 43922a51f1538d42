/*
 * amgsplat export IN -o DIR --tiles: a point set or .hier as a streamed 3D Tiles 1.1 tileset
 * (asp_tiles_export_hier, issue 32), for the web page's streaming mode and any 3D Tiles client.
 * docs/web.md says how to serve it.
 */
#include <stdio.h>

#include <cjson/cJSON.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

int export_tiles(struct cli_env *env, const char *in, int hier_file, const char *dir, size_t tile_points,
                 unsigned flags);

int export_tiles(struct cli_env *env, const char *in, int hier_file, const char *dir, size_t tile_points,
                 unsigned flags)
{
    asp_error err = {0};
    asp_hier *h = NULL;
    int rc;
    if (hier_file)
        rc = asp_hier_load(in, &env->ctx, &h, &err);
    else {
        asp_cloud *c = NULL;
        rc = asp_cloud_load(in, &env->ctx, &c, &err);
        if (!rc)
            rc = asp_hier_build(c, NULL, &env->ctx, &h, &err);
        asp_cloud_destroy(c); // only the hierarchy is needed from here on
    }
    asp_tiles_stats st = {0};
    const asp_tiles_desc d = {.gltf = {.flags = flags}, .tile_points = tile_points};
    if (!rc)
        rc = asp_tiles_export_hier(h, dir, &d, &st, &err);
    asp_hier_destroy(h);
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    if (env->json) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "input", in);
        cJSON_AddStringToObject(j, "output", dir);
        cJSON_AddStringToObject(j, "kind", "tileset");
        cJSON_AddNumberToObject(j, "tiles", (double)st.tiles);
        cJSON_AddNumberToObject(j, "points", (double)st.points);
        cJSON_AddNumberToObject(j, "splats", (double)st.splats);
        cJSON_AddNumberToObject(j, "leaf_points", (double)st.leaf_points);
        cJSON_AddNumberToObject(j, "largest_tile", (double)st.largest);
        cJSON_AddNumberToObject(j, "depth", st.depth);
        cJSON_AddNumberToObject(j, "root_error", st.root_error);
        cJSON_AddNumberToObject(j, "json_bytes", (double)st.json_bytes);
        cJSON_AddNumberToObject(j, "bytes", (double)st.file_bytes);
        cJSON_AddBoolToObject(j, "gaussian_splats", !(flags & ASP_GLTF_NO_SPLATS));
        cJSON_AddBoolToObject(j, "compressed", !(flags & ASP_GLTF_PLAIN));
        cJSON *o = cJSON_AddArrayToObject(j, "origin");
        for (int k = 0; k < 3; k++)
            cJSON_AddItemToArray(o, cJSON_CreateNumber(st.origin[k]));
        return cli_json_print(env, j);
    }
    if (!env->quiet)
        printf("exported '%s' -> '%s/tileset.json': %zu tiles (depth %u, at most %zu splats), %zu points in "
               "%zu splats, %zu bytes\n",
               in, dir, st.tiles, st.depth, st.largest, st.points, st.splats, st.file_bytes);
    return 0;
}
