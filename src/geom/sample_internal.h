/*
 * Helpers shared by the samplers and the synthetic models (private to
 * src/geom/sample_*.c and synth.c): seeded hashing, the R2 low-discrepancy
 * sequence, Heitz's low-distortion square-to-triangle map, and the
 * covering-radius kernel that makes discs close all holes.
 */
#ifndef ASP_GEOM_SAMPLE_INTERNAL_H
#define ASP_GEOM_SAMPLE_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "amgsplat/cloud.h"
#include "amgsplat/sample.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846 /* C11 without XSI does not define it */
#endif

/* splitmix64 finaliser: decorrelates (seed, index) pairs into per-triangle offsets. */
static inline uint64_t asp__mix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* Uniform double in [0,1) from 53 hash bits. */
static inline double asp__unit(uint64_t h)
{
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/*
 * i-th point of the R2 sequence (Roberts 2018, generalised golden ratio): its
 * gaps stay within a small constant of the ideal 1/sqrt(n), unlike random
 * points, so a fixed disc radius closes all holes.
 */
static inline void asp__r2(uint64_t i, double off_u, double off_v, double *u, double *v)
{
    const double a1 = 0.75487766624669276005; /* 1/g, g = plastic number */
    const double a2 = 0.56984029099805326591; /* 1/g^2 */
    double x = off_u + a1 * (double)i, y = off_v + a2 * (double)i;
    *u = x - floor(x);
    *v = y - floor(y);
}

/*
 * Heitz 2019, "A low-distortion map between triangle and square": area
 * preserving and continuous, so a low-discrepancy square set stays evenly
 * spread in the triangle (the common fold a+b>1 -> (1-a,1-b) piles points
 * along the diagonal). Returns barycentric weights of vertices 1 and 2.
 */
static inline void asp__square_to_triangle(double u, double v, double *b1, double *b2)
{
    if (v > u) {
        u *= 0.5;
        v -= u;
    } else {
        v *= 0.5;
        u -= v;
    }
    *b1 = u;
    *b2 = v;
}

/*
 * Margin on the exact covering radius: discs that only just touch at Voronoi
 * vertices leave pinholes once rasterised, and on a curved surface the flat
 * disc falls short of its cell by about r^2 / (2 R). 10% closes both.
 */
#define ASP__COVER_MARGIN 1.1f

/*
 * Per-point covering radius from the k nearest neighbours: the largest
 * distance from point i to its Voronoi cell in the tangent plane (clipped by
 * the bisectors of the neighbours), capped at the k-th neighbour distance so
 * open borders do not grow huge discs, times scale, and at least floor_radius.
 * positions/normals are packed xyz; radii receives count values.
 * Returns 0, ASP_EINVAL (count < 2), ASP_ENOMEM, ASP_ECANCELED.
 */
int asp__covering_radii(const float *positions, const float *normals, size_t count, size_t k, float scale,
                        float floor_radius, const asp_context *ctx, float *radii, asp_error *err);


/*
 * Attributes of the surface point with barycentric weights w[3] in triangle t:
 * position (relative to the mesh origin), unit normal (interpolated vertex
 * normals, Schwarz 2004 3.1.6; the face normal if they cancel), uv (zero
 * without UVs) and RGBA in 0..255 (texture through the uv 3.1.7, else vertex
 * colours, else the material colour). Any output pointer may be NULL.
 */
void asp__surface_point(const asp_mesh *m, size_t t, const double w[3], double pos[3], double nrm[3], double uv[2],
                        float rgba[4]);

/* 1 when the mesh has a colour source worth storing (texture with UVs, vertex colours, a file material colour). */
int asp__mesh_has_color(const asp_mesh *m);

/* Method kernels behind asp_sample_mesh: desc has its defaults resolved; they fill positions..labels and radii. */
int asp__sample_vertices(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                         asp_sample_stats *st, asp_error *err);
int asp__sample_area(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                     asp_sample_stats *st, asp_error *err);
int asp__sample_voxel(const asp_mesh *m, const asp_sample_desc *d, const asp_context *ctx, asp_cloud **out,
                      asp_sample_stats *st, asp_error *err);

/* Creates the output cloud with the attributes the mesh and desc call for (colours, uvs, labels). */
int asp__sample_cloud_create(const asp_mesh *m, const asp_sample_desc *d, size_t count, const asp_context *ctx,
                             asp_cloud **out, asp_error *err);

/* Stores one sample: rounds the colour, normalises the normal. */
void asp__sample_store(asp_cloud *c, size_t i, const double pos[3], const double nrm[3], const double uv[2],
                       const float rgba[4], uint32_t label);

#endif
