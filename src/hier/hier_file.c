/*
 * On-disk hierarchy, so a large model loads without rebuilding (issue 6; layout
 * in docs/hier.md): a little-endian header and payload, each with an FNV-1a 64
 * checksum. Loading reads the whole file through the shared byte reader
 * (util/byte_io.h, like .amg and .dps), checks sizes against it before
 * allocating and validates the tree, so a corrupted file is an error naming the
 * byte offset, never a crash.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hier/internal.h"
#include "amgsplat/hier_ooc.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

#define MAGIC "ASPHIER"
/*
 * Version 2 records the source point set's frame (asp_frame) at header byte
 * 96, so a hierarchy is framed exactly as its points (issue 12); its header
 * checksum moves to byte 152. Version 1 (128-byte header) still loads, framed
 * by the root bounding sphere.
 */
enum { VERSION = 2, HEADER_SIZE = 160, HEADER_V1 = 128, FRAME_AT = 96, UP_AT = 128, NODE_REC = 48, SPLAT_REC = 64,
       COV_REC = 8 * ASP_HIER_COV };
enum { CHUNK = 1 << 16 };


static int host_is_le(void)
{
    const uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 1;
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
        w->hash = asp__fnv1a64(w->hash, p, n);
        if (fwrite(p, 1, n, w->fp) != n)
            return -1;
    }
    return 0;
}

static void encode_header(const asp_hier *h, uint64_t payload, uint64_t payload_hash, uint8_t hd[HEADER_SIZE])
{
    memset(hd, 0, HEADER_SIZE);
    memcpy(hd, MAGIC, 8);
    asp__store_u32(hd + 8, VERSION);
    asp__store_u32(hd + 12, HEADER_SIZE);
    asp__store_u32(hd + 16, h->flags);
    asp__store_u32(hd + 20, h->depth);
    asp__store_u64(hd + 24, h->node_count);
    asp__store_u64(hd + 32, h->point_count);
    asp__store_u64(hd + 40, h->leaf_size);
    for (int i = 0; i < 3; i++)
        asp__store_f64(hd + 48 + 8 * i, h->origin[i]);
    asp__store_u32(hd + 72, NODE_REC);
    asp__store_u32(hd + 76, SPLAT_REC);
    asp__store_u64(hd + 80, payload);
    asp__store_u64(hd + 88, payload_hash);
    for (int i = 0; i < 3; i++)
        asp__store_f64(hd + FRAME_AT + 8 * i, h->frame.center[i]);
    asp__store_f64(hd + FRAME_AT + 24, h->frame.radius);
    /* issue 29, in bytes that were reserved (zero, "not recorded"): the source's up axis + 1, and the
       frame's box half sides (asp_frame_half_encode: the camera fits flat, wide sets by them) */
    asp__store_u32(hd + UP_AT, (uint32_t)h->frame.up + 1u);
    uint16_t q[3];
    asp_frame_half_encode(&h->frame, q);
    asp__store_u32(hd + UP_AT + 4, (uint32_t)q[0] | (uint32_t)q[1] << 16);
    asp__store_u32(hd + UP_AT + 8, q[2]);
    /* bytes 140-151 are reserved (zero); the header checksum covers everything before it */
    asp__store_u64(hd + HEADER_SIZE - 8, asp__fnv1a64(ASP__FNV1A64_START, hd, HEADER_SIZE - 8));
}

static uint64_t payload_size(uint64_t nodes, uint64_t points)
{
    return nodes * (NODE_REC + COV_REC) + (nodes + points) * SPLAT_REC;
}

/* The whole file parsed and its tree validated before it replaces the target (issue #13). */
static int hier_reads_back(const char *tmp, void *user, asp_error *err)
{
    const asp_hier *hier = user;
    asp_hier *back = NULL;
    int rc = asp_hier_load(tmp, &hier->ctx, &back, err);
    asp_hier_destroy(back);
    return rc;
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
    w->hash = ASP__FNV1A64_START;
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
    return asp__atomic_commit_checked(&f, hier_reads_back, (void *)hier, err);
}

/* ---- loading ---- */

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

/* Fails naming the byte where record i (of rec bytes, starting at base) begins. */
static int bad_record(asp__byte_reader *r, size_t base, size_t i, size_t rec, const char *msg)
{
    r->at = base + i * rec;
    return asp__byte_bad(r, msg);
}

