/*
 * Reading a streamed .hier (issue 28; docs/hier.md "Streamed layout"): the
 * header and node table are read and validated on open, so traversal can
 * trust them; points are read per node on demand. A view's cut is chosen
 * coarse first by projected point spacing under a point budget, as Potree
 * (Schuetz 2016, 3.3) loads nodes by projected size.
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/camera.h"
#include "hier/ooc_format.h"
#include "util/checksum.h"
#include "util/regular_file.h"
#include "util/banned.h"

struct asp_ooc {
    asp_context ctx;
    FILE *fp;
    char path[1024];
    size_t node_count;
    uint64_t point_count;
    uint32_t depth;
    double origin[3];
    asp_frame frame;
    double full_radius; /* disc radius at full density, as the points drawn from memory get; 0 = unknown */
    asp_ooc_node *nodes;
};

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get64(const uint8_t *p) { return (uint64_t)get32(p) | (uint64_t)get32(p + 4) << 32; }

static double getf64(const uint8_t *p)
{
    uint64_t v = get64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

int asp_ooc_probe(const char *path)
{
    FILE *fp = asp__regular_file_open(path, NULL); // a FIFO or directory is refused, never waited on
    if (!fp)
        return ASP_EIO;
    uint8_t hd[20];
    size_t got = fread(hd, 1, sizeof hd, fp);
    fclose(fp);
    return got == sizeof hd && memcmp(hd, "ASPHIER", 8) == 0 && (get32(hd + 16) & ASP_HIER_STREAMED) ? 1 : 0;
}

static int bad(const asp_ooc *o, asp_error *err, const char *fmt, const char *what, unsigned long long a,
               unsigned long long b)
{
    char msg[200];
    snprintf(msg, sizeof msg, fmt, what, a, b);
    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': %s", o->path, msg);
}

/* One root, children contiguous after their parent, point ranges inside the file and counting every point once. */
static int check_tree(const asp_ooc *o, asp_error *err)
{
    const asp_ooc_node *n = o->nodes;
    uint64_t total = 0;
    if (n[0].parent != UINT32_MAX || n[0].depth != 0)
        return bad(o, err, "%s %llu: expected the root (parent none, depth 0)%.0llu", "node", 0, 0);
    for (size_t i = 0; i < o->node_count; i++) {
        const asp_ooc_node *a = &n[i];
        if (a->child_count > 8 || (a->child_count && (a->first_child <= i ||
                                                      (uint64_t)a->first_child + a->child_count > o->node_count)))
            return bad(o, err, "%s %llu: children from %llu out of range", "node", i, a->first_child);
        if (a->first_point > o->point_count || a->point_count > o->point_count - a->first_point)
            return bad(o, err, "%s %llu: points from %llu out of range", "node", i, a->first_point);
        if (!(isfinite(a->center[0]) && isfinite(a->center[1]) && isfinite(a->center[2]) && a->half > 0 &&
              isfinite(a->half) && a->spacing > 0 && isfinite(a->spacing)))
            return bad(o, err, "%s %llu: cube or spacing not finite and positive%.0llu", "node", i, 0);
        uint64_t sub = a->point_count;
        for (uint32_t k = 0; k < a->child_count; k++) {
            const asp_ooc_node *c = &n[a->first_child + k];
            if (c->parent != i || c->depth != a->depth + 1)
                return bad(o, err, "%s %llu: parent or depth does not match node %llu", "node", a->first_child + k, i);
            sub += c->subtree_points;
        }
        if (sub != a->subtree_points)
            return bad(o, err, "%s %llu: subtree holds %llu points, not the sum of its own and its children's", "node",
                       i, a->subtree_points);
        total += a->point_count;
    }
    if (total != o->point_count || n[0].subtree_points != o->point_count)
        return bad(o, err, "%s: nodes hold %llu points, the header says %llu", "node table", total, o->point_count);
    return 0;
}

int asp_ooc_open(const char *path, const asp_context *ctx, asp_ooc **out, asp_error *err)
{
    ASP_ASSERT(path && out);
    asp_ooc *o = calloc(1, sizeof *o);
    if (!o)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    if (ctx)
        o->ctx = *ctx;
    snprintf(o->path, sizeof o->path, "%s", path);
    uint8_t hd[ASP__OOC_HEADER];
    int rc = 0;
    off_t size = 0;
    asp_error open_err = {0, ""};
    if (!(o->fp = asp__regular_file_open(path, &open_err))) // a FIFO or directory is refused, never waited on
        rc = asp_error_set(err, open_err.code, "%s", open_err.msg);
    else if (fseeko(o->fp, 0, SEEK_END) != 0 || (size = ftello(o->fp)) < 0 || fseeko(o->fp, 0, SEEK_SET) != 0)
        rc = asp_error_set(err, ASP_EIO, "cannot open '%s': %s", path, strerror(errno));
    else if (fread(hd, 1, sizeof hd, o->fp) != sizeof hd || memcmp(hd, "ASPHIER", 8) != 0)
        rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': not a hierarchy file or truncated header", path);
    else if (!(get32(hd + 16) & ASP_HIER_STREAMED))
        rc = asp_error_set(err, ASP_EUNSUPPORTED, "'%s' is an in-memory hierarchy (asp_hier_load reads it)", path);
    else if (get32(hd + 8) != ASP__OOC_VERSION || get32(hd + 12) != ASP__OOC_HEADER)
        rc = asp_error_set(err, get32(hd + 8) > ASP__OOC_VERSION ? ASP_EUNSUPPORTED : ASP_EFORMAT,
                           "cannot read '%s': streamed format version %u, header %u bytes; this build reads version %d",
                           path, get32(hd + 8), get32(hd + 12), ASP__OOC_VERSION);
    else if (get64(hd + ASP__OOC_HEADER - 8) != asp__fnv1a64(ASP__FNV1A64_START, hd, ASP__OOC_HEADER - 8))
        rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': header checksum mismatch (bytes 0-%d)", path,
                           ASP__OOC_HEADER - 9);
    if (!rc) {
        o->depth = get32(hd + 20);
        uint64_t nodes = get64(hd + 24), table = get64(hd + ASP__OOC_TABLE_AT);
        o->point_count = get64(hd + 32);
        for (int k = 0; k < 3; k++) {
            o->origin[k] = getf64(hd + 48 + 8 * k);
            o->frame.center[k] = getf64(hd + ASP__OOC_FRAME_AT + 8 * k);
        }
        o->frame.radius = getf64(hd + ASP__OOC_FRAME_AT + 24);
        o->full_radius = getf64(hd + ASP__OOC_RADIUS_AT);
        uint32_t up = get32(hd + ASP__OOC_UP_AT);
        o->frame.up = up >= 1 && up <= (uint32_t)ASP_UP_NEG_X + 1u ? (asp_up_axis)(up - 1u) : ASP_UP_Y;
        uint32_t q01 = get32(hd + ASP__OOC_HALF_AT), q2 = get32(hd + ASP__OOC_HALF_AT + 4);
        asp_frame_half_decode(&o->frame, (const uint16_t[3]){(uint16_t)(q01 & 0xffffu), (uint16_t)(q01 >> 16),
                                                             (uint16_t)(q2 & 0xffffu)});
        uint64_t fsize = (uint64_t)size;
        int finite = isfinite(o->frame.radius) && o->frame.radius > 0 && isfinite(o->full_radius) &&
                     o->full_radius >= 0 && up <= (uint32_t)ASP_UP_NEG_X + 1u;
        for (int k = 0; k < 3; k++)
            finite &= isfinite(o->origin[k]) && isfinite(o->frame.center[k]);
        if (get32(hd + 72) != ASP__OOC_NODE_REC || get32(hd + 76) != ASP__OOC_POINT_REC || nodes == 0 ||
            o->point_count == 0 || o->point_count > (fsize - ASP__OOC_HEADER) / ASP__OOC_POINT_REC ||
            table != ASP__OOC_HEADER + o->point_count * ASP__OOC_POINT_REC || table > fsize ||
            nodes != (fsize - table) / ASP__OOC_NODE_REC || (fsize - table) % ASP__OOC_NODE_REC || !finite)
            rc = asp_error_set(err, ASP_EFORMAT,
                               "cannot read '%s': byte 24: header: %llu nodes, %llu points, node table at byte %llu "
                               "do not match the file's %llu bytes (or records, origin, frame invalid)",
                               path, (unsigned long long)nodes, (unsigned long long)o->point_count,
                               (unsigned long long)table, (unsigned long long)fsize);
        else if (!(o->full_radius <= FLT_MAX)) // it becomes the points' float radius
            rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': byte %d: full-density radius %g, expected at most %g",
                               path, ASP__OOC_RADIUS_AT, o->full_radius, (double)FLT_MAX);
        else if (nodes >= UINT32_MAX || !(o->nodes = malloc((size_t)nodes * sizeof *o->nodes)))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %llu nodes of '%s'", (unsigned long long)nodes, path);
        else if (fseeko(o->fp, (off_t)table, SEEK_SET) != 0 ||
                 fread(o->nodes, sizeof *o->nodes, (size_t)nodes, o->fp) != (size_t)nodes)
            rc = asp_error_set(err, ASP_EIO, "cannot read '%s': node table: %s", path, strerror(errno));
        else if (asp__fnv1a64(ASP__FNV1A64_START, o->nodes, (size_t)nodes * sizeof *o->nodes) !=
                 get64(hd + ASP__OOC_TABLE_HASH))
            rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': byte %llu: node table checksum mismatch", path,
                               (unsigned long long)table);
        else {
            o->node_count = (size_t)nodes;
            rc = check_tree(o, err);
        }
    }
    if (rc) {
        asp_ooc_close(o);
        return rc;
    }
    *out = o;
    return 0;
}

