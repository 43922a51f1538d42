/*
 * A point hierarchy as a streamed 3D Tiles 1.1 tileset (issue 32): tileset.json with explicit
 * tiling and one compact GLB a tile (asp__gltf_points_write), written tile by tile so that memory
 * stays at one tile's content however large the hierarchy (docs/web.md, docs/cli/export.md).
 *
 * Tiles are octree nodes. A tile's content is the cut of its node's subtree at a content depth c:
 * the representative splats of the nodes at depth c (seed 001 section 3: each covers the points
 * of its subtree, eq. 2-6), and the points of leaves shallower than c. c is the deepest for which
 * the cut holds at most tile_points splats, and at least one deeper than the parent tile's, so
 * each refinement step adds detail. The children of a tile are its node's children, and refine is
 * REPLACE: a node's splat stands for exactly the points of its subtree (the hierarchy is a cut
 * hierarchy, seed 004 section 3.2), so drawing a parent's splats with its children's (ADD) would
 * draw every surface twice, one coarse layer blended over the fine one. A tile whose cut holds
 * only points is a leaf (geometricError 0).
 *
 * geometricError is the largest diameter 2a of the node splats in the tile's content: the
 * screen-space error a client computes from it (geometricError x screen height / (2 distance
 * tan(fov_y / 2))) is then the projected splat diameter in pixels, the tau of asp_hier_select,
 * so a client's error target in pixels is the hierarchy's tolerance. It is clamped to the
 * parent's so that it never grows downwards.
 *
 * Frames: the GLBs are glTF, y up, in the hierarchy's local frame (positions relative to
 * asp_hier_origin). 3D Tiles is z up and turns glTF content y-up to z-up (3D Tiles 1.1 spec,
 * "glTF transforms": (x, y, z) -> (x, -z, y)), so bounding boxes are written in that z-up frame
 * and the root transform translates it by the origin (in the same frame). The origin and the
 * source's frame sphere are kept in the tileset's extras.amgsplat for viewers that frame as
 * amgsplat render does.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "export/internal.h"
#include "util/atomic_file.h"
#include "util/regular_file.h"
#include "util/banned.h"

enum { TILE_POINTS_DEFAULT = 32768, STACK = 8 * (64 + 2) };

typedef struct tiles_run {
    const asp_hier *hier;
    const asp_hier_node *nodes;
    const asp_hier_splat *splats;
    size_t node_count;
    size_t tile_points;
    const asp_tiles_desc *desc;
    const char *dir;
    asp_tiles_stats st;
    asp_error *err; /* the caller's, or local when the caller passed NULL: its code is the result */
    asp_error local;
    asp_up_axis up; /* the source's, turned to the GLBs' +y */
} tiles_run;

/*
 * The cut of node root's subtree at depth c (module comment): writes the splat ids to ids (may be
 * NULL) and returns their count; *points_only = 1 when it holds no node splat, *diameter = the
 * largest 2a among its node splats.
 */
static size_t cut(const tiles_run *t, asp_index root, uint32_t c, asp_index *ids, int *points_only, double *diameter)
{
    asp_index stack[STACK];
    size_t top = 0, n = 0;
    *points_only = 1;
    *diameter = 0;
    stack[top++] = root;
    while (top) {
        const asp_hier_node *nd = &t->nodes[stack[--top]];
        asp_index id = stack[top];
        if (nd->depth >= c || (nd->child_count > 0 && top + nd->child_count > STACK)) {
            if (ids)
                ids[n] = id;
            n++;
            *points_only = 0;
            *diameter = fmax(*diameter, 2.0 * t->splats[id].a);
        } else if (nd->child_count == 0) {
            for (uint32_t j = 0; j < nd->point_count; j++) {
                if (ids)
                    ids[n] = (asp_index)(t->node_count + nd->first_point + j);
                n++;
            }
        } else {
            // children pushed last-first so that they come out in id order (deterministic files)
            for (uint32_t k = nd->child_count; k-- > 0;)
                stack[top++] = nd->first_child + k;
        }
    }
    return n;
}

/*
 * Grows box (lo xyz, hi xyz, in the GLBs' y-up frame) by the ellipse of splat s, center + a cos(t)
 * u + b sin(t) v turned from the source's up axis as the GLB turns it (asp__gltf_turn_up): its
 * extent along axis k is sqrt((a u_k)^2 + (b v_k)^2), so a flat patch gets a flat box.
 */
static void box_add(double box[6], const asp_hier_splat *s, asp_up_axis up)
{
    double a = s->a > 0 ? s->a : 0, b = s->b > 0 ? s->b : 0;
    float c[3] = {s->center[0], s->center[1], s->center[2]}, u[3] = {s->u[0], s->u[1], s->u[2]},
          v[3] = {s->v[0], s->v[1], s->v[2]};
    asp__gltf_turn_up_f(up, c);
    asp__gltf_turn_up_f(up, u);
    asp__gltf_turn_up_f(up, v);
    for (int k = 0; k < 3; k++) {
        double r = sqrt(a * a * u[k] * u[k] + b * b * v[k] * v[k]);
        box[k] = fmin(box[k], (double)c[k] - r);
        box[3 + k] = fmax(box[3 + k], (double)c[k] + r);
    }
}

