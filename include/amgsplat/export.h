/*
 * glTF 2.0 export (issue 16): domain primitives (.dps) as textured quads, point sets and
 * hierarchies as POINTS with seed 001's splat ellipses through KHR_gaussian_splatting, so the
 * results open in engines, web viewers and the tools users already have. JSON through cJSON.
 */
#ifndef AMGSPLAT_EXPORT_H
#define AMGSPLAT_EXPORT_H

#include "hier.h"
#include "hier_ooc.h"
#include "prim.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How primitive materials treat alpha (glTF material.alphaMode). */
typedef enum asp_gltf_alpha_mode {
    ASP_GLTF_ALPHA_BLEND = 0, /* BLEND (default): alpha = the domain's basis function, blended */
    ASP_GLTF_ALPHA_MASK = 1   /* MASK with alphaCutoff = alpha_cutoff: opaque where alpha > it */
} asp_gltf_alpha_mode;

/** Export flags (asp_gltf_desc.flags); 0 is the default. */
enum asp_gltf_flags {
    ASP_GLTF_LIT = 1 << 0,           /* primitives: metallic-roughness material instead of KHR_materials_unlit */
    ASP_GLTF_NO_NORMAL_MAP = 1 << 1, /* primitives: leave the level's normal map out */
    ASP_GLTF_NO_SPLATS = 1 << 2,     /* points: plain POINTS, no KHR_gaussian_splatting attributes */
    ASP_GLTF_PLAIN = 1 << 3,         /* points: float attributes, uncompressed (no KHR_mesh_quantization,
                                        no EXT_meshopt_compression), in input order */
    ASP_GLTF_SPZ = 1 << 4            /* points: the splats as one SPZ stream (KHR_gaussian_splatting_
                                        compression_spz_2, required; what CesiumJS draws); not with
                                        ASP_GLTF_PLAIN or ASP_GLTF_NO_SPLATS (ASP_EINVAL) */
};

/** Options; the zero value means the defaults. */
typedef struct asp_gltf_desc {
    unsigned flags;               /* asp_gltf_flags */
    asp_gltf_alpha_mode alpha_mode;
    float alpha_cutoff;           /* MASK cutoff in (0, 1); 0 = 0.1, the renderer's alpha reference */
    const size_t *levels;         /* .dps: indices into dps->levels to export; NULL = every level */
    size_t level_count;
} asp_gltf_desc;

/** What an export wrote. */
typedef struct asp_gltf_stats {
    size_t nodes;        /* mesh nodes (one per level, or 1 for points) */
    size_t primitives;   /* quads written (domain primitives) */
    size_t points;       /* points written */
    size_t images;       /* PNG images (atlases and normal maps) */
    size_t json_bytes;   /* JSON chunk / .gltf size */
    size_t bin_bytes;    /* binary chunk / .bin size (images included when embedded) */
    size_t file_bytes;   /* bytes of every file written */
    size_t files;        /* files written (1 for .glb) */
    double origin[3];    /* world origin kept in the nodes' translation */
} asp_gltf_stats;

/**
 * Writes dps to path as glTF 2.0: binary GLB when path ends in .glb, else
 * JSON .gltf with a .bin and the PNG images beside it (same stem). Each
 * exported level is one node named by level ("L-6 (354 primitives)") whose
 * mesh has one quad per primitive, exactly the renderer's support rectangle
 * (centre +- half_u axis_u +- half_v axis_v; texture coordinates on the
 * texture rectangle's texel edges) with NORMAL, TANGENT (axis_u) and
 * TEXCOORD_0; the atlas is a PNG in baseColorTexture (sRGB colour, straight
 * alpha = basis function), double-sided, BLEND or MASK, unlit
 * (KHR_materials_unlit) unless ASP_GLTF_LIT. A level's world-space normal
 * atlas becomes a tangent-space normalTexture. Positions are relative to the
 * origin dps->frame.center (the primitives' bounds centre when the frame is
 * unknown), which the node's translation restores; the frame is also kept in
 * scene.extras.amgsplat so a viewer can frame the camera as amgsplat render
 * does. The file is written atomically. stats may be NULL.
 * Errors: ASP_EINVAL (bad desc, level index out of range, unknown extension),
 * ASP_EDEGENERATE (no primitives to write), ASP_ENOMEM, ASP_EIO.
 * Thread-safe (no shared state).
 */
