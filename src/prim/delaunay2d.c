/*
 * 2D Delaunay triangulation of a domain's projected points, the support of the
 * linear affine textures (thesis 3.3.3, where Shewchuk's Triangle was used).
 * Incremental insertion in Hilbert order with a visibility walk and Lawson
 * flips; coordinates snapped to a 2^20 grid make both predicates exact.
 */
#include <stdlib.h>
#include <string.h>

#include "amgsplat/prim.h"
#include "util/banned.h"

__extension__ typedef __int128 i128;

enum { GRID_BITS = 20 };
#define GRID_MAX ((int64_t)((1 << GRID_BITS) - 1))
/* Super-triangle corners: inside +-2^29, the largest magnitude for which the
 * in-circle determinant (degree 4, three terms) stays below 2^127. */
#define SUPER_LO (-((int64_t)1 << 28))
#define SUPER_HI ((int64_t)1 << 29)

typedef struct key_index {
    uint64_t key;
    uint32_t idx;
    uint32_t pad;
} key_index;

typedef struct dt {
    int64_t *x, *y;   /* snapped coordinates of unique points, then the 3 super corners */
    int32_t *v, *nb;  /* per triangle: 3 vertices (ccw), 3 neighbours (nb[i] opposite v[i]) */
    size_t ntri;
    int32_t *stack;
    size_t stack_cap;
} dt;

size_t asp_delaunay2d_bound(size_t n)
{
    return 2 * n + 1;
}

static size_t tri_cap(size_t n)
{
    return 2 * n + 4;
}

size_t asp_delaunay2d_scratch_size(size_t n)
{
    size_t t = tri_cap(n);
    return n * sizeof(key_index) + (n + 3) * (2 * sizeof(int64_t) + sizeof(uint32_t)) +
           t * 6 * sizeof(int32_t) + (4 * n + 32) * sizeof(int32_t) + 64;
}

/* Position along a Hilbert curve on the 2^20 grid, so consecutive insertions are close and walks short. */
static uint64_t hilbert(uint32_t x, uint32_t y)
{
    uint64_t d = 0;
    for (uint32_t s = 1u << (GRID_BITS - 1); s > 0; s >>= 1) {
        uint32_t rx = (x & s) > 0, ry = (y & s) > 0;
        d += (uint64_t)s * s * ((3 * rx) ^ ry);
        if (ry == 0) {
            if (rx == 1) {
                x = s - 1 - (x & (s - 1));
                y = s - 1 - (y & (s - 1));
            }
            uint32_t t = x;
            x = y;
            y = t;
        }
        x &= s - 1;
        y &= s - 1;
    }
    return d;
}

static int cmp_key(const void *a, const void *b)
{
    const key_index *p = a, *q = b;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return p->idx < q->idx ? -1 : p->idx > q->idx;
}

/* > 0 when c lies left of a->b; exact: differences < 2^31, products < 2^62. */
static int64_t orient(const dt *d, int32_t a, int32_t b, int32_t c)
{
    return (d->x[b] - d->x[a]) * (d->y[c] - d->y[a]) - (d->y[b] - d->y[a]) * (d->x[c] - d->x[a]);
}

/* > 0 when e lies inside the circumcircle of the ccw triangle a, b, c; exact in 128 bits. */
static int incircle(const dt *d, int32_t a, int32_t b, int32_t c, int32_t e)
{
    int64_t ax = d->x[a] - d->x[e], ay = d->y[a] - d->y[e];
    int64_t bx = d->x[b] - d->x[e], by = d->y[b] - d->y[e];
    int64_t cx = d->x[c] - d->x[e], cy = d->y[c] - d->y[e];
    i128 al = (i128)ax * ax + (i128)ay * ay;
    i128 bl = (i128)bx * bx + (i128)by * by;
    i128 cl = (i128)cx * cx + (i128)cy * cy;
    i128 det = al * ((i128)bx * cy - (i128)by * cx) - bl * ((i128)ax * cy - (i128)ay * cx) +
               cl * ((i128)ax * by - (i128)ay * bx);
    return det > 0;
}

static void set_tri(dt *d, size_t t, int32_t a, int32_t b, int32_t c, int32_t na, int32_t nb, int32_t nc)
{
    d->v[3 * t] = a, d->v[3 * t + 1] = b, d->v[3 * t + 2] = c;
    d->nb[3 * t] = na, d->nb[3 * t + 1] = nb, d->nb[3 * t + 2] = nc;
}

/* In triangle u, replace the neighbour link to old by new. */
static void relink(dt *d, int32_t u, int32_t old, int32_t nw)
{
    if (u < 0)
        return;
    for (int k = 0; k < 3; k++)
        if (d->nb[3 * u + k] == old) {
            d->nb[3 * u + k] = nw;
            return;
        }
}

