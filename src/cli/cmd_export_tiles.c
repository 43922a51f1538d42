/*
 * amgsplat export IN -o DIR --tiles: a point set, .hier or .dps as a streamed 3D Tiles 1.1
 * tileset (issue 32), for the web page's streaming mode and any 3D Tiles client. docs/web.md says
 * how to serve it. Four routes:
 *  - a streamed .hier (amgsplat convert): one tile a node, refine ADD (asp_tiles_export_ooc),
 *    memory bounded by the largest node;
 *  - a point file: converted first to a temporary streamed .hier next to DIR within --memory
 *    (asp_ooc_build, as PotreeConverter does), then as above, so a scan of any size tiles in
 *    bounded memory; the temporary file is removed;
 *  - an in-memory .hier (amgsplat convert --in-memory), or a point file with --splat-codec spz
 *    (Gaussians need its ellipses, so it is built in memory): elliptical splats, refine REPLACE
 *    (asp_tiles_export_hier);
 *  - a .dps: one tile a level, coarsest first, refine REPLACE (asp_tiles_export_dps).
 */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "amgsplat/hier_ooc.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

int export_tiles(struct cli_env *env, const char *in, asp_file_kind kind, const char *dir, size_t tile_points,
                 const char *memory, const asp_gltf_desc *gd);

/* The streamed .hier in as tiles; with convert, in is a point file, converted first to a temporary .hier next
 * to dir. */
static int tiles_streamed(struct cli_env *env, const char *in, int convert, const char *dir, size_t tile_points,
                          size_t memory, unsigned flags, asp_tiles_stats *st, asp_error *err)
{
    char tmp[4096];
    const char *path = in;
    int rc = 0;
    if (convert) {
        size_t len = strlen(dir);
        while (len > 1 && dir[len - 1] == '/')
            len--;
        if (snprintf(tmp, sizeof tmp, "%.*s.convert-%ld.hier", (int)len, dir, (long)getpid()) >= (int)sizeof tmp)
            return asp_error_set(err, ASP_EINVAL, "tileset directory name '%s' is too long", dir);
        const asp_ooc_build_desc bd = {.memory = memory, .node_points = tile_points};
        asp_ooc_build_stats bs;
        if ((rc = asp_ooc_build(in, tmp, &bd, &env->ctx, &bs, err)) != 0)
            return rc;
        cli_info(env, "amgsplat export: converted '%s' to a streamed hierarchy (%llu points, %zu nodes, depth %u)", in,
                 (unsigned long long)bs.points, bs.nodes, bs.depth);
        path = tmp;
    }
    asp_ooc *ooc = NULL;
    rc = asp_ooc_open(path, &env->ctx, &ooc, err);
    const asp_tiles_desc d = {.gltf = {.flags = flags}};
    if (!rc)
        rc = asp_tiles_export_ooc(ooc, dir, &d, st, err);
    asp_ooc_close(ooc);
    if (convert)
        remove(tmp);
    return rc;
}

