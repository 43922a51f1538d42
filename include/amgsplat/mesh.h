/*
 * asp_mesh: a triangle mesh in structure-of-arrays form, the input of the
 * mesh-to-point samplers (Schwarz 2004 section 3.1 starts from "a polygon-based
 * object"). Files are read through assimp's C API; the node hierarchy is
 * flattened (transforms applied) and all meshes are merged into one.
 */
#ifndef AMGSPLAT_MESH_H
#define AMGSPLAT_MESH_H

#include "cloud.h"
#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A material: diffuse colour and an optional diffuse texture. */
typedef struct asp_material {
    char name[64];          /* material name from the file ("DefaultMaterial" when assimp made one up) */
    float diffuse[4];       /* RGBA in 0..1 */
    int has_color;          /* 1 when the colour came from the file, 0 for assimp's default material */
    asp_image texture;      /* pixels == NULL when the material has no texture */
    char texture_path[512]; /* where the texture came from ("*0" = embedded), "" when none; when
                               texture_missing, the file that was looked for */
    int texture_missing;    /* 1: the material names a texture file that cannot be found (only with
                               asp_mesh_load_desc.allow_missing_textures; texture.pixels is NULL) */
} asp_material;

/**
 * The mesh. Fields are public for reading; allocate only through asp_mesh_create
 * or asp_mesh_load. Arrays are 64-byte aligned and owned by the mesh.
 */
typedef struct asp_mesh {
    size_t vertex_count;
    size_t triangle_count;
    double origin[3];       /* world position = origin + positions[i] (bounding-box centre after loading) */
    float *positions;       /* 3 * vertex_count */
    float *normals;         /* 3 * vertex_count, unit length (from the file, else area-weighted) */
    float *uvs;             /* 2 * vertex_count, or NULL (GL convention: v = 0 is the image bottom) */
    uint8_t *colors;        /* 4 * vertex_count RGBA sRGB, or NULL (only when the file has vertex colours) */
    uint32_t *triangles;    /* 3 * triangle_count vertex indices, counter-clockwise seen from outside */
    uint32_t *material_ids; /* triangle_count indices into materials */
    size_t material_count;  /* >= 1 */
    asp_material *materials;
    unsigned uv_set_count;  /* texture coordinate sets in the file (the largest over its meshes);
                               uvs holds the first */
    asp_up_axis up;         /* the axis of the file's coordinates taken as up; positions and normals
                               are turned so that it is +y (asp_mesh_load_desc.up) */
    char up_rule[96];       /* why that axis, for info: "obj stores no up axis: the file's coordinates, y by convention" */
    asp_context ctx;        /* copy of the context that allocated the arrays */
} asp_mesh;

/** Bits for asp_mesh_create: which optional vertex arrays to allocate. */
enum asp_mesh_attr {
    ASP_MESH_UVS = 1 << 0,
    ASP_MESH_COLORS = 1 << 1
};

/**
 * Creates a mesh with vertex_count vertices and triangle_count triangles:
 * positions, normals, triangles and material_ids zeroed, uvs/colors when asked
 * in attrs (ASP_MESH_* bits), and one material (grey 0.6, no texture, has_color
 * 0). For building meshes in code (tests, generators). ctx may be NULL.
 * Returns 0, ASP_EINVAL (counts >= 2^32) or ASP_ENOMEM. Free with asp_mesh_destroy.
 */
int asp_mesh_create(size_t vertex_count, size_t triangle_count, unsigned attrs, const asp_context *ctx,
                    asp_mesh **out, asp_error *err);

/** Frees the mesh, its materials and their textures; NULL is accepted. */
void asp_mesh_destroy(asp_mesh *mesh);

