/*
 * asp_cloud: a point set in structure-of-arrays form (STYLE.md section 6).
 * Positions are float offsets from a double-precision origin so that scans in
 * large coordinates (UTM, ECEF) keep sub-millimetre precision. Any vertex
 * property the input carries beyond the standard ones is kept by name and
 * type, so a PLY read-write round trip loses nothing.
 */
#ifndef AMGSPLAT_CLOUD_H
#define AMGSPLAT_CLOUD_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef uint32_t asp_index; /* point index; a cloud holds at most 2^32-1 points */

/** Scalar types of PLY and of extra properties. */
typedef enum asp_scalar_type {
    ASP_SCALAR_NONE = 0,
    ASP_SCALAR_INT8, ASP_SCALAR_UINT8, ASP_SCALAR_INT16, ASP_SCALAR_UINT16,
    ASP_SCALAR_INT32, ASP_SCALAR_UINT32, ASP_SCALAR_FLOAT32, ASP_SCALAR_FLOAT64
} asp_scalar_type;

/** Size in bytes of one value of type t (0 for NONE). */
size_t asp_scalar_size(asp_scalar_type t);
/** PLY name of t ("uchar", "float", ...). */
const char *asp_scalar_name(asp_scalar_type t);

/** An extra per-point scalar property: count values of type, densely packed. */
typedef struct asp_property {
    char name[64];
    asp_scalar_type type;
    void *data; /* count * asp_scalar_size(type) bytes, owned by the cloud */
} asp_property;

/** A LAS variable-length record (VLR or, in LAS 1.4, extended EVLR) kept as bytes: GeoTIFF keys, WKT, ... */
typedef struct asp_las_vlr {
    char user_id[17];     /* NUL-terminated */
    uint16_t record_id;
    char description[33]; /* NUL-terminated */
    int extended;         /* 1: an EVLR (after the points, 64-bit length) */
    size_t size;
    uint8_t *data;        /* size bytes, owned by the cloud */
} asp_las_vlr;

/**
 * What a LAS file says beyond its points, kept so that LAS in, LAS out
 * reproduces it (asp_las_read fills it, asp_las_write reuses it). The Extra
 * Bytes VLR is not among vlrs: the writer makes it from the properties.
 */
typedef struct asp_las_meta {
    uint8_t version_minor;   /* 1.version_minor: 0 to 4 */
    uint8_t point_format;    /* point data record format, 0 to 10 */
    uint16_t record_length;  /* bytes per point record in the file */
    uint16_t file_source_id, global_encoding;
    uint8_t guid[16];
    char system_id[33], software[33]; /* NUL-terminated */
    uint16_t creation_day, creation_year;
    double scale[3], offset[3];       /* world = offset + scale * integer coordinate */
    double min[3], max[3];            /* bounds as the header states them */
    uint64_t point_count;             /* as the header states it */
    uint64_t points_by_return[15];
    size_t vlr_count;
    asp_las_vlr *vlrs;
} asp_las_meta;

/**
 * Which world axis points up: for the orbit camera (asp_camera.up) and for the
 * mesh loader (asp_mesh.up, the axis of the file taken as up). The zero value
 * is +y (OpenGL, OBJ, glTF, PLY from most meshes).
 */
typedef enum asp_up_axis {
    ASP_UP_Y = 0, /* azimuth 0 looks from +z */
    ASP_UP_Z = 1, /* scanners, CAD, 3DS: azimuth 0 looks from -y (the "front" view of z-up tools) */
    ASP_UP_X = 2, /* azimuth 0 looks from +z */
    ASP_UP_NEG_Y = 3, /* the negative axes: the positive one's frame turned 180 degrees about its view axis */
    ASP_UP_NEG_Z = 4,
    ASP_UP_NEG_X = 5
} asp_up_axis;

/** Which optional attributes a cloud holds (bit set). */
enum asp_cloud_attr {
    ASP_ATTR_NORMALS = 1 << 0,
    ASP_ATTR_COLORS = 1 << 1,
    ASP_ATTR_RADII = 1 << 2,
    ASP_ATTR_UVS = 1 << 3,
    ASP_ATTR_LABELS = 1 << 4
};

