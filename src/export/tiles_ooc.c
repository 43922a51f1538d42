/*
 * A streamed (out-of-core) point hierarchy as a 3D Tiles 1.1 tileset (issue 32; docs/web.md,
 * docs/cli/export.md "Tilesets"): one tile per node of the .hier, refine ADD, read and written one
 * node at a time, so memory is the node table and the largest node whatever the set's size.
 *
 * Why ADD: a streamed hierarchy stores every point exactly once, an inner node holding a grid
 * subsample of its subtree's points and its descendants the rest (Schuetz, Ohrhallinger, Wimmer
 * 2020; docs/hier.md "Streamed layout"). The points a view needs are the union of its cut's nodes
 * (asp_ooc_load), which is what 3D Tiles' ADD refinement draws: a tile's content together with its
 * ancestors'. It is how PotreeConverter's 3D Tiles are built, and the tileset holds each point once
 * (its bytes are the set's, not a multiple).
 *
 * geometricError is the node's point spacing (asp_ooc_node.spacing: the distance between
 * neighbouring points of the node and its ancestors, which is what ADD shows of it), 0 for a leaf
 * (nothing left to add). A 3D Tiles client refines a tile while geometricError x screen height /
 * (2 distance tan(fov_y / 2)) exceeds its maximum screen-space error; asp_ooc_select refines a node
 * while spacing x 0.5 height proj[1][1] / distance = the same quantity exceeds tau. So a client's
 * error target in pixels is the hierarchy's tolerance (render --tolerance of the .hier), and the
 * tiles it draws are the cut `amgsplat render` draws. It is clamped to the parent's, so that it never
 * grows downwards.
 *
 * Content: a compact GLB a node (EXT_meshopt_compression + KHR_mesh_quantization, as
 * asp__gltf_points_write compacts points: POSITION 16-bit in the node's box with the node's
 * translation and uniform scale, COLOR_0 8-bit linear, spatially sorted) without normals or
 * KHR_gaussian_splatting: the points carry none, so they are round discs. The disc radius
 * asp_ooc_load gives the node's points (asp_ooc_disc_radius) is in the mesh's
 * extras.amgsplat.pointRadius (model units), with the node's cube, for the web page (web/tiles.js),
 * which draws them as the disc renderer draws the cut; generic clients draw plain glTF points.
 *
 * Frames are those of tiles.c: GLB content y up in the hierarchy's local frame (turned from the
 * source's up axis by asp__gltf_turn_up), boxes turned to 3D Tiles z-up (asp__tiles_box), the
 * origin in the root transform. A tile's box is the box of its subtree's points (each node's own,
 * bottom up: children have larger ids, so one pass in decreasing id order sees them first).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <meshoptimizer.h>

#include "export/internal.h"
#include "amgsplat/hier_ooc.h"
#include "util/banned.h"

typedef struct ooc_run {
    asp_ooc *ooc;
    const asp_ooc_node *nodes;
    size_t node_count;
    int plain;
    asp_up_axis up;
    double *boxes;         /* 6 a node: its subtree's points, y up */
    uint8_t lut[256];      /* sRGB byte -> linear byte (glTF colours are linear) */
    asp_tiles_stats st;
} ooc_run;

/* Scratch for the largest node: records, turned positions, and the encoder's arrays. */
typedef struct scratch {
    asp_ooc_point *rec;
    float *pos;
    unsigned *remap;
    uint8_t *buf;
} scratch;

/*
 * Children with points below them: the converter can leave a node's octants empty (a node of a
 * few points split anyway), and a tile without content or children is no tile. A node whose
 * children are all empty is a leaf here.
 */
static uint32_t live_children(const ooc_run *r, const asp_ooc_node *nd)
{
    uint32_t n = 0;
    for (uint32_t k = 0; k < nd->child_count; k++)
        n += r->nodes[nd->first_child + k].subtree_points > 0;
    return n;
}

