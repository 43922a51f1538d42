/*
 * The .dps file (issue 4, docs/cli/build.md): several levels of domain
 * primitives (journal section 3) with their neighbour lists (section 4) and
 * texture atlases, the build parameters and the source name. Versioned,
 * little-endian, CRC-32 trailer; the reader trusts no count it has not checked.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "prim/internal.h"
#include "util/atomic_file.h"
#include "util/checksum.h"
#include "util/banned.h"

#define DPS_MAGIC "ASPDPS\r\n"
enum { DPS_VERSION = 1, DPS_HEADER = 64, DPS_PARAMS = 128, DPS_LEVEL = 96, DPS_PRIM = 124, DPS_SIDE = 16384 };

/* ---- writing: explicit little-endian bytes, so the format does not depend on the host ---- */

typedef asp__crc_writer writer;

static void put(writer *w, const void *data, size_t len)
{
    asp__crc_put(w, data, len);
}

static void le32(uint8_t *b, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        b[k] = (uint8_t)(v >> (8 * k));
}

static void le64(uint8_t *b, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        b[k] = (uint8_t)(v >> (8 * k));
}

static void put_u32(writer *w, uint32_t v)
{
    uint8_t b[4];
    le32(b, v);
    put(w, b, 4);
}

static void put_u64(writer *w, uint64_t v)
{
    uint8_t b[8];
    le64(b, v);
    put(w, b, 8);
}

static void put_f32(writer *w, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    put_u32(w, u);
}

static void put_f64(writer *w, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put_u64(w, u);
}

static uint64_t level_bytes(const asp_dps_level *lv)
{
    uint64_t atlas = 4 * (uint64_t)lv->atlas.width * lv->atlas.height;
    return DPS_LEVEL + DPS_PRIM * (uint64_t)lv->prim_count + 4 * (uint64_t)lv->neighbour_total + atlas +
           (lv->normal_atlas.width ? atlas : 0);
}

static void put_prim(writer *w, const asp_prim *p)
{
    for (int k = 0; k < 3; k++)
        put_f64(w, p->centre[k]);
    for (int k = 0; k < 3; k++)
        put_f32(w, p->axis_u[k]);
    for (int k = 0; k < 3; k++)
        put_f32(w, p->axis_v[k]);
    for (int k = 0; k < 3; k++)
        put_f32(w, p->normal[k]);
    const float f[6] = {p->half_u, p->half_v, p->texel, p->error, p->error_norm, p->curvature};
    for (int k = 0; k < 6; k++)
        put_f32(w, f[k]);
    const uint32_t u[10] = {p->points, p->basis,  p->merged, p->flags,           p->tex_x,
                            p->tex_y,  p->tex_w, p->tex_h,  p->neighbour_first, p->neighbour_count};
    for (int k = 0; k < 10; k++)
        put_u32(w, u[k]);
}

