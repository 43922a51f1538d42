/*
 * Elliptical splat of a hierarchy node in its tangent plane (seed 001 section
 * 3.4): axis directions and ratio from the tangent-plane covariance (eq. 5-6),
 * then scaled by the smallest f that covers every member's ellipse, not just
 * its centre (Fig. 6b), so coarse levels leave no holes.
 */
#include <float.h>
#include <math.h>

#include "hier/internal.h"
#include "util/banned.h"

/* smallest axis ratio b/a kept, so that the ellipse norm never divides by zero */
#define MIN_RATIO 1e-3

void asp__tangent_basis(const double n[3], double t1[3], double t2[3])
{
    /* Duff et al. 2017, "Building an orthonormal basis, revisited": continuous except at n.z = 0 sign flip */
    double sign = n[2] >= 0 ? 1.0 : -1.0;
    double a = -1.0 / (sign + n[2]);
    double b = n[0] * n[1] * a;
    t1[0] = 1.0 + sign * n[0] * n[0] * a;
    t1[1] = sign * b;
    t1[2] = -sign * n[0];
    t2[0] = b;
    t2[1] = sign + n[1] * n[1] * a;
    t2[2] = -n[1];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* t^T C s for the symmetric C stored xx xy xz yy yz zz */
static double quad(const double c[6], const double t[3], const double s[3])
{
    double cs0 = c[0] * s[0] + c[1] * s[1] + c[2] * s[2];
    double cs1 = c[1] * s[0] + c[3] * s[1] + c[4] * s[2];
    double cs2 = c[2] * s[0] + c[4] * s[1] + c[5] * s[2];
    return t[0] * cs0 + t[1] * cs1 + t[2] * cs2;
}

void asp__ellipse_axes(asp_hier_splat *s, const double c[6], double extent2, int lambda_axes)
{
    double n[3] = {s->normal[0], s->normal[1], s->normal[2]};
    double t1[3], t2[3];
    asp__tangent_basis(n, t1, t2);
    /* eq. 3 with R = (t1, t2, n): the upper-left 2x2 of R C R^T is the covariance in the plane */
    double s11 = quad(c, t1, t1) + extent2;
    double s12 = quad(c, t1, t2);
    double s22 = quad(c, t2, t2) + extent2;
    /* eq. 5: eigenvalues of the 2x2 matrix; eq. 6: the major eigenvector */
    double half_tr = 0.5 * (s11 + s22);
    double d = sqrt(0.25 * (s11 - s22) * (s11 - s22) + s12 * s12);
    double l1 = half_tr + d, l2 = half_tr - d;
    double e1x, e1y;
    if (fabs(s12) > 1e-300 && d > 0) {
        e1x = l1 - s22;
        e1y = s12;
        /* of the two equivalent forms pick the better conditioned one */
        if (fabs(s11 - l1) > fabs(e1x)) {
            e1x = s12;
            e1y = l1 - s11;
        }
        double len = sqrt(e1x * e1x + e1y * e1y);
        e1x /= len;
        e1y /= len;
    } else if (s11 >= s22) {
        e1x = 1;
        e1y = 0;
    } else {
        e1x = 0;
        e1y = 1;
    }
    /*
     * The paper takes a' = l1, b' = l2 (eq. 5-6; lambda_axes); only the ratio
     * matters because f rescales. Standard deviations give the ratio of the
     * point spread, so that is the default (ASP_HIER_BUILD_LAMBDA_AXES).
     */
    double ratio = l1 > 0 ? (l2 > 0 ? l2 / l1 : 0.0) : 1.0;
    if (!lambda_axes)
        ratio = sqrt(ratio);
    if (ratio < MIN_RATIO)
        ratio = MIN_RATIO;
    for (int i = 0; i < 3; i++) {
        s->u[i] = (float)(e1x * t1[i] + e1y * t2[i]);
        s->v[i] = (float)(-e1y * t1[i] + e1x * t2[i]);
    }
    s->a = 1.0f;
    s->b = (float)ratio;
}

void asp__ellipse_scale(asp_hier_splat *s, double f)
{
    /*
     * Inflate by a relative 1e-5 and by a few float ulps of the centre's
     * magnitude: the axes, centre and lengths are stored as float, and the
     * covering must survive that rounding.
     */
    double cmax = fmax(fabs(s->center[0]), fmax(fabs(s->center[1]), fabs(s->center[2])));
    double slack = f > 0 ? 8.0 * FLT_EPSILON * cmax : 0.0;
    double a = f * s->a * (1.0 + 1e-5) + slack;
    double b = f * s->b * (1.0 + 1e-5) + slack;
    s->a = (float)a;
    s->b = (float)(b < a ? b : a);
}

/* s0 = offset of q from s's centre in ellipse-normalised coordinates */
static void normalise(const asp_hier_splat *s, const double d[3], double out[2])
{
    double u[3] = {s->u[0], s->u[1], s->u[2]}, v[3] = {s->v[0], s->v[1], s->v[2]};
    out[0] = dot3(d, u) / s->a;
    out[1] = dot3(d, v) / s->b;
}

double asp__ellipse_point_norm(const asp_hier_splat *s, const float p[3])
{
    double d[3] = {(double)p[0] - s->center[0], (double)p[1] - s->center[1], (double)p[2] - s->center[2]};
    if (!(s->a > 0) || !(s->b > 0)) {
        double u[3] = {s->u[0], s->u[1], s->u[2]}, v[3] = {s->v[0], s->v[1], s->v[2]};
        return (dot3(d, u) == 0 && dot3(d, v) == 0) ? 0.0 : INFINITY;
    }
    double q[2];
    normalise(s, d, q);
    return sqrt(q[0] * q[0] + q[1] * q[1]);
}

double asp__ellipse_cover_norm(const asp_hier_splat *s, const asp_hier_splat *m)
{
    double s0 = asp__ellipse_point_norm(s, m->center);
    if (!(m->a > 0))
        return s0;
    if (!(s->a > 0) || !(s->b > 0))
        return INFINITY;
    /*
     * The member ellipse projects to {q0 + B w : |w| <= 1}, an ellipse in s's
     * normalised plane. Two upper bounds of max |q0 + B w|: the corners of its
     * bounding parallelogram (the paper's bounding boxes, Fig. 6b) and
     * |q0| + sigma_max(B); the smaller is still conservative and is exact
     * for a centred member.
     */
    double d[3] = {(double)m->center[0] - s->center[0], (double)m->center[1] - s->center[1],
                   (double)m->center[2] - s->center[2]};
    double q0[2], bu[2], bv[2];
    normalise(s, d, q0);
    double mu[3] = {(double)m->u[0] * m->a, (double)m->u[1] * m->a, (double)m->u[2] * m->a};
    double mv[3] = {(double)m->v[0] * m->b, (double)m->v[1] * m->b, (double)m->v[2] * m->b};
    normalise(s, mu, bu);
    normalise(s, mv, bv);
    double corner = 0;
    for (int i = 0; i < 4; i++) {
        double su = (i & 1) ? 1.0 : -1.0, sv = (i & 2) ? 1.0 : -1.0;
        double x = q0[0] + su * bu[0] + sv * bv[0];
        double y = q0[1] + su * bu[1] + sv * bv[1];
        double r = x * x + y * y;
        if (r > corner)
            corner = r;
    }
    corner = sqrt(corner);
    /* sigma_max^2 = largest eigenvalue of B^T B, B = [bu bv] */
    double p11 = bu[0] * bu[0] + bu[1] * bu[1];
    double p12 = bu[0] * bv[0] + bu[1] * bv[1];
    double p22 = bv[0] * bv[0] + bv[1] * bv[1];
    double sig2 = 0.5 * (p11 + p22) + sqrt(0.25 * (p11 - p22) * (p11 - p22) + p12 * p12);
    double spectral = sqrt(q0[0] * q0[0] + q0[1] * q0[1]) + sqrt(sig2);
    return corner < spectral ? corner : spectral;
}

void asp__ellipse_fit(asp_hier_splat *s, const double c[6], const asp_hier_splat *members, size_t count,
                      int lambda_axes)
{
    /*
     * The covariance of the member centres ignores the members' own extent,
     * so one member, or colinear members, would give a needle. Adding the
     * mean in-plane second moment of the member disks ((a^2 + b^2) / 8 per
     * axis for a uniform elliptic disk, averaged over directions) keeps the
     * ratio meaningful; a deviation from the paper, which has point members.
     */
    double extent2 = 0;
    for (size_t i = 0; i < count; i++)
        extent2 += ((double)members[i].a * members[i].a + (double)members[i].b * members[i].b) * 0.125;
    extent2 /= (double)(count ? count : 1);
    asp__ellipse_axes(s, c, extent2, lambda_axes);
    double f = 0;
    for (size_t i = 0; i < count; i++) {
        double r = asp__ellipse_cover_norm(s, &members[i]);
        if (r > f)
            f = r;
    }
    asp__ellipse_scale(s, f);
}
