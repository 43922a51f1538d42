/*
 * amgsplat io: point files. PLY (ascii, binary little and big endian, every
 * scalar type, list properties, faces) and plain-text XYZ/PTS, plus load/save
 * by extension. The point set is the input of every later stage (journal
 * Sect. 1, Fig. 2 pipeline; Schwarz 2004 1.4: samples carry position, normal,
 * colour, and uv as in 3.1.6-3.1.7).
 */
#ifndef AMGSPLAT_IO_H
#define AMGSPLAT_IO_H

#include "cloud.h"
#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/** PLY body encoding for writing; 0 means binary little endian. */
typedef enum asp_ply_encoding {
    ASP_PLY_DEFAULT = 0,      /* binary_little_endian */
    ASP_PLY_BINARY_LE = 1,
    ASP_PLY_BINARY_BE = 2,
    ASP_PLY_ASCII = 3
} asp_ply_encoding;

/** LAS point data record format n for asp_save_desc.las_format (0 there means "choose"). */
#define ASP_LAS_FORMAT(n) ((unsigned)(n) + 1u)

/** Options for writing point files; the zero value means defaults. */
typedef struct asp_save_desc {
    asp_ply_encoding encoding; /* PLY only; ignored by the text formats */
    unsigned las_format;       /* LAS only: ASP_LAS_FORMAT(0..3, 6..8), or 0 to choose (asp_las_write) */
    double las_scale;          /* LAS only: coordinate step in world units; 0 keeps the source's, else 0.001 */
} asp_save_desc;

/**
 * Reads a PLY file into a new cloud (*out; free with asp_cloud_destroy).
 *
 * Accepted: "format ascii|binary_little_endian|binary_big_endian 1.0", every
 * scalar type and alias (char/int8 ... double/float64), list properties in any
 * element, elements in any order, CRLF or LF header lines. The 'vertex'
 * element gives the points:
 *  - x, y, z of any numeric type (required). float32 (and 8/16-bit integer)
 *    coordinates are stored exactly with origin 0. double and 32-bit integer
 *    coordinates set origin[k] to the first point's coordinate rounded to an
 *    integer and store float offsets from it; position_type becomes FLOAT64.
 *  - colours red/green/blue[/alpha], r/g/b[/a] or diffuse_red/... as uchar,
 *    or as float/double in 0..1 (color_type records which; alpha is 255 when
 *    absent). The three (four) must share one type.
 *  - normals nx/ny/nz or normal_x/normal_y/normal_z (float or double);
 *    radius, psz or point_size (float or double); uvs u/v, s/t or
 *    texture_u/texture_v (float or double); label (uint) into labels.
 *  - every other scalar vertex property is kept as an asp_property with its
 *    name and type, in file order; list properties of the vertex are skipped.
 * The 'face' element's vertex_indices (or vertex_index) list becomes
 * triangles (polygons fan-triangulated, fewer than 3 indices dropped); other
 * elements and lists (tristrips, edges, material ...) are skipped. comment
 * and obj_info lines are kept in order.
 *
 * Errors: ASP_EIO (cannot open or read), ASP_EUNSUPPORTED (more than 2^32-1
 * points), ASP_ENOMEM, ASP_ECANCELED (progress callback), ASP_EFORMAT for
 * anything malformed: bad magic, unknown format or type, missing x/y/z,
 * duplicate property, empty vertex element, NaN/Inf coordinate, truncation,
 * a count the file cannot hold (checked against the file size before any
 * allocation), an out-of-range face index. Messages read
 * "cannot read 'F': line N: ..." for the header and ascii bodies, and
 * "cannot read 'F': element 'vertex' N of M, byte B: ..." for binary bodies,
 * N counting records from 1 and B being the file offset. On failure *out is
 * unchanged and nothing leaks. Reentrant; ctx may be NULL.
 */
int asp_ply_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err);

/**
 * As asp_ply_read, from size bytes at data (borrowed for the call); name is
 * used in messages (NULL gives "<memory>"). Safe on arbitrary bytes (fuzzed).
 */
int asp_ply_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err);