int asp_gltf_export_dps(const asp_dps *dps, const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats,
                        asp_error *err);

/**
 * Writes the points of hier (its point splats) to path as glTF POINTS:
 * POSITION, NORMAL, COLOR_0 (linear RGBA), and unless ASP_GLTF_NO_SPLATS the
 * ellipses of seed 001 as a KHR_gaussian_splatting primitive
 * (asp_gltf_gaussian_from_ellipse): ROTATION, SCALE, OPACITY and
 * SH_DEGREE_0_COEF_0, that extension in extensionsUsed only. By default the
 * attributes are quantised (KHR_mesh_quantization: positions 16-bit normalized in the
 * points' box, which the node's translation and uniform scale undo; normals
 * octahedral 8-bit; colours and opacity 8-bit; rotations 12-bit quaternions;
 * scales and SH exponential-filtered floats, scales as ln(sigma / s) in
 * the node's units, s its scale) and compressed with
 * meshoptimizer's vertex codec (EXT_meshopt_compression), points in
 * meshopt_spatialSortRemap order; both extensions are required.
 * ASP_GLTF_PLAIN writes float attributes in input order, as glTF core.
 * Positions are relative to the hierarchy's origin (asp_hier_origin), kept
 * in the node's translation; the frame asp_hier_frame in scene.extras.amgsplat.
 * Errors, file kinds and stats as asp_gltf_export_dps. Thread-safe.
 */
int asp_gltf_export_hier(const asp_hier *hier, const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats,
                         asp_error *err);

/**
 * Builds the hierarchy of cloud (asp_hier_build with default options, which
 * gives every point its seed 001 ellipse) and exports it with
 * asp_gltf_export_hier. Runs with asp_context_threads(ctx) threads. Errors as
 * both. Thread-safe.
 */
int asp_gltf_export_cloud(const asp_cloud *cloud, const char *path, const asp_gltf_desc *desc,
                          const asp_context *ctx, asp_gltf_stats *stats, asp_error *err);

/**
 * The 3D Gaussian of KHR_gaussian_splatting (kernel "ellipse", cut at 3
 * sigma) for a flat elliptical splat center + s a u + t b v, s^2 + t^2 <= 1:
 * rotation quat (x, y, z, w) takes the local axes x, y, z to u, v and their
 * normal (u x v); log_scale = ln of sigma along them, sigma_u = a / 2 and
 * sigma_v = b / 2, so the splat rim lies at 2 sigma (weight 0.14, near
 * amgsplat's splat kernel's 0.17 there) and the 3 sigma cut at 1.5 semi-axes,
 * the B = 1.5 of that kernel; the normal's sigma is 1/100 of the smaller
 * one (a flat disc). b = 0 is taken as a / 1000; a must be > 0. u and v must be
 * unit and orthogonal. Pure.
 */
void asp_gltf_gaussian_from_ellipse(const float u[3], const float v[3], float a, float b, float quat[4],
                                    float log_scale[3]);

/* ---- streamed tilesets (issue 32, docs/web.md) ---- */

/** Tileset options; the zero value means the defaults. */
typedef struct asp_tiles_desc {
    asp_gltf_desc gltf;  /* each tile's GLB: flags (ASP_GLTF_NO_SPLATS, ASP_GLTF_PLAIN); no levels */
    size_t tile_points;  /* most splats in a tile's content where the tree allows it; 0 = 32768 */
} asp_tiles_desc;

/** What a tileset export wrote. */
typedef struct asp_tiles_stats {
    size_t tiles;        /* tiles (one GLB each) */
    size_t splats;       /* splats in all tiles' contents (node splats and points) */
    size_t points;       /* the hierarchy's points */
    size_t leaf_points;  /* points in leaf tiles (full resolution) */
    size_t largest;      /* splats of the largest tile */
    uint32_t depth;      /* deepest tile (root = 0) */
    double root_error;   /* the root tile's geometricError */
    size_t json_bytes;   /* tileset.json */
    size_t file_bytes;   /* every file written */
    double origin[3];    /* world origin in the root transform */
} asp_tiles_stats;

