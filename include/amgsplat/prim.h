/*
 * Domain primitives (journal section 3, thesis chapter 3): every domain of an
 * AMG level becomes one planar rectangle (PCA support polygon, thesis 3.1)
 * with a texture whose colour holds the points' colours and whose alpha holds
 * the domain's basis function (thesis 3.3); neighbour lists for rendering
 * (journal section 4); and the .dps file that stores several levels.
 */
#ifndef AMGSPLAT_PRIM_H
#define AMGSPLAT_PRIM_H

#include "amg.h"
#include "cloud.h"
#include "image.h"
#include "io.h"
#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- options ---- */

/** Texture construction method (thesis 3.3). */
typedef enum asp_prim_method {
    ASP_PRIM_AFFINE = 0, /* linear affine: 2D Delaunay + barycentric, radial linear outside (3.3.3); default */
    ASP_PRIM_RADIAL = 1  /* radial basis functions summed per texel (3.3.2) */
} asp_prim_method;

/** Radial basis-function shape (thesis 3.3.2); d = texel distance, R = w r. */
typedef enum asp_prim_shape {
    ASP_PRIM_LINEAR = 0,   /* 1 - d/R inside R; default */
    ASP_PRIM_CONSTANT = 1, /* 1 inside R */
    ASP_PRIM_GAUSSIAN = 2  /* exp(-d^2 / 2 sigma^2), sigma = R/3, cut at R (value 0.011) */
} asp_prim_shape;

/** Per-texel normalisation criterion of the radial sum f(t) = sum phi_p(t) (thesis eq. 3.3 / 3.4). */
typedef enum asp_prim_normalise {
    ASP_PRIM_NORM_POSITIVE = 0, /* divide by f where f > 0 (eq. 3.4); default */
    ASP_PRIM_NORM_GE1 = 1       /* divide by f only where f >= 1 (eq. 3.3): alpha fades at the border */
} asp_prim_normalise;

/** Which domains become primitives (asp_prim_desc.strict; thesis 2.5 and appendix C "Domain Set"). */
typedef enum asp_prim_domain_set {
    ASP_PRIM_DOMAINS_THRESHOLDED = 0, /* Psi > tau, overlapping (journal eq. 8); default */
    ASP_PRIM_DOMAINS_STRICT = 1,      /* each point in the domain of its largest Psi (thesis eq. 2.5) */
    ASP_PRIM_DOMAINS_BOTH = 2         /* both, so one file switches between them */
} asp_prim_domain_set;

/**
 * The texture fills of a batch of primitives, for a texture builder outside
 * the library's CPU path (thesis 3.6: on the graphics hardware,
 * asp_prim_gpu_fill_set in render.h). Primitive k has samples
 * sample_first[k] .. sample_first[k + 1] - 1 and a w[k] x h[k] texel grid
 * stored from texel texel_first[k] on, row by row; sample s lies at (x[s],
 * y[s]) in texel units (texel i spans [i, i + 1)), footprint radius r[s]
 * texels, attributes attr[4 s ..] = r, g, b (0..255), Psi. Affine: the kept
 * Delaunay triangles tri[3 t ..] (global sample indices), tri_first[k] ..
 * tri_first[k + 1] - 1 per primitive.
 */
typedef struct asp_prim_fill_batch {
    size_t prim_count;
    const size_t *sample_first, *texel_first, *tri_first; /* prim_count + 1 entries each */
    const uint32_t *w, *h;
    const float *x, *y, *r, *attr;
    const uint32_t *tri;
    int method;          /* asp_prim_method */
    int shape;           /* asp_prim_shape (radial) */
} asp_prim_fill_batch;

/**
 * A texture fill (asp_prim_desc.fill): writes per texel t < texel_first[prim_count]
 * acc[4 t ..] (the sum of phi times the attributes, or for affine the
 * barycentric interpolation where covered[t] = 1), f[t] (the sum of phi) and
 * covered[t], exactly as the CPU path's first half does (texture.c); the
 * library then normalises, extends colour and encodes. Buffers arrive
 * zeroed. Returns 0 or an ASP_E* code with err filled.
 */
typedef int (*asp_prim_fill_fn)(void *user, const asp_prim_fill_batch *batch, float *acc, float *f, uint8_t *covered,
                                asp_error *err);

/**
 * Build options; the zero value means the documented defaults, so
 * `&(asp_prim_desc){ .texel_size = 2 }` works.
 */
