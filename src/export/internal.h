/*
 * The glTF 2.0 document builder shared by the primitive and point exports: a cJSON tree, one
 * binary buffer of 4-byte aligned buffer views, PNG images embedded (GLB) or kept for files
 * beside the .gltf, and the atomic writer of both layouts (glTF 2.0 spec 4.4 GLB, 3.6 buffers).
 */
#ifndef ASP_EXPORT_INTERNAL_H
#define ASP_EXPORT_INTERNAL_H

#include <cjson/cJSON.h>

#include "amgsplat/export.h"

/* glTF enums (spec 5.1.2 componentType, 5.11.1 bufferView.target, 5.24 sampler filters) */
enum {
    ASP__GL_BYTE = 5120,
    ASP__GL_UNSIGNED_BYTE = 5121,
    ASP__GL_SHORT = 5122,
    ASP__GL_UNSIGNED_SHORT = 5123,
    ASP__GL_UNSIGNED_INT = 5125,
    ASP__GL_FLOAT = 5126,
    ASP__GL_ARRAY_BUFFER = 34962,
    ASP__GL_ELEMENT_ARRAY_BUFFER = 34963,
    ASP__GL_LINEAR = 9729,
    ASP__GL_CLAMP_TO_EDGE = 33071
};

typedef struct asp__gltf_png {
    unsigned char *data; /* the encoded PNG, through ctx's allocator */
    size_t size;
    char uri[256];       /* file name beside the .gltf */
} asp__gltf_png;

typedef struct asp__gltf {
    cJSON *root;
    cJSON *buffer_views, *accessors, *images, *textures, *samplers, *materials, *meshes, *nodes, *extensions_used;
    cJSON *extensions_required;
    size_t fallback_size; /* bytes of buffer 1, EXT_meshopt_compression's fallback (no data): 0 = none */
    uint8_t *bin;
    size_t bin_size, bin_capacity;
    asp__gltf_png *pngs;
    size_t png_count;
    int glb;             /* 1: one .glb, images in the binary chunk; 0: .gltf + .bin + .png files */
    char stem[96];       /* base name of the outputs (no directory, no extension) */
    const asp_context *ctx;
    int failed;          /* an allocation failed: the document is incomplete */
} asp__gltf;

/* Starts a document for path (.glb or .gltf). Returns 0, ASP_EINVAL (other extension), ASP_ENOMEM. */
int asp__gltf_init(asp__gltf *g, const char *path, const char *generator_note, const asp_context *ctx,
                   asp_error *err);
void asp__gltf_release(asp__gltf *g);

/* Appends size bytes as a buffer view (target 0 = none); returns its index or -1 (out of memory). */
int asp__gltf_view(asp__gltf *g, const void *data, size_t size, int target);
/*
 * Appends count elements of stride bytes (stride % 4 == 0, <= 256) as a vertex buffer view
 * compressed with meshoptimizer's vertex codec (EXT_meshopt_compression, mode ATTRIBUTES;
 * filter "NONE", "OCTAHEDRAL", "QUATERNION" or "EXPONENTIAL" names the meshopt_encodeFilter*
 * already applied to data). The view itself lies in the fallback buffer 1 (no data, the
 * extension's "fallback": true), the compressed bytes in buffer 0; the extension is required.
 * Returns the view's index or -1 (out of memory, or a codec version the extension does not know).
 */
int asp__gltf_view_meshopt(asp__gltf *g, const void *data, size_t count, size_t stride, const char *filter);
/* An accessor over a whole view; min/max (ncomp values each) may be NULL. Returns its index or -1. */
int asp__gltf_accessor(asp__gltf *g, int view, int component_type, size_t count, const char *type, int normalized,
                       const float *min, const float *max);
/* Encodes RGBA8 pixels as PNG and adds it as an image; returns its index or -1. */
int asp__gltf_image(asp__gltf *g, const uint8_t *rgba, uint32_t width, uint32_t height, const char *name);
/* A texture of image with the one linear, clamped, unmipmapped sampler; returns its index or -1. */
int asp__gltf_texture(asp__gltf *g, int image);
/* Adds name to extensionsUsed once. */
void asp__gltf_use_extension(asp__gltf *g, const char *name);
/* Adds name to extensionsUsed and extensionsRequired once (a viewer without it cannot show the file). */
void asp__gltf_require_extension(asp__gltf *g, const char *name);
/* Adds obj to the array (ownership moves); returns its index or -1. */
int asp__gltf_append(asp__gltf *g, cJSON *array, cJSON *obj);
/* A cJSON array of n floats (doubles kept exact). */
cJSON *asp__gltf_numbers(const double *v, int n);

/* Writes the document and its files atomically; fills stats' byte and file counts. */
int asp__gltf_write(asp__gltf *g, const char *path, asp_gltf_stats *stats, asp_error *err);

/*
 * glTF is y-up (spec 3.4: "+Y is up"): out = in turned by the proper rotation that takes the
 * source's up axis to +y (identity for ASP_UP_Y); in and out may alias. The inverse of the turn
 * asp_camera gives its y-up orbit (camera.c orbit_axes), so a glTF viewer's front view (from +z)
 * is amgsplat render's azimuth 0. A signed permutation: exact in float and double.
 */
void asp__gltf_turn_up(asp_up_axis up, const double in[3], double out[3]);
/* The same on a float vector in place. */
void asp__gltf_turn_up_f(asp_up_axis up, float v[3]);

/*
 * The scene extras both exports write for viewers that frame like amgsplat: kind, source, origin
 * (glTF coordinates: already turned), the frame (the source's coordinates, turned here by
 * frame->up), and the source's up axis with the matrix back to its coordinates.
 */
