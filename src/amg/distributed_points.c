/*
 * The points of a distributed decomposition (issue 19): each rank reads its
 * own range of a binary PLY's vertices, a sample sort along a Morton curve of
 * quantised coordinates gives every rank a compact piece of the surface, and
 * a halo brings copies of the other ranks' points within each owned point's
 * neighbourhood radius (bounding boxes of the balls) so journal 2.1-2.2's
 * neighbourhoods, classifier and fans of owned points see the whole surface.
 */
#ifdef ASP_HAVE_HYPRE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amg/distributed.h"
#include "util/regular_file.h"
#include "util/banned.h"

/* One point on its way between ranks: the Morton key, its input index (ties), and every attribute kept. */
typedef struct rec {
    uint64_t key, index;
    float pos[3], nrm[3], radius, uv[2];
    uint32_t label;
    uint8_t rgba[4];
} rec;

/* P_U, P_V: the first pair of the names the serial PLY reader takes for uvs (src/io/ply_read.c) */
enum { P_X, P_Y, P_Z, P_NX, P_NY, P_NZ, P_R, P_G, P_B, P_A, P_RADIUS, P_LABEL, P_U, P_V, P_S, P_T, P_TU, P_TV, P_COUNT };
static const char *const prop_names[P_COUNT] = {"x",   "y",     "z",     "nx",     "ny", "nz", "red", "green", "blue",
                                                "alpha", "radius", "label", "u",   "v",  "s",  "t",   "texture_u",
                                                "texture_v"};

typedef struct layout {
    size_t count, record, data_at;
    int type[P_COUNT]; /* 0 = absent, else the byte size with sign/float flag below */
    size_t at[P_COUNT];
} layout;

enum { T_FLOAT = 0x100, T_SIGNED = 0x200 };

static int type_of(const char *name)
{
    static const struct {
        const char *n;
        int t;
    } types[] = {{"char", 1 | T_SIGNED},  {"int8", 1 | T_SIGNED},   {"uchar", 1},          {"uint8", 1},
                 {"short", 2 | T_SIGNED}, {"int16", 2 | T_SIGNED},  {"ushort", 2},         {"uint16", 2},
                 {"int", 4 | T_SIGNED},   {"int32", 4 | T_SIGNED},  {"uint", 4},           {"uint32", 4},
                 {"float", 4 | T_FLOAT},  {"float32", 4 | T_FLOAT}, {"double", 8 | T_FLOAT}, {"float64", 8 | T_FLOAT}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(types[i].n, name) == 0)
            return types[i].t;
    return 0;
}

static double load(const uint8_t *p, int t)
{
    switch (t) {
    case 4 | T_FLOAT: { float f; memcpy(&f, p, 4); return f; }
    case 8 | T_FLOAT: { double v; memcpy(&v, p, 8); return v; }
    case 1: return p[0];
    case 1 | T_SIGNED: return (int8_t)p[0];
    case 2: { uint16_t v; memcpy(&v, p, 2); return v; }
    case 2 | T_SIGNED: { int16_t v; memcpy(&v, p, 2); return v; }
    case 4: { uint32_t v; memcpy(&v, p, 4); return v; }
    default: { int32_t v; memcpy(&v, p, 4); return v; }
    }
}

