/*
 * The greedy plane search of a billboard cloud (Decoret, Durand, Sillion and
 * Dorsey 2003, section 4.3): take the densest bin of the plane space, refine
 * inside it (its angular cell subdivided, the best offset for each direction
 * found by a sweep over the candidates' validity intervals), give the plane
 * every element valid for it, remove their contributions and repeat until all
 * elements are taken or the plane budget is spent. An element no bin holds (a
 * large face whose valid directions fall between bin centres) gets a plane of
 * its own, with the offset chosen to take as much else as it can.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "prim/billboard_internal.h"
#include "util/banned.h"

enum { SUB = 4, REFINE_LEVELS = 3, SWEEP_BINS = 96 };

typedef struct sweep {
    double *acc;      /* SWEEP_BINS + 1 difference array */
} sweep;

/*
 * Best offset for direction n over the elements idx[0..m-1] within [base, base + span]: each valid
 * element adds its weight to the fine bins lying wholly inside its interval, so the chosen bin's
 * centre is valid for every element counted. Returns the weight, *rho the offset.
 */
static double best_offset(const asp__bb_elem *elems, const uint32_t *idx, size_t m, const float n[3], float eps,
                          double base, double span, double *acc, double *rho)
{
    const double fw = span / SWEEP_BINS;
    memset(acc, 0, (SWEEP_BINS + 1) * sizeof *acc);
    for (size_t q = 0; q < m; q++) {
        float lo, hi;
        const asp__bb_elem *e = &elems[idx[q]];
        if (!asp__bb_interval(e, n, eps, &lo, &hi))
            continue;
        long b0 = (long)ceil(((double)lo - base) / fw), b1 = (long)floor(((double)hi - base) / fw) - 1;
        if (b0 < 0)
            b0 = 0;
        if (b1 > SWEEP_BINS - 1)
            b1 = SWEEP_BINS - 1;
        if (b0 > b1)
            continue;
        /* a tiny share of the area too, so faces seen edge-on still count and a plane always takes something */
        double w = asp__bb_weight(e, n) + 1e-6 * e->area + 1e-30;
        acc[b0] += w;
        acc[b1 + 1] -= w;
    }
    double run = 0, best = 0;
    long bi = -1;
    for (long b = 0; b < SWEEP_BINS; b++) {
        run += acc[b];
        if (run > best * (1 + 1e-12) + 1e-300)
            best = run, bi = b;
    }
    if (bi >= 0)
        *rho = base + (bi + 0.5) * fw;
    return bi >= 0 ? best : 0;
}

/* Refines the bin (direction k, offset bin b): the best (n, rho) over subdivided cells; 0 when none. */
static double refine(const asp__bb_space *s, const asp__bb_elem *elems, const uint32_t *cand, size_t m, size_t k,
                     uint32_t b, double *acc, float n_out[3], double *rho_out)
{
    const double dt = (ASP__BB_PI / 2) / s->nt, dp = (2 * ASP__BB_PI) / s->np;
    double tc = ((double)(k / s->np) + 0.5) * dt, pc = ((double)(k % s->np) + 0.5) * dp;
    const double base = s->rmin + (double)b * s->rw - 1.5 * s->eps, span = s->rw + 3.0 * s->eps;
    double best = 0;
    float n[3];
    asp__bb_direction(tc, pc, n);
    double rho = 0, w = best_offset(elems, cand, m, n, s->eps, base, span, acc, &rho);
    if (w > best)
        best = w, memcpy(n_out, n, sizeof n), *rho_out = rho;
    double ht = dt, hp = dp;
    for (int level = 0; level < REFINE_LEVELS; level++) {
        double bt = tc, bp = pc;
        for (int i = 0; i < SUB; i++)
            for (int j = 0; j < SUB; j++) {
                double t = tc - ht / 2 + (i + 0.5) * ht / SUB, p = pc - hp / 2 + (j + 0.5) * hp / SUB;
                asp__bb_direction(t, p, n);
                w = best_offset(elems, cand, m, n, s->eps, base, span, acc, &rho);
                if (w > best * (1 + 1e-9))
                    best = w, memcpy(n_out, n, sizeof n), *rho_out = rho, bt = t, bp = p;
            }
        tc = bt, pc = bp, ht /= SUB / 2.0, hp /= SUB / 2.0;
    }
    return best;
}

