/*
 * The .amg file (docs/cli/decompose.md): the whole input point set, tangent
 * normals, classifier (journal 2.1) and the prolongations P^l of the hierarchy
 * (journal 2.3), from which any level's basis is one chain of sparse products
 * (the thesis stores the AMG output and constructs only the chosen basis, 2.6).
 * Versioned, little-endian, with a CRC-32 over everything before it.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amg/internal.h"
#include "util/atomic_file.h"
#include "util/checksum.h"
#include "util/banned.h"

#define AMG_MAGIC "ASPAMG\r\n"
enum { AMG_VERSION = 2, AMG_HEADER = 64, AMG_OPTIONS = 128 };
/* point attributes a version-2 file may carry after the classifier */
static const unsigned amg_attrs = ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII | ASP_ATTR_UVS | ASP_ATTR_LABELS;

/* Bytes per point of the optional attributes in attrs. */
static uint64_t attr_bytes(unsigned attrs)
{
    return (attrs & ASP_ATTR_NORMALS ? 12u : 0u) + (attrs & ASP_ATTR_COLORS ? 4u : 0u) +
           (attrs & ASP_ATTR_RADII ? 4u : 0u) + (attrs & ASP_ATTR_UVS ? 8u : 0u) + (attrs & ASP_ATTR_LABELS ? 4u : 0u);
}

/* Attributes the file stores: the input's normals only when they differ from the tangent normals. */
static unsigned stored_attrs(const asp_amg *amg)
{
    unsigned a = asp_cloud_attrs(amg->cloud) & amg_attrs;
    if (!amg->input_normals)
        a &= ~(unsigned)ASP_ATTR_NORMALS;
    return a;
}

static int host_is_little_endian(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}

typedef asp__crc_writer writer;

static void put(writer *w, const void *data, size_t len)
{
    asp__crc_put(w, data, len);
}

static void put_u64(writer *w, uint64_t v) { put(w, &v, 8); }
static void put_u32(writer *w, uint32_t v) { put(w, &v, 4); }
static void put_f64(writer *w, double v) { put(w, &v, 8); }

static uint64_t payload_size(const asp_amg *amg)
{
    uint64_t n = amg->cloud->count;
    uint64_t s = 7 * 4 * n + 8 + attr_bytes(stored_attrs(amg)) * n + AMG_OPTIONS + 8 * (uint64_t)amg->nlevels;
    for (size_t l = 1; l < amg->nlevels; l++) {
        const asp_amg_csr *p = amg->prolong[l];
        s += 8 + 8 * ((uint64_t)p->rows + 1) + 12 * (uint64_t)p->row_ptr[p->rows];
    }
    return s;
}