/* the tree is a tree, ranges in bounds, so traversal can trust it; nodes start at byte hsize */
static int validate(const asp_hier *h, asp__byte_reader *r, size_t hsize)
{
    const asp_hier_node *nd = h->nodes;
    const size_t nn = h->node_count, np = h->point_count, splats = hsize + nn * NODE_REC;
    char msg[200];
    if (nd[0].parent != UINT32_MAX || nd[0].depth != 0 || nd[0].first_point != 0 || nd[0].point_count != np) {
        snprintf(msg, sizeof msg, "invalid hierarchy: node 0 is not a root over all %zu points, expected parent "
                 "none, depth 0, points 0+%zu", np, np);
        return bad_record(r, hsize, 0, NODE_REC, msg);
    }
    uint64_t claimed = 0;
    uint32_t depth = 0;
    for (size_t i = 0; i < nn; i++) {
        const asp_hier_node *n = &nd[i];
        const asp_hier_splat *s = &h->splats[i];
        if (!finite_n(n->sphere, 5) || !(n->sphere[3] >= 0) || !(n->cone_angle >= 0)) {
            snprintf(msg, sizeof msg, "invalid hierarchy: node %zu has a bad value, expected a finite sphere and cone",
                     i);
            return bad_record(r, hsize, i, NODE_REC, msg);
        }
        if (!splat_ok(s) || s->index != i) {
            snprintf(msg, sizeof msg, "invalid hierarchy: node %zu has a bad splat, expected finite axes a >= b >= 0 "
                     "and index %zu", i, i);
            return bad_record(r, splats, i, SPLAT_REC, msg);
        }
        if (n->depth > ASP_HIER_MAX_DEPTH || (size_t)n->first_point + n->point_count > np || n->point_count == 0) {
            snprintf(msg, sizeof msg, "invalid hierarchy: node %zu: depth %u or points %u+%u out of range, expected "
                     "depth <= %d and points within 0..%zu", i, n->depth, n->first_point, n->point_count,
                     ASP_HIER_MAX_DEPTH, np);
            return bad_record(r, hsize, i, NODE_REC, msg);
        }
        depth = n->depth > depth ? n->depth : depth;
        if (n->child_count == 0) {
            if (n->point_count > h->leaf_size) {
                snprintf(msg, sizeof msg, "invalid hierarchy: leaf %zu holds %u points, expected at most the leaf "
                         "size %zu", i, n->point_count, h->leaf_size);
                return bad_record(r, hsize, i, NODE_REC, msg);
            }
            continue;
        }
        if (n->child_count == 1 || n->child_count > 8 || n->first_child <= i ||
            (size_t)n->first_child + n->child_count > nn) {
            snprintf(msg, sizeof msg, "invalid hierarchy: node %zu: children %u+%u out of range, expected 2..8 "
                     "children after it, below %zu", i, n->first_child, n->child_count, nn);
            return bad_record(r, hsize, i, NODE_REC, msg);
        }
        uint32_t next = n->first_point;
        for (uint32_t c = 0; c < n->child_count; c++) {
            const asp_hier_node *k = &nd[n->first_child + c];
            if (k->parent != i || k->depth != n->depth + 1 || k->first_point != next) {
                snprintf(msg, sizeof msg, "invalid hierarchy: node %u: inconsistent with parent %zu, expected its "
                         "parent, depth %u, first point %u", n->first_child + c, i, n->depth + 1, next);
                return bad_record(r, hsize, n->first_child + c, NODE_REC, msg);
            }
            next += k->point_count;
        }
        if (next != n->first_point + n->point_count) {
            snprintf(msg, sizeof msg, "invalid hierarchy: node %zu: children hold %u points, expected %u", i,
                     next - n->first_point, n->point_count);
            return bad_record(r, hsize, i, NODE_REC, msg);
        }
        claimed += n->child_count;
    }
    if (claimed != nn - 1)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': invalid hierarchy: %llu of %zu nodes are "
                             "children, expected all but the root", r->path, (unsigned long long)claimed, nn - 1);
    if (depth != h->depth) {
        snprintf(msg, sizeof msg, "invalid hierarchy: depth %u in the nodes, the header says %u", depth, h->depth);
        r->at = 20;
        return asp__byte_bad(r, msg);
    }
    for (size_t j = 0; j < np; j++) {
        const asp_hier_splat *s = &h->splats[nn + j];
        if (!splat_ok(s) || s->index >= np) {
            snprintf(msg, sizeof msg, "invalid hierarchy: point %zu has a bad splat, expected finite axes a >= b >= 0 "
                     "and an index below %zu", j, np);
            return bad_record(r, splats, nn + j, SPLAT_REC, msg);
        }
    }
    return 0;
}