int asp_dps_save(const asp_dps *dps, const char *path, asp_error *err)
{
    if (!dps || !path)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_save needs a dps and a path");
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    writer w = {f.fp, 0, 0};
    size_t slen = strnlen(dps->source, sizeof dps->source - 1);
    uint64_t payload = DPS_PARAMS + 4 + slen;
    for (size_t i = 0; i < dps->level_count; i++)
        payload += level_bytes(&dps->levels[i]);
    int normals = dps->level_count && dps->levels[0].normal_atlas.width;
    put(&w, DPS_MAGIC, 8);
    put_u32(&w, DPS_VERSION);
    put_u32(&w, DPS_HEADER);
    put_u64(&w, dps->level_count);
    put_u64(&w, payload);
    put_u64(&w, dps->source_points);
    put_f64(&w, dps->mean_radius);
    put_u32(&w, dps->amg_levels);
    put_u32(&w, normals ? 1u : 0u);
    put_u32(&w, dps->skipped_levels);
    put_u32(&w, 0);
    /* parameters: 128 bytes */
    const asp_prim_desc *d = &dps->desc;
    put_f64(&w, d->tau);
    put_f64(&w, d->texel_size);
    put_f64(&w, d->width);
    put_f64(&w, d->neighbour_fraction);
    put_f64(&w, d->merge_flatness);
    put_f64(&w, d->merge_angle);
    const uint32_t u[10] = {d->max_texture, (uint32_t)d->method, (uint32_t)d->shape, (uint32_t)d->normalise,
                            (uint32_t)d->unweighted, (uint32_t)d->project_radii, (uint32_t)d->no_extend_color,
                            (uint32_t)d->normal_map, (uint32_t)d->merge, d->padding};
    for (int k = 0; k < 10; k++)
        put_u32(&w, u[k]);
    for (int k = 0; k < (DPS_PARAMS - 48 - 40) / 8; k++)
        put_u64(&w, 0);
    put_u32(&w, (uint32_t)slen);
    put(&w, dps->source, slen);
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        put_u32(&w, lv->level);
        put_u32(&w, lv->basis_count);
        put_u64(&w, lv->prim_count);
        put_u64(&w, lv->neighbour_total);
        put_u32(&w, lv->atlas.width);
        put_u32(&w, lv->atlas.height);
        put_u32(&w, lv->normal_atlas.width ? 1u : 0u);
        put_u32(&w, lv->skipped);
        put_u32(&w, lv->degenerate);
        put_u32(&w, lv->capped);
        put_u32(&w, lv->merges);
        put_u32(&w, 0);
        put_u64(&w, lv->texels);
        put_f64(&w, lv->error);
        put_f64(&w, lv->error_norm);
        put_f64(&w, lv->t_basis);
        put_f64(&w, lv->t_construct);
        for (size_t k = 0; k < lv->prim_count; k++)
            put_prim(&w, &lv->prims[k]);
        for (size_t k = 0; k < lv->neighbour_total; k++)
            put_u32(&w, lv->neighbours[k]);
        put(&w, lv->atlas.pixels, 4 * (size_t)lv->atlas.width * lv->atlas.height);
        if (lv->normal_atlas.width)
            put(&w, lv->normal_atlas.pixels, 4 * (size_t)lv->atlas.width * lv->atlas.height);
    }
    uint8_t b[4];
    le32(b, w.crc);
    if (!w.failed && fwrite(b, 1, 4, w.fp) != 4)
        w.failed = 1;
    if (w.failed) {
        int e = errno;
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", path, strerror(e));
    }
    return asp__atomic_commit(&f, err);
}

/* ---- reading ---- */

typedef struct reader {
    const uint8_t *base, *p;
    size_t left;
    const char *path;
} reader;

static uint32_t get_u32(reader *r)
{
    uint32_t v = 0;
    for (int k = 0; k < 4; k++)
        v |= (uint32_t)r->p[k] << (8 * k);
    r->p += 4, r->left -= 4;
    return v;
}

static uint64_t get_u64(reader *r)
{
    uint64_t v = 0;
    for (int k = 0; k < 8; k++)
        v |= (uint64_t)r->p[k] << (8 * k);
    r->p += 8, r->left -= 8;
    return v;
}

