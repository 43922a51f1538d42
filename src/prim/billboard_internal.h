/*
 * Private to the billboard-cloud files of src/prim (issue 30; Decoret,
 * Durand, Sillion and Dorsey 2003): the elements a cloud is built from (faces
 * or discs), the discretised plane space with its density, and the greedy
 * search. Not public API (include/amgsplat/billboard.h is).
 */
#ifndef ASP_PRIM_BILLBOARD_INTERNAL_H
#define ASP_PRIM_BILLBOARD_INTERNAL_H

#include <math.h>

#include "amgsplat/billboard.h"

#define ASP__BB_PI 3.14159265358979323846

/*
 * One element: a triangle (three vertices) or a disc (centre, radius, normal
 * or none), in coordinates relative to the bounding-box centre so that plane
 * offsets stay small and float keeps their digits.
 */
typedef struct asp__bb_elem {
    float p[9];   /* triangle: vertices a, b, c; disc: centre in p[0..2] */
    float n[3];   /* unit face or disc normal; 0 for a disc without one (a point) */
    float own[3]; /* a plane normal the element lies in exactly (its own plane, the fallback) */
    float r;      /* disc radius; 0 for a triangle */
    float area;   /* face or disc area */
} asp__bb_elem;

typedef struct asp__bb_input {
    size_t count;
    int discs;            /* 1: discs, 0: triangles */
    asp__bb_elem *elems;
    double centre[3];     /* local = input position - centre (input's local frame, before origin) */
    double diagonal;      /* bounding-box diagonal (discs: their rims included) */
    double half;          /* largest distance of an element point from centre, radius included */
} asp__bb_input;

/*
 * Validity of element e for the planes of normal n (Decoret 2003 section 4.1):
 * the offsets rho with every vertex (disc rim) within eps of n . x = rho form
 * [*lo, *hi]; returns 0 when that is empty (the element is too steep for n).
 */
static inline int asp__bb_interval(const asp__bb_elem *e, const float n[3], float eps, float *lo, float *hi)
{
    if (e->r > 0.0f) { /* a disc (radii are positive; triangles have r = 0) */
        float s = n[0] * e->p[0] + n[1] * e->p[1] + n[2] * e->p[2];
        float c = n[0] * e->n[0] + n[1] * e->n[1] + n[2] * e->n[2];
        /* a disc of radius r at angle c to n spans r sqrt(1 - c^2) along n; a point (no normal) spans 0 */
        float ext = (e->n[0] != 0 || e->n[1] != 0 || e->n[2] != 0) ? e->r * sqrtf(fmaxf(0.0f, 1.0f - c * c)) : 0.0f;
        *lo = s + ext - eps;
        *hi = s - ext + eps;
    } else {
        float a = n[0] * e->p[0] + n[1] * e->p[1] + n[2] * e->p[2];
        float b = n[0] * e->p[3] + n[1] * e->p[4] + n[2] * e->p[5];
        float c = n[0] * e->p[6] + n[1] * e->p[7] + n[2] * e->p[8];
        float mx = a > b ? a : b, mn = a < b ? a : b; /* not fmaxf: a libm call without -ffinite-math-only */
        mx = mx > c ? mx : c, mn = mn < c ? mn : c;
        *lo = mx - eps;
        *hi = mn + eps;
    }
    return *lo <= *hi;
}

/* Density weight of e on a plane of normal n: its area projected onto the plane (Decoret 2003 4.2). */
static inline float asp__bb_weight(const asp__bb_elem *e, const float n[3])
{
    if (e->n[0] == 0 && e->n[1] == 0 && e->n[2] == 0)
        return e->area;
    return e->area * fabsf(n[0] * e->n[0] + n[1] * e->n[1] + n[2] * e->n[2]);
}

/* Elements of a mesh's triangles or a cloud's discs (allocated through ctx; release below). */
int asp__bb_input_mesh(const asp_mesh *mesh, const asp_context *ctx, asp__bb_input *in, asp_error *err);
int asp__bb_input_cloud(const asp_cloud *cloud, const asp_context *ctx, asp__bb_input *in, asp_error *err);
void asp__bb_input_release(asp__bb_input *in, const asp_context *ctx);

/*
 * The discretised plane space (Decoret 2003 section 4.2): nt x np directions
 * (theta in [0, pi/2] over the half sphere, phi in [0, 2 pi)) times nr offset
 * bins of width rw from rmin; density[(k * nr) + b] sums the weights of the
 * elements valid for some offset of bin b at direction k's centre.
 */
typedef struct asp__bb_space {
    uint32_t nt, np, nr;
    size_t dirs;          /* nt * np */
    float rmin, rw, eps;
    float *dir;           /* 3 * dirs bin-centre directions */
    double *density;      /* dirs * nr */
} asp__bb_space;

int asp__bb_space_init(asp__bb_space *s, uint32_t nt, uint32_t np, double half, double eps, const asp_context *ctx,
                       asp_error *err);
void asp__bb_space_release(asp__bb_space *s, const asp_context *ctx);
/* Adds (sign +1) or removes (-1) the contributions of elems[idx[0 .. n-1]]; parallel over directions, deterministic. */
void asp__bb_space_add(asp__bb_space *s, const asp__bb_elem *elems, const uint32_t *idx, size_t n, double sign,
                       const asp_context *ctx);
/* The densest bin (lowest index among equals): direction *k, offset bin *b; returns its density. */
double asp__bb_space_best(const asp__bb_space *s, size_t *k, uint32_t *b);
/* Direction of angles (theta, phi). */
void asp__bb_direction(double theta, double phi, float n[3]);

/* The greedy search on in (billboard_greedy.c): planes in in's local frame (offset relative to in->centre). */
int asp__bb_search(const asp__bb_input *in, const asp_billboard_desc *d, const asp_context *ctx,
                   asp_billboard_plane **planes, size_t *plane_count, uint32_t *assign, asp_billboard_stats *st,
                   asp_error *err);

#endif
