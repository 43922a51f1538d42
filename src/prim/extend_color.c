/*
 * Extend colour (thesis 3.3.4): texels no point reaches take the colour of
 * the nearest point, so that linear texture filtering never blends black into
 * a primitive's border. Nearest points are propagated over the texel grid by
 * two raster sweeps (a Danielsson-style vector distance transform): O(texels).
 */
#include "prim/internal.h"
#include "util/banned.h"

static double dist2(const asp__tex_input *in, int32_t p, size_t i, size_t j)
{
    double dx = (double)i + 0.5 - in->x[p], dy = (double)j + 0.5 - in->y[p];
    return dx * dx + dy * dy;
}

static void relax(const asp__tex_input *in, int32_t *seed, size_t i, size_t j, long di, long dj)
{
    long ni = (long)i + di, nj = (long)j + dj;
    if (ni < 0 || nj < 0 || ni >= (long)in->w || nj >= (long)in->h)
        return;
    int32_t s = seed[(size_t)nj * in->w + (size_t)ni];
    int32_t *me = &seed[j * in->w + i];
    if (s >= 0 && (*me < 0 || dist2(in, s, i, j) < dist2(in, *me, i, j)))
        *me = s;
}

void asp__prim_extend_color(const asp__tex_input *in, const float *f, int32_t *seed, float *acc)
{
    const size_t w = in->w, h = in->h;
    for (size_t t = 0; t < w * h; t++)
        seed[t] = -1;
    for (size_t p = 0; p < in->n; p++) {
        double fx = in->x[p], fy = in->y[p];
        long i = (long)fx, j = (long)fy;
        i = i < 0 ? 0 : i >= (long)w ? (long)w - 1 : i;
        j = j < 0 ? 0 : j >= (long)h ? (long)h - 1 : j;
        int32_t *s = &seed[(size_t)j * w + (size_t)i];
        if (*s < 0 || dist2(in, (int32_t)p, (size_t)i, (size_t)j) < dist2(in, *s, (size_t)i, (size_t)j))
            *s = (int32_t)p;
    }
    for (size_t j = 0; j < h; j++) {
        for (size_t i = 0; i < w; i++) {
            relax(in, seed, i, j, -1, -1), relax(in, seed, i, j, 0, -1), relax(in, seed, i, j, 1, -1);
            relax(in, seed, i, j, -1, 0);
        }
        for (size_t i = w; i-- > 0;)
            relax(in, seed, i, j, 1, 0);
    }
    for (size_t j = h; j-- > 0;) {
        for (size_t i = w; i-- > 0;) {
            relax(in, seed, i, j, 1, 1), relax(in, seed, i, j, 0, 1), relax(in, seed, i, j, -1, 1);
            relax(in, seed, i, j, 1, 0);
        }
        for (size_t i = 0; i < w; i++)
            relax(in, seed, i, j, -1, 0);
    }
    const int C = in->channels;
    for (size_t t = 0; t < w * h; t++) {
        if (f[t] > 0 || seed[t] < 0)
            continue;
        const float *a = &in->attr[(size_t)C * (size_t)seed[t]];
        for (int c = 0; c < C; c++)
            acc[t * (size_t)C + (size_t)c] = c == 3 ? 0.0f : a[c]; /* channel 3 is Psi: alpha stays 0 */
    }
}