/*
 * The GLB of n points (pos y-up, rec's colours) at path: compact (module comment) or, with plain,
 * float positions and uncompressed colours in file order.
 */
static int write_glb(const ooc_run *r, uint32_t id, const scratch *s, size_t n, const char *path, size_t *bytes,
                     asp_error *err)
{
    const asp_ooc_node *nd = &r->nodes[id];
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], s->pos[3 * i + k]);
            hi[k] = fmaxf(hi[k], s->pos[3 * i + k]);
        }
    asp__gltf g;
    int rc = asp__gltf_init(&g, path, "(points, streamed tile)", NULL, err);
    if (rc)
        return rc;
    double translation[3] = {0, 0, 0}, scale = 1;
    int pos, col;
    if (r->plain) {
        pos = asp__gltf_accessor(&g, asp__gltf_view(&g, s->pos, n * 12, ASP__GL_ARRAY_BUFFER), ASP__GL_FLOAT, n,
                                 "VEC3", 0, lo, hi);
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 4; k++)
                s->buf[4 * i + k] = k < 3 ? r->lut[s->rec[i].color[k]] : s->rec[i].color[3];
        col = asp__gltf_accessor(&g, asp__gltf_view(&g, s->buf, n * 4, ASP__GL_ARRAY_BUFFER), ASP__GL_UNSIGNED_BYTE,
                                 n, "VEC4", 1, NULL, NULL);
    } else {
        // neighbours next to each other: what the vertex codec's byte deltas compress
        meshopt_spatialSortRemap(s->remap, s->pos, n, 12);
        // plain 16-bit integers under a node scale of one step (not normalized: the streamed tiles' form)
        pos = asp__gltf_compact_positions(&g, s->pos, n, lo, hi, s->remap, 0, s->buf, translation, &scale);
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 4; k++)
                s->buf[4 * (size_t)s->remap[i] + k] = k < 3 ? r->lut[s->rec[i].color[k]] : s->rec[i].color[3];
        col = asp__gltf_accessor(&g, asp__gltf_view_meshopt(&g, s->buf, n, 4, "NONE"), ASP__GL_UNSIGNED_BYTE, n,
                                 "VEC4", 1, NULL, NULL);
        asp__gltf_require_extension(&g, "KHR_mesh_quantization");
    }
    cJSON *attrs = cJSON_CreateObject(), *pr = cJSON_CreateObject(), *mesh = cJSON_CreateObject();
    cJSON_AddNumberToObject(attrs, "POSITION", pos);
    cJSON_AddNumberToObject(attrs, "COLOR_0", col);
    cJSON_AddItemToObject(pr, "attributes", attrs);
    cJSON_AddNumberToObject(pr, "mode", 0); // POINTS
    cJSON_AddItemToArray(cJSON_AddArrayToObject(mesh, "primitives"), pr);
    cJSON_AddStringToObject(mesh, "name", "points");
    cJSON *am = cJSON_AddObjectToObject(cJSON_AddObjectToObject(mesh, "extras"), "amgsplat");
    cJSON_AddNumberToObject(am, "pointRadius", asp_ooc_disc_radius(r->ooc, id));
    // the node's cube (centre y up, as the positions, and half side): the page tells a point's
    // octant by it and draws the point at the radius of a visible child there, as asp_ooc_load
    // sizes a point by the deepest loaded node holding it
    float cc[3] = {nd->center[0], nd->center[1], nd->center[2]};
    asp__gltf_turn_up_f(r->up, cc);
    double cube[4] = {cc[0], cc[1], cc[2], nd->half};
    cJSON_AddItemToObject(am, "cube", asp__gltf_numbers(cube, 4));
    cJSON_AddNumberToObject(am, "spacing", nd->spacing);
    cJSON_AddNumberToObject(am, "node", id);
    cJSON_AddNumberToObject(am, "depth", nd->depth);
    cJSON_AddBoolToObject(am, "leaf", live_children(r, nd) == 0);
    int m = asp__gltf_append(&g, g.meshes, mesh);
    char name[64];
    snprintf(name, sizeof name, "node %u (%zu points)", (unsigned)id, n);
    cJSON *node = cJSON_CreateObject();
    cJSON_AddStringToObject(node, "name", name);
    cJSON_AddNumberToObject(node, "mesh", m);
    if (!r->plain) {
        double sc[3] = {scale, scale, scale};
        cJSON_AddItemToObject(node, "translation", asp__gltf_numbers(translation, 3));
        cJSON_AddItemToObject(node, "scale", asp__gltf_numbers(sc, 3));
    }
    int ni = asp__gltf_append(&g, g.nodes, node);
    cJSON *scenes = cJSON_AddArrayToObject(g.root, "scenes"), *sc = cJSON_CreateObject();
    double zero = 0;
    cJSON_AddStringToObject(sc, "name", "points");
    cJSON_AddItemToObject(sc, "nodes", asp__gltf_numbers(&zero, 1));
    asp__gltf_append(&g, scenes, sc);
    cJSON_AddNumberToObject(g.root, "scene", 0);
    asp_gltf_stats gs = {0};
    if (pos < 0 || col < 0 || m < 0 || ni < 0)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the glTF document of '%s'", path);
    else
        rc = asp__gltf_write(&g, path, &gs, err);
    asp__gltf_release(&g);
    *bytes = gs.file_bytes;
    return rc;
}