cJSON *asp__tiles_box(const double box[6])
{
    double c[3], h[3];
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5 * (box[k] + box[3 + k]);
        h[k] = fmax(0.5 * (box[3 + k] - box[k]), 1e-9); // a zero half-axis is a degenerate box
    }
    double v[12] = {c[0], -c[2], c[1], h[0], 0, 0, 0, h[2], 0, 0, 0, h[1]};
    cJSON *bv = cJSON_CreateObject();
    cJSON_AddItemToObject(bv, "box", asp__gltf_numbers(v, 12));
    return bv;
}

/*
 * Writes the tile of node id (its content depth at least min_c, its error at most max_error) and,
 * depth first, its children; returns the tile as JSON (NULL on error, t->err set) and its box.
 */
static cJSON *write_tile(tiles_run *t, asp_index id, uint32_t min_c, double max_error, uint32_t tile_depth,
                         double box[6])
{
    const asp_hier_node *nd = &t->nodes[id];
    uint32_t c = nd->depth > min_c ? nd->depth : min_c;
    int points_only;
    double diameter;
    size_t n = cut(t, id, c, NULL, &points_only, &diameter);
    while (!points_only) { // the deepest cut within the budget
        int po;
        double dm;
        size_t m = cut(t, id, c + 1, NULL, &po, &dm);
        if (m > t->tile_points)
            break;
        c++, n = m, points_only = po, diameter = dm;
    }
    asp_index *ids = asp_alloc(NULL, n * sizeof *ids);
    if (!ids) {
        asp_error_set(t->err, ASP_ENOMEM, "out of memory for the %zu splats of tile %u", n, (unsigned)id);
        return NULL;
    }
    cut(t, id, c, ids, &points_only, &diameter);
    char path[4096], uri[64];
    snprintf(uri, sizeof uri, "tiles/%u.glb", (unsigned)id);
    if (snprintf(path, sizeof path, "%s/%s", t->dir, uri) >= (int)sizeof path) {
        asp_free(NULL, ids);
        asp_error_set(t->err, ASP_EINVAL, "tileset directory name '%s' is too long", t->dir);
        return NULL;
    }
    static const double zero[3] = {0, 0, 0};
    asp_gltf_stats gs = {0};
    int rc = asp__gltf_points_write(t->hier, ids, n, zero, NULL, path, &t->desc->gltf, &gs, t->err);
    for (int k = 0; k < 3; k++) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    // the subtree's points (contiguous in hierarchy order) and the content's node splats
    for (uint32_t j = 0; j < nd->point_count; j++)
        box_add(box, &t->splats[t->node_count + nd->first_point + j], t->up);
    for (size_t i = 0; i < n; i++)
        if (ids[i] < t->node_count)
            box_add(box, &t->splats[ids[i]], t->up);
    asp_free(NULL, ids);
    if (rc)
        return NULL;
    t->st.tiles++;
    t->st.splats += n;
    t->st.file_bytes += gs.file_bytes;
    t->st.depth = tile_depth > t->st.depth ? tile_depth : t->st.depth;
    t->st.largest = n > t->st.largest ? n : t->st.largest;
    if (points_only)
        t->st.leaf_points += n;
    double error = points_only ? 0 : fmin(diameter, max_error);
    cJSON *tile = cJSON_CreateObject();
    cJSON_AddNumberToObject(tile, "geometricError", error);
    cJSON *content = cJSON_AddObjectToObject(tile, "content");
    cJSON_AddStringToObject(content, "uri", uri);
    if (points_only || nd->child_count == 0) {
        cJSON_AddItemToObject(tile, "boundingVolume", asp__tiles_box(box));
        return tile;
    }
    cJSON *children = cJSON_AddArrayToObject(tile, "children");
    for (uint32_t k = 0; k < nd->child_count; k++) {
        double cb[6];
        cJSON *child = write_tile(t, nd->first_child + k, c + 1, error, tile_depth + 1, cb);
        if (!child) {
            cJSON_Delete(tile);
            return NULL;
        }
        cJSON_AddItemToArray(children, child);
        for (int j = 0; j < 3; j++) { // a tile's volume holds its children's (3D Tiles 1.1, bounding volume spatial coherence)
            box[j] = fmin(box[j], cb[j]);
            box[3 + j] = fmax(box[3 + j], cb[3 + j]);
        }
    }
    cJSON_AddItemToObject(tile, "boundingVolume", asp__tiles_box(box));
    return tile;
}