typedef struct asp_prim_desc {
    double tau;              /* domain threshold: points with Psi > tau (0 = 0.05, journal eq. 8) */
    double texel_size;       /* texel edge = texel_size x mean point radius (0 = 1, thesis 5.2.1) */
    uint32_t max_texture;    /* cap on a primitive's texture side in texels (0 = 512); the texel grows */
    asp_prim_method method;
    asp_prim_shape shape;    /* radial only */
    double width;            /* radial width factor w (0 = 1) */
    asp_prim_normalise normalise; /* radial only */
    int unweighted;          /* 1: plain PCA instead of PCA weighted by Psi */
    int project_radii;       /* 1: radius r |n_p . n_plane| (thesis 3.1) */
    int no_extend_color;     /* 1: leave texels without coverage black (thesis 3.3.4 off) */
    int normal_map;          /* 1: also build a per-texel normal atlas (journal section 6) */
    double neighbour_fraction; /* neighbours share more than this fraction of either's points (0 = 0.05) */
    int merge;               /* 1: greedy domain merging (thesis 3.4) */
    double merge_flatness;   /* merge while l_min / sum l of both and the union is below this (0 = 0.01) */
    double merge_angle;      /* and their normals differ by less than this, degrees (0 = 15) */
    uint32_t padding;        /* atlas padding around each texture, texels (0 = 2) */
    int normalise_color;     /* 1: the radial criterion decides for colour too, as eq. 3.3 reads (colour not
                                divided where f < 1, so it darkens with alpha at a domain's border); 0:
                                colour, stored straight, is always divided by f (an interpolation) */
    int no_model_colors;     /* 1: every point light grey 200 (thesis appendix C "Use Model Colors" unchecked) */
    double brightness;       /* thesis appendix C "Adjust Brightness": added to each point colour's HSV value,
                                in [-1, 1] (1 = full scale); hue and saturation kept; 0 = unchanged */
    int strict;              /* asp_prim_domain_set: 1 (ASP_PRIM_DOMAINS_STRICT): primitives of the strict domains
                                (thesis eq. 2.5, asp_amg_strict_domain_rows), alpha 1 inside, for the no-blend
                                method; 0: thresholded domains Psi > tau; 2 (ASP_PRIM_DOMAINS_BOTH): both sets,
                                each level twice, thresholded first (thesis appendix C "Domain Set") */
    double enlarge;          /* thesis appendix C "Enlarge Bounding Rectangle": > 0 grows the sides of the
                                points' bounding rectangle by this percentage (at most 1000) instead of the
                                default margin of one point footprint on every side (0) */
    asp_prim_fill_fn fill;   /* NULL: textures on the CPU; else the fills go to fill(fill_user, ...) in batches
                                (thesis 3.6; render.h asp_prim_gpu_fill_set); not with normal_map */
    void *fill_user;
} asp_prim_desc;

/* ---- one primitive ---- */

/**
 * A textured support rectangle. The rectangle is centre + s axis_u + t axis_v,
 * |s| <= half_u, |t| <= half_v; its texture is the atlas rectangle
 * [tex_x, tex_x + tex_w) x [tex_y, tex_y + tex_h), where atlas row tex_y + j
 * and column tex_x + i hold (s, t) = (-half_u + (i + 0.5) texel,
 * -half_v + (j + 0.5) texel). So tex_w texel = 2 half_u, tex_h texel = 2 half_v.
 */
typedef struct asp_prim {
    double centre[3];         /* world coordinates */
    float axis_u[3], axis_v[3]; /* unit, in-plane PCA axes; axis_u x axis_v = normal */
    float normal[3];          /* unit; faces the weighted mean of the point normals */
    float half_u, half_v;     /* half extents, world units, margin included */
    float texel;              /* texel edge, world units */
    float error;              /* mean |distance| of the domain's points to the plane (thesis 3.2) */
    float error_norm;         /* error / mean point radius of the cloud */
    float curvature;          /* l_min / (l0 + l1 + l2) of the (weighted) PCA (thesis 3.2, 3.4) */
    uint32_t points;          /* points in the domain (Psi > tau) */
    uint32_t basis;           /* index of the basis function (the first one when merged) */
    uint32_t merged;          /* basis functions summed into this one (1 unless merged) */
    uint32_t flags;           /* ASP_PRIM_FLAG_* */
    uint32_t tex_x, tex_y, tex_w, tex_h; /* texture rectangle in the level's atlas */
    uint32_t neighbour_first, neighbour_count; /* range in the level's neighbour array */
} asp_prim;

enum asp_prim_flags {
    ASP_PRIM_FLAG_DEGENERATE = 1 << 0, /* 1 or 2 points, or colinear: plane from the point normals */
    ASP_PRIM_FLAG_CAPPED = 1 << 1      /* max_texture was reached; texel is larger than asked */
};

/* ---- a built file ---- */

