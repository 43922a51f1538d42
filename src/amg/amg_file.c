/*
 * The .amg file (docs/cli/decompose.md): the whole input point set, tangent
 * normals, classifier (journal 2.1) and the prolongations P^l of the hierarchy
 * (journal 2.3), from which any level's basis is one chain of sparse products
 * (the thesis stores the AMG output and constructs only the chosen basis, 2.6).
 * Versioned, little-endian, with a CRC-32 over everything before it.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "amg/amg_format.h"
#include "amg/internal.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

enum { AMG_VERSION = ASP__AMG_VERSION, AMG_HEADER = ASP__AMG_HEADER, AMG_HEADER_V2 = ASP__AMG_HEADER_V2,
       AMG_OPTIONS = ASP__AMG_OPTIONS };

const unsigned asp__amg_attr_bit[ASP__AMG_NATTRS] = {ASP_ATTR_NORMALS, ASP_ATTR_COLORS, ASP_ATTR_RADII, ASP_ATTR_UVS,
                                                     ASP_ATTR_LABELS};
const unsigned asp__amg_attr_size[ASP__AMG_NATTRS] = {12, 4, 4, 8, 4};

uint64_t asp__amg_attr_bytes(unsigned attrs)
{
    uint64_t b = 0;
    for (int i = 0; i < ASP__AMG_NATTRS; i++)
        b += attrs & asp__amg_attr_bit[i] ? asp__amg_attr_size[i] : 0u;
    return b;
}

void asp__amg_put_header(asp__crc_writer *w, const asp__amg_header *h)
{
    /* per point: positions, tangent normals and classifier (28 bytes) and the optional arrays */
    uint64_t payload = (28 + asp__amg_attr_bytes(h->attrs)) * h->points + 8 + AMG_OPTIONS + 8 * h->nlevels;
    for (size_t l = 1; l < h->nlevels; l++)
        payload += 8 + 8 * ((uint64_t)h->level_size[l - 1] + 1);
    payload += 12 * h->prolong_nnz;
    asp__crc_put(w, ASP__AMG_MAGIC, 8);
    asp__put_u32(w, AMG_VERSION);
    asp__put_u32(w, AMG_HEADER);
    asp__put_u64(w, h->points);
    asp__put_u64(w, h->nlevels);
    asp__put_u64(w, payload);
    for (int a = 0; a < 3; a++)
        asp__put_f64(w, h->origin[a]);
    for (int a = 0; a < 3; a++)
        asp__put_f64(w, h->frame.center[a]);
    asp__put_f64(w, h->frame.radius);
}

void asp__amg_put_attr_set(asp__crc_writer *w, unsigned attrs, asp_up_axis up)
{
    asp__put_u32(w, attrs);
    asp__put_u32(w, (uint32_t)up + 1u);
}

void asp__amg_put_options(asp__crc_writer *w, const asp_amg_desc *d, const size_t *level_size, size_t nlevels)
{
    asp__put_f64(w, d->epsilon);
    asp__put_u64(w, d->k_min);
    asp__put_u64(w, d->k_max);
    asp__put_u64(w, d->fan_k);
    asp__put_u32(w, (uint32_t)d->classifier);
    asp__put_u32(w, (uint32_t)d->coarsen);
    asp__put_u32(w, (uint32_t)d->interp);
    asp__put_u32(w, 0);
    asp__put_f64(w, d->alpha);
    asp__put_f64(w, d->beta);
    asp__put_f64(w, d->strong_threshold);
    asp__put_f64(w, d->trunc_factor);
    asp__put_f64(w, d->drop_tol);
    asp__put_u64(w, d->max_levels);
    asp__put_u64(w, d->max_coarse);
    asp__put_f64(w, d->weak_coupling);
    asp__put_f64(w, d->crease_cut);
    asp__put_u64(w, 0); /* reserved */
    for (size_t l = 0; l < nlevels; l++)
        asp__put_u64(w, level_size[l]);
}

/* Attributes the file stores: the input's normals only when they differ from the tangent normals. */
static unsigned stored_attrs(const asp_amg *amg)
{
    unsigned a = asp_cloud_attrs(amg->cloud) & ASP__AMG_ATTRS;
    if (!amg->input_normals)
        a &= ~(unsigned)ASP_ATTR_NORMALS;
    return a;
}

