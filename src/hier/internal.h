/*
 * Private parts of the hierarchy module: the asp_hier object, and the
 * per-concept kernels shared by the build (octree_build.c), the point and node
 * ellipses (point_ellipse.c, ellipse.c), the generic homogeneous covariance
 * (covariance.c) and bounding volumes (normal_cone.c). Not public API.
 */
#ifndef ASP_HIER_INTERNAL_H
#define ASP_HIER_INTERNAL_H

#include <assert.h>

#include "amgsplat/hier.h"

_Static_assert(sizeof(asp_hier_splat) == 64, "asp_hier_splat is uploaded to GL as 4 vec4");
_Static_assert(sizeof(asp_hier_node) == 48, "asp_hier_node is uploaded to GL as 3 vec4");

enum {
    ASP_HIER_COV = 10,            /* doubles per generic homogeneous covariance */
    ASP_HIER_MAX_LEAF = 65536,    /* largest leaf_size accepted */
    ASP_HIER_SPLIT_DEPTH = 40,    /* below this depth split by count, bounding the depth (see octree_build.c) */
    ASP_HIER_MAX_DEPTH = 64       /* no node is deeper: 40 mean splits + log8(2^32) count splits */
};

#define ASP_HIER_PI 3.14159265358979323846

struct asp_hier {
    asp_context ctx;
    size_t node_count;
    size_t point_count;
    size_t leaf_size;
    uint32_t depth;
    unsigned flags;
    double origin[3];
    asp_hier_node *nodes;   /* node_count */
    asp_hier_splat *splats; /* node_count + point_count */
    double *cov;            /* ASP_HIER_COV * node_count */
    asp_frame frame;        /* the source points' frame (asp_cloud_frame) */
};

/* Advises the kernel to back a large block with huge pages (Linux; otherwise a no-op). */
void asp__hier_huge_pages(void *ptr, size_t size);

/* Allocates an empty hierarchy object with arrays for the given sizes. */
int asp__hier_alloc(const asp_context *ctx, size_t node_count, size_t point_count, asp_hier **out,
                    asp_error *err);

/*
 * Per-point splats (point_ellipse.c): dst[slot[i]] is the splat of input
 * point i, and order is the inverse permutation (order[slot[i]] = i).
 * Circles from radii, or bounding ellipses of the k nearest neighbours (seed
 * 001, end of 3.4); PCA normals when the cloud has none. Sets ASP_HIER_* bits
 * in *flags.
 */
int asp__hier_point_splats(const asp_cloud *cloud, size_t k, unsigned build_flags, const asp_index *slot,
                           const asp_index *order, const asp_context *ctx, asp_hier_splat *dst, unsigned *flags,
                           asp_error *err);

/* ---- covariance.c: generic homogeneous covariance (seed 001 eq. 2-4) ---- */

/* Adds p' p'^T for p' = (p, 1) to m (ASP_HIER_COV doubles). */
void asp__hcov_add_point(double *m, const float p[3]);
/* m += o (eq. 4). */
void asp__hcov_add(double *m, const double *o);
/* Mean position of the points summed in m (n > 0). */
void asp__hcov_mean(const double *m, double mean[3]);
/* Covariance about the mean, divided by n (eq. 1-2), as xx xy xz yy yz zz. */
void asp__hcov_central(const double *m, double c[6]);

/* ---- ellipse.c: tangent-plane ellipse covering member ellipses (eq. 5-6, Fig. 6) ---- */

/* Orthonormal tangent basis t1, t2 of unit normal n (right-handed: t1 x t2 = n). */
void asp__tangent_basis(const double n[3], double t1[3], double t2[3]);

/*
 * Sets the axis directions u, v of splat s (center and normal already set) from
 * the centred 3x3 covariance c (xx xy xz yy yz zz) projected into the tangent
 * plane (eq. 5-6), with extent2 added to both in-plane variances; leaves the
 * provisional lengths a = 1, b = axis ratio, to be scaled by
 * asp__ellipse_scale.
 */
void asp__ellipse_axes(asp_hier_splat *s, const double c[6], double extent2, int lambda_axes);
/* Scales the provisional ellipse by f (Fig. 6), inflated for float rounding. */
void asp__ellipse_scale(asp_hier_splat *s, double f);
/*
 * Upper bound of the ellipse norm sqrt(x^2/a^2 + y^2/b^2) of s over member
 * ellipse m projected onto s's plane: 1 or less means m is covered.
 */
double asp__ellipse_cover_norm(const asp_hier_splat *s, const asp_hier_splat *m);
/* Ellipse norm of point p projected onto s's plane. */
double asp__ellipse_point_norm(const asp_hier_splat *s, const float p[3]);
/* Axes (from c) and scale so that all count member ellipses are covered. */
void asp__ellipse_fit(asp_hier_splat *s, const double c[6], const asp_hier_splat *members, size_t count,
                      int lambda_axes);

/* ---- normal_cone.c: bounding sphere and normal cone of a node ---- */

/* Sphere containing count child spheres and the ellipse of own (the node's splat). */
void asp__sphere_of_nodes(const asp_hier_node *children, size_t count, const asp_hier_splat *own, float out[4]);
/* Sphere containing count point ellipses (centre, radius a) and the ellipse of own. */
void asp__sphere_of_points(const asp_hier_splat *points, size_t count, const asp_hier_splat *own, float out[4]);
/*
 * Normal-cone semi-angle around unit axis containing the normals of count
 * member splats widened by their own cones (member_nodes[i].cone_angle, or 0
 * when member_nodes is NULL, i.e. the members are points). At most pi.
 */
float asp__cone_bound(const float axis[3], const asp_hier_splat *members, const asp_hier_node *member_nodes,
                      size_t count);

/* ---- misc ---- */

/* sRGB 8-bit to linear light table (256 entries), and its nearest inverse. */
void asp__srgb_table(float lin[256]);
uint8_t asp__linear_to_srgb8(const float lin[256], double v);

#endif
