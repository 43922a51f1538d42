/*
 * The .dps file (issue 4, docs/cli/build.md): several levels of domain
 * primitives (journal section 3) with their neighbour lists (section 4) and
 * texture atlases, the build parameters and the source name. Versioned,
 * little-endian, CRC-32 trailer; the reader trusts no count it has not checked.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "prim/bc3.h"
#include "prim/internal.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

#define DPS_MAGIC "ASPDPS\r\n"
/*
 * Version 2 appends the source point set's frame (asp_frame, 32 bytes) to the
 * header, so a .dps is framed exactly as its points (issue 12); version 1
 * files still load with radius 0 ("not known"). Version 3 (issue 18) stores
 * the build options versions 1-2 did not (in the parameters' spare bytes), a
 * level's strict flag (its spare u32) and appends to the level header the
 * links to the next coarser level (16 bytes: count, flag), their lists after
 * the neighbours; versions 1 and 2 load without links.
 */
enum { DPS_VERSION = 3, DPS_HEADER = 96, DPS_HEADER_V1 = 64, DPS_PARAMS = 128, DPS_LEVEL_V2 = 96, DPS_LEVEL = 112,
       DPS_PRIM = 124, DPS_SIDE = 16384 };

/* ---- writing: explicit little-endian bytes, so the format does not depend on the host ---- */

/* Bytes of one stored atlas: RGBA8 texels, or BC3 blocks when the level is compressed. */
static uint64_t atlas_bytes(const asp_dps_level *lv)
{
    return lv->atlas_bc3 ? ASP__BC3_BYTES(lv->atlas.width, lv->atlas.height)
                         : 4 * (uint64_t)lv->atlas.width * lv->atlas.height;
}

static uint64_t level_bytes(const asp_dps_level *lv)
{
    uint64_t atlas = atlas_bytes(lv);
    uint64_t links = lv->link_first ? 4 * ((uint64_t)lv->prim_count + 1) + 8 * (uint64_t)lv->link_total : 0;
    return DPS_LEVEL + DPS_PRIM * (uint64_t)lv->prim_count + 4 * (uint64_t)lv->neighbour_total + links + atlas +
           (lv->normal_atlas.width ? atlas : 0);
}

static void put_prim(asp__crc_writer *w, const asp_prim *p)
{
    for (int k = 0; k < 3; k++)
        asp__put_f64(w, p->centre[k]);
    for (int k = 0; k < 3; k++)
        asp__put_f32(w, p->axis_u[k]);
    for (int k = 0; k < 3; k++)
        asp__put_f32(w, p->axis_v[k]);
    for (int k = 0; k < 3; k++)
        asp__put_f32(w, p->normal[k]);
    const float f[6] = {p->half_u, p->half_v, p->texel, p->error, p->error_norm, p->curvature};
    for (int k = 0; k < 6; k++)
        asp__put_f32(w, f[k]);
    const uint32_t u[10] = {p->points, p->basis,  p->merged, p->flags,           p->tex_x,
                            p->tex_y,  p->tex_w, p->tex_h,  p->neighbour_first, p->neighbour_count};
    for (int k = 0; k < 10; k++)
        asp__put_u32(w, u[k]);
}

/* The whole file parsed back before it replaces the target (issue #13): no command writes what build, render and info refuse. */
static int dps_reads_back(const char *tmp, void *user, asp_error *err)
{
    const asp_dps *dps = user;
    asp_dps *back = NULL;
    int rc = asp_dps_load(tmp, &dps->ctx, &back, err);
    asp_dps_destroy(back);
    return rc;
}