/*
 * No command writes what its own reader refuses (issue #13): the whole file
 * is parsed back before it replaces the target. A full read, not a header
 * check, because what went wrong before was in the payload (an epsilon of
 * inf in the options block); it costs about what the write does.
 */
static int amg_reads_back(const char *tmp, void *user, asp_error *err)
{
    const asp_amg *amg = user;
    asp_amg *back = NULL;
    int rc = asp_amg_load(tmp, &amg->ctx, &back, err);
    asp_amg_destroy(back);
    return rc;
}

int asp_amg_save(const asp_amg *amg, const char *path, asp_error *err)
{
    if (!asp__amg_host_little_endian())
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': .amg files are little-endian only", path);
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    asp__crc_writer w = {f.fp, 0, 0};
    const asp_cloud *c = amg->cloud;
    const size_t n = c->count;
    asp__amg_header h = {.points = n, .nlevels = amg->nlevels, .level_size = amg->level_size,
                         .attrs = stored_attrs(amg), .frame = amg->frame};
    memcpy(h.origin, c->origin, sizeof h.origin);
    for (size_t l = 1; l < amg->nlevels; l++)
        h.prolong_nnz += amg->prolong[l]->row_ptr[amg->prolong[l]->rows];
    asp__amg_put_header(&w, &h);
    asp__crc_put(&w, c->positions, 3 * n * sizeof(float));
    asp__crc_put(&w, amg->tangent, 3 * n * sizeof(float));
    asp__crc_put(&w, amg->classifier, n * sizeof(float));
    /* the input's attributes (version 2): a bit set, then one array per bit in this order */
    asp__amg_put_attr_set(&w, h.attrs, amg->frame.up);
    const void *const arrays[ASP__AMG_NATTRS] = {c->normals, c->colors, c->radii, c->uvs, c->labels};
    for (int i = 0; i < ASP__AMG_NATTRS; i++)
        if (h.attrs & asp__amg_attr_bit[i])
            asp__crc_put(&w, arrays[i], asp__amg_attr_size[i] * n);
    asp__amg_put_options(&w, &amg->desc, amg->level_size, amg->nlevels);
    for (size_t l = 1; l < amg->nlevels; l++) {
        const asp_amg_csr *p = amg->prolong[l];
        size_t nnz = p->row_ptr[p->rows];
        asp__put_u64(&w, nnz);
        for (size_t r = 0; r <= p->rows; r++)
            asp__put_u64(&w, p->row_ptr[r]);
        asp__crc_put(&w, p->col, nnz * sizeof *p->col);
        asp__crc_put(&w, p->val, nnz * sizeof *p->val);
    }
    return asp__byte_commit(&w, &f, path, amg_reads_back, (void *)amg, err);
}

/* The options block (128 bytes): what produced the hierarchy (docs/cli/decompose.md). */
static int read_options(asp__byte_reader *r, asp_amg_desc *d)
{
    uint64_t u64[3], lim[2], reserved;
    uint32_t u32[4];
    double f[5];
    int rc;
    if ((rc = asp__byte_take(r, &d->epsilon, 8, "options")) || (rc = asp__byte_take(r, u64, 24, "options")) ||
        (rc = asp__byte_take(r, u32, 16, "options")) || (rc = asp__byte_take(r, f, 40, "options")) ||
        (rc = asp__byte_take(r, lim, 16, "options")) || (rc = asp__byte_take(r, &d->weak_coupling, 8, "options")) ||
        (rc = asp__byte_take(r, &d->crease_cut, 8, "options")) || (rc = asp__byte_take(r, &reserved, 8, "options")))
        return rc;
    if (u32[0] > ASP_AMG_CLASSIFIER_MOMENT || u32[1] > ASP_AMG_COARSEN_HMIS || u32[2] > ASP_AMG_INTERP_EXTENDED_I)
        return asp__byte_bad(r, "unknown classifier, coarsening or interpolation code");
    /* drop_tol drives every product P^l (journal 2.3): a NaN would silently empty the basis */
    char msg[120];
    if (!isfinite(d->epsilon) || !(f[4] < 0.01)) {
        r->at -= AMG_OPTIONS; // the start of the options block
        if (!isfinite(d->epsilon))
            snprintf(msg, sizeof msg, "options: epsilon %g, expected a finite neighbourhood radius", d->epsilon);
        else
            snprintf(msg, sizeof msg, "options: drop tolerance %.17g, expected one below 0.01", f[4]);
        return asp__byte_bad(r, msg);
    }
    d->k_min = (size_t)u64[0];
    d->k_max = (size_t)u64[1];
    d->fan_k = (size_t)u64[2];
    d->classifier = (asp_amg_classifier_kind)u32[0];
    d->coarsen = (asp_amg_coarsen)u32[1];
    d->interp = (asp_amg_interp)u32[2];
    d->alpha = f[0];
    d->beta = f[1];
    d->strong_threshold = f[2];
    d->trunc_factor = f[3];
    d->drop_tol = f[4];
    d->max_levels = (size_t)lim[0];
    d->max_coarse = (size_t)lim[1];
    return 0;
}