/* The vertex layout of a binary little-endian PLY whose first element is the vertices. */
static int read_layout(FILE *fp, const char *path, layout *lay, asp_error *err)
{
    char line[512];
    size_t lineno = 0;
    int in_vertex = 0, seen_vertex = 0, fmt = 0;
    memset(lay, 0, sizeof *lay);
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        char a[64] = "", b[64] = "", c[64] = "";
        int n = sscanf(line, "%63s %63s %63s", a, b, c);
        if (lineno == 1 && strcmp(a, "ply") != 0)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line 1: expected 'ply'", path);
        if (strcmp(a, "format") == 0) {
            if (strcmp(b, "binary_little_endian") != 0)
                return asp_error_set(err, ASP_EFORMAT,
                                     "cannot read '%s' on MPI ranks: line %zu: format %s, expected binary_little_endian "
                                     "(convert it with 'amgsplat convert --encoding binary')", path, lineno, b);
            fmt = 1;
        } else if (strcmp(a, "element") == 0) {
            if (seen_vertex && in_vertex)
                in_vertex = 0;
            if (!seen_vertex) {
                if (strcmp(b, "vertex") != 0)
                    return asp_error_set(err, ASP_EFORMAT,
                                         "cannot read '%s' on MPI ranks: line %zu: element '%s' before 'vertex', "
                                         "expected the vertices first", path, lineno, b);
                char *end;
                unsigned long long v = strtoull(c, &end, 10);
                if (*end || n < 3)
                    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: bad vertex count '%s'", path,
                                         lineno, c);
                lay->count = (size_t)v;
                seen_vertex = in_vertex = 1;
            }
        } else if (strcmp(a, "property") == 0 && in_vertex) {
            if (strcmp(b, "list") == 0)
                return asp_error_set(err, ASP_EFORMAT,
                                     "cannot read '%s' on MPI ranks: line %zu: a list property in the vertices, "
                                     "expected fixed-size records", path, lineno);
            int t = type_of(b);
            if (!t || n < 3)
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': line %zu: unknown property type '%s'", path,
                                     lineno, b);
            for (int p = 0; p < P_COUNT; p++)
                if (strcmp(c, prop_names[p]) == 0 && !lay->type[p]) {
                    lay->type[p] = t;
                    lay->at[p] = lay->record;
                }
            lay->record += (size_t)(t & 0xff);
        } else if (strcmp(a, "end_header") == 0) {
            lay->data_at = (size_t)ftell(fp);
            if (!fmt || !seen_vertex)
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': no format or vertex element in the header",
                                     path);
            if (!lay->type[P_X] || !lay->type[P_Y] || !lay->type[P_Z])
                return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the vertices have no x, y, z", path);
            for (int p = P_NX; p <= P_NZ; p++)
                if (!(lay->type[P_NX] && lay->type[P_NY] && lay->type[P_NZ]))
                    lay->type[p] = 0;
            for (int p = P_R; p <= P_A; p++)
                if (lay->type[p] != 1 || !(lay->type[P_R] == 1 && lay->type[P_G] == 1 && lay->type[P_B] == 1))
                    lay->type[p] = p == P_A && lay->type[P_A] == 1 ? lay->type[P_A] : 0;
            if (!lay->type[P_R])
                lay->type[P_A] = 0;
            /* uvs as the serial reader takes them: two floats of one type, u/v before s/t before texture_u/v */
            int uv = P_U;
            while (uv < P_COUNT && !((lay->type[uv] & T_FLOAT) && lay->type[uv] == lay->type[uv + 1]))
                uv += 2;
            for (int k = 0; k < 2; k++) {
                lay->type[P_U + k] = uv < P_COUNT ? lay->type[uv + k] : 0;
                lay->at[P_U + k] = uv < P_COUNT ? lay->at[uv + k] : 0;
            }
            return 0;
        }
    }
    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': no end_header", path);
}

static int cmp_rec(const void *a, const void *b)
{
    const rec *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* This rank's records [first, first+m) of the file, positions as offsets from origin. */
static int read_range(const asp_context *ctx, FILE *fp, const char *path, const layout *lay, size_t first, size_t m,
                      const double origin[3], rec *out, asp_error *err)
{
    enum { CHUNK = 1 << 16 };
    uint8_t *buf = asp_alloc(ctx, CHUNK * lay->record);
    if (!buf)
        return asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", path);
    for (size_t done = 0; done < m;) {
        size_t take = m - done < CHUNK ? m - done : CHUNK;
        if (fseeko(fp, (off_t)(lay->data_at + (first + done) * lay->record), SEEK_SET) != 0 ||
            fread(buf, lay->record, take, fp) != take) {
            asp_free(ctx, buf);
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': vertex %zu: the file ends before vertex %zu",
                                 path, first + done, lay->count);
        }
        for (size_t i = 0; i < take; i++) {
            const uint8_t *b = buf + i * lay->record;
            rec *r = out + done + i;
            memset(r, 0, sizeof *r);
            r->index = first + done + i;
            for (int k = 0; k < 3; k++) {
                double v = load(b + lay->at[P_X + k], lay->type[P_X + k]);
                if (!isfinite(v)) {
                    asp_free(ctx, buf);
                    return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': vertex %zu: coordinate %c is not finite",
                                         path, (size_t)r->index, "xyz"[k]);
                }
                r->pos[k] = (float)(v - origin[k]);
                r->nrm[k] = lay->type[P_NX] ? (float)load(b + lay->at[P_NX + k], lay->type[P_NX + k]) : 0.0f;
            }
            for (int k = 0; k < 4; k++)
                r->rgba[k] = lay->type[P_R + k] ? b[lay->at[P_R + k]] : 255;
            r->radius = lay->type[P_RADIUS] ? (float)load(b + lay->at[P_RADIUS], lay->type[P_RADIUS]) : 0.0f;
            r->label = lay->type[P_LABEL] ? (uint32_t)load(b + lay->at[P_LABEL], lay->type[P_LABEL]) : 0;
            for (int k = 0; k < 2; k++)
                r->uv[k] = lay->type[P_U + k] ? (float)load(b + lay->at[P_U + k], lay->type[P_U + k]) : 0.0f;
        }
        done += take;
    }
    asp_free(ctx, buf);
    return 0;
}