void asp_ooc_close(asp_ooc *o)
{
    if (!o)
        return;
    if (o->fp)
        fclose(o->fp);
    free(o->nodes);
    free(o);
}

size_t asp_ooc_node_count(const asp_ooc *o) { return o->node_count; }
uint64_t asp_ooc_point_count(const asp_ooc *o) { return o->point_count; }
uint32_t asp_ooc_depth(const asp_ooc *o) { return o->depth; }
const asp_ooc_node *asp_ooc_nodes(const asp_ooc *o) { return o->nodes; }
void asp_ooc_origin(const asp_ooc *o, double out[3]) { memcpy(out, o->origin, sizeof o->origin); }
const asp_frame *asp_ooc_frame(const asp_ooc *o) { return &o->frame; }

/* ---- the cut ---- */

typedef struct cand {
    float size; /* projected spacing, pixels */
    uint32_t node;
} cand;

static void heap_push(cand *h, size_t *n, cand c)
{
    size_t i = (*n)++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (h[p].size > c.size || (h[p].size == c.size && h[p].node < c.node))
            break;
        h[i] = h[p];
        i = p;
    }
    h[i] = c;
}

static cand heap_pop(cand *h, size_t *n)
{
    cand top = h[0], last = h[--(*n)];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        cand best = last;
        if (l < *n && (h[l].size > best.size || (h[l].size == best.size && h[l].node < best.node)))
            m = l, best = h[l];
        if (r < *n && (h[r].size > best.size || (h[r].size == best.size && h[r].node < best.node)))
            m = r, best = h[r];
        if (m == i)
            break;
        h[i] = h[m];
        i = m;
    }
    if (*n)
        h[i] = last;
    return top;
}