int asp__tiles_dirs(const char *dir, asp_error *err)
{
    char sub[4096];
    if (snprintf(sub, sizeof sub, "%s/tiles", dir) >= (int)sizeof sub)
        return asp_error_set(err, ASP_EINVAL, "tileset directory name '%s' is too long", dir);
    int rc = asp__dir_ensure(dir, "directory", err);
    return rc ? rc : asp__dir_ensure(sub, "directory", err);
}

int asp__tiles_write_tileset(const char *dir, cJSON *root_tile, const char *refine, const double box[6],
                             const double origin[3], const asp_frame *frame, unsigned gltf_flags,
                             asp_tiles_stats *st, asp_error *err)
{
    cJSON_AddStringToObject(root_tile, "refine", refine);
    if (origin[0] != 0 || origin[1] != 0 || origin[2] != 0) {
        double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, origin[0], -origin[2], origin[1], 1};
        cJSON_AddItemToObject(root_tile, "transform", asp__gltf_numbers(m, 16));
    }
    cJSON *root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(root, "asset");
    cJSON_AddStringToObject(asset, "version", "1.1");
    cJSON_AddStringToObject(asset, "generator", "amgsplat " ASP_VERSION_STRING " export --tiles");
    double diag = 0;
    for (int k = 0; k < 3; k++)
        diag += (box[3 + k] - box[k]) * (box[3 + k] - box[k]);
    // the error of showing nothing: the whole model as one pixel-sized dot
    cJSON_AddNumberToObject(root, "geometricError", sqrt(diag));
    cJSON_AddItemToObject(root, "root", root_tile);
    asp__gltf_tileset_extensions(root, gltf_flags);
    cJSON *extras = asp__gltf_extras("tileset", NULL, origin, frame);
    cJSON *a = cJSON_GetObjectItemCaseSensitive(extras, "amgsplat");
    cJSON_AddNumberToObject(a, "points", (double)st->points);
    cJSON_AddNumberToObject(a, "tiles", (double)st->tiles);
    cJSON_AddNumberToObject(a, "splats", (double)st->splats);
    cJSON_AddNumberToObject(a, "bytes", (double)st->file_bytes);
    cJSON_AddStringToObject(a, "refine", refine);
    cJSON_AddItemToObject(root, "extras", extras);
    // the root tile's error, for a client that starts from it
    st->root_error = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(root_tile, "geometricError"));
    char *json = cJSON_PrintUnformatted(root); // bytes the first frame waits for
    cJSON_Delete(root);
    if (!json)
        return asp_error_set(err, ASP_ENOMEM, "out of memory printing the tileset of '%s'", dir);
    char path[4096 + 16];
    snprintf(path, sizeof path, "%s/tileset.json", dir);
    asp__atomic_file f;
    size_t len = strlen(json);
    int rc = asp__atomic_open(&f, path, err);
    if (!rc) {
        if (fwrite(json, 1, len, f.fp) != len) {
            asp__atomic_abort(&f);
            rc = asp_error_set(err, ASP_EIO, "cannot write '%s'", path);
        } else
            rc = asp__atomic_commit(&f, err);
    }
    cJSON_free(json);
    if (rc)
        return rc;
    st->json_bytes = len;
    st->file_bytes += len;
    memcpy(st->origin, origin, sizeof st->origin);
    return 0;
}

int asp_tiles_export_hier(const asp_hier *hier, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                          asp_error *err)
{
    ASP_ASSERT(hier && dir);
    static const asp_tiles_desc zero;
    const asp_tiles_desc *d = desc ? desc : &zero;
    if (d->gltf.levels || d->gltf.level_count)
        return asp_error_set(err, ASP_EINVAL, "tiles of a hierarchy take no levels");
    tiles_run t = {.hier = hier,
                   .up = asp_hier_frame(hier)->up,
                   .nodes = asp_hier_nodes(hier),
                   .splats = asp_hier_splats(hier),
                   .node_count = asp_hier_node_count(hier),
                   .tile_points = d->tile_points ? d->tile_points : TILE_POINTS_DEFAULT,
                   .desc = d,
                   .dir = dir};
    t.err = err ? err : &t.local;
    int rc = asp__tiles_dirs(dir, err);
    if (rc)
        return rc;
    double box[6];
    cJSON *root_tile = write_tile(&t, 0, 0, INFINITY, 0, box);
    if (!root_tile)
        return t.err->code; // the tiles written so far stay; without tileset.json they are no tileset
    double origin[3];
    asp_hier_origin(hier, origin);
    // the origin in the GLBs' y-up frame, as their content is (a z-up scan turns to y-up there, and
    // 3D Tiles turns it back to z-up below)
    asp__gltf_turn_up(asp_hier_frame(hier)->up, origin, origin);
    t.st.points = asp_hier_point_count(hier);
    rc = asp__tiles_write_tileset(dir, root_tile, "REPLACE", box, origin, asp_hier_frame(hier), d->gltf.flags, &t.st,
                                  err);
    if (rc)
        return rc;
    if (stats)
        *stats = t.st;
    return 0;
}