/** One level of a .dps: primitives, neighbour lists, atlases and the Table 5.2 figures. */
typedef struct asp_dps_level {
    uint32_t level;           /* AMG level index (0 = points) */
    uint32_t basis_count;     /* basis functions of the level (before skipping and merging) */
    size_t prim_count;
    asp_prim *prims;
    size_t neighbour_total;   /* entries of neighbours (each pair appears twice) */
    uint32_t *neighbours;     /* prim indices, sorted within each primitive's range */
    asp_image atlas;          /* RGBA8: colour (sRGB, straight) + alpha = basis function */
    asp_image normal_atlas;   /* RGB = world normal * 0.5 + 0.5, A = alpha; width 0 when absent */
    uint64_t texels;          /* sum of tex_w * tex_h */
    double error, error_norm; /* mean over all domain points (thesis Table 5.2 "error", "normalized") */
    double t_basis;           /* seconds to get Psi and the domains ("cb") */
    double t_construct;       /* seconds for planes, textures, atlas, neighbours ("dpc") */
    uint32_t skipped;         /* basis functions without a point above tau */
    uint32_t degenerate;      /* primitives flagged DEGENERATE */
    uint32_t capped;          /* primitives flagged CAPPED */
    uint32_t merges;          /* merge operations performed */
    uint32_t strict;          /* 1: built from strict domains (thesis eq. 2.5, desc.strict), drawn with the
                                 no-blend method; a .dps may hold thresholded and strict levels side by side */
    /*
     * Links to the next coarser stored level (issue 18; journal section 6, thesis 2.6.3): primitive k's
     * share of coarse primitive link_parent[q] (an index into the next level's prims) is link_weight[q],
     * q in link_first[k] .. link_first[k + 1] - 1, such that sum_k w(k -> c) Psi_k ~= Psi_c (docs/cut.md).
     * link_first is NULL (link_total 0) on the coarsest level and when unknown (.dps versions 1, 2).
     */
    size_t link_total;
    uint32_t *link_first;     /* prim_count + 1 entries */
    uint32_t *link_parent;    /* link_total; increasing within a primitive's range */
    float *link_weight;       /* link_total, in (0, 1] */
    /*
     * The atlases as BC3 (DXT5) blocks, stored so in the .dps and uploaded so (issue 27;
     * asp_dps_level_compress): 16 bytes per 4x4 block, 1 byte per texel. NULL (normal_bc3 also when there
     * is no normal atlas) for an RGBA8 level. When set, atlas and normal_atlas hold the decoded texels,
     * what the GPU samples, so every CPU path (fit rasteriser, export) sees the same picture. Allocated
     * through the level's context; any change of the atlas texels must drop them (asp_free, NULL).
     */
    uint8_t *atlas_bc3, *normal_bc3;
    /*
     * 1: a billboard cloud (issue 30, asp_billboard_mesh in billboard.h): textured planes with a binary
     * alpha mask, drawn alpha-tested and opaque with depth test and write, never blended or normalised.
     */
    uint32_t billboards;
} asp_dps_level;

/** A set of levels; create with asp_prim_build or asp_dps_load, free with asp_dps_destroy. */
typedef struct asp_dps {
    size_t level_count;
    asp_dps_level *levels;    /* finest first */
    uint32_t amg_levels;      /* level count of the decomposition (to name levels "L-k") */
    uint32_t skipped_levels;  /* requested levels left out because no domain had a point above tau */
    uint64_t source_points;
    double mean_radius;       /* mean point radius, world units */
    asp_prim_desc desc;       /* parameters used, defaults resolved */
    char source[256];         /* the input file's name (may be empty) */
    asp_frame frame;          /* the source point set's frame (asp_cloud_frame), for one camera framing;
                                 radius 0 when unknown */
    asp_context ctx;
} asp_dps;

/* ---- building ---- */

/**
 * Builds the primitives of levels[0 .. nlevels-1] of amg (indices as given by
 * asp_amg_level_parse; nlevels >= 1, each < asp_amg_level_count) into a new
 * asp_dps (*out, levels stored finest first, duplicates removed; a level
 * whose domains are all empty is left out and counted in skipped_levels). Colours and
 * radii come from attrs when it is not NULL (it must have the amg's point
 * count), else from asp_amg_cloud(amg); missing colours are light grey,
 * missing radii are estimated (16th neighbour). source names the input in the
 * file (NULL = ""). desc may be NULL (defaults). Runs with
 * asp_context_threads(ctx) threads; the result is identical for any count.
 * Errors: ASP_EINVAL (bad option, level out of range, attrs of another size),
 * ASP_EDEGENERATE (every requested level is empty), ASP_ENOMEM,
 * ASP_EUNSUPPORTED (an atlas would exceed 16384 texels a side: raise
 * texel_size), ASP_ECANCELED. On failure *out is unchanged. Reports progress
 * as stage "primitives". Thread-safe on a shared amg.
 */
