/*
 * The levels of a .dps as a 3D Tiles 1.1 tileset (issue 32, item 2: "from a linked multi-level .dps,
 * coarse levels refined by finer ones"): one tile a level, the coarsest the root, each level's
 * only child the next finer one, refine REPLACE. A client draws the coarsest level first and
 * swaps in finer whole levels as the model covers more of the screen: the levels of detail of
 * thesis 2.6.3 / journal section 6, streamed.
 *
 * Why whole levels and not regions mixed across levels as the cut renderer (src/prim/level_cut.c)
 * mixes them: REPLACE means a tile's children together stand for exactly its content, and a
 * domain's support overlaps its neighbours' (the basis functions form a partition of unity only
 * across a whole level), so a region of coarse primitives replaced by fine ones leaves the blend
 * unnormalised along the seam, which the cut renderer hides by fading weights through the level
 * links at run time and a 3D Tiles client cannot do. NEEDSWORK: regional tiles would need the
 * fine primitives grouped under the coarse ones by the links and the seam weights baked in.
 *
 * geometricError of a level is the cut renderer's refinement measure in world units: the largest
 * error + size_weight x half diagonal over its primitives (asp_dps_cut_view, size_weight 0.2, the
 * renderer's default), never less than the finer levels'; the finest level's is 0. A client that
 * refines while geometricError projects above its target in pixels then switches level where
 * `render --method cut` would refine that level's worst primitive. Each tile's GLB is the level as
 * `export` writes it (asp_gltf_export_dps: quads, atlas, normal map, alphaRef and depthWindow in
 * the node extras) with positions relative to the frame centre, which the root transform adds.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export/internal.h"
#include "util/banned.h"

/* asp_dps_cut_view.size_weight's default (render.h): the cut renderer's refinement measure */
#define SIZE_WEIGHT 0.2

/* The world error of drawing level lv instead of the finest (module comment). */
static double level_error(const asp_dps_level *lv)
{
    double e = 0;
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        double r = sqrt((double)p->half_u * p->half_u + (double)p->half_v * p->half_v);
        e = fmax(e, (double)p->error + SIZE_WEIGHT * r);
    }
    return e;
}

/* Grows box (y-up, relative to the turned origin) by the support rectangles of lv. */
static void level_box(const asp_dps_level *lv, asp_up_axis up, const double origin[3], double box[6])
{
    for (size_t i = 0; i < lv->prim_count; i++) {
        const asp_prim *p = &lv->prims[i];
        for (int c = 0; c < 4; c++) {
            double su = c & 1 ? 1 : -1, sv = c & 2 ? 1 : -1, w[3], t[3];
            for (int k = 0; k < 3; k++)
                w[k] = p->centre[k] + su * p->half_u * p->axis_u[k] + sv * p->half_v * p->axis_v[k];
            asp__gltf_turn_up(up, w, t);
            for (int k = 0; k < 3; k++) {
                box[k] = fmin(box[k], t[k] - origin[k]);
                box[3 + k] = fmax(box[3 + k], t[k] - origin[k]);
            }
        }
    }
}