int asp__bb_search(const asp__bb_input *in, const asp_billboard_desc *d, const asp_context *ctx,
                   asp_billboard_plane **planes_out, size_t *plane_count, uint32_t *assign_out,
                   asp_billboard_stats *st_out, asp_error *err)
{
    if (!(d->error > 0 && d->error <= 1))
        return asp_error_set(err, ASP_EINVAL, "billboard error bound %g, expected a fraction of the diagonal in (0, 1]",
                             d->error);
    if (d->theta_bins > 1024 || d->phi_bins > 4096)
        return asp_error_set(err, ASP_EINVAL, "plane space of %u x %u angle bins, expected at most 1024 x 4096",
                             d->theta_bins, d->phi_bins);
    const double t0 = asp_time_now();
    const uint32_t nt = d->theta_bins ? d->theta_bins : 24, np = d->phi_bins ? d->phi_bins : 4 * nt;
    const double eps = d->error * in->diagonal;
    const size_t n = in->count;
    const asp__bb_elem *elems = in->elems;
    asp__bb_space s;
    int rc = asp__bb_space_init(&s, nt, np, in->half, eps, ctx, err);
    if (rc)
        return rc;
    size_t cap = 64, count = 0;
    asp_billboard_plane *planes = asp_alloc(ctx, cap * sizeof *planes);
    uint32_t *assign = asp_alloc(ctx, n * sizeof *assign), *cand = asp_alloc(ctx, n * sizeof *cand),
             *took = asp_alloc(ctx, n * sizeof *took);
    double *acc = asp_alloc(ctx, (SWEEP_BINS + 1) * sizeof *acc);
    if (!planes || !assign || !cand || !took || !acc) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the billboard search of %zu elements", n);
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        assign[i] = UINT32_MAX;
    asp__bb_space_add(&s, elems, NULL, n, 1.0, ctx);
    double total_area = 0;
    for (size_t i = 0; i < n; i++)
        total_area += elems[i].area;
    const double floor_density = 1e-9 * total_area + 1e-300;
    size_t left = n, fallbacks = 0;
    while (left && (!d->max_planes || count < d->max_planes)) {
        if ((rc = asp_progress(ctx, "billboards", 1.0 - (double)left / (double)n)) != 0) {
            rc = asp_error_set(err, rc, "billboard search canceled");
            goto done;
        }
        size_t k;
        uint32_t b;
        float pn[3] = {0, 0, 1};
        double rho = 0, got = 0;
        int fallback = 0;
        if (asp__bb_space_best(&s, &k, &b) > floor_density) {
            /* candidates: the uncovered elements valid somewhere in the bin at its centre direction */
            const float *dir = s.dir + 3 * k;
            const float r0 = s.rmin + (float)b * s.rw, r1 = r0 + s.rw;
            size_t m = 0;
            for (size_t i = 0; i < n; i++) {
                float lo, hi;
                if (assign[i] == UINT32_MAX && asp__bb_interval(&elems[i], dir, s.eps, &lo, &hi) && hi >= r0 && lo <= r1)
                    cand[m++] = (uint32_t)i;
            }
            got = m ? refine(&s, elems, cand, m, k, b, acc, pn, &rho) : 0;
            if (!(got > 0)) { /* rounding residue of removed contributions: empty the bin and look again */
                s.density[k * s.nr + b] = 0;
                continue;
            }
        } else {
            /* no bin holds what is left: the largest uncovered element's own plane (Decoret 2003 would miss it) */
            size_t e = SIZE_MAX;
            for (size_t i = 0; i < n; i++)
                if (assign[i] == UINT32_MAX && (e == SIZE_MAX || elems[i].area > elems[e].area))
                    e = i;
            memcpy(pn, elems[e].own, sizeof pn);
            float lo, hi;
            asp__bb_interval(&elems[e], pn, s.eps, &lo, &hi);
            size_t m = 0;
            for (size_t i = 0; i < n; i++)
                if (assign[i] == UINT32_MAX)
                    cand[m++] = (uint32_t)i;
            /* the offset that takes most within the element's own interval, so it is taken itself */
            if (!(best_offset(elems, cand, m, pn, s.eps, lo, fmax((double)hi - lo, 1e-30), acc, &rho) > 0))
                rho = 0.5 * ((double)lo + hi);
            fallback = 1;
            fallbacks++;
        }
        /* the plane takes every uncovered element valid for it */
        size_t m = 0;
        double area = 0, orient = 0;
        for (size_t i = 0; i < n; i++) {
            float lo, hi;
            if (assign[i] != UINT32_MAX || !asp__bb_interval(&elems[i], pn, s.eps, &lo, &hi) || !(lo <= rho && rho <= hi))
                continue;
            took[m++] = (uint32_t)i;
            assign[i] = (uint32_t)count;
            area += elems[i].area;
            orient += elems[i].area * ((double)pn[0] * elems[i].n[0] + (double)pn[1] * elems[i].n[1] +
                                       (double)pn[2] * elems[i].n[2]);
        }
        if (!m) { /* cannot happen for a fallback (its element is valid); guard against an endless loop */
            if (fallback) {
                rc = asp_error_set(err, ASP_EDEGENERATE, "billboard search stalled with %zu elements left", left);
                goto done;
            }
            s.density[k * s.nr + b] = 0;
            continue;
        }
        asp__bb_space_add(&s, elems, took, m, -1.0, ctx);
        left -= m;
        if (count == cap) {
            asp_billboard_plane *grown = asp_realloc(ctx, planes, cap * sizeof *planes, 2 * cap * sizeof *planes);
            if (!grown) {
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboard planes", 2 * cap);
                goto done;
            }
            planes = grown, cap *= 2;
        }
        asp_billboard_plane *P = &planes[count];
        memset(P, 0, sizeof *P);
        double sgn = orient < 0 ? -1.0 : 1.0; /* face the covered side: the texture's front */
        for (int c = 0; c < 3; c++)
            P->normal[c] = sgn * pn[c];
        P->offset = sgn * rho;
        P->elements = m;
        P->area = area;
        P->fallback = fallback;
        count++;
    }
    asp_billboard_stats st = {0};
    st.elements = n;
    st.planes = count;
    st.uncovered = left;
    st.fallbacks = fallbacks;
    st.eps = eps;
    st.diagonal = in->diagonal;
    for (size_t i = 0; i < n; i++) {
        if (assign[i] == UINT32_MAX)
            continue;
        const asp_billboard_plane *P = &planes[assign[i]];
        const asp__bb_elem *e = &elems[i];
        if (e->r > 0) {
            double c = P->normal[0] * e->n[0] + P->normal[1] * e->n[1] + P->normal[2] * e->n[2];
            double ext = (e->n[0] || e->n[1] || e->n[2]) ? e->r * sqrt(fmax(0.0, 1.0 - c * c)) : 0.0;
            double dd = fabs(P->normal[0] * e->p[0] + P->normal[1] * e->p[1] + P->normal[2] * e->p[2] - P->offset) + ext;
            st.max_distance = fmax(st.max_distance, dd);
        } else {
            for (int j = 0; j < 3; j++) {
                const float *v = e->p + 3 * j;
                double dd = fabs(P->normal[0] * v[0] + P->normal[1] * v[1] + P->normal[2] * v[2] - P->offset);
                st.max_distance = fmax(st.max_distance, dd);
            }
        }
    }
    st.t_search = asp_time_now() - t0;
    if (st_out)
        *st_out = st;
    memcpy(assign_out, assign, n * sizeof *assign);
    *planes_out = planes;
    *plane_count = count;
    planes = NULL;
done:
    asp_free(ctx, planes);
    asp_free(ctx, assign);
    asp_free(ctx, cand);
    asp_free(ctx, took);
    asp_free(ctx, acc);
    asp__bb_space_release(&s, ctx);
    return rc;
}

