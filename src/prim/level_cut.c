/*
 * The view-dependent cut across the levels of a .dps (issue 18 item 2;
 * journal section 6, thesis 2.6.3; seed 001 section 5 selects detail per node
 * by its screen error): refine a primitive whose error covers more than a
 * tolerance in pixels, pass its weight to its children through the links, and
 * fade changes of the cut so the drawn weights stay a partition of unity.
 */
#include <math.h>
#include <string.h>

#include "prim/internal.h"
#include "util/banned.h"

struct asp_dps_cut {
    const asp_dps *dps;
    asp_context ctx;
    double fade;             /* seconds; 0: no fade */
    size_t total;            /* primitives over all levels */
    size_t *base;            /* level_count + 1: first weight index of each level */
    /* children of each primitive of level i >= 1 (the transpose of level i-1's links) */
    uint32_t *child_first;   /* total + 1, indexed by the global primitive index */
    uint32_t *child;         /* global indices of the children */
    float *child_w;          /* w(child -> parent) */
    float *radius;           /* half diagonal of each support rectangle */
    float *target, *start, *drawn; /* total each */
    float *scratch;          /* total: d during a target computation */
    double s;                /* fade progress in [0, 1] */
    int started, fading;
    asp_dps_cut_item *items;
    size_t item_count;
};

size_t asp_dps_cut_target_count(const asp_dps_cut *cut)
{
    return cut->total;
}

void asp_dps_cut_destroy(asp_dps_cut *cut)
{
    if (!cut)
        return;
    asp_context ctx = cut->ctx;
    asp_free(&ctx, cut->base);
    asp_free(&ctx, cut->child_first);
    asp_free(&ctx, cut->child);
    asp_free(&ctx, cut->child_w);
    asp_free(&ctx, cut->radius);
    asp_free(&ctx, cut->target);
    asp_free(&ctx, cut->start);
    asp_free(&ctx, cut->drawn);
    asp_free(&ctx, cut->scratch);
    asp_free(&ctx, cut->items);
    asp_free(&ctx, cut);
}

/* Children lists: counting sort of every level's links by global parent index. */
static void build_children(asp_dps_cut *c)
{
    const asp_dps *dps = c->dps;
    for (size_t i = 0; i + 1 < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        for (size_t q = 0; q < lv->link_total; q++)
            c->child_first[c->base[i + 1] + lv->link_parent[q] + 1]++;
    }
    for (size_t g = 0; g < c->total; g++)
        c->child_first[g + 1] += c->child_first[g];
    uint32_t *fill = (uint32_t *)c->scratch; /* total entries of 4 bytes: the scratch is free now */
    memcpy(fill, c->child_first, c->total * sizeof *fill);
    for (size_t i = 0; i + 1 < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        for (size_t k = 0; k < lv->prim_count; k++)
            for (size_t q = lv->link_first[k]; q < lv->link_first[k + 1]; q++) {
                size_t g = c->base[i + 1] + lv->link_parent[q];
                c->child[fill[g]] = (uint32_t)(c->base[i] + k);
                c->child_w[fill[g]++] = lv->link_weight[q];
            }
    }
    memset(c->scratch, 0, c->total * sizeof *c->scratch);
}

int asp_dps_cut_create(const asp_dps *dps, double fade_seconds, const asp_context *ctx, asp_dps_cut **out,
                       asp_error *err)
{
    if (!dps || !out || dps->level_count == 0)
        return asp_error_set(err, ASP_EINVAL, "asp_dps_cut_create needs a dps with levels and an output");
    if (dps->level_count > 1 && !asp_dps_has_links(dps))
        return asp_error_set(err, ASP_EINVAL, "no links between levels (a .dps of version 1 or 2, or a merged "
                             "level): rebuild it with this version of 'amgsplat build' for a cut across levels");
    asp_dps_cut *c = asp_calloc(ctx, 1, sizeof *c);
    if (!c)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a cut");
    c->dps = dps;
    c->ctx = ctx ? *ctx : (asp_context){0};
    c->fade = fade_seconds == 0 ? 0.25 : (fade_seconds < 0 ? 0 : fade_seconds);
    c->base = asp_calloc(ctx, dps->level_count + 1, sizeof *c->base);
    if (!c->base)
        goto oom;
    size_t links = 0;
    for (size_t i = 0; i < dps->level_count; i++) {
        c->base[i + 1] = c->base[i] + dps->levels[i].prim_count;
        links += dps->levels[i].link_total;
    }
    c->total = c->base[dps->level_count];
    c->child_first = asp_calloc(ctx, c->total + 1, sizeof *c->child_first);
    c->child = asp_alloc(ctx, (links ? links : 1) * sizeof *c->child);
    c->child_w = asp_alloc(ctx, (links ? links : 1) * sizeof *c->child_w);
    c->radius = asp_alloc(ctx, c->total * sizeof *c->radius);
    c->target = asp_calloc(ctx, c->total, sizeof *c->target);
    c->start = asp_calloc(ctx, c->total, sizeof *c->start);
    c->drawn = asp_calloc(ctx, c->total, sizeof *c->drawn);
    c->scratch = asp_calloc(ctx, c->total, sizeof *c->scratch);
    c->items = asp_alloc(ctx, c->total * sizeof *c->items);
    if (!c->child_first || !c->child || !c->child_w || !c->radius || !c->target || !c->start || !c->drawn ||
        !c->scratch || !c->items)
        goto oom;
    for (size_t i = 0; i < dps->level_count; i++)
        for (size_t k = 0; k < dps->levels[i].prim_count; k++) {
            const asp_prim *p = &dps->levels[i].prims[k];
            c->radius[c->base[i] + k] = sqrtf(p->half_u * p->half_u + p->half_v * p->half_v);
        }
    build_children(c);
    *out = c;
    return 0;
oom:
    asp_dps_cut_destroy(c);
    return asp_error_set(err, ASP_ENOMEM, "out of memory for a cut of %zu levels", dps->level_count);
}