int asp_amg_save(const asp_amg *amg, const char *path, asp_error *err)
{
    if (!host_is_little_endian())
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': .amg files are little-endian only", path);
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    writer w = {f.fp, 0, 0};
    const size_t n = amg->cloud->count;
    /* header: 64 bytes */
    put(&w, AMG_MAGIC, 8);
    put_u32(&w, AMG_VERSION);
    put_u32(&w, AMG_HEADER);
    put_u64(&w, n);
    put_u64(&w, amg->nlevels);
    put_u64(&w, payload_size(amg));
    for (int a = 0; a < 3; a++)
        put_f64(&w, amg->cloud->origin[a]);
    put(&w, amg->cloud->positions, 3 * n * sizeof(float));
    put(&w, amg->tangent, 3 * n * sizeof(float));
    put(&w, amg->classifier, n * sizeof(float));
    /* the input's attributes (version 2): a bit set, then one array per bit in this order */
    const unsigned attrs = stored_attrs(amg);
    const asp_cloud *c = amg->cloud;
    put_u32(&w, attrs);
    put_u32(&w, 0);
    if (attrs & ASP_ATTR_NORMALS)
        put(&w, c->normals, 3 * n * sizeof(float));
    if (attrs & ASP_ATTR_COLORS)
        put(&w, c->colors, 4 * n);
    if (attrs & ASP_ATTR_RADII)
        put(&w, c->radii, n * sizeof(float));
    if (attrs & ASP_ATTR_UVS)
        put(&w, c->uvs, 2 * n * sizeof(float));
    if (attrs & ASP_ATTR_LABELS)
        put(&w, c->labels, n * sizeof(uint32_t));
    /* options block: 128 bytes, what produced the hierarchy */
    const asp_amg_desc *d = &amg->desc;
    put_f64(&w, d->epsilon);
    put_u64(&w, d->k_min);
    put_u64(&w, d->k_max);
    put_u64(&w, d->fan_k);
    put_u32(&w, (uint32_t)d->classifier);
    put_u32(&w, (uint32_t)d->coarsen);
    put_u32(&w, (uint32_t)d->interp);
    put_u32(&w, 0);
    put_f64(&w, d->alpha);
    put_f64(&w, d->beta);
    put_f64(&w, d->strong_threshold);
    put_f64(&w, d->trunc_factor);
    put_f64(&w, d->drop_tol);
    put_u64(&w, d->max_levels);
    put_u64(&w, d->max_coarse);
    put_f64(&w, d->weak_coupling);
    put_f64(&w, d->crease_cut);
    put_u64(&w, 0); /* reserved */
    for (size_t l = 0; l < amg->nlevels; l++)
        put_u64(&w, amg->level_size[l]);
    for (size_t l = 1; l < amg->nlevels; l++) {
        const asp_amg_csr *p = amg->prolong[l];
        size_t nnz = p->row_ptr[p->rows];
        put_u64(&w, nnz);
        for (size_t r = 0; r <= p->rows; r++)
            put_u64(&w, p->row_ptr[r]);
        put(&w, p->col, nnz * sizeof *p->col);
        put(&w, p->val, nnz * sizeof *p->val);
    }
    uint32_t crc = w.crc;
    put(&w, &crc, 4);
    if (w.failed) {
        int e = errno;
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", path, strerror(e));
    }
    return asp__atomic_commit(&f, err);
}

/* Bounds-checked reader over the file in memory; every failure names the byte offset. */
typedef struct reader {
    const uint8_t *buf;
    size_t size, at;
    const char *path;
    asp_error *err;
} reader;

static int take(reader *r, void *dst, size_t len, const char *what)
{
    if (len > r->size - r->at)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': byte %zu: truncated in %s (%zu bytes needed, %zu left)",
                             r->path, r->at, what, len, r->size - r->at);
    memcpy(dst, r->buf + r->at, len);
    r->at += len;
    return 0;
}

static int bad(reader *r, const char *what)
{
    return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': byte %zu: %s", r->path, r->at, what);
}

static int read_file(const char *path, const asp_context *ctx, uint8_t **buf, size_t *size, asp_error *err)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    long end = -1;
    if (fseek(fp, 0, SEEK_END) == 0)
        end = ftell(fp);
    if (end < 0 || fseek(fp, 0, SEEK_SET) != 0) {
        fclose(fp);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': not a seekable file", path);
    }
    uint8_t *b = asp_alloc(ctx, (size_t)end + 1);
    if (!b) {
        fclose(fp);
        return asp_error_set(err, ASP_ENOMEM, "cannot read '%s': out of memory for %ld bytes", path, end);
    }
    if (fread(b, 1, (size_t)end, fp) != (size_t)end) {
        int e = errno;
        fclose(fp);
        asp_free(ctx, b);
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    fclose(fp);
    *buf = b;
    *size = (size_t)end;
    return 0;
}

