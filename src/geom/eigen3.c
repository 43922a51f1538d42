/*
 * Symmetric 3x3 eigen-decomposition by cyclic Jacobi rotations, applied to the
 * neighbourhood covariance (covariance.c): the PCA behind local surface
 * classification (journal 3.1, thesis 3.3.1) and normal estimation. Jacobi is
 * chosen over the closed-form cubic because it stays accurate for repeated and
 * near-repeated eigenvalues, which flat neighbourhoods produce all the time.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "util/banned.h"

enum { JACOBI_MAX_SWEEPS = 64 };

static void rotate(double a[3][3], double v[3][3], int p, int q)
{
    double apq = a[p][q];
    double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    /* For huge theta, theta^2 would overflow; the rotation is then t ~ 1/(2 theta). */
    double t = fabs(theta) > 1e150 ? 0.5 / theta
                                   : (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
    double c = 1.0 / sqrt(t * t + 1.0);
    double s = t * c;
    double tau = s / (1.0 + c);
    double h = t * apq;
    a[p][p] -= h;
    a[q][q] += h;
    a[p][q] = a[q][p] = 0.0;
    for (int r = 0; r < 3; r++) {
        if (r != p && r != q) {
            double g = a[r][p], hh = a[r][q];
            a[r][p] = a[p][r] = g - s * (hh + g * tau);
            a[r][q] = a[q][r] = hh + s * (g - hh * tau);
        }
        double g = v[r][p], hh = v[r][q];
        v[r][p] = g - s * (hh + g * tau);
        v[r][q] = hh + s * (g - hh * tau);
    }
}

/* Sign convention for reproducible output: the largest-magnitude component is positive. */
static void canonical_sign(double v[3])
{
    int m = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(v[i]) > fabs(v[m]))
            m = i;
    if (v[m] < 0)
        for (int i = 0; i < 3; i++)
            v[i] = -v[i];
}

void asp_eigen_sym3(const double m[6], double evals[3], double evecs[9])
{
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double scale = 0.0;
    int finite = 1;
    for (int i = 0; i < 6; i++) {
        finite &= isfinite(m[i]) != 0;
        scale = fabs(m[i]) > scale ? fabs(m[i]) : scale;
    }
    if (!finite || scale == 0.0) {
        double e = finite ? 0.0 : NAN;
        evals[0] = evals[1] = evals[2] = e;
        memcpy(evecs, identity, sizeof identity);
        return;
    }
    /* Scaling to unit max entry keeps squares of huge or tiny entries representable. */
    double a[3][3] = {{m[0] / scale, m[1] / scale, m[2] / scale},
                      {m[1] / scale, m[3] / scale, m[4] / scale},
                      {m[2] / scale, m[4] / scale, m[5] / scale}};
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int sweep = 0; sweep < JACOBI_MAX_SWEEPS; sweep++) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        /* Converged when the off-diagonal part is below rounding of the (unit-scaled) matrix. */
        if (off == 0.0 || off <= 1e-3 * DBL_EPSILON * (diag + off))
            break;
        for (int r = 0; r < 3; r++) {
            int p = pairs[r][0], q = pairs[r][1];
            if (a[p][q] != 0.0)
                rotate(a, v, p, q);
        }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[order[j]][order[j]] > a[order[i]][order[i]]) {
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
    double cols[3][3];
    for (int k = 0; k < 3; k++) {
        evals[k] = a[order[k]][order[k]] * scale;
        for (int r = 0; r < 3; r++)
            cols[k][r] = v[r][order[k]];
    }
    canonical_sign(cols[0]);
    canonical_sign(cols[1]);
    /* Right-handed frame: the third axis is the cross product of the first two. */
    cols[2][0] = cols[0][1] * cols[1][2] - cols[0][2] * cols[1][1];
    cols[2][1] = cols[0][2] * cols[1][0] - cols[0][0] * cols[1][2];
    cols[2][2] = cols[0][0] * cols[1][1] - cols[0][1] * cols[1][0];
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++)
            evecs[3 * r + k] = cols[k][r];
}
