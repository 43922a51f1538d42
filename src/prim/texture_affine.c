/*
 * Linear affine textures (thesis 3.3.3, journal 3.2): the 2D Delaunay
 * triangulation of the projected points, without the triangles that bridge
 * concavities (an edge longer than its two vertices' radii, thesis Fig. 3.8),
 * and barycentric interpolation of colour and Psi for the texel centres
 * inside each kept triangle. Cost: triangles' bounding boxes, about 2x texels.
 */
#include <math.h>

#include "prim/internal.h"
#include "util/banned.h"

size_t asp__prim_affine_triangles(const asp__tex_input *in, void *scratch, uint32_t **tri_out)
{
    const size_t n = in->n;
    double *xy = scratch;
    uint32_t *tri = (uint32_t *)(xy + 2 * n);
    void *dts = tri + 3 * asp_delaunay2d_bound(n) + (3 * asp_delaunay2d_bound(n) & 1); /* keep 8-byte alignment */
    for (size_t p = 0; p < n; p++) {
        xy[2 * p] = in->x[p];
        xy[2 * p + 1] = in->y[p];
    }
    size_t nt = n >= 3 ? asp_delaunay2d(xy, n, tri, dts) : 0, kept = 0;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t v[3] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
        int keep = 1;
        for (int e = 0; e < 3 && keep; e++) {
            uint32_t p = v[e], q = v[(e + 1) % 3];
            double dx = xy[2 * p] - xy[2 * q], dy = xy[2 * p + 1] - xy[2 * q + 1];
            double lim = (double)in->r[p] + (double)in->r[q];
            keep = dx * dx + dy * dy <= lim * lim;
        }
        if (keep)
            for (int e = 0; e < 3; e++)
                tri[3 * kept + (size_t)e] = v[e];
        kept += (size_t)keep;
    }
    *tri_out = tri;
    return kept;
}

void asp__prim_affine(const asp__tex_input *in, void *scratch, float *acc, uint8_t *covered)
{
    const int C = in->channels;
    uint32_t *tri = NULL;
    size_t nt = asp__prim_affine_triangles(in, scratch, &tri);
    const double *xy = scratch;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
        double ax = xy[2 * a], ay = xy[2 * a + 1], bx = xy[2 * b], by = xy[2 * b + 1], cx = xy[2 * c],
               cy = xy[2 * c + 1];
        double area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
        if (!(area > 0))
            continue;
        double xmin = fmin(ax, fmin(bx, cx)), xmax = fmax(ax, fmax(bx, cx));
        double ymin = fmin(ay, fmin(by, cy)), ymax = fmax(ay, fmax(by, cy));
        long i0 = (long)ceil(xmin - 0.5), i1 = (long)floor(xmax - 0.5);
        long j0 = (long)ceil(ymin - 0.5), j1 = (long)floor(ymax - 0.5);
        i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0;
        i1 = i1 >= (long)in->w ? (long)in->w - 1 : i1, j1 = j1 >= (long)in->h ? (long)in->h - 1 : j1;
        const double eps = -1e-9 * area; /* texel centres on a shared edge belong to both; either value is right */
        for (long j = j0; j <= j1; j++) {
            double py = (double)j + 0.5;
            for (long i = i0; i <= i1; i++) {
                double px = (double)i + 0.5;
                double la = (bx - px) * (cy - py) - (by - py) * (cx - px);
                double lb = (cx - px) * (ay - py) - (cy - py) * (ax - px);
                double lc = area - la - lb;
                if (la < eps || lb < eps || lc < eps)
                    continue;
                la /= area, lb /= area, lc /= area;
                size_t tx = (size_t)j * in->w + (size_t)i;
                for (int k = 0; k < C; k++)
                    acc[tx * (size_t)C + (size_t)k] = (float)(la * in->attr[(size_t)C * a + (size_t)k] +
                                                              lb * in->attr[(size_t)C * b + (size_t)k] +
                                                              lc * in->attr[(size_t)C * c + (size_t)k]);
                covered[tx] = 1;
            }
        }
    }
}