/*
 * Level l's prolongation P^l (journal 2.3): rows x cols, every row non-empty
 * with increasing columns and weights in [0,1] summing to 1 (a partition of
 * unity, which the basis products rely on).
 */
static int read_prolongation(asp__byte_reader *r, size_t l, size_t rows, size_t cols, const asp_context *ctx,
                             asp_amg_csr **out)
{
    uint64_t nnz;
    int rc;
    char msg[200];
    if ((rc = asp__byte_take(r, &nnz, 8, "a prolongation")) != 0)
        return rc;
    /* 8 bytes per row pointer, 12 per entry: compare by division so a forged count cannot overflow */
    const size_t avail = asp__byte_left(r), ptr_bytes = 8 * (rows + 1);
    if (nnz < rows || nnz > avail / 12 || ptr_bytes > avail - 12 * (size_t)nnz) {
        r->at -= 8;
        snprintf(msg, sizeof msg, "level %zu: prolongation entry count %llu, expected %zu..%zu for %zu rows in the %zu "
                 "bytes left", l, (unsigned long long)nnz, rows, avail >= ptr_bytes ? (avail - ptr_bytes) / 12 : 0,
                 rows, avail);
        return asp__byte_bad(r, msg);
    }
    asp_amg_csr *p;
    if ((rc = asp_amg_csr_create(rows, cols, (size_t)nnz, ctx, &p, r->err)) != 0)
        return rc;
    for (size_t q = 0; q <= rows; q++) {
        uint64_t v = asp__get_u64(r);
        p->row_ptr[q] = (size_t)v;
        /* row pointers are checked before any column is touched: entries beyond nnz are never read */
        if (q == 0 ? v != 0 : (v <= p->row_ptr[q - 1] || v > nnz || (q == rows && v != nnz))) {
            asp_amg_csr_destroy(p);
            r->at -= 8;
            snprintf(msg, sizeof msg,
                     "level %zu: row pointer %zu of P is %llu, expected increasing from 0 to %llu (no empty row)", l, q,
                     (unsigned long long)v, (unsigned long long)nnz);
            return asp__byte_bad(r, msg);
        }
    }
    memcpy(p->col, r->buf + r->at, 4 * (size_t)nnz);
    r->at += 4 * (size_t)nnz;
    memcpy(p->val, r->buf + r->at, 8 * (size_t)nnz);
    r->at += 8 * (size_t)nnz;
    for (size_t q = 0; q < rows; q++) {
        double sum = 0;
        for (size_t k = p->row_ptr[q]; k < p->row_ptr[q + 1]; k++) {
            const int bad_col = p->col[k] >= cols || (k > p->row_ptr[q] && p->col[k] <= p->col[k - 1]);
            if (bad_col || !(p->val[k] >= 0 && p->val[k] <= 1)) {
                if (bad_col)
                    rc = asp_error_set(r->err, ASP_EFORMAT,
                                       "cannot read '%s': level %zu: row %zu of P has column %u, expected increasing "
                                       "columns below %zu", r->path, l, q, (unsigned)p->col[k], cols);
                else
                    // %.17g: 1.0000000000000566 printed with %g read "weight 1, expected one in [0,1]" (issue #13)
                    rc = asp_error_set(r->err, ASP_EFORMAT,
                                       "cannot read '%s': level %zu: row %zu of P has weight %.17g, %s (weights are "
                                       "in [0,1])", r->path, l, q, p->val[k],
                                       p->val[k] > 1 ? "above 1" : p->val[k] < 0 ? "below 0" : "not a number");
                asp_amg_csr_destroy(p);
                return rc;
            }
            sum += p->val[k];
        }
        if (fabs(sum - 1) > 1e-6) {
            asp_amg_csr_destroy(p);
            return asp_error_set(r->err, ASP_EFORMAT,
                                 "cannot read '%s': level %zu: row %zu of P sums to %.17g, expected 1 within 1e-6",
                                 r->path, l, q, sum);
        }
    }
    *out = p;
    return 0;
}

