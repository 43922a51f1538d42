/*
 * On-disk hierarchy, so a large model loads without rebuilding (issue 6; layout
 * in docs/hier.md): a little-endian header and payload, each with an FNV-1a 64
 * checksum. Loading checks sizes against the file before allocating and
 * validates the tree, so a corrupted file is an error, never a crash.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hier/internal.h"
#include "util/atomic_file.h"
#include "util/banned.h"

#define MAGIC "ASPHIER"
enum { VERSION = 1, HEADER_SIZE = 128, NODE_REC = 48, SPLAT_REC = 64, COV_REC = 8 * ASP_HIER_COV };
enum { CHUNK = 1 << 16 };

#define FNV_OFFSET 0xcbf29ce484222325ULL
#define FNV_PRIME 0x100000001b3ULL

static uint64_t fnv1a(uint64_t h, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= FNV_PRIME;
    }
    return h;
}

static int host_is_le(void)
{
    const uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get32(const uint8_t *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)p[i] << (8 * i);
    return v;
}

static uint64_t get64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static void putf64(uint8_t *p, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    put64(p, v);
}

static double getf64(const uint8_t *p)
{
    uint64_t v = get64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

/*
 * Records are arrays of 4-byte words (floats, uint32) except the splat colour
 * (4 single bytes, word 3) and covariances (8-byte doubles). On a
 * little-endian host the in-memory layout is the file layout; elsewhere the
 * words are swapped in place.
 */
static void swap_words(uint8_t *p, size_t bytes, size_t word, size_t rec, size_t skip_word)
{
    for (size_t off = 0; off < bytes; off += word) {
        if (skip_word != (size_t)-1 && (off % rec) / 4 == skip_word)
            continue;
        for (size_t i = 0; i < word / 2; i++) {
            uint8_t t = p[off + i];
            p[off + i] = p[off + word - 1 - i];
            p[off + word - 1 - i] = t;
        }
    }
}

typedef struct writer {
    FILE *fp;
    uint64_t hash;
    uint8_t buf[CHUNK];
} writer;

static int put_array(writer *w, const void *src, size_t bytes, size_t word, size_t rec, size_t skip_word)
{
    const uint8_t *s = src;
    int le = host_is_le();
    for (size_t off = 0; off < bytes; off += CHUNK) {
        size_t n = bytes - off < CHUNK ? bytes - off : CHUNK;
        const uint8_t *p = s + off;
        if (!le) {
            memcpy(w->buf, p, n);
            swap_words(w->buf, n, word, rec, skip_word);
            p = w->buf;
        }
        w->hash = fnv1a(w->hash, p, n);
        if (fwrite(p, 1, n, w->fp) != n)
            return -1;
    }
    return 0;
}

static void encode_header(const asp_hier *h, uint64_t payload, uint64_t payload_hash, uint8_t hd[HEADER_SIZE])
{
    memset(hd, 0, HEADER_SIZE);
    memcpy(hd, MAGIC, 8);
    put32(hd + 8, VERSION);
    put32(hd + 12, HEADER_SIZE);
    put32(hd + 16, h->flags);
    put32(hd + 20, h->depth);
    put64(hd + 24, h->node_count);
    put64(hd + 32, h->point_count);
    put64(hd + 40, h->leaf_size);
    for (int i = 0; i < 3; i++)
        putf64(hd + 48 + 8 * i, h->origin[i]);
    put32(hd + 72, NODE_REC);
    put32(hd + 76, SPLAT_REC);
    put64(hd + 80, payload);
    put64(hd + 88, payload_hash);
    /* bytes 96-119 are reserved (zero); the header checksum covers everything before it */
    put64(hd + 120, fnv1a(FNV_OFFSET, hd, 120));
}

static uint64_t payload_size(uint64_t nodes, uint64_t points)
{
    return nodes * (NODE_REC + COV_REC) + (nodes + points) * SPLAT_REC;
}

int asp_hier_save(const asp_hier *hier, const char *path, asp_error *err)
{
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc)
        return rc;
    writer *w = asp_alloc(&hier->ctx, sizeof *w);
    if (!w) {
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
    }
    w->fp = f.fp;
    w->hash = FNV_OFFSET;
    uint8_t hd[HEADER_SIZE];
    size_t ns = hier->node_count + hier->point_count;
    uint64_t payload = payload_size(hier->node_count, hier->point_count);
    /* placeholder header; rewritten with the checksum once the payload is hashed */
    encode_header(hier, payload, 0, hd);
    int bad = fwrite(hd, 1, HEADER_SIZE, f.fp) != HEADER_SIZE ||
              put_array(w, hier->nodes, hier->node_count * NODE_REC, 4, NODE_REC, (size_t)-1) ||
              put_array(w, hier->splats, ns * SPLAT_REC, 4, SPLAT_REC, 3) ||
              put_array(w, hier->cov, hier->node_count * COV_REC, 8, COV_REC, (size_t)-1);
    if (!bad) {
        encode_header(hier, payload, w->hash, hd);
        bad = fseek(f.fp, 0, SEEK_SET) != 0 || fwrite(hd, 1, HEADER_SIZE, f.fp) != HEADER_SIZE;
    }
    asp_free(&hier->ctx, w);
    if (bad) {
        int e = errno;
        asp__atomic_abort(&f);
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", path, strerror(e ? e : EIO));
    }
    return asp__atomic_commit(&f, err);
}