/* Reads this rank's share into *recs (count *m) with the file's layout and the origin of wide axes. */
static int read_share(const asp__dist *d, const char *path, layout *lay, double origin[3], rec **recs, size_t *m,
                      asp_error *err)
{
    FILE *fp = asp__regular_file_open(path, err);
    int rc = fp ? 0 : err && err->code ? err->code : ASP_EIO;
    if (!rc)
        rc = read_layout(fp, path, lay, err);
    if (!rc && lay->count < 3)
        rc = asp_error_set(err, ASP_EDEGENERATE, "cannot decompose %zu points: need at least 3", lay->count);
    if (!rc && lay->count > (size_t)INT32_MAX - 1)
        rc = asp_error_set(err, ASP_EUNSUPPORTED, "cannot decompose %zu points: at most 2^31-2 are supported",
                           lay->count);
    size_t first = 0;
    if (!rc) {
        first = lay->count * (size_t)d->rank / (size_t)d->size;
        *m = lay->count * (size_t)(d->rank + 1) / (size_t)d->size - first;
        /* the serial reader's origin: wide (double) axes are offsets from the first point, rounded */
        for (int k = 0; k < 3 && !rc; k++) {
            uint8_t raw[8];
            if (fseeko(fp, (off_t)(lay->data_at + lay->at[P_X + k]), SEEK_SET) || fread(raw, 1, 8, fp) < 4)
                rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': no vertex data", path);
            double v = rc ? 0 : load(raw, lay->type[P_X + k]);
            origin[k] = (lay->type[P_X + k] & 0xff) != 4 || !(lay->type[P_X + k] & T_FLOAT) ? floor(v + 0.5) : 0.0;
        }
    }
    if (!rc) {
        *recs = asp_alloc(&d->ctx, (*m + 1) * sizeof **recs);
        if (!*recs)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu points of '%s'", *m, path);
    }
    if (!rc) {
        rc = read_range(&d->ctx, fp, path, lay, first, *m, origin, *recs, err);
        if (rc) {
            asp_free(&d->ctx, *recs);
            *recs = NULL;
        }
    }
    if (fp)
        fclose(fp);
    return rc;
}