/* Projected spacing in pixels, or -1 when the node's bounding sphere is outside the frustum. */
static float project(const asp_ooc_node *n, const asp_hier_view *v, const float planes[6][4], float scale, int ortho)
{
    float r = n->half * 1.7320508f;
    if (!v->no_frustum_cull)
        for (int k = 0; k < 6; k++)
            if (planes[k][0] * n->center[0] + planes[k][1] * n->center[1] + planes[k][2] * n->center[2] + planes[k][3] <
                -r)
                return -1;
    if (ortho)
        return n->spacing * scale;
    float dx = n->center[0] - v->eye[0], dy = n->center[1] - v->eye[1], dz = n->center[2] - v->eye[2];
    float d = sqrtf(dx * dx + dy * dy + dz * dz) - r;
    float dmin = 1e-3f * n->half;
    return n->spacing * scale / (d > dmin ? d : dmin);
}

int asp_ooc_select(const asp_ooc *o, const asp_hier_view *v, uint64_t max_points, uint32_t *dst, size_t *count,
                   uint64_t *points, asp_error *err)
{
    ASP_ASSERT(o && v && dst && count && points);
    if (!v->width || !v->height)
        return asp_error_set(err, ASP_EINVAL, "cut: zero viewport");
    float planes[6][4];
    asp_camera_frustum_planes(v->view, v->proj, planes);
    // transform the planes to hierarchy-local coordinates? The view matrix already takes local coordinates.
    int ortho = v->proj[15] == 1.0f;
    // pixels per unit at unit distance (perspective) or per unit (orthographic)
    float scale = 0.5f * (float)v->height * v->proj[5];
    float tau = v->tau > 0 ? v->tau : 1.0f;
    cand *heap = malloc(o->node_count * sizeof *heap);
    if (!heap)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the cut of %zu nodes", o->node_count);
    size_t nh = 0, nsel = 0;
    uint64_t pts = 0;
    float s0 = project(&o->nodes[0], v, planes, scale, ortho);
    if (s0 >= 0 && o->nodes[0].point_count <= max_points)
        heap_push(heap, &nh, (cand){s0, 0});
    while (nh) {
        cand c = heap_pop(heap, &nh);
        const asp_ooc_node *n = &o->nodes[c.node];
        if (pts + n->point_count > max_points)
            continue; // over budget: this subtree stays coarser
        dst[nsel++] = c.node;
        pts += n->point_count;
        if (c.size <= tau)
            continue;
        for (uint32_t k = 0; k < n->child_count; k++) {
            uint32_t id = n->first_child + k;
            float s = project(&o->nodes[id], v, planes, scale, ortho);
            if (s >= 0)
                heap_push(heap, &nh, (cand){s, id});
        }
    }
    free(heap);
    *count = nsel;
    *points = pts;
    return 0;
}