/* ---- loading ---- */

typedef struct reader {
    FILE *fp;
    const uint8_t *mem;
    size_t size; /* total bytes; known for memory and seekable files */
    size_t pos;
    const char *name;
    uint64_t hash;
} reader;

static size_t read_bytes(reader *r, void *dst, size_t n)
{
    size_t got;
    if (r->mem) {
        got = r->size - r->pos < n ? r->size - r->pos : n;
        memcpy(dst, r->mem + r->pos, got);
    } else {
        got = fread(dst, 1, n, r->fp);
    }
    r->pos += got;
    return got;
}

static int get_array(reader *r, void *dst, size_t bytes, size_t word, size_t rec, size_t skip_word, const char *what,
                     asp_error *err)
{
    uint8_t *d = dst;
    int le = host_is_le();
    for (size_t off = 0; off < bytes; off += CHUNK) {
        size_t n = bytes - off < CHUNK ? bytes - off : CHUNK;
        if (read_bytes(r, d + off, n) != n)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': truncated at byte %zu in the %s", r->name,
                                 r->pos, what);
        r->hash = fnv1a(r->hash, d + off, n);
        if (!le)
            swap_words(d + off, n, word, rec, skip_word);
    }
    return 0;
}

static int finite_n(const float *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(p[i]))
            return 0;
    return 1;
}

static int splat_ok(const asp_hier_splat *s)
{
    return finite_n(s->center, 3) && finite_n(s->normal, 3) && finite_n(s->u, 3) && finite_n(s->v, 3) &&
           isfinite(s->a) && s->b >= 0 && s->a >= s->b;
}

/* the tree is a tree, ranges in bounds, so traversal can trust it */
static int validate(const asp_hier *h, const char *name, asp_error *err)
{
    const asp_hier_node *nd = h->nodes;
    size_t nn = h->node_count, np = h->point_count;
    if (nd[0].parent != UINT32_MAX || nd[0].depth != 0 || nd[0].first_point != 0 || nd[0].point_count != np)
        return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node 0 is not a root over all %zu points",
                             name, np);
    uint64_t claimed = 0;
    uint32_t depth = 0;
    for (size_t i = 0; i < nn; i++) {
        const asp_hier_node *n = &nd[i];
        const asp_hier_splat *s = &h->splats[i];
        if (!finite_n(n->sphere, 5) || !(n->sphere[3] >= 0) || !(n->cone_angle >= 0) ||
            !splat_ok(s) || s->index != i)
            return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node %zu has a bad value", name, i);
        if (n->depth > ASP_HIER_MAX_DEPTH || (size_t)n->first_point + n->point_count > np || n->point_count == 0)
            return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node %zu: depth %u or points %u+%u out of range",
                                 name, i, n->depth, n->first_point, n->point_count);
        depth = n->depth > depth ? n->depth : depth;
        if (n->child_count == 0) {
            if (n->point_count > h->leaf_size)
                return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': leaf %zu holds %u points, leaf size is %zu",
                                     name, i, n->point_count, h->leaf_size);
            continue;
        }
        if (n->child_count == 1 || n->child_count > 8 || n->first_child <= i ||
            (size_t)n->first_child + n->child_count > nn)
            return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node %zu: children %u+%u out of range",
                                 name, i, n->first_child, n->child_count);
        uint32_t next = n->first_point;
        for (uint32_t c = 0; c < n->child_count; c++) {
            const asp_hier_node *k = &nd[n->first_child + c];
            if (k->parent != i || k->depth != n->depth + 1 || k->first_point != next)
                return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node %u: inconsistent with parent %zu",
                                     name, n->first_child + c, i);
            next += k->point_count;
        }
        if (next != n->first_point + n->point_count)
            return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': node %zu: children hold %u points, not %u",
                                 name, i, next - n->first_point, n->point_count);
        claimed += n->child_count;
    }
    if (claimed != nn - 1)
        return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': %llu of %zu nodes are children", name,
                             (unsigned long long)claimed, nn - 1);
    if (depth != h->depth)
        return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': depth %u, header says %u", name, depth, h->depth);
    for (size_t j = 0; j < np; j++) {
        const asp_hier_splat *s = &h->splats[nn + j];
        if (!splat_ok(s) || s->index >= np)
            return asp_error_set(err, ASP_EFORMAT, "invalid hierarchy '%s': point %zu has a bad value", name, j);
    }
    return 0;
}