/* Sample sort by key: splitters from regular samples of every rank, then one all-to-all of the records. */
static int sample_sort(const asp__dist *d, rec **recs, size_t *m, asp_error *err)
{
    const int P = d->size;
    rec *r = *recs;
    qsort(r, *m, sizeof *r, cmp_rec);
    if (P == 1)
        return 0;
    const int s = 32; /* samples per rank: enough for a few % of imbalance */
    uint64_t mine[32], *all = asp_alloc(&d->ctx, (size_t)P * s * sizeof *all), *split = asp_alloc(&d->ctx, (size_t)P * sizeof *split);
    int *cnt = asp_calloc(&d->ctx, 4 * (size_t)P, sizeof *cnt);
    if (!all || !split || !cnt) {
        asp_free(&d->ctx, all);
        asp_free(&d->ctx, split);
        asp_free(&d->ctx, cnt);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the sample sort");
    }
    for (int i = 0; i < s; i++)
        mine[i] = *m ? r[(size_t)i * *m / (size_t)s].key : UINT64_MAX;
    MPI_Allgather(mine, s, MPI_UINT64_T, all, s, MPI_UINT64_T, d->comm);
    qsort(all, (size_t)P * s, sizeof *all, cmp_u64);
    for (int q = 1; q < P; q++)
        split[q] = all[(size_t)q * s];
    int *dis = cnt + P, *rcnt = cnt + 2 * P, *rdis = cnt + 3 * P;
    for (size_t i = 0, q = 0; i < *m; i++) {
        while ((int)q + 1 < P && r[i].key >= split[q + 1])
            q++;
        cnt[q]++;
    }
    MPI_Alltoall(cnt, 1, MPI_INT, rcnt, 1, MPI_INT, d->comm);
    size_t total = 0;
    for (int q = 0; q < P; q++) {
        dis[q] = q ? dis[q - 1] + cnt[q - 1] : 0;
        rdis[q] = (int)total;
        total += (size_t)rcnt[q];
    }
    rec *in = asp_alloc(&d->ctx, (total + 1) * sizeof *in);
    int ok = in != NULL, allok = 0;
    MPI_Allreduce(&ok, &allok, 1, MPI_INT, MPI_MIN, d->comm);
    if (allok) {
        MPI_Datatype t;
        MPI_Type_contiguous((int)sizeof(rec), MPI_BYTE, &t);
        MPI_Type_commit(&t);
        MPI_Alltoallv(r, cnt, dis, t, in, rcnt, rdis, t, d->comm);
        MPI_Type_free(&t);
        qsort(in, total, sizeof *in, cmp_rec);
        asp_free(&d->ctx, r);
        *recs = in;
        *m = total;
    } else {
        asp_free(&d->ctx, in);
    }
    asp_free(&d->ctx, all);
    asp_free(&d->ctx, split);
    asp_free(&d->ctx, cnt);
    return allok ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu points from other ranks", total);
}

int asp__dist_read_sorted(const asp__dist *d, const char *path, asp__dist_points *pts, asp_error *err)
{
    layout lay;
    rec *recs = NULL;
    size_t m = 0;
    memset(pts, 0, sizeof *pts);
    int rc = read_share(d, path, &lay, pts->origin, &recs, &m, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_free(&d->ctx, recs);
        return rc;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < m; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], recs[i].pos[k]);
            hi[k] = fmaxf(hi[k], recs[i].pos[k]);
        }
    MPI_Allreduce(lo, pts->lo, 3, MPI_FLOAT, MPI_MIN, d->comm);
    MPI_Allreduce(hi, pts->hi, 3, MPI_FLOAT, MPI_MAX, d->comm);
    /* the serial decomposition's numbering (morton.c): one rank gives exactly its hierarchy */
    const double scale = asp__amg_morton_scale(pts->lo, pts->hi);
    for (size_t i = 0; i < m; i++)
        recs[i].key = asp__amg_morton_key(recs[i].pos, pts->lo, scale);
    rc = sample_sort(d, &recs, &m, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_free(&d->ctx, recs);
        return rc;
    }
    const asp_context *ctx = &d->ctx;
    pts->n_global = lay.count;
    pts->n_own = m;
    pts->starts = asp_alloc(ctx, ((size_t)d->size + 1) * sizeof *pts->starts);
    pts->pos = asp_alloc(ctx, (3 * m + 3) * sizeof *pts->pos);
    if (lay.type[P_NX])
        pts->normals = asp_alloc(ctx, (3 * m + 3) * sizeof *pts->normals);
    if (lay.type[P_R])
        pts->colors = asp_alloc(ctx, 4 * m + 4);
    if (lay.type[P_RADIUS])
        pts->radii = asp_alloc(ctx, (m + 1) * sizeof *pts->radii);
    if (lay.type[P_LABEL])
        pts->labels = asp_alloc(ctx, (m + 1) * sizeof *pts->labels);
    if (lay.type[P_U])
        pts->uvs = asp_alloc(ctx, (2 * m + 2) * sizeof *pts->uvs);
    pts->has_alpha = lay.type[P_A] != 0;
    rc = !pts->starts || !pts->pos || (lay.type[P_NX] && !pts->normals) || (lay.type[P_R] && !pts->colors) ||
                 (lay.type[P_RADIUS] && !pts->radii) || (lay.type[P_LABEL] && !pts->labels) || (lay.type[P_U] && !pts->uvs)
             ? asp_error_set(err, ASP_ENOMEM, "out of memory for %zu points", m)
             : 0;
    if (!rc && asp__dist_partition(d, m, pts->starts))
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the partition");
    for (size_t i = 0; !rc && i < m; i++) {
        memcpy(pts->pos + 3 * i, recs[i].pos, sizeof recs[i].pos);
        if (pts->normals)
            memcpy(pts->normals + 3 * i, recs[i].nrm, sizeof recs[i].nrm);
        if (pts->colors)
            memcpy(pts->colors + 4 * i, recs[i].rgba, 4);
        if (pts->radii)
            pts->radii[i] = recs[i].radius;
        if (pts->labels)
            pts->labels[i] = recs[i].label;
        if (pts->uvs)
            memcpy(pts->uvs + 2 * i, recs[i].uv, sizeof recs[i].uv);
    }
    asp_free(&d->ctx, recs);
    return asp__dist_agree(d, rc, err);
}