/* Planes from the input's local frame (relative to in->centre) to the caller's (the input's positions). */
static void to_input_frame(const asp__bb_input *in, asp_billboard_plane *planes, size_t count)
{
    for (size_t i = 0; i < count; i++)
        planes[i].offset += planes[i].normal[0] * in->centre[0] + planes[i].normal[1] * in->centre[1] +
                            planes[i].normal[2] * in->centre[2];
}

int asp_billboard_search_mesh(const asp_mesh *mesh, const asp_billboard_desc *desc, const asp_context *ctx,
                              asp_billboard_plane **planes, size_t *plane_count, uint32_t *assign,
                              asp_billboard_stats *stats, asp_error *err)
{
    ASP_ASSERT(mesh && desc && planes && plane_count && assign);
    asp__bb_input in;
    int rc = asp__bb_input_mesh(mesh, ctx, &in, err);
    if (!rc)
        rc = asp__bb_search(&in, desc, ctx, planes, plane_count, assign, stats, err);
    if (!rc)
        to_input_frame(&in, *planes, *plane_count);
    asp__bb_input_release(&in, ctx);
    return rc;
}

int asp_billboard_search_cloud(const asp_cloud *cloud, const asp_billboard_desc *desc, const asp_context *ctx,
                               asp_billboard_plane **planes, size_t *plane_count, uint32_t *assign,
                               asp_billboard_stats *stats, asp_error *err)
{
    ASP_ASSERT(cloud && desc && planes && plane_count && assign);
    asp__bb_input in;
    int rc = asp__bb_input_cloud(cloud, ctx, &in, err);
    if (!rc)
        rc = asp__bb_search(&in, desc, ctx, planes, plane_count, assign, stats, err);
    if (!rc)
        to_input_frame(&in, *planes, *plane_count);
    asp__bb_input_release(&in, ctx);
    return rc;
}
