/*
 * The MODEL argument of the evaluation commands: a point file, a synthetic
 * shape (the octahedron of journal Fig. 1) or a mesh sampled to points by
 * area (seed 004 section 3.1: mesh-to-point conversion before rendering);
 * the mesh itself is kept for eval's true-surface reference (issue 14).
 */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "amgsplat/eval.h"
#include "amgsplat/io.h"
#include "amgsplat/sample.h"
#include "util/banned.h"

int asp_eval_load_model_mesh(const char *model, size_t points, const char *texture, const asp_context *ctx,
                             asp_cloud **out, asp_mesh **mesh_out, asp_error *err)
{
    asp_synth_shape shape;
    struct stat st;
    // a shape name is a shape unless a file of that name is there
    int synth = asp_synth_shape_parse(model, &shape, NULL) == 0 && stat(model, &st) != 0;
    asp_file_type type = {0};
    if (!synth) {
        int rc = asp_file_recognise(model, &type, err);
        if (rc)
            return rc;
        if (type.kind != ASP_FILE_POINTS && type.kind != ASP_FILE_MESH)
            return asp_error_set(err, ASP_EUNSUPPORTED, "cannot evaluate '%s': %s, not points or a mesh", model,
                                 asp_file_kind_name(type.kind));
        // without a mesh to keep, a PLY with faces stays its vertices, as bench-paper has always read it
        if (!mesh_out && asp_cloud_format_of(model))
            type.kind = ASP_FILE_POINTS;
    }
    if (synth || type.kind == ASP_FILE_POINTS) {
        if (texture)
            return asp_error_set(err, ASP_EINVAL, "a texture ('%s') applies to meshes only, not to '%s'", texture,
                                 model);
        if (mesh_out)
            *mesh_out = NULL;
        if (!synth)
            return asp_cloud_load(model, ctx, out, err);
        return asp_synth(shape, &(asp_synth_desc){.points = points}, ctx, out, err);
    }
    asp_mesh *mesh = NULL;
    int rc = asp_mesh_load(model, &(asp_mesh_load_desc){.texture_override = texture}, ctx, &mesh, err);
    if (rc)
        return rc;
    // seed 1: the same model gives the same points in every run, so results compare
    asp_sample_desc desc = {.method = ASP_SAMPLE_AREA, .points = points ? points : 100000, .seed = 1};
    rc = asp_sample_mesh(mesh, &desc, ctx, out, NULL, err);
    if (!rc && mesh_out) {
        *mesh_out = mesh;
        return 0;
    }
    asp_mesh_destroy(mesh);
    return rc;
}

int asp_eval_load_model(const char *model, size_t points, const char *texture, const asp_context *ctx,
                        asp_cloud **out, asp_error *err)
{
    return asp_eval_load_model_mesh(model, points, texture, ctx, out, NULL, err);
}
