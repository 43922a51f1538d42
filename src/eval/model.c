/*
 * The MODEL argument of the evaluation commands: a point file, a synthetic
 * shape (the octahedron of journal Fig. 1) or a mesh sampled to points by
 * area (seed 004 section 3.1: mesh-to-point conversion before rendering).
 */
#include <stdio.h>
#include <string.h>

#include "amgsplat/eval.h"
#include "amgsplat/io.h"
#include "amgsplat/sample.h"
#include "util/banned.h"

int asp_eval_load_model(const char *model, size_t points, const char *texture, const asp_context *ctx,
                        asp_cloud **out, asp_error *err)
{
    asp_synth_shape shape;
    if (asp_cloud_format_of(model) || asp_synth_shape_parse(model, &shape, NULL) == 0) {
        if (texture)
            return asp_error_set(err, ASP_EINVAL, "a texture ('%s') applies to meshes only, not to '%s'", texture,
                                 model);
        if (asp_cloud_format_of(model))
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
    asp_mesh_destroy(mesh);
    return rc;
}