/**
 * Writes hier as a 3D Tiles 1.1 tileset in directory dir (created if
 * missing): dir/tileset.json (explicit tiling, refine REPLACE, boxes) and
 * one compact GLB a tile, dir/tiles/<node id>.glb, as
 * asp_gltf_export_hier writes points (positions relative to the origin,
 * y up; the root transform holds the origin, z up). A tile is an octree
 * node; its content is the cut of its subtree at the deepest depth that
 * keeps at most tile_points splats (node splats where the cut stops above
 * the leaves), one depth deeper at least than its parent's; geometricError
 * is the largest splat diameter in it (0 for full resolution), so a
 * client's screen-space error in pixels is asp_hier_select's tau. Written
 * tile by tile: memory beyond the hierarchy is one tile's content. Files
 * are written atomically, tileset.json last. stats may be NULL.
 * Errors: ASP_EINVAL (desc with levels, directory name too long),
 * ASP_EIO (cannot create or write), ASP_ENOMEM. Thread-safe.
 */
int asp_tiles_export_hier(const asp_hier *hier, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                          asp_error *err);

/**
 * Writes the streamed hierarchy ooc (asp_ooc_open, docs/hier.md "Streamed
 * layout") as a 3D Tiles 1.1 tileset in directory dir (created if missing):
 * one tile per node with points, refine ADD (a node's points are a
 * subsample its descendants' points complete, each point stored once, so a
 * view draws the union of its tiles' contents, as asp_ooc_load loads a cut),
 * dir/tiles/<node id>.glb holding the node's own points as compact glTF
 * POINTS (POSITION 16-bit in the node's box, COLOR_0 8-bit linear; with
 * ASP_GLTF_PLAIN float positions, uncompressed), no normals and no
 * KHR_gaussian_splatting: they are round discs, whose radius
 * (asp_ooc_disc_radius) is in the mesh's extras.amgsplat.pointRadius.
 * geometricError is the node's point spacing (0 at leaves), so a client's
 * screen-space error in pixels is asp_ooc_select's tau; boxes hold the
 * subtree's points. Frames as asp_tiles_export_hier (y-up GLBs, z-up
 * boxes, the origin in the root transform). Reads one node at a time:
 * memory is the node table and the largest node. desc->tile_points must be
 * 0 (the nodes are the tiles). Files are written atomically, tileset.json
 * last. Moves ooc's file position (not thread safe on one ooc). stats may
 * be NULL; splats counts points.
 * Errors: ASP_EINVAL (desc with levels or tile_points, directory name too
 * long), ASP_EIO (cannot read the points, create or write), ASP_ENOMEM.
 */
int asp_tiles_export_ooc(asp_ooc *ooc, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                         asp_error *err);

/**
 * Writes the levels of dps as a 3D Tiles 1.1 tileset in directory dir
 * (created if missing): one tile a level, dir/tiles/<level name>.glb as
 * asp_gltf_export_dps writes that level (positions relative to the frame
 * centre, which the root transform adds), the coarsest level the root and
 * each level's one child the next finer, refine REPLACE, so a client
 * draws whole levels, coarse first. geometricError of a level is the largest
 * error + 0.2 x half diagonal of its primitives (the cut renderer's measure,
 * asp_dps_cut_view), at least the finer levels', 0 for the finest; boxes
 * hold the support rectangles of the level and the finer ones. stats: tiles
 * = levels, splats = primitives over all levels, largest = the largest
 * level's primitives, points = the source's points. desc: gltf flags and
 * alpha mode as asp_gltf_export_dps; no levels, tile_points 0.
 * Errors: ASP_EINVAL (desc with levels or tile_points, directory name too
 * long), ASP_EDEGENERATE (no level), ASP_EIO, ASP_ENOMEM.
 */
int asp_tiles_export_dps(const asp_dps *dps, const char *dir, const asp_tiles_desc *desc, asp_tiles_stats *stats,
                         asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
