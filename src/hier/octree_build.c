/*
 * Point-octree construction (seed 001 section 3.2, Fig. 4): each node's
 * points are split into the eight octants around their mean position (data
 * driven), children's means gathered during the split; then, bottom up, the
 * generic homogeneous covariance (eq. 4), mean normal and colour, covering
 * ellipse (3.4), bounding sphere and normal cone of every node.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "hier/internal.h"
#include "util/banned.h"

typedef struct rec {
    float p[3];
    asp_index idx;
} rec;

/* node topology during the split; ids are local to a subtree job until merged */
typedef struct topo {
    uint32_t first_child;
    uint32_t first_point;
    uint32_t point_count;
    uint16_t child_count;
    uint16_t depth;
} topo;

typedef struct part_child {
    uint32_t lo, count;
    double mean[3];
} part_child;

typedef struct builder {
    rec *buf[2]; /* ping-pong: a node's points sit in buf[src], its children's in buf[1 - src] */
    uint32_t leaf_size;
} builder;

/* one top-level subtree built by one thread */
typedef struct job {
    uint32_t root;   /* global id of the subtree root */
    uint32_t lo, count;
    uint16_t depth;
    uint8_t src;
    double mean[3];
    topo *loc;       /* local nodes, loc[0] = root; capacity 2 * count */
    uint32_t nloc;   /* local node count */
    uint32_t base;   /* global id of local node 1 */
} job;

static void range_mean(const rec *r, uint32_t m, double mean[3])
{
    double s[3] = {0, 0, 0};
    for (uint32_t i = 0; i < m; i++)
        for (int d = 0; d < 3; d++)
            s[d] += r[i].p[d];
    for (int d = 0; d < 3; d++)
        mean[d] = s[d] / (double)m;
}

static int octant(const float p[3], const double m[3])
{
    return (p[0] > m[0]) | ((p[1] > m[1]) << 1) | ((p[2] > m[2]) << 2);
}

/*
 * Splits points [lo, lo + m) of buf[src] (m > leaf_size) into children in
 * buf[1 - src]. Octants around the mean (section 3.2); when that makes no
 * progress (all points equal) or the tree is already ASP_HIER_SPLIT_DEPTH
 * deep (skewed input: a split at the mean may peel off single points), split
 * by count instead, which bounds the depth by log8.
 */
static int split(const builder *b, int src, uint32_t lo, uint32_t m, const double mean[3], uint32_t depth,
                 part_child ch[8])
{
    const rec *in = b->buf[src] + lo;
    rec *out = b->buf[1 - src] + lo;
    if (depth < ASP_HIER_SPLIT_DEPTH) {
        uint32_t cnt[8] = {0};
        double sum[8][3] = {{0}};
        for (uint32_t i = 0; i < m; i++) {
            int o = octant(in[i].p, mean);
            cnt[o]++;
            for (int d = 0; d < 3; d++)
                sum[o][d] += in[i].p[d];
        }
        uint32_t biggest = 0;
        for (int o = 0; o < 8; o++)
            biggest = cnt[o] > biggest ? cnt[o] : biggest;
        if (biggest < m) {
            uint32_t off[8], at = 0;
            int c = 0;
            for (int o = 0; o < 8; o++) {
                off[o] = at;
                if (cnt[o]) {
                    ch[c].lo = lo + at;
                    ch[c].count = cnt[o];
                    for (int d = 0; d < 3; d++)
                        ch[c].mean[d] = sum[o][d] / (double)cnt[o];
                    c++;
                }
                at += cnt[o];
            }
            for (uint32_t i = 0; i < m; i++)
                out[off[octant(in[i].p, mean)]++] = in[i];
            return c;
        }
    }
    uint32_t c = m < 8 ? m : 8;
    memcpy(out, in, (size_t)m * sizeof *out);
    for (uint32_t j = 0; j < c; j++) {
        uint32_t a = (uint32_t)((uint64_t)m * j / c), e = (uint32_t)((uint64_t)m * (j + 1) / c);
        ch[j].lo = lo + a;
        ch[j].count = e - a;
        range_mean(out + a, e - a, ch[j].mean);
    }
    return (int)c;
}

