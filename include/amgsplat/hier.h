/*
 * Multiresolution point hierarchy (Pajarola, Sainz, Guidotti 2003, section 3):
 * a point-octree with mean positions, normals, colours, covariances (eq. 2-4),
 * covering tangent ellipses (eq. 5-6, Fig. 6), bounding spheres and normal cones;
 * GL-free view-dependent cuts (Schwarz 2004, 3.2); an on-disk form. docs/hier.md.
 */
#ifndef AMGSPLAT_HIER_H
#define AMGSPLAT_HIER_H

#include "cloud.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The hierarchy; opaque, immutable after build or load. */
typedef struct asp_hier asp_hier;

/**
 * One elliptical splat (64 bytes, GL std430 friendly). Coordinates are in the
 * hierarchy's local frame: the positions of the source cloud, i.e. world
 * minus asp_hier_origin(). The ellipse lies in the plane through center
 * perpendicular to normal: center + s * a * u + t * b * v with s^2 + t^2 <= 1.
 */
typedef struct asp_hier_splat {
    float center[3];  /* mean position of the points represented */
    uint8_t color[4]; /* RGBA 8-bit sRGB; RGB averaged in linear light, alpha linearly */
    float normal[3];  /* unit normal */
    asp_index index;  /* point splat: index of the input point; node splat: the node id */
    float u[3];       /* unit major axis direction, perpendicular to normal */
    float a;          /* major semi-axis length (>= b >= 0) */
    float v[3];       /* unit minor axis direction, perpendicular to normal and u */
    float b;          /* minor semi-axis length */
} asp_hier_splat;

/**
 * Topology and culling data of one node (48 bytes). Node 0 is the root; the
 * children of a node are the contiguous nodes [first_child, first_child +
 * child_count) and always have larger ids than their parent, so a sweep in
 * decreasing id visits children before parents. The points of a node's
 * subtree are the contiguous hierarchy-order points [first_point, first_point
 * + point_count).
 */
typedef struct asp_hier_node {
    float sphere[4];       /* bounding sphere centre xyz and radius; contains the children's spheres and the node's ellipse */
    float cone_angle;      /* normal-cone semi-angle in radians around the node splat's normal, in [0, pi]; pi = no culling */
    asp_index parent;      /* parent node id; UINT32_MAX for the root */
    asp_index first_child; /* first child node id (0 for a leaf) */
    uint32_t child_count;  /* 0 for a leaf, else 2..8 */
    asp_index first_point; /* first point of the subtree, hierarchy order */
    uint32_t point_count;  /* points in the subtree (>= 1); a leaf holds 1..leaf_size */
    uint32_t depth;        /* root = 0 */
    uint32_t reserved;     /* 0 */
} asp_hier_node;

/** Build flags (asp_hier_desc.flags). */
enum asp_hier_build_flags {
    ASP_HIER_BUILD_IGNORE_RADII = 1 << 0, /* use k-neighbourhood ellipses even if the cloud has radii */
    /*
     * Seed 001 eq. 5-6 as written: axis ratio b'/a' = lambda_2 / lambda_1 of the tangent-plane covariance.
     * Default: sqrt(lambda_2 / lambda_1), the ratio of the standard deviations, i.e. of the point spread
     * (a uniform 4:1 rectangle gets a 4:1 ellipse, not 16:1); f rescales both axes either way.
     */
    ASP_HIER_BUILD_LAMBDA_AXES = 1 << 1
};

/** What the hierarchy was built from (asp_hier_flags()). */
enum asp_hier_flags {
    ASP_HIER_HAS_COLORS = 1 << 0,   /* the cloud had colours (else all splats are opaque white) */
    ASP_HIER_UNORIENTED = 1 << 1,   /* no input normals: PCA normals with arbitrary sign, cones are pi */
    ASP_HIER_KNN_ELLIPSES = 1 << 2  /* point ellipses came from k-neighbourhoods, not radii */
};

/** Build options; the zero value means the defaults. */
typedef struct asp_hier_desc {
    size_t leaf_size; /* most points in a leaf node; 0 = 8; at most 65536 */
    size_t k;         /* neighbours for point ellipses (and normals if the cloud has none); 0 = 8; at most 1024 */
    unsigned flags;   /* asp_hier_build_flags */
} asp_hier_desc;

/**
 * Builds the hierarchy over cloud (positions required; normals, colours and
 * radii used when present). Point ellipses: a circle of the point's radius in
 * the plane perpendicular to its normal when the cloud has radii, else the
 * bounding ellipse of its k nearest neighbours in that plane (seed 001, end of
 * 3.4). Without normals, each point's normal is the smallest-eigenvalue
 * eigenvector of its neighbourhood (unoriented; ASP_HIER_UNORIENTED).
 * desc may be NULL (defaults). Deterministic: identical results for any
 * thread count. The caller frees *out with asp_hier_destroy; the cloud is not
 * referenced afterwards. On failure *out is unchanged.
 * Errors: ASP_EINVAL (leaf_size > 65536, k > 1024, a NaN/infinite coordinate, normal or
 * radius), ASP_EDEGENERATE (empty cloud), ASP_ENOMEM, ASP_ECANCELED.
 * Thread safety: reentrant; uses asp_context_threads(ctx) OpenMP threads.
 */