/* Levels coarsest first (dps keeps them finest first): indices into dps->levels. */
static void coarse_first(const asp_dps *dps, size_t *order)
{
    for (size_t i = 0; i < dps->level_count; i++)
        order[i] = i;
    for (size_t i = 1; i < dps->level_count; i++) // insertion sort by AMG level, coarsest (largest) first
        for (size_t j = i; j > 0 && dps->levels[order[j]].level > dps->levels[order[j - 1]].level; j--) {
            size_t t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
}

int asp_tiles_export_dps(const asp_dps *dps, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                         asp_error *err)
{
    ASP_ASSERT(dps && dir);
    static const asp_tiles_desc zero;
    const asp_tiles_desc *d = desc ? desc : &zero;
    if (d->gltf.levels || d->gltf.level_count || d->tile_points)
        return asp_error_set(err, ASP_EINVAL, "tiles of a .dps take no levels and no tile size (a tile is a level)");
    if (dps->level_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' holds no level to tile", dps->source);
    int rc = asp__tiles_dirs(dir, err);
    if (rc)
        return rc;
    size_t n = dps->level_count;
    size_t *order = calloc(n, sizeof *order);
    double *errors = calloc(n, sizeof *errors), *boxes = calloc(6 * n, sizeof *boxes);
    cJSON **tiles = calloc(n, sizeof *tiles);
    if (!order || !errors || !boxes || !tiles) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the tiles of %zu levels", n);
        goto done;
    }
    coarse_first(dps, order);
    asp_tiles_stats st;
    memset(&st, 0, sizeof st);
    double origin[3] = {0, 0, 0};
    // each level's GLB, finest last; the origin every GLB is relative to is the same (the frame's)
    for (size_t i = 0; i < n && !rc; i++) {
        char name[16], uri[64], path[4096 + 64];
        asp_dps_level_name(dps, order[i], name);
        snprintf(uri, sizeof uri, "tiles/%s.glb", name);
        if (snprintf(path, sizeof path, "%s/%s", dir, uri) >= (int)sizeof path) {
            rc = asp_error_set(err, ASP_EINVAL, "tileset directory name '%s' is too long", dir);
            break;
        }
        asp_gltf_stats gs;
        memset(&gs, 0, sizeof gs);
        if ((rc = asp__gltf_prims_tile(dps, order[i], path, &d->gltf, &gs, err)) != 0)
            break;
        memcpy(origin, gs.origin, sizeof origin);
        const asp_dps_level *lv = &dps->levels[order[i]];
        double *b = boxes + 6 * i;
        for (int k = 0; k < 3; k++) {
            b[k] = INFINITY;
            b[3 + k] = -INFINITY;
        }
        level_box(lv, dps->frame.up, gs.origin, b);
        errors[i] = i + 1 < n ? level_error(lv) : 0.0;
        st.tiles++;
        st.splats += lv->prim_count;
        st.file_bytes += gs.file_bytes;
        st.largest = lv->prim_count > st.largest ? lv->prim_count : st.largest;
        tiles[i] = cJSON_CreateObject();
        cJSON *content = cJSON_AddObjectToObject(tiles[i], "content");
        cJSON_AddStringToObject(content, "uri", uri);
    }
    if (rc)
        goto done;
    // from the finest up: an error never below the finer levels', a box holding the finer boxes
    // (3D Tiles 1.1: a tile's volume encloses its children's), the finer level the only child
    for (size_t i = n; i-- > 0;) {
        double *b = boxes + 6 * i;
        if (i + 1 < n) {
            errors[i] = fmax(errors[i], errors[i + 1]);
            for (int k = 0; k < 3; k++) {
                b[k] = fmin(b[k], boxes[6 * (i + 1) + k]);
                b[3 + k] = fmax(b[3 + k], boxes[6 * (i + 1) + 3 + k]);
            }
            cJSON *children = cJSON_AddArrayToObject(tiles[i], "children");
            cJSON_AddItemToArray(children, tiles[i + 1]);
            tiles[i + 1] = NULL;
        }
        cJSON_AddNumberToObject(tiles[i], "geometricError", errors[i]);
        cJSON_AddItemToObject(tiles[i], "boundingVolume", asp__tiles_box(b));
    }
    st.depth = (uint32_t)(n - 1);
    st.points = dps->source_points;
    rc = asp__tiles_write_tileset(dir, tiles[0], "REPLACE", boxes, origin, &dps->frame, 0, &st, err); // no splats
    tiles[0] = NULL; // taken over
    if (!rc && stats)
        *stats = st;
done:
    for (size_t i = 0; tiles && i < n; i++)
        cJSON_Delete(tiles[i]);
    free(tiles);
    free(order);
    free(errors);
    free(boxes);
    return rc;
}
