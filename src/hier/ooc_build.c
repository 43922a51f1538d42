/*
 * Out-of-core hierarchy build (issue 28), after Schuetz, Ohrhallinger and
 * Wimmer 2020 ("Fast out-of-core octree generation for massive point clouds",
 * the method of PotreeConverter 2): three passes over the input (bounds; a
 * counting sort's counts on a 128^3 or 256^3 grid, merged bottom up into
 * chunks that fit the memory budget; the points distributed into one file per
 * chunk), then one in-memory octree per chunk (Morton order by radix sort,
 * leaves of at most node_points, inner nodes taking one point per cell of a
 * 128^3 grid from their children's points), then the top of the tree above
 * the chunk roots from the roots' points, and the node table.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "amgsplat/point_stream.h"
#include "hier/internal.h"
#include "hier/ooc_format.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

enum { BATCH = 1 << 20, KEY_LEVELS = 21, MAX_CHUNKS = 1 << 20, FLIGHT = 4 };
#define NO_NODE UINT32_MAX

/* A node while building: cube by level and integer cell, children by proto id. */
typedef struct proto {
    uint32_t level;
    uint32_t cell[3];
    uint32_t child[8];
    uint32_t nchild;
    uint32_t point_count;
    float spacing;
    uint64_t first_point;
    uint64_t subtree;
} proto;

typedef struct chunk {
    uint32_t level, cell[3];
    uint64_t count;
    uint32_t proto;          /* the chunk root's proto id */
    uint64_t root_at, root_n; /* the root's points in the roots store */
} chunk;

typedef struct build {
    const asp_context *ctx;
    asp_error *err;
    asp_point_reader *in;
    double origin[3];
    double half; /* local cube [-half, half]^3 */
    uint64_t n;
    size_t leaf_max, chunk_max, memory;
    uint32_t grid_bits;
    chunk *chunks;
    size_t nchunks;
    proto *protos;
    size_t nprotos, cap_protos;
    char dir[4096];
    asp__atomic_file out;
    uint64_t written; /* point records written */
    asp_ooc_point *roots; /* chunk roots' points for the top */
    uint64_t nroots, cap_roots;
} build;

static int add_proto(build *b, uint32_t level, const uint32_t cell[3], uint32_t *id)
{
    if (b->nprotos == b->cap_protos) {
        size_t cap = b->cap_protos ? 2 * b->cap_protos : 1024;
        proto *p = realloc(b->protos, cap * sizeof *p);
        if (!p)
            return asp_error_set(b->err, ASP_ENOMEM, "out of memory for %zu hierarchy nodes", cap);
        b->protos = p;
        b->cap_protos = cap;
    }
    if (b->nprotos >= UINT32_MAX - 1)
        return asp_error_set(b->err, ASP_ENOMEM, "more than 2^32 - 2 hierarchy nodes");
    proto *p = &b->protos[b->nprotos];
    memset(p, 0, sizeof *p);
    p->level = level;
    memcpy(p->cell, cell, sizeof p->cell);
    *id = (uint32_t)b->nprotos++;
    return 0;
}

static void cube_of(const build *b, uint32_t level, const uint32_t cell[3], float center[3], float *half)
{
    double size = 2.0 * b->half / (double)(1u << level);
    for (int k = 0; k < 3; k++)
        center[k] = (float)(-b->half + ((double)cell[k] + 0.5) * size);
    *half = (float)(0.5 * size);
}

static uint32_t quantise(double v, double half, uint32_t bits)
{
    double t = (v + half) / (2.0 * half) * (double)(1u << bits);
    if (!(t > 0))
        return 0;
    uint32_t q = t >= (double)(1u << bits) ? (1u << bits) - 1 : (uint32_t)t;
    return q;
}