/* ---- loading a cut ---- */

typedef struct at_node {
    uint64_t first_point;
    uint32_t node;
} at_node;

static int cmp_offset(const void *a, const void *b)
{
    uint64_t x = ((const at_node *)a)->first_point, y = ((const at_node *)b)->first_point;
    return x < y ? -1 : x > y;
}

int asp_ooc_load(asp_ooc *o, const uint32_t *nodes, size_t count, asp_cloud **out, asp_error *err)
{
    ASP_ASSERT(o && out && (nodes || !count));
    uint64_t total = 0;
    for (size_t i = 0; i < count; i++)
        total += o->nodes[nodes[i]].point_count;
    if (total >= UINT32_MAX - 1)
        return asp_error_set(err, ASP_EINVAL, "a cut of %llu points: a cloud holds at most 2^32 - 2",
                             (unsigned long long)total);
    uint8_t *sel = calloc(o->node_count, 1);
    at_node *order = malloc((count ? count : 1) * sizeof *order);
    asp_ooc_point *buf = malloc(sizeof *buf * 65536);
    asp_cloud *c = NULL;
    int rc = !sel || !order || !buf ? asp_error_set(err, ASP_ENOMEM, "out of memory") : 0;
    if (!rc)
        rc = asp_cloud_create((size_t)total, ASP_ATTR_COLORS | ASP_ATTR_RADII, &o->ctx, &c, err);
    if (!rc) {
        memcpy(c->origin, o->origin, sizeof c->origin);
        for (size_t i = 0; i < count; i++)
            sel[nodes[i]] = 1;
        // file order: one forward sweep over the points
        for (size_t i = 0; i < count; i++)
            order[i] = (at_node){o->nodes[nodes[i]].first_point, nodes[i]};
        qsort(order, count, sizeof *order, cmp_offset);
    }
    size_t at = 0;
    for (size_t i = 0; i < count && !rc; i++) {
        const asp_ooc_node *n = &o->nodes[order[i].node];
        if (fseeko(o->fp, (off_t)(ASP__OOC_HEADER + n->first_point * ASP__OOC_POINT_REC), SEEK_SET) != 0) {
            rc = asp_error_set(err, ASP_EIO, "cannot read '%s': %s", o->path, strerror(errno));
            break;
        }
        for (uint32_t done = 0; done < n->point_count && !rc;) {
            uint32_t m = n->point_count - done < 65536 ? n->point_count - done : 65536;
            if (fread(buf, sizeof *buf, m, o->fp) != m) {
                rc = asp_error_set(err, ASP_EIO, "cannot read '%s': points of node %u", o->path, order[i].node);
                break;
            }
            for (uint32_t j = 0; j < m; j++, at++) {
                const asp_ooc_point *p = &buf[j];
                // the points are outside the checksums: a non-finite one is refused, as the point readers do
                if (!(isfinite(p->position[0]) && isfinite(p->position[1]) && isfinite(p->position[2]))) {
                    uint64_t k = n->first_point + done + j;
                    rc = asp_error_set(err, ASP_EFORMAT,
                                       "cannot read '%s': byte %llu: point %llu of node %u: expected a finite position",
                                       o->path, (unsigned long long)(ASP__OOC_HEADER + k * ASP__OOC_POINT_REC),
                                       (unsigned long long)k, order[i].node);
                    break;
                }
                memcpy(c->positions + 3 * at, p->position, 12);
                memcpy(c->colors + 4 * at, p->color, 4);
                // the deepest selected node whose cube holds the point sets its disc size
                const asp_ooc_node *d = n;
                for (;;) {
                    const asp_ooc_node *next = NULL;
                    for (uint32_t k = 0; k < d->child_count && !next; k++) {
                        const asp_ooc_node *ch = &o->nodes[d->first_child + k];
                        if (sel[d->first_child + k] && fabsf(p->position[0] - ch->center[0]) <= ch->half &&
                            fabsf(p->position[1] - ch->center[1]) <= ch->half &&
                            fabsf(p->position[2] - ch->center[2]) <= ch->half)
                            next = ch;
                    }
                    if (!next)
                        break;
                    d = next;
                }
                c->radii[at] = asp_ooc_disc_radius(o, (uint32_t)(d - o->nodes));
            }
            done += m;
        }
    }
    free(sel);
    free(order);
    free(buf);
    if (rc) {
        asp_cloud_destroy(c);
        return rc;
    }
    *out = c;
    return 0;
}

