/*
 * Generic homogeneous covariance (seed 001 section 3.3, eq. 2-4): the sum of
 * p' p'^T over a node's points with p' = (p, 1). Leaves sum their points once;
 * inner nodes add their children's matrices (eq. 4), and the covariance about
 * any centre follows by the translation of eq. 2.
 */
#include "hier/internal.h"
#include "util/banned.h"

/*
 * Layout: upper triangle of the symmetric 4x4 matrix, row by row:
 * xx xy xz x | yy yz y | zz z | n. Sums are double because eq. 2 subtracts
 * n * mean * mean^T from them, which cancels most digits of a float sum.
 */
enum { XX, XY, XZ, X, YY, YZ, Y, ZZ, Z, N };

void asp__hcov_add_point(double *m, const float p[3])
{
    double x = p[0], y = p[1], z = p[2];
    m[XX] += x * x;
    m[XY] += x * y;
    m[XZ] += x * z;
    m[X] += x;
    m[YY] += y * y;
    m[YZ] += y * z;
    m[Y] += y;
    m[ZZ] += z * z;
    m[Z] += z;
    m[N] += 1.0;
}

void asp__hcov_add(double *m, const double *o)
{
    for (int i = 0; i < ASP_HIER_COV; i++)
        m[i] += o[i];
}

void asp__hcov_mean(const double *m, double mean[3])
{
    double inv = m[N] > 0 ? 1.0 / m[N] : 0.0;
    mean[0] = m[X] * inv;
    mean[1] = m[Y] * inv;
    mean[2] = m[Z] * inv;
}

void asp__hcov_central(const double *m, double c[6])
{
    /* eq. 2: (1/n) T Mbar T^T with T the translation by -mean, upper-left 3x3 */
    double mu[3];
    asp__hcov_mean(m, mu);
    double inv = m[N] > 0 ? 1.0 / m[N] : 0.0;
    c[0] = m[XX] * inv - mu[0] * mu[0];
    c[1] = m[XY] * inv - mu[0] * mu[1];
    c[2] = m[XZ] * inv - mu[0] * mu[2];
    c[3] = m[YY] * inv - mu[1] * mu[1];
    c[4] = m[YZ] * inv - mu[1] * mu[2];
    c[5] = m[ZZ] * inv - mu[2] * mu[2];
    /* rounding can leave a tiny negative variance; the ellipse fit needs >= 0 */
    if (c[0] < 0)
        c[0] = 0;
    if (c[3] < 0)
        c[3] = 0;
    if (c[5] < 0)
        c[5] = 0;
}