int asp_dps_save(const asp_dps *dps, const char *path, asp_error *err)
{
    if (!dps || !path)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_save needs a dps and a path");
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    asp__crc_writer w = {f.fp, 0, 0};
    size_t slen = strnlen(dps->source, sizeof dps->source - 1);
    uint64_t payload = DPS_PARAMS + 4 + slen;
    for (size_t i = 0; i < dps->level_count; i++)
        payload += level_bytes(&dps->levels[i]);
    int normals = dps->level_count && dps->levels[0].normal_atlas.width;
    asp__crc_put(&w, DPS_MAGIC, 8);
    asp__put_u32(&w, DPS_VERSION);
    asp__put_u32(&w, DPS_HEADER);
    asp__put_u64(&w, dps->level_count);
    asp__put_u64(&w, payload);
    asp__put_u64(&w, dps->source_points);
    asp__put_f64(&w, dps->mean_radius);
    asp__put_u32(&w, dps->amg_levels);
    asp__put_u32(&w, normals ? 1u : 0u);
    asp__put_u32(&w, dps->skipped_levels);
    asp__put_u32(&w, (uint32_t)dps->frame.up + 1u); // issue 29: the source's up axis + 1 (0 before: not recorded)
    for (int k = 0; k < 3; k++)
        asp__put_f64(&w, dps->frame.center[k]);
    asp__put_f64(&w, dps->frame.radius);
    /* parameters: 128 bytes */
    const asp_prim_desc *d = &dps->desc;
    asp__put_f64(&w, d->tau);
    asp__put_f64(&w, d->texel_size);
    asp__put_f64(&w, d->width);
    asp__put_f64(&w, d->neighbour_fraction);
    asp__put_f64(&w, d->merge_flatness);
    asp__put_f64(&w, d->merge_angle);
    const uint32_t u[10] = {d->max_texture, (uint32_t)d->method, (uint32_t)d->shape, (uint32_t)d->normalise,
                            (uint32_t)d->unweighted, (uint32_t)d->project_radii, (uint32_t)d->no_extend_color,
                            (uint32_t)d->normal_map, (uint32_t)d->merge, d->padding};
    for (int k = 0; k < 10; k++)
        asp__put_u32(&w, u[k]);
    /* version 3: the options versions 1-2 left out (the 40 spare bytes), so info shows every build option */
    asp__put_f64(&w, d->brightness);
    asp__put_f64(&w, d->enlarge);
    const uint32_t v3[4] = {(uint32_t)d->normalise_color, (uint32_t)d->no_model_colors, (uint32_t)d->strict, 0};
    for (int k = 0; k < 4; k++)
        asp__put_u32(&w, v3[k]);
    uint16_t half[3]; // issue 29: the frame's box (asp_frame_half_encode) in the spare u64; 0 before
    asp_frame_half_encode(&dps->frame, half);
    asp__put_u64(&w, (uint64_t)half[0] | (uint64_t)half[1] << 16 | (uint64_t)half[2] << 32);
    asp__put_u32(&w, (uint32_t)slen);
    asp__crc_put(&w, dps->source, slen);
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        asp__put_u32(&w, lv->level);
        asp__put_u32(&w, lv->basis_count);
        asp__put_u64(&w, lv->prim_count);
        asp__put_u64(&w, lv->neighbour_total);
        asp__put_u32(&w, lv->atlas.width);
        asp__put_u32(&w, lv->atlas.height);
        /* bit 0: a normal atlas follows; bit 1: the atlases are BC3 blocks (issue 27); bit 2: a billboard
           cloud, drawn alpha-tested and opaque (issue 30; older readers refuse the unknown bit) */
        asp__put_u32(&w, (lv->normal_atlas.width ? 1u : 0u) | (lv->atlas_bc3 ? 2u : 0u) | (lv->billboards ? 4u : 0u));
        asp__put_u32(&w, lv->skipped);
        asp__put_u32(&w, lv->degenerate);
        asp__put_u32(&w, lv->capped);
        asp__put_u32(&w, lv->merges);
        asp__put_u32(&w, lv->strict);
        asp__put_u64(&w, lv->texels);
        asp__put_f64(&w, lv->error);
        asp__put_f64(&w, lv->error_norm);
        asp__put_f64(&w, lv->t_basis);
        asp__put_f64(&w, lv->t_construct);
        asp__put_u64(&w, lv->link_first ? lv->link_total : 0);
        asp__put_u32(&w, lv->link_first ? 1u : 0u);
        asp__put_u32(&w, 0);
        for (size_t k = 0; k < lv->prim_count; k++)
            put_prim(&w, &lv->prims[k]);
        for (size_t k = 0; k < lv->neighbour_total; k++)
            asp__put_u32(&w, lv->neighbours[k]);
        if (lv->link_first) {
            for (size_t k = 0; k <= lv->prim_count; k++)
                asp__put_u32(&w, lv->link_first[k]);
            for (size_t k = 0; k < lv->link_total; k++) {
                asp__put_u32(&w, lv->link_parent[k]);
                asp__put_f32(&w, lv->link_weight[k]);
            }
        }
        if (lv->atlas_bc3) {
            asp__crc_put(&w, lv->atlas_bc3, (size_t)atlas_bytes(lv));
            if (lv->normal_atlas.width)
                asp__crc_put(&w, lv->normal_bc3, (size_t)atlas_bytes(lv));
        } else {
            asp__crc_put(&w, lv->atlas.pixels, 4 * (size_t)lv->atlas.width * lv->atlas.height);
            if (lv->normal_atlas.width)
                asp__crc_put(&w, lv->normal_atlas.pixels, 4 * (size_t)lv->atlas.width * lv->atlas.height);
        }
    }
    return asp__byte_commit(&w, &f, path, dps_reads_back, (void *)dps, err);
}

/* ---- reading ---- */