int asp_ooc_read_points(asp_ooc *o, uint32_t node, asp_ooc_point *dst, asp_error *err)
{
    ASP_ASSERT(o && (dst || node >= o->node_count || !o->nodes[node].point_count));
    if (node >= o->node_count)
        return asp_error_set(err, ASP_EINVAL, "'%s' has %zu nodes, no node %u", o->path, o->node_count, node);
    const asp_ooc_node *n = &o->nodes[node];
    if (!n->point_count)
        return 0;
    if (fseeko(o->fp, (off_t)(ASP__OOC_HEADER + n->first_point * ASP__OOC_POINT_REC), SEEK_SET) != 0)
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", o->path, strerror(errno));
    if (fread(dst, sizeof *dst, n->point_count, o->fp) != n->point_count)
        return asp_error_set(err, ASP_EIO, "cannot read '%s': the %u points of node %u (file truncated?)", o->path,
                             n->point_count, node);
    return 0;
}

uint64_t asp_ooc_budget_points(size_t memory)
{
    return (uint64_t)(memory ? memory : (size_t)2 << 30) / 64u;
}

float asp_ooc_disc_radius(const asp_ooc *o, uint32_t node)
{
    ASP_ASSERT(o && node < o->node_count);
    const asp_ooc_node *d = &o->nodes[node];
    // full density (a leaf) draws at the radius the whole set gets in memory, coarser cuts
    // wider: 2 / sqrt(pi) spacings, asp_cloud_default_radius's closing factor
    float r = (float)fmin(1.1283792 * d->spacing, FLT_MAX), full = (float)o->full_radius; // finite
    return full > 0 && (!d->child_count || r < full) ? full : r;
}
