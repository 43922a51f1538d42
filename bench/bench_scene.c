/*
 * Scene benchmark (issue 18 item 4): a field of N instances of MODEL seen from
 * ground level to the horizon (asp_instance_field's camera), drawn by the scene
 * renderer: splats (instanced: one accumulation, and one by one: a clear and a
 * resolve per instance), discs, and, for a .dps MODEL, domain primitives both
 * ways. Median of several frames (asp_render_frame with glFinish: culling,
 * cuts, upload and drawing, no read-back). Timings never fail anything.
 * usage: bench_scene MODEL [instances=1000] [frames=5] [size=512] [tau=1]
 */
#if !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* realpath, mkdtemp */
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/instances.h"
#include "amgsplat/scene_renderer.h"
#include "bench_common.h"

/* The scene renderer of s with renderer kind name for every source, instanced or one by one. */
static int make(asp_gl_context *gl, const asp_instance_scene *s, const char *name, float tau, int one_by_one,
                asp_renderer **out, asp_error *err)
{
    asp_scene_renderer_group g[8];
    memset(g, 0, sizeof g);
    size_t n = s->source_count < 8 ? s->source_count : 8;
    asp_renderer_options o;
    memset(&o, 0, sizeof o);
    o.splat.tolerance = o.square.tolerance = tau;
    int rc = 0;
    for (size_t i = 0; i < n && !rc; i++) {
        const asp_scene *sc = &s->sources[i].scene;
        const asp_renderer_kind *kind = NULL;
        rc = asp_renderer_kind_find(name, asp_scene_inputs(sc), &kind, err);
        asp_render_source src;
        asp_scene_render_source(sc, &src);
        if (!rc)
            rc = kind->create(gl, &src, &o, NULL, &g[i].renderer, err);
        g[i].count = asp_instance_scene_count(s, i);
        float *m = malloc(16 * g[i].count * sizeof *m);
        if (!m)
            return 1;
        asp_instance_scene_models(s, i, m);
        g[i].models = m;
        for (int a = 0; a < 3; a++)
            g[i].center[a] = (float)(sc->frame.center[a] - sc->origin[a]);
        g[i].radius = (float)sc->frame.radius;
        g[i].one_by_one = one_by_one;
    }
    if (!rc)
        rc = asp_scene_renderer_create(gl, g, n, out, err);
    for (size_t i = 0; i < n; i++)
        free((void *)g[i].models);
    return rc;
}

static int time_frames(asp_gl_context *gl, asp_renderer *r, const asp_instance_scene *s, uint32_t size, int frames,
                       double *seconds)
{
    asp_camera cam;
    asp_instance_scene_camera(s, 0, 1.0f, 40.0f, 0.0f, 0.0f, 0.0f, &cam);
    asp_render_desc desc = {.width = size, .height = size, .flags = ASP_RENDER_WAIT};
    double t[64];
    asp_error err;
    // one frame first: shader compilation and target allocation are not part of a frame
    if (asp_render_frame(gl, r, &cam, &desc, &err)) {
        fprintf(stderr, "bench_scene: %s\n", err.msg);
        return 1;
    }
    for (int f = 0; f < frames; f++) {
        double t0 = asp_time_now();
        if (asp_render_frame(gl, r, &cam, &desc, &err)) {
            fprintf(stderr, "bench_scene: %s\n", err.msg);
            return 1;
        }
        t[f] = asp_time_now() - t0;
    }
    *seconds = bench_median(t, frames);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_scene MODEL [instances=1000] [frames=5] [size=512] [tau=1]\n");
        return 2;
    }
    const char *model = argv[1];
    size_t n = argc > 2 ? (size_t)atof(argv[2]) : 1000;
    int frames = argc > 3 ? atoi(argv[3]) : 5;
    uint32_t size = argc > 4 ? (uint32_t)atoi(argv[4]) : 512;
    float tau = argc > 5 ? (float)atof(argv[5]) : 1.0f;
    if (n == 0 || frames < 1 || frames > 64 || size < 16 || size > 4096 || !(tau >= 0)) {
        fprintf(stderr, "usage: bench_scene MODEL [instances=1000] [frames=5 (1..64)] [size=512] [tau=1]\n");
        return 2;
    }
    asp_error err = {0, ""};
    asp_scene m;
    memset(&m, 0, sizeof m);
    asp_instance_scene field, s;
    char dir[] = "/tmp/bench_scene_XXXXXX", path[64], real[4096];
    if (!mkdtemp(dir) || !realpath(model, real)) {
        fprintf(stderr, "bench_scene: cannot make a folder or find '%s'\n", model);
        return 1;
    }
    snprintf(path, sizeof path, "%s/field.json", dir);
    if (asp_scene_load(model, NULL, NULL, &m, &err) ||
        asp_instance_field(&m, real, &(asp_instance_field_desc){.instances = n, .seed = 1}, &field, &err) ||
        asp_instance_scene_save(&field, path, &err) || asp_instance_scene_load(path, NULL, NULL, &s, &err)) {
        fprintf(stderr, "bench_scene: %s\n", err.msg);
        return 1;
    }
    asp_instance_scene_release(&field);
    unlink(path);
    rmdir(dir);
    asp_gl_context *gl = bench_gl_headless("bench_scene");
    if (!gl)
        return 1;
    printf("bench_scene: %zu instances of '%s' (%s), %ux%u, tau %g px, median of %d frames, %s\n", n, model,
           asp_file_kind_name(m.type.kind), size, size, (double)tau, frames, asp_gl_context_renderer(gl));
    printf("%-8s %-11s %10s %10s %12s\n", "renderer", "draws", "instances", "primitives", "ms/frame");
    static const char *const names[] = {"splat", "disc", "prim"};
    for (int k = 0; k < 3; k++)
        for (int one = 0; one < 2; one++) {
            if ((k == 1 && one) || (k == 2) != (m.dps != NULL) || (k == 1 && m.dps))
                continue;
            asp_renderer *r = NULL;
            double sec = 0;
            if (make(gl, &s, names[k], tau, one, &r, &err)) {
                fprintf(stderr, "bench_scene: %s\n", err.msg);
                return 1;
            }
            if (time_frames(gl, r, &s, size, frames, &sec))
                return 1;
            printf("%-8s %-11s %10zu %10zu %12.1f\n", names[k], one ? "one by one" : "instanced",
                   asp_scene_renderer_drawn(r), asp_renderer_count(r), 1e3 * sec);
            asp_renderer_destroy(r);
        }
    asp_gl_context_destroy(gl);
    asp_instance_scene_release(&s);
    asp_scene_release(&m);
    return 0;
}