static int load(reader *r, const asp_context *ctx, asp_hier **out, asp_error *err)
{
    uint8_t hd[HEADER_SIZE];
    size_t got = read_bytes(r, hd, HEADER_SIZE);
    if (got != HEADER_SIZE)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': truncated header: %zu of %d bytes", r->name, got,
                             HEADER_SIZE);
    if (memcmp(hd, MAGIC, 8) != 0)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': not a hierarchy file (bad magic at byte 0)",
                             r->name);
    if (get64(hd + 120) != fnv1a(FNV_OFFSET, hd, 120))
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': header checksum mismatch (bytes 0-119)", r->name);
    uint32_t version = get32(hd + 8);
    if (version != VERSION)
        return asp_error_set(err, version > VERSION ? ASP_EUNSUPPORTED : ASP_EFORMAT,
                             "cannot read '%s': format version %u, this build reads version %d", r->name, version,
                             VERSION);
    uint64_t nodes = get64(hd + 24), points = get64(hd + 32), leaf = get64(hd + 40), payload = get64(hd + 80);
    uint32_t flags = get32(hd + 16);
    if (get32(hd + 12) != HEADER_SIZE || get32(hd + 72) != NODE_REC || get32(hd + 76) != SPLAT_REC)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': unexpected header or record sizes", r->name);
    if (points == 0 || points > (UINT32_MAX - 1) / 3 || nodes == 0 || nodes > 2 * points - 1 || leaf == 0 ||
        leaf > ASP_HIER_MAX_LEAF || (flags & ~7u))
        return asp_error_set(err, ASP_EFORMAT,
                             "cannot read '%s': header: %llu nodes, %llu points, leaf size %llu, flags %#x out of range",
                             r->name, (unsigned long long)nodes, (unsigned long long)points,
                             (unsigned long long)leaf, flags);
    if (payload != payload_size(nodes, points))
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': header: payload %llu bytes, expected %llu",
                             r->name, (unsigned long long)payload, (unsigned long long)payload_size(nodes, points));
    if (r->size != (size_t)-1 && r->size != HEADER_SIZE + payload)
        return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': file has %zu bytes, header says %llu%s", r->name,
                             r->size, (unsigned long long)(HEADER_SIZE + payload),
                             r->size < HEADER_SIZE + payload ? " (truncated)" : "");
    asp_hier *h = NULL;
    int rc = asp__hier_alloc(ctx, (size_t)nodes, (size_t)points, &h, err);
    if (rc)
        return rc;
    h->flags = flags;
    h->depth = get32(hd + 20);
    h->leaf_size = (size_t)leaf;
    for (int i = 0; i < 3; i++)
        h->origin[i] = getf64(hd + 48 + 8 * i);
    r->hash = FNV_OFFSET;
    size_t ns = h->node_count + h->point_count;
    if ((rc = get_array(r, h->nodes, h->node_count * NODE_REC, 4, NODE_REC, (size_t)-1, "nodes", err)) ||
        (rc = get_array(r, h->splats, ns * SPLAT_REC, 4, SPLAT_REC, 3, "splats", err)) ||
        (rc = get_array(r, h->cov, h->node_count * COV_REC, 8, COV_REC, (size_t)-1, "covariances", err)))
        goto fail;
    uint8_t extra;
    if (r->size == (size_t)-1 && read_bytes(r, &extra, 1) == 1) {
        rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': trailing bytes after byte %zu", r->name, r->pos - 1);
        goto fail;
    }
    if (r->hash != get64(hd + 88)) {
        rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': payload checksum mismatch (bytes %d-%llu)", r->name,
                           HEADER_SIZE, (unsigned long long)(HEADER_SIZE + payload - 1));
        goto fail;
    }
    if ((rc = validate(h, r->name, err)) != 0)
        goto fail;
    for (int i = 0; i < 3; i++) // NEEDSWORK: read the recorded frame; the root sphere is close
        h->frame.center[i] = h->origin[i] + h->nodes[0].sphere[i];
    h->frame.radius = h->nodes[0].sphere[3];
    *out = h;
    return 0;
fail:
    asp_hier_destroy(h);
    return rc;
}

int asp_hier_load(const char *path, const asp_context *ctx, asp_hier **out, asp_error *err)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    reader r = {.fp = fp, .size = (size_t)-1, .name = path};
    if (fseek(fp, 0, SEEK_END) == 0) {
        long end = ftell(fp);
        if (end >= 0)
            r.size = (size_t)end;
        if (fseek(fp, 0, SEEK_SET) != 0)
            r.size = (size_t)-1;
    }
    int rc = load(&r, ctx, out, err);
    if (rc == ASP_EFORMAT && ferror(fp))
        rc = asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(errno));
    fclose(fp);
    return rc;
}

int asp_hier_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_hier **out,
                         asp_error *err)
{
    static const uint8_t empty[1];
    reader r = {.mem = data ? data : empty, .size = data ? size : 0, .name = name ? name : "<memory>"};
    return load(&r, ctx, out, err);
}