/* The error of primitive p in pixels: its error at the nearest distance of its rectangle to the eye. */
static int refines(const asp_prim *p, float radius, const asp_dps_cut_view *v)
{
    if (!(v->tolerance > 0))
        return 1;
    double d[3] = {p->centre[0] - v->eye[0], p->centre[1] - v->eye[1], p->centre[2] - v->eye[2]};
    double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - radius;
    /* inside the bounding sphere the projection is unbounded: refine (seed 001 section 5 does the same) */
    if (dist <= 1e-9)
        return 1;
    return ((double)p->error + v->size_weight * radius) * v->pixels_per_unit / dist > v->tolerance;
}

size_t asp_dps_cut_target(const asp_dps_cut *cut, const asp_dps_cut_view *view, float *out)
{
    const asp_dps *dps = cut->dps;
    float *d = cut->scratch;
    memset(d, 0, cut->total * sizeof *d);
    size_t top = dps->level_count - 1, drawn = 0;
    for (size_t k = 0; k < dps->levels[top].prim_count; k++)
        d[cut->base[top] + k] = 1;
    for (size_t i = top + 1; i-- > 0;) {
        const asp_dps_level *lv = &dps->levels[i];
        for (size_t k = 0; k < lv->prim_count; k++) {
            size_t g = cut->base[i] + k;
            float w = d[g];
            if (!(w > 0))
                continue;
            if (i > 0 && refines(&lv->prims[k], cut->radius[g], view)) {
                for (size_t q = cut->child_first[g]; q < cut->child_first[g + 1]; q++)
                    d[cut->child[q]] += w * cut->child_w[q];
                d[g] = 0; /* refined: drawn through its children */
            } else {
                drawn++;
            }
        }
    }
    if (out)
        memcpy(out, d, cut->total * sizeof *out);
    return drawn;
}

static void collect_items(asp_dps_cut *c)
{
    size_t n = 0;
    for (size_t i = 0; i < c->dps->level_count; i++)
        for (size_t k = 0; k < c->dps->levels[i].prim_count; k++) {
            float w = c->drawn[c->base[i] + k];
            if (w > 0)
                c->items[n++] = (asp_dps_cut_item){(uint32_t)i, (uint32_t)k, w};
        }
    c->item_count = n;
}

int asp_dps_cut_update(asp_dps_cut *c, const asp_dps_cut_view *view, double dt, asp_error *err)
{
    (void)err; /* everything was allocated by asp_dps_cut_create */
    asp_dps_cut_target(c, view, NULL);
    const float *next = c->scratch;
    int changed = memcmp(next, c->target, c->total * sizeof *next) != 0;
    if (!c->started || dt < 0 || c->fade == 0) {
        memcpy(c->target, next, c->total * sizeof *next);
        memcpy(c->drawn, next, c->total * sizeof *next);
        c->started = 1, c->fading = 0, c->s = 1;
        collect_items(c);
        return 0;
    }
    if (changed) {
        /* what is drawn now (a partition of unity) becomes the start of a new fade */
        memcpy(c->start, c->drawn, c->total * sizeof *next);
        memcpy(c->target, next, c->total * sizeof *next);
        c->s = 0, c->fading = 1;
    }
    if (c->fading) {
        c->s += dt / c->fade;
        if (c->s >= 1)
            c->s = 1, c->fading = 0;
        float s = (float)c->s;
        /* one s for every primitive: sum_f ((1 - s) start_f + s target_f) Psi_f = (1 - s) + s = 1 */
        for (size_t g = 0; g < c->total; g++)
            c->drawn[g] = (1 - s) * c->start[g] + s * c->target[g];
    }
    collect_items(c);
    return 0;
}

size_t asp_dps_cut_items(const asp_dps_cut *cut, const asp_dps_cut_item **items)
{
    if (items)
        *items = cut->items;
    return cut->item_count;
}

int asp_dps_cut_fading(const asp_dps_cut *cut)
{
    return cut->fading;
}