cJSON *asp__gltf_extras(const char *kind, const char *source, const double origin[3], const asp_frame *frame);

/*
 * The points export (asp_gltf_export_hier) of n splats of hier: ids are indices into
 * asp_hier_splats (node and point splats, e.g. a tile's cut, tiles.c), or NULL for every point in
 * input order (n = the point count). Positions are relative to origin, which the node translation
 * adds back (tiles pass 0: their tileset.json transform holds the world offset); origin and the
 * splats are turned from the source's up axis to glTF's +y. crs: the source's CRS (asp__gltf_crs)
 * for asset.extras, or NULL; taken over. Errors as
 * asp_gltf_export_hier.
 */
int asp__gltf_points_write(const asp_hier *hier, const asp_index *ids, size_t n, const double origin[3], cJSON *crs,
                           const char *path, const asp_gltf_desc *desc, asp_gltf_stats *stats, asp_error *err);

/*
 * The coordinate reference system a LAS file names (ASPRS LAS 1.4 2.5: the LASF_Projection VLRs,
 * OGC WKT record 2112, GeoTIFF GeoKeyDirectory 34735 with its 34736 doubles and 34737 ASCII
 * params) as a JSON object {"wkt": ..., "epsg": ..., "geoKeys": [...], ...}, or NULL when it
 * names none (or las is NULL).
 */
cJSON *asp__gltf_crs(const asp_las_meta *las);

/*
 * One level of dps as a tile's GLB (tiles_dps.c): as asp_gltf_export_dps writes it, positions
 * relative to the frame centre but no node translation (the tileset's root transform adds it);
 * stats->origin is that centre turned to glTF's +y. Errors as asp_gltf_export_dps.
 */
int asp__gltf_prims_tile(const asp_dps *dps, size_t level, const char *path, const asp_gltf_desc *desc,
                         asp_gltf_stats *stats, asp_error *err);

/*
 * Positions pos (n xyz in lo..hi) as a compact POSITION accessor (an EXT_meshopt_compression view;
 * the caller requires KHR_mesh_quantization): unsigned short VEC3 (stride 8) written in remap order,
 * q = round((p - lo) / side x 65535), side = the box's longest side (one step on every axis, so
 * one uniform node scale undoes it). normalized: stored normalized, the node's scale is side; else
 * plain integers, the node's scale is side / 65535. translation = lo. buf: 8 n bytes. Returns the
 * accessor (< 0 on failure).
 */
int asp__gltf_compact_positions(asp__gltf *g, const float *pos, size_t n, const float lo[3], const float hi[3],
                                const unsigned *remap, int normalized, uint8_t *buf, double translation[3],
                                double *scale);

/* An sRGB byte in linear light, 0..1 (glTF's COLOR_0 is linear; gltf_points.c). */
float asp__gltf_srgb_to_linear(uint8_t c);

/* ---- tilesets (tiles.c, shared by tiles_ooc.c and tiles_dps.c) ---- */

/* Creates dir and dir/tiles. Returns 0, ASP_EINVAL (name too long), ASP_EIO. */
int asp__tiles_dirs(const char *dir, asp_error *err);
/*
 * A box (lo xyz, hi xyz) in the GLBs' y-up frame as a 3D Tiles z-up boundingVolume.box: centre and
 * three half-axes, turned as 3D Tiles turns glTF content ((x, y, z) -> (x, -z, y)).
 */
cJSON *asp__tiles_box(const double box[6]);
/*
 * Writes dir/tileset.json atomically around root_tile (taken over): refine on the root, the root
 * transform to origin (y-up, as the GLBs' frame: turned to z-up here), the tileset's
 * geometricError from box (y-up), the glTF extensions tiles written with gltf_flags need
 * (asp__gltf_tileset_extensions), extras.amgsplat with frame and st's counts. Adds the JSON's
 * bytes to st and fills st->json_bytes, root_error and origin.
 */
int asp__tiles_write_tileset(const char *dir, cJSON *root_tile, const char *refine, const double box[6],
                             const double origin[3], const asp_frame *frame, unsigned gltf_flags,
                             asp_tiles_stats *st, asp_error *err);

/* n Gaussians for asp__spz_encode, in the glTF node's local frame (gltf_spz.c) */
typedef struct asp__spz_splats {
    const float *positions;  /* xyz */
    const float *rotations;  /* unit quaternions x, y, z, w */
    const float *log_scales; /* ln sigma, 3 a splat */
    const float *opacities;  /* in [0, 1] */
    const float *sh0;        /* SH DC, 3 a splat (colour = 0.5 + 0.2820948 sh0) */
    int fractional_bits;     /* of the 24-bit fixed-point positions, 0..23 (|x| < 2^(23 - bits)) */
} asp__spz_splats;
/*
 * The gzipped SPZ version 2 stream of n splats (KHR_gaussian_splatting_compression_spz_2) in
 * *dst (asp_alloc'd, asp_free) of *dst_size bytes. Errors: ASP_EINVAL (n = 0 or too many), ASP_ENOMEM.
 */
int asp__spz_encode(const asp__spz_splats *s, size_t n, uint8_t **dst, size_t *dst_size, asp_error *err);
/* What a tileset of tiles written with flags (asp_gltf_flags) adds to tileset.json's root: the
 * glTF extensions a client needs (3DTILES_content_gltf; CesiumJS draws Gaussian splats only where
 * it lists KHR_gaussian_splatting_compression_spz_2 as required). */
void asp__gltf_tileset_extensions(cJSON *tileset, unsigned flags);

#endif