/** Options for asp_mesh_load; the zero value means defaults. */
typedef struct asp_mesh_load_desc {
    /*
     * Image file used as the diffuse texture of every material that names no
     * texture, or whose texture file cannot be found. Needs UVs in the mesh.
     */
    const char *texture_override;
    int ignore_file_normals; /* 1: recompute area-weighted normals even if the file has some */
    /*
     * 1: a texture file that cannot be found is recorded (texture_missing,
     * texture_path) instead of failing the load, for 'amgsplat info'. 0 (the
     * default): ASP_EIO naming the file, since sampling would lose its colours.
     */
    int allow_missing_textures;
    /*
     * The axis of the file's coordinates that points up; the loaded mesh is
     * turned so that it becomes +y (the renderer's default). The zero value,
     * ASP_UP_Y, keeps the file's coordinates as they are. Rule for every
     * format: the file's own coordinates, y up (OBJ, PLY, OFF, STL store no
     * axis; glTF is y-up by its specification). assimp's 3DS importer turns
     * the scene -90 degrees about x to make 3ds Max's z-up data y-up; the
     * loader undoes that turn, because 3DS files store no up axis and those
     * met in practice (glmark2's cat and horse) are y-up: a z-up 3DS file
     * needs up = ASP_UP_Z like any other z-up file.
     */
    asp_up_axis up;
} asp_mesh_load_desc;

/** What a glTF 2.0 / GLB file holds, read from its JSON alone (asp_gltf_summary_load). */
typedef struct asp_gltf_summary {
    size_t primitives; /* mesh primitives over every mesh */
    size_t points;     /* POSITION elements of primitives drawn as points (mode 0) */
    size_t vertices;   /* POSITION elements of every other primitive */
    int glb;           /* 1: binary container */
    int decodable;     /* 0: it requires an extension the mesh reader cannot decode (asp_mesh_load refuses it) */
    char required[256]; /* extensionsRequired, comma-separated (cut at 255 bytes) */
} asp_gltf_summary;

/**
 * Describes the glTF 2.0 or GLB file at path from its JSON, after the same
 * structural checks asp_mesh_load makes before its reader (header and chunk
 * lengths, buffers, views, accessors, meshes, nodes), without decoding any
 * vertex data; so it also describes files whose required extensions the mesh
 * reader lacks, such as the compact GLB amgsplat export writes
 * (EXT_meshopt_compression). Returns 0 and fills *out, or ASP_EIO,
 * ASP_EFORMAT (the message names the file and element), ASP_ENOMEM; *out is
 * unchanged on failure.
 */
int asp_gltf_summary_load(const char *path, const asp_context *ctx, asp_gltf_summary *out, asp_error *err);

/**
 * Loads a triangle mesh (OBJ+MTL, PLY with faces, OFF, STL, glTF/GLB, 3DS and
 * whatever else the installed assimp reads). Polygons are triangulated, the
 * node transforms applied, all meshes merged; points and lines are dropped.
 * Texture paths resolve relative to the model file; embedded textures ("*0")
 * are decoded. Normals come from the file when every mesh has them, else they
 * are computed area-weighted over triangles sharing a position (so UV seams do
 * not show). desc may be NULL.
 * Errors: ASP_EIO (unreadable file or a named texture that cannot be read: the
 * message names the texture path and the material and suggests --texture),
 * ASP_EFORMAT (assimp's message; a non-finite coordinate), ASP_EDEGENERATE (no
 * triangles; zero surface area), ASP_EINVAL (texture_override without UVs),
 * ASP_EUNSUPPORTED (more than 2^32-1 vertices), ASP_ENOMEM. On failure *out is
 * unchanged. Thread safety: not safe to call from two threads at once, because
 * assimp's C API keeps its last error message in a process-wide string.
 * Containment (issue #31): OFF, STL, OBJ, PLY, glTF/GLB, Collada and 3DS are
 * pre-checked (counts, lengths and indices against the bytes); then assimp
 * runs in a forked child process with its address space capped at 512 MB plus
 * 64 bytes per byte of the file and its CPU time at 60 s plus 10 s per MB, so
 * a crash inside it is ASP_EFORMAT "cannot read 'x.dae': the reader (assimp)
 * crashed with signal 11 (...)" and a blow-up ASP_ENOMEM "... out of memory:
 * the reader (assimp) reached its limit of N MB". Texture files are read in
 * the calling process and recorded so that no output replaces them.
 */