static float get_f32(reader *r)
{
    uint32_t u = get_u32(r);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static double get_f64(reader *r)
{
    uint64_t u = get_u64(r);
    double f;
    memcpy(&f, &u, 8);
    return f;
}

static void get_prim(reader *r, asp_prim *p)
{
    for (int k = 0; k < 3; k++)
        p->centre[k] = get_f64(r);
    for (int k = 0; k < 3; k++)
        p->axis_u[k] = get_f32(r);
    for (int k = 0; k < 3; k++)
        p->axis_v[k] = get_f32(r);
    for (int k = 0; k < 3; k++)
        p->normal[k] = get_f32(r);
    p->half_u = get_f32(r), p->half_v = get_f32(r), p->texel = get_f32(r);
    p->error = get_f32(r), p->error_norm = get_f32(r), p->curvature = get_f32(r);
    p->points = get_u32(r), p->basis = get_u32(r), p->merged = get_u32(r), p->flags = get_u32(r);
    p->tex_x = get_u32(r), p->tex_y = get_u32(r), p->tex_w = get_u32(r), p->tex_h = get_u32(r);
    p->neighbour_first = get_u32(r), p->neighbour_count = get_u32(r);
}

static int prim_finite(const asp_prim *p)
{
    double s = p->centre[0] + p->centre[1] + p->centre[2] + p->half_u + p->half_v + p->texel + p->error +
               p->error_norm + p->curvature;
    for (int k = 0; k < 3; k++)
        s += p->axis_u[k] + p->axis_v[k] + p->normal[k];
    return isfinite(s) && p->half_u >= 0 && p->half_v >= 0 && p->texel > 0;
}

static int bad(reader *r, asp_error *err, const char *what)
{
    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %s", r->path, what);
}

static int read_level(reader *r, const asp_dps *dps, size_t li, asp_dps_level *lv, const asp_context *ctx,
                      asp_error *err)
{
    char msg[160];
    if (r->left < DPS_LEVEL) {
        snprintf(msg, sizeof msg, "level %zu: truncated level header", li);
        return bad(r, err, msg);
    }
    lv->level = get_u32(r);
    lv->basis_count = get_u32(r);
    uint64_t np = get_u64(r), nn = get_u64(r);
    uint32_t aw = get_u32(r), ah = get_u32(r), has_n = get_u32(r);
    lv->skipped = get_u32(r), lv->degenerate = get_u32(r), lv->capped = get_u32(r), lv->merges = get_u32(r);
    (void)get_u32(r);
    lv->texels = get_u64(r);
    lv->error = get_f64(r), lv->error_norm = get_f64(r), lv->t_basis = get_f64(r), lv->t_construct = get_f64(r);
    if (lv->level >= dps->amg_levels) {
        snprintf(msg, sizeof msg, "level %zu: AMG level %u, expected below %u", li, lv->level, dps->amg_levels);
        return bad(r, err, msg);
    }
    if (np == 0 || aw == 0 || ah == 0 || aw > DPS_SIDE || ah > DPS_SIDE || has_n > 1) {
        snprintf(msg, sizeof msg, "level %zu: %llu primitives in a %ux%u atlas, expected at least one in at most %d",
                 li, (unsigned long long)np, aw, ah, DPS_SIDE);
        return bad(r, err, msg);
    }
    uint64_t atlas = 4 * (uint64_t)aw * ah;
    if (np > r->left / DPS_PRIM || nn > r->left / 4 ||
        np * DPS_PRIM + nn * 4 + atlas * (1 + has_n) > r->left) {
        snprintf(msg, sizeof msg, "level %zu: truncated: %llu primitives, %llu neighbours and the atlas need more "
                 "than the %zu bytes left", li, (unsigned long long)np, (unsigned long long)nn, r->left);
        return bad(r, err, msg);
    }
    lv->prims = asp_calloc(ctx, (size_t)np, sizeof *lv->prims); /* zeroed padding: records compare with memcmp */
    lv->neighbours = asp_alloc(ctx, (size_t)(nn ? nn : 1) * sizeof *lv->neighbours);
    if (!lv->prims || !lv->neighbours)
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", r->path);
    lv->prim_count = (size_t)np;
    lv->neighbour_total = (size_t)nn;
    uint64_t texels = 0;
    for (size_t k = 0; k < np; k++) {
        asp_prim *p = &lv->prims[k];
        get_prim(r, p);
        if (!prim_finite(p)) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: non-finite or negative geometry", li, k);
            return bad(r, err, msg);
        }
        if (p->tex_w == 0 || p->tex_h == 0 || p->tex_x > aw || p->tex_w > aw - p->tex_x || p->tex_y > ah ||
            p->tex_h > ah - p->tex_y) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: texture %u+%u x %u+%u outside the %ux%u atlas", li,
                     k, p->tex_x, p->tex_w, p->tex_y, p->tex_h, aw, ah);
            return bad(r, err, msg);
        }
        if ((uint64_t)p->neighbour_first + p->neighbour_count > nn) {
            snprintf(msg, sizeof msg, "level %zu, primitive %zu: neighbours %u+%u beyond the %llu stored", li, k,
                     p->neighbour_first, p->neighbour_count, (unsigned long long)nn);
            return bad(r, err, msg);
        }
        texels += (uint64_t)p->tex_w * p->tex_h;
    }
    for (size_t k = 0; k < nn; k++) {
        lv->neighbours[k] = get_u32(r);
        if (lv->neighbours[k] >= np) {
            snprintf(msg, sizeof msg, "level %zu: neighbour entry %zu is %u, expected below %llu", li, k,
                     lv->neighbours[k], (unsigned long long)np);
            return bad(r, err, msg);
        }
    }
    if (texels != lv->texels) {
        snprintf(msg, sizeof msg, "level %zu: %llu texels recorded, the rectangles hold %llu", li,
                 (unsigned long long)lv->texels, (unsigned long long)texels);
        return bad(r, err, msg);
    }
    int rc = asp_image_init(&lv->atlas, aw, ah, err);
    if (!rc && has_n)
        rc = asp_image_init(&lv->normal_atlas, aw, ah, err);
    if (rc)
        return rc;
    memcpy(lv->atlas.pixels, r->p, (size_t)atlas);
    r->p += atlas, r->left -= (size_t)atlas;
    if (has_n) {
        memcpy(lv->normal_atlas.pixels, r->p, (size_t)atlas);
        r->p += atlas, r->left -= (size_t)atlas;
    }
    return 0;
}

