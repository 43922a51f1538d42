/*
 * Culling volumes of a hierarchy node (seed 001 section 3.2: "sphere radius
 * r_c and normal-cone [SAE93] semi-angle theta_c bounding all surfels"; seed
 * 004 section 3.2.2): a bounding sphere containing the children's spheres and
 * the node's own ellipse, and a cone of normals containing the children's.
 */
#include <float.h>
#include <math.h>

#include "hier/internal.h"
#include "util/banned.h"

/* sphere (c, r) grown for float storage: relative slack plus a few ulps of the centre */
static void store_sphere(const double c[3], double r, float out[4])
{
    for (int i = 0; i < 3; i++)
        out[i] = (float)c[i];
    double cmax = fmax(fabs(out[0]), fmax(fabs(out[1]), fabs(out[2])));
    out[3] = (float)(r * (1.0 + 1e-6) + 8.0 * FLT_EPSILON * cmax);
}

static double dist3(const double a[3], const float b[3])
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* radius of the sphere at c that contains ellipse s: its centre distance plus major semi-axis */
static double own_extent(const double c[3], const asp_hier_splat *s)
{
    return dist3(c, s->center) + s->a;
}

static void rounded_center(const double lo[3], const double hi[3], double c[3])
{
    /* use the float the centre will be stored as, so containment holds for the stored sphere */
    for (int i = 0; i < 3; i++)
        c[i] = (float)(0.5 * (lo[i] + hi[i]));
}

void asp__sphere_of_nodes(const asp_hier_node *children, size_t count, const asp_hier_splat *own, float out[4])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < count; i++) {
        for (int d = 0; d < 3; d++) {
            double r = children[i].sphere[3];
            lo[d] = fmin(lo[d], (double)children[i].sphere[d] - r);
            hi[d] = fmax(hi[d], (double)children[i].sphere[d] + r);
        }
    }
    double c[3];
    rounded_center(lo, hi, c);
    double r = own_extent(c, own);
    for (size_t i = 0; i < count; i++)
        r = fmax(r, dist3(c, children[i].sphere) + children[i].sphere[3]);
    store_sphere(c, r, out);
}

void asp__sphere_of_points(const asp_hier_splat *points, size_t count, const asp_hier_splat *own, float out[4])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < count; i++) {
        for (int d = 0; d < 3; d++) {
            double r = points[i].a;
            lo[d] = fmin(lo[d], (double)points[i].center[d] - r);
            hi[d] = fmax(hi[d], (double)points[i].center[d] + r);
        }
    }
    double c[3];
    rounded_center(lo, hi, c);
    double r = own_extent(c, own);
    for (size_t i = 0; i < count; i++)
        r = fmax(r, dist3(c, points[i].center) + points[i].a);
    store_sphere(c, r, out);
}

float asp__cone_bound(const float axis[3], const asp_hier_splat *members, const asp_hier_node *member_nodes,
                      size_t count)
{
    /*
     * Cones of half-angles theta_i around n_i lie inside the cone around axis
     * of half-angle max(angle(axis, n_i) + theta_i) (triangle inequality on
     * the sphere of directions).
     */
    double theta = 0;
    if (!member_nodes) {
        /* points have no cone of their own: the widest angle is the smallest cosine, one acos */
        double lo = 1;
        for (size_t i = 0; i < count; i++) {
            const float *n = members[i].normal;
            double d = (double)axis[0] * n[0] + (double)axis[1] * n[1] + (double)axis[2] * n[2];
            lo = d < lo ? d : lo;
        }
        theta = acos(lo < -1 ? -1 : lo);
    }
    for (size_t i = 0; member_nodes && i < count; i++) {
        const float *n = members[i].normal;
        double d = (double)axis[0] * n[0] + (double)axis[1] * n[1] + (double)axis[2] * n[2];
        d = d > 1 ? 1 : (d < -1 ? -1 : d);
        double t = acos(d) + member_nodes[i].cone_angle;
        if (t > theta)
            theta = t;
    }
    /* a few 1e-6 rad for the float normals, whose length is 1 only to rounding */
    theta += 4e-6;
    return theta >= ASP_HIER_PI ? (float)ASP_HIER_PI : (float)theta;
}
