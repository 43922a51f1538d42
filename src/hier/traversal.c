/*
 * View-dependent cuts of the hierarchy without GL: LOD selection by a screen
 * tolerance tau (seed 001 section 5.1 step 1), view-frustum culling with the
 * bounding spheres and normal-cone back-face culling (seed 004 sections 3.2.2
 * and 3.2.4), the depth limit of 3.2.5, and a cut to a target splat count.
 */
#include <math.h>
#include <string.h>

#include "hier/internal.h"
#include "util/banned.h"

typedef struct viewer {
    const asp_hier *h;
    double planes[6][4]; /* inward unit normals: inside when n . x + d >= 0 */
    int nplanes;
    double zrow[4];      /* row 2 of the view matrix: eye-space z */
    double fwd[3];       /* orthographic: viewing direction in local coordinates */
    double eye[3];
    double scale;        /* pixels per unit length at unit distance (or in all of an orthographic view) */
    int ortho;
    int backface;
    float tau;
    uint32_t depth_limit;
} viewer;

/* sink for selected splat ids: writes the first capacity, counts all */
typedef struct sink {
    asp_index *dst;
    size_t capacity;
    size_t count;
} sink;

static void emit(sink *s, asp_index id)
{
    if (s->count < s->capacity)
        s->dst[s->count] = id;
    s->count++;
}

static int finite16(const float *m)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i]))
            return 0;
    return 1;
}

static int setup(viewer *w, const asp_hier *h, const asp_hier_view *v, asp_error *err)
{
    if (!v->width || !v->height)
        return asp_error_set(err, ASP_EINVAL, "invalid view: viewport %ux%u is empty", v->width, v->height);
    if (!(v->tau >= 0))
        return asp_error_set(err, ASP_EINVAL, "invalid view: tau %g must be >= 0", (double)v->tau);
    if (!finite16(v->view) || !finite16(v->proj) || !isfinite(v->eye[0]) || !isfinite(v->eye[1]) ||
        !isfinite(v->eye[2]))
        return asp_error_set(err, ASP_EINVAL, "invalid view: matrix or eye has a NaN or infinite entry");
    memset(w, 0, sizeof *w);
    w->h = h;
    /* clip = P V x; the planes of Gribb and Hartmann: row3 +- row0, row1, row2 */
    double m[16];
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += (double)v->proj[4 * k + r] * v->view[4 * c + k];
            m[4 * c + r] = s;
        }
    if (!v->no_frustum_cull) {
        for (int p = 0; p < 6; p++) {
            int row = p / 2;
            double sign = (p & 1) ? -1.0 : 1.0;
            double e[4];
            for (int c = 0; c < 4; c++)
                e[c] = m[4 * c + 3] + sign * m[4 * c + row];
            double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            if (len == 0)
                continue; /* e.g. a far plane at infinity */
            for (int c = 0; c < 4; c++)
                w->planes[w->nplanes][c] = e[c] / len;
            w->nplanes++;
        }
    }
    for (int c = 0; c < 4; c++)
        w->zrow[c] = v->view[4 * c + 2];
    w->ortho = v->proj[15] == 1.0f && v->proj[11] == 0.0f;
    double zlen = sqrt(w->zrow[0] * w->zrow[0] + w->zrow[1] * w->zrow[1] + w->zrow[2] * w->zrow[2]);
    for (int d = 0; d < 3; d++) {
        w->fwd[d] = zlen > 0 ? -w->zrow[d] / zlen : 0.0;
        w->eye[d] = v->eye[d];
    }
    double sx = fabs((double)v->proj[0]) * v->width * 0.5, sy = fabs((double)v->proj[5]) * v->height * 0.5;
    w->scale = sx > sy ? sx : sy;
    w->backface = v->cull_backfaces && !(h->flags & ASP_HIER_UNORIENTED);
    w->tau = v->tau;
    w->depth_limit = v->depth_limit;
    return 0;
}