static int parse(reader *r, const asp_context *ctx, asp_dps *dps, asp_error *err)
{
    char msg[160];
    size_t total = r->left;
    if (total < DPS_HEADER + 4 || memcmp(r->p, DPS_MAGIC, 8) != 0)
        return bad(r, err, total < 8 || memcmp(r->p, DPS_MAGIC, 6) != 0
                               ? "not a .dps file (expected the magic 'ASPDPS')"
                               : "truncated header");
    r->p += 8, r->left -= 8;
    uint32_t version = get_u32(r), hsize = get_u32(r);
    if (version != DPS_VERSION || hsize != DPS_HEADER) {
        snprintf(msg, sizeof msg, "unsupported version %u (header %u bytes), expected version %d", version, hsize,
                 DPS_VERSION);
        return bad(r, err, msg);
    }
    uint64_t nl = get_u64(r), payload = get_u64(r);
    dps->source_points = get_u64(r);
    dps->mean_radius = get_f64(r);
    dps->amg_levels = get_u32(r);
    (void)get_u32(r);
    dps->skipped_levels = get_u32(r);
    (void)get_u32(r);
    if (payload != total - DPS_HEADER - 4) {
        snprintf(msg, sizeof msg, "%s: header says %llu payload bytes, the file has %zu",
                 payload > total - DPS_HEADER - 4 ? "truncated" : "trailing bytes", (unsigned long long)payload,
                 total - DPS_HEADER - 4);
        return bad(r, err, msg);
    }
    const uint8_t *end = r->p + payload;
    uint32_t stored = (uint32_t)end[0] | (uint32_t)end[1] << 8 | (uint32_t)end[2] << 16 | (uint32_t)end[3] << 24;
    uint32_t crc = asp__crc32(0, r->base, total - 4);
    if (crc != stored) {
        snprintf(msg, sizeof msg, "checksum mismatch (stored 0x%08x, computed 0x%08x): the file is damaged", stored,
                 crc);
        return bad(r, err, msg);
    }
    r->left = (size_t)payload;
    if (nl == 0 || nl > 64 || dps->amg_levels == 0 || !(dps->mean_radius > 0) || r->left < DPS_PARAMS + 4) {
        snprintf(msg, sizeof msg, "%llu levels of a %u-level decomposition, mean radius %g: expected 1..64 levels",
                 (unsigned long long)nl, dps->amg_levels, dps->mean_radius);
        return bad(r, err, msg);
    }
    asp_prim_desc *d = &dps->desc;
    d->tau = get_f64(r), d->texel_size = get_f64(r), d->width = get_f64(r);
    d->neighbour_fraction = get_f64(r), d->merge_flatness = get_f64(r), d->merge_angle = get_f64(r);
    d->max_texture = get_u32(r);
    d->method = (asp_prim_method)get_u32(r);
    d->shape = (asp_prim_shape)get_u32(r);
    d->normalise = (asp_prim_normalise)get_u32(r);
    d->unweighted = (int)get_u32(r), d->project_radii = (int)get_u32(r), d->no_extend_color = (int)get_u32(r);
    d->normal_map = (int)get_u32(r), d->merge = (int)get_u32(r), d->padding = get_u32(r);
    r->p += DPS_PARAMS - 88, r->left -= DPS_PARAMS - 88;
    uint32_t slen = get_u32(r);
    if (slen >= sizeof dps->source || slen > r->left) {
        snprintf(msg, sizeof msg, "source name of %u bytes, expected below %zu", slen, sizeof dps->source);
        return bad(r, err, msg);
    }
    memcpy(dps->source, r->p, slen);
    dps->source[slen] = 0;
    r->p += slen, r->left -= slen;
    dps->levels = asp_calloc(ctx, (size_t)nl, sizeof *dps->levels);
    if (!dps->levels)
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", r->path);
    for (size_t i = 0; i < nl; i++) {
        dps->level_count = i + 1;
        int rc = read_level(r, dps, i, &dps->levels[i], ctx, err);
        if (rc)
            return rc;
    }
    if (r->left != 0) {
        snprintf(msg, sizeof msg, "%zu unexpected bytes after the last level", r->left);
        return bad(r, err, msg);
    }
    return 0;
}