int asp_mesh_load(const char *path, const asp_mesh_load_desc *desc, const asp_context *ctx, asp_mesh **out,
                  asp_error *err);

/**
 * Recomputes normals: area-weighted sums of triangle normals over all vertices
 * at the same position (exactly equal coordinates), normalised; a vertex whose
 * sum vanishes gets (0,0,1). Returns 0 or ASP_ENOMEM (scratch).
 */
int asp_mesh_compute_normals(asp_mesh *mesh, asp_error *err);

/** Total triangle area in world units squared (summed in double). */
double asp_mesh_area(const asp_mesh *mesh);

/* The largest |position| asp_mesh_validate accepts (relative to origin): squares stay finite in float. */
#define ASP_MESH_MAX_COORD 1e18

/**
 * Checks a mesh before sampling: triangle indices in range, finite positions
 * within +-ASP_MESH_MAX_COORD, uvs and normals, a finite origin, material ids
 * in range, non-zero area. name is used in the
 * messages ("mesh 'x.obj' has zero surface area"). Returns 0, ASP_EFORMAT or
 * ASP_EDEGENERATE.
 */
int asp_mesh_validate(const asp_mesh *mesh, const char *name, asp_error *err);

/*
 * GPU bytes of a mesh, the count issue #14 compares with domain primitives:
 * per vertex 12 (float position) + 12 (float normal) + 8 (float uv, when the
 * mesh has uvs) + 4 (RGBA8 colour, when it has vertex colours); 4 per index
 * (uint32, three per triangle); per texture width * height * 4 * 4 / 3
 * (RGBA8 with its full mipmap chain, rounded down), each texture counted once
 * (materials naming the same texture_path share it) and only when a triangle
 * uses its material. Pure.
 */
typedef struct asp_mesh_bytes {
    size_t vertex, index, texture, total;
} asp_mesh_bytes;

/** Fills the byte counts above for mesh; returns the total. out may be NULL. */
size_t asp_mesh_gpu_bytes(const asp_mesh *mesh, asp_mesh_bytes *out);

/** Options for asp_mesh_save; the zero value means defaults. */
typedef struct asp_mesh_save_desc {
    int ply_ascii; /* PLY: 1 writes ascii text; 0 (default) binary little endian */
} asp_mesh_save_desc;

/**
 * Writes mesh to path, the format told by its extension (asp_file_type_of_name):
 *  - .obj: "v x y z" in world coordinates (origin + position; "v x y z r g b"
 *    when the mesh has vertex colours, as assimp reads them), "vt", "vn",
 *    faces grouped by material under "usemtl", and "mtllib" naming a .mtl file
 *    beside it (same name, .mtl) with Kd and d per material. A material's
 *    texture is written as PNG beside it, named after the output: OUT.png for
 *    the first textured material, OUT_<i>.png for material i after it; map_Kd
 *    names it relative to the OBJ.
 *  - .ply: binary little endian (or ascii, desc->ply_ascii) with x y z,
 *    nx ny nz, texture_u texture_v (when uvs), red green blue alpha uchar
 *    (when colours) and "face" with "list uchar int vertex_indices". PLY has
 *    no materials: the first textured material's texture is written as
 *    OUT.png and named by "comment TextureFile OUT.png" (assimp's convention);
 *    other materials' colours and textures are not kept.
 * What is written reads back through asp_mesh_load with the same vertex and
 * triangle counts, uvs and texture (material names with spaces become '_').
 * Each file appears atomically (temporary + rename); the textures and the
 * .mtl are written before the mesh file, so a mesh file never names a file
 * that is not there. Errors: ASP_EUNSUPPORTED (another extension: "cannot
 * write 'f.stl': mesh output is .obj or .ply"), ASP_EIO, ASP_ENOMEM. desc may
 * be NULL. Reentrant; the mesh is only read.
 */
int asp_mesh_save(const asp_mesh *mesh, const char *path, const asp_mesh_save_desc *desc, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