/* depth-first build of a subtree; children of a node get consecutive local ids */
static void build_local(const builder *b, job *jb, uint32_t id, int src, uint32_t lo, uint32_t m,
                        const double mean[3], uint32_t depth)
{
    topo *t = &jb->loc[id];
    t->first_point = lo;
    t->point_count = m;
    t->depth = (uint16_t)depth;
    t->child_count = 0;
    t->first_child = 0;
    if (m <= b->leaf_size) {
        /* leaves gather their points in buf[0], which becomes the hierarchy order */
        if (src == 1)
            memcpy(b->buf[0] + lo, b->buf[1] + lo, (size_t)m * sizeof(rec));
        return;
    }
    part_child ch[8];
    int c = split(b, src, lo, m, mean, depth, ch);
    uint32_t first = jb->nloc;
    jb->nloc += (uint32_t)c;
    t->first_child = first;
    t->child_count = (uint16_t)c;
    for (int j = 0; j < c; j++)
        build_local(b, jb, first + (uint32_t)j, 1 - src, ch[j].lo, ch[j].count, ch[j].mean, depth + 1);
}

/*
 * The top splits touch every point, so they run in parallel over fixed-size
 * chunks: per-chunk counts and sums, combined in chunk order, then a stable
 * scatter. The chunking does not depend on the thread count, so neither do
 * the sums nor the order.
 */
enum { CHUNK_RECS = 1 << 16 };

typedef struct chunk_stat {
    uint32_t cnt[8];
    double sum[8][3];
} chunk_stat;

static size_t chunk_count(size_t m)
{
    return m ? (m + CHUNK_RECS - 1) / CHUNK_RECS : 1;
}

static void chunk_range(long long c, uint32_t m, uint32_t *a, uint32_t *e)
{
    *a = (uint32_t)(c * CHUNK_RECS);
    *e = m - *a < CHUNK_RECS ? m : *a + CHUNK_RECS;
}

static void mean_parallel(const rec *in, uint32_t m, double mean[3], chunk_stat *cs, int threads)
{
    long long nc = (long long)chunk_count(m);
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long c = 0; c < nc; c++) {
        uint32_t a, e;
        chunk_range(c, m, &a, &e);
        double acc[3] = {0, 0, 0};
        for (uint32_t i = a; i < e; i++)
            for (int d = 0; d < 3; d++)
                acc[d] += in[i].p[d];
        memcpy(cs[c].sum[0], acc, sizeof acc);
    }
    double tot[3] = {0, 0, 0};
    for (long long c = 0; c < nc; c++)
        for (int d = 0; d < 3; d++)
            tot[d] += cs[c].sum[0][d];
    for (int d = 0; d < 3; d++)
        mean[d] = tot[d] / (double)m;
}

