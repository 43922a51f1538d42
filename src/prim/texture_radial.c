/*
 * Radial basis-function splatting (thesis 3.3.2): each projected point adds
 * phi_p(t) times its colour and Psi to the texels within its footprint w r
 * (constant, linear or Gaussian with sigma = w r / 3), so the cost is
 * points x footprint, never points x texels. Also the radial linear fringe
 * of the linear affine method outside the triangulation (thesis 3.3.3).
 */
#include <math.h>

#include "prim/internal.h"
#include "util/banned.h"

void asp__prim_splat_radial(const asp__tex_input *in, asp_prim_shape shape, const uint8_t *skip, int nearest,
                            float *acc, float *f)
{
    const int C = in->channels;
    for (size_t p = 0; p < in->n; p++) {
        /* a footprint of at least one texel: coarse texel sizes must not drop points between texel centres */
        double R = in->r[p] > 1.0f ? in->r[p] : 1.0, px = in->x[p], py = in->y[p];
        double inv2s2 = 4.5 / (R * R); /* 1 / (2 sigma^2) with sigma = R / 3 */
        long i0 = (long)floor(px - R - 0.5), i1 = (long)ceil(px + R - 0.5);
        long j0 = (long)floor(py - R - 0.5), j1 = (long)ceil(py + R - 0.5);
        i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0;
        i1 = i1 >= (long)in->w ? (long)in->w - 1 : i1, j1 = j1 >= (long)in->h ? (long)in->h - 1 : j1;
        const float *a = &in->attr[(size_t)C * p];
        for (long j = j0; j <= j1; j++) {
            double dy = (double)j + 0.5 - py;
            for (long i = i0; i <= i1; i++) {
                double dx = (double)i + 0.5 - px, d2 = dx * dx + dy * dy;
                if (d2 > R * R)
                    continue;
                size_t t = (size_t)j * in->w + (size_t)i;
                if (skip && skip[t])
                    continue;
                double d = sqrt(d2);
                if (nearest) /* distance to the nearest point of the texel square, not its centre */
                    d = d > 0.5 ? d - 0.5 : 0.0, d2 = d * d;
                double phi = shape == ASP_PRIM_CONSTANT ? 1.0
                             : shape == ASP_PRIM_GAUSSIAN ? exp(-d2 * inv2s2)
                                                          : 1.0 - d / R;
                if (!(phi > 0))
                    continue;
                f[t] += (float)phi;
                for (int c = 0; c < C; c++)
                    acc[t * (size_t)C + (size_t)c] += (float)phi * a[c];
            }
        }
    }
}
