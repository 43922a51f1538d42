/*
 * One primitive of a level as a level of its own: the thesis viewer's "draw
 * one picked domain only" debug option (appendix C), so that any rendering
 * method draws just that domain's footprint.
 */
#include <string.h>

#include "amgsplat/prim.h"
#include "util/banned.h"

static void copy_rect(const asp_image *src, const asp_prim *p, asp_image *dst)
{
    for (uint32_t j = 0; j < p->tex_h; j++)
        memcpy(&dst->pixels[4 * (size_t)j * p->tex_w],
               &src->pixels[4 * ((size_t)(p->tex_y + j) * src->width + p->tex_x)], 4 * (size_t)p->tex_w);
}

int asp_dps_level_pick(const asp_dps_level *src, size_t prim, const asp_context *ctx, asp_dps_level *out,
                       asp_error *err)
{
    ASP_ASSERT(src && out);
    if (prim >= src->prim_count)
        return asp_error_set(err, ASP_EINVAL, "no domain %zu: level %u has domains 0..%zu", prim, src->level,
                             src->prim_count ? src->prim_count - 1 : 0);
    const asp_prim *p = &src->prims[prim];
    if (!src->atlas.pixels || p->tex_w == 0 || p->tex_h == 0 || p->tex_x > src->atlas.width ||
        p->tex_w > src->atlas.width - p->tex_x || p->tex_y > src->atlas.height || p->tex_h > src->atlas.height - p->tex_y)
        return asp_error_set(err, ASP_EFORMAT, "domain %zu: texture %ux%u at (%u, %u) is outside the %ux%u atlas", prim,
                             p->tex_w, p->tex_h, p->tex_x, p->tex_y, src->atlas.width, src->atlas.height);
    asp_dps_level lv = *src;
    lv.prim_count = 1;
    lv.neighbour_total = 0;
    lv.neighbours = NULL;
    lv.atlas = (asp_image){0, 0, NULL};
    lv.normal_atlas = (asp_image){0, 0, NULL};
    lv.atlas_bc3 = lv.normal_bc3 = NULL; /* the picked texels are the decoded ones, stored as RGBA8 */
    lv.texels = (uint64_t)p->tex_w * p->tex_h;
    lv.prims = asp_alloc(ctx, sizeof *lv.prims);
    int rc = lv.prims ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory");
    if (!rc)
        rc = asp_image_init(&lv.atlas, p->tex_w, p->tex_h, err);
    if (!rc && src->normal_atlas.width)
        rc = asp_image_init(&lv.normal_atlas, p->tex_w, p->tex_h, err);
    if (rc) {
        asp_dps_level_release(&lv, ctx);
        return rc;
    }
    lv.prims[0] = *p;
    lv.prims[0].tex_x = lv.prims[0].tex_y = 0;
    lv.prims[0].neighbour_first = lv.prims[0].neighbour_count = 0;
    copy_rect(&src->atlas, p, &lv.atlas);
    if (src->normal_atlas.width)
        copy_rect(&src->normal_atlas, p, &lv.normal_atlas);
    *out = lv;
    return 0;
}
