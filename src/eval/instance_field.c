/*
 * `amgsplat scene field`: a test scene of many instances of one model on a
 * ground grid receding to the horizon (issue 18 item 4), the large scene of
 * seed 004's future work where distance-dependent detail pays off (seed 001
 * 5.1: far instances need far fewer splats). Seeded, so a seed gives one file.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/instances.h"
#include "util/banned.h"

static const double pi = 3.14159265358979323846;

/* SplitMix64 (Steele et al. 2014): a tiny seeded generator whose stream is fixed across platforms. */
static uint64_t next_u64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double next_unit(uint64_t *state)
{
    return (double)(next_u64(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* The model's lowest world y: its points, mesh vertices or primitive corners; else the frame's bottom. */
static double model_floor(const asp_scene *m)
{
    double lo = INFINITY;
    if (m->cloud)
        for (size_t i = 0; i < m->cloud->count; i++)
            lo = fmin(lo, m->cloud->origin[1] + m->cloud->positions[3 * i + 1]);
    else if (m->mesh)
        for (size_t i = 0; i < m->mesh->vertex_count; i++)
            lo = fmin(lo, m->mesh->origin[1] + m->mesh->positions[3 * i + 1]);
    else if (asp_scene_dps_level(m)) {
        const asp_dps_level *l = asp_scene_dps_level(m);
        for (size_t i = 0; i < l->prim_count; i++) {
            const asp_prim *p = &l->prims[i];
            lo = fmin(lo, p->centre[1] - fabs(p->half_u * p->axis_u[1]) - fabs(p->half_v * p->axis_v[1]));
        }
    }
    return isfinite(lo) ? lo : m->frame.center[1] - m->frame.radius;
}

int asp_instance_field(const asp_scene *model, const char *source_name, const asp_instance_field_desc *desc,
                       asp_instance_scene *out, asp_error *err)
{
    ASP_ASSERT(model && source_name && out);
    static const asp_instance_field_desc zero;
    const asp_instance_field_desc *d = desc ? desc : &zero;
    size_t n = d->instances ? d->instances : 100;
    double spacing = d->spacing ? d->spacing : 1.5, jitter = d->jitter ? d->jitter : 0.3;
    if (n > ASP_INSTANCE_SCENE_MAX_INSTANCES)
        return asp_error_set(err, ASP_EINVAL, "%zu instances, more than %d", n, ASP_INSTANCE_SCENE_MAX_INSTANCES);
    if (!(spacing > 0 && spacing <= 1e3))
        return asp_error_set(err, ASP_EINVAL, "spacing %g model diameters is not in (0, 1000]", spacing);
    if (jitter < 0)
        jitter = 0;
    if (!(jitter <= 1))
        return asp_error_set(err, ASP_EINVAL, "jitter %g grid steps is not in [0, 1]", jitter);
    if (strlen(source_name) >= sizeof out->sources[0].name || !source_name[0])
        return asp_error_set(err, ASP_EINVAL, "source name '%.64s' is empty or longer than %zu bytes", source_name,
                             sizeof out->sources[0].name - 1);
    double r = model->frame.radius;
    if (!(r > 0) || !isfinite(r))
        return asp_error_set(err, ASP_EDEGENERATE, "'%s' has no frame to size a field by", model->path);

    asp_instance_scene s;
    memset(&s, 0, sizeof s);
    s.instances = asp_calloc(&s.ctx, n, sizeof *s.instances);
    s.sources = asp_calloc(&s.ctx, 1, sizeof *s.sources);
    if (!s.instances || !s.sources) {
        asp_instance_scene_release(&s);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu instances", n);
    }
    snprintf(s.sources[0].name, sizeof s.sources[0].name, "%s", source_name);
    snprintf(s.sources[0].path, sizeof s.sources[0].path, "%s", source_name);
    s.source_count = 1;
    s.instance_count = n;

    // twice as deep as wide, so from its near edge the field fills the view and runs to the horizon
    size_t cols = (size_t)ceil(sqrt((double)n / 2.0));
    cols = cols ? cols : 1;
    size_t rows = (n + cols - 1) / cols;
    double step = spacing * 2.0 * r;
    double floor_y = model_floor(model);
    const double *c = model->frame.center;
    uint64_t state = d->seed;
    for (size_t k = 0; k < n; k++) {
        size_t row = k / cols, col = k % cols;
        double yaw = 2.0 * pi * next_unit(&state);
        double jx = jitter * (next_unit(&state) - 0.5), jz = jitter * (next_unit(&state) - 0.5);
        double x = ((double)col - 0.5 * (double)(cols - 1) + jx) * step, z = -((double)row + jz) * step;
        double cy = cos(yaw), sy = sin(yaw);
        // T(x, 0, z) * Ry(yaw) * T(-c.x, -floor, -c.z): the model's centre over (x, z), its lowest point on y = 0
        double *m = s.instances[k].model;
        memset(m, 0, 16 * sizeof *m);
        m[0] = cy;
        m[2] = -sy;
        m[5] = 1;
        m[8] = sy;
        m[10] = cy;
        m[15] = 1;
        m[12] = x - (cy * c[0] + sy * c[2]);
        m[13] = -floor_y;
        m[14] = z - (-sy * c[0] + cy * c[2]);
    }
    // at the near edge, half a model high, looking along the field to its far end, pitched 8 degrees
    // down so the horizon sits in the upper third of a 50-degree view and the field fills the rest
    double eye_h = r, depth = ((double)(rows > 1 ? rows - 1 : 1) + 0.8) * step;
    s.camera.given = 1;
    s.camera.eye[0] = 0;
    s.camera.eye[1] = eye_h;
    s.camera.eye[2] = 0.8 * step;
    s.camera.target[0] = 0;
    s.camera.target[1] = eye_h - depth * tan(8.0 * pi / 180.0);
    s.camera.target[2] = s.camera.eye[2] - depth;
    s.camera.fov_y = 50.0f;
    *out = s;
    return 0;
}
