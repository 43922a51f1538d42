/*
 * Out-of-core point hierarchy (issue 28; docs/hier.md "Streamed layout"): an
 * octree built from point files larger than memory by a chunked counting sort
 * and per-chunk octrees whose inner nodes hold a grid subsample of their
 * children's points (each point stored once, as Schuetz, Ohrhallinger and
 * Wimmer 2020 and PotreeConverter 2 do), written as a .hier file whose header
 * flag ASP_HIER_STREAMED tells it from the in-memory layout; and the reader
 * that opens only the node table and loads the points of a view's cut.
 */
#ifndef AMGSPLAT_HIER_OOC_H
#define AMGSPLAT_HIER_OOC_H

#include "hier.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Header flag (asp_hier_flags bit) of a streamed .hier; asp_hier_load refuses it with ASP_EUNSUPPORTED. */
#define ASP_HIER_STREAMED (1u << 3)

/**
 * One node of a streamed hierarchy (56 bytes in the file, little endian).
 * Node 0 is the root; children are contiguous with larger ids than their
 * parent. A node's points are its own (a subsample for inner nodes, the rest
 * for leaves): the points of a cut are the union of its nodes' points, and
 * all nodes' points together are the input, each point once.
 */
typedef struct asp_ooc_node {
    float center[3];         /* cube centre, hierarchy-local (world minus origin) */
    float half;              /* cube half side */
    float spacing;           /* typical distance between neighbouring points of this node and its ancestors */
    uint32_t parent;         /* UINT32_MAX for the root */
    uint32_t first_child;    /* 0 for a leaf */
    uint32_t child_count;    /* 0..8 */
    uint64_t first_point;    /* index of its first point record */
    uint32_t point_count;    /* points stored in this node */
    uint32_t depth;          /* root = 0 */
    uint64_t subtree_points; /* points in this node and below */
} asp_ooc_node;

/** A point record: hierarchy-local position and sRGB colour (16 bytes). */
typedef struct asp_ooc_point {
    float position[3];
    uint8_t color[4];
} asp_ooc_point;

/** Conversion options; the zero value means the defaults. */
typedef struct asp_ooc_build_desc {
    size_t memory;        /* working-set budget in bytes; 0 = 2 GiB; at least 64 MiB */
    size_t node_points;   /* most points in a leaf; 0 = 32768 */
    const char *temp_dir; /* directory for the chunk files; NULL = next to the output */
} asp_ooc_build_desc;

/** What a conversion did. */
typedef struct asp_ooc_build_stats {
    uint64_t points;
    size_t nodes, chunks;
    uint32_t depth;
    uint32_t grid;            /* counting grid cells per side */
    double seconds_bounds;    /* pass 1: bounds */
    double seconds_count;     /* pass 2: counting sort counts */
    double seconds_distribute;/* pass 3: points to chunk files */
    double seconds_index;     /* per-chunk octrees, the top, the node table */
} asp_ooc_build_stats;

/**
 * Converts the point file in (asp_point_reader: binary PLY, LAS) into a
 * streamed hierarchy at out, atomically, with at most about desc->memory
 * bytes of working set whatever the input size. Chunk files go to
 * desc->temp_dir (or out's directory) and are removed afterwards. Inner
 * nodes keep one point per cell of a 128^3 grid over their cube, taken from
 * their children's points in a fixed pseudo-random order, so the file is
 * identical for any thread count. stats may be NULL. Progress stages:
 * "bounds", "count", "distribute", "index". Returns 0; the reader's errors;
 * ASP_EDEGENERATE (no points); ASP_EFORMAT (a non-finite coordinate, naming
 * the point); ASP_EINVAL (memory below 64 MiB); ASP_EIO; ASP_ENOMEM;
 * ASP_ECANCELED. Uses asp_context_threads(ctx) threads for the chunks.
 */
int asp_ooc_build(const char *in, const char *out, const asp_ooc_build_desc *desc, const asp_context *ctx,
                  asp_ooc_build_stats *stats, asp_error *err);

/** An open streamed hierarchy: the header and node table in memory, points read on demand. Opaque. */
typedef struct asp_ooc asp_ooc;

/**
 * 1 when path is a .hier in the streamed layout, 0 when it is any other
 * file (or an in-memory .hier), ASP_EIO when it cannot be read.
 */
int asp_ooc_probe(const char *path);