/**
 * The point set. Fields are public for reading and writing the arrays in place;
 * allocate and resize only through the asp_cloud_* functions. Absent attributes
 * are NULL. All arrays are 64-byte aligned.
 */
typedef struct asp_cloud {
    size_t count;
    double origin[3];   /* world position = origin + positions[i] */
    float *positions;   /* 3 * count, xyz packed */
    float *normals;     /* 3 * count, unit length, or NULL */
    uint8_t *colors;    /* 4 * count, RGBA 8-bit sRGB (A = 255 if the input had none), or NULL */
    float *radii;       /* count, splat radius in world units, or NULL */
    float *uvs;         /* 2 * count texture coordinates, or NULL */
    uint32_t *labels;   /* count, e.g. face or part id, or NULL */

    size_t property_count;
    asp_property *properties; /* extra per-point scalars, in file order */

    /* Triangles when the source had faces (PLY face lists, fan-triangulated): 3 * face_count indices. */
    size_t face_count;
    uint32_t *faces;

    /* Source metadata kept for round trips: PLY comments and obj_info lines (NUL-terminated strings). */
    size_t comment_count;
    char **comments;
    size_t obj_info_count;
    char **obj_info;

    /* How standard attributes were typed in the source file, so a writer can reproduce them. */
    asp_scalar_type position_type; /* FLOAT32 or FLOAT64 (NONE = float) */
    asp_scalar_type color_type;    /* UINT8 or FLOAT32 (NONE = uchar) */

    asp_las_meta *las; /* the LAS header and VLRs when read from LAS, else NULL; owned, copied by asp_cloud_clone */
    asp_up_axis up;    /* the source's up axis: ASP_UP_Z for LAS (ASPRS LAS 1.4: Z is elevation), else ASP_UP_Y;
                          asp_cloud_frame records it, so .amg/.dps/.hier and render/view/export keep it */

    asp_context ctx; /* copy of the context that allocated the arrays */
} asp_cloud;

/**
 * Creates a cloud of count points with positions (zeroed) and the attributes in
 * attrs (ASP_ATTR_* bits, zeroed). ctx may be NULL. Returns 0 or ASP_ENOMEM.
 * The caller frees the result with asp_cloud_destroy.
 */
int asp_cloud_create(size_t count, unsigned attrs, const asp_context *ctx, asp_cloud **out, asp_error *err);

/** Frees the cloud and everything it owns; NULL is accepted. */
void asp_cloud_destroy(asp_cloud *cloud);

/** Adds the attributes in attrs that are missing (zero-filled). Returns 0 or ASP_ENOMEM. */
int asp_cloud_add_attrs(asp_cloud *cloud, unsigned attrs, asp_error *err);

/** Bit set of the attributes present. */
unsigned asp_cloud_attrs(const asp_cloud *cloud);

/**
 * Adds an extra property of the given type (zero-filled) and returns a pointer
 * to it in *out (valid until the next add/remove). Fails with ASP_EINVAL if the
 * name exists or is longer than 63 bytes.
 */
int asp_cloud_add_property(asp_cloud *cloud, const char *name, asp_scalar_type type,
                           asp_property **out, asp_error *err);

/** The property called name, or NULL. */
asp_property *asp_cloud_find_property(const asp_cloud *cloud, const char *name);

/** Value i (< the cloud's count) of property p as a double, whatever its scalar type; NaN for an unknown type. */
double asp_property_value(const asp_property *p, size_t i);

/** Appends a comment (PLY "comment" line, without the keyword). */
int asp_cloud_add_comment(asp_cloud *cloud, const char *text, asp_error *err);
/** Appends an obj_info line (without the keyword). */
int asp_cloud_add_obj_info(asp_cloud *cloud, const char *text, asp_error *err);

/** Sets the face list (copies 3 * face_count indices). Fails with ASP_EFORMAT if an index is >= count. */
int asp_cloud_set_faces(asp_cloud *cloud, const uint32_t *faces, size_t face_count, asp_error *err);