/* Rotates triangle t so that its slot i becomes slot 0. */
static void rotate(dt *d, int32_t t, int i)
{
    int32_t v[3], n[3];
    for (int k = 0; k < 3; k++) {
        v[k] = d->v[3 * t + (k + i) % 3];
        n[k] = d->nb[3 * t + (k + i) % 3];
    }
    memcpy(&d->v[3 * t], v, sizeof v);
    memcpy(&d->nb[3 * t], n, sizeof n);
}

/* Finds the triangle containing p (walk from start); *edge = the edge p lies on, or -1 when strictly inside. */
static int32_t locate(const dt *d, int32_t start, int32_t p, int *edge)
{
    int32_t t = start;
    size_t steps = 0, limit = 4 * d->ntri + 16;
    for (;;) {
        int moved = 0, on = -1;
        for (int k = 0; k < 3 && !moved; k++) {
            int i = (int)((k + steps) % 3); /* rotating start edge: no cycling on ties */
            int64_t o = orient(d, d->v[3 * t + (i + 1) % 3], d->v[3 * t + (i + 2) % 3], p);
            if (o < 0) {
                t = d->nb[3 * t + i];
                moved = 1;
            } else if (o == 0) {
                on = i;
            }
        }
        if (!moved) {
            *edge = on;
            return t;
        }
        if (++steps > limit)
            break;
    }
    /* The visibility walk terminates on Delaunay triangulations; this scan is a safety net only. */
    for (size_t s = 0; s < d->ntri; s++) {
        int on = -1, out = 0;
        for (int i = 0; i < 3; i++) {
            int64_t o = orient(d, d->v[3 * s + (i + 1) % 3], d->v[3 * s + (i + 2) % 3], p);
            out |= o < 0;
            if (o == 0)
                on = i;
        }
        if (!out) {
            *edge = on;
            return (int32_t)s;
        }
    }
    *edge = -1;
    return -1;
}

static void push(dt *d, size_t *top, int32_t t)
{
    if (*top < d->stack_cap)
        d->stack[(*top)++] = t;
}

/* Lawson flips: every stacked triangle has the new point p at slot 0 and the edge to test at slot 0's opposite. */
static void legalize(dt *d, size_t top, int32_t p)
{
    while (top > 0) {
        int32_t t = d->stack[--top];
        int i = -1;
        for (int k = 0; k < 3; k++)
            if (d->v[3 * t + k] == p)
                i = k;
        if (i < 0)
            continue;
        rotate(d, t, i);
        int32_t u = d->nb[3 * t];
        if (u < 0)
            continue;
        int j = -1;
        for (int k = 0; k < 3; k++)
            if (d->nb[3 * u + k] == t)
                j = k;
        if (j < 0)
            continue;
        rotate(d, u, j);
        int32_t a = d->v[3 * t + 1], b = d->v[3 * t + 2], e = d->v[3 * u];
        if (!incircle(d, p, a, b, e))
            continue;
        int32_t tn1 = d->nb[3 * t + 1], tn2 = d->nb[3 * t + 2];
        int32_t un1 = d->nb[3 * u + 1], un2 = d->nb[3 * u + 2];
        set_tri(d, (size_t)t, p, a, e, un1, u, tn2);
        set_tri(d, (size_t)u, p, e, b, un2, tn1, t);
        relink(d, un1, u, t);
        relink(d, tn1, t, u);
        push(d, &top, t);
        push(d, &top, u);
    }
}

static void insert(dt *d, int32_t p, int32_t *last)
{
    int edge;
    int32_t t = locate(d, *last, p, &edge);
    if (t < 0)
        return;
    size_t top = 0;
    if (edge < 0) {
        int32_t v0 = d->v[3 * t], v1 = d->v[3 * t + 1], v2 = d->v[3 * t + 2];
        int32_t n0 = d->nb[3 * t], n1 = d->nb[3 * t + 1], n2 = d->nb[3 * t + 2];
        int32_t t1 = (int32_t)d->ntri, t2 = (int32_t)d->ntri + 1;
        d->ntri += 2;
        set_tri(d, (size_t)t, p, v1, v2, n0, t1, t2);
        set_tri(d, (size_t)t1, p, v2, v0, n1, t2, t);
        set_tri(d, (size_t)t2, p, v0, v1, n2, t, t1);
        relink(d, n1, t, t1);
        relink(d, n2, t, t2);
        push(d, &top, t);
        push(d, &top, t1);
        push(d, &top, t2);
    } else {
        rotate(d, t, edge);
        int32_t u = d->nb[3 * t];
        int j = -1;
        for (int k = 0; k < 3; k++)
            if (d->nb[3 * u + k] == t)
                j = k;
        rotate(d, u, j);
        int32_t v0 = d->v[3 * t], v1 = d->v[3 * t + 1], v2 = d->v[3 * t + 2], w0 = d->v[3 * u];
        int32_t tn1 = d->nb[3 * t + 1], tn2 = d->nb[3 * t + 2], un1 = d->nb[3 * u + 1], un2 = d->nb[3 * u + 2];
        int32_t t2 = (int32_t)d->ntri, u2 = (int32_t)d->ntri + 1;
        d->ntri += 2;
        set_tri(d, (size_t)t, p, v0, v1, tn2, u2, t2);
        set_tri(d, (size_t)t2, p, v2, v0, tn1, t, u);
        set_tri(d, (size_t)u, p, w0, v2, un2, t2, u2);
        set_tri(d, (size_t)u2, p, v1, w0, un1, u, t);
        relink(d, tn1, t, t2);
        relink(d, un1, u, u2);
        push(d, &top, t);
        push(d, &top, t2);
        push(d, &top, u);
        push(d, &top, u2);
    }
    legalize(d, top, p);
    *last = t;
}

