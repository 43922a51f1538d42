/*
 * Texture atlas of one level (issue 4: all primitive textures in one image,
 * padded against bleeding): shelf packing by decreasing height into a
 * power-of-two width, and clamp-to-edge padding so that linear filtering at a
 * rectangle's border reads the border texel, never a neighbour's texel.
 */
#include <stdlib.h>
#include <string.h>

#include "prim/bc3.h"
#include "prim/internal.h"
#include "util/banned.h"

typedef struct rect_order {
    uint32_t h, idx;
} rect_order;

static int cmp_rect(const void *a, const void *b)
{
    const rect_order *p = a, *q = b;
    if (p->h != q->h)
        return p->h > q->h ? -1 : 1;
    return p->idx < q->idx ? -1 : p->idx > q->idx;
}

/* Shelf packing at width W; returns the height used, or UINT64_MAX when a rectangle is wider than W. */
static uint64_t shelf(const rect_order *ord, const uint32_t *w, size_t n, uint32_t pad, uint64_t W, uint32_t *x,
                      uint32_t *y)
{
    uint64_t cx = 0, cy = 0, shelf_h = 0;
    for (size_t k = 0; k < n; k++) {
        uint32_t i = ord[k].idx;
        uint64_t rw = (uint64_t)w[i] + 2 * (uint64_t)pad, rh = (uint64_t)ord[k].h + 2 * (uint64_t)pad;
        if (rw > W)
            return UINT64_MAX;
        if (cx + rw > W) {
            cy += shelf_h;
            cx = 0;
            shelf_h = 0;
        }
        x[i] = (uint32_t)(cx + pad);
        y[i] = (uint32_t)(cy + pad);
        cx += rw;
        shelf_h = rh > shelf_h ? rh : shelf_h;
        if (cy + shelf_h > UINT32_MAX)
            return UINT64_MAX;
    }
    return cy + shelf_h;
}

int asp__atlas_pack(const uint32_t *w, const uint32_t *h, size_t n, uint32_t pad, uint32_t max_side, uint32_t *x,
                    uint32_t *y, uint32_t *atlas_w, uint32_t *atlas_h, const asp_context *ctx)
{
    rect_order *ord = asp_alloc(ctx, (n ? n : 1) * sizeof *ord);
    if (!ord)
        return -2;
    uint64_t area = 0, widest = 1;
    for (size_t i = 0; i < n; i++) {
        ord[i].h = h[i];
        ord[i].idx = (uint32_t)i;
        area += ((uint64_t)w[i] + 2 * pad) * ((uint64_t)h[i] + 2 * pad);
        widest = (uint64_t)w[i] + 2 * pad > widest ? (uint64_t)w[i] + 2 * pad : widest;
    }
    qsort(ord, n, sizeof *ord, cmp_rect);
    uint64_t W = 64;
    while (W < widest || W * W < area)
        W *= 2;
    int rc = -1;
    for (; W <= max_side; W *= 2) {
        uint64_t H = shelf(ord, w, n, pad, W, x, y);
        if (H == UINT64_MAX)
            continue;
        if (H <= max_side) { /* a wide, low atlas is fine; square-ish comes from starting at sqrt(area) */
            *atlas_w = (uint32_t)W;
            *atlas_h = (uint32_t)(H ? H : 1);
            rc = 0;
            break;
        }
    }
    asp_free(ctx, ord);
    return rc;
}

void asp__atlas_pad(asp_image *img, const asp_prim *prims, size_t n, uint32_t pad)
{
    if (!pad)
        return;
    const size_t W = img->width;
    for (size_t k = 0; k < n; k++) {
        const asp_prim *p = &prims[k];
        long x0 = (long)p->tex_x, y0 = (long)p->tex_y, x1 = x0 + (long)p->tex_w - 1, y1 = y0 + (long)p->tex_h - 1;
        for (long yy = y0 - (long)pad; yy <= y1 + (long)pad; yy++) {
            if (yy < 0 || yy >= (long)img->height)
                continue;
            long sy = yy < y0 ? y0 : yy > y1 ? y1 : yy;
            for (long xx = x0 - (long)pad; xx <= x1 + (long)pad; xx++) {
                if (xx < 0 || xx >= (long)W || (yy >= y0 && yy <= y1 && xx >= x0 && xx <= x1))
                    continue;
                long sx = xx < x0 ? x0 : xx > x1 ? x1 : xx;
                memcpy(&img->pixels[4 * ((size_t)yy * W + (size_t)xx)], &img->pixels[4 * ((size_t)sy * W + (size_t)sx)],
                       4);
            }
        }
    }
}

/* img padded to a multiple of 4 rows (zero texels), encoded to BC3 and decoded back into img. */
static int compress_image(asp_image *img, uint8_t **blocks, const asp_context *ctx, asp_error *err)
{
    const uint32_t W = img->width, H = (img->height + 3) & ~3u;
    asp_image padded = {0, 0, NULL};
    int rc = asp_image_init(&padded, W, H, err);
    if (rc)
        return rc;
    memset(padded.pixels, 0, 4 * (size_t)W * H);
    memcpy(padded.pixels, img->pixels, 4 * (size_t)W * img->height);
    *blocks = asp_alloc(ctx, (size_t)ASP__BC3_BYTES(W, H));
    if (!*blocks) {
        asp_image_release(&padded);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the BC3 blocks of a %ux%u atlas", W, H);
    }
    asp__bc3_encode(padded.pixels, (int)W, (int)H, *blocks);
    asp__bc3_decode(*blocks, (int)W, (int)H, padded.pixels);
    asp_image_release(img);
    *img = padded;
    return 0;
}

int asp_dps_level_compress(asp_dps_level *lv, const asp_context *ctx, asp_error *err)
{
    if (lv->atlas_bc3)
        return 0;
    if (!lv->atlas.pixels || !lv->atlas.width || !lv->atlas.height || lv->atlas.width % 4)
        return asp_error_set(err, ASP_EINVAL, "cannot compress level %u: %ux%u atlas, expected a width that is a "
                             "multiple of 4", lv->level, lv->atlas.width, lv->atlas.height);
    /* work on copies so that lv is unchanged on failure */
    asp_image a = {0, 0, NULL}, n = {0, 0, NULL};
    uint8_t *ab = NULL, *nb = NULL;
    int rc = asp_image_init(&a, lv->atlas.width, lv->atlas.height, err);
    if (!rc && lv->normal_atlas.width)
        rc = asp_image_init(&n, lv->normal_atlas.width, lv->normal_atlas.height, err);
    if (!rc) {
        memcpy(a.pixels, lv->atlas.pixels, 4 * (size_t)a.width * a.height);
        if (n.width)
            memcpy(n.pixels, lv->normal_atlas.pixels, 4 * (size_t)n.width * n.height);
        rc = compress_image(&a, &ab, ctx, err);
    }
    if (!rc && n.width)
        rc = compress_image(&n, &nb, ctx, err);
    if (rc) {
        asp_image_release(&a);
        asp_image_release(&n);
        asp_free(ctx, ab);
        asp_free(ctx, nb);
        return rc;
    }
    asp_image_release(&lv->atlas);
    lv->atlas = a;
    lv->atlas_bc3 = ab;
    if (n.width) {
        asp_image_release(&lv->normal_atlas);
        lv->normal_atlas = n;
        lv->normal_bc3 = nb;
    }
    return 0;
}