/* Copies one array of records out of the file (checked to fit), swapping words on big-endian hosts. */
static void get_array(asp__byte_reader *r, void *dst, size_t bytes, size_t word, size_t rec, size_t skip_word)
{
    memcpy(dst, r->buf + r->at, bytes);
    r->at += bytes;
    if (!host_is_le())
        swap_words(dst, bytes, word, rec, skip_word);
}

static int load(asp__byte_reader *r, const asp_context *ctx, asp_hier **out)
{
    char msg[200];
    /* a prefix of the magic is a truncated hierarchy file; anything else is not one */
    const size_t mlen = r->size < 8 ? r->size : 8;
    if (memcmp(r->buf, MAGIC, mlen) != 0)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': not a hierarchy file (bad magic at byte 0)",
                             r->path);
    if (r->size < 16)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': truncated header: %zu of at least %d bytes",
                             r->path, r->size, HEADER_V1);
    r->at = 8;
    const uint32_t version = asp__get_u32(r);
    if (version != 1 && version != VERSION)
        return asp_error_set(r->err, version > VERSION ? ASP_EUNSUPPORTED : ASP_EFORMAT,
                             "cannot read '%s': format version %u, this build reads versions 1 and %d", r->path,
                             version, VERSION);
    const size_t hsize = version == 1 ? HEADER_V1 : HEADER_SIZE;
    if (r->size < hsize)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': truncated header: %zu of %zu bytes", r->path,
                             r->size, hsize);
    r->at = hsize - 8;
    if (asp__get_u64(r) != asp__fnv1a64(ASP__FNV1A64_START, r->buf, hsize - 8))
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': header checksum mismatch (bytes 0-%zu)",
                             r->path, hsize - 9);
    r->at = 12;
    const uint32_t header = asp__get_u32(r), flags = asp__get_u32(r), depth = asp__get_u32(r);
    if (flags & ASP_HIER_STREAMED) // issue 28: the out-of-core layout has its own reader
        return asp_error_set(r->err, ASP_EUNSUPPORTED, "'%s' is a streamed hierarchy (out-of-core layout): it is read "
                             "in parts by asp_ooc_open (amgsplat render draws it)", r->path);
    const uint64_t nodes = asp__get_u64(r), points = asp__get_u64(r), leaf = asp__get_u64(r);
    double origin[3];
    for (int i = 0; i < 3; i++)
        origin[i] = asp__get_f64(r);
    const uint32_t node_rec = asp__get_u32(r), splat_rec = asp__get_u32(r);
    const uint64_t payload = asp__get_u64(r), payload_hash = asp__get_u64(r);
    if (header != hsize || node_rec != NODE_REC || splat_rec != SPLAT_REC) {
        r->at = 12;
        snprintf(msg, sizeof msg, "header: header size %u, records %u and %u bytes, expected %zu, %d and %d", header,
                 node_rec, splat_rec, hsize, NODE_REC, SPLAT_REC);
        return asp__byte_bad(r, msg);
    }
    if (points == 0 || points > (UINT32_MAX - 1) / 3 || nodes == 0 || nodes > 2 * points - 1 || leaf == 0 ||
        leaf > ASP_HIER_MAX_LEAF || (flags & ~7u)) {
        r->at = 16;
        snprintf(msg, sizeof msg, "header: %llu nodes, %llu points, leaf size %llu, flags %#x out of range, expected "
                 "1..%u points, fewer than twice as many nodes, leaf size 1..%d, flags below 8",
                 (unsigned long long)nodes, (unsigned long long)points, (unsigned long long)leaf, flags,
                 (UINT32_MAX - 1) / 3, ASP_HIER_MAX_LEAF);
        return asp__byte_bad(r, msg);
    }
    if (!(isfinite(origin[0]) && isfinite(origin[1]) && isfinite(origin[2]))) { // issue #31: a NaN origin
        r->at = 48;
        snprintf(msg, sizeof msg, "header: origin (%g, %g, %g), expected finite values", origin[0], origin[1],
                 origin[2]);
        return asp__byte_bad(r, msg);
    }
    if (payload != payload_size(nodes, points)) {
        r->at = 80;
        snprintf(msg, sizeof msg, "header: payload %llu bytes, expected %llu", (unsigned long long)payload,
                 (unsigned long long)payload_size(nodes, points));
        return asp__byte_bad(r, msg);
    }
    if (r->size - hsize != payload)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': file has %zu bytes, header says %llu%s", r->path,
                             r->size, (unsigned long long)(hsize + payload),
                             r->size - hsize < payload ? " (truncated)" : " (trailing bytes)");
    asp_frame frame;
    memset(&frame, 0, sizeof frame); // padding too: frames are compared bit for bit
    if (version >= 2) {
        r->at = FRAME_AT;
        for (int i = 0; i < 3; i++)
            frame.center[i] = asp__get_f64(r);
        frame.radius = asp__get_f64(r);
        if (!(isfinite(frame.center[0]) && isfinite(frame.center[1]) && isfinite(frame.center[2]) &&
              isfinite(frame.radius) && frame.radius >= 0)) {
            r->at = FRAME_AT;
            snprintf(msg, sizeof msg, "frame: centre (%g, %g, %g), radius %g, expected finite values and a radius >= 0",
                     frame.center[0], frame.center[1], frame.center[2], frame.radius);
            return asp__byte_bad(r, msg);
        }
        r->at = UP_AT;
        const uint32_t up = asp__get_u32(r), q01 = asp__get_u32(r), q2 = asp__get_u32(r);
        if (up > (uint32_t)ASP_UP_NEG_X + 1u || q2 > 0xffffu) {
            r->at = UP_AT;
            snprintf(msg, sizeof msg, "frame: up axis code %u, box side code %u, expected 0..%u and 0..65535", up,
                     q2, (unsigned)ASP_UP_NEG_X + 1u);
            return asp__byte_bad(r, msg);
        }
        frame.up = up ? (asp_up_axis)(up - 1u) : ASP_UP_Y; // 0: written before it was recorded
        asp_frame_half_decode(&frame, (const uint16_t[3]){(uint16_t)(q01 & 0xffffu), (uint16_t)(q01 >> 16),
                                                          (uint16_t)q2});
    }
    /* the whole payload is hashed before anything large is allocated */
    if (asp__fnv1a64(ASP__FNV1A64_START, r->buf + hsize, (size_t)payload) != payload_hash)
        return asp_error_set(r->err, ASP_EFORMAT, "cannot read '%s': payload checksum mismatch (bytes %zu-%llu)",
                             r->path, hsize, (unsigned long long)(hsize + payload - 1));
    asp_hier *h = NULL;
    int rc = asp__hier_alloc(ctx, (size_t)nodes, (size_t)points, &h, r->err);
    if (rc)
        return rc;
    h->flags = flags;
    h->depth = depth;
    h->leaf_size = (size_t)leaf;
    memcpy(h->origin, origin, sizeof origin);
    r->at = hsize;
    get_array(r, h->nodes, h->node_count * NODE_REC, 4, NODE_REC, (size_t)-1);
    get_array(r, h->splats, (h->node_count + h->point_count) * SPLAT_REC, 4, SPLAT_REC, 3);
    get_array(r, h->cov, h->node_count * COV_REC, 8, COV_REC, (size_t)-1);
    if ((rc = validate(h, r, hsize)) != 0) {
        asp_hier_destroy(h);
        return rc;
    }
    if (version >= 2) {
        memcpy(&h->frame, &frame, sizeof frame);
    } else { // version 1 predates the recorded frame: the root bounding sphere is close to it
        for (int i = 0; i < 3; i++)
            h->frame.center[i] = h->origin[i] + h->nodes[0].sphere[i];
        h->frame.radius = h->nodes[0].sphere[3];
    }
    *out = h;
    return 0;
}

int asp_hier_load(const char *path, const asp_context *ctx, asp_hier **out, asp_error *err)
{
    if (!path || !out)
        return asp_error_set(err, ASP_EINVAL, "asp_hier_load needs a path and an output");
    uint8_t *buf = NULL;
    size_t size = 0;
    int rc = asp__byte_slurp(path, ctx, &buf, &size, err);
    if (rc)
        return rc;
    rc = asp_hier_load_memory(buf, size, path, ctx, out, err);
    asp_free(ctx, buf);
    return rc;
}

int asp_hier_load_memory(const void *data, size_t size, const char *name, const asp_context *ctx, asp_hier **out,
                         asp_error *err)
{
    static const uint8_t empty[1];
    if (!out)
        return asp_error_set(err, ASP_EINVAL, "asp_hier_load_memory needs an output");
    asp__byte_reader r = {data ? data : empty, data ? size : 0, 0, name ? name : "<memory>", err};
    return load(&r, ctx, out);
}