/* the octant split of split() for a large node; returns 0 when it makes no progress */
static int split_parallel(const builder *b, int src, uint32_t lo, uint32_t m, const double mean[3], part_child ch[8],
                          chunk_stat *cs, int threads)
{
    const rec *in = b->buf[src] + lo;
    rec *out = b->buf[1 - src] + lo;
    long long nc = (long long)chunk_count(m);
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long c = 0; c < nc; c++) {
        chunk_stat *st = &cs[c];
        memset(st, 0, sizeof *st);
        uint32_t a, e;
        chunk_range(c, m, &a, &e);
        for (uint32_t i = a; i < e; i++) {
            int o = octant(in[i].p, mean);
            st->cnt[o]++;
            for (int d = 0; d < 3; d++)
                st->sum[o][d] += in[i].p[d];
        }
    }
    uint32_t cnt[8] = {0}, run[8];
    double sum[8][3] = {{0}};
    for (long long c = 0; c < nc; c++)
        for (int o = 0; o < 8; o++) {
            cnt[o] += cs[c].cnt[o];
            for (int d = 0; d < 3; d++)
                sum[o][d] += cs[c].sum[o][d];
        }
    uint32_t at = 0;
    int k = 0;
    for (int o = 0; o < 8; o++) {
        if (cnt[o] == m)
            return 0;
        run[o] = at;
        if (cnt[o]) {
            ch[k].lo = lo + at;
            ch[k].count = cnt[o];
            for (int d = 0; d < 3; d++)
                ch[k].mean[d] = sum[o][d] / (double)cnt[o];
            k++;
        }
        at += cnt[o];
    }
    /* each chunk's first slot per octant, so chunks scatter independently and stably */
    for (long long c = 0; c < nc; c++)
        for (int o = 0; o < 8; o++) {
            uint32_t q = cs[c].cnt[o];
            cs[c].cnt[o] = run[o];
            run[o] += q;
        }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long c = 0; c < nc; c++) {
        uint32_t a, e, off[8];
        chunk_range(c, m, &a, &e);
        memcpy(off, cs[c].cnt, sizeof off);
        for (uint32_t i = a; i < e; i++)
            out[off[octant(in[i].p, mean)]++] = in[i];
    }
    return k;
}

/* ---- bottom-up node attributes ---- */

typedef struct finisher {
    asp_hier *h;
    double *sums; /* 7 per node: normal sum xyz, linear colour sum rgba (alpha in 0..1) */
    float lin[256];
    int lambda_axes; /* ASP_HIER_BUILD_LAMBDA_AXES */
} finisher;

/* PCA normal of the node's points, or 0 when they are (nearly) colinear */
static int pca_normal(const double c[6], double n[3])
{
    double evals[3], evecs[9];
    asp_eigen_sym3(c, evals, evecs);
    if (!(evals[1] > 1e-12 * evals[0]))
        return 0;
    for (int d = 0; d < 3; d++)
        n[d] = evecs[3 * d + 2];
    return 1;
}

static void node_normal(const finisher *f, const double *sums, const double c[6], const asp_hier_splat *members,
                        uint32_t point_count, float out[3])
{
    double n[3] = {sums[0], sums[1], sums[2]};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (f->h->flags & ASP_HIER_UNORIENTED) {
        /* signs are arbitrary, so a sum means nothing: the plane of the points does */
        if (!pca_normal(c, n))
            memcpy(out, members[0].normal, 3 * sizeof(float));
        else
            for (int d = 0; d < 3; d++)
                out[d] = (float)n[d];
        return;
    }
    if (len > 1e-3 * point_count) {
        for (int d = 0; d < 3; d++)
            out[d] = (float)(n[d] / len);
        return;
    }
    /* the normals cancel (a thin sheet seen from both sides): take the plane, signed like the sum */
    double p[3];
    if (!pca_normal(c, p)) {
        memcpy(out, members[0].normal, 3 * sizeof(float));
        return;
    }
    double s = p[0] * n[0] + p[1] * n[1] + p[2] * n[2] < 0 ? -1.0 : 1.0;
    for (int d = 0; d < 3; d++)
        out[d] = (float)(s * p[d]);
}