static void get_prim(asp__byte_reader *r, asp_prim *p)
{
    for (int k = 0; k < 3; k++)
        p->centre[k] = asp__get_f64(r);
    for (int k = 0; k < 3; k++)
        p->axis_u[k] = asp__get_f32(r);
    for (int k = 0; k < 3; k++)
        p->axis_v[k] = asp__get_f32(r);
    for (int k = 0; k < 3; k++)
        p->normal[k] = asp__get_f32(r);
    p->half_u = asp__get_f32(r), p->half_v = asp__get_f32(r), p->texel = asp__get_f32(r);
    p->error = asp__get_f32(r), p->error_norm = asp__get_f32(r), p->curvature = asp__get_f32(r);
    p->points = asp__get_u32(r), p->basis = asp__get_u32(r), p->merged = asp__get_u32(r), p->flags = asp__get_u32(r);
    p->tex_x = asp__get_u32(r), p->tex_y = asp__get_u32(r), p->tex_w = asp__get_u32(r), p->tex_h = asp__get_u32(r);
    p->neighbour_first = asp__get_u32(r), p->neighbour_count = asp__get_u32(r);
}

static int prim_finite(const asp_prim *p)
{
    double s = p->centre[0] + p->centre[1] + p->centre[2] + p->half_u + p->half_v + p->texel + p->error +
               p->error_norm + p->curvature;
    for (int k = 0; k < 3; k++)
        s += p->axis_u[k] + p->axis_v[k] + p->normal[k];
    return isfinite(s) && p->half_u >= 0 && p->half_v >= 0 && p->texel > 0;
}

/* Like asp__byte_bad for what concerns the whole file (magic, version, size, checksum): no byte offset. */
static int bad_file(const asp__byte_reader *r, const char *what)
{
    return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': %s", r->path, what);
}

/* The primitives' neighbour lists (journal section 4): sorted within each range, never the primitive itself. */
static int check_neighbours(asp__byte_reader *r, const asp_dps_level *lv, size_t li)
{
    char msg[160];
    for (size_t k = 0; k < lv->prim_count; k++) {
        const asp_prim *p = &lv->prims[k];
        for (size_t q = p->neighbour_first; q < (size_t)p->neighbour_first + p->neighbour_count; q++)
            if (lv->neighbours[q] == k || (q > p->neighbour_first && lv->neighbours[q] <= lv->neighbours[q - 1])) {
                snprintf(msg, sizeof msg, "level %zu, primitive %zu: neighbour %u, expected increasing indices other "
                         "than the primitive's own", li, k, lv->neighbours[q]);
                return asp__byte_bad(r, msg);
            }
    }
    return 0;
}

/* Level li's links (version 3): ranges that tile 0..link_total, parents increasing, weights in (0, 1]. */
static int read_links(asp__byte_reader *r, asp_dps_level *lv, size_t li, const asp_context *ctx)
{
    char msg[200];
    size_t np = lv->prim_count, nl = lv->link_total;
    lv->link_first = asp_alloc(ctx, (np + 1) * sizeof *lv->link_first);
    lv->link_parent = asp_alloc(ctx, (nl ? nl : 1) * sizeof *lv->link_parent);
    lv->link_weight = asp_alloc(ctx, (nl ? nl : 1) * sizeof *lv->link_weight);
    if (!lv->link_first || !lv->link_parent || !lv->link_weight)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for %zu links", r->path, nl);
    for (size_t k = 0; k <= np; k++) {
        lv->link_first[k] = asp__get_u32(r);
        uint32_t lo = k ? lv->link_first[k - 1] : 0;
        if ((k == 0 && lv->link_first[0] != 0) || lv->link_first[k] < lo || lv->link_first[k] > nl ||
            (k == np && lv->link_first[k] != nl)) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: link range start %u, expected %u..%zu (%s)", li, k,
                     lv->link_first[k], lo, nl, k == np ? "the last equals the link count" : "non-decreasing");
            return asp__byte_bad(r, msg);
        }
    }
    for (size_t q = 0; q < nl; q++)
        lv->link_parent[q] = asp__get_u32(r), lv->link_weight[q] = asp__get_f32(r);
    for (size_t k = 0; k < np; k++)
        for (size_t q = lv->link_first[k]; q < lv->link_first[k + 1]; q++)
            if (!(lv->link_weight[q] > 0 && lv->link_weight[q] <= 1) ||
                (q > lv->link_first[k] && lv->link_parent[q] <= lv->link_parent[q - 1])) {
                snprintf(msg, sizeof msg, "level %zu, primitive %zu: link to %u with weight %g, expected parents "
                         "increasing and a weight in (0, 1]", li, k, lv->link_parent[q], lv->link_weight[q]);
                return asp__byte_bad(r, msg);
            }
    return 0;
}