int asp_hier_build(const asp_cloud *cloud, const asp_hier_desc *desc, const asp_context *ctx,
                   asp_hier **out, asp_error *err);

/** Frees the hierarchy; NULL is accepted. */
void asp_hier_destroy(asp_hier *hier);

/** Number of nodes (>= 1). */
size_t asp_hier_node_count(const asp_hier *hier);
/** Number of input points (>= 1). */
size_t asp_hier_point_count(const asp_hier *hier);
/** Largest node depth (root = 0); the points below a leaf of depth d count as depth d + 1. */
uint32_t asp_hier_depth(const asp_hier *hier);
/** Bit set of asp_hier_flags. */
unsigned asp_hier_flags(const asp_hier *hier);
/** The leaf size it was built with. */
size_t asp_hier_leaf_size(const asp_hier *hier);
/** World position of the local origin (the source cloud's origin). */
void asp_hier_origin(const asp_hier *hier, double out[3]);

/**
 * Frame (asp_cloud_frame) of the source point set, recorded in the .hier file,
 * so a hierarchy is framed exactly as its source points. Valid until
 * asp_hier_destroy.
 */
const asp_frame *asp_hier_frame(const asp_hier *hier);

/** The node array (asp_hier_node_count entries); valid until asp_hier_destroy. */
const asp_hier_node *asp_hier_nodes(const asp_hier *hier);

/**
 * All splats, valid until asp_hier_destroy: node_count + point_count entries.
 * Splat s < node_count is node s's representative ellipse; splat node_count + j
 * is point j in hierarchy order (its index field is the input point index).
 * Selections (asp_hier_select) return indices into this array.
 */
const asp_hier_splat *asp_hier_splats(const asp_hier *hier);

/**
 * Generic homogeneous covariances (seed 001 eq. 2-4), 10 doubles per node:
 * the upper triangle of sum_i p'_i p'_i^T with p' = (x, y, z, 1), in the order
 * xx xy xz x yy yz y zz z n (n = point count). Valid until asp_hier_destroy.
 */
const double *asp_hier_covariances(const asp_hier *hier);

/**
 * Writes the hierarchy to path atomically (temporary file + rename): a
 * versioned little-endian binary with an FNV-1a 64 checksum of the payload.
 * Returns 0, ASP_EIO or ASP_ENOMEM. Thread-safe for concurrent reads.
 */
int asp_hier_save(const asp_hier *hier, const char *path, asp_error *err);

/**
 * Loads a hierarchy written by asp_hier_save (version 2, with the recorded
 * frame; a version-1 file is framed by its root bounding sphere) through the
 * shared byte reader: a directory or FIFO is refused (ASP_EIO) before it is
 * opened. A truncated, corrupted (checksum
 * mismatch) or structurally inconsistent file fails with ASP_EFORMAT naming the
 * file and the byte offset or element; a newer version with ASP_EUNSUPPORTED;
 * ASP_EIO if it cannot be read; ASP_ENOMEM. Sizes are checked against the
 * file size before anything large is allocated. On failure *out is unchanged.
 */
int asp_hier_load(const char *path, const asp_context *ctx, asp_hier **out, asp_error *err);

/** Like asp_hier_load from a memory buffer (name is used in messages; may be NULL). */
int asp_hier_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx,
                         asp_hier **out, asp_error *err);

/* ---- view-dependent cuts (seed 001 section 5.1 step 1; seed 004 section 3.2) ---- */

/**
 * A view. Matrices are column-major (OpenGL): clip = proj * view * (x, y, z, 1)
 * for hierarchy-local x, y, z; the camera looks down -z in eye space.
 * A projection with proj[15] == 1 is orthographic.
 */
typedef struct asp_hier_view {
    float view[16];
    float proj[16];
    uint32_t width, height; /* viewport in pixels (> 0) */
    float tau;              /* pixels: a node whose projected ellipse diameter is < tau is drawn instead of its children */
    int cull_backfaces;     /* drop subtrees whose whole normal cone faces away from eye (ignored if unoriented) */
    int no_frustum_cull;    /* keep subtrees outside the view frustum */
    float eye[3];           /* camera position, hierarchy-local (perspective back-face test) */
    uint32_t depth_limit;   /* 0 = none; else only splats of depth < depth_limit (seed 004 Fig. 3.5) */
} asp_hier_view;

struct asp_camera;
/**
 * The view of cam (asp_camera, camera.h: its view and projection matrices and eye) for a
 * width x height viewport and tolerance tau; culling flags and depth limit off. out is
 * hierarchy-local when cam is (the renderers' local frame).
 */