/* The tile of node id and, depth first, its children's, as JSON (NULL: out of memory). */
static cJSON *tile_json(const ooc_run *r, uint32_t id, double max_error)
{
    const asp_ooc_node *nd = &r->nodes[id];
    double error = live_children(r, nd) ? fmin((double)nd->spacing, max_error) : 0;
    cJSON *tile = cJSON_CreateObject();
    if (!tile)
        return NULL;
    cJSON_AddItemToObject(tile, "boundingVolume", asp__tiles_box(r->boxes + 6 * (size_t)id));
    cJSON_AddNumberToObject(tile, "geometricError", error);
    if (nd->point_count) {
        char uri[64];
        snprintf(uri, sizeof uri, "tiles/%u.glb", (unsigned)id);
        cJSON_AddStringToObject(cJSON_AddObjectToObject(tile, "content"), "uri", uri);
    }
    if (!live_children(r, nd))
        return tile;
    cJSON *children = cJSON_AddArrayToObject(tile, "children");
    for (uint32_t k = 0; k < nd->child_count; k++) {
        if (r->nodes[nd->first_child + k].subtree_points == 0)
            continue; // no points below: nothing to draw or to hold
        cJSON *c = tile_json(r, nd->first_child + k, error);
        if (!c || !cJSON_AddItemToArray(children, c)) {
            cJSON_Delete(c);
            cJSON_Delete(tile);
            return NULL;
        }
    }
    return tile;
}

