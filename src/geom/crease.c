/*
 * Clip planes at sharp creases: a splat that straddles a feature line is cut
 * by the plane of the surface on the other side, as in the clip lines of
 * Pauly et al. 2003 (Shape modeling with point-sampled geometry, section 4),
 * Zwicker et al. 2004 (Perspective accurate splatting, section 5) and Botsch
 * et al. 2005 (High-quality surface splatting on today's GPUs, section 4.2).
 */
#include <math.h>
#include <string.h>

#include "geom/kdtree_internal.h"
#include "util/banned.h"

#define DEFAULT_ANGLE 60.0f
#define DEFAULT_K 16
#define DEFAULT_SUPPORT 2

static const double deg_to_rad = 0.017453292519943295769;

/*
 * Read-only inputs of the per-point pass. Normals are compared through their
 * inverse lengths so that unnormalised input normals work unchanged.
 */
typedef struct crease_job {
    const float *p, *n, *radii;
    const float *inv_len; /* 1 / |n_j|, 0 for a zero normal */
    const asp_index *idx;
    const float *dist2;
    size_t k, min_support;
    double cos_max; /* cos(angle_deg) */
} crease_job;

/* |cos| of the angle between the normals of a and b; unoriented (Pauly 2003 4.1: PCA normals have no sign). */
static double abs_cos(const crease_job *J, size_t a, size_t b)
{
    const float *na = J->n + 3 * a, *nb = J->n + 3 * b;
    double d = (double)na[0] * nb[0] + (double)na[1] * nb[1] + (double)na[2] * nb[2];
    return fabs(d) * J->inv_len[a] * J->inv_len[b];
}

/* Neighbour j of row i is on the point's own side (S): within the angle, ignoring the normals' signs. */
static int same_side(const crease_job *J, size_t i, size_t j)
{
    return abs_cos(J, i, j) >= J->cos_max;
}

/*
 * Fits the plane of the O members of row i that are within the angle of seed
 * and not excluded by first_seed (the first cluster's seed; SIZE_MAX for the
 * first cluster itself). Sums in double: up to k positions of magnitude ~1
 * whose mean feeds a signed distance compared against 1e-3 of a spacing.
 * Returns the member count; writes the unit mean normal (flipped into the
 * seed's hemisphere) and the mean position.
 */
static size_t fit_cluster(const crease_job *J, size_t i, size_t seed, size_t first_seed, double nrm[3],
                          double mean[3])
{
    const asp_index *row = J->idx + i * J->k;
    double ns[3] = {0, 0, 0}, ps[3] = {0, 0, 0};
    size_t m = 0;
    for (size_t a = 0; a < J->k; a++) {
        size_t j = row[a];
        if (J->inv_len[j] == 0.0f || same_side(J, i, j))
            continue;
        if (first_seed != SIZE_MAX && abs_cos(J, first_seed, j) >= J->cos_max)
            continue; // a member of the first cluster
        if (abs_cos(J, seed, j) < J->cos_max)
            continue;
        const float *nj = J->n + 3 * j, *ns0 = J->n + 3 * seed, *pj = J->p + 3 * j;
        double dot = (double)nj[0] * ns0[0] + (double)nj[1] * ns0[1] + (double)nj[2] * ns0[2];
        double w = (dot < 0 ? -1.0 : 1.0) * J->inv_len[j];
        for (int c = 0; c < 3; c++) {
            ns[c] += w * nj[c];
            ps[c] += pj[c];
        }
        m++;
    }
    if (m == 0)
        return 0;
    double len = sqrt(ns[0] * ns[0] + ns[1] * ns[1] + ns[2] * ns[2]);
    for (int c = 0; c < 3; c++) {
        nrm[c] = len > 0 ? ns[c] / len : 0.0;
        mean[c] = ps[c] / (double)m;
    }
    return len > 0 ? m : 0;
}

/*
 * Orients the plane (nrm, through mean) so that s_mean is kept and writes it
 * to out; returns 0 without writing when s_mean lies within tol of the plane,
 * where the side it is meant to keep is ambiguous.
 */
static int put_plane(const double nrm[3], const double mean[3], const double s_mean[3], double tol, float out[4])
{
    double d = -(nrm[0] * mean[0] + nrm[1] * mean[1] + nrm[2] * mean[2]);
    double s = nrm[0] * s_mean[0] + nrm[1] * s_mean[1] + nrm[2] * s_mean[2] + d;
    if (!(fabs(s) > tol))
        return 0;
    double sign = s < 0 ? -1.0 : 1.0;
    for (int c = 0; c < 3; c++)
        out[c] = (float)(sign * nrm[c]);
    out[3] = (float)(sign * d);
    return 1;
}

