/*
 * One domain primitive's texture (thesis 3.3): the radial or the linear
 * affine construction, per-texel normalisation (eq. 3.3 / 3.4), extend
 * colour (3.3.4) and the RGBA8 encoding: colour in sRGB, straight alpha =
 * the interpolated basis function Psi; optional normal map (journal 6).
 */
#include <math.h>
#include <string.h>

#include "prim/internal.h"
#include "util/banned.h"

static size_t align64(size_t b)
{
    return (b + 63) & ~(size_t)63;
}

static size_t affine_bytes(size_t n)
{
    size_t tb = 3 * asp_delaunay2d_bound(n);
    return 2 * n * sizeof(double) + (tb + (tb & 1)) * sizeof(uint32_t) + asp_delaunay2d_scratch_size(n);
}

size_t asp__prim_texture_scratch(size_t n, size_t texels, int channels)
{
    return align64(texels * (size_t)channels * sizeof(float)) + align64(texels * sizeof(float)) +
           align64(texels) + align64(texels * sizeof(int32_t)) + align64(affine_bytes(n));
}

static uint8_t to_byte(double v)
{
    return (uint8_t)(v <= 0 ? 0 : v >= 255 ? 255 : v + 0.5);
}

void asp__prim_texture(const asp__tex_input *in, void *scratch, uint8_t *rgba, uint8_t *nrm, size_t stride)
{
    const size_t T = (size_t)in->w * in->h;
    const int C = in->channels;
    uint8_t *s = scratch;
    float *acc = (float *)s;
    s += align64(T * (size_t)C * sizeof(float));
    float *f = (float *)s;
    s += align64(T * sizeof(float));
    uint8_t *covered = s;
    s += align64(T);
    int32_t *seed = (int32_t *)s;
    s += align64(T * sizeof(int32_t));
    memset(acc, 0, T * (size_t)C * sizeof(float));
    memset(f, 0, T * sizeof(float));
    memset(covered, 0, T);

    if (in->method == ASP_PRIM_AFFINE) {
        asp__prim_affine(in, s, acc, covered);
        /* outside the triangulation: radial linear within a point's radius; alpha fades (eq. 3.3) */
        asp__prim_splat_radial(in, ASP_PRIM_LINEAR, covered, 1, acc, f);
    } else {
        asp__prim_splat_radial(in, in->shape, NULL, 0, acc, f);
    }
    asp__prim_texture_finish(in, acc, f, covered, seed, rgba, nrm, stride);
}

void asp__prim_texture_finish(const asp__tex_input *in, float *acc, float *f, const uint8_t *covered, int32_t *seed,
                              uint8_t *rgba, uint8_t *nrm, size_t stride)
{
    const size_t T = (size_t)in->w * in->h;
    const int C = in->channels;
    asp_prim_normalise crit = in->normalise;
    if (in->method == ASP_PRIM_AFFINE) {
        for (size_t t = 0; t < T; t++)
            if (covered[t])
                f[t] = 1.0f; /* acc already holds the interpolated values */
        crit = ASP_PRIM_NORM_GE1;
    }
    for (size_t t = 0; t < T; t++) {
        if (!(f[t] > 0) || covered[t])
            continue;
        /* colour is stored straight (not premultiplied), so it is always an interpolation: divide by f;
         * the criterion decides only whether alpha is normalised too, unless normalise_color asks for
         * eq. 3.3 as the thesis writes it (radial only: affine coverage is exact) */
        double inv = 1.0 / f[t];
        int all = in->normalise_color && in->method == ASP_PRIM_RADIAL;
        for (int c = 0; c < C; c++)
            if ((c != 3 && !all) || crit == ASP_PRIM_NORM_POSITIVE || f[t] >= 1.0f)
                acc[t * (size_t)C + (size_t)c] *= (float)inv;
    }
    if (in->extend_color)
        asp__prim_extend_color(in, f, seed, acc);
    for (size_t j = 0; j < in->h; j++)
        for (size_t i = 0; i < in->w; i++) {
            size_t t = j * in->w + i;
            const float *a = &acc[t * (size_t)C];
            uint8_t *o = &rgba[4 * (j * stride + i)];
            double alpha = f[t] > 0 ? a[3] : 0;
            o[0] = to_byte(a[0]), o[1] = to_byte(a[1]), o[2] = to_byte(a[2]);
            o[3] = to_byte(255.0 * (alpha > 1 ? 1 : alpha));
            if (nrm && C >= 7) {
                double nx = a[4], ny = a[5], nz = a[6], l = sqrt(nx * nx + ny * ny + nz * nz);
                uint8_t *q = &nrm[4 * (j * stride + i)];
                if (l > 0)
                    nx /= l, ny /= l, nz /= l;
                q[0] = to_byte(127.5 * (nx + 1)), q[1] = to_byte(127.5 * (ny + 1)), q[2] = to_byte(127.5 * (nz + 1));
                q[3] = o[3];
            }
        }
}