int asp_dps_load(const char *path, const asp_context *ctx, asp_dps **out, asp_error *err)
{
    if (!path || !out)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_load needs a path and an output");
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    long size = -1;
    if (fseek(fp, 0, SEEK_END) == 0)
        size = ftell(fp);
    if (size < 0 || fseek(fp, 0, SEEK_SET) != 0) {
        int e = errno;
        fclose(fp);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    uint8_t *buf = asp_alloc(ctx, (size_t)size + 1);
    if (!buf) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s' (%ld bytes)", path, size);
    }
    size_t got = fread(buf, 1, (size_t)size, fp);
    int rerr = ferror(fp);
    fclose(fp);
    if (rerr || got != (size_t)size) {
        asp_free(ctx, buf);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': short read", path);
    }
    asp_dps *dps = asp_calloc(ctx, 1, sizeof *dps);
    if (!dps) {
        asp_free(ctx, buf);
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", path);
    }
    dps->ctx = ctx ? *ctx : (asp_context){0};
    reader r = {buf, buf, (size_t)size, path};
    int rc = parse(&r, ctx, dps, err);
    asp_free(ctx, buf);
    if (rc) {
        asp_dps_destroy(dps);
        return rc;
    }
    *out = dps;
    return 0;
}

void asp_dps_summarize(const asp_dps *dps, asp_dps_summary *rows)
{
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        asp_dps_summary *s = &rows[i];
        memset(s, 0, sizeof *s);
        s->level = lv->level;
        uint32_t top = dps->amg_levels ? dps->amg_levels - 1 : 0;
        if (lv->level == top)
            snprintf(s->name, sizeof s->name, "L");
        else
            snprintf(s->name, sizeof s->name, "L-%u", top - lv->level);
        s->primitives = lv->prim_count;
        s->texels = lv->texels;
        s->error = lv->error, s->error_norm = lv->error_norm;
        s->t_basis = lv->t_basis, s->t_construct = lv->t_construct;
        s->skipped = lv->skipped, s->degenerate = lv->degenerate, s->capped = lv->capped, s->merges = lv->merges;
        s->atlas_width = lv->atlas.width, s->atlas_height = lv->atlas.height;
        s->neighbour_pairs = lv->neighbour_total / 2;
        s->normal_map = lv->normal_atlas.width > 0;
    }
}