/* The two planes of point i (zeros where there is none). */
static void point_planes(const crease_job *J, size_t i, float out[8])
{
    memset(out, 0, 8 * sizeof(float));
    if (J->inv_len[i] == 0.0f)
        return;
    const asp_index *row = J->idx + i * J->k;
    const float *pi = J->p + 3 * i;
    double s_sum[3] = {pi[0], pi[1], pi[2]}, dist = 0;
    size_t s_count = 1, o_count = 0, seed1 = SIZE_MAX;
    for (size_t a = 0; a < J->k; a++) {
        size_t j = row[a];
        dist += sqrt((double)J->dist2[i * J->k + a]);
        if (J->inv_len[j] == 0.0f)
            continue;
        if (same_side(J, i, j)) {
            for (int c = 0; c < 3; c++)
                s_sum[c] += J->p[3 * j + c];
            s_count++;
        } else {
            o_count++;
            if (seed1 == SIZE_MAX)
                seed1 = j; // rows are sorted nearest first
        }
    }
    if (o_count < J->min_support || o_count == 0)
        return;
    double s_mean[3];
    for (int c = 0; c < 3; c++)
        s_mean[c] = s_sum[c] / (double)s_count;
    // "within 1e-3 of a spacing": the splat's own radius, else the mean neighbour distance
    double scale = J->radii && J->radii[i] > 0 ? J->radii[i] : dist / (double)J->k;
    double tol = 1e-3 * scale;

    size_t planes = 0;
    double nrm[3], mean[3];
    if (fit_cluster(J, i, seed1, SIZE_MAX, nrm, mean) >= J->min_support)
        planes += (size_t)put_plane(nrm, mean, s_mean, tol, out);
    // the second surface (a corner) is seeded by the nearest O member outside the first cluster
    size_t seed2 = SIZE_MAX;
    for (size_t a = 0; a < J->k && seed2 == SIZE_MAX; a++) {
        size_t j = row[a];
        if (J->inv_len[j] != 0.0f && !same_side(J, i, j) && abs_cos(J, seed1, j) < J->cos_max)
            seed2 = j;
    }
    if (seed2 != SIZE_MAX && fit_cluster(J, i, seed2, seed1, nrm, mean) >= J->min_support)
        put_plane(nrm, mean, s_mean, tol, out + 4 * planes);
}

static int check_cloud(const asp_cloud *cloud, asp_error *err)
{
    for (size_t i = 0; i < cloud->count; i++)
        for (int a = 0; a < 3; a++) {
            if (!isfinite(cloud->positions[3 * i + a]))
                return asp_error_set(err, ASP_EFORMAT, "cannot find creases: point %zu: coordinate %c is not finite",
                                     i, "xyz"[a]);
            if (!isfinite(cloud->normals[3 * i + a]))
                return asp_error_set(err, ASP_EFORMAT, "cannot find creases: point %zu: normal %c is not finite", i,
                                     "xyz"[a]);
        }
    return 0;
}

int asp_crease_clip_planes(const asp_cloud *cloud, const asp_crease_desc *desc, const asp_context *ctx, float *dst,
                           size_t *clipped, asp_error *err)
{
    static const asp_crease_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    if (!cloud || !dst)
        return asp_error_set(err, ASP_EINVAL, "cannot find creases: %s is NULL", cloud ? "dst" : "cloud");
    if (!cloud->normals)
        return asp_error_set(err, ASP_EINVAL, "crease clipping needs normals");
    if (cloud->count < 2)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot find creases among %zu points: need at least 2",
                             cloud->count);
    float angle = desc->angle_deg != 0.0f ? desc->angle_deg : DEFAULT_ANGLE;
    // unoriented normals are at most 90 degrees apart, so 90 and above would find nothing
    if (!(angle > 0.0f && angle < 90.0f))
        return asp_error_set(err, ASP_EINVAL, "crease angle %g degrees is outside (0, 90)", (double)angle);
    size_t k = desc->k ? desc->k : DEFAULT_K;
    k = k < cloud->count ? k : cloud->count - 1;
    size_t min_support = desc->min_support ? desc->min_support : DEFAULT_SUPPORT;
    int rc = check_cloud(cloud, err);
    if (rc)
        return rc;
    size_t n = cloud->count;
    if (n > (size_t)UINT32_MAX - 1)
        return asp_error_set(err, ASP_EINVAL, "cannot find creases among %zu points: at most 2^32 - 2", n);
    float *inv_len = asp_alloc(ctx, n * sizeof(float));
    if (!inv_len)
        return asp_error_set(err, ASP_ENOMEM, "cannot find creases among %zu points: out of memory", n);
    asp_index *idx = NULL;
    float *d2 = NULL;
    rc = asp__knn_graph(cloud->positions, n, 3 * sizeof(float), k, &idx, &d2, ctx, err);
    if (rc) {
        asp_free(ctx, inv_len);
        return rc;
    }
    for (size_t i = 0; i < n; i++) {
        const float *v = cloud->normals + 3 * i;
        double len = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
        inv_len[i] = len > 0 && isfinite(1.0 / len) ? (float)(1.0 / len) : 0.0f;
    }
    crease_job job = {cloud->positions, cloud->normals, cloud->radii, inv_len, idx, d2, k, min_support,
                      cos((double)angle * deg_to_rad)};
    const long long cnt = (long long)n;
    // each row reads only shared inputs and writes its own 8 floats: identical for any thread count
#pragma omp parallel for schedule(static) num_threads(asp_context_threads(ctx))
    for (long long i = 0; i < cnt; i++)
        point_planes(&job, (size_t)i, dst + 8 * (size_t)i);
    if (clipped) {
        size_t c = 0;
        for (size_t i = 0; i < n; i++) {
            const float *q = dst + 8 * i;
            c += q[0] != 0.0f || q[1] != 0.0f || q[2] != 0.0f || q[3] != 0.0f;
        }
        *clipped = c;
    }
    asp_free(ctx, idx);
    asp_free(ctx, d2);
    asp_free(ctx, inv_len);
    return 0;
}
