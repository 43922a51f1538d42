/*
 * Private interfaces of the domain-primitive module (src/prim/): the support
 * plane of one domain (thesis 3.1-3.2), the texture rasterisers (3.3), the
 * atlas packer and the domain merger (3.4). Not public API.
 */
#ifndef ASP_PRIM_INTERNAL_H
#define ASP_PRIM_INTERNAL_H

#include "amgsplat/prim.h"

/* Support plane of one domain, relative to the cloud origin. */
typedef struct asp__plane {
    double c[3];          /* (weighted) centroid */
    double u[3], v[3], n[3]; /* in-plane axes and normal, right-handed */
    double smin, smax, tmin, tmax; /* extent of the projected points along u, v (no margin) */
    double error;         /* mean |(p - c) . n| */
    double curvature;     /* l_min / (l0 + l1 + l2) */
    int degenerate;       /* fewer than 3 points or colinear: normal from the point normals */
} asp__plane;

/*
 * Fits the plane of the n points pos[idx[k]] with weights w[k] (Psi; all 1
 * when unweighted). normals (may be NULL) orient the plane and replace PCA's
 * normal for degenerate domains. n >= 1. Thread-safe, no allocation.
 */
void asp__prim_plane(const float *pos, const float *normals, const asp_index *idx, const double *w, size_t n,
                     int unweighted, asp__plane *pl);

/* Weighted moments of a point set, additive under merging (thesis 3.4: the merged basis is the sum). */
typedef struct asp__moments {
    double w;        /* sum of weights */
    double s[3];     /* sum w p */
    double ss[6];    /* sum w p p^T: xx xy xz yy yz zz */
    double nrm[3];   /* sum w n */
} asp__moments;

void asp__moments_add_points(asp__moments *m, const float *pos, const float *normals, const asp_index *idx,
                             const double *w, size_t n);
/* l_min / sum l and the unit normal (oriented by the mean normal) of the moments. */
double asp__moments_curvature(const asp__moments *m, double normal[3]);

/* One domain's samples projected to its texture grid (texel units: texel i spans [i, i+1)). */
typedef struct asp__tex_input {
    size_t n;
    const float *x, *y;   /* positions in texel units */
    const float *r;       /* footprint radius in texel units (affine: r, radial: w r) */
    const float *attr;    /* n * channels: r, g, b (0..255), psi, [nx, ny, nz] */
    int channels;         /* 4 or 7 */
    uint32_t w, h;
    asp_prim_method method;
    asp_prim_shape shape;
    asp_prim_normalise normalise;
    int normalise_color; /* asp_prim_desc.normalise_color */
    int extend_color;
} asp__tex_input;

/* Scratch bytes asp__prim_texture needs for n points and w*h texels. */
size_t asp__prim_texture_scratch(size_t n, size_t texels, int channels);

/*
 * Rasterises one texture into rgba (and nrm when not NULL, for 7 channels),
 * rows of stride texels apart. Cost: points x footprint + triangles' bounding
 * boxes + texels, never points x texels. Thread-safe.
 */
void asp__prim_texture(const asp__tex_input *in, void *scratch, uint8_t *rgba, uint8_t *nrm, size_t stride);

/*
 * The texture's second half, after the fill (affine interpolation into acc with covered[t] = 1, radial
 * sums into acc and f): normalisation (eq. 3.3 / 3.4), extend colour (3.3.4, seed holds w*h int32) and
 * the RGBA8 encoding. acc and f are changed. The GPU build fills acc, f, covered on the device (thesis
 * 3.6) and finishes here, so both builds share this code.
 */
void asp__prim_texture_finish(const asp__tex_input *in, float *acc, float *f, const uint8_t *covered, int32_t *seed,
                              uint8_t *rgba, uint8_t *nrm, size_t stride);

/* Radial pass: adds phi-weighted attributes to acc (texels x channels) and phi to f, skipping texels with
 * skip[t] != 0 when skip is not NULL (thesis 3.3.2; 3.3.3 outside the triangulation). nearest: evaluate
 * phi at the texel's point nearest the sample, so the texel holding a point gets its full weight. */
void asp__prim_splat_radial(const asp__tex_input *in, asp_prim_shape shape, const uint8_t *skip, int nearest,
                            float *acc, float *f);
/* Affine pass: barycentric interpolation inside the kept Delaunay triangles; sets covered[t] = 1.
 * Returns 0, or -1 when there were too few distinct points for a triangle. */
void asp__prim_affine(const asp__tex_input *in, void *scratch, float *acc, uint8_t *covered);
/* The kept Delaunay triangles of the affine pass (edges no longer than their vertices' radii summed,
 * thesis Fig. 3.8), as sample index triples in *tri (inside scratch); returns their number. scratch as for
 * asp__prim_affine (the xy doubles stay at its start). */
size_t asp__prim_affine_triangles(const asp__tex_input *in, void *scratch, uint32_t **tri);
/* Extend colour (thesis 3.3.4): texels with f == 0 get the colour of the (approximately) nearest point. */
void asp__prim_extend_color(const asp__tex_input *in, const float *f, int32_t *seed, float *acc);

/* Shelf packing of n rectangles (w[i] x h[i]) with pad texels around each into an atlas of at most
 * max_side; writes x, y and the atlas size. Returns 0 or -1 when it does not fit. Deterministic. */
int asp__atlas_pack(const uint32_t *w, const uint32_t *h, size_t n, uint32_t pad, uint32_t max_side, uint32_t *x,
                    uint32_t *y, uint32_t *atlas_w, uint32_t *atlas_h, const asp_context *ctx);
/* Copies the border texels of each rectangle into its padding (clamp to edge against bleeding). */
void asp__atlas_pad(asp_image *img, const asp_prim *prims, size_t n, uint32_t pad);

/*
 * Greedy domain merging (thesis 3.4) on the thresholded domains dom (rows =
 * domains): writes a new CSR *out (rows = merged domains) and for each output
 * row the first basis index (first[r]) and merged count (count[r]), arrays
 * allocated through ctx. Returns 0, ASP_ENOMEM.
 */
int asp__prim_merge(const asp_amg_csr *dom, const float *pos, const float *normals, double flatness,
                    double angle_deg, const asp_context *ctx, asp_amg_csr **out, uint32_t **first, uint32_t **count,
                    uint32_t *merges, asp_error *err);

/* Frees a level's links (level_links.c) and sets them absent. */
void asp__level_links_release(const asp_context *ctx, asp_dps_level *lv);

#endif
