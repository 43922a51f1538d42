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

void asp__bb_space_add(asp__bb_space *s, const asp__bb_elem *elems, const uint32_t *idx, size_t n, double sign,
                       const asp_context *ctx)
{
    const long dirs = (long)s->dirs;
    const int nth = asp_context_threads(ctx);
    (void)nth;
    /* each direction's row is written by one thread, elements in order: the sums do not depend on the threads */
#pragma omp parallel for schedule(static) num_threads(nth)
    for (long k = 0; k < dirs; k++) {
        const float *dir = s->dir + 3 * k;
        double *row = s->density + (size_t)k * s->nr;
        for (size_t q = 0; q < n; q++) {
            const asp__bb_elem *e = &elems[idx ? idx[q] : q];
            float lo, hi;
            if (!asp__bb_interval(e, dir, s->eps, &lo, &hi))
                continue;
            double w = sign * asp__bb_weight(e, dir);
            long b0 = (long)floorf((lo - s->rmin) / s->rw), b1 = (long)floorf((hi - s->rmin) / s->rw);
            if (b0 < 0)
                b0 = 0;
            if (b1 >= (long)s->nr)
                b1 = (long)s->nr - 1;
            for (long b = b0; b <= b1; b++)
                row[b] += w;
        }
    }
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