static int parse(asp__byte_reader *r, const asp_context *ctx, asp_amg *a)
{
    char magic[8], msg[200];
    uint32_t version, header, u32[2];
    uint64_t n, nlevels, payload, u64;
    double origin[3];
    int rc;
    if (r->size < AMG_HEADER_V2 + 4)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': %zu bytes is too short for an .amg file (expected at least %d)", r->path,
                             r->size, AMG_HEADER_V2 + 4);
    /* the size was checked: the header fields cannot fail */
    asp__byte_take(r, magic, 8, "the header");
    if (memcmp(magic, ASP__AMG_MAGIC, 8) != 0)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': not an .amg file (bad magic)", r->path);
    asp__byte_take(r, &version, 4, "the header");
    asp__byte_take(r, &header, 4, "the header");
    if (version == 1)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': .amg version 1 lacks the point attributes; decompose the input again "
                             "(version %d)", r->path, AMG_VERSION);
    if (version != AMG_VERSION && version != 2)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': .amg version %u, expected 2 or %d", r->path,
                             (unsigned)version, AMG_VERSION);
    const size_t hsize = version == 2 ? AMG_HEADER_V2 : AMG_HEADER;
    if (header != hsize)
        return asp__byte_bad(r, "unexpected header size");
    if (r->size < hsize + 4)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': %zu bytes is too short for an .amg file (expected at least %zu)", r->path,
                             r->size, hsize + 4);
    asp__byte_take(r, &n, 8, "the header");
    asp__byte_take(r, &nlevels, 8, "the header");
    asp__byte_take(r, &payload, 8, "the header");
    asp__byte_take(r, origin, 24, "the header");
    const size_t frame_at = r->at;
    const int recorded = version >= 3;
    if (recorded) {
        asp__byte_take(r, a->frame.center, 24, "the header");
        asp__byte_take(r, &a->frame.radius, 8, "the header");
    }
    if (payload != r->size - hsize - 4)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': truncated or padded: the header promises %llu payload bytes, the "
                             "file has %zu",
                             r->path, (unsigned long long)payload, r->size - hsize - 4);
    uint32_t stored;
    memcpy(&stored, r->buf + r->size - 4, 4);
    if (asp__crc32(0, r->buf, r->size - 4) != stored)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': checksum mismatch (file corrupted)", r->path);
    r->size -= 4; /* the trailer is not payload */
    if (recorded && !(isfinite(a->frame.center[0]) && isfinite(a->frame.center[1]) &&
                               isfinite(a->frame.center[2]) && isfinite(a->frame.radius) && a->frame.radius >= 0)) {
        r->at = frame_at;
        snprintf(msg, sizeof msg, "frame: centre (%g, %g, %g), radius %g, expected finite values and a radius >= 0",
                 a->frame.center[0], a->frame.center[1], a->frame.center[2], a->frame.radius);
        return asp__byte_bad(r, msg);
    }
    if (!(isfinite(origin[0]) && isfinite(origin[1]) && isfinite(origin[2]))) { // issue #31: a NaN origin
        r->at = 40;
        snprintf(msg, sizeof msg, "origin (%g, %g, %g), expected finite values", origin[0], origin[1], origin[2]);
        return asp__byte_bad(r, msg);
    }
    /* sizes come from a checksummed file, but a crafted one must still not make us allocate wildly */
    if (n < 1 || n > payload / 28 || n > (uint64_t)INT32_MAX) {
        r->at = 16;
        snprintf(msg, sizeof msg, "point count %llu, expected 1..%llu (28 bytes per point in a %llu-byte payload)",
                 (unsigned long long)n, (unsigned long long)(payload / 28 < INT32_MAX ? payload / 28 : INT32_MAX),
                 (unsigned long long)payload);
        return asp__byte_bad(r, msg);
    }
    if (nlevels < 1 || nlevels > 100) {
        r->at = 24;
        snprintf(msg, sizeof msg, "level count %llu, expected 1..100", (unsigned long long)nlevels);
        return asp__byte_bad(r, msg);
    }
    /* the attribute bit set sits after the fixed per-point arrays; read it first to size the cloud */
    uint32_t attrs = 0;
    r->at = hsize + 28 * (size_t)n;
    if ((rc = asp__byte_take(r, &attrs, 4, "the attribute set")) != 0)
        return rc;
    r->at -= 4;
    if (attrs & ~(uint32_t)ASP__AMG_ATTRS)
        return asp__byte_bad(r, "unknown point attribute bits");
    /* per-point data, options and one size per level must fit before anything per point is allocated */
    if (payload < 28 * n + 8 + asp__amg_attr_bytes(attrs) * n + AMG_OPTIONS + 8 * nlevels) {
        snprintf(msg, sizeof msg, "point attributes 0x%x of %llu points and %llu levels need %llu payload bytes, the "
                 "file has %llu", (unsigned)attrs, (unsigned long long)n, (unsigned long long)nlevels,
                 (unsigned long long)(28 * n + 8 + asp__amg_attr_bytes(attrs) * n + AMG_OPTIONS + 8 * nlevels),
                 (unsigned long long)payload);
        return asp__byte_bad(r, msg);
    }
    r->at = hsize;
    if ((rc = asp_cloud_create((size_t)n, ASP_ATTR_NORMALS | attrs, ctx, &a->cloud, r->err)) != 0)
        return rc;
    memcpy(a->cloud->origin, origin, sizeof origin);
    a->input_normals = (attrs & ASP_ATTR_NORMALS) != 0;
    a->classifier = asp_alloc(ctx, (size_t)n * sizeof(float));
    a->tangent = asp_alloc(ctx, 12 * (size_t)n);
    a->level_size = asp_calloc(ctx, (size_t)nlevels, sizeof *a->level_size);
    a->prolong = asp_calloc(ctx, (size_t)nlevels, sizeof *a->prolong);
    a->nlevels = (size_t)nlevels;
    if (!a->classifier || !a->tangent || !a->level_size || !a->prolong)
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory for %llu points", r->path,
                             (unsigned long long)n);
    asp_cloud *c = a->cloud;
    if ((rc = asp__byte_take(r, c->positions, 12 * (size_t)n, "positions")) ||
        (rc = asp__byte_take(r, a->tangent, 12 * (size_t)n, "tangent normals")) ||
        (rc = asp__byte_take(r, a->classifier, 4 * (size_t)n, "classifier values")) ||
        (rc = asp__byte_take(r, u32, 8, "the attribute set")))
        return rc;
    if (u32[1] > (uint32_t)ASP_UP_NEG_X + 1u) { // the up axis plus 1; 0: written before it was recorded
        r->at -= 4;
        snprintf(msg, sizeof msg, "up axis code %u, expected 0 (not recorded) or 1..%u", (unsigned)u32[1],
                 (unsigned)ASP_UP_NEG_X + 1u);
        return asp__byte_bad(r, msg);
    }
    const asp_up_axis up = u32[1] ? (asp_up_axis)(u32[1] - 1u) : ASP_UP_Y;
    c->up = up;
    if (attrs & ASP_ATTR_NORMALS)
        rc = asp__byte_take(r, c->normals, 12 * (size_t)n, "normals");
    else
        memcpy(c->normals, a->tangent, 12 * (size_t)n);
    if (!rc && (attrs & ASP_ATTR_COLORS))
        rc = asp__byte_take(r, c->colors, 4 * (size_t)n, "colors");
    if (!rc && (attrs & ASP_ATTR_RADII))
        rc = asp__byte_take(r, c->radii, 4 * (size_t)n, "radii");
    if (!rc && (attrs & ASP_ATTR_UVS))
        rc = asp__byte_take(r, c->uvs, 8 * (size_t)n, "uvs");
    if (!rc && (attrs & ASP_ATTR_LABELS))
        rc = asp__byte_take(r, c->labels, 4 * (size_t)n, "labels");
    if (rc)
        return rc;
    asp_error verr;
    if (asp_cloud_validate(c, &verr) != 0)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': %s", r->path, verr.msg);
    for (size_t i = 0; i < (size_t)n; i++)
        if (!isfinite(a->tangent[3 * i]) || !isfinite(a->tangent[3 * i + 1]) || !isfinite(a->tangent[3 * i + 2]) ||
            !isfinite(a->classifier[i]))
            return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': point %zu: non-finite tangent normal or classifier",
                                 r->path, i);
    if ((rc = read_options(r, &a->desc)) != 0)
        return rc;
    for (size_t l = 0; l < a->nlevels; l++) {
        if ((rc = asp__byte_take(r, &u64, 8, "level sizes")) != 0)
            return rc;
        /* each coarsening step makes fewer unknowns (hierarchy.c stops when it does not, journal 2.3) */
        uint64_t hi = l ? a->level_size[l - 1] - 1 : n;
        if (u64 < 1 || u64 > hi || (l == 0 && u64 != n)) {
            r->at -= 8;
            snprintf(msg, sizeof msg, "level %zu: size %llu, expected %s%llu", l, (unsigned long long)u64,
                     l ? "1.." : "the point count ", (unsigned long long)hi);
            return asp__byte_bad(r, msg);
        }
        a->level_size[l] = (size_t)u64;
    }
    for (size_t l = 1; l < a->nlevels; l++)
        if ((rc = read_prolongation(r, l, a->level_size[l - 1], a->level_size[l], ctx, &a->prolong[l])) != 0)
            return rc;
    if (r->at != r->size) {
        snprintf(msg, sizeof msg, "%zu unexpected bytes after the last level", asp__byte_left(r));
        return asp__byte_bad(r, msg);
    }
    a->info.epsilon = a->desc.epsilon;
    a->info.k_min = a->desc.k_min;
    a->info.k_max = a->desc.k_max;
    a->info.fan_k = a->desc.fan_k;
    // a version-2 file predates the recorded frame: computed as decompose does (radius 0 if nothing to frame);
    // the box is not recorded: the file holds every point, so it is the points' box again
    asp_frame box;
    if (asp_cloud_frame(a->cloud, &box, NULL) != 0)
        memset(&box, 0, sizeof box);
    if (recorded) {
        memcpy(box.center, a->frame.center, sizeof box.center);
        box.radius = a->frame.radius;
    }
    a->frame = box;
    a->frame.up = up;
    return 0;
}

int asp_amg_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_amg **out,
                        asp_error *err)
{
    static const uint8_t empty[1];
    const char *nm = name ? name : "<memory>";
    if (!out)
        return asp_error_set(err, ASP_EINVAL, "asp_amg_load_memory needs an output");
    if (!asp__amg_host_little_endian())
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': .amg files are little-endian only", nm);
    asp_amg *a;
    int rc = asp__amg_alloc(ctx, &a, err);
    if (rc)
        return rc;
    asp__byte_reader r = {data ? data : empty, data ? size : 0, 0, nm, err};
    rc = parse(&r, ctx, a);
    if (rc) {
        asp_amg_destroy(a);
        return rc;
    }
    *out = a;
    return 0;
}

int asp_amg_load(const char *path, const asp_context *ctx, asp_amg **out, asp_error *err)
{
    if (!path || !out)
        return asp_error_set(err, ASP_EINVAL, "asp_amg_load needs a path and an output");
    if (!asp__amg_host_little_endian())
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': .amg files are little-endian only", path);
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = asp__byte_slurp(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    rc = asp_amg_load_memory(buf, size, path, ctx, out, err);
    asp_free(ctx, buf);
    return rc;
}