int asp_prim_build(const asp_amg *amg, const asp_cloud *attrs, const size_t *levels, size_t nlevels,
                   const asp_prim_desc *desc, const char *source, const asp_context *ctx, asp_dps **out,
                   asp_error *err);

/**
 * Builds one level from explicit domains: dom has one row per domain listing
 * its points (indices into cloud, increasing) and their Psi values, as
 * asp_amg_domains writes it; dom->cols == cloud->count. cloud needs positions;
 * normals, colours and radii are used when present (radii are estimated
 * otherwise). Empty rows are skipped and counted; domains of 1 or 2 points or
 * colinear points become small primitives flagged DEGENERATE, their plane
 * normal taken from the point normals. Fills *out (level = 0, t_basis = 0;
 * release with asp_dps_level_release). Errors: ASP_EINVAL, ASP_EDEGENERATE
 * (every row empty, or no positive radius), ASP_ENOMEM, ASP_EUNSUPPORTED
 * (atlas too large). On failure *out is zeroed. Thread-safe.
 */
int asp_prim_build_level(const asp_cloud *cloud, const asp_amg_csr *dom, const asp_prim_desc *desc,
                         const asp_context *ctx, asp_dps_level *out, asp_error *err);
/** Frees what asp_prim_build_level put in lv (ctx as given to it) and zeroes it. */
void asp_dps_level_release(asp_dps_level *lv, const asp_context *ctx);

/**
 * Picks the finest level with at most max_prims basis functions (the budget
 * --primitives N); when even the coarsest has more, the coarsest. Returns 0,
 * or ASP_EINVAL for max_prims == 0.
 */
int asp_prim_level_for_budget(const asp_amg *amg, size_t max_prims, size_t *level, asp_error *err);

/**
 * Picks the level whose basis function count is nearest prims (build
 * --primitives N, issue 29: 300 gives the level with 372 rather than the one
 * with 161); of two equally near, the finer. Returns 0, or ASP_EINVAL for
 * prims == 0.
 */
int asp_prim_level_nearest(const asp_amg *amg, size_t prims, size_t *level, asp_error *err);

/** Frees a dps and everything it owns; NULL is accepted. */
void asp_dps_destroy(asp_dps *dps);

/* ---- links between levels and the view-dependent cut (issue 18, docs/cut.md) ---- */

/**
 * Fills the links of every stored level but the coarsest of dps (built from amg by asp_prim_build, so
 * levels and basis indices refer to amg): w(j -> k) = (P^{a+1} ... P^b)[basis_j][basis_k] between AMG
 * levels a < b (Psi^b = Psi^a P^{a+1} ... P^b, journal 2.3), entries below 1e-4 dropped. A merged
 * level (thesis 3.4: a primitive stands for several basis functions whose list is not kept) and the
 * level above it get no links (NEEDSWORK: weights from the point overlap of the merged domains), nor
 * do neighbours of different domain sets or not increasing in AMG level.
 * Replaces links already there. Returns 0, ASP_EINVAL (dps not from amg: a level or basis index out of
 * range), ASP_ENOMEM; on failure the levels keep no links. Thread-safe on a shared amg.
 */
int asp_prim_links(const asp_amg *amg, asp_dps *dps, const asp_context *ctx, asp_error *err);

/** 1 when every level but the coarsest has links (a cut across levels is possible), else 0. */
int asp_dps_has_links(const asp_dps *dps);

/** One primitive of a cut: level index into dps->levels, primitive index, weight d_f in (0, 1]. */
typedef struct asp_dps_cut_item {
    uint32_t level, prim;
    float weight;
} asp_dps_cut_item;

/** The view a cut is taken for (coordinates of the dps's primitives). */
typedef struct asp_dps_cut_view {
    double eye[3];
    double pixels_per_unit;   /* pixels covered by one world unit at distance 1: height / (2 tan(fovy / 2)) */
    double tolerance;         /* pixels; <= 0 refines to the finest level everywhere */
    double size_weight;       /* >= 0: the error measured is asp_prim.error + size_weight x the rectangle's half
                                 diagonal, so large flat primitives refine too (0 = the geometric error alone) */
} asp_dps_cut_view;

/** Opaque cut state: child lists, target and drawn weights, the fade. */
typedef struct asp_dps_cut asp_dps_cut;

/**
 * Prepares cuts of dps (borrowed: it must outlive the cut and keep its links). fade_seconds is how long
 * a change of the cut takes to blend in (0 = 0.25, negative = no fade). Returns 0, ASP_EINVAL (a level
 * without links: "no links between levels: rebuild with this version"), ASP_ENOMEM.
 */