static int read_level(asp__byte_reader *r, const asp_dps *dps, uint32_t version, size_t li, asp_dps_level *lv,
                      const asp_context *ctx)
{
    char msg[200];
    const size_t hsize = version >= 3 ? DPS_LEVEL : DPS_LEVEL_V2;
    if (asp__byte_left(r) < hsize) {
        snprintf(msg, sizeof msg, "level %zu: truncated level header (%zu bytes needed, %zu left)", li, hsize,
                 asp__byte_left(r));
        return asp__byte_bad(r, msg);
    }
    lv->level = asp__get_u32(r);
    lv->basis_count = asp__get_u32(r);
    uint64_t np = asp__get_u64(r), nn = asp__get_u64(r);
    uint32_t aw = asp__get_u32(r), ah = asp__get_u32(r), aflags = asp__get_u32(r);
    const uint32_t has_n = aflags & 1u, bc3 = (aflags >> 1) & 1u;
    lv->billboards = (aflags >> 2) & 1u;
    lv->skipped = asp__get_u32(r), lv->degenerate = asp__get_u32(r);
    lv->capped = asp__get_u32(r), lv->merges = asp__get_u32(r);
    uint32_t strict = asp__get_u32(r); /* spare (0) before version 3 */
    lv->texels = asp__get_u64(r);
    lv->error = asp__get_f64(r), lv->error_norm = asp__get_f64(r);
    lv->t_basis = asp__get_f64(r), lv->t_construct = asp__get_f64(r);
    uint64_t nlinks = 0;
    uint32_t has_links = 0;
    if (version >= 3) {
        nlinks = asp__get_u64(r);
        has_links = asp__get_u32(r);
        (void)asp__get_u32(r);
    }
    if (strict > 1 || has_links > 1 || (!has_links && nlinks) || (has_links && li + 1 == dps->level_count)) {
        snprintf(msg, sizeof msg, "level %zu: strict flag %u, link flag %u with %llu links, expected flags 0 or 1, "
                 "no links when the flag is 0 and none on the coarsest level", li, strict, has_links,
                 (unsigned long long)nlinks);
        return asp__byte_bad(r, msg);
    }
    lv->strict = strict;
    // issue #31: a NaN in a level's errors or timings (checksum fixed up) reached export's glTF
    if (!(isfinite(lv->error) && isfinite(lv->error_norm) && isfinite(lv->t_basis) && isfinite(lv->t_construct))) {
        snprintf(msg, sizeof msg, "level %zu: error %g, relative error %g, times %g and %g s, expected finite values", li,
                 lv->error, lv->error_norm, lv->t_basis, lv->t_construct);
        return asp__byte_bad(r, msg);
    }
    /* levels are stored finest first without duplicates (asp_prim_build) */
    /* thresholded then strict levels of one AMG level may sit side by side (build --domains both) */
    const uint32_t lo = li ? dps->levels[li - 1].level + !(lv->strict && !dps->levels[li - 1].strict) : 0;
    if (lv->level < lo || lv->level >= dps->amg_levels) {
        snprintf(msg, sizeof msg, "level %zu: AMG level %u, expected %u..%u (increasing, below the level count)", li,
                 lv->level, lo, dps->amg_levels - 1);
        return asp__byte_bad(r, msg);
    }
    /* the counts must fit the bytes left before anything is allocated */
    const size_t avail = asp__byte_left(r);
    if (np == 0 || np > avail / DPS_PRIM) {
        snprintf(msg, sizeof msg, "level %zu: primitive count %llu, expected 1..%zu (%d bytes each, %zu bytes left)",
                 li, (unsigned long long)np, avail / DPS_PRIM, DPS_PRIM, avail);
        return asp__byte_bad(r, msg);
    }
    const size_t after_prims = avail - (size_t)np * DPS_PRIM;
    if (nn > after_prims / 4) {
        snprintf(msg, sizeof msg, "level %zu: neighbour count %llu, expected at most %zu (4 bytes each, %zu bytes "
                 "left after the primitives)", li, (unsigned long long)nn, after_prims / 4, after_prims);
        return asp__byte_bad(r, msg);
    }
    if (aw == 0 || ah == 0 || aw > DPS_SIDE || ah > DPS_SIDE || aflags > 7 || (bc3 && (aw % 4 || ah % 4))) {
        snprintf(msg, sizeof msg, "level %zu: %ux%u atlas with flags %u, expected sides 1..%d (multiples of 4 when "
                 "BC3) and flags 0..7 (1 normal atlas, 2 BC3 blocks, 4 billboards)", li, aw, ah, aflags, DPS_SIDE);
        return asp__byte_bad(r, msg);
    }
    const size_t after_lists = after_prims - (size_t)nn * 4,
                 atlas = bc3 ? (size_t)ASP__BC3_BYTES(aw, ah) : 4 * (size_t)aw * ah;
    if (has_links && (after_lists < 4 * ((size_t)np + 1) || nlinks > (after_lists - 4 * ((size_t)np + 1)) / 8)) {
        snprintf(msg, sizeof msg, "level %zu: %llu links of %llu primitives, expected them to fit the %zu bytes left "
                 "after the neighbours", li, (unsigned long long)nlinks, (unsigned long long)np, after_lists);
        return asp__byte_bad(r, msg);
    }
    const size_t after_nbrs = after_lists - (has_links ? 4 * ((size_t)np + 1) + 8 * (size_t)nlinks : 0);
    if (atlas * (1 + has_n) > after_nbrs) {
        snprintf(msg, sizeof msg, "level %zu: truncated: %ux%u atlas%s of %zu bytes, expected at most the %zu "
                 "bytes left after the neighbours", li, aw, ah, has_n ? "es (colour and normal)" : "",
                 atlas * (1 + has_n), after_nbrs);
        return asp__byte_bad(r, msg);
    }
    lv->prims = asp_calloc(ctx, (size_t)np, sizeof *lv->prims); /* zeroed padding: records compare with memcmp */
    lv->neighbours = asp_alloc(ctx, (size_t)(nn ? nn : 1) * sizeof *lv->neighbours);
    if (!lv->prims || !lv->neighbours)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for %llu primitives", r->path,
                             (unsigned long long)np);
    lv->prim_count = (size_t)np;
    lv->neighbour_total = (size_t)nn;
    uint64_t texels = 0;
    for (size_t k = 0; k < np; k++) {
        asp_prim *p = &lv->prims[k];
        get_prim(r, p);
        if (!prim_finite(p)) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: non-finite or negative geometry", li, k);
            return asp__byte_bad(r, msg);
        }
        if (p->tex_w == 0 || p->tex_h == 0 || p->tex_x > aw || p->tex_w > aw - p->tex_x || p->tex_y > ah ||
            p->tex_h > ah - p->tex_y) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: texture %u+%u x %u+%u outside the %ux%u atlas", li,
                     k, p->tex_x, p->tex_w, p->tex_y, p->tex_h, aw, ah);
            return asp__byte_bad(r, msg);
        }
        if ((uint64_t)p->neighbour_first + p->neighbour_count > nn) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: neighbours %u+%u beyond the %llu stored", li, k,
                     p->neighbour_first, p->neighbour_count, (unsigned long long)nn);
            return asp__byte_bad(r, msg);
        }
        if (p->basis >= lv->basis_count) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: basis function %u, expected below %u", li, k,
                     p->basis, lv->basis_count);
            return asp__byte_bad(r, msg);
        }
        texels += (uint64_t)p->tex_w * p->tex_h;
    }
    for (size_t k = 0; k < nn; k++) {
        lv->neighbours[k] = asp__get_u32(r);
        if (lv->neighbours[k] >= np) {
            snprintf(msg, sizeof msg, "level %zu: neighbour entry %zu is %u, expected below %llu", li, k,
                     lv->neighbours[k], (unsigned long long)np);
            return asp__byte_bad(r, msg);
        }
    }
    int rc = check_neighbours(r, lv, li);
    if (rc)
        return rc;
    lv->link_total = (size_t)nlinks;
    if (has_links && (rc = read_links(r, lv, li, ctx)) != 0)
        return rc;
    if (texels != lv->texels) {
        snprintf(msg, sizeof msg, "level %zu: %llu texels recorded, the rectangles hold %llu", li,
                 (unsigned long long)lv->texels, (unsigned long long)texels);
        return asp__byte_bad(r, msg);
    }
    rc = asp_image_init(&lv->atlas, aw, ah, r->err);
    if (!rc && has_n)
        rc = asp_image_init(&lv->normal_atlas, aw, ah, r->err);
    if (rc)
        return rc;
    if (bc3) { /* keep the blocks (what is uploaded) and decode them once for the CPU paths */
        lv->atlas_bc3 = asp_alloc(ctx, atlas);
        lv->normal_bc3 = has_n ? asp_alloc(ctx, atlas) : NULL;
        if (!lv->atlas_bc3 || (has_n && !lv->normal_bc3))
            return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for a %ux%u BC3 atlas",
                                 r->path, aw, ah);
        memcpy(lv->atlas_bc3, r->buf + r->at, atlas);
        asp__bc3_decode(lv->atlas_bc3, (int)aw, (int)ah, lv->atlas.pixels);
        r->at += atlas;
        if (has_n) {
            memcpy(lv->normal_bc3, r->buf + r->at, atlas);
            asp__bc3_decode(lv->normal_bc3, (int)aw, (int)ah, lv->normal_atlas.pixels);
            r->at += atlas;
        }
        return 0;
    }
    memcpy(lv->atlas.pixels, r->buf + r->at, atlas);
    r->at += atlas;
    if (has_n) {
        memcpy(lv->normal_atlas.pixels, r->buf + r->at, atlas);
        r->at += atlas;
    }
    return 0;
}