static int parse(reader *r, const asp_context *ctx, asp_amg *a)
{
    char magic[8];
    uint32_t version, header, u32[4];
    uint64_t n, nlevels, payload, u64;
    double origin[3];
    int rc;
    if (r->size < AMG_HEADER + 4)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': %zu bytes is too short for an .amg file",
                             r->path, r->size);
    take(r, magic, 8, "the header");
    if (memcmp(magic, AMG_MAGIC, 8) != 0)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': not an .amg file (bad magic)", r->path);
    take(r, &version, 4, "the header");
    take(r, &header, 4, "the header");
    if (version == 1)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': .amg version 1 lacks the point attributes; decompose the input again "
                             "(version %d)", r->path, AMG_VERSION);
    if (version != AMG_VERSION)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': .amg version %u, expected %d", r->path,
                             (unsigned)version, AMG_VERSION);
    if (header != AMG_HEADER)
        return bad(r, "unexpected header size");
    take(r, &n, 8, "the header");
    take(r, &nlevels, 8, "the header");
    take(r, &payload, 8, "the header");
    take(r, origin, 24, "the header");
    if (payload > r->size || r->size - AMG_HEADER - 4 != payload)
        return asp_error_set(r->err, ASP_EFORMAT,
                             "cannot read '%s': truncated or padded: the header promises %llu bytes, the file has %zu",
                             r->path, (unsigned long long)(payload + AMG_HEADER + 4), r->size);
    uint32_t stored;
    memcpy(&stored, r->buf + r->size - 4, 4);
    if (asp__crc32(0, r->buf, r->size - 4) != stored)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': checksum mismatch (file corrupted)", r->path);
    /* sizes come from a checksummed file, but a crafted one must still not make us allocate wildly */
    if (n < 1 || n > payload / 28 || n > (uint64_t)INT32_MAX)
        return bad(r, "point count does not fit the file");
    if (nlevels < 1 || nlevels > 100)
        return bad(r, "level count outside 1..100");
    /* the attribute bit set sits after the fixed per-point arrays; read it first to size the cloud */
    uint32_t attrs = 0;
    r->at = AMG_HEADER + 28 * (size_t)n;
    if ((rc = take(r, &attrs, 4, "the attribute set")) != 0)
        return rc;
    if (attrs & ~(uint32_t)amg_attrs)
        return bad(r, "unknown point attribute bits");
    if (payload < 28 * n + 8 + attr_bytes(attrs) * n)
        return bad(r, "point attributes do not fit the file");
    r->at = AMG_HEADER;
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
        return asp_error_set(r->err, ASP_ENOMEM, "cannot read '%s': out of memory", r->path);
    asp_cloud *c = a->cloud;
    if ((rc = take(r, c->positions, 12 * (size_t)n, "positions")) ||
        (rc = take(r, a->tangent, 12 * (size_t)n, "tangent normals")) ||
        (rc = take(r, a->classifier, 4 * (size_t)n, "classifier values")) ||
        (rc = take(r, u32, 8, "the attribute set")))
        return rc;
    if (attrs & ASP_ATTR_NORMALS)
        rc = take(r, c->normals, 12 * (size_t)n, "normals");
    else
        memcpy(c->normals, a->tangent, 12 * (size_t)n);
    if (!rc && (attrs & ASP_ATTR_COLORS))
        rc = take(r, c->colors, 4 * (size_t)n, "colors");
    if (!rc && (attrs & ASP_ATTR_RADII))
        rc = take(r, c->radii, 4 * (size_t)n, "radii");
    if (!rc && (attrs & ASP_ATTR_UVS))
        rc = take(r, c->uvs, 8 * (size_t)n, "uvs");
    if (!rc && (attrs & ASP_ATTR_LABELS))
        rc = take(r, c->labels, 4 * (size_t)n, "labels");
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
    asp_amg_desc *d = &a->desc;
    take(r, &d->epsilon, 8, "options");
    take(r, &u64, 8, "options");
    d->k_min = (size_t)u64;
    take(r, &u64, 8, "options");
    d->k_max = (size_t)u64;
    take(r, &u64, 8, "options");
    d->fan_k = (size_t)u64;
    take(r, u32, 16, "options");
    if (u32[0] > ASP_AMG_CLASSIFIER_MOMENT || u32[1] > ASP_AMG_COARSEN_HMIS || u32[2] > ASP_AMG_INTERP_EXTENDED_I)
        return bad(r, "unknown classifier, coarsening or interpolation code");
    d->classifier = (asp_amg_classifier_kind)u32[0];
    d->coarsen = (asp_amg_coarsen)u32[1];
    d->interp = (asp_amg_interp)u32[2];
    take(r, &d->alpha, 8, "options");
    take(r, &d->beta, 8, "options");
    take(r, &d->strong_threshold, 8, "options");
    take(r, &d->trunc_factor, 8, "options");
    take(r, &d->drop_tol, 8, "options");
    take(r, &u64, 8, "options");
    d->max_levels = (size_t)u64;
    take(r, &u64, 8, "options");
    d->max_coarse = (size_t)u64;
    if ((rc = take(r, &d->weak_coupling, 8, "options")) || (rc = take(r, &d->crease_cut, 8, "options")) ||
        (rc = take(r, &u64, 8, "options")))
        return rc;
    if (!(d->drop_tol < 0.01))
        return bad(r, "invalid drop tolerance");
    for (size_t l = 0; l < a->nlevels; l++) {
        if ((rc = take(r, &u64, 8, "level sizes")) != 0)
            return rc;
        if (u64 < 1 || u64 > n || (l == 0 && u64 != n))
            return bad(r, "level size outside 1..point count (level 0 must equal it)");
        a->level_size[l] = (size_t)u64;
    }
    for (size_t l = 1; l < a->nlevels; l++) {
        size_t rows = a->level_size[l - 1], cols = a->level_size[l];
        uint64_t nnz;
        if ((rc = take(r, &nnz, 8, "a prolongation")) != 0)
            return rc;
        if (nnz > (r->size - r->at) / 12 || nnz < rows)
            return bad(r, "prolongation size does not fit the file");
        asp_amg_csr *p;
        if ((rc = asp_amg_csr_create(rows, cols, (size_t)nnz, ctx, &p, r->err)) != 0)
            return rc;
        a->prolong[l] = p;
        if ((rc = take(r, p->row_ptr, 8 * (rows + 1), "a prolongation")) ||
            (rc = take(r, p->col, 4 * (size_t)nnz, "a prolongation")) ||
            (rc = take(r, p->val, 8 * (size_t)nnz, "a prolongation")))
            return rc;
        if (p->row_ptr[0] != 0 || p->row_ptr[rows] != nnz)
            return bad(r, "prolongation row pointers do not span its entries");
        for (size_t q = 0; q < rows; q++) {
            if (p->row_ptr[q + 1] <= p->row_ptr[q])
                return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': level %zu: row %zu of P is empty or unordered",
                                     r->path, l, q);
            double sum = 0;
            for (size_t k = p->row_ptr[q]; k < p->row_ptr[q + 1]; k++) {
                if (p->col[k] >= cols || (k > p->row_ptr[q] && p->col[k] <= p->col[k - 1]))
                    return asp_error_set(r->err, ASP_EFORMAT,
                                         "cannot read '%s': level %zu: row %zu of P has a bad column", r->path, l, q);
                if (!(p->val[k] >= 0 && p->val[k] <= 1))
                    return asp_error_set(r->err, ASP_EFORMAT,
                                         "cannot read '%s': level %zu: row %zu of P has a weight outside [0,1]", r->path,
                                         l, q);
                sum += p->val[k];
            }
            if (fabs(sum - 1) > 1e-6)
                return asp_error_set(r->err, ASP_EFORMAT,
                                     "cannot read '%s': level %zu: row %zu of P sums to %g, expected 1", r->path, l, q,
                                     sum);
        }
    }
    if (r->at != r->size - 4)
        return bad(r, "unexpected bytes after the last level");
    a->info.epsilon = d->epsilon;
    a->info.k_min = d->k_min;
    a->info.k_max = d->k_max;
    a->info.fan_k = d->fan_k;
    return 0;
}

int asp_amg_load(const char *path, const asp_context *ctx, asp_amg **out, asp_error *err)
{
    if (!host_is_little_endian())
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': .amg files are little-endian only", path);
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = read_file(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    asp_amg *a;
    rc = asp__amg_alloc(ctx, &a, err);
    if (!rc) {
        reader r = {buf, size, 0, path, err};
        rc = parse(&r, ctx, a);
        if (rc)
            asp_amg_destroy(a);
        else
            *out = a;
    }
    asp_free(ctx, buf);
    return rc;
}
