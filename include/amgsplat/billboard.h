/*
 * Billboard clouds (Decoret, Durand, Sillion and Dorsey 2003, "Billboard
 * clouds for extreme model simplification"; thesis 000 section 6.2 and Table
 * 6.1, the method domain primitives are compared with): a model is replaced by
 * a few textured planes chosen top-down and greedily so that every face (or
 * point) lies within an error bound of the plane it is drawn on. Each plane's
 * texture is the orthographic projection of what it covers with a binary alpha
 * mask. The planes are written as a level of a .dps (asp_dps_level.billboards
 * = 1) that every renderer draws alpha-tested and opaque.
 */
#ifndef AMGSPLAT_BILLBOARD_H
#define AMGSPLAT_BILLBOARD_H

#include "cloud.h"
#include "mesh.h"
#include "prim.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Options; the zero value means defaults except error, which is required, so
 * `&(asp_billboard_desc){ .error = 0.04 }` works.
 */
typedef struct asp_billboard_desc {
    double error;         /* error bound eps as a fraction of the bounding-box diagonal (Decoret 2003 section
                             6 quotes bounds so), in (0, 1]; every element ends within eps of its plane */
    double texel_size;    /* texel edge as a fraction of the bounding-box diagonal; 0 = 1/512 unless texels is set */
    uint64_t texels;      /* > 0: the texel edge is chosen so that the planes' textures hold about this many
                             texels (for comparisons at one texel count); then texel_size must be 0 */
    size_t max_planes;    /* stop after this many planes (elements left over are not drawn); 0 = no limit */
    int normal_map;       /* 1: also a normal atlas (the interpolated vertex or point normals) */
    uint32_t theta_bins;  /* plane-space bins of the polar angle over the half sphere; 0 = 24 */
    uint32_t phi_bins;    /* bins of the azimuth; 0 = 4 theta_bins */
} asp_billboard_desc;

/** One plane of a billboard cloud: n . p = offset for p in the input's local positions (before origin). */
typedef struct asp_billboard_plane {
    double normal[3];     /* unit; faces the area-weighted mean normal of what it covers */
    double offset;
    size_t elements;      /* faces or points assigned to it */
    double area;          /* their area */
    int fallback;         /* 1: taken from one element's own plane (no bin of the plane space held it) */
} asp_billboard_plane;

/** What a search or build did. */
typedef struct asp_billboard_stats {
    size_t elements;      /* faces (or points) of the input; degenerate faces (zero area) included */
    size_t planes;
    size_t uncovered;     /* elements on no plane (max_planes reached) */
    size_t fallbacks;     /* planes taken from an element's own plane */
    double eps;           /* the error bound in world units */
    double diagonal;      /* the bounding-box diagonal, world units */
    double max_distance;  /* largest distance of an assigned element's vertex (disc edge) to its plane, world */
    double texel;         /* texel edge used, world units */
    uint64_t texels;      /* texels of the textures (tex_w * tex_h summed) */
    double t_search;      /* seconds: plane space, density and greedy search */
    double t_texture;     /* seconds: textures and atlas */
} asp_billboard_stats;

/**
 * The greedy plane search alone (Decoret 2003 section 4) over the triangles of
 * mesh: the plane space (theta, phi over the half sphere, offset) is cut into
 * bins; every face adds its projected area to the bins of the planes for which
 * it is valid (all three vertices within eps); the densest bin is refined (its
 * angles subdivided, the best offset found by a sweep) and the plane found
 * takes every face valid for it; their contributions are removed and the
 * search repeats until all faces are taken or max_planes planes exist. A face
 * valid for no bin gets a plane of its own (stats->fallbacks). Writes *planes
 * (allocated through ctx, free with asp_free) and *plane_count, and assign[f]
 * (mesh->triangle_count entries, caller's): the plane of face f, or UINT32_MAX
 * when max_planes left it uncovered. Deterministic for any thread count.
 * stats may be NULL. Returns 0, ASP_EINVAL (bad option), ASP_EDEGENERATE (no
 * triangles, or a bounding box of zero size), ASP_ENOMEM; outputs unchanged
 * on failure. Thread-safe.
 */
int asp_billboard_search_mesh(const asp_mesh *mesh, const asp_billboard_desc *desc, const asp_context *ctx,
                              asp_billboard_plane **planes, size_t *plane_count, uint32_t *assign,
                              asp_billboard_stats *stats, asp_error *err);

/**
 * The same over the points of cloud taken as discs (radius from cloud->radii,
 * else the cloud's default radius; oriented by cloud->normals when present,
 * else points): a disc is valid for a plane when its rim is within eps.
 */
int asp_billboard_search_cloud(const asp_cloud *cloud, const asp_billboard_desc *desc, const asp_context *ctx,
                               asp_billboard_plane **planes, size_t *plane_count, uint32_t *assign,
                               asp_billboard_stats *stats, asp_error *err);

/**
 * A billboard cloud of mesh as a new one-level asp_dps (*out, free with
 * asp_dps_destroy; level 0, billboards = 1, no neighbours): the search above,
 * then per plane the tight rectangle of what it covers (oriented by the 2D
 * principal axes) and its texture at the texel size: each covered face
 * rasterised conservatively onto the plane (colour from the mesh's texture,
 * vertex colours or material, else grey 200; alpha 255 where covered, else 0;
 * the face farthest along the plane normal wins a texel), texels outside
 * given the colour of covered ones nearby so filtering does not bleed black.
 * dps->mean_radius is the texel edge and desc.texel_size 1; level error is the
 * mean distance of the vertices to their planes. source names the input (NULL
 * = ""). Errors as asp_billboard_search_mesh, and ASP_EUNSUPPORTED when the
 * atlas exceeds 16384 texels a side even with the texel doubled twice.
 */
int asp_billboard_mesh(const asp_mesh *mesh, const asp_billboard_desc *desc, const char *source,
                       const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, asp_error *err);

/** The same for the discs of cloud (colour from cloud->colors, else grey 200). */
int asp_billboard_cloud(const asp_cloud *cloud, const asp_billboard_desc *desc, const char *source,
                        const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
