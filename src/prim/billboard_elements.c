/*
 * The elements of a billboard cloud (issue 30): a mesh's triangles or a point
 * set's discs, moved to the bounding-box centre, each with its area, normal and
 * its own plane (the plane a face lies in exactly, for the search's fallback).
 * Decoret et al. 2003 work on faces; discs (points with radii) are the
 * point-set analogue: a disc is a planar element with a rim.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "prim/billboard_internal.h"
#include "util/banned.h"

/* A unit vector perpendicular to a (for a degenerate face: a plane through its line). */
static void perpendicular(const double a[3], float out[3])
{
    double ax = fabs(a[0]), ay = fabs(a[1]), az = fabs(a[2]);
    double e[3] = {ax <= ay && ax <= az, ay < ax && ay <= az, az < ax && az < ay};
    double c[3] = {a[1] * e[2] - a[2] * e[1], a[2] * e[0] - a[0] * e[2], a[0] * e[1] - a[1] * e[0]};
    double l = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(l > 0)) {
        out[0] = 0, out[1] = 0, out[2] = 1;
        return;
    }
    for (int k = 0; k < 3; k++)
        out[k] = (float)(c[k] / l);
}

static int check_finite(const float *p, size_t n, const char *what, asp_error *err)
{
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(p[i]))
            return asp_error_set(err, ASP_EINVAL, "cannot build billboards: %s %zu has a non-finite coordinate", what,
                                 i / 3);
    return 0;
}

int asp__bb_input_mesh(const asp_mesh *mesh, const asp_context *ctx, asp__bb_input *in, asp_error *err)
{
    memset(in, 0, sizeof *in);
    if (!mesh->triangle_count)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot build billboards: the mesh has no triangles");
    int rc = check_finite(mesh->positions, mesh->vertex_count, "vertex", err);
    if (rc)
        return rc;
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t t = 0; t < 3 * mesh->triangle_count; t++) {
        uint32_t v = mesh->triangles[t];
        if (v >= mesh->vertex_count)
            return asp_error_set(err, ASP_EINVAL, "cannot build billboards: triangle %zu names vertex %u of %zu", t / 3,
                                 v, mesh->vertex_count);
        for (int k = 0; k < 3; k++)
            lo[k] = fminf(lo[k], mesh->positions[3 * (size_t)v + k]), hi[k] = fmaxf(hi[k], mesh->positions[3 * (size_t)v + k]);
    }
    double diag2 = 0;
    for (int k = 0; k < 3; k++) {
        in->centre[k] = 0.5 * ((double)lo[k] + hi[k]);
        diag2 += ((double)hi[k] - lo[k]) * ((double)hi[k] - lo[k]);
    }
    in->diagonal = sqrt(diag2);
    in->half = 0.5 * in->diagonal;
    if (!(in->diagonal > 0))
        return asp_error_set(err, ASP_EDEGENERATE, "cannot build billboards: every vertex is at one point");
    in->count = mesh->triangle_count;
    in->elems = asp_alloc(ctx, in->count * sizeof *in->elems);
    if (!in->elems)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboard elements", in->count);
    for (size_t t = 0; t < in->count; t++) {
        asp__bb_elem *e = &in->elems[t];
        memset(e, 0, sizeof *e);
        double v[3][3];
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) {
                v[j][k] = (double)mesh->positions[3 * (size_t)mesh->triangles[3 * t + j] + k] - in->centre[k];
                e->p[3 * j + k] = (float)v[j][k];
            }
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++)
            e1[k] = v[1][k] - v[0][k], e2[k] = v[2][k] - v[0][k];
        double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double l = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        e->area = (float)(0.5 * l);
        if (l > 1e-30 * diag2) {
            for (int k = 0; k < 3; k++)
                e->n[k] = e->own[k] = (float)(c[k] / l);
        } else { /* degenerate: weight 0; any plane through its longest edge holds it */
            double e3[3] = {v[2][0] - v[1][0], v[2][1] - v[1][1], v[2][2] - v[1][2]};
            const double *longest = e1;
            double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
            double l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
            double l3 = e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2];
            if (l2 > l1 && l2 >= l3)
                longest = e2;
            else if (l3 > l1 && l3 > l2)
                longest = e3;
            perpendicular(longest, e->own);
            e->area = 0;
        }
    }
    return 0;
}

int asp__bb_input_cloud(const asp_cloud *cloud, const asp_context *ctx, asp__bb_input *in, asp_error *err)
{
    memset(in, 0, sizeof *in);
    if (!cloud->count)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot build billboards: the point set is empty");
    int rc = check_finite(cloud->positions, cloud->count, "point", err);
    if (rc)
        return rc;
    float fallback_r = cloud->radii ? 0.0f : asp_cloud_default_radius(cloud);
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX}, rmax = 0;
    for (size_t i = 0; i < cloud->count; i++) {
        float r = cloud->radii ? cloud->radii[i] : fallback_r;
        if (!(r > 0) || !isfinite(r))
            return asp_error_set(err, ASP_EINVAL, "cannot build billboards: point %zu has radius %g, expected > 0", i,
                                 (double)r);
        rmax = fmaxf(rmax, r);
        for (int k = 0; k < 3; k++)
            lo[k] = fminf(lo[k], cloud->positions[3 * i + k]), hi[k] = fmaxf(hi[k], cloud->positions[3 * i + k]);
    }
    double diag2 = 0;
    for (int k = 0; k < 3; k++) {
        in->centre[k] = 0.5 * ((double)lo[k] + hi[k]);
        double side = (double)hi[k] - lo[k] + 2.0 * rmax;
        diag2 += side * side;
    }
    in->diagonal = sqrt(diag2);
    in->half = 0.5 * in->diagonal;
    in->discs = 1;
    in->count = cloud->count;
    in->elems = asp_alloc(ctx, in->count * sizeof *in->elems);
    if (!in->elems)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu billboard elements", in->count);
    for (size_t i = 0; i < in->count; i++) {
        asp__bb_elem *e = &in->elems[i];
        memset(e, 0, sizeof *e);
        for (int k = 0; k < 3; k++)
            e->p[k] = (float)((double)cloud->positions[3 * i + k] - in->centre[k]);
        e->r = cloud->radii ? cloud->radii[i] : fallback_r;
        e->area = (float)(ASP__BB_PI * (double)e->r * e->r);
        double l = 0;
        if (cloud->normals) {
            const float *n = cloud->normals + 3 * i;
            l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (l > 0 && isfinite(l))
                for (int k = 0; k < 3; k++)
                    e->n[k] = e->own[k] = (float)(n[k] / l);
        }
        if (!(l > 0 && isfinite(l)))
            e->own[2] = 1; /* a point lies in every plane through it */
    }
    return 0;
}

void asp__bb_input_release(asp__bb_input *in, const asp_context *ctx)
{
    asp_free(ctx, in->elems);
    memset(in, 0, sizeof *in);
}
