/*
 * Local surface classification (journal 2.1, eq. 1-3): zero and first moments
 * of each neighbourhood, their eigenvalues l0 >= l1 >= l2, the classifier
 * C = G(|M0 - x| l2 / (eps l0)) with G(s) = 1 / (alpha + beta s^2), or the
 * thesis's surface variation sigma = l2 / (l0 + l1 + l2) (thesis 2.3).
 */
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "amg/internal.h"
#include "amgsplat/geom.h"
#include "util/banned.h"

int asp_amg_classify_points(const double *pts, size_t m, double epsilon, asp_amg_classifier_kind kind,
                            double alpha, double beta, double *c, double normal[3])
{
    if (alpha <= 0)
        alpha = 0.01;
    if (beta <= 0)
        beta = 100;
    /* M0 (the mean) and M1 (the covariance about it), summed in double by asp_covariance_sym3d */
    double m0[3], cov[6];
    asp_covariance_sym3d(pts, 3 * sizeof *pts, NULL, m, NULL, m0, cov);
    double ev[3], evec[9];
    asp_eigen_sym3(cov, ev, evec);
    if (m < 3 || !(ev[0] > 0) || !(epsilon > 0)) {
        *c = 1.0 / alpha;
        normal[0] = 0;
        normal[1] = 0;
        normal[2] = 1;
        return ASP_EDEGENERATE;
    }
    /* the normal is the eigenvector of the vanishing eigenvalue (journal 2.1, Fig. 3a) */
    for (int a = 0; a < 3; a++)
        normal[a] = evec[3 * a + 2];
    double l2 = ev[2] > 0 ? ev[2] : 0.0;
    double s;
    if (kind == ASP_AMG_CLASSIFIER_VARIATION)
        s = l2 / (ev[0] + ev[1] + l2);
    else
        s = sqrt(m0[0] * m0[0] + m0[1] * m0[1] + m0[2] * m0[2]) * l2 / (epsilon * ev[0]);
    *c = 1.0 / (alpha + beta * s * s);
    return 0;
}

int asp__amg_classify(const float *pos, const asp__amg_nbhd *nb, const asp_amg_desc *desc, const asp_context *ctx,
                      float *classifier, float *normals, asp_error *err)
{
    const size_t n = nb->n, kmax = nb->kmax;
    const int threads = asp_context_threads(ctx);
    /* one neighbourhood buffer per thread, allocated before the parallel region */
    double *buf = asp_alloc(ctx, (size_t)threads * (kmax + 1) * 3 * sizeof *buf);
    if (!buf)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the classifier");
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        double *p = buf + (size_t)t * (kmax + 1) * 3;
        const float *x = pos + 3 * i;
        /* x itself belongs to its ball B_eps(x) */
        p[0] = p[1] = p[2] = 0;
        size_t m = nb->nn[i];
        const asp_index *row = asp__amg_nbhd_row(nb, i);
        for (size_t j = 0; j < m; j++) {
            const float *q = pos + 3 * (size_t)row[j];
            for (int a = 0; a < 3; a++)
                p[3 * (j + 1) + a] = (double)q[a] - (double)x[a];
        }
        double c, nrm[3];
        asp_amg_classify_points(p, m + 1, desc->epsilon, desc->classifier, desc->alpha, desc->beta, &c, nrm);
        classifier[i] = (float)c;
        for (int a = 0; a < 3; a++)
            normals[3 * i + a] = (float)nrm[a];
    }
    asp_free(ctx, buf);
    return 0;
}