static uint64_t spread3(uint32_t v)
{
    uint64_t x = v & 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

static uint64_t morton(const float p[3], double half)
{
    return spread3(quantise(p[0], half, KEY_LEVELS)) | spread3(quantise(p[1], half, KEY_LEVELS)) << 1 |
           spread3(quantise(p[2], half, KEY_LEVELS)) << 2;
}

static int progress(build *b, const char *stage, double f)
{
    int rc = asp_progress(b->ctx, stage, f);
    return rc ? asp_error_set(b->err, rc, "conversion canceled") : 0;
}

/* ---- passes over the input ---- */

static int pass_bounds(build *b, double *xyz, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    uint64_t seen = 0;
    for (;;) {
        size_t got;
        int rc = asp_point_reader_read(b->in, xyz, NULL, BATCH, &got, b->err);
        if (rc)
            return rc;
        if (!got)
            break;
        double l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
        int finite = 1;
        int threads = asp_context_threads(b->ctx);
        (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : l0, l1, l2) reduction(max : h0, h1, h2) reduction(&& : finite)
        for (size_t i = 0; i < got; i++) {
            const double *p = xyz + 3 * i;
            finite = finite && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
            l0 = p[0] < l0 ? p[0] : l0, l1 = p[1] < l1 ? p[1] : l1, l2 = p[2] < l2 ? p[2] : l2;
            h0 = p[0] > h0 ? p[0] : h0, h1 = p[1] > h1 ? p[1] : h1, h2 = p[2] > h2 ? p[2] : h2;
        }
        lo[0] = l0, lo[1] = l1, lo[2] = l2, hi[0] = h0, hi[1] = h1, hi[2] = h2;
        for (size_t i = 0; i < got && !finite; i++)
            for (int k = 0; k < 3; k++)
                if (!isfinite(xyz[3 * i + (size_t)k]))
                    return asp_error_set(b->err, ASP_EFORMAT, "point %llu: coordinate %c is not finite",
                                         (unsigned long long)(seen + i), "xyz"[k]);
        seen += got;
        if ((rc = progress(b, "bounds", (double)seen / (double)b->n)) != 0)
            return rc;
    }
    return 0;
}

static size_t cell_index(const build *b, const double *p)
{
    uint32_t q[3];
    for (int k = 0; k < 3; k++)
        q[k] = quantise(p[k] - b->origin[k], b->half, b->grid_bits);
    return ((size_t)q[2] << (2 * b->grid_bits)) | ((size_t)q[1] << b->grid_bits) | q[0];
}

static int pass_count(build *b, double *xyz, uint32_t *cells, uint32_t *counts, double *max_dist2)
{
    uint64_t seen = 0;
    double m = 0;
    int threads = asp_context_threads(b->ctx);
    (void)threads;
    int rc = asp_point_reader_rewind(b->in, b->err);
    while (!rc) {
        size_t got;
        if ((rc = asp_point_reader_read(b->in, xyz, NULL, BATCH, &got, b->err)) != 0 || !got)
            break;
        // cells in parallel, then one thread counts (the grid is shared)
#pragma omp parallel for schedule(static) num_threads(threads) reduction(max : m)
        for (size_t i = 0; i < got; i++) {
            const double *p = xyz + 3 * i;
            cells[i] = (uint32_t)cell_index(b, p);
            double d = 0;
            for (int k = 0; k < 3; k++)
                d += (p[k] - b->origin[k]) * (p[k] - b->origin[k]);
            m = d > m ? d : m;
        }
        for (size_t i = 0; i < got; i++)
            counts[cells[i]] += counts[cells[i]] != UINT32_MAX; // a cell of 2^32 points is split by the octree anyway
        seen += got;
        rc = progress(b, "count", (double)seen / (double)b->n);
    }
    *max_dist2 = m;
    return rc;
}

/*
 * Chunks: the counting grid's pyramid (each level sums 8 cells of the level
 * below) descended from the root; a cell within chunk_max points becomes a
 * chunk (every finest cell below it maps to it), a larger one a top node of
 * the hierarchy whose non-empty octants are visited in turn.
 */
typedef struct pyramid {
    uint64_t *level[9];
    uint32_t bits;
} pyramid;

static uint64_t pyr_count(const pyramid *p, uint32_t l, const uint32_t c[3])
{
    return p->level[l][((size_t)c[2] << (2 * l)) | ((size_t)c[1] << l) | c[0]];
}

static int descend(build *b, const pyramid *pyr, uint32_t *lut, uint32_t level, const uint32_t cell[3], uint32_t *id)
{
    uint64_t count = pyr_count(pyr, level, cell);
    int rc = add_proto(b, level, cell, id);
    if (rc)
        return rc;
    if (count <= b->chunk_max || level == pyr->bits) {
        if (b->nchunks >= MAX_CHUNKS)
            return asp_error_set(b->err, ASP_EINVAL, "more than %d chunks: raise --memory", MAX_CHUNKS);
        chunk *c = &b->chunks[b->nchunks];
        memset(c, 0, sizeof *c);
        c->level = level;
        memcpy(c->cell, cell, sizeof c->cell);
        c->count = count;
        c->proto = *id;
        uint32_t span = 1u << (pyr->bits - level);
        for (uint32_t z = 0; z < span; z++)
            for (uint32_t y = 0; y < span; y++)
                for (uint32_t x = 0; x < span; x++) {
                    size_t g = ((size_t)(cell[2] * span + z) << (2 * pyr->bits)) |
                               ((size_t)(cell[1] * span + y) << pyr->bits) | (cell[0] * span + x);
                    lut[g] = (uint32_t)b->nchunks;
                }
        b->nchunks++;
        return 0;
    }
    for (uint32_t o = 0; o < 8; o++) {
        uint32_t cc[3] = {2 * cell[0] + (o & 1), 2 * cell[1] + (o >> 1 & 1), 2 * cell[2] + (o >> 2 & 1)};
        if (!pyr_count(pyr, level + 1, cc))
            continue;
        uint32_t child;
        if ((rc = descend(b, pyr, lut, level + 1, cc, &child)) != 0)
            return rc;
        proto *p = &b->protos[*id];
        p->child[p->nchild++] = child;
    }
    return 0;
}

static int make_chunks(build *b, uint32_t *counts, uint32_t *lut)
{
    pyramid pyr = {.bits = b->grid_bits};
    int rc = 0;
    for (uint32_t l = 0; l <= pyr.bits && !rc; l++)
        if (!(pyr.level[l] = calloc((size_t)1 << (3 * l), sizeof(uint64_t))))
            rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory for the counting grid");
    if (!rc) {
        size_t cells = (size_t)1 << (3 * pyr.bits);
        for (size_t i = 0; i < cells; i++)
            pyr.level[pyr.bits][i] = counts[i];
        for (uint32_t l = pyr.bits; l > 0; l--) {
            uint32_t side = 1u << l;
            for (uint32_t z = 0; z < side; z++)
                for (uint32_t y = 0; y < side; y++)
                    for (uint32_t x = 0; x < side; x++) {
                        uint32_t up = l - 1;
                        pyr.level[up][((size_t)(z / 2) << (2 * up)) | ((size_t)(y / 2) << up) | (x / 2)] +=
                            pyr.level[l][((size_t)z << (2 * l)) | ((size_t)y << l) | x];
                    }
        }
        b->chunks = calloc(MAX_CHUNKS, sizeof *b->chunks);
        if (!b->chunks)
            rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory for the chunk table");
    }
    uint32_t root;
    if (!rc)
        rc = descend(b, &pyr, lut, 0, (const uint32_t[3]){0, 0, 0}, &root);
    for (uint32_t l = 0; l <= pyr.bits; l++)
        free(pyr.level[l]);
    return rc;
}

static void chunk_path(const build *b, size_t c, char *out, size_t cap)
{
    snprintf(out, cap, "%s/chunk_%06zu.bin", b->dir, c);
}

static int flush_chunk(build *b, size_t c, const asp_ooc_point *recs, size_t n)
{
    char path[4200];
    chunk_path(b, c, path, sizeof path);
    FILE *fp = fopen(path, "ab");
    if (!fp)
        return asp_error_set(b->err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    int bad = fwrite(recs, sizeof *recs, n, fp) != n;
    bad |= fclose(fp) != 0;
    return bad ? asp_error_set(b->err, ASP_EIO, "cannot write '%s': %s", path, strerror(errno)) : 0;
}

static int pass_distribute(build *b, double *xyz, uint8_t *rgba, uint32_t *cells, asp_ooc_point *recs,
                           const uint32_t *lut)
{
    int threads = asp_context_threads(b->ctx);
    (void)threads;
    size_t per = (b->memory / 8) / sizeof(asp_ooc_point) / b->nchunks;
    per = per < 4096 ? 4096 : per > (1u << 16) ? (1u << 16) : per;
    asp_ooc_point *buf = malloc(per * b->nchunks * sizeof *buf);
    size_t *fill = calloc(b->nchunks, sizeof *fill);
    int rc = !buf || !fill ? asp_error_set(b->err, ASP_ENOMEM, "out of memory for %zu chunk buffers", b->nchunks) : 0;
    uint64_t seen = 0;
    if (!rc)
        rc = asp_point_reader_rewind(b->in, b->err);
    while (!rc) {
        size_t got;
        if ((rc = asp_point_reader_read(b->in, xyz, rgba, BATCH, &got, b->err)) != 0 || !got)
            break;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (size_t i = 0; i < got; i++) {
            const double *p = xyz + 3 * i;
            cells[i] = lut[cell_index(b, p)];
            for (int k = 0; k < 3; k++)
                recs[i].position[k] = (float)(p[k] - b->origin[k]);
            memcpy(recs[i].color, rgba + 4 * i, 4);
        }
        for (size_t i = 0; i < got && !rc; i++) {
            uint32_t c = cells[i];
            buf[(size_t)c * per + fill[c]] = recs[i];
            if (++fill[c] == per) {
                rc = flush_chunk(b, c, buf + (size_t)c * per, per);
                fill[c] = 0;
            }
        }
        seen += got;
        if (!rc)
            rc = progress(b, "distribute", (double)seen / (double)b->n);
    }
    for (size_t c = 0; c < b->nchunks && !rc; c++)
        if (fill[c])
            rc = flush_chunk(b, c, buf + c * per, fill[c]);
    free(buf);
    free(fill);
    return rc;
}

/* ---- one chunk's octree ---- */

typedef struct lnode {
    uint32_t level, cell[3];
    uint32_t child[8], nchild; /* local ids */
    uint32_t *list;            /* candidate and own points (indices), owner tells which are still its */
    size_t nlist;
    float spacing;             /* see leaf_spacing and sample */
} lnode;

typedef struct scratch {
    uint64_t *bits; /* SAMPLE_GRID^3 occupancy bits */
} scratch;

typedef struct sub {
    const build *b;
    asp_ooc_point *pts;
    uint32_t *owner;
    lnode *nodes;
    size_t nnodes, cap;
    unsigned sorted_from; /* keys are sorted on bits from here up */
    int failed;
} sub;

static uint32_t add_lnode(sub *s, uint32_t level, const uint32_t cell[3])
{
    if (s->nnodes == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 256;
        lnode *p = realloc(s->nodes, cap * sizeof *p);
        if (!p) {
            s->failed = 1;
            return NO_NODE;
        }
        s->nodes = p;
        s->cap = cap;
    }
    lnode *n = &s->nodes[s->nnodes];
    memset(n, 0, sizeof *n);
    n->level = level;
    memcpy(n->cell, cell, sizeof n->cell);
    return (uint32_t)s->nnodes++;
}

static uint64_t gcd(uint64_t a, uint64_t b)
{
    while (b) {
        uint64_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/*
 * Grid subsampling (Schuetz et al. 2020, 4.3, their "random" sampler): the
 * children's remaining points in a fixed pseudo-random order (a stride
 * coprime to their number, so no corner of a grid cell is favoured), the first
 * in each empty cell of the parent's 128^3 grid moves up.
 */
static void sample(sub *s, uint32_t id, scratch *sc)
{
    lnode *p = &s->nodes[id];
    size_t total = 0;
    for (uint32_t c = 0; c < p->nchild; c++)
        total += s->nodes[p->child[c]].nlist;
    p->list = malloc((total ? total : 1) * sizeof *p->list);
    if (!p->list) {
        s->failed = 1;
        return;
    }
    float center[3], half;
    cube_of(s->b, p->level, p->cell, center, &half);
    const float inv = (float)ASP__OOC_SAMPLE_GRID / (2.0f * half);
    const float lo[3] = {center[0] - half, center[1] - half, center[2] - half};
    for (uint32_t c = 0; c < p->nchild; c++) {
        const lnode *ch = &s->nodes[p->child[c]];
        uint32_t cid = p->child[c];
        size_t m = ch->nlist;
        uint64_t stride = m > 2 ? (uint64_t)((double)m * 0.6180339887) | 1 : 1;
        while (gcd(stride, m) != 1)
            stride += 2;
        uint64_t k = 0;
        for (size_t j = 0; j < m; j++, k += stride) {
            if (k >= m)
                k -= m;
            uint32_t i = ch->list[k];
            if (s->owner[i] != cid)
                continue;
            const float *q = s->pts[i].position;
            size_t cell = 0;
            for (int a = 2; a >= 0; a--) {
                int v = (int)((q[a] - lo[a]) * inv);
                v = v < 0 ? 0 : v > ASP__OOC_SAMPLE_GRID - 1 ? ASP__OOC_SAMPLE_GRID - 1 : v;
                cell = cell * ASP__OOC_SAMPLE_GRID + (size_t)v;
            }
            uint64_t bit = 1ull << (cell & 63);
            if (sc->bits[cell >> 6] & bit)
                continue;
            sc->bits[cell >> 6] |= bit;
            s->owner[i] = id;
            p->list[p->nlist++] = i;
        }
    }
    // one point per occupied grid cell: the cell size, shrunk by the ancestors' share (1/4 + 1/16 + ... on a surface)
    p->spacing = 2.0f * half / (float)ASP__OOC_SAMPLE_GRID * 0.866f;
    // 256 KiB once per inner node: cheaper than remembering the cells
    memset(sc->bits, 0, (size_t)ASP__OOC_SAMPLE_GRID * ASP__OOC_SAMPLE_GRID * ASP__OOC_SAMPLE_GRID / 8);
}

/*
 * LSD radix sort of (key, index) pairs on key bits [lo, hi): the octants of
 * the levels those bits hold come out in order; bits below lo stay unsorted.
 */
static int radix_sort(uint64_t *keys, uint32_t *idx, size_t n, unsigned lo, unsigned hi)
{
    uint64_t *k2 = malloc(n * sizeof *k2);
    uint32_t *i2 = malloc(n * sizeof *i2);
    if (!k2 || !i2) {
        free(k2);
        free(i2);
        return ASP_ENOMEM;
    }
    for (unsigned shift = lo; shift < hi; shift += 8) {
        size_t count[257] = {0};
        uint64_t mask = hi - shift >= 8 ? 255 : (1u << (hi - shift)) - 1;
        for (size_t i = 0; i < n; i++)
            count[((keys[i] >> shift) & mask) + 1]++;
        for (int d = 0; d < 256; d++)
            count[d + 1] += count[d];
        for (size_t i = 0; i < n; i++) {
            size_t at = count[(keys[i] >> shift) & mask]++;
            k2[at] = keys[i];
            i2[at] = idx[i];
        }
        memcpy(keys, k2, n * sizeof *keys);
        memcpy(idx, i2, n * sizeof *idx);
    }
    free(k2);
    free(i2);
    return 0;
}

/*
 * The first sort orders a chunk's keys only as deep as its octree is likely
 * to go (surfaces: a quarter of the points per level); a node still too big
 * below that depth sorts its own range on the next levels' bits.
 */
static int sort_deeper(sub *s, uint64_t *keys, size_t a, size_t b, unsigned shift)
{
    size_t m = b - a;
    uint32_t *idx = malloc(m * sizeof *idx);
    asp_ooc_point *tmp = malloc(m * sizeof *tmp);
    unsigned lo = shift + 3 > 24 ? shift + 3 - 24 : 0;
    int rc = !idx || !tmp ? ASP_ENOMEM : 0;
    if (!rc) {
        for (size_t i = 0; i < m; i++)
            idx[i] = (uint32_t)i;
        rc = radix_sort(keys + a, idx, m, lo, shift + 3);
    }
    if (!rc) {
        for (size_t i = 0; i < m; i++)
            tmp[i] = s->pts[a + idx[i]];
        memcpy(s->pts + a, tmp, m * sizeof *tmp);
    }
    free(idx);
    free(tmp);
    return rc;
}

/*
 * A leaf holds all its cube's points but those its ancestors took. Its
 * surface area is estimated by the occupied cells of a 64^3 grid (the parent's
 * sampling grid), so a cube the surface only grazes is not taken for a full
 * one; the spacing is then sqrt(area / points).
 */
static float leaf_spacing(const sub *s, const lnode *n, size_t a, size_t b, scratch *sc)
{
    enum { G = 64 };
    float center[3], half;
    cube_of(s->b, n->level, n->cell, center, &half);
    const float inv = (float)G / (2.0f * half);
    size_t occupied = 0;
    for (size_t i = a; i < b; i++) {
        const float *q = s->pts[i].position;
        size_t cell = 0;
        for (int k = 2; k >= 0; k--) {
            int v = (int)((q[k] - (center[k] - half)) * inv);
            v = v < 0 ? 0 : v > G - 1 ? G - 1 : v;
            cell = cell * G + (size_t)v;
        }
        uint64_t bit = 1ull << (cell & 63);
        occupied += !(sc->bits[cell >> 6] & bit);
        sc->bits[cell >> 6] |= bit;
    }
    memset(sc->bits, 0, (size_t)G * G * G / 8);
    double cell = 2.0 * half / G, area = (double)occupied * cell * cell;
    return (float)sqrt(area / (double)(b - a > 0 ? b - a : 1));
}

/* Sorted keys [a, b) of one cube at level; returns its local id. Children are built and sampled first. */
static uint32_t split(sub *s, uint64_t *keys, size_t a, size_t b, uint32_t level, const uint32_t cell[3],
                      scratch *sc)
{
    uint32_t id = add_lnode(s, level, cell);
    if (id == NO_NODE)
        return NO_NODE;
    if (b - a <= s->b->leaf_max || level >= KEY_LEVELS) {
        lnode *n = &s->nodes[id];
        n->list = malloc((b - a) * sizeof *n->list);
        if (!n->list) {
            s->failed = 1;
            return id;
        }
        for (size_t i = a; i < b; i++) {
            n->list[i - a] = (uint32_t)i;
            s->owner[i] = id;
        }
        n->nlist = b - a;
        n->spacing = leaf_spacing(s, n, a, b, sc);
        return id;
    }
    unsigned shift = 3 * (KEY_LEVELS - 1 - level);
    if (shift < s->sorted_from) {
        if (sort_deeper(s, keys, a, b, shift)) {
            s->failed = 1;
            return id;
        }
    }
    size_t lo = a;
    for (uint32_t o = 0; o < 8 && lo < b; o++) {
        size_t hi = lo;
        // keys are sorted: the octant's run ends at the first key with a larger digit
        size_t l2 = lo, r2 = b;
        while (l2 < r2) {
            size_t mid = l2 + (r2 - l2) / 2;
            if (((keys[mid] >> shift) & 7) <= o)
                l2 = mid + 1;
            else
                r2 = mid;
        }
        hi = l2;
        if (hi > lo) {
            uint32_t cc[3] = {2 * cell[0] + (o & 1), 2 * cell[1] + (o >> 1 & 1), 2 * cell[2] + (o >> 2 & 1)};
            uint32_t child = split(s, keys, lo, hi, level + 1, cc, sc);
            if (child == NO_NODE || s->failed)
                return id;
            lnode *n = &s->nodes[id];
            n->child[n->nchild++] = child;
        }
        lo = hi;
    }
    sample(s, id, sc);
    return id;
}

typedef struct chunk_result {
    sub s;
    int rc;
} chunk_result;

static void free_sub(sub *s)
{
    for (size_t i = 0; i < s->nnodes; i++)
        free(s->nodes[i].list);
    free(s->nodes);
    free(s->pts);
    free(s->owner);
    memset(s, 0, sizeof *s);
}

static int index_chunk(const build *b, size_t c, chunk_result *out, scratch *sc, asp_error *err)
{
    const chunk *ch = &b->chunks[c];
    char path[4200];
    chunk_path(b, c, path, sizeof path);
    sub *s = &out->s;
    memset(s, 0, sizeof *s);
    s->b = b;
    size_t n = (size_t)ch->count;
    asp_ooc_point *raw = malloc((n ? n : 1) * sizeof *raw);
    uint64_t *keys = malloc((n ? n : 1) * sizeof *keys);
    uint32_t *idx = malloc((n ? n : 1) * sizeof *idx);
    s->pts = malloc((n ? n : 1) * sizeof *s->pts);
    s->owner = malloc((n ? n : 1) * sizeof *s->owner);
    int rc = 0;
    if (!raw || !keys || !idx || !s->pts || !s->owner)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for chunk %zu of %zu points", c, n);
    if (!rc) {
        FILE *fp = fopen(path, "rb");
        if (!fp)
            rc = asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
        else {
            if (fread(raw, sizeof *raw, n, fp) != n)
                rc = asp_error_set(err, ASP_EIO, "cannot read '%s': %zu points expected", path, n);
            fclose(fp);
        }
        remove(path); // read once; the disk holds the input, these and the output at most
    }
    if (!rc) {
        for (size_t i = 0; i < n; i++) {
            keys[i] = morton(raw[i].position, b->half);
            idx[i] = (uint32_t)i;
        }
        unsigned hi = 3 * (KEY_LEVELS - ch->level), levels = 2;
        for (double m = (double)n / (double)b->leaf_max; m > 1; m /= 4)
            levels++;
        s->sorted_from = hi > 3 * levels ? hi - 3 * levels : 0;
        if (radix_sort(keys, idx, n, s->sorted_from, hi))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory sorting chunk %zu", c);
    }
    if (!rc) {
        for (size_t i = 0; i < n; i++)
            s->pts[i] = raw[idx[i]];
        free(raw), raw = NULL;
        free(idx), idx = NULL;
        split(s, keys, 0, n, ch->level, ch->cell, sc);
        if (s->failed)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory building chunk %zu", c);
    }
    free(raw);
    free(idx);
    free(keys);
    out->rc = rc;
    return rc;
}

static int write_points(build *b, const asp_ooc_point *pts, const uint32_t *owner, const uint32_t *list, size_t nlist,
                        uint32_t id, proto *p)
{
    enum { OUT = 4096 };
    asp_ooc_point buf[OUT];
    size_t fill = 0;
    p->first_point = b->written;
    p->point_count = 0;
    for (size_t j = 0; j < nlist; j++) {
        uint32_t i = list[j];
        if (owner[i] != id)
            continue;
        buf[fill++] = pts[i];
        if (fill == OUT || j + 1 == nlist) {
            if (fwrite(buf, sizeof *buf, fill, b->out.fp) != fill)
                return asp_error_set(b->err, ASP_EIO, "cannot write '%s': %s", b->out.tmp, strerror(errno));
            b->written += fill;
            p->point_count += (uint32_t)fill;
            fill = 0;
        }
    }
    if (fill) {
        if (fwrite(buf, sizeof *buf, fill, b->out.fp) != fill)
            return asp_error_set(b->err, ASP_EIO, "cannot write '%s': %s", b->out.tmp, strerror(errno));
        b->written += fill;
        p->point_count += (uint32_t)fill;
    }
    return 0;
}

/* A built chunk: its nodes become protos (the root fills the chunk's), non-root points go to the file. */
static int emit_chunk(build *b, size_t c, sub *s)
{
    uint32_t *map = malloc(s->nnodes * sizeof *map);
    if (!map)
        return asp_error_set(b->err, ASP_ENOMEM, "out of memory");
    map[0] = b->chunks[c].proto;
    int rc = 0;
    for (size_t i = 1; i < s->nnodes && !rc; i++)
        rc = add_proto(b, s->nodes[i].level, s->nodes[i].cell, &map[i]);
    for (size_t i = 0; i < s->nnodes && !rc; i++) {
        proto *p = &b->protos[map[i]];
        p->nchild = s->nodes[i].nchild;
        p->spacing = s->nodes[i].spacing;
        for (uint32_t k = 0; k < p->nchild; k++)
            p->child[k] = map[s->nodes[i].child[k]];
        if (i > 0)
            rc = write_points(b, s->pts, s->owner, s->nodes[i].list, s->nodes[i].nlist, (uint32_t)i, p);
    }
    // the root's points wait in memory for the top of the tree to take its samples
    size_t own = 0;
    const lnode *r = &s->nodes[0];
    for (size_t j = 0; j < r->nlist; j++)
        own += s->owner[r->list[j]] == 0;
    if (!rc && b->nroots + own > b->cap_roots) {
        uint64_t cap = b->cap_roots ? 2 * b->cap_roots : 1 << 16;
        while (cap < b->nroots + own)
            cap *= 2;
        asp_ooc_point *p = realloc(b->roots, (size_t)cap * sizeof *p);
        if (!p)
            rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory for the chunk roots' points");
        else
            b->roots = p, b->cap_roots = cap;
    }
    if (!rc) {
        b->chunks[c].root_at = b->nroots;
        for (size_t j = 0; j < r->nlist; j++)
            if (s->owner[r->list[j]] == 0)
                b->roots[b->nroots++] = s->pts[r->list[j]];
        b->chunks[c].root_n = b->nroots - b->chunks[c].root_at;
    }
    free(map);
    return rc;
}

/*
 * The top: the protos above the chunk roots sample the roots' points as the
 * chunks' inner nodes sample theirs. The roots store is one more "chunk" whose
 * leaves are the chunk roots.
 */
static int build_top(build *b, scratch *sc)
{
    sub s = {.b = b, .pts = b->roots};
    size_t n = (size_t)b->nroots;
    s.owner = malloc((n ? n : 1) * sizeof *s.owner);
    uint32_t *local = malloc(b->nprotos * sizeof *local); // proto -> local id, for the top and chunk roots
    uint32_t *back = NULL;
    int rc = !s.owner || !local ? asp_error_set(b->err, ASP_ENOMEM, "out of memory for the top") : 0;
    if (!rc) {
        for (size_t i = 0; i < b->nprotos; i++)
            local[i] = NO_NODE;
        // the protos of top nodes and chunk roots come first (made by descend); chunk roots are leaves here
        int *is_root = calloc(b->nprotos, sizeof *is_root);
        if (!is_root)
            rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory");
        for (size_t c = 0; c < b->nchunks && !rc; c++)
            is_root[b->chunks[c].proto] = (int)c + 1;
        size_t top = 0;
        for (size_t c = 0; c < b->nchunks; c++)
            top = b->chunks[c].proto + 1 > top ? b->chunks[c].proto + 1 : top;
        back = malloc((top ? top : 1) * sizeof *back);
        if (!back && !rc)
            rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory");
        for (size_t i = 0; i < top && !rc; i++) {
            uint32_t id = add_lnode(&s, b->protos[i].level, b->protos[i].cell);
            if (id == NO_NODE) {
                rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory");
                break;
            }
            local[i] = id;
            back[id] = (uint32_t)i;
            if (is_root[i]) {
                const chunk *ch = &b->chunks[is_root[i] - 1];
                lnode *l = &s.nodes[id];
                l->list = malloc((ch->root_n ? ch->root_n : 1) * sizeof *l->list);
                if (!l->list) {
                    rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory");
                    break;
                }
                for (uint64_t j = 0; j < ch->root_n; j++) {
                    l->list[j] = (uint32_t)(ch->root_at + j);
                    s.owner[ch->root_at + j] = id;
                }
                l->nlist = (size_t)ch->root_n;
            }
        }
        // children after parents in descend's preorder: a reverse sweep samples bottom up
        for (size_t i = top; i-- > 0 && !rc;) {
            if (is_root[i])
                continue;
            lnode *l = &s.nodes[local[i]];
            l->nchild = b->protos[i].nchild;
            for (uint32_t k = 0; k < l->nchild; k++)
                l->child[k] = local[b->protos[i].child[k]];
            sample(&s, local[i], sc);
            b->protos[i].spacing = s.nodes[local[i]].spacing;
            if (s.failed)
                rc = asp_error_set(b->err, ASP_ENOMEM, "out of memory for the top");
        }
        for (size_t id = 0; id < s.nnodes && !rc; id++)
            rc = write_points(b, s.pts, s.owner, s.nodes[id].list, s.nodes[id].nlist, (uint32_t)id,
                              &b->protos[back[id]]);
        free(is_root);
    }
    s.pts = NULL; // b->roots, freed by the caller
    free_sub(&s);
    free(local);
    free(back);
    return rc;
}

/* ---- the node table ---- */

static uint64_t subtree_of(build *b, uint32_t id)
{
    proto *p = &b->protos[id];
    uint64_t s = p->point_count;
    for (uint32_t k = 0; k < p->nchild; k++)
        s += subtree_of(b, p->child[k]);
    p->subtree = s;
    return s;
}

static int write_table(build *b, uint32_t root, const asp_frame *frame, double radius, asp_ooc_build_stats *st)
{
    size_t n = b->nprotos;
    uint32_t *order = malloc(n * sizeof *order);
    asp_ooc_node *nodes = calloc(n, sizeof *nodes);
    if (!order || !nodes) {
        free(order);
        free(nodes);
        return asp_error_set(b->err, ASP_ENOMEM, "out of memory for %zu nodes", n);
    }
    subtree_of(b, root);
    // breadth first: children contiguous, after their parent
    size_t head = 0, tail = 0;
    order[tail++] = root;
    uint32_t depth = 0;
    nodes[0].parent = UINT32_MAX;
    while (head < tail) {
        uint32_t id = (uint32_t)head;
        const proto *p = &b->protos[order[head++]];
        asp_ooc_node *o = &nodes[id];
        cube_of(b, p->level, p->cell, o->center, &o->half);
        o->spacing = p->spacing > 0 ? p->spacing : o->half; // > 0 always; a guard for an empty leaf
        o->first_child = p->nchild ? (uint32_t)tail : 0;
        o->child_count = p->nchild;
        o->first_point = p->first_point;
        o->point_count = p->point_count;
        o->depth = p->level;
        o->subtree_points = p->subtree;
        depth = p->level > depth ? p->level : depth;
        for (uint32_t k = 0; k < p->nchild; k++) {
            nodes[tail].parent = id;
            order[tail++] = p->child[k];
        }
    }
    // little endian on disk; a big-endian host would swap the words here (NEEDSWORK: not built there)
    uint64_t table_at = (uint64_t)ASP__OOC_HEADER + b->written * ASP__OOC_POINT_REC;
    uint64_t hash = asp__fnv1a64(ASP__FNV1A64_START, nodes, n * sizeof *nodes);
    int rc = 0;
    if (fwrite(nodes, sizeof *nodes, n, b->out.fp) != n)
        rc = asp_error_set(b->err, ASP_EIO, "cannot write '%s': %s", b->out.tmp, strerror(errno));
    uint8_t hd[ASP__OOC_HEADER];
    memset(hd, 0, sizeof hd);
    memcpy(hd, "ASPHIER", 8);
    asp__store_u32(hd + 8, ASP__OOC_VERSION);
    asp__store_u32(hd + 12, ASP__OOC_HEADER);
    asp__store_u32(hd + 16, ASP_HIER_HAS_COLORS | ASP_HIER_UNORIENTED | ASP_HIER_STREAMED);
    asp__store_u32(hd + 20, depth);
    asp__store_u64(hd + 24, n);
    asp__store_u64(hd + 32, b->written);
    asp__store_u64(hd + 40, b->leaf_max);
    for (int k = 0; k < 3; k++)
        asp__store_f64(hd + 48 + 8 * k, b->origin[k]);
    asp__store_u32(hd + 72, ASP__OOC_NODE_REC);
    asp__store_u32(hd + 76, ASP__OOC_POINT_REC);
    asp__store_u64(hd + ASP__OOC_TABLE_AT, table_at);
    asp__store_u64(hd + ASP__OOC_TABLE_HASH, hash);
    for (int k = 0; k < 3; k++)
        asp__store_f64(hd + ASP__OOC_FRAME_AT + 8 * k, frame->center[k]);
    asp__store_f64(hd + ASP__OOC_FRAME_AT + 24, frame->radius);
    asp__store_f64(hd + ASP__OOC_RADIUS_AT, radius);
    asp__store_u32(hd + ASP__OOC_UP_AT, (uint32_t)frame->up + 1u);
    uint16_t q[3]; // the frame's box, as the in-memory layout keeps it after the up axis
    asp_frame_half_encode(frame, q);
    asp__store_u32(hd + ASP__OOC_HALF_AT, (uint32_t)q[0] | (uint32_t)q[1] << 16);
    asp__store_u32(hd + ASP__OOC_HALF_AT + 4, q[2]);
    asp__store_u64(hd + ASP__OOC_HEADER - 8, asp__fnv1a64(ASP__FNV1A64_START, hd, ASP__OOC_HEADER - 8));
    if (!rc && (fseeko(b->out.fp, 0, SEEK_SET) != 0 || fwrite(hd, 1, sizeof hd, b->out.fp) != sizeof hd))
        rc = asp_error_set(b->err, ASP_EIO, "cannot write '%s': %s", b->out.tmp, strerror(errno));
    if (st) {
        st->nodes = n;
        st->depth = depth;
    }
    free(order);
    free(nodes);
    return rc;
}

static int reads_back(const char *tmp, void *user, asp_error *err)
{
    asp_ooc *o = NULL;
    int rc = asp_ooc_open(tmp, user, &o, err);
    asp_ooc_close(o);
    return rc;
}

static void remove_dir(build *b)
{
    char path[4200];
    for (size_t c = 0; c < b->nchunks; c++) {
        chunk_path(b, c, path, sizeof path);
        remove(path);
    }
    rmdir(b->dir);
}

int asp_ooc_build(const char *in, const char *out, const asp_ooc_build_desc *desc, const asp_context *ctx,
                  asp_ooc_build_stats *stats, asp_error *err)
{
    ASP_ASSERT(in && out);
    asp_ooc_build_desc d = desc ? *desc : (asp_ooc_build_desc){0};
    build b = {.ctx = ctx, .err = err};
    b.memory = d.memory ? d.memory : (size_t)2 << 30;
    b.leaf_max = d.node_points ? d.node_points : 32768;
    if (b.memory < ((size_t)64 << 20))
        return asp_error_set(err, ASP_EINVAL, "memory budget %zu bytes: expected at least 64 MiB", b.memory);
    asp_ooc_build_stats st;
    memset(&st, 0, sizeof st);
    double t0 = asp_time_now();
    int rc = asp_point_reader_open(in, ctx, &b.in, err);
    if (rc)
        return rc;
    b.n = asp_point_reader_count(b.in);
    if (b.n == 0) {
        asp_point_reader_close(b.in);
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' has no points", in);
    }
    int threads = asp_context_threads(ctx);
    /*
     * Working set: up to FLIGHT chunks in flight take about 56 bytes a point
     * (records twice while sorting, keys twice, indices, owners), half the
     * budget; the counting grid, the chunk buffers and the roots' points share
     * the rest.
     */
    b.chunk_max = b.memory / 2 / FLIGHT / 56;
    if (threads > FLIGHT) // chunks are sized for FLIGHT at once, whatever the thread count, so the file is too
        threads = FLIGHT;
    b.grid_bits = b.n < 100000000u ? 7 : 8;
    st.grid = 1u << b.grid_bits;
    double *xyz = malloc(sizeof(double) * 3 * BATCH);
    uint32_t *cells_buf = malloc(sizeof(uint32_t) * BATCH);
    asp_ooc_point *recs = malloc(sizeof(asp_ooc_point) * BATCH);
    uint8_t *rgba = malloc((size_t)4 * BATCH);
    size_t cells = (size_t)1 << (3 * b.grid_bits);
    uint32_t *counts = calloc(cells, sizeof *counts), *lut = malloc(cells * sizeof *lut);
    scratch *sc = calloc((size_t)threads, sizeof *sc);
    chunk_result *res = calloc((size_t)threads, sizeof *res);
    if (!xyz || !rgba || !cells_buf || !recs || !counts || !lut || !sc || !res)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the conversion buffers");
    for (int t = 0; t < threads && !rc; t++)
        if (!(sc[t].bits = calloc((size_t)ASP__OOC_SAMPLE_GRID * ASP__OOC_SAMPLE_GRID * ASP__OOC_SAMPLE_GRID / 64,
                                  sizeof(uint64_t))))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory");
    double lo[3], hi[3];
    if (!rc)
        rc = pass_bounds(&b, xyz, lo, hi);
    st.seconds_bounds = asp_time_now() - t0;
    asp_frame frame;
    memset(&frame, 0, sizeof frame);
    // the up axis as a point file's load gives it (issue 29): z for LAS (ASPRS LAS 1.4: Z is the
    // elevation of its CRS), else y
    asp_file_type ftype;
    if (asp_file_recognise(in, &ftype, NULL) == 0 && (strcmp(ftype.format, "las") == 0 || strcmp(ftype.format, "laz") == 0))
        frame.up = ASP_UP_Z;
    double full_radius = 0;
    if (!rc) {
        double ext = 0;
        for (int k = 0; k < 3; k++) {
            b.origin[k] = 0.5 * (lo[k] + hi[k]);
            ext = hi[k] - lo[k] > ext ? hi[k] - lo[k] : ext;
        }
        // a hair larger than the bounds so the largest coordinate quantises inside the cube
        b.half = ext > 0 ? 0.5 * ext * (1 + 1e-6) + 1e-9 * fabs(b.origin[0] + b.origin[1] + b.origin[2]) : 1.0;
        double md2;
        double t1 = asp_time_now();
        rc = pass_count(&b, xyz, cells_buf, counts, &md2);
        st.seconds_count = asp_time_now() - t1;
        // the frame asp_cloud_frame gives the same points: bounds centre, farthest point plus the default disc radius
        double sx = hi[0] - lo[0], sy = hi[1] - lo[1], sz = hi[2] - lo[2], area = sx * sy + sy * sz + sz * sx;
        double dr = area > 0 ? 2.0 * sqrt(area / (ASP_HIER_PI * (double)b.n)) : fmax(sx, fmax(sy, sz)) / (double)b.n;
        memcpy(frame.center, b.origin, sizeof frame.center);
        frame.radius = sqrt(md2) + dr;
        full_radius = dr;
        if (!(frame.radius > 0))
            frame.radius = 1;
        // and its box, so a flat site is framed by its extent as a point file's is (asp_cloud_frame)
        for (int k = 0; k < 3; k++)
            frame.half[k] = 0.5 * (hi[k] - lo[k]) + dr;
        uint16_t q[3];
        asp_frame_half_encode(&frame, q);
        asp_frame_half_decode(&frame, q);
    }
    if (!rc)
        rc = make_chunks(&b, counts, lut);
    free(counts);
    counts = NULL;
    if (!rc) {
        snprintf(b.dir, sizeof b.dir, "%s%s%s.chunks.%ld", d.temp_dir ? d.temp_dir : "", d.temp_dir ? "/" : "",
                 d.temp_dir ? (strrchr(out, '/') ? strrchr(out, '/') + 1 : out) : out, (long)getpid());
        if (mkdir(b.dir, 0700) != 0)
            rc = asp_error_set(err, ASP_EIO, "cannot create '%s': %s", b.dir, strerror(errno));
    }
    int made_dir = !rc;
    double t2 = asp_time_now();
    if (!rc)
        rc = pass_distribute(&b, xyz, rgba, cells_buf, recs, lut);
    st.seconds_distribute = asp_time_now() - t2;
    free(lut);
    lut = NULL;
    free(xyz);
    xyz = NULL;
    free(rgba);
    rgba = NULL;
    free(cells_buf);
    cells_buf = NULL;
    free(recs);
    recs = NULL;
    asp_point_reader_close(b.in);
    b.in = NULL;
    double t3 = asp_time_now();
    int opened = 0;
    if (!rc && (rc = asp__atomic_open(&b.out, out, err)) == 0) {
        opened = 1;
        uint8_t zero[ASP__OOC_HEADER] = {0};
        if (fwrite(zero, 1, sizeof zero, b.out.fp) != sizeof zero)
            rc = asp_error_set(err, ASP_EIO, "cannot write '%s': %s", b.out.tmp, strerror(errno));
    }
    // chunks in groups of one per thread, written in chunk order so the file does not depend on timing
    for (size_t c0 = 0; c0 < b.nchunks && !rc; c0 += (size_t)threads) {
        int group = (int)(b.nchunks - c0 < (size_t)threads ? b.nchunks - c0 : (size_t)threads);
        asp_error errs[64];
        memset(errs, 0, sizeof errs);
#pragma omp parallel for schedule(static, 1) num_threads(threads)
        for (int t = 0; t < group; t++)
            index_chunk(&b, c0 + (size_t)t, &res[t], &sc[t], t < 64 ? &errs[t] : NULL);
        for (int t = 0; t < group; t++) {
            if (!rc && res[t].rc) {
                rc = res[t].rc;
                if (err && t < 64)
                    *err = errs[t];
            }
            if (!rc)
                rc = emit_chunk(&b, c0 + (size_t)t, &res[t].s);
            free_sub(&res[t].s);
        }
        if (!rc)
            rc = progress(&b, "index", (double)(c0 + (size_t)group) / (double)b.nchunks);
    }
    if (!rc)
        rc = build_top(&b, &sc[0]);
    if (!rc && b.written != b.n)
        rc = asp_error_set(err, ASP_EFORMAT, "'%s': %llu points written of %llu read (internal error)", out,
                           (unsigned long long)b.written, (unsigned long long)b.n);
    if (!rc)
        rc = write_table(&b, 0, &frame, full_radius, &st);
    if (opened)
        rc = rc ? (asp__atomic_abort(&b.out), rc) : asp__atomic_commit_checked(&b.out, reads_back, (void *)ctx, err);
    st.seconds_index = asp_time_now() - t3;
    if (made_dir)
        remove_dir(&b);
    st.points = b.n;
    st.chunks = b.nchunks;
    if (!rc && stats)
        *stats = st;
    for (int t = 0; t < threads && sc; t++)
        free(sc[t].bits);
    free(sc);
    free(res);
    free(counts);
    free(lut);
    free(xyz);
    free(rgba);
    free(cells_buf);
    free(recs);
    asp_point_reader_close(b.in);
    free(b.chunks);
    free(b.protos);
    free(b.roots);
    return rc;
}