/* The build parameters (128 bytes) and the source name. */
static int read_params(asp__byte_reader *r, asp_dps *dps, uint32_t version)
{
    char msg[200];
    asp_prim_desc *d = &dps->desc;
    d->tau = asp__get_f64(r), d->texel_size = asp__get_f64(r), d->width = asp__get_f64(r);
    d->neighbour_fraction = asp__get_f64(r), d->merge_flatness = asp__get_f64(r), d->merge_angle = asp__get_f64(r);
    d->max_texture = asp__get_u32(r);
    const uint32_t method = asp__get_u32(r), shape = asp__get_u32(r), normalise = asp__get_u32(r);
    d->unweighted = (int)asp__get_u32(r), d->project_radii = (int)asp__get_u32(r);
    d->no_extend_color = (int)asp__get_u32(r);
    d->normal_map = (int)asp__get_u32(r), d->merge = (int)asp__get_u32(r), d->padding = asp__get_u32(r);
    /* enum values outside their range would index name tables (asp_prim_method_name) */
    if (method > ASP_PRIM_RADIAL || shape > ASP_PRIM_GAUSSIAN || normalise > ASP_PRIM_NORM_GE1) {
        snprintf(msg, sizeof msg, "parameters: method %u, shape %u, normalisation %u, expected at most %d, %d, %d",
                 method, shape, normalise, ASP_PRIM_RADIAL, ASP_PRIM_GAUSSIAN, ASP_PRIM_NORM_GE1);
        return asp__byte_bad(r, msg);
    }
    d->method = (asp_prim_method)method;
    d->shape = (asp_prim_shape)shape;
    d->normalise = (asp_prim_normalise)normalise;
    if (!isfinite(d->tau + d->texel_size + d->width + d->neighbour_fraction + d->merge_flatness + d->merge_angle))
        return asp__byte_bad(r, "parameters: a non-finite value, expected finite resolved options");
    if (version >= 3) {
        d->brightness = asp__get_f64(r), d->enlarge = asp__get_f64(r);
        uint32_t nc = asp__get_u32(r), nm = asp__get_u32(r), st = asp__get_u32(r);
        /* strict is a domain set: 0 thresholded, 1 strict, 2 both (each level twice) */
        if (!(d->brightness >= -1 && d->brightness <= 1) || !(d->enlarge >= 0 && d->enlarge <= 1000) || nc > 1 ||
            nm > 1 || st > 2) {
            snprintf(msg, sizeof msg, "parameters: brightness %g, enlarge %g, flags %u %u, domain set %u, expected "
                     "brightness in [-1, 1], enlarge in [0, 1000], flags 0 or 1 and a domain set 0..2", d->brightness,
                     d->enlarge, nc, nm, st);
            return asp__byte_bad(r, msg);
        }
        d->normalise_color = (int)nc, d->no_model_colors = (int)nm, d->strict = (int)st;
        r->at += DPS_PARAMS - 88 - 28;
        // issue 29: the frame's box sides in the last 8 bytes (0: written before them, "not known")
        uint64_t q = 0;
        for (int b = 0; b < 8; b++)
            q |= (uint64_t)r->buf[r->at - 8 + b] << 8 * b;
        asp_frame_half_decode(&dps->frame, (const uint16_t[3]){(uint16_t)q, (uint16_t)(q >> 16), (uint16_t)(q >> 32)});
    } else {
        r->at += DPS_PARAMS - 88;
    }
    uint32_t slen = asp__get_u32(r);
    if (slen >= sizeof dps->source || slen > asp__byte_left(r)) {
        snprintf(msg, sizeof msg, "source name of %u bytes, expected below %zu and within the %zu bytes left", slen,
                 sizeof dps->source, asp__byte_left(r));
        return asp__byte_bad(r, msg);
    }
    memcpy(dps->source, r->buf + r->at, slen);
    dps->source[slen] = 0;
    r->at += slen;
    return 0;
}