/**
 * Writes cloud as PLY (desc may be NULL: binary little endian). Positions are
 * float, or double world coordinates (origin + offset) when position_type is
 * FLOAT64 or the origin is non-zero; normals, radius ("radius"), uvs
 * ("texture_u", "texture_v") and labels ("label", uint) as written by
 * asp_ply_read; colours as uchar or float 0..1 per color_type ("alpha" only
 * when some alpha is not 255); every extra property with its own type; faces
 * as "face" with "list uchar int vertex_indices" (uint when an index exceeds
 * 2^31-1); comments and obj_info (newlines inside them become spaces).
 * The file appears atomically (temporary file + rename).
 * Errors: ASP_EINVAL (an extra property's name clashes with a written
 * standard property), ASP_EIO, ASP_ENOMEM; on failure no file is left.
 * Reentrant; the cloud is only read.
 */
int asp_ply_write(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err);

/**
 * Reads a plain-text point file: one point per line, values separated by
 * spaces, tabs, commas or semicolons; blank lines and lines starting with '#'
 * or "//" are skipped; a first data line holding a single integer is a point
 * count (as in .pts) and is skipped. The first data line fixes the column
 * count, every other line must match:
 *   3: x y z            4: x y z intensity       7: x y z intensity r g b
 *   6: x y z nx ny nz  or  x y z r g b           9: x y z nx ny nz r g b
 * Six columns mean colours when, on every line, the last three values are
 * integers in 0..255 and not every triple has unit length (so "0 0 1" is a
 * normal); otherwise normals. Colour columns hold integers 0..255, or values
 * in 0..1 (color_type FLOAT32). intensity becomes the float property
 * "intensity". When the coordinates are far from zero (|x| > 65536) the
 * origin is the bounding-box centre rounded to an integer and positions are
 * float offsets from it. Values are parsed as doubles.
 * Errors: ASP_EIO, ASP_ENOMEM, ASP_EFORMAT "cannot read 'F': line N: ..."
 * (wrong value count, not a number, colour out of range, no points).
 * On failure *out is unchanged. Reentrant.
 */
int asp_xyz_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err);

/** As asp_xyz_read from memory (data borrowed; name for messages, NULL = "<memory>"). */
int asp_xyz_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err);

/**
 * Writes "x y z [nx ny nz] [r g b]" lines with world coordinates (shortest
 * text that reads back to the same float, or 17 digits when the origin is
 * non-zero). With no normals, an extra property "intensity" is written as the
 * fourth column (4 or 7 columns, Leica PTS layout). Radius, uvs, labels,
 * alpha, other extra properties, faces and comments are not written. When
 * the path ends in ".pts" a first line holds the point count. desc is
 * ignored (may be NULL). Atomic; errors ASP_EIO, ASP_ENOMEM. Reentrant.
 */
int asp_xyz_write(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err);

/**
 * Reads an ASPRS LAS file, versions 1.0 to 1.4, point data record formats 0
 * to 10 (LAS 1.4 R15), into a new cloud (*out; free with asp_cloud_destroy).
 *  - World coordinates are offset + scale * X (X the int32 of the record).
 *    origin is the header's offset, or, when some |X| >= 2^23, the offset
 *    plus the middle of the data's X range times the scale; positions are
 *    the float rest, within half a scale step of the true value for spans up
 *    to 2^24 scale steps. position_type is FLOAT64.
 *  - Record fields become properties with the same names in every format:
 *    intensity (uint16), return_number, number_of_returns,
 *    scan_direction_flag, edge_of_flight_line, classification,
 *    classification_flags (bit 0 synthetic, 1 key-point, 2 withheld, 3
 *    overlap), scanner_channel (formats 6-10), user_data (uint8),
 *    scan_angle_rank (int8 degrees, formats 0-5) or scan_angle (int16 steps
 *    of 0.006 degrees, 6-10), point_source_id (uint16), gps_time (double),
 *    red16/green16/blue16 and nir (uint16), the wave packet fields
 *    (wave_packet_index, wave_packet_offset, wave_packet_size,
 *    wave_return_location, wave_dx/dy/dz; the waveforms are not read).
 *  - RGB also becomes colors (alpha 255): the high byte when any value of
 *    the file exceeds 255, else the values as they are.
 *  - Extra bytes become properties named and typed by the Extra Bytes VLR
 *    (scaled ones as double, 64-bit integers as double), bytes nothing
 *    describes as uint8 "extra_byte_K"; extra bytes nx/ny/nz (float) become
 *    normals, radius (float) radii, label (uint32) labels.
 *  - The header and every VLR and EVLR but Extra Bytes and waveform data
 *    are kept in cloud->las for asp_las_write.
 * Errors: ASP_EIO (open, read), ASP_ENOMEM, ASP_EUNSUPPORTED (LAS 2.x;
 * LASzip-compressed data, by the format byte or the LASzip VLR: "cannot read
 * 'F': compressed LAS (LASzip) needs a decompressor this build does not
 * have; ..."; more than 2^32-1 points), ASP_EFORMAT "cannot read 'F': ..."
 * for a bad magic, a truncated header or VLR, a record length below the
 * format's size, counts the file cannot hold (checked before allocating),
 * disagreeing legacy and 64-bit counts, a zero or non-finite scale, a
 * non-finite offset, a bad Extra Bytes descriptor; ASP_ECANCELED (progress
 * callback, stage "read LAS"). The file is read a chunk of records at a
 * time, never held whole. On failure *out is unchanged. Reentrant; ctx may
 * be NULL.
 */
