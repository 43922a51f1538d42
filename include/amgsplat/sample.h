/*
 * Mesh-to-point sampling (one point per vertex as QSplat; area-stratified
 * low-discrepancy samples; the voxel sampler of Schwarz 2004 section 3.1) and
 * the synthetic test models (the octahedron of Reniers & Telea 2006 Fig. 1,
 * the checker plane of Pajarola et al. 2003). Every result carries positions,
 * unit normals and radii chosen so that the discs close all holes.
 */
#ifndef AMGSPLAT_SAMPLE_H
#define AMGSPLAT_SAMPLE_H

#include "cloud.h"
#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- mesh sampling (src/geom/sample_*.c) ---- */

typedef enum asp_sample_method {
    ASP_SAMPLE_AREA = 0,     /* desc.points samples spread evenly over the area (default) */
    ASP_SAMPLE_VERTICES = 1, /* one point per mesh vertex */
    ASP_SAMPLE_VOXEL = 2     /* one point per occupied cell of an n^3 grid (Schwarz 2004 3.1) */
} asp_sample_method;

/** Options for asp_sample_mesh; the zero value means defaults. */
typedef struct asp_sample_desc {
    asp_sample_method method;
    size_t points;      /* AREA: number of samples (0 = 100000; at most 2^32-1) */
    uint32_t grid;      /* VOXEL: cells per axis n (0 = 256; 1..2^20) */
    uint64_t seed;      /* AREA: seeds the per-triangle sequence offsets; equal seeds give equal clouds */
    float radius_scale; /* multiplies every radius (0 = 1) */
    int with_uvs;       /* 1: also store interpolated texture coordinates when the mesh has UVs */
    int with_labels;    /* 1: store in labels the triangle a point came from (VOXEL: the first one) */
} asp_sample_desc;

/** Figures about one sampling run, for summaries and benchmarks. */
typedef struct asp_sample_stats {
    size_t points;        /* points produced */
    double area;          /* mesh surface area */
    double mean_radius;   /* mean of the radii */
    double sample_seconds; /* placing points, normals and colours */
    double radii_seconds;  /* computing radii */
} asp_sample_stats;

/**
 * Samples mesh into a new cloud in *out (same origin as the mesh). Normals are
 * interpolated from the vertex normals. Colours come, per triangle, from its
 * material's texture through the interpolated UVs (bilinear, GL_REPEAT), else
 * from vertex colours, else from the material colour; the texture replaces the
 * diffuse colour rather than multiplying it. When the mesh has no colour
 * source at all (no texture, no vertex colours, only assimp's default
 * material) the cloud has no colours (renderers show those light grey).
 * Radii: VERTICES, the triangle covering radius (see sample_vertices.c);
 * AREA, from the sample density (see sample_area.c); VOXEL, half the cell
 * diagonal. Runs in parallel; the result is bit-identical for any thread
 * count. stats may be NULL.
 * Errors: ASP_EINVAL (bad desc values), ASP_EDEGENERATE / ASP_EFORMAT (from
 * asp_mesh_validate), ASP_ENOMEM, ASP_ECANCELED. On failure *out is unchanged.
 */
int asp_sample_mesh(const asp_mesh *mesh, const asp_sample_desc *desc, const asp_context *ctx, asp_cloud **out,
                    asp_sample_stats *stats, asp_error *err);

/** "area", "vertices", "voxel" -> method; returns 0 or ASP_EINVAL for other names. */
int asp_sample_method_parse(const char *name, asp_sample_method *out, asp_error *err);
/** Name of a method ("area"). */
const char *asp_sample_method_name(asp_sample_method method);

/* ---- synthetic models (src/geom/synth.c) ---- */

typedef enum asp_synth_shape {
    ASP_SYNTH_OCTAHEDRON = 0, /* |x|+|y|+|z| = 1; 8 faces, labels 0..7, default 16000 points */
    ASP_SYNTH_CUBE = 1,       /* [-1,1]^3 surface; 6 faces, labels 0..5, default 24000 points */
    ASP_SYNTH_SPHERE = 2,     /* unit sphere, colour by normal, default 20000 points */
    ASP_SYNTH_TORUS = 3,      /* major radius 1, minor 0.35, colour by angles, default 30000 points */
    ASP_SYNTH_CHECKER_PLANE = 4 /* grid x grid points on z = 0 in [-1,1]^2, normals +z, two colours */
} asp_synth_shape;

/** Options for asp_synth; the zero value means defaults. */
typedef struct asp_synth_desc {
    size_t points;    /* number of points (0 = the shape's default); ignored by CHECKER_PLANE */
    uint64_t seed;    /* sequence offsets; equal seeds give equal clouds */
    uint32_t grid;    /* CHECKER_PLANE: points per side (0 = 512) */
    uint32_t squares; /* CHECKER_PLANE: checker squares per side (0 = 8) */
} asp_synth_desc;

/**
 * Makes a synthetic point model in *out with positions, exact unit normals,
 * RGBA colours and radii that close all holes; the octahedron and the cube also
 * fill labels with the face id (octahedron: bit 0 set for x < 0, bit 1 for
 * y < 0, bit 2 for z < 0; cube: 0..5 = +x,-x,+y,-y,+z,-z), the checker plane
 * with the square colour (0 or 1). Points are spread evenly (equal counts per
 * face, low-discrepancy within a face). Deterministic for a given desc and any
 * thread count. desc may be NULL.
 * Errors: ASP_EINVAL (unknown shape, fewer points than faces, grid < 2 or
 * grid^2 >= 2^32), ASP_ENOMEM. On failure *out is unchanged.
 */
int asp_synth(asp_synth_shape shape, const asp_synth_desc *desc, const asp_context *ctx, asp_cloud **out,
              asp_error *err);

/** "octahedron", "cube", "sphere", "torus", "checker-plane" -> shape; 0 or ASP_EINVAL. */
int asp_synth_shape_parse(const char *name, asp_synth_shape *out, asp_error *err);
/** Name of a shape ("checker-plane"). */
const char *asp_synth_shape_name(asp_synth_shape shape);

/**
 * Streams a synthetic terrain of points points to path (binary little-endian
 * PLY: float x, y, z, uchar rgb; asp_point_writer) without holding it: a
 * 1000 m x 1000 m fractal heightfield (value noise, 2048^2 samples plus a
 * tiled 256^2 detail texture at 16x frequency), points uniformly random
 * within square tiles written tile by tile, coloured by height and slope.
 * Working set about 150 MB whatever points is. Deterministic per seed, for
 * any thread count (asp_context_threads tiles generated at once).
 * Errors: ASP_EINVAL (points == 0), ASP_EIO, ASP_ENOMEM, ASP_ECANCELED
 * (progress stage "synth").
 */
int asp_synth_terrain_stream(const char *path, uint64_t points, uint64_t seed, const asp_context *ctx,
                             asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
