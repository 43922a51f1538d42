/*
 * The discretised plane space of a billboard cloud and its density (Decoret,
 * Durand, Sillion and Dorsey 2003, section 4.2): planes n . x = rho with n on
 * the half sphere in spherical angles (theta, phi) and rho in bins of one eps;
 * an element adds its projected area to every bin (direction, offset range)
 * holding a plane it is valid for. The greedy search reads the densest bin,
 * refines inside it and removes what the chosen plane covers, so the same
 * function adds and subtracts contributions.
 */
#include <math.h>
#include <string.h>

#include "prim/billboard_internal.h"
#include "util/banned.h"

void asp__bb_direction(double theta, double phi, float n[3])
{
    n[0] = (float)(sin(theta) * cos(phi));
    n[1] = (float)(sin(theta) * sin(phi));
    n[2] = (float)cos(theta);
}

int asp__bb_space_init(asp__bb_space *s, uint32_t nt, uint32_t np, double half, double eps, const asp_context *ctx,
                       asp_error *err)
{
    memset(s, 0, sizeof *s);
    s->nt = nt, s->np = np;
    s->dirs = (size_t)nt * np;
    s->eps = (float)eps;
    /* bins of one eps: a valid offset range is at most 2 eps wide, so an element touches at most 3 bins */
    s->rw = (float)eps;
    s->rmin = (float)(-half - eps);
    double nr = ceil((2.0 * half + 2.0 * eps) / eps) + 1;
    if (nr > 1e6)
        return asp_error_set(err, ASP_EINVAL, "error bound %g of a %g extent needs %g offset bins; use a larger bound",
                             eps, 2 * half, nr);
    s->nr = (uint32_t)nr;
    s->dir = asp_alloc(ctx, 3 * s->dirs * sizeof *s->dir);
    s->density = asp_calloc(ctx, s->dirs * s->nr, sizeof *s->density);
    if (!s->dir || !s->density) {
        asp__bb_space_release(s, ctx);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %zu x %u plane space", s->dirs, (unsigned)nr);
    }
    for (uint32_t i = 0; i < nt; i++)
        for (uint32_t j = 0; j < np; j++)
            asp__bb_direction((i + 0.5) * (ASP__BB_PI / 2) / nt, (j + 0.5) * (2 * ASP__BB_PI) / np,
                              s->dir + 3 * ((size_t)i * np + j));
    return 0;
}

void asp__bb_space_release(asp__bb_space *s, const asp_context *ctx)
{
    asp_free(ctx, s->dir);
    asp_free(ctx, s->density);
    memset(s, 0, sizeof *s);
}

enum { CHUNK = 256 };

/*
 * The elements' data as structure of arrays (x, y, z of up to three points, normal, area, radius), so
 * the intervals of a chunk of elements for one direction compute in SIMD lanes before the scatter.
 */
typedef struct soa {
    float *c[9], *n[3], *area, *r;
} soa;