int asp_tiles_export_ooc(asp_ooc *ooc, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                         asp_error *err)
{
    ASP_ASSERT(ooc && dir);
    static const asp_tiles_desc zero;
    const asp_tiles_desc *d = desc ? desc : &zero;
    if (d->gltf.levels || d->gltf.level_count)
        return asp_error_set(err, ASP_EINVAL, "tiles of a hierarchy take no levels");
    if (d->tile_points)
        return asp_error_set(err, ASP_EINVAL, "a streamed hierarchy's tiles are its nodes: tile_points does not "
                                              "apply (set the node size when converting)");
    ooc_run r = {.ooc = ooc,
                 .nodes = asp_ooc_nodes(ooc),
                 .node_count = asp_ooc_node_count(ooc),
                 .plain = (d->gltf.flags & ASP_GLTF_PLAIN) != 0,
                 .up = asp_ooc_frame(ooc)->up};
    for (int c = 0; c < 256; c++)
        r.lut[c] = (uint8_t)lrintf(255.0f * asp__gltf_srgb_to_linear((uint8_t)c));
    size_t largest = 0;
    for (size_t i = 0; i < r.node_count; i++)
        largest = r.nodes[i].point_count > largest ? r.nodes[i].point_count : largest;
    scratch s = {0};
    r.boxes = asp_alloc(NULL, r.node_count * 6 * sizeof *r.boxes);
    s.rec = asp_alloc(NULL, (largest ? largest : 1) * sizeof *s.rec);
    s.pos = asp_alloc(NULL, (largest ? largest : 1) * 12);
    s.remap = asp_alloc(NULL, (largest ? largest : 1) * sizeof *s.remap);
    s.buf = asp_alloc(NULL, (largest ? largest : 1) * 8);
    int rc = 0;
    if (!r.boxes || !s.rec || !s.pos || !s.remap || !s.buf)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the tiles of %zu nodes (largest %zu points)",
                           r.node_count, largest);
    if (!rc)
        rc = asp__tiles_dirs(dir, err);
    // bottom up: a node's box holds its children's, which have larger ids
    for (size_t i = r.node_count; i-- > 0 && !rc;) {
        const asp_ooc_node *nd = &r.nodes[i];
        double *box = r.boxes + 6 * i;
        for (int k = 0; k < 3; k++) {
            box[k] = INFINITY;
            box[3 + k] = -INFINITY;
        }
        size_t n = nd->point_count, bytes = 0;
        if (n) {
            if ((rc = asp_ooc_read_points(ooc, (uint32_t)i, s.rec, err)) != 0)
                break;
            for (size_t j = 0; j < n; j++) {
                float *p = s.pos + 3 * j;
                memcpy(p, s.rec[j].position, 12);
                asp__gltf_turn_up_f(r.up, p);
                for (int k = 0; k < 3; k++) {
                    box[k] = fmin(box[k], p[k]);
                    box[3 + k] = fmax(box[3 + k], p[k]);
                }
            }
            char path[4096];
            if (snprintf(path, sizeof path, "%s/tiles/%u.glb", dir, (unsigned)i) >= (int)sizeof path) {
                rc = asp_error_set(err, ASP_EINVAL, "tileset directory name '%s' is too long", dir);
                break;
            }
            if ((rc = write_glb(&r, (uint32_t)i, &s, n, path, &bytes, err)) != 0)
                break;
            r.st.tiles++;
            r.st.splats += n;
            r.st.file_bytes += bytes;
            r.st.largest = n > r.st.largest ? n : r.st.largest;
            r.st.depth = nd->depth > r.st.depth ? nd->depth : r.st.depth;
            if (!live_children(&r, nd))
                r.st.leaf_points += n;
        }
        for (uint32_t k = 0; k < nd->child_count; k++) { // 3D Tiles 1.1: a tile's volume holds its children's
            const double *cb = r.boxes + 6 * ((size_t)nd->first_child + k);
            for (int j = 0; j < 3; j++) {
                box[j] = fmin(box[j], cb[j]);
                box[3 + j] = fmax(box[3 + j], cb[3 + j]);
            }
        }
    }
    asp_free(NULL, s.rec);
    asp_free(NULL, s.pos);
    asp_free(NULL, s.remap);
    asp_free(NULL, s.buf);
    cJSON *root_tile = NULL;
    if (!rc && !(root_tile = tile_json(&r, 0, INFINITY)))
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the tileset of %zu nodes", r.node_count);
    if (!rc) {
        double origin[3];
        asp_ooc_origin(ooc, origin);
        asp__gltf_turn_up(r.up, origin, origin); // as the GLBs' content (tiles.c)
        r.st.points = (size_t)asp_ooc_point_count(ooc);
        rc = asp__tiles_write_tileset(dir, root_tile, "ADD", r.boxes, origin, asp_ooc_frame(ooc), 0 /* round discs, no splats */,
                                      &r.st, err);
    }
    // the tiles written before an error stay; without tileset.json they are no tileset
    asp_free(NULL, r.boxes);
    if (!rc && stats)
        *stats = r.st;
    return rc;
}
