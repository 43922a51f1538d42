/*
 * Shared by the fit tests (test_fit_*.c): a camera as asp_fit_view without GL, the octahedron's
 * 8 face domains built into one level (asp_prim_build_level, no hypre), and a level copy whose
 * atlas the test may change.
 */
#ifndef ASP_TEST_FIT_COMMON_H
#define ASP_TEST_FIT_COMMON_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amgsplat.h"

#define PI 3.14159265358979323846

/* A camera at distance 3.2 from the origin (asp_camera conventions, fov 40, no GL needed). */
static inline void look(float az_deg, float el_deg, uint32_t size, asp_fit_view *v)
{
    double az = az_deg * PI / 180, el = el_deg * PI / 180, dist = 3.2;
    double eye[3] = {dist * cos(el) * sin(az), dist * sin(el), dist * cos(el) * cos(az)};
    double f[3] = {-eye[0] / dist, -eye[1] / dist, -eye[2] / dist};
    double up[3] = {0, 1, 0};
    if (fabs(f[1]) > 0.999)
        up[1] = 0, up[2] = f[1] > 0 ? 1 : -1;
    double r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
    double rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int a = 0; a < 3; a++)
        r[a] /= rn;
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    memset(v, 0, sizeof *v);
    for (int a = 0; a < 3; a++) {
        v->view[4 * a] = (float)r[a];
        v->view[4 * a + 1] = (float)u[a];
        v->view[4 * a + 2] = (float)-f[a];
    }
    v->view[12] = (float)-(r[0] * eye[0] + r[1] * eye[1] + r[2] * eye[2]);
    v->view[13] = (float)-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    v->view[14] = (float)(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
    v->view[15] = 1;
    double t = 1 / tan(20 * PI / 180), n = 1, fa = 6;
    v->proj[0] = (float)t;
    v->proj[5] = (float)t;
    v->proj[10] = (float)((fa + n) / (n - fa));
    v->proj[11] = -1;
    v->proj[14] = (float)(2 * fa * n / (n - fa));
    v->width = v->height = size;
    v->light[2] = 1;
}

/* The octahedron's faces as 8 domains of Psi 1 (asp_synth labels). */
static inline int octahedron_level(asp_dps_level *lv)
{
    asp_error err = {0};
    asp_cloud *c = NULL;
    asp_amg_csr *dom = NULL;
    int rc = asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 8000}, NULL, &c, &err);
    if (!rc)
        rc = asp_amg_csr_create(8, c->count, c->count, NULL, &dom, &err);
    if (!rc) {
        size_t e = 0;
        for (uint32_t f = 0; f < 8; f++) {
            dom->row_ptr[f] = e;
            for (size_t p = 0; p < c->count; p++)
                if (c->labels[p] == f) {
                    dom->col[e] = (asp_index)p;
                    dom->val[e++] = 1.0;
                }
        }
        dom->row_ptr[8] = e;
        memset(lv, 0, sizeof *lv);
        rc = asp_prim_build_level(c, dom, NULL, NULL, lv, &err);
    }
    if (rc)
        fprintf(stderr, "octahedron level: %s\n", err.msg);
    asp_amg_csr_destroy(dom);
    asp_cloud_destroy(c);
    return rc;
}

static inline int copy_level(const asp_dps_level *src, asp_dps_level *dst)
{
    *dst = *src;
    size_t bytes = 4 * (size_t)src->atlas.width * src->atlas.height;
    dst->atlas.pixels = malloc(bytes);
    if (!dst->atlas.pixels)
        return -1;
    memcpy(dst->atlas.pixels, src->atlas.pixels, bytes);
    return 0;
}

#endif
