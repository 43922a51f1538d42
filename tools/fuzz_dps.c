/*
 * libFuzzer target for the .dps reader (asp_dps_load_memory): arbitrary bytes
 * must give a clean error or domain primitives whose invariants hold (texture
 * rectangles inside the atlas, thesis 3.3; neighbour lists inside the level,
 * journal section 4), never a crash, leak or huge allocation (STYLE.md 11).
 *   ./fuzz_dps -max_total_time=300 -rss_limit_mb=2048 corpus
 * Seed the corpus with small built files (amgsplat build). Each input is also
 * tried with its payload size and CRC-32 trailer patched, so mutations reach
 * the parser behind the checksum.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "fuzz_support.h"

enum { PAYLOAD_AT = 24 }; /* header byte of the payload size */

static void check_level(const asp_dps *d, size_t i, size_t size)
{
    const asp_dps_level *lv = &d->levels[i];
    const uint32_t aw = lv->atlas.width, ah = lv->atlas.height;
    if (lv->level >= d->amg_levels || (i > 0 && lv->level <= d->levels[i - 1].level))
        abort();
    if (lv->prim_count < 1 || !lv->prims || !lv->neighbours || aw < 1 || ah < 1 || !lv->atlas.pixels)
        abort();
    /* the atlases come from the file, so they cannot be larger than it */
    if (4 * (uint64_t)aw * ah * (lv->normal_atlas.width ? 2 : 1) > size)
        abort();
    if (lv->normal_atlas.width && (lv->normal_atlas.width != aw || lv->normal_atlas.height != ah ||
                                   !lv->normal_atlas.pixels))
        abort();
    uint64_t texels = 0;
    for (size_t k = 0; k < lv->prim_count; k++) {
        const asp_prim *p = &lv->prims[k];
        if (p->tex_w < 1 || p->tex_h < 1 || (uint64_t)p->tex_x + p->tex_w > aw || (uint64_t)p->tex_y + p->tex_h > ah)
            abort();
        if ((uint64_t)p->neighbour_first + p->neighbour_count > lv->neighbour_total || p->basis >= lv->basis_count)
            abort();
        if (!(p->texel > 0) || !(p->half_u >= 0) || !(p->half_v >= 0) || !isfinite(p->centre[0]) ||
            !isfinite(p->centre[1]) || !isfinite(p->centre[2]))
            abort();
        for (size_t q = p->neighbour_first; q < (size_t)p->neighbour_first + p->neighbour_count; q++)
            if (lv->neighbours[q] >= lv->prim_count || lv->neighbours[q] == k ||
                (q > p->neighbour_first && lv->neighbours[q] <= lv->neighbours[q - 1]))
                abort();
        texels += (uint64_t)p->tex_w * p->tex_h;
    }
    for (size_t q = 0; q < lv->neighbour_total; q++)
        if (lv->neighbours[q] >= lv->prim_count)
            abort();
    if (texels != lv->texels)
        abort();
    /* touch the first and last texel of every atlas so ASan sees the whole allocation */
    volatile uint8_t t = lv->atlas.pixels[0];
    t = lv->atlas.pixels[4 * (size_t)aw * ah - 1];
    if (lv->normal_atlas.width)
        t = lv->normal_atlas.pixels[4 * (size_t)aw * ah - 1];
    (void)t;
}

static void one(const uint8_t *data, size_t size)
{
    fuzz_budget b; /* sees only the context's allocations: the atlases use asp_image_init's own malloc */
    asp_context ctx = fuzz_budget_context(&b, size, "fuzz_dps");
    asp_dps *d = NULL;
    asp_error err = {0};
    int rc = asp_dps_load_memory(data, size, "fuzz.dps", &ctx, &d, &err);
    if (rc == 0) {
        if (!d || d->level_count < 1 || d->level_count > 64 || !d->levels || !(d->mean_radius > 0) ||
            memchr(d->source, 0, sizeof d->source) == NULL)
            abort();
        /* the recorded frame was validated: finite, radius >= 0 */
        if (!(isfinite(d->frame.center[0]) && isfinite(d->frame.center[1]) && isfinite(d->frame.center[2]) &&
              isfinite(d->frame.radius) && d->frame.radius >= 0))
            abort();
        for (size_t i = 0; i < d->level_count; i++)
            check_level(d, i, size);
        asp_dps_summary rows[64];
        size_t shown = asp_dps_summarize(d, rows, sizeof rows / sizeof rows[0]);
        if (shown != d->level_count)
            abort();
        shown = shown < 64 ? shown : 64;
        for (size_t i = 0; i < shown; i++)
            if (rows[i].name[0] == '\0' || rows[i].primitives != d->levels[i].prim_count)
                abort();
        if (asp_prim_method_name(d->desc.method)[0] == '?' || asp_prim_shape_name(d->desc.shape)[0] == '?' ||
            asp_prim_normalise_name(d->desc.normalise)[0] == '?')
            abort();
        asp_dps_destroy(d);
        return;
    }
    /* a failure leaves the output alone and explains itself, naming the file */
    if (d || err.msg[0] == '\0' || !strstr(err.msg, "fuzz.dps") || rc != err.code)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_with_fixed_trailer(data, size, PAYLOAD_AT, one);
    return 0;
}
