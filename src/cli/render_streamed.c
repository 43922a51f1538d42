/*
 * render of a streamed .hier (issue 28): the views' cameras are made first,
 * each picks its cut coarse first by projected point spacing (asp_ooc_select)
 * under a share of the point budget that --memory allows, and only the union
 * of those nodes is read, into the scene's cloud, which the point renderers
 * then draw like a point file's (discs of the loaded density).
 */
#include <stdlib.h>
#include <string.h>

#include "amgsplat/camera.h"
#include "amgsplat/hier_ooc.h"
#include "cli/cli.h"
#include "util/banned.h"


int cli_render_streamed(const char *path, const struct cli_streamed_view *v, const asp_context *ctx, asp_scene *s,
                        struct cli_streamed_stats *st, asp_error *err)
{
    asp_ooc *ooc = NULL;
    int rc = asp_ooc_open(path, ctx, &ooc, err);
    if (rc)
        return rc;
    size_t nn = asp_ooc_node_count(ooc);
    uint32_t *cut = malloc(nn * sizeof *cut), *all = malloc(nn * sizeof *all);
    uint8_t *mark = calloc(nn, 1);
    size_t nall = 0;
    uint64_t budget = asp_ooc_budget_points(v->memory);
    uint64_t per_view = budget / (v->views ? v->views : 1);
    double origin[3];
    asp_ooc_origin(ooc, origin);
    if (!cut || !all || !mark)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the cut of %zu nodes", nn);
    for (size_t i = 0; i < v->views && !rc; i++) {
        asp_camera cam;
        asp_camera_init(&cam);
        cam.fov_y = (float)v->fov;
        cam.up = v->up_given ? v->up : asp_ooc_frame(ooc)->up;
        cam.azimuth = (float)(v->az + 360.0 * (double)i / (double)v->views);
        cam.elevation = (float)(i % 2 ? -v->el : v->el);
        asp_camera_frame(&cam, asp_ooc_frame(ooc), origin, (float)v->width / (float)v->height, (float)v->dist);
        asp_hier_view hv;
        asp_hier_view_of_camera(&cam, v->width, v->height, (float)v->tau, &hv);
        size_t n = 0;
        uint64_t pts = 0;
        if ((rc = asp_ooc_select(ooc, &hv, per_view, cut, &n, &pts, err)) != 0)
            break;
        for (size_t k = 0; k < n; k++)
            if (!mark[cut[k]]) {
                mark[cut[k]] = 1;
                all[nall++] = cut[k];
            }
    }
    asp_cloud *cloud = NULL;
    double t0 = asp_time_now();
    if (!rc)
        rc = asp_ooc_load(ooc, all, nall, &cloud, err);
    if (!rc) {
        memset(s, 0, sizeof *s);
        asp_file_type_of_name(path, &s->type, NULL);
        snprintf(s->path, sizeof s->path, "%s", path);
        s->cloud = cloud;
        s->frame = *asp_ooc_frame(ooc);
        memcpy(s->origin, origin, sizeof s->origin);
        if (ctx)
            s->ctx = *ctx;
        st->nodes = nall;
        st->node_count = nn;
        st->points = cloud->count;
        st->point_count = asp_ooc_point_count(ooc);
        st->budget = budget;
        st->load_seconds = asp_time_now() - t0;
    }
    free(cut);
    free(all);
    free(mark);
    asp_ooc_close(ooc);
    return rc;
}