int asp_dps_cut_create(const asp_dps *dps, double fade_seconds, const asp_context *ctx, asp_dps_cut **out,
                       asp_error *err);
void asp_dps_cut_destroy(asp_dps_cut *cut);

/**
 * Target cut for view (seed 001 section 5: per-node screen error): from the coarsest level down, a
 * primitive with weight d > 0 is refined when its error (asp_prim.error, world units) projected at its
 * nearest distance from the eye exceeds view->tolerance pixels: its weight passes to its children,
 * d_j += d * w(j -> k); else it is drawn with weight d. The finest level draws what reaches it. So
 * sum_f d_f Psi_f = sum of the coarsest Psi = 1 wherever the links are exact (docs/cut.md). Pure:
 * writes target weights (asp_dps_cut_target_count entries, by level then primitive, 0 = not drawn) to
 * out when not NULL and returns the number of drawn primitives.
 */
size_t asp_dps_cut_target(const asp_dps_cut *cut, const asp_dps_cut_view *view, float *out);

/** Total primitives over all levels (the length of a weight array). */
size_t asp_dps_cut_target_count(const asp_dps_cut *cut);

/**
 * Advances the drawn cut by dt seconds towards the target for view: when the target changes, the
 * weights drawn now become the start of a fade and the drawn weights are (1 - s) start + s target,
 * s rising linearly to 1 over the fade time, so the drawn weights keep the partition of unity during
 * the fade (both are partitions of unity). The first update (or dt < 0) jumps to the target.
 * Returns 0 or ASP_ENOMEM.
 */
int asp_dps_cut_update(asp_dps_cut *cut, const asp_dps_cut_view *view, double dt, asp_error *err);

/**
 * The drawn primitives after the last update, by level then primitive: *items stays valid until the
 * next update or destroy. Returns their count.
 */
size_t asp_dps_cut_items(const asp_dps_cut *cut, const asp_dps_cut_item **items);

/** 1 while a fade is in progress. */
int asp_dps_cut_fading(const asp_dps_cut *cut);

/* ---- kernels (usable and testable alone) ---- */

/**
 * 2D Delaunay triangulation of n points (xy packed, finite) by incremental
 * insertion along a Hilbert curve with Lawson flips, on coordinates snapped to
 * a 2^20 grid over their bounding box so that the orientation and in-circle
 * predicates are exact in integer arithmetic. Points that snap to the same
 * grid node count once (the first in index order). Writes triangles as vertex
 * index triples, counter-clockwise, to tri (capacity 3 * asp_delaunay2d_bound(n))
 * and returns their number (0 for fewer than 3 distinct or all colinear
 * points). Every triangle's circumcircle holds no other input point (exact on
 * the snapped coordinates); hull slivers flatter than about 1/256 of the
 * extent may be missing. scratch holds asp_delaunay2d_scratch_size(n) bytes.
 * Thread-safe; no allocation.
 */
size_t asp_delaunay2d(const double *xy, size_t n, uint32_t *tri, void *scratch);
/** Most triangles asp_delaunay2d can write for n points (2n). */
size_t asp_delaunay2d_bound(size_t n);
/** Scratch bytes asp_delaunay2d needs for n points. */
size_t asp_delaunay2d_scratch_size(size_t n);

/**
 * Domain neighbours (journal section 4): domains a and b (rows of dom, as
 * written by asp_amg_domains, column indices sorted) are neighbours when their
 * common points exceed fraction (in (0,1)) times the point count of a or of b.
 * Writes, per row a, its neighbours in increasing order: first[a] .. first[a+1]
 * in *list (first holds dom->rows + 1 entries; *list is allocated here through
 * ctx, free with asp_free; *total = first[rows]). Parallel, deterministic.
 * Returns 0, ASP_EINVAL, ASP_ENOMEM.
 */
int asp_prim_neighbours(const asp_amg_csr *dom, double fraction, const asp_context *ctx, size_t *first,
                        uint32_t **list, size_t *total, asp_error *err);

/* ---- the .dps file ---- */

/**
 * Writes dps to path atomically in the versioned, little-endian .dps format
 * (docs/cli/build.md, version 3): the source frame (dps->frame), parameters (every
 * field of asp_prim_desc), the levels' strict flags and links,
 * source name and per level the primitives,
 * neighbour lists and atlases, with a CRC-32 trailer. Returns 0, ASP_EIO,
 * ASP_ENOMEM.
 */
int asp_dps_save(const asp_dps *dps, const char *path, asp_error *err);