static int inside(const float *p, const float *b)
{
    return p[0] >= b[0] && p[1] >= b[1] && p[2] >= b[2] && p[0] <= b[3] && p[1] <= b[4] && p[2] <= b[5];
}

/* A uniform grid over the model's box listing, per cell, the boxes that reach into it (CSR). */
typedef struct box_grid {
    int g;
    float lo[3], inv[3];
    size_t *start; /* g^3 + 1 */
    uint32_t *box;
} box_grid;

static int cell_of(const box_grid *gr, float v, int k)
{
    int c = (int)((v - gr->lo[k]) * gr->inv[k]);
    return c < 0 ? 0 : c >= gr->g ? gr->g - 1 : c;
}

/* At most 128^3 cells: 17 MB of cell starts on every rank when the boxes of all ranks share one grid. */
static int grid_build(const asp_context *ctx, box_grid *gr, const asp__dist_points *pts, const float *boxes, size_t nbox)
{
    int g = (int)(2 * cbrt((double)nbox)) + 1;
    gr->g = g > 128 ? 128 : g;
    for (int k = 0; k < 3; k++) {
        gr->lo[k] = pts->lo[k];
        float ext = pts->hi[k] - pts->lo[k];
        gr->inv[k] = ext > 0 ? (float)gr->g / ext : 0;
    }
    const size_t cells = (size_t)gr->g * gr->g * gr->g;
    gr->start = asp_calloc(ctx, cells + 1, sizeof *gr->start);
    gr->box = NULL;
    if (!gr->start)
        return ASP_ENOMEM;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t b = 0; b < nbox; b++) {
            const float *bb = boxes + 6 * b;
            int c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = cell_of(gr, bb[k], k);
                c1[k] = cell_of(gr, bb[3 + k], k);
            }
            for (int x = c0[0]; x <= c1[0]; x++)
                for (int y = c0[1]; y <= c1[1]; y++)
                    for (int z = c0[2]; z <= c1[2]; z++) {
                        size_t c = ((size_t)x * gr->g + (size_t)y) * gr->g + (size_t)z;
                        if (pass == 0)
                            gr->start[c + 1]++;
                        else
                            gr->box[gr->start[c]++] = (uint32_t)b;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < cells; c++)
                gr->start[c + 1] += gr->start[c];
            gr->box = asp_alloc(ctx, (gr->start[cells] + 1) * sizeof *gr->box);
            if (!gr->box)
                return ASP_ENOMEM;
        } else {
            /* the fill advanced each start to the next cell's: shift back */
            for (size_t c = cells; c > 0; c--)
                gr->start[c] = gr->start[c - 1];
            gr->start[0] = 0;
        }
    }
    return 0;
}

/*
 * The halo by boxes of balls over runs of consecutive points: a piece of a
 * Morton curve is a staircase whose one bounding box can span the whole model
 * (measured: 526k halo points for 1M on 2 ranks with one box per rank), while
 * a short run of consecutive points is compact. Each rank publishes the boxes of its runs' balls; a point goes
 * to rank q when it lies in one of q's boxes, found through a grid of them.
 */