static void finish_node(const finisher *f, uint32_t id)
{
    asp_hier *h = f->h;
    asp_hier_node *nd = &h->nodes[id];
    asp_hier_splat *sp = &h->splats[id];
    double *cov = h->cov + (size_t)ASP_HIER_COV * id;
    double *sums = f->sums + (size_t)7 * id;
    int leaf = nd->child_count == 0;
    const asp_hier_splat *members = leaf ? h->splats + h->node_count + nd->first_point : h->splats + nd->first_child;
    size_t count = leaf ? nd->point_count : nd->child_count;
    memset(cov, 0, ASP_HIER_COV * sizeof *cov);
    memset(sums, 0, 7 * sizeof *sums);
    if (leaf) {
        /* section 3.3: tensor-product sums are formed once, at the leaves */
        for (size_t i = 0; i < count; i++) {
            const asp_hier_splat *p = &members[i];
            asp__hcov_add_point(cov, p->center);
            for (int d = 0; d < 3; d++) {
                sums[d] += p->normal[d];
                sums[3 + d] += f->lin[p->color[d]];
            }
            sums[6] += p->color[3] / 255.0;
        }
    } else {
        for (size_t i = 0; i < count; i++) {
            uint32_t c = nd->first_child + (uint32_t)i;
            asp__hcov_add(cov, h->cov + (size_t)ASP_HIER_COV * c); /* eq. 4 */
            for (int d = 0; d < 7; d++)
                sums[d] += f->sums[(size_t)7 * c + d];
        }
    }
    double mean[3], c[6];
    asp__hcov_mean(cov, mean);
    asp__hcov_central(cov, c);
    for (int d = 0; d < 3; d++)
        sp->center[d] = (float)mean[d];
    sp->index = id;
    double inv = 1.0 / (double)nd->point_count;
    for (int d = 0; d < 3; d++)
        sp->color[d] = asp__linear_to_srgb8(f->lin, sums[3 + d] * inv);
    sp->color[3] = (uint8_t)lround(sums[6] * inv * 255.0);
    node_normal(f, sums, c, members, nd->point_count, sp->normal);
    asp__ellipse_fit(sp, c, members, count, f->lambda_axes);
    if (leaf) {
        asp__sphere_of_points(members, count, sp, nd->sphere);
    } else {
        asp__sphere_of_nodes(h->nodes + nd->first_child, count, sp, nd->sphere);
    }
    nd->cone_angle = (h->flags & ASP_HIER_UNORIENTED)
                         ? (float)ASP_HIER_PI
                         : asp__cone_bound(sp->normal, members, leaf ? NULL : h->nodes + nd->first_child, count);
}

/* ---- driver ---- */

static int cmp_job_size(const void *pa, const void *pb)
{
    const job *a = *(const job *const *)pa, *b = *(const job *const *)pb;
    if (a->count != b->count)
        return a->count > b->count ? -1 : 1;
    return a->root < b->root ? -1 : (a->root > b->root);
}

typedef struct build_state {
    const asp_context *ctx;
    rec *buf[2];
    topo *ta;      /* top nodes, split sequentially breadth first */
    double *tmean; /* 3 per top node */
    uint8_t *tsrc;
    size_t nta, cap;
    job *jobs;
    job **order;   /* jobs by decreasing size, for a balanced static schedule */
    size_t njobs;
    topo *scratch; /* 2 * n local topology slots, sliced per job */
    asp_index *perm;     /* hierarchy position of each input point */
    asp_index *point_at; /* input point at each hierarchy position */
    chunk_stat *chunks;  /* per-chunk statistics of the top splits */
    double *sums;
} build_state;

static void free_state(build_state *s)
{
    const asp_context *ctx = s->ctx;
    asp_free(ctx, s->buf[0]);
    asp_free(ctx, s->buf[1]);
    asp_free(ctx, s->ta);
    asp_free(ctx, s->tmean);
    asp_free(ctx, s->tsrc);
    asp_free(ctx, s->jobs);
    asp_free(ctx, s->order);
    asp_free(ctx, s->scratch);
    asp_free(ctx, s->perm);
    asp_free(ctx, s->point_at);
    asp_free(ctx, s->chunks);
    asp_free(ctx, s->sums);
}

