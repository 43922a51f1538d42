/*
 * Elliptical splats of the input points, the leaves' members (seed 001,
 * section 3.1 and the end of 3.4): a circle of the point's radius when the
 * cloud has radii, else the bounding ellipse of the point's k nearest
 * neighbours in its tangent plane; the normal from the k-neighbourhood
 * covariance when the cloud has none.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "hier/internal.h"
#include "util/banned.h"

typedef struct point_job {
    const asp_cloud *cloud;
    const float *pos;     /* positions the neighbour rows index: hierarchy order */
    const asp_index *knn; /* count * k neighbour rows, or NULL */
    size_t k;
    int use_radii;
    int lambda_axes; /* ASP_HIER_BUILD_LAMBDA_AXES */
} point_job;

/* smallest-eigenvalue eigenvector of the neighbourhood of row i (the point and its neighbours) */
static void pca_normal(const point_job *job, size_t i, float n[3])
{
    const asp_index self = (asp_index)i;
    double mu[3], c[6];
    asp_covariance_sym3(job->pos, 3 * sizeof(float), job->knn + i * job->k, job->k,
                        &(asp_covariance_desc){.also = &self, .also_count = 1}, mu, c);
    double evals[3], evecs[9];
    asp_eigen_sym3(c, evals, evecs);
    for (int d = 0; d < 3; d++)
        n[d] = (float)evecs[3 * d + 2];
}

/* bounding ellipse of the neighbours of row i, centred at the point (end of section 3.4) */
static void knn_ellipse(const point_job *job, size_t i, asp_hier_splat *s)
{
    const float *pos = job->pos;
    const asp_index *row = job->knn + i * job->k;
    /* second moment of the neighbours about the point itself, not their mean: the ellipse is centred there */
    const double at[3] = {s->center[0], s->center[1], s->center[2]};
    double mu[3], c[6];
    asp_covariance_sym3(pos, 3 * sizeof *pos, row, job->k, &(asp_covariance_desc){.center = at}, mu, c);
    asp__ellipse_axes(s, c, 0.0, job->lambda_axes);
    double f = 0;
    for (size_t j = 0; j < job->k; j++) {
        double r = asp__ellipse_point_norm(s, pos + 3 * (size_t)row[j]);
        if (r > f)
            f = r;
    }
    asp__ellipse_scale(s, f);
}

static void circle(asp_hier_splat *s, float radius)
{
    double n[3] = {s->normal[0], s->normal[1], s->normal[2]}, t1[3], t2[3];
    asp__tangent_basis(n, t1, t2);
    for (int d = 0; d < 3; d++) {
        s->u[d] = (float)t1[d];
        s->v[d] = (float)t2[d];
    }
    s->a = s->b = fabsf(radius);
}

/* splat of input point i, whose neighbour row (if any) is row */
static void point_splat(const point_job *job, asp_index i, size_t row, asp_hier_splat *s)
{
    const asp_cloud *cl = job->cloud;
    memcpy(s->center, cl->positions + 3 * (size_t)i, sizeof s->center);
    s->index = i;
    if (cl->colors)
        memcpy(s->color, cl->colors + 4 * (size_t)i, 4);
    else
        memset(s->color, 255, 4);
    if (cl->normals) {
        const float *n = cl->normals + 3 * (size_t)i;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (len > 0) {
            for (int d = 0; d < 3; d++)
                s->normal[d] = (float)(n[d] / len);
        } else {
            /* a zero normal carries no orientation; any unit vector keeps the ellipse well defined */
            s->normal[0] = s->normal[1] = 0;
            s->normal[2] = 1;
        }
    } else if (job->knn) {
        pca_normal(job, row, s->normal);
    } else {
        s->normal[0] = s->normal[1] = 0;
        s->normal[2] = 1;
    }
    if (job->use_radii) {
        circle(s, cl->radii[i]);
    } else if (job->knn) {
        knn_ellipse(job, row, s);
    } else {
        circle(s, 0.0f); /* a lone point without radius has no extent */
    }
}

/*
 * With neighbours: positions are copied into hierarchy order first, so that
 * the kd-tree indices, the neighbour rows and the positions they point at are
 * all spatially coherent in memory, and the loop runs in hierarchy order.
 */
static int knn_splats(const asp_cloud *cloud, point_job *job, const asp_index *slot, const asp_index *order,
                      const asp_context *ctx, asp_hier_splat *dst, asp_error *err)
{
    size_t n = cloud->count;
    long long nn = (long long)n;
    int threads = asp_context_threads(ctx);
    (void)threads; /* only the OpenMP pragmas read it */
    float *pos = asp_alloc(ctx, 3 * n * sizeof *pos);
    asp_index *knn = asp_calloc(ctx, n, job->k * sizeof *knn);
    asp_kdtree *tree = NULL;
    int rc = 0;
    if (!pos || !knn) {
        rc = asp_error_set(err, ASP_ENOMEM, "cannot allocate %zu neighbour lists of %zu points", n, job->k);
        goto done;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long i = 0; i < nn; i++)
        memcpy(pos + 3 * (size_t)slot[i], cloud->positions + 3 * i, 3 * sizeof *pos);
    if ((rc = asp_kdtree_create(pos, n, 12, ctx, &tree, err)) != 0)
        goto done;
    if ((rc = asp_knn_all(tree, job->k, knn, NULL, ctx, err)) != 0)
        goto done;
    job->pos = pos;
    job->knn = knn;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long j = 0; j < nn; j++)
        point_splat(job, order[j], (size_t)j, &dst[j]);
done:
    asp_kdtree_destroy(tree);
    asp_free(ctx, knn);
    asp_free(ctx, pos);
    return rc;
}

int asp__hier_point_splats(const asp_cloud *cloud, size_t k, unsigned build_flags, const asp_index *slot,
                           const asp_index *order, const asp_context *ctx, asp_hier_splat *dst, unsigned *flags,
                           asp_error *err)
{
    size_t n = cloud->count;
    point_job job = {cloud, NULL, NULL, 0, cloud->radii && !(build_flags & ASP_HIER_BUILD_IGNORE_RADII),
                     (build_flags & ASP_HIER_BUILD_LAMBDA_AXES) != 0};
    if ((!job.use_radii || !cloud->normals) && n >= 2) {
        job.k = k < n - 1 ? k : n - 1;
        int rc = knn_splats(cloud, &job, slot, order, ctx, dst, err);
        if (rc != 0)
            return rc;
    } else {
        long long nn = (long long)n;
        /*
         * Input order, scattered to dst: the attribute arrays are read in
         * sequence and each point costs one 64-byte line of dst, where a
         * gather in hierarchy order would miss the cache once per attribute.
         */
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
        for (long long i = 0; i < nn; i++) {
#if defined(__GNUC__)
            /* the scattered stores miss the cache; announce them early */
            if (i + 16 < nn)
                __builtin_prefetch(&dst[slot[i + 16]], 1, 0);
#endif
            point_splat(&job, (asp_index)i, 0, &dst[slot[i]]);
        }
    }
    *flags |= (cloud->colors ? ASP_HIER_HAS_COLORS : 0u) | (cloud->normals ? 0u : ASP_HIER_UNORIENTED) |
              (job.use_radii ? 0u : ASP_HIER_KNN_ELLIPSES);
    return 0;
}
