/*
 * amgsplat scene: the one loader behind render, view and eval (STYLE.md 9b).
 * It tells a file's kind with asp_file_recognise (io.h), loads points, an
 * .amg decomposition (coloured by classifier or domains, journal Fig. 1b, 5),
 * a .dps level of domain primitives (journal section 4), a .hier point
 * hierarchy or a triangle mesh (seed 004 2.2-2.3), and hands back what to draw together with the one frame every
 * representation of a model is fitted to (asp_frame, cloud.h: the source point
 * set's sphere), so `--view AZ,EL` means one picture whatever the file.
 */
#ifndef AMGSPLAT_SCENE_H
#define AMGSPLAT_SCENE_H

#include "amg.h"
#include "cloud.h"
#include "hier.h"
#include "io.h"
#include "mesh.h"
#include "prim.h"
#include "render.h"
#include "sample.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How the points of an .amg are coloured (asp_scene_desc.amg_color). */
typedef enum asp_scene_amg_color {
    ASP_SCENE_AMG_INPUT = 0,      /* the points' own colours (light grey without any) */
    ASP_SCENE_AMG_CLASSIFIER = 1, /* asp_amg_colorize ASP_AMG_COLOR_CLASSIFIER (journal Fig. 1b) */
    ASP_SCENE_AMG_DOMAINS = 2,    /* ASP_AMG_COLOR_DOMAINS of one level (journal Fig. 5c-d) */
    ASP_SCENE_AMG_STRICT = 3      /* ASP_AMG_COLOR_STRICT of one level (thesis 2.5) */
} asp_scene_amg_color;

/** Options of asp_scene_load; the zero value means defaults. */
typedef struct asp_scene_desc {
    asp_scene_amg_color amg_color; /* .amg only */
    const char *level;   /* .amg: level of the domain colours ("L", "L-3" or an index; NULL = "L");
                            .dps: level drawn (asp_dps_level_parse; NULL = the finest in the file) */
    float crease_angle;  /* point and .amg inputs: degrees in (0, 90): clip planes at sharper creases
                            (asp_crease_clip_planes; needs normals); 0 = none */
    int crease_if_normals; /* 1: crease_angle is a default, not a request: points without normals are
                              drawn unclipped instead of refused */
    const char *texture; /* meshes: image used as the texture of every material that names none or whose
                            file is missing (asp_mesh_load_desc.texture_override); NULL = none */
} asp_scene_desc;

/** What asp_scene_load loaded; release with asp_scene_release. */
typedef struct asp_scene {
    asp_file_type type;      /* what the file is (asp_file_recognise) */
    char path[512];          /* the file as given */
    asp_cloud *cloud;        /* points to draw, in the cloud's local frame: the file's points or a coloured
                                copy of the .amg's; NULL for .dps (until asp_scene_load_source) and .hier */
    asp_amg *amg;            /* .amg: the decomposition */
    asp_scene_amg_color amg_color;
    size_t amg_level;        /* .amg: level of the domain colours */
    asp_dps *dps;            /* .dps: every level of the file */
    size_t dps_level;        /* .dps: index into dps->levels of the level drawn */
    asp_hier *hier;          /* .hier */
    float *clip_planes;      /* 8 floats per point of cloud with desc->crease_angle, else NULL */
    asp_mesh *mesh;          /* meshes: the mesh (asp_mesh_load; a missing texture is recorded in its
                                material, texture_missing, and drawn in the material colour) */
    asp_render_mesh render_mesh;    /* meshes: what the mesh renderer draws, arrays borrowed from mesh */
    asp_render_material *materials; /* meshes: render_mesh.materials */
    asp_frame frame;         /* world-space sphere to fit the camera to (asp_camera_frame): the frame of the
                                source point set, recorded in .amg/.dps/.hier; a representation's own
                                bounds only when the file records none (radius 0) and no source is found;
                                a mesh's vertices framed as asp_cloud_frame frames points of radius 0
                                (asp_scene_mesh_frame) */
    double origin[3];        /* the local frame every renderer of the scene draws in: cloud->origin, the
                                hierarchy's origin, the mesh's origin, or for .dps the frame centre */
    asp_context ctx;
} asp_scene;