static int grow_top(build_state *s, size_t need)
{
    if (need <= s->cap)
        return 0;
    size_t cap = s->cap ? s->cap : 64;
    while (cap < need)
        cap *= 2;
    topo *ta = asp_realloc(s->ctx, s->ta, s->cap * sizeof *ta, cap * sizeof *ta);
    if (!ta)
        return ASP_ENOMEM;
    s->ta = ta;
    double *tm = asp_realloc(s->ctx, s->tmean, s->cap * 3 * sizeof *tm, cap * 3 * sizeof *tm);
    if (!tm)
        return ASP_ENOMEM;
    s->tmean = tm;
    uint8_t *ts = asp_realloc(s->ctx, s->tsrc, s->cap, cap);
    if (!ts)
        return ASP_ENOMEM;
    s->tsrc = ts;
    s->cap = cap;
    return 0;
}

/*
 * Top levels, breadth first and sequential: nodes larger than the job size
 * are split here; the rest become jobs. The job size depends on n only, not
 * on the thread count, so the tree is the same for any thread count.
 */
static int split_top(build_state *s, const builder *b, size_t n, int threads, asp_error *err)
{
    uint32_t job_size = (uint32_t)(n / 64 > 4096 ? n / 64 : 4096);
    if (grow_top(s, 1))
        return asp_error_set(err, ASP_ENOMEM, "cannot allocate octree nodes");
    s->ta[0] = (topo){0, 0, (uint32_t)n, 0, 0};
    mean_parallel(b->buf[0], (uint32_t)n, s->tmean, s->chunks, threads);
    s->tsrc[0] = 0;
    s->nta = 1;
    for (size_t i = 0; i < s->nta; i++) {
        topo t = s->ta[i];
        if (t.point_count <= job_size || t.point_count <= b->leaf_size) {
            s->njobs++;
            continue;
        }
        part_child ch[8];
        int c = 0;
        if (t.point_count >= 4 * CHUNK_RECS && t.depth < ASP_HIER_SPLIT_DEPTH)
            c = split_parallel(b, s->tsrc[i], t.first_point, t.point_count, s->tmean + 3 * i, ch, s->chunks, threads);
        if (c == 0)
            c = split(b, s->tsrc[i], t.first_point, t.point_count, s->tmean + 3 * i, t.depth, ch);
        if (grow_top(s, s->nta + (size_t)c))
            return asp_error_set(err, ASP_ENOMEM, "cannot allocate octree nodes");
        s->ta[i].first_child = (uint32_t)s->nta;
        s->ta[i].child_count = (uint16_t)c;
        for (int j = 0; j < c; j++) {
            size_t k = s->nta + (size_t)j;
            s->ta[k] = (topo){0, ch[j].lo, ch[j].count, 0, (uint16_t)(t.depth + 1)};
            memcpy(s->tmean + 3 * k, ch[j].mean, sizeof ch[j].mean);
            s->tsrc[k] = (uint8_t)(1 - s->tsrc[i]);
        }
        s->nta += (size_t)c;
    }
    return 0;
}

static void convert(asp_hier_node *dst, const topo *t, uint32_t first_child)
{
    dst->first_child = t->child_count ? first_child : 0;
    dst->child_count = t->child_count;
    dst->first_point = t->first_point;
    dst->point_count = t->point_count;
    dst->depth = t->depth;
    dst->parent = UINT32_MAX;
    dst->reserved = 0;
}

