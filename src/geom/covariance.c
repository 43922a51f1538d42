/*
 * The one covariance sum (asp_covariance_sym3): the neighbourhood second
 * moment behind PCA normals (thesis 3.3.1), the AMG classifier's M1 (journal
 * 2.1, eq. 2) and the point ellipses of the hierarchy (seed 001, end of 3.4).
 * Before issue 12 each of the three summed it by hand.
 */
#include <string.h>

#include "amgsplat/geom.h"
#include "util/banned.h"

/*
 * The points come as float or double (f or d is NULL); one loop body for both
 * keeps the two entry points one sum. The type test is loop-invariant, so the
 * compiler hoists it out (bench/bench_knn: no slower than the hand loops).
 */
typedef struct points {
    const float *f;
    const double *d;
    size_t stride; /* in elements */
    const asp_index *idx;
    size_t n;
    const asp_covariance_desc *desc;
} points;

static inline size_t point_at(const points *p, size_t j)
{
    if (j < p->n)
        return p->idx ? (size_t)p->idx[j] : j;
    return (size_t)p->desc->also[j - p->n];
}

static inline void fetch(const points *p, size_t q, double x[3])
{
    if (p->f) {
        const float *a = p->f + q * p->stride;
        x[0] = a[0], x[1] = a[1], x[2] = a[2];
    } else {
        const double *a = p->d + q * p->stride;
        x[0] = a[0], x[1] = a[1], x[2] = a[2];
    }
}

static void sum(const points *p, double centroid[3], double cov[6])
{
    const size_t total = p->n + (p->desc ? p->desc->also_count : 0);
    const float *w = p->desc ? p->desc->weights : NULL;
    double c[3] = {0, 0, 0}, s[6] = {0, 0, 0, 0, 0, 0}, wsum = 0, x[3];
    /*
     * Two passes in double: subtracting the mean before squaring avoids the
     * catastrophic cancellation of E[x^2] - E[x]^2 for points far from the
     * origin relative to their spread (dense scans in UTM-like coordinates).
     */
    for (size_t j = 0; j < total; j++) {
        const size_t q = point_at(p, j);
        const double wj = w ? (double)w[q] : 1.0;
        fetch(p, q, x);
        c[0] += wj * x[0];
        c[1] += wj * x[1];
        c[2] += wj * x[2];
        wsum += wj;
    }
    if (!(wsum > 0)) {
        memset(centroid, 0, 3 * sizeof *centroid);
        memset(cov, 0, 6 * sizeof *cov);
        return;
    }
    for (int a = 0; a < 3; a++)
        c[a] /= wsum;
    const double *m = p->desc && p->desc->center ? p->desc->center : c;
    for (size_t j = 0; j < total; j++) {
        const size_t q = point_at(p, j);
        const double wj = w ? (double)w[q] : 1.0;
        fetch(p, q, x);
        const double dx = x[0] - m[0], dy = x[1] - m[1], dz = x[2] - m[2];
        s[0] += wj * dx * dx;
        s[1] += wj * dx * dy;
        s[2] += wj * dx * dz;
        s[3] += wj * dy * dy;
        s[4] += wj * dy * dz;
        s[5] += wj * dz * dz;
    }
    for (int i = 0; i < 6; i++)
        cov[i] = s[i] / wsum;
    memcpy(centroid, c, sizeof c);
}

void asp_covariance_sym3(const float *positions, size_t stride_bytes, const asp_index *idx, size_t n,
                         const asp_covariance_desc *desc, double centroid[3], double cov[6])
{
    const points p = {positions, NULL, stride_bytes / sizeof(float), idx, n, desc};
    sum(&p, centroid, cov);
}

void asp_covariance_sym3d(const double *positions, size_t stride_bytes, const asp_index *idx, size_t n,
                          const asp_covariance_desc *desc, double centroid[3], double cov[6])
{
    const points p = {NULL, positions, stride_bytes / sizeof(double), idx, n, desc};
    sum(&p, centroid, cov);
}