/* 0 outside, 1 intersecting, 2 entirely inside (so descendants need no test) */
static int frustum(const viewer *w, const float c[3], double r)
{
    int inside = 2;
    for (int p = 0; p < w->nplanes; p++) {
        const double *e = w->planes[p];
        double dist = e[0] * c[0] + e[1] * c[1] + e[2] * c[2] + e[3];
        if (dist < -r)
            return 0;
        if (dist < r)
            inside = 1;
    }
    return inside;
}

/*
 * Whole cone of normals (axis n, half-angle theta) faces away from every
 * point of the sphere (c, r) as seen from the eye: the view directions form a
 * cone of half-angle beta = asin(r / |c - eye|) around c - eye, and every
 * normal makes an angle below 90 degrees with every view direction when
 * angle(n, c - eye) + theta + beta < 90 degrees (seed 004 3.2.2, made
 * conservative for perspective).
 */
static int backfacing(const viewer *w, const float n[3], double theta, const float c[3], double r)
{
    if (theta >= 0.5 * ASP_HIER_PI)
        return 0;
    double d[3], len, beta;
    if (w->ortho) {
        memcpy(d, w->fwd, sizeof d);
        len = 1;
        beta = 0;
    } else {
        for (int i = 0; i < 3; i++)
            d[i] = (double)c[i] - w->eye[i];
        len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len <= r)
            return 0;
        beta = asin(r / len);
    }
    double cosang = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / len;
    if (cosang <= 0)
        return 0;
    double alpha = acos(cosang > 1 ? 1 : cosang);
    return alpha + theta + beta < 0.5 * ASP_HIER_PI;
}

/* projected diameter in pixels of an ellipse of major semi-axis a at c; infinite when at the eye */
static double projected(const viewer *w, const float c[3], double a)
{
    if (w->ortho)
        return 2.0 * a * w->scale;
    double depth = -(w->zrow[0] * c[0] + w->zrow[1] * c[1] + w->zrow[2] * c[2] + w->zrow[3]);
    /* nearest depth of the ellipse, so a splat reaching towards the eye is not underestimated */
    double near = depth - a;
    return near > 0 ? 2.0 * a * w->scale / near : INFINITY;
}

/* -1 culled, else the frustum state for descendants */
static int node_visible(const viewer *w, uint32_t id, int inside)
{
    const asp_hier_node *nd = &w->h->nodes[id];
    if (inside != 2) {
        inside = frustum(w, nd->sphere, nd->sphere[3]);
        if (!inside)
            return -1;
    }
    if (w->backface && backfacing(w, w->h->splats[id].normal, nd->cone_angle, nd->sphere, nd->sphere[3]))
        return -1;
    return inside;
}

static int point_visible(const viewer *w, const asp_hier_splat *p, int inside)
{
    if (inside != 2 && !frustum(w, p->center, p->a))
        return 0;
    if (w->backface && backfacing(w, p->normal, 0.0, p->center, 0.0))
        return 0;
    return 1;
}

static void visit(const viewer *w, uint32_t id, int inside, sink *out)
{
    const asp_hier *h = w->h;
    const asp_hier_node *nd = &h->nodes[id];
    inside = node_visible(w, id, inside);
    if (inside < 0)
        return;
    if (projected(w, h->splats[id].center, h->splats[id].a) < w->tau ||
        (w->depth_limit && nd->depth + 1 >= w->depth_limit)) {
        emit(out, id);
        return;
    }
    size_t before = out->count;
    if (nd->child_count == 0) {
        size_t base = h->node_count + nd->first_point;
        for (uint32_t j = 0; j < nd->point_count; j++)
            if (point_visible(w, &h->splats[base + j], inside))
                emit(out, (asp_index)(base + j));
    } else {
        for (uint32_t c = 0; c < nd->child_count; c++)
            visit(w, nd->first_child + c, inside, out);
    }
    /* the conservative bounds passed but nothing below did: draw the node, so counts never grow with tau */
    if (out->count == before)
        emit(out, id);
}