static int parse(asp__byte_reader *r, const asp_context *ctx, asp_dps *dps)
{
    char msg[200];
    const size_t total = r->size;
    if (total < 8 || memcmp(r->buf, DPS_MAGIC, 8) != 0)
        return bad_file(r, total >= 6 && memcmp(r->buf, DPS_MAGIC, 6) == 0
                          ? "unsupported variant of the magic 'ASPDPS'"
                          : "not a .dps file (expected the magic 'ASPDPS')");
    if (total < DPS_HEADER_V1 + 4) {
        snprintf(msg, sizeof msg, "truncated header (%zu bytes, expected at least %d)", total, DPS_HEADER_V1 + 4);
        return bad_file(r, msg);
    }
    r->at += 8;
    uint32_t version = asp__get_u32(r), hsize = asp__get_u32(r);
    if (!((version == 2 || version == DPS_VERSION) && hsize == DPS_HEADER) && !(version == 1 && hsize == DPS_HEADER_V1)) {
        snprintf(msg, sizeof msg, "unsupported version %u (header %u bytes), expected version 1 (64 bytes), 2 or %d "
                 "(%d bytes)", version, hsize, DPS_VERSION, DPS_HEADER);
        return bad_file(r, msg);
    }
    if (total < (size_t)hsize + 4) {
        snprintf(msg, sizeof msg, "truncated header (%zu bytes, expected at least %u)", total, hsize + 4);
        return bad_file(r, msg);
    }
    uint64_t nl = asp__get_u64(r), payload = asp__get_u64(r);
    dps->source_points = asp__get_u64(r);
    dps->mean_radius = asp__get_f64(r);
    dps->amg_levels = asp__get_u32(r);
    (void)asp__get_u32(r);
    dps->skipped_levels = asp__get_u32(r);
    const uint32_t up = asp__get_u32(r); // the up axis + 1; 0: written before it was recorded (issue 29)
    if (up > (uint32_t)ASP_UP_NEG_X + 1u) {
        r->at -= 4;
        snprintf(msg, sizeof msg, "up axis code %u, expected 0 (not recorded) or 1..%u", up, (unsigned)ASP_UP_NEG_X + 1u);
        return asp__byte_bad(r, msg);
    }
    dps->frame.up = up ? (asp_up_axis)(up - 1u) : ASP_UP_Y;
    const size_t frame_at = r->at;
    if (version >= 2) {
        for (int k = 0; k < 3; k++)
            dps->frame.center[k] = asp__get_f64(r);
        dps->frame.radius = asp__get_f64(r);
    } /* else radius 0 ("not known"): a version-1 file's primitives do not bound the source points */
    const size_t have = total - hsize - 4;
    if (payload != have) {
        snprintf(msg, sizeof msg, "%s: header says %llu payload bytes, the file has %zu",
                 payload > have ? "truncated" : "trailing bytes", (unsigned long long)payload, have);
        return bad_file(r, msg);
    }
    /* the CRC-32 trailer covers everything before it, header included */
    const uint8_t *end = r->buf + total - 4;
    uint32_t stored = (uint32_t)end[0] | (uint32_t)end[1] << 8 | (uint32_t)end[2] << 16 | (uint32_t)end[3] << 24;
    uint32_t crc = asp__crc32(0, r->buf, total - 4);
    if (crc != stored) {
        snprintf(msg, sizeof msg, "checksum mismatch (stored 0x%08x, computed 0x%08x): the file is damaged", stored,
                 crc);
        return bad_file(r, msg);
    }
    r->size = total - 4; /* the trailer is not payload */
    const asp_frame *fr = &dps->frame;
    if (!(isfinite(fr->center[0]) && isfinite(fr->center[1]) && isfinite(fr->center[2]) && isfinite(fr->radius) &&
          fr->radius >= 0)) {
        r->at = frame_at;
        snprintf(msg, sizeof msg, "frame: centre (%g, %g, %g), radius %g, expected finite values and a radius >= 0",
                 fr->center[0], fr->center[1], fr->center[2], fr->radius);
        return asp__byte_bad(r, msg);
    }
    if (nl == 0 || nl > 64 || dps->amg_levels == 0 || !(dps->mean_radius > 0) || !isfinite(dps->mean_radius)) {
        r->at = 16;
        snprintf(msg, sizeof msg, "level count %llu of a %u-level decomposition, mean radius %g: expected 1..64 "
                 "levels, at least one AMG level and a finite radius above 0",
                 (unsigned long long)nl, dps->amg_levels, dps->mean_radius);
        return asp__byte_bad(r, msg);
    }
    const uint64_t lhead = version >= 3 ? DPS_LEVEL : DPS_LEVEL_V2;
    if (asp__byte_left(r) < DPS_PARAMS + 4 + (size_t)nl * lhead) {
        snprintf(msg, sizeof msg, "truncated: %llu levels need at least %llu payload bytes, the file has %zu",
                 (unsigned long long)nl, (unsigned long long)(DPS_PARAMS + 4 + nl * lhead), asp__byte_left(r));
        return asp__byte_bad(r, msg);
    }
    int rc = read_params(r, dps, version);
    if (rc)
        return rc;
    dps->levels = asp_calloc(ctx, (size_t)nl, sizeof *dps->levels);
    if (!dps->levels)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for %llu levels", r->path,
                             (unsigned long long)nl);
    dps->level_count = (size_t)nl; /* read_level checks the coarsest has no links */
    for (size_t i = 0; i < nl; i++)
        if ((rc = read_level(r, dps, version, i, &dps->levels[i], ctx)) != 0)
            return rc;
    /* a link names a primitive of the next level, known only now */
    for (size_t i = 0; i + 1 < nl; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        for (size_t q = 0; q < lv->link_total; q++)
            if (lv->link_parent[q] >= dps->levels[i + 1].prim_count) {
                snprintf(msg, sizeof msg, "level %zu: link %zu names primitive %u of level %zu, expected below %zu",
                         i, q, lv->link_parent[q], i + 1, dps->levels[i + 1].prim_count);
                return asp__byte_bad(r, msg);
            }
    }
    if (r->at != r->size) {
        snprintf(msg, sizeof msg, "%zu unexpected bytes after the last level", asp__byte_left(r));
        return asp__byte_bad(r, msg);
    }
    return 0;
}