int asp__dist_halo(const asp__dist *d, asp__dist_points *pts, const float *radius, asp_error *err)
{
    const int P = d->size;
    /* runs of at most max(32, N / 2^21) points: about 2^21 boxes in all, below 50 MB on every rank */
    const size_t n = pts->n_own, run = pts->n_global >> 21 > 32 ? pts->n_global >> 21 : 32;
    asp_free(&d->ctx, pts->ghost_gid); /* a new round replaces the last one's halo */
    pts->ghost_gid = NULL;
    pts->n_ghost = 0;
    /*
     * A run also ends where the curve jumps: its points' box may not grow past 8 mean radii (runs of 32
     * points without this limit had boxes as wide as the model and a halo of 243k points for 1M on 2 ranks)
     */
    double mean_r = 0;
    for (size_t i = 0; i < n; i++)
        mean_r += radius[i];
    const float limit = (float)(8 * mean_r / (double)(n ? n : 1));
    float *mine = asp_alloc(&d->ctx, (6 * n + 7) * sizeof *mine);
    int *cnt = asp_calloc(&d->ctx, 6 * (size_t)P, sizeof *cnt);
    if (!mine || !cnt) {
        asp_free(&d->ctx, mine);
        asp_free(&d->ctx, cnt);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the halo");
    }
    size_t nrun = 0;
    for (size_t i = 0; i < n;) {
        float *bb = mine + 6 * nrun++, pl[3], ph[3];
        for (int k = 0; k < 3; k++) {
            bb[k] = pl[k] = INFINITY;
            bb[3 + k] = ph[k] = -INFINITY;
        }
        for (size_t first = i; i < n && i < first + run; i++) {
            const float *p = pts->pos + 3 * i;
            if (i > first && (fmaxf(ph[0], p[0]) - fminf(pl[0], p[0]) > limit ||
                              fmaxf(ph[1], p[1]) - fminf(pl[1], p[1]) > limit ||
                              fmaxf(ph[2], p[2]) - fminf(pl[2], p[2]) > limit))
                break;
            for (int k = 0; k < 3; k++) {
                pl[k] = fminf(pl[k], p[k]);
                ph[k] = fmaxf(ph[k], p[k]);
                bb[k] = fminf(bb[k], p[k] - radius[i]);
                bb[3 + k] = fmaxf(bb[3 + k], p[k] + radius[i]);
            }
        }
    }
    int *bcnt = cnt + 4 * P, *bdis = cnt + 5 * P, nb = (int)nrun * 6, total_boxes = 0;
    MPI_Allgather(&nb, 1, MPI_INT, bcnt, 1, MPI_INT, d->comm);
    for (int q = 0; q < P; q++) {
        bdis[q] = total_boxes;
        total_boxes += bcnt[q];
    }
    float *boxes = asp_alloc(&d->ctx, ((size_t)total_boxes + 1) * sizeof *boxes);
    int ok = boxes != NULL, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (!all) {
        asp_free(&d->ctx, mine);
        asp_free(&d->ctx, cnt);
        asp_free(&d->ctx, boxes);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %d halo boxes", total_boxes / 6);
    }
    MPI_Allgatherv(mine, nb, MPI_FLOAT, boxes, bcnt, bdis, MPI_FLOAT, d->comm);
    asp_free(&d->ctx, mine);
    int *dis = cnt + P, *rcnt = cnt + 2 * P, *rdis = cnt + 3 * P;
    /*
     * One grid over the boxes of every other rank, each box knowing its rank: every owned point is
     * looked up once, whatever P (a grid per rank looked every point up P - 1 times). A point goes to
     * each rank once; the lists come out per rank in increasing point order, as before.
     */
    const size_t nother = (size_t)total_boxes / 6 - (size_t)bcnt[d->rank] / 6;
    float *oth = asp_alloc(&d->ctx, (6 * nother + 6) * sizeof *oth);
    int *oth_rank = asp_alloc(&d->ctx, (nother + 1) * sizeof *oth_rank);
    size_t *seen = asp_calloc(&d->ctx, (size_t)P, sizeof *seen);
    size_t cap = 1024, w = 0;
    struct pair {
        int q;
        asp_index i;
    } *pairs = asp_alloc(&d->ctx, cap * sizeof *pairs);
    int rc = oth && oth_rank && seen && pairs ? 0 : ASP_ENOMEM;
    box_grid gr = {0};
    if (!rc) {
        size_t o = 0;
        for (int q = 0; q < P; q++)
            for (size_t b = (size_t)bdis[q] / 6; q != d->rank && b < (size_t)(bdis[q] + bcnt[q]) / 6; b++, o++) {
                memcpy(oth + 6 * o, boxes + 6 * b, 6 * sizeof *oth);
                oth_rank[o] = q;
            }
        rc = grid_build(&d->ctx, &gr, pts, oth, nother);
    }
    for (size_t i = 0; !rc && i < n; i++) {
        const float *p = pts->pos + 3 * i;
        size_t c = ((size_t)cell_of(&gr, p[0], 0) * gr.g + (size_t)cell_of(&gr, p[1], 1)) * gr.g +
                   (size_t)cell_of(&gr, p[2], 2);
        for (size_t b = gr.start[c]; b < gr.start[c + 1]; b++) {
            const int q = oth_rank[gr.box[b]];
            if (seen[q] == i + 1 || !inside(p, oth + 6 * (size_t)gr.box[b]))
                continue;
            seen[q] = i + 1;
            if (w == cap) {
                struct pair *g = asp_realloc(&d->ctx, pairs, cap * sizeof *pairs, 2 * cap * sizeof *pairs);
                if (!g) {
                    rc = ASP_ENOMEM;
                    break;
                }
                pairs = g;
                cap *= 2;
            }
            pairs[w++] = (struct pair){q, (asp_index)i};
            cnt[q]++;
        }
    }
    asp_free(&d->ctx, gr.start);
    asp_free(&d->ctx, gr.box);
    asp_free(&d->ctx, oth);
    asp_free(&d->ctx, oth_rank);
    asp_free(&d->ctx, seen);
    asp_free(&d->ctx, boxes);
    /* by rank, each rank's points in increasing order (the pairs are in increasing point order) */
    asp_index *sid = rc ? NULL : asp_alloc(&d->ctx, (w + 1) * sizeof *sid);
    if (!rc && !sid)
        rc = ASP_ENOMEM;
    if (!rc) {
        size_t at = 0;
        for (int q = 0; q < P; q++) {
            dis[q] = (int)at;
            at += (size_t)cnt[q];
        }
        int *next = rcnt; /* scratch until the all-to-all below fills it */
        for (int q = 0; q < P; q++)
            next[q] = dis[q];
        for (size_t k = 0; k < w; k++)
            sid[next[pairs[k].q]++] = pairs[k].i; /* local for now */
    }
    asp_free(&d->ctx, pairs);
    float *spos = rc ? NULL : asp_alloc(&d->ctx, (3 * w + 3) * sizeof *spos);
    for (size_t k = 0; spos && k < w; k++) {
        memcpy(spos + 3 * k, pts->pos + 3 * (size_t)sid[k], 3 * sizeof *spos);
        sid[k] = (asp_index)(pts->starts[d->rank] + sid[k]);
    }
    MPI_Alltoall(cnt, 1, MPI_INT, rcnt, 1, MPI_INT, d->comm);
    size_t got = 0;
    for (int q = 0; q < P; q++) {
        rdis[q] = (int)got;
        got += (size_t)rcnt[q];
    }
    float *np = asp_realloc(&d->ctx, pts->pos, (3 * n + 3) * sizeof *np, (3 * (n + got) + 3) * sizeof *np);
    if (np)
        pts->pos = np;
    pts->ghost_gid = asp_alloc(&d->ctx, (got + 1) * sizeof *pts->ghost_gid);
    ok = spos && sid && np && pts->ghost_gid;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (all) {
        MPI_Alltoallv(sid, cnt, dis, MPI_UINT32_T, pts->ghost_gid, rcnt, rdis, MPI_UINT32_T, d->comm);
        MPI_Datatype t;
        MPI_Type_contiguous(3, MPI_FLOAT, &t);
        MPI_Type_commit(&t);
        MPI_Alltoallv(spos, cnt, dis, t, pts->pos + 3 * n, rcnt, rdis, t, d->comm);
        MPI_Type_free(&t);
        pts->n_ghost = got;
    }
    asp_free(&d->ctx, spos);
    asp_free(&d->ctx, sid);
    asp_free(&d->ctx, cnt);
    return all ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for a halo of %zu points", got);
}

void asp__dist_points_release(const asp_context *ctx, asp__dist_points *pts)
{
    asp_free(ctx, pts->starts);
    asp_free(ctx, pts->pos);
    asp_free(ctx, pts->normals);
    asp_free(ctx, pts->colors);
    asp_free(ctx, pts->radii);
    asp_free(ctx, pts->labels);
    asp_free(ctx, pts->uvs);
    asp_free(ctx, pts->ghost_gid);
    memset(pts, 0, sizeof *pts);
}
#else
typedef int asp__dist_points_unused;
#endif