void asp_hier_view_of_camera(const struct asp_camera *cam, uint32_t width, uint32_t height, float tau,
                             asp_hier_view *out);

/** Capacity that always suffices for a selection: the point count. */
size_t asp_hier_select_bound(const asp_hier *hier);

/**
 * Cut for one view: traverses depth first from the root, dropping subtrees
 * whose bounding sphere lies outside the frustum or (cull_backfaces) whose
 * normal cone faces away from every point of the sphere as seen from eye.
 * A node whose projected ellipse diameter (2a) is < tau, or at depth
 * depth_limit - 1, is emitted; a leaf that is not is replaced by its points,
 * each culled alike. A visible node whose children are all culled is emitted
 * itself, so the count never grows with tau. tau = 0 with nothing culled
 * emits every point. Writes splat ids (into asp_hier_splats) to dst in
 * traversal order, at most capacity of them, and the total found to *count
 * (which may exceed capacity: call again with asp_hier_select_bound).
 * Errors: ASP_EINVAL (zero viewport, negative or NaN tau). Thread-safe.
 */
int asp_hier_select(const asp_hier *hier, const asp_hier_view *view, asp_index *dst, size_t capacity,
                    size_t *count, asp_error *err);

/**
 * Cut to about target splats for a view (tau and depth_limit are ignored):
 * starting from the root, repeatedly replaces the splat of largest projected
 * diameter by its visible children (or a leaf by its points), skipping any
 * whose expansion would exceed target, until nothing more fits. Culling as in
 * asp_hier_select, except that a node whose children (or a leaf whose points)
 * are all culled is left out rather than drawn: with no tau to keep monotone
 * it would only blur past the silhouette. Writes min(result, capacity) ids and
 * the result count (<= target, equal to min(target, visible points) unless the
 * tree's fan-out prevents it) to *count; a target of at least the visible
 * points gives asp_hier_select's tau = 0 cut without its fallback nodes. Ties
 * are broken by splat id: deterministic.
 * Errors: ASP_EINVAL, ASP_ENOMEM (scratch heap). Thread-safe.
 */
int asp_hier_select_count(const asp_hier *hier, const asp_hier_view *view, size_t target, asp_index *dst,
                          size_t capacity, size_t *count, asp_error *err);

/* ---- adaptive traversal depth (seed 004 section 3.2.5, Fig. 3.5) ---- */

/** What the controller adjusts. */
enum asp_hier_adapt_mode {
    ASP_HIER_ADAPT_DEPTH = 0, /* the depth limit, as in Fig. 3.5 */
    ASP_HIER_ADAPT_TAU = 1    /* the screen tolerance tau, multiplicatively */
};

/** Controller options; zero fields take the defaults noted. */
typedef struct asp_hier_adapt_desc {
    double f_min, f_max; /* frame-time band in seconds, 0 < f_min <= f_max (required) */
    int mode;            /* asp_hier_adapt_mode */
    uint32_t depth_min;  /* initial k_min; 0 = 1 */
    uint32_t depth_max;  /* deepest useful limit, e.g. asp_hier_depth() + 2; 0 = 64 */
    float tau;           /* initial tau; 0 = 1 pixel */
    float tau_min;       /* 0 = 0.25 pixel */
    float tau_max;       /* 0 = 1024 pixels */
    float tau_step;      /* factor per adjustment (> 1); 0 = 1.25 */
} asp_hier_adapt_desc;

/** Controller state; fields are readable, change them only through the functions. */
typedef struct asp_hier_adapt {
    asp_hier_adapt_desc desc;
    uint32_t depth_min; /* k_min of Fig. 3.5 */
    uint32_t depth;     /* k_0: the depth limit for the next frame */
    float tau;          /* tau for the next frame */
    int refine;         /* last result of asp_hier_adapt_update */
} asp_hier_adapt;

/** Initialises a from desc. Returns 0 or ASP_EINVAL (bad band or tau range). */
int asp_hier_adapt_init(asp_hier_adapt *a, const asp_hier_adapt_desc *desc, asp_error *err);

/**
 * Feeds the last frame time (seconds) and whether the view changed (event).
 * DEPTH mode, Fig. 3.5: a frame faster than f_min raises k_min and sets k_0 =
 * k_min; a frame slower than f_max lowers k_0 (and k_min with it when k_0
 * would drop below it, so an event does not return to a depth known to be
 * too slow); an event sets k_0 = k_min. TAU mode: faster than f_min divides
 * tau by tau_step, slower than f_max multiplies it, within [tau_min, tau_max].
 * Returns refine: 1 if the next frame may add detail, 0 after a slow frame.
 */
int asp_hier_adapt_update(asp_hier_adapt *a, double frame_time, int event);

/** Copies the controller's depth limit (DEPTH mode) or tau (TAU mode) into view. */
void asp_hier_adapt_apply(const asp_hier_adapt *a, asp_hier_view *view);

#ifdef __cplusplus
}
#endif
#endif
