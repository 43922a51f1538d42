/*
 * Support plane of a domain (thesis 3.1, journal 3.1): PCA of the points
 * weighted by Psi, plane through the weighted centroid, normal turned towards
 * the weighted mean point normal, in-plane PCA axes for the bounding
 * rectangle; and the approximation error, the mean point-plane distance (3.2).
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "prim/internal.h"
#include "util/banned.h"

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalise3(double a[3])
{
    double l = sqrt(dot3(a, a));
    if (!(l > 1e-30))
        return -1;
    a[0] /= l, a[1] /= l, a[2] /= l;
    return 0;
}

/* Any unit vector perpendicular to n. */
static void perpendicular(const double n[3], double out[3])
{
    double e[3] = {0, 0, 0};
    int k = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0 : fabs(n[1]) <= fabs(n[2]) ? 1 : 2;
    e[k] = 1;
    cross3(n, e, out);
    normalise3(out);
}

void asp__moments_add_points(asp__moments *m, const float *pos, const float *normals, const asp_index *idx,
                             const double *w, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        const float *p = &pos[3 * (size_t)idx[k]];
        double wk = w ? w[k] : 1.0, x = p[0], y = p[1], z = p[2];
        m->w += wk;
        m->s[0] += wk * x, m->s[1] += wk * y, m->s[2] += wk * z;
        m->ss[0] += wk * x * x, m->ss[1] += wk * x * y, m->ss[2] += wk * x * z;
        m->ss[3] += wk * y * y, m->ss[4] += wk * y * z, m->ss[5] += wk * z * z;
        if (normals)
            for (int j = 0; j < 3; j++)
                m->nrm[j] += wk * normals[3 * (size_t)idx[k] + j];
    }
}

double asp__moments_curvature(const asp__moments *m, double normal[3])
{
    if (!(m->w > 0)) {
        normal[0] = normal[1] = 0, normal[2] = 1;
        return 0;
    }
    double c[3] = {m->s[0] / m->w, m->s[1] / m->w, m->s[2] / m->w};
    /* raw moments lose digits for far-off points; fine for a flatness test on positions near the origin */
    double cov[6] = {m->ss[0] / m->w - c[0] * c[0], m->ss[1] / m->w - c[0] * c[1], m->ss[2] / m->w - c[0] * c[2],
                     m->ss[3] / m->w - c[1] * c[1], m->ss[4] / m->w - c[1] * c[2], m->ss[5] / m->w - c[2] * c[2]};
    double ev[3], vec[9];
    asp_eigen_sym3(cov, ev, vec);
    for (int r = 0; r < 3; r++)
        normal[r] = vec[3 * r + 2];
    if (dot3(normal, m->nrm) < 0)
        normal[0] = -normal[0], normal[1] = -normal[1], normal[2] = -normal[2];
    double sum = ev[0] + ev[1] + ev[2];
    return sum > 0 ? fmax(ev[2], 0) / sum : 0;
}

void asp__prim_plane(const float *pos, const float *normals, const asp_index *idx, const double *w, size_t n,
                     int unweighted, asp__plane *pl)
{
    memset(pl, 0, sizeof *pl);
    /* double sums: a domain holds up to all points and float would lose the centroid's low digits */
    double sw = 0, c[3] = {0, 0, 0}, mn[3] = {0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        double wk = unweighted ? 1.0 : w[k];
        const float *p = &pos[3 * (size_t)idx[k]];
        sw += wk;
        for (int j = 0; j < 3; j++) {
            c[j] += wk * p[j];
            if (normals)
                mn[j] += wk * normals[3 * (size_t)idx[k] + j];
        }
    }
    if (!(sw > 0)) { /* all weights zero cannot happen above tau >= 0, but keep the plane finite */
        sw = (double)n;
        for (size_t k = 0; k < n; k++)
            for (int j = 0; j < 3; j++)
                c[j] += pos[3 * (size_t)idx[k] + j];
    }
    for (int j = 0; j < 3; j++)
        c[j] /= sw;
    double cov[6] = {0, 0, 0, 0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        double wk = unweighted || !(w[k] > 0) ? 1.0 : w[k];
        const float *p = &pos[3 * (size_t)idx[k]];
        double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
        cov[0] += wk * d[0] * d[0], cov[1] += wk * d[0] * d[1], cov[2] += wk * d[0] * d[2];
        cov[3] += wk * d[1] * d[1], cov[4] += wk * d[1] * d[2], cov[5] += wk * d[2] * d[2];
    }
    double ev[3], vec[9];
    asp_eigen_sym3(cov, ev, vec);
    double u[3] = {vec[0], vec[3], vec[6]}, nn[3] = {vec[2], vec[5], vec[8]};
    double sum = ev[0] + ev[1] + ev[2];
    pl->curvature = sum > 0 ? fmax(ev[2], 0) / sum : 0;
    /* 1 or 2 points, or colinear: PCA leaves the normal free about the line; the points' normals fix it */
    pl->degenerate = n < 3 || !(ev[1] > 1e-10 * ev[0]);
    if (pl->degenerate) {
        double m[3] = {mn[0], mn[1], mn[2]};
        if (normalise3(m) == 0) {
            double along = dot3(u, m);
            for (int j = 0; j < 3; j++)
                nn[j] = m[j];
            double uu[3] = {u[0] - along * m[0], u[1] - along * m[1], u[2] - along * m[2]};
            if (ev[0] > 0 && normalise3(uu) == 0)
                memcpy(u, uu, sizeof u);
            else
                perpendicular(nn, u);
        } else if (!(ev[0] > 0)) {
            nn[0] = nn[1] = 0, nn[2] = 1;
            u[0] = 1, u[1] = u[2] = 0;
        }
    }
    if (dot3(nn, mn) < 0)
        for (int j = 0; j < 3; j++)
            nn[j] = -nn[j];
    double v[3];
    cross3(nn, u, v);
    normalise3(v);
    cross3(v, nn, u); /* re-orthogonalise: u = v x n keeps u x v = n exactly */
    memcpy(pl->c, c, sizeof c);
    memcpy(pl->u, u, sizeof u);
    memcpy(pl->v, v, sizeof v);
    memcpy(pl->n, nn, sizeof nn);
    double err = 0;
    pl->smin = pl->tmin = INFINITY;
    pl->smax = pl->tmax = -INFINITY;
    for (size_t k = 0; k < n; k++) {
        const float *p = &pos[3 * (size_t)idx[k]];
        double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
        double s = dot3(d, u), t = dot3(d, v);
        err += fabs(dot3(d, nn));
        pl->smin = fmin(pl->smin, s), pl->smax = fmax(pl->smax, s);
        pl->tmin = fmin(pl->tmin, t), pl->tmax = fmax(pl->tmax, t);
    }
    pl->error = n ? err / (double)n : 0;
}