/**
 * Opens a streamed hierarchy: reads and checks the header (checksum, sizes
 * against the file) and the node table (checksum, tree structure, point
 * ranges inside the file that partition the points). Returns 0; ASP_EIO;
 * ASP_EFORMAT naming the file and the byte or node; ASP_EUNSUPPORTED (an
 * in-memory .hier: asp_hier_load reads it); ASP_ENOMEM. Free with
 * asp_ooc_close. Reading points is not thread safe on one asp_ooc.
 */
int asp_ooc_open(const char *path, const asp_context *ctx, asp_ooc **out, asp_error *err);

/** Closes the file and frees the object; NULL is accepted. */
void asp_ooc_close(asp_ooc *ooc);

size_t asp_ooc_node_count(const asp_ooc *ooc);
uint64_t asp_ooc_point_count(const asp_ooc *ooc);
uint32_t asp_ooc_depth(const asp_ooc *ooc);
/** The node table (asp_ooc_node_count entries), valid until asp_ooc_close. */
const asp_ooc_node *asp_ooc_nodes(const asp_ooc *ooc);
/** World position of the local origin. */
void asp_ooc_origin(const asp_ooc *ooc, double out[3]);
/** Frame of the source points (as asp_cloud_frame), valid until asp_ooc_close. */
const asp_frame *asp_ooc_frame(const asp_ooc *ooc);

/**
 * The cut for one view, coarse first: starting at the root, repeatedly
 * refines the visible node whose point spacing projects largest on screen,
 * while that is above view->tau pixels (0 = 1 pixel) and the points of the
 * cut stay within max_points. Frustum culling by the node cubes' bounding
 * spheres (ignored with view->no_frustum_cull). Writes node ids to dst
 * (capacity asp_ooc_node_count), parents before children, the node count to
 * *count and their points to *points. Thread safe. Returns 0 or ASP_EINVAL
 * (zero viewport), ASP_ENOMEM.
 */
int asp_ooc_select(const asp_ooc *ooc, const asp_hier_view *view, uint64_t max_points, uint32_t *dst, size_t *count,
                   uint64_t *points, asp_error *err);

/**
 * The points of a cut that memory bytes hold while it is drawn: 64 bytes a point (the cloud's
 * position, colour and radius, 20, the renderer's copies in GL buffers, 20 on llvmpipe where
 * buffers are host memory, and the driver's staging); memory 0 = 2 GiB. The budget render and
 * view give asp_ooc_select for --memory.
 */
uint64_t asp_ooc_budget_points(size_t memory);

/**
 * Loads the points of the given nodes (a cut from asp_ooc_select: closed
 * under parents) into a new cloud with positions (hierarchy-local, origin
 * set), colours and radii. A point whose deepest listed node (holding it) is
 * a leaf gets the disc radius the whole set gets when drawn from memory
 * (asp_cloud_default_radius, recorded at conversion), so a cut at full detail
 * draws as the point file does; elsewhere 2 / sqrt(pi) times that node's
 * spacing, if larger, so coarse cuts stay closed. Returns 0, ASP_EIO, ASP_EFORMAT
 * (file shorter than its node table says), ASP_EINVAL (more than 2^32 - 2
 * points), ASP_ENOMEM.
 */
int asp_ooc_load(asp_ooc *ooc, const uint32_t *nodes, size_t count, asp_cloud **out, asp_error *err);

/**
 * The disc radius asp_ooc_load gives a point whose deepest loaded node is
 * node: at a leaf, the radius the whole set gets when drawn from memory
 * (asp_cloud_default_radius, recorded at conversion); above, 2 / sqrt(pi)
 * times the node's spacing if that is larger, so coarse cuts stay closed.
 * Hierarchy-local units. Pure.
 */
float asp_ooc_disc_radius(const asp_ooc *ooc, uint32_t node);

/**
 * Reads the points stored in node (its own, asp_ooc_node.point_count of
 * them, hierarchy-local, in the source's frame) into dst, which holds at
 * least that many records. Reading one node at a time keeps memory at the
 * largest node whatever the set's size (asp_tiles_export_ooc). Returns 0,
 * ASP_EIO (a read failed or the file is shorter than its node table says,
 * naming the node), ASP_EINVAL (node out of range). Not thread safe on one
 * asp_ooc (one file position), as asp_ooc_load.
 */
int asp_ooc_read_points(asp_ooc *ooc, uint32_t node, asp_ooc_point *dst, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