static int check_cloud(const asp_cloud *cloud, const asp_hier_desc *d, asp_error *err)
{
    if (!cloud || !cloud->positions)
        return asp_error_set(err, ASP_EINVAL, "cannot build a hierarchy: no cloud or no positions");
    if (cloud->count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot build a hierarchy of an empty cloud");
    /* node ids and node_count + point splat ids must fit asp_index */
    if (cloud->count > (UINT32_MAX - 1) / 3)
        return asp_error_set(err, ASP_EINVAL, "cannot build a hierarchy of %zu points: at most %u", cloud->count,
                             (unsigned)((UINT32_MAX - 1) / 3));
    if (d->leaf_size > ASP_HIER_MAX_LEAF)
        return asp_error_set(err, ASP_EINVAL, "leaf size %zu is too large: at most %d", d->leaf_size,
                             ASP_HIER_MAX_LEAF);
    if (d->k > 1024)
        return asp_error_set(err, ASP_EINVAL, "neighbour count k = %zu is too large: at most 1024", d->k);
    asp_error bad = {0};
    if (asp_cloud_validate(cloud, &bad) != 0)
        return asp_error_set(err, ASP_EINVAL, "cannot build a hierarchy: %s", bad.msg);
    return 0;
}

int asp_hier_build(const asp_cloud *cloud, const asp_hier_desc *desc, const asp_context *ctx, asp_hier **out,
                   asp_error *err)
{
    asp_hier_desc d = desc ? *desc : (asp_hier_desc){0};
    int rc = check_cloud(cloud, &d, err);
    if (rc)
        return rc;
    if (d.leaf_size == 0)
        d.leaf_size = 8;
    if (d.k == 0)
        d.k = 8;
    size_t n = cloud->count;
    long long nn = (long long)n;
    int threads = asp_context_threads(ctx);
    (void)threads; /* only the OpenMP pragmas read it */
    build_state s = {.ctx = ctx};
    asp_hier *h = NULL;
    s.buf[0] = asp_alloc(ctx, n * sizeof(rec));
    s.buf[1] = asp_alloc(ctx, n * sizeof(rec));
    s.scratch = asp_alloc(ctx, 2 * n * sizeof(topo));
    s.chunks = asp_alloc(ctx, chunk_count(n) * sizeof *s.chunks);
    if (!s.buf[0] || !s.buf[1] || !s.scratch || !s.chunks) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot allocate octree scratch for %zu points", n);
        goto fail;
    }
    asp__hier_huge_pages(s.buf[0], n * sizeof(rec));
    asp__hier_huge_pages(s.buf[1], n * sizeof(rec));
    asp__hier_huge_pages(s.scratch, 2 * n * sizeof(topo));
    const float *pos = cloud->positions;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long i = 0; i < nn; i++) {
        memcpy(s.buf[0][i].p, pos + 3 * i, 3 * sizeof(float));
        s.buf[0][i].idx = (asp_index)i;
    }
    builder b = {{s.buf[0], s.buf[1]}, (uint32_t)d.leaf_size};
    if ((rc = split_top(&s, &b, n, threads, err)) != 0)
        goto fail;
    if ((rc = asp_progress(ctx, "hier", 0.1)) != 0) {
        asp_error_set(err, rc, "hierarchy build canceled");
        goto fail;
    }

    /* subtrees in parallel, each into its own slice of scratch: no allocation, no shared writes */
    s.jobs = asp_calloc(ctx, s.njobs, sizeof *s.jobs);
    s.order = asp_calloc(ctx, s.njobs, sizeof *s.order);
    if (!s.jobs || !s.order) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot allocate %zu octree jobs", s.njobs);
        goto fail;
    }
    for (size_t i = 0, j = 0; i < s.nta; i++) {
        const topo *t = &s.ta[i];
        if (t->child_count)
            continue;
        job *jb = &s.jobs[j];
        *jb = (job){.root = (uint32_t)i, .lo = t->first_point, .count = t->point_count, .depth = t->depth,
                    .src = s.tsrc[i], .loc = s.scratch + 2 * (size_t)t->first_point, .nloc = 1};
        memcpy(jb->mean, s.tmean + 3 * i, sizeof jb->mean);
        s.order[j] = jb;
        j++;
    }
    qsort(s.order, s.njobs, sizeof *s.order, cmp_job_size);
    long long nj = (long long)s.njobs;