int export_tiles(struct cli_env *env, const char *in, asp_file_kind kind, const char *dir, size_t tile_points,
                 const char *memory, const asp_gltf_desc *gd)
{
    asp_error err = {0};
    asp_hier *h = NULL;
    unsigned flags = gd->flags;
    int hier_file = kind == ASP_FILE_HIER;
    int streamed = hier_file && asp_ooc_probe(in) == 1;
    // Gaussian splats (--splat-codec spz, what CesiumJS draws) need seed 001's ellipses, which only
    // the in-memory hierarchy computes: a point file is then built into one in memory, not streamed
    int gaussians = (flags & ASP_GLTF_SPZ) != 0;
    int in_memory = kind != ASP_FILE_DPS && ((hier_file && !streamed) || (!hier_file && gaussians));
    if (streamed && gaussians)
        return cli_usage_error(env, "--splat-codec spz: the tiles of the streamed hierarchy '%s' are round discs "
                                    "without Gaussians; tile its point file instead", in);
    if (!hier_file && gaussians && memory)
        return cli_usage_error(env, "--memory: a tileset of Gaussian splats (--splat-codec spz) is built in memory, "
                                    "not converted");
    size_t budget = 0;
    if (memory && hier_file)
        return cli_usage_error(env, "--memory is the budget of converting a point file; '%s' is a hierarchy already",
                               in);
    if (memory && cli_memory_option(env, memory, &budget))
        return 2;
    if (!hier_file && !in_memory && tile_points && (tile_points < 64 || tile_points > 1000000))
        return cli_usage_error(env, "--tile-points %zu: a point file's leaf nodes hold 64 to 1000000 points",
                               tile_points);
    if (streamed && tile_points)
        return cli_usage_error(env, "--tile-points: the tiles of the streamed hierarchy '%s' are its nodes (set "
                                    "--node-points when converting)", in);
    int rc;
    asp_tiles_stats st = {0};
    if (kind == ASP_FILE_DPS) { // one tile a level, coarse first (asp_tiles_export_dps)
        asp_dps *dps = NULL;
        rc = asp_dps_load(in, &env->ctx, &dps, &err);
        const asp_tiles_desc d = {.gltf = *gd};
        if (!rc)
            rc = asp_tiles_export_dps(dps, dir, &d, &st, &err);
        asp_dps_destroy(dps);
    } else if (!in_memory)
        rc = tiles_streamed(env, in, !hier_file, dir, tile_points, budget, flags, &st, &err);
    else {
        if (hier_file)
            rc = asp_hier_load(in, &env->ctx, &h, &err);
        else { // the ellipses of seed 001, built in memory (asp_hier_build)
            asp_cloud *c = NULL;
            rc = asp_cloud_load(in, &env->ctx, &c, &err);
            if (!rc)
                rc = asp_hier_build(c, NULL, &env->ctx, &h, &err);
            asp_cloud_destroy(c); // the hierarchy holds what the tiles need
        }
        const asp_tiles_desc d = {.gltf = {.flags = flags}, .tile_points = tile_points};
        if (!rc)
            rc = asp_tiles_export_hier(h, dir, &d, &st, &err);
        asp_hier_destroy(h);
    }
    if (rc)
        return cli_fail(env, &err);
    cli_progress_end(env);
    const char *refine = in_memory || kind == ASP_FILE_DPS ? "REPLACE" : "ADD";
    if (env->json) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "input", in);
        cJSON_AddStringToObject(j, "output", dir);
        cJSON_AddStringToObject(j, "kind", "tileset");
        cJSON_AddStringToObject(j, "refine", refine);
        cJSON_AddNumberToObject(j, "tiles", (double)st.tiles);
        cJSON_AddNumberToObject(j, "points", (double)st.points);
        cJSON_AddNumberToObject(j, "splats", (double)st.splats);
        cJSON_AddNumberToObject(j, "leaf_points", (double)st.leaf_points);
        cJSON_AddNumberToObject(j, "largest_tile", (double)st.largest);
        cJSON_AddNumberToObject(j, "depth", st.depth);
        cJSON_AddNumberToObject(j, "root_error", st.root_error);
        cJSON_AddNumberToObject(j, "json_bytes", (double)st.json_bytes);
        cJSON_AddNumberToObject(j, "bytes", (double)st.file_bytes);
        // streamed tiles are round discs (no normals to orient an ellipse)
        cJSON_AddBoolToObject(j, "gaussian_splats", !(flags & ASP_GLTF_NO_SPLATS) && in_memory);
        if (kind == ASP_FILE_DPS)
            cJSON_AddNumberToObject(j, "primitives", (double)st.splats);
        cJSON_AddBoolToObject(j, "compressed", !(flags & ASP_GLTF_PLAIN));
        cJSON *o = cJSON_AddArrayToObject(j, "origin");
        for (int k = 0; k < 3; k++)
            cJSON_AddItemToArray(o, cJSON_CreateNumber(st.origin[k]));
        return cli_json_print(env, j);
    }
    if (!env->quiet && kind == ASP_FILE_DPS)
        printf("exported '%s' -> '%s/tileset.json': %zu tiles, one a level (refine REPLACE, coarsest first), %zu "
               "primitives in all, at most %zu in a level, %zu bytes\n",
               in, dir, st.tiles, st.splats, st.largest, st.file_bytes);
    else if (!env->quiet)
        printf("exported '%s' -> '%s/tileset.json': %zu tiles (refine %s, depth %u, at most %zu splats), %zu points "
               "in %zu splats, %zu bytes\n",
               in, dir, st.tiles, refine, st.depth, st.largest, st.points, st.splats, st.file_bytes);
    return 0;
}