int asp_las_read(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err);

/** As asp_las_read from size bytes at data (borrowed); name for messages (NULL: "<memory>"). Fuzzed. */
int asp_las_read_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_cloud **out,
                        asp_error *err);

/**
 * Writes cloud as LAS. Point format: desc->las_format when set (0-3 or 6-8;
 * 4, 5, 9, 10 carry waveforms, which are not written: ASP_EINVAL), else the
 * source's (cloud->las; a waveform format becomes 1, 3, 6 or 8 without the
 * packet), else 8 when there is a "nir" property, 7 with colours, 6 without.
 * Version 1.4 for formats 6-8 and when the source has EVLRs, the source's
 * version when its format is kept, else 1.2 (read by every LAS reader).
 * Scale: desc->las_scale, else the source's, else 0.001 per axis; offset:
 * the source's, else the floor of the bounding-box minimum. Fields are
 * taken from the properties asp_las_read makes (any numeric type, rounded);
 * missing ones are 0, return_number and number_of_returns 1; RGB is
 * red16/green16/blue16 when they give the colours by the read rule, else
 * colour * 257. Other properties, normals (nx, ny, nz), radii (radius) and
 * labels (label) are written as extra bytes with an Extra Bytes VLR; uvs and
 * alpha are not written. The source's VLRs and EVLRs are written back.
 * Errors: ASP_EINVAL (a coordinate outside int32 at the scale, naming the
 * point: choose a larger scale; a value outside its field in the format,
 * e.g. classification 40 in format 3; a name longer than 32 bytes for an
 * extra byte; records over 65535 bytes), ASP_EIO, ASP_ENOMEM. Atomic.
 * Reentrant; the cloud is only read.
 */
int asp_las_write(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err);

/**
 * Loads a point file, its format told by asp_file_recognise (magic bytes, then
 * the extension, case-insensitive: BUNNY.PLY loads): PLY through asp_ply_read
 * (a PLY with faces too: its vertices), LAS through asp_las_read (LAZ:
 * ASP_EUNSUPPORTED, "compressed LAS (LASzip) needs a decompressor ..."),
 * .xyz/.pts/.txt through asp_xyz_read. Then rejects non-finite
 * values (asp_cloud_validate) and an empty cloud, with ASP_EFORMAT
 * "cannot read 'F': ...". A cloud whose points are all equal loads fine.
 * Unknown extension: ASP_EUNSUPPORTED "cannot read 'f.abc': unknown point
 * format '.abc' (expected .ply, .xyz, .pts, .txt, .las)". A file that is
 * something else (a mesh, an image, an .amg ...: by its magic or extension)
 * gives ASP_EUNSUPPORTED "cannot read 'f.obj': a mesh file (obj), not a point
 * file; sample it ...". A directory or FIFO: ASP_EIO at once. On failure
 * *out is unchanged. Reentrant; ctx may be NULL.
 */
int asp_cloud_load(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err);

/**
 * Saves by extension (case-insensitive, asp_file_type_of_name): .ply through asp_ply_write (desc->encoding applies),
 * .las through asp_las_write (desc->las_format, las_scale apply; .laz is ASP_EUNSUPPORTED),
 * .xyz/.pts/.txt through asp_xyz_write. Unknown extension: ASP_EUNSUPPORTED
 * "cannot write 'f.abc': unknown point format ...". Atomic. Reentrant.
 */
int asp_cloud_save(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err);

/**
 * Point format of a path by its extension (case-insensitive): "ply", "xyz"
 * (for .xyz, .pts, .txt) or NULL when unknown. Pure; never fails.
 */