/**
 * Reads a .dps file into a new asp_dps (*out): reads the whole file and parses
 * it with asp_dps_load_memory. A version-1 file (no recorded frame) loads
 * with frame.radius 0 ("not known"); versions 1 and 2 load without links
 * (asp_dps_has_links 0) and with the build options they did not record at 0. Returns 0, ASP_EINVAL (path or out NULL),
 * ASP_EIO (cannot open/read), ASP_ENOMEM, or ASP_EFORMAT as
 * asp_dps_load_memory. On failure *out is unchanged. Thread-safe.
 */
int asp_dps_load(const char *path, const asp_context *ctx, asp_dps **out, asp_error *err);

/**
 * The file the .dps at dps_path was built from (dps->source, the input's name as
 * amgsplat build was given it): the name as stored, then, when it is relative,
 * the same name next to the .dps (a file moved with its source, or built from
 * another directory). Writes the first candidate that exists and is recognised
 * (asp_file_recognise) to out (capacity cap) and its type to *type (may be
 * NULL); the caller checks the kind it needs. The one resolution for every
 * reader of the source (the scene loader, render --debug triangulation).
 * Returns 0, ASP_EUNSUPPORTED (the .dps names no source), ASP_EINVAL (a
 * candidate longer than cap) or the first candidate's asp_file_recognise error
 * (ASP_EIO when missing); out and *type unchanged on failure. Thread safe.
 */
int asp_dps_source_find(const asp_dps *dps, const char *dps_path, char *out, size_t cap, asp_file_type *type,
                        asp_error *err);

/**
 * Parses the bytes of a .dps file (size bytes at data, borrowed for the call;
 * data may be NULL when size is 0) into a new asp_dps (*out, freed by the
 * caller with asp_dps_destroy). name is the file name used in messages (NULL =
 * "<memory>"). Returns 0, ASP_EINVAL (out NULL), ASP_ENOMEM, or ASP_EFORMAT
 * for anything damaged (wrong magic or version, truncated or trailing bytes,
 * checksum mismatch, a count the bytes left cannot hold, levels not increasing
 * or not below amg_levels, an unknown method/shape/normalisation code, a
 * texture rectangle outside its atlas, a neighbour index out of range, a
 * neighbour list not increasing or naming its own primitive, a basis index
 * not below basis_count, a non-finite value), with a message naming the file,
 * the byte offset, the level and primitive, the field and what was expected.
 * Every count is checked against the bytes left before any allocation, so a
 * forged count costs no more memory than about twice size. On failure *out is
 * unchanged and nothing stays allocated. Thread-safe (no shared state).
 */
int asp_dps_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_dps **out,
                        asp_error *err);

/** One row of the thesis Table 5.2 for a level (what `amgsplat info X.dps` prints). */
typedef struct asp_dps_summary {
    uint32_t level;           /* AMG level index */
    char name[16];            /* "L", "L-3" */
    size_t primitives;
    uint64_t texels;
    double error, error_norm;
    double t_basis, t_construct;
    uint32_t skipped, degenerate, capped, merges;
    uint32_t atlas_width, atlas_height;
    size_t neighbour_pairs;   /* neighbour_total / 2 */
    int normal_map;
    int compressed;           /* 1: the atlases are BC3 blocks (asp_dps_level_compress) */
} asp_dps_summary;

/**
 * Fills rows[0 .. min(level_count, capacity) - 1] and returns dps->level_count
 * (so a caller can see that rows were left out); prints nothing. Thread-safe.
 */
size_t asp_dps_summarize(const asp_dps *dps, asp_dps_summary *rows, size_t capacity);

/**
 * GPU bytes of a level drawn as textured quads, counted as asp_mesh_gpu_bytes
 * counts a mesh (mesh.h) so the two compare: per primitive 4 vertices x (12
 * position + 12 normal + 8 uv) and 6 indices x 4; the colour atlas as the
 * renderer allocates it (one level, no mipmaps): width * height * 4 bytes
 * (RGBA8), or width * height (BC3 blocks, asp_dps_level_compress), and the
 * normal atlas the same way when the level has one (issue 27: what is really
 * in GPU memory). The renderer's own buffers (storage
 * buffers of primitives and neighbours) are not counted: they replace the
 * vertex buffers, not add to them. out may be NULL; returns the total. Pure.
 */
size_t asp_dps_level_gpu_bytes(const asp_dps_level *level, asp_mesh_bytes *out);

/** Writes the name of dps->levels[index] ("L", "L-3") to name. Thread-safe. */
void asp_dps_level_name(const asp_dps *dps, size_t index, char name[16]);

/**
 * The index into dps->levels of the level text names: its name ("L", "L-3",
 * as asp_dps_summarize names them) or its AMG level index ("4"). Returns 0, or
 * ASP_EINVAL "no level 'X' (the file holds L, L-3)" (callers prefix the file
 * name). *index is unchanged on failure. Thread-safe.
 */