int asp_hier_select(const asp_hier *hier, const asp_hier_view *view, asp_index *dst, size_t capacity,
                    size_t *count, asp_error *err)
{
    viewer w;
    int rc = setup(&w, hier, view, err);
    if (rc)
        return rc;
    sink out = {dst, dst ? capacity : 0, 0};
    visit(&w, 0, 0, &out);
    *count = out.count;
    return 0;
}

/* ---- cut to a target count: a max-heap on projected size ---- */

typedef struct item {
    double size;
    asp_index id;
    int inside;
} item;

static int above(const item *a, const item *b)
{
    return a->size > b->size || (a->size == b->size && a->id < b->id);
}

static void heap_push(item *hp, size_t *n, item it)
{
    size_t i = (*n)++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!above(&it, &hp[p]))
            break;
        hp[i] = hp[p];
        i = p;
    }
    hp[i] = it;
}

static item heap_pop(item *hp, size_t *n)
{
    item top = hp[0], last = hp[--*n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= *n)
            break;
        if (c + 1 < *n && above(&hp[c + 1], &hp[c]))
            c++;
        if (!above(&hp[c], &last))
            break;
        hp[i] = hp[c];
        i = c;
    }
    if (*n > 0)
        hp[i] = last;
    return top;
}

int asp_hier_select_count(const asp_hier *hier, const asp_hier_view *view, size_t target, asp_index *dst,
                          size_t capacity, size_t *count, asp_error *err)
{
    viewer w;
    int rc = setup(&w, hier, view, err);
    if (rc)
        return rc;
    sink out = {dst, dst ? capacity : 0, 0};
    if (target > hier->point_count)
        target = hier->point_count;
    int inside0 = target ? node_visible(&w, 0, 0) : -1;
    if (inside0 < 0) {
        *count = 0;
        return 0;
    }
    /* the cut never holds more than target splats, of which the heap holds some */
    size_t cap = target + 8;
    size_t kids_cap = hier->leaf_size > 8 ? hier->leaf_size : 8;
    item *hp = asp_alloc(&hier->ctx, cap * sizeof *hp);
    item *kids = asp_alloc(&hier->ctx, kids_cap * sizeof *kids);
    if (!hp || !kids) {
        asp_free(&hier->ctx, hp);
        asp_free(&hier->ctx, kids);
        return asp_error_set(err, ASP_ENOMEM, "cannot allocate a selection heap of %zu entries", cap);
    }
    size_t nh = 0, cut = 1;
    heap_push(hp, &nh, (item){projected(&w, hier->splats[0].center, hier->splats[0].a), 0, inside0});
    while (nh > 0) {
        item it = heap_pop(hp, &nh);
        const asp_hier_node *nd = &hier->nodes[it.id];
        size_t nk = 0;
        if (nd->child_count == 0) {
            size_t base = hier->node_count + nd->first_point;
            for (uint32_t j = 0; j < nd->point_count; j++)
                if (point_visible(&w, &hier->splats[base + j], it.inside))
                    kids[nk++] = (item){0, (asp_index)(base + j), 0};
        } else {
            for (uint32_t c = 0; c < nd->child_count; c++) {
                asp_index id = nd->first_child + c;
                int in = node_visible(&w, id, it.inside);
                if (in >= 0)
                    kids[nk++] = (item){projected(&w, hier->splats[id].center, hier->splats[id].a), id, in};
            }
        }
        if (nk == 0) {
            /* the conservative bounds passed but nothing below did: the splat would cover nothing visible
               (and blur past the silhouette), so leave it out and give its place to another */
            cut--;
            continue;
        }
        if (cut - 1 + nk > target) {
            emit(&out, it.id);
            continue;
        }
        cut += nk - 1;
        for (size_t k = 0; k < nk; k++) {
            if (nd->child_count == 0)
                emit(&out, kids[k].id);
            else
                heap_push(hp, &nh, kids[k]);
        }
    }
    asp_free(&hier->ctx, hp);
    asp_free(&hier->ctx, kids);
    *count = out.count;
    return 0;
}