size_t asp_delaunay2d(const double *xy, size_t n, uint32_t *tri, void *scratch)
{
    if (n < 3 || !xy || !tri || !scratch || n > (size_t)INT32_MAX / 4)
        return 0;
    double lo[2] = {xy[0], xy[1]}, hi[2] = {xy[0], xy[1]};
    for (size_t i = 1; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = xy[2 * i + k] < lo[k] ? xy[2 * i + k] : lo[k];
            hi[k] = xy[2 * i + k] > hi[k] ? xy[2 * i + k] : hi[k];
        }
    double extent = hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1];
    if (!(extent > 0))
        return 0;
    double scale = (double)GRID_MAX / extent;

    uint8_t *s = scratch;
    key_index *keys = (key_index *)s;
    s += n * sizeof(key_index);
    dt d;
    d.x = (int64_t *)s;
    s += (n + 3) * sizeof(int64_t);
    d.y = (int64_t *)s;
    s += (n + 3) * sizeof(int64_t);
    uint32_t *map = (uint32_t *)s;
    s += (n + 3) * sizeof(uint32_t);
    d.v = (int32_t *)s;
    s += tri_cap(n) * 3 * sizeof(int32_t);
    d.nb = (int32_t *)s;
    s += tri_cap(n) * 3 * sizeof(int32_t);
    d.stack = (int32_t *)s;
    d.stack_cap = 4 * n + 32;

    for (size_t i = 0; i < n; i++) {
        int64_t gx = (int64_t)((xy[2 * i] - lo[0]) * scale + 0.5), gy = (int64_t)((xy[2 * i + 1] - lo[1]) * scale + 0.5);
        gx = gx < 0 ? 0 : gx > GRID_MAX ? GRID_MAX : gx;
        gy = gy < 0 ? 0 : gy > GRID_MAX ? GRID_MAX : gy;
        keys[i].key = hilbert((uint32_t)gx, (uint32_t)gy); /* same node <=> same key */
        keys[i].idx = (uint32_t)i;
        keys[i].pad = 0;
        d.x[i] = gx; /* temporarily by input index */
        d.y[i] = gy;
    }
    qsort(keys, n, sizeof *keys, cmp_key);
    /* unique points in Hilbert order; the coordinates move into insertion order (keys keep the originals) */
    size_t m = 0;
    uint64_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        uint64_t key = keys[i].key;
        if (i > 0 && key == prev)
            continue;
        prev = key;
        keys[m].key = (uint64_t)d.x[keys[i].idx] | ((uint64_t)d.y[keys[i].idx] << 32);
        keys[m].idx = keys[i].idx;
        m++;
    }
    for (size_t i = 0; i < m; i++) {
        d.x[i] = (int64_t)(keys[i].key & 0xFFFFFFFFu);
        d.y[i] = (int64_t)(keys[i].key >> 32);
        map[i] = keys[i].idx;
    }
    if (m < 3)
        return 0;
    int32_t sa = (int32_t)m, sb = sa + 1, sc = sa + 2;
    d.x[sa] = SUPER_LO, d.y[sa] = SUPER_LO;
    d.x[sb] = SUPER_HI, d.y[sb] = SUPER_LO;
    d.x[sc] = SUPER_LO, d.y[sc] = SUPER_HI;
    d.ntri = 1;
    set_tri(&d, 0, sa, sb, sc, -1, -1, -1);
    int32_t last = 0;
    for (size_t i = 0; i < m; i++)
        insert(&d, (int32_t)i, &last);

    size_t out = 0;
    for (size_t t = 0; t < d.ntri; t++) {
        const int32_t *v = &d.v[3 * t];
        if (v[0] >= sa || v[1] >= sa || v[2] >= sa)
            continue;
        if (orient(&d, v[0], v[1], v[2]) <= 0) /* all-colinear input leaves no real triangle of area > 0 */
            continue;
        tri[3 * out] = map[v[0]];
        tri[3 * out + 1] = map[v[1]];
        tri[3 * out + 2] = map[v[2]];
        out++;
    }
    return out;
}