int asp_dps_level_parse(const asp_dps *dps, const char *text, size_t *index, asp_error *err);

/**
 * The index into dps->levels of the level of the other domain set (thesis
 * appendix C "Domain Set"): the level with lv->strict == strict built from the
 * same AMG level as dps->levels[from], else the finest level of that set.
 * Returns 0, or ASP_EINVAL when from is out of range or the file holds no level
 * of that set ("no strict levels in the file; build with --domains strict or
 * both"). *index is unchanged on failure. Thread-safe.
 */
int asp_dps_domain_set_pick(const asp_dps *dps, size_t from, int strict, size_t *index, asp_error *err);

/**
 * Copies primitive prim of src into *out as a level of one primitive (the
 * thesis viewer's "one picked domain only", appendix C): same geometry, the
 * primitive's texture cropped to an atlas of its own (and its normal map when
 * src has one), no neighbours; the level's figures (level, strict, error) are
 * src's. Release with asp_dps_level_release (ctx as given here). Returns 0,
 * ASP_EINVAL ("no domain N: level L has domains 0..M"), ASP_EFORMAT (texture
 * outside the atlas), ASP_ENOMEM; *out is unchanged on failure. Thread-safe.
 */
int asp_dps_level_pick(const asp_dps_level *src, size_t prim, const asp_context *ctx, asp_dps_level *out,
                       asp_error *err);

/**
 * Compresses lv's atlas (and normal atlas) to BC3 blocks through libsquish (atlas_bc3, normal_bc3) and
 * replaces the texels by the decoded blocks, what the GPU then samples. The atlas height is first
 * padded to a multiple of 4 (rows of zero texels; the width is a power of two >= 64). A level that is
 * already compressed is left as it is. GPU bytes (asp_dps_level_gpu_bytes) become 1 per texel and
 * atlas. Returns 0, ASP_EINVAL (no atlas), ASP_ENOMEM; lv is unchanged on failure. Thread-safe on
 * distinct levels.
 */
int asp_dps_level_compress(asp_dps_level *lv, const asp_context *ctx, asp_error *err);

/**
 * Resamples every primitive's texture of lv to tex_w[i] x tex_h[i] texels (each 1..16384; box filter
 * when shrinking, colour averaged in linear light; bilinear-like when growing), alpha and the normal
 * atlas alike, and packs them into a new atlas with pad texels of clamp-to-edge padding, as the
 * build does; geometry is kept (texel becomes the mean of the two edge lengths). Used by the texel
 * budget of asp_fit (issue 27). Returns 0, ASP_EINVAL, ASP_EUNSUPPORTED (atlas over 16384 a side),
 * ASP_ENOMEM; lv is unchanged on failure. Thread-safe on distinct levels.
 */
int asp_dps_level_resize(asp_dps_level *lv, const uint32_t *tex_w, const uint32_t *tex_h, uint32_t pad,
                         const asp_context *ctx, asp_error *err);

/**
 * The kept Delaunay triangles of the affine method (thesis 3.3.3, Fig. 3.8)
 * of every primitive of dps->levels[index], for the thesis viewer's
 * triangulation drawing (appendix C). The triangles are not stored in a
 * .dps, so the level's domains are made again from amg (the decomposition the
 * file was built from, asp_dps.source) and each domain's points projected to
 * its primitive's plane. Writes 6 floats per edge (two points, world minus
 * origin; origin NULL = 0) to *lines, allocated through ctx (free with
 * asp_free), and the edge count to *segments. Merged primitives are left out.
 * Returns 0, ASP_EINVAL (index out of range, amg of another point count or
 * without the level), ASP_ENOMEM; outputs unchanged on failure. Thread-safe.
 */
int asp_prim_level_triangles(const asp_amg *amg, const asp_dps *dps, size_t index, const double origin[3],
                             const asp_context *ctx, float **lines, size_t *segments, asp_error *err);

/** Option names: "affine"/"radial", "linear"/"constant"/"gaussian", "positive"/"ge1". 0 or ASP_EINVAL. */
int asp_prim_method_parse(const char *name, asp_prim_method *out, asp_error *err);
int asp_prim_shape_parse(const char *name, asp_prim_shape *out, asp_error *err);
int asp_prim_normalise_parse(const char *name, asp_prim_normalise *out, asp_error *err);
/** Names of the enums above ("affine"). */
const char *asp_prim_method_name(asp_prim_method m);
const char *asp_prim_shape_name(asp_prim_shape s);
const char *asp_prim_normalise_name(asp_prim_normalise n);