int asp_dps_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_dps **out,
                        asp_error *err)
{
    static const uint8_t empty[1];
    if (!out)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_load_memory needs an output");
    asp_dps *dps = asp_calloc(ctx, 1, sizeof *dps);
    const char *nm = name ? name : "<memory>";
    if (!dps)
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory", nm);
    dps->ctx = ctx ? *ctx : (asp_context){0};
    const uint8_t *b = data ? data : empty;
    asp__byte_reader r = {b, data ? size : 0, 0, nm, err};
    int rc = parse(&r, ctx, dps);
    if (rc) {
        asp_dps_destroy(dps);
        return rc;
    }
    *out = dps;
    return 0;
}

int asp_dps_load(const char *path, const asp_context *ctx, asp_dps **out, asp_error *err)
{
    if (!path || !out)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_load needs a path and an output");
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = asp__byte_slurp(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    rc = asp_dps_load_memory(buf, size, path, ctx, out, err);
    asp_free(ctx, buf);
    return rc;
}

int asp_dps_source_find(const asp_dps *dps, const char *dps_path, char *out, size_t cap, asp_file_type *type,
                        asp_error *err)
{
    ASP_ASSERT(dps && dps_path && out && cap > 0);
    const char *src = dps->source;
    if (!src[0])
        return asp_error_set(err, ASP_EUNSUPPORTED, "'%s' names no source file", dps_path);
    char alt[4096] = "";
    const char *slash = strrchr(dps_path, '/');
    if (src[0] != '/' && slash)
        snprintf(alt, sizeof alt, "%.*s/%s", (int)(slash - dps_path), dps_path, src);
    const char *tries[2] = {src, alt};
    asp_error first = {0, ""};
    for (int t = 0; t < 2; t++) {
        asp_file_type ft;
        asp_error e = {0, ""};
        if (!tries[t][0] || asp_file_recognise(tries[t], &ft, &e) != 0) {
            if (!first.code && tries[t][0])
                first = e;
            continue;
        }
        if (strlen(tries[t]) >= cap)
            return asp_error_set(err, ASP_EINVAL, "source '%s' of '%s' is longer than %zu bytes", tries[t], dps_path,
                                 cap - 1);
        snprintf(out, cap, "%s", tries[t]);
        if (type)
            *type = ft;
        return 0;
    }
    if (err)
        *err = first;
    return first.code ? first.code : ASP_EIO;
}

/* One level, no mipmaps: the renderer allocates the atlases so (glTextureStorage2D with 1 level). */
static size_t atlas_gpu_bytes(const asp_dps_level *lv, const asp_image *img)
{
    return lv->atlas_bc3 ? (size_t)ASP__BC3_BYTES(img->width, img->height) : (size_t)img->width * img->height * 4;
}

size_t asp_dps_level_gpu_bytes(const asp_dps_level *level, asp_mesh_bytes *out)
{
    asp_mesh_bytes b;
    b.vertex = level->prim_count * 4 * (12 + 12 + 8);
    b.index = level->prim_count * 6 * 4;
    b.texture = atlas_gpu_bytes(level, &level->atlas) +
                (level->normal_atlas.width ? atlas_gpu_bytes(level, &level->normal_atlas) : 0);
    b.total = b.vertex + b.index + b.texture;
    if (out)
        *out = b;
    return b.total;
}

void asp_dps_level_name(const asp_dps *dps, size_t index, char name[16])
{
    uint32_t top = dps->amg_levels ? dps->amg_levels - 1 : 0;
    uint32_t level = dps->levels[index].level;
    if (level >= top)
        snprintf(name, 16, "L");
    else
        snprintf(name, 16, "L-%u", top - level);
}

size_t asp_dps_summarize(const asp_dps *dps, asp_dps_summary *rows, size_t capacity)
{
    for (size_t i = 0; i < dps->level_count && i < capacity; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        asp_dps_summary *s = &rows[i];
        memset(s, 0, sizeof *s);
        s->level = lv->level;
        asp_dps_level_name(dps, i, s->name);
        s->primitives = lv->prim_count;
        s->texels = lv->texels;
        s->error = lv->error, s->error_norm = lv->error_norm;
        s->t_basis = lv->t_basis, s->t_construct = lv->t_construct;
        s->skipped = lv->skipped, s->degenerate = lv->degenerate, s->capped = lv->capped, s->merges = lv->merges;
        s->atlas_width = lv->atlas.width, s->atlas_height = lv->atlas.height;
        s->neighbour_pairs = lv->neighbour_total / 2;
        s->normal_map = lv->normal_atlas.width > 0;
        s->compressed = lv->atlas_bc3 != NULL;
    }
    return dps->level_count;
}

int asp_dps_level_parse(const asp_dps *dps, const char *text, size_t *index, asp_error *err)
{
    char list[160] = "";
    size_t len = 0;
    for (size_t i = 0; i < dps->level_count; i++) {
        char name[16], number[16];
        asp_dps_level_name(dps, i, name);
        snprintf(number, sizeof number, "%u", dps->levels[i].level);
        if (strcmp(text, name) == 0 || strcmp(text, number) == 0) {
            *index = i;
            return 0;
        }
        if (len < sizeof list)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", name);
    }
    return asp_error_set(err, ASP_EINVAL, "no level '%s' (the file holds %s)", text, list);
}