void asp__bb_space_add(asp__bb_space *s, const asp__bb_elem *elems, const uint32_t *idx, size_t n, double sign,
                       const asp_context *ctx)
{
    if (!n)
        return;
    const int discs = elems[idx ? idx[0] : 0].r > 0;
    float *buf = asp_alloc(ctx, 14 * n * sizeof *buf);
    soa a;
    if (buf) {
        for (int k = 0; k < 9; k++)
            a.c[k] = buf + (size_t)k * n;
        for (int k = 0; k < 3; k++)
            a.n[k] = buf + (size_t)(9 + k) * n;
        a.area = buf + 12 * n, a.r = buf + 13 * n;
        for (size_t q = 0; q < n; q++) {
            const asp__bb_elem *e = &elems[idx ? idx[q] : q];
            for (int k = 0; k < 9; k++)
                a.c[k][q] = e->p[k];
            for (int k = 0; k < 3; k++)
                a.n[k][q] = e->n[k];
            a.area[q] = e->area, a.r[q] = e->r;
        }
    }
    const long dirs = (long)s->dirs;
    const int nth = asp_context_threads(ctx);
    const float inv = 1.0f / s->rw, eps = s->eps;
    (void)nth;
    /* each direction's row is written by one thread, elements in order: the sums do not depend on the threads */
#pragma omp parallel for schedule(static) num_threads(nth)
    for (long k = 0; k < dirs; k++) {
        const float dx = s->dir[3 * k], dy = s->dir[3 * k + 1], dz = s->dir[3 * k + 2];
        double *row = s->density + (size_t)k * s->nr;
        float lo[CHUNK], hi[CHUNK], w[CHUNK];
        for (size_t q0 = 0; q0 < n; q0 += CHUNK) {
            const size_t m = n - q0 < CHUNK ? n - q0 : CHUNK;
            if (!buf) { /* out of memory for the copy: the same numbers element by element */
                for (size_t q = 0; q < m; q++) {
                    const asp__bb_elem *e = &elems[idx ? idx[q0 + q] : q0 + q];
                    if (!asp__bb_interval(e, s->dir + 3 * k, eps, &lo[q], &hi[q]))
                        lo[q] = 1, hi[q] = 0;
                    w[q] = asp__bb_weight(e, s->dir + 3 * k);
                }
            } else if (discs) {
                const float *cx = a.c[0] + q0, *cy = a.c[1] + q0, *cz = a.c[2] + q0, *nx = a.n[0] + q0,
                            *ny = a.n[1] + q0, *nz = a.n[2] + q0, *ar = a.area + q0, *rr = a.r + q0;
#pragma omp simd
                for (size_t q = 0; q < m; q++) {
                    float sd = dx * cx[q] + dy * cy[q] + dz * cz[q], c = dx * nx[q] + dy * ny[q] + dz * nz[q];
                    float has = nx[q] * nx[q] + ny[q] * ny[q] + nz[q] * nz[q];
                    float s2 = 1.0f - c * c, ext = has > 0 && s2 > 0 ? rr[q] * sqrtf(s2) : 0.0f;
                    lo[q] = sd + ext - eps, hi[q] = sd - ext + eps;
                    w[q] = has > 0 ? ar[q] * fabsf(c) : ar[q];
                }
            } else {
                float *const *c = a.c;
                const float *nx = a.n[0] + q0, *ny = a.n[1] + q0, *nz = a.n[2] + q0, *ar = a.area + q0;
                const float *x0 = c[0] + q0, *y0 = c[1] + q0, *z0 = c[2] + q0, *x1 = c[3] + q0, *y1 = c[4] + q0,
                            *z1 = c[5] + q0, *x2 = c[6] + q0, *y2 = c[7] + q0, *z2 = c[8] + q0;
#pragma omp simd
                for (size_t q = 0; q < m; q++) {
                    float p0 = dx * x0[q] + dy * y0[q] + dz * z0[q], p1 = dx * x1[q] + dy * y1[q] + dz * z1[q],
                          p2 = dx * x2[q] + dy * y2[q] + dz * z2[q];
                    /* ternaries, not fmaxf: without -ffinite-math-only fmaxf is a libm call per lane */
                    float mx = p0 > p1 ? p0 : p1, mn = p0 < p1 ? p0 : p1;
                    mx = mx > p2 ? mx : p2, mn = mn < p2 ? mn : p2;
                    lo[q] = mx - eps;
                    hi[q] = mn + eps;
                    w[q] = ar[q] * fabsf(dx * nx[q] + dy * ny[q] + dz * nz[q]);
                }
            }
            for (size_t q = 0; q < m; q++) {
                if (!(lo[q] <= hi[q]))
                    continue;
                /* offsets are above rmin by construction (rmin is below every point by eps) */
                long b0 = (long)((lo[q] - s->rmin) * inv), b1 = (long)((hi[q] - s->rmin) * inv);
                if (b0 < 0)
                    b0 = 0;
                if (b1 >= (long)s->nr)
                    b1 = (long)s->nr - 1;
                const double wq = sign * w[q];
                for (long b = b0; b <= b1; b++)
                    row[b] += wq;
            }
        }
    }
    asp_free(ctx, buf);
}

double asp__bb_space_best(const asp__bb_space *s, size_t *k, uint32_t *b)
{
    double best = 0;
    size_t bk = 0;
    uint32_t bb = 0;
    const size_t total = s->dirs * s->nr;
    for (size_t i = 0; i < total; i++)
        if (s->density[i] > best)
            best = s->density[i], bk = i / s->nr, bb = (uint32_t)(i % s->nr);
    *k = bk;
    *b = bb;
    return best;
}