const char *asp_cloud_format_of(const char *path);

/* ------------------------------------------------------------------------ */
/* The one file recogniser (STYLE.md 9b): every command asks it what a file is */
/* ------------------------------------------------------------------------ */

/** What a file holds, as far as amgsplat is concerned. */
typedef enum asp_file_kind {
    ASP_FILE_UNKNOWN = 0,
    ASP_FILE_POINTS = 1, /* PLY without faces, LAS/LAZ, XYZ, PTS, TXT point lists */
    ASP_FILE_MESH = 2,   /* OBJ, PLY with faces, OFF, STL, glTF/GLB, 3DS, ... (assimp; asp_mesh_load) */
    ASP_FILE_AMG = 3,    /* AMG decomposition (amgsplat decompose) */
    ASP_FILE_DPS = 4,    /* domain primitives (amgsplat build) */
    ASP_FILE_HIER = 5,   /* point hierarchy (asp_hier_save) */
    ASP_FILE_IMAGE = 6,  /* PNG, JPEG, BMP, TGA, ... (stb_image) */
    ASP_FILE_SCENE = 7   /* a scene of instances (JSON with "instances", instances.h) */
} asp_file_kind;

/** What asp_file_recognise found. */
typedef struct asp_file_type {
    asp_file_kind kind;
    char format[16]; /* lower-case short name: "ply", "xyz", "pts", "txt", "las", "laz", "obj", "off", "stl", "gltf",
                        "glb", "3ds", "fbx", "dae", "amg", "dps", "hier", "png", "jpeg", "bmp", "tga",
                        "gif", "json" (scenes); "" when unknown */
    int by_magic;    /* 1: told by the first bytes of the file, 0: by its extension */
} asp_file_type;

/**
 * Tells what path holds: magic bytes first (PLY, LAS "LASF" (format "laz"
 * when LASzip-compressed: format byte bit 7 or 6, or a LASzip VLR), OFF, GLB, binary 3DS, the
 * .amg/.dps/.hier magics, PNG, JPEG ...), then the extension, compared
 * case-insensitively ("BUNNY.PLY", "o.AMG"). A PLY is a mesh when its header
 * declares a non-empty face element (asp_cloud_load still reads its vertices
 * as points). Directories, FIFOs and other non-regular files are refused at
 * once, before any read (no hang).
 * Returns 0; ASP_EIO ("cannot open 'f': ..." or "cannot read 'f': not a
 * regular file"); ASP_EUNSUPPORTED ("cannot read 'f.abc': unknown file type
 * '.abc' (expected ...)" listing what is known). *out is unchanged on failure.
 * Reads at most a few kilobytes. Reentrant.
 */
int asp_file_recognise(const char *path, asp_file_type *out, asp_error *err);

/**
 * As asp_file_recognise on the first size bytes of a file (head, borrowed)
 * whose name (for the extension and messages) is name. Never touches the file
 * system; safe on arbitrary bytes.
 */
int asp_file_recognise_memory(const void *head, size_t size, const char *name, asp_file_type *out, asp_error *err);

/**
 * The kind a path to be written would have, by its extension alone
 * (case-insensitive), for outputs: 0 and *out filled, or ASP_EUNSUPPORTED
 * naming the extension. Pure.
 */
int asp_file_type_of_name(const char *path, asp_file_type *out, asp_error *err);

/** An image file's header: what asp_image_probe reads without decoding pixels. */
typedef struct asp_image_header {
    uint32_t width, height;
    unsigned channels; /* in the file: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA */
} asp_image_header;

/**
 * Reads the size and channel count of an image (PNG, JPEG, BMP, TGA, GIF ...)
 * from its header. Returns 0; ASP_EIO (cannot open); ASP_EFORMAT (not an
 * image stb_image reads, with its reason). *out is unchanged on failure.
 * Reentrant except for stb_image's failure reason string.
 */
int asp_image_probe(const char *path, asp_image_header *out, asp_error *err);

/**
 * 1 when path's extension names format (asp_file_type.format, e.g. "png"),
 * compared case-insensitively as asp_file_type_of_name does; else 0. For
 * checking output names. Pure.
 */
int asp_file_name_is(const char *path, const char *format);

/** "unknown", "points", "mesh", "amg", "dps", "hier", "image", "scene". Never NULL. */
const char *asp_file_kind_name(asp_file_kind kind);

#ifdef __cplusplus
}
#endif
#endif
