/*
 * The bounding sphere of a level's support rectangles (journal section 4: the
 * rectangles are what is drawn), so a .dps that records no frame is framed by
 * what it shows. No GL: eval frames such a file with it in every build.
 */
#include <math.h>

#include "amgsplat/prim.h"
#include "util/banned.h"

int asp_prim_level_bounding_sphere(const asp_dps_level *level, const double origin[3], float center[3],
                                   float *radius, asp_error *err)
{
    static const double zero[3] = {0, 0, 0};
    if (!origin)
        origin = zero;
    if (level->prim_count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot bound a level without primitives");
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    // corners in double: centres are world coordinates that may be far from origin
    for (size_t i = 0; i < level->prim_count; i++) {
        const asp_prim *p = &level->prims[i];
        for (int k = 0; k < 4; k++) {
            double su = (k & 1 ? 1.0 : -1.0) * p->half_u, sv = (k & 2 ? 1.0 : -1.0) * p->half_v;
            for (int a = 0; a < 3; a++) {
                double x = p->centre[a] - origin[a] + su * p->axis_u[a] + sv * p->axis_v[a];
                if (!isfinite(x))
                    return asp_error_set(err, ASP_EFORMAT, "cannot bound primitive %zu: non-finite corner", i);
                lo[a] = fmin(lo[a], x);
                hi[a] = fmax(hi[a], x);
            }
        }
    }
    double c[3], r2 = 0;
    for (int a = 0; a < 3; a++)
        c[a] = 0.5 * (lo[a] + hi[a]);
    for (size_t i = 0; i < level->prim_count; i++) {
        const asp_prim *p = &level->prims[i];
        for (int k = 0; k < 4; k++) {
            double su = (k & 1 ? 1.0 : -1.0) * p->half_u, sv = (k & 2 ? 1.0 : -1.0) * p->half_v, d2 = 0;
            for (int a = 0; a < 3; a++) {
                double x = p->centre[a] - origin[a] + su * p->axis_u[a] + sv * p->axis_v[a] - c[a];
                d2 += x * x;
            }
            r2 = fmax(r2, d2);
        }
    }
    if (!(r2 > 0))
        return asp_error_set(err, ASP_EDEGENERATE, "cannot bound a level whose primitives are all one point");
    for (int a = 0; a < 3; a++)
        center[a] = (float)c[a];
    *radius = (float)sqrt(r2);
    return 0;
}