#pragma omp parallel for schedule(static, 1) num_threads(threads)
    for (long long j = 0; j < nj; j++) {
        job *jb = s.order[j];
        build_local(&b, jb, 0, jb->src, jb->lo, jb->count, jb->mean, jb->depth);
    }

    /* merge: top nodes keep their ids, job j's local node l > 0 becomes base_j + l - 1 */
    size_t node_count = s.nta;
    for (size_t j = 0; j < s.njobs; j++) {
        s.jobs[j].base = (uint32_t)node_count;
        node_count += s.jobs[j].nloc - 1;
    }
    if ((rc = asp__hier_alloc(ctx, node_count, n, &h, err)) != 0)
        goto fail;
    h->leaf_size = d.leaf_size;
    memcpy(h->origin, cloud->origin, sizeof h->origin);
    if (asp_cloud_frame(cloud, &h->frame, NULL) != 0)
        memset(&h->frame, 0, sizeof h->frame); // all points equal without radii: nothing to frame, radius 0
    for (size_t i = 0; i < s.nta; i++)
        if (s.ta[i].child_count)
            convert(&h->nodes[i], &s.ta[i], s.ta[i].first_child);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long j = 0; j < nj; j++) {
        const job *jb = &s.jobs[j];
        convert(&h->nodes[jb->root], &jb->loc[0], jb->base + jb->loc[0].first_child - 1);
        for (uint32_t l = 1; l < jb->nloc; l++)
            convert(&h->nodes[jb->base + l - 1], &jb->loc[l], jb->base + jb->loc[l].first_child - 1);
    }
    long long nc = (long long)node_count;
    uint32_t depth = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(max : depth)
    for (long long i = 0; i < nc; i++) {
        const asp_hier_node *nd = &h->nodes[i];
        for (uint32_t c = 0; c < nd->child_count; c++)
            h->nodes[nd->first_child + c].parent = (asp_index)i;
        depth = nd->depth > depth ? nd->depth : depth;
    }
    h->depth = depth;

    /* point splats, written directly in hierarchy order */
    s.perm = asp_alloc(ctx, n * sizeof *s.perm);
    s.point_at = asp_alloc(ctx, n * sizeof *s.point_at);
    s.sums = asp_alloc(ctx, node_count * 7 * sizeof *s.sums);
    if (!s.perm || !s.point_at || !s.sums) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot allocate hierarchy scratch for %zu nodes", node_count);
        goto fail;
    }
    asp__hier_huge_pages(s.sums, node_count * 7 * sizeof *s.sums);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long j = 0; j < nn; j++) {
        s.perm[s.buf[0][j].idx] = (asp_index)j;
        s.point_at[j] = s.buf[0][j].idx;
    }
    asp_free(ctx, s.buf[0]);
    asp_free(ctx, s.buf[1]);
    s.buf[0] = s.buf[1] = NULL;
    if ((rc = asp__hier_point_splats(cloud, d.k, d.flags, s.perm, s.point_at, ctx, h->splats + node_count,
                                     &h->flags, err)) != 0)
        goto fail;
    if ((rc = asp_progress(ctx, "hier", 0.6)) != 0) {
        asp_error_set(err, rc, "hierarchy build canceled");
        goto fail;
    }

    /* bottom up: each subtree in decreasing id (children first), then the top nodes */
    finisher fin = {.h = h, .sums = s.sums, .lambda_axes = (d.flags & ASP_HIER_BUILD_LAMBDA_AXES) != 0};
    asp__srgb_table(fin.lin);
#pragma omp parallel for schedule(static, 1) num_threads(threads)
    for (long long j = 0; j < nj; j++) {
        const job *jb = s.order[j];
        for (uint32_t l = jb->nloc - 1; l >= 1; l--)
            finish_node(&fin, jb->base + l - 1);
        finish_node(&fin, jb->root);
    }
    for (size_t i = s.nta; i-- > 0;)
        if (s.ta[i].child_count)
            finish_node(&fin, (uint32_t)i);
    h->nodes[0].parent = UINT32_MAX;
    free_state(&s);
    *out = h;
    (void)asp_progress(ctx, "hier", 1.0);
    return 0;

fail:
    asp_hier_destroy(h);
    free_state(&s);
    return rc;
}