/* ---- GL-free maths of drawing a level: its bounds, and the hybrid's split (issue 26) ---- */
/*
 * These need no GL but the level's types, so they live here, below render (STYLE.md 9b): eval
 * frames a .dps without a recorded frame with the same code in the no-GL build, and the hybrid
 * renderer (render.h) and tools share one split. src/prim/level_bounds.c, src/prim/hybrid_select.c.
 */

/**
 * Bounding sphere of the support rectangles of level in the frame centred on
 * origin (NULL = world origin): centre of their corners' bounding box and the
 * largest corner distance from it. Returns 0, ASP_EDEGENERATE (no primitives,
 * or all corners at one point) or ASP_EFORMAT (non-finite values); outputs
 * are unchanged on failure. Thread safe; no GL.
 */
int asp_prim_level_bounding_sphere(const asp_dps_level *level, const double origin[3], float center[3],
                                   float *radius, asp_error *err);

/*
 * Defaults of asp_hybrid_split_desc (and so of the hybrid renderer,
 * asp_hybrid_desc in render.h), chosen by measurement (docs/hybrid.md): a
 * primitive is replaced by its domain's points when the Psi-weighted RMS
 * distance of those points to its plane exceeds ERROR_LIMIT times its radius
 * sqrt(half_u half_v), or when more than TURNED_LIMIT of its domain (Psi
 * weighted) has normals more than 45 degrees from its own; a point is drawn
 * when the kept primitives near it (facing its way, within 2 error + 2
 * spacings of it) have Psi summing below COVERAGE_MIN.
 */
#define ASP_HYBRID_ERROR_LIMIT 0.15f
#define ASP_HYBRID_TURNED_LIMIT 0.4f
#define ASP_HYBRID_COVERAGE_MIN 0.3f

/** asp_hybrid_split's point_cover value of a point drawn as a point. */
#define ASP_HYBRID_DRAWN UINT32_MAX

/** Thresholds of asp_hybrid_split; the zero value means the defaults above. */
typedef struct asp_hybrid_split_desc {
    float error_limit;  /* 0 = ASP_HYBRID_ERROR_LIMIT; else > 0 */
    float turned_limit; /* 0 = ASP_HYBRID_TURNED_LIMIT; else > 0 */
    float coverage_min; /* 0 = ASP_HYBRID_COVERAGE_MIN; else > 0 */
} asp_hybrid_split_desc;

/** What asp_hybrid_split decided. */
typedef struct asp_hybrid_counts {
    size_t prims_kept, prims_replaced;
    size_t points_drawn, points_total;
} asp_hybrid_counts;

/**
 * Decides per primitive of level whether it is kept or replaced by points,
 * and per point of points (the level's source points, in their local frame
 * centred on points->origin) whether a kept primitive stands for it. The
 * domain of primitive i is the points projecting onto texels of its texture
 * with alpha (= Psi_i) > tau = 0.05 (journal eq. 8), within half the
 * primitive's radius of its plane and not facing away from it (normal dot >
 * -0.1, when points has normals). Writes prim_replaced[i] (1 = replaced;
 * level->prim_count entries), point_cover[j] (points->count entries): the
 * kept primitive of largest Psi standing for point j, or ASP_HYBRID_DRAWN;
 * prim_score[i] (optional, NULL = not wanted): max(relative error /
 * error_limit, turned share / turned_limit), replaced when > 1 (INFINITY
 * for a primitive with no domain point). Coverage holds by construction:
 * every point is either drawn or in the domain of the kept primitive
 * point_cover names. counts may be NULL. Returns 0; ASP_EINVAL (a negative or
 * non-finite threshold); ASP_EDEGENERATE (no primitives or points); ASP_EFORMAT (no
 * atlas, a texture rectangle outside it, an empty rectangle); ASP_ENOMEM.
 * Cost: primitives x points bounding-sphere tests; OpenMP threads of ctx.
 * Thread safe, no GL.
 */
int asp_hybrid_split(const asp_dps_level *level, const asp_cloud *points, const asp_hybrid_split_desc *desc,
                     const asp_context *ctx, uint8_t *restrict prim_replaced, uint32_t *restrict point_cover,
                     float *restrict prim_score, asp_hybrid_counts *counts, asp_error *err);

/**
 * Psi of primitive prim of level at point x (frame centred on origin, NULL =
 * world origin) with normal (NULL = any) as asp_hybrid_split reads it: the
 * alpha of the texel under x's projection when x is in the primitive's
 * domain, else 0. For tests and tools. Thread safe, no GL.
 */
float asp_hybrid_domain_weight(const asp_dps_level *level, size_t prim, const double origin[3], const float x[3],
                               const float normal[3]);

#ifdef __cplusplus
}
#endif
#endif