/** World-space position of point i in double precision. */
void asp_cloud_world_position(const asp_cloud *cloud, size_t i, double out[3]);

/** Axis-aligned bounds of positions (relative to origin). Returns ASP_EDEGENERATE for an empty cloud. */
int asp_cloud_bounds(const asp_cloud *cloud, float lo[3], float hi[3], asp_error *err);

/**
 * Checks that every position (and normal, radius, uv if present) is finite.
 * On failure names the first bad point: "point 17: coordinate x is NaN".
 */
int asp_cloud_validate(const asp_cloud *cloud, asp_error *err);

/** Deep copy. */
int asp_cloud_clone(const asp_cloud *src, asp_cloud **out, asp_error *err);

/**
 * The sphere every representation of one point set is framed by: render, view
 * and eval point the camera at it whatever the file (.ply, .amg, .dps, .hier),
 * so one --view means one picture. .amg, .dps and .hier files record the frame
 * of the point set they came from. World coordinates (double, so UTM scans keep
 * their digits); radius 0 means "not known".
 */
typedef struct asp_frame {
    double center[3]; /* world coordinates: middle of the position bounding box */
    double radius;    /* largest distance of a point from center plus the largest disc radius */
    double half[3];   /* half sides of that box plus the largest disc radius, rounded up to steps of radius /
                         65535 (asp_frame_half_encode: as the files store them); 0 0 0 = not known (files
                         that predate it): the camera then fits the sphere alone (asp_camera_frame) */
    asp_up_axis up;   /* the source's up axis (asp_cloud.up); ASP_UP_Y also for files that predate it */
} asp_frame;

/**
 * The disc radius used when a cloud has no radii: 2 * sqrt(A / (pi n)) where
 * A = xy + yz + zx of the bounding box sides (half the box's surface area:
 * exact for a plane, 0.95 of a sphere's area) and n the point count. Discs of
 * radius sqrt(A / (pi n)) would have the surface's total area; the factor 2
 * closes the gaps of irregular (random) sampling. If A is 0 (colinear points)
 * the longest side / n is used. Returns 0 for an empty cloud or all points
 * equal. Pure; thread safe.
 */
float asp_cloud_default_radius(const asp_cloud *cloud);

/**
 * Frame of cloud (asp_frame): centre of the position bounds in world
 * coordinates, radius = largest distance from it plus the largest radius (the
 * cloud's radii, else asp_cloud_default_radius), the box's half sides plus
 * that radius and the cloud's up axis. Returns 0; ASP_EDEGENERATE
 * (empty cloud; all points equal without radii); ASP_EFORMAT (non-finite
 * values, naming the point). *out is unchanged on failure. Thread safe.
 */
int asp_cloud_frame(const asp_cloud *cloud, asp_frame *out, asp_error *err);

/**
 * The frame of count float positions (3 each, offsets from origin): centre of
 * their float bounding box, radius = largest distance from it plus radius
 * (the largest splat radius; 0 for mesh vertices), half = the box's half
 * sides plus radius, up = ASP_UP_Y (asp_cloud_frame sets the cloud's). asp_cloud_frame and the
 * mesh frame of the scene loader both come from here, so a mesh and the points
 * sampled from it frame alike. Returns 0; ASP_EDEGENERATE (count 0, or all
 * positions equal with radius 0); ASP_EFORMAT (a non-finite position, naming
 * it). *out is unchanged on failure. Thread safe.
 */
int asp_positions_frame(const float *positions, size_t count, const double origin[3], double radius, asp_frame *out,
                        asp_error *err);

/**
 * asp_frame.half as .dps and .hier files store it: each side in 16 bits, in
 * steps of radius / 65535, rounded up (so the box still holds the set);
 * decode gives back the same doubles from f->radius. Pure.
 */
void asp_frame_half_encode(const asp_frame *f, uint16_t q[3]);
void asp_frame_half_decode(asp_frame *f, const uint16_t q[3]);

#ifdef __cplusplus
}
#endif
#endif