/**
 * Loads path (recognised by magic bytes, then extension: asp_file_recognise)
 * into *out (zeroed or released before; filled only on success). Points go
 * through asp_cloud_load, .amg through asp_amg_load (coloured by
 * desc->amg_color), .dps through asp_dps_load (desc->level picked), .hier
 * through asp_hier_load, meshes (ASP_FILE_MESH: OBJ+MTL, PLY with faces,
 * OFF, STL, glTF/GLB, 3DS) through asp_mesh_load with missing textures
 * allowed (listed in out->mesh->materials[i].texture_missing, for the caller
 * to warn about) and desc->texture; a PLY with faces loads its vertices as
 * points too (asp_cloud_load), so the point renderers draw it as well. A
 * .dps that records no frame is framed by its source points (asp_dps.source,
 * tried as stored and next to the .dps) when they load, else by the level's
 * support rectangles. desc may be NULL; ctx
 * (NULL = defaults) gives threads and allocator and is kept in out->ctx.
 * Returns 0; the loaders' errors (ASP_EIO, ASP_EFORMAT naming the file);
 * ASP_EUNSUPPORTED for an image; ASP_EINVAL (a level the file does
 * not have, input colours asked of points without colours is not an error);
 * ASP_EDEGENERATE (nothing to frame); ASP_ENOMEM. Reentrant, except that
 * two meshes must not load at once (asp_mesh_load keeps assimp's error
 * message in a process-wide string).
 */
int asp_scene_load(const char *path, const asp_scene_desc *desc, const asp_context *ctx, asp_scene *out,
                   asp_error *err);

/**
 * .amg scenes: colours s->cloud by color at level (an index of the
 * decomposition; ignored by INPUT and CLASSIFIER). The cloud is unchanged on
 * failure. Returns 0, ASP_EINVAL (not an .amg scene, a level out of range,
 * input colours of points that have none) or ASP_ENOMEM.
 */
int asp_scene_recolor(asp_scene *s, asp_scene_amg_color color, size_t level, asp_error *err);

/** Points asp_scene_load_source samples from a mesh (area sampling, `amgsplat sample` defaults otherwise). */
#define ASP_SCENE_MESH_POINTS 200000

/**
 * .dps scenes: loads the source points the file names (asp_dps.source, an
 * .amg or point file, tried as stored and next to the .dps) into s->cloud,
 * moved into the primitives' frame (s->origin) so one camera shows both.
 * Mesh scenes: samples ASP_SCENE_MESH_POINTS points from the mesh
 * (asp_sample_mesh, ASP_SAMPLE_AREA, seed 0, so the points `amgsplat sample
 * --method area --points 200000` writes) into s->cloud, in the mesh's frame.
 * A no-op when s->cloud is already there (a PLY with faces). Returns 0,
 * ASP_EINVAL (neither a .dps nor a mesh scene), ASP_EUNSUPPORTED (no usable
 * source name) or the loaders' and the sampler's errors.
 */
int asp_scene_load_source(asp_scene *s, asp_error *err);

/**
 * As asp_scene_load_source, for .dps scenes from path (a point file or .amg,
 * e.g. `render --hybrid-points`) instead of the source the file names; path
 * NULL is asp_scene_load_source. Returns its errors, or ASP_EINVAL when path
 * is given for a scene that is not a .dps.
 */
int asp_scene_load_source_from(asp_scene *s, const char *path, asp_error *err);

/** The .dps level drawn (s->dps_level), or NULL for other kinds. */
const asp_dps_level *asp_scene_dps_level(const asp_scene *s);

/**
 * What the renderer table (asp_renderer_kind in render.h) draws of s: its
 * cloud, clip planes, hierarchy, .dps level, mesh and origin, borrowed from s.
 */
void asp_scene_render_source(const asp_scene *s, asp_render_source *out);

/**
 * The frame of a mesh (asp_frame in world coordinates): exactly what
 * asp_cloud_frame gives for its vertices as points of radius 0 (centre of the
 * float bounding box, largest vertex distance from it), so a mesh and the
 * points sampled from it (amgsplat sample) frame alike: the samples' frame
 * differs only by their own bounds (inside the mesh's) and their largest disc
 * radius. Returns 0, ASP_EDEGENERATE (no vertices, all at one point) or
 * ASP_EFORMAT (a non-finite position). Thread safe.
 */
int asp_scene_mesh_frame(const asp_mesh *mesh, asp_frame *out, asp_error *err);

/**
 * render's plain description of mesh (what the mesh renderer draws): out
 * borrows mesh's arrays (valid while mesh lives) and points at materials,
 * mesh->material_count entries the caller provides, which receive each
 * material's colour (light grey for a material without one, as points without
 * colours) and texture (borrowed from mesh). Pure.
 */
void asp_scene_mesh_describe(const asp_mesh *mesh, asp_render_material *materials, asp_render_mesh *out);

/**
 * The asp_render_input_bits s can feed: points when it has a cloud or
 * hierarchy, primitives for .dps, a mesh for meshes.
 */
unsigned asp_scene_inputs(const asp_scene *s);

/** Frees everything s owns and zeroes it; a zeroed scene is accepted. */
void asp_scene_release(asp_scene *s);

#ifdef __cplusplus
}
#endif
#endif
