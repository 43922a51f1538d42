/*
 * Each test's scene in the three representations of the study (seed 004 2.2:
 * polygons, points; and this project's domain primitives): the mesh, points
 * sampled from it by the library's sampler, and primitives built by the
 * library's pipeline (decompose -> build), cached on disk so that fifteen
 * subjects do not rebuild them.
 */
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "experiment/internal.h"
#include "util/banned.h"

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * 0x100000001B3ull;
    return h;
}

/* the cache key: everything the derived files depend on; the version changes with the worlds' colours
   (v2: the path's verge, issue 29), which the sampled points carry */
static uint64_t scene_key(const asp_experiment_scene *s, const char *model, int short_tests)
{
    char text[1024];
    int n = snprintf(text, sizeof text, "v2|%d|%s|%llu|%u|%.6g|%.6g|%.6g|%zu|%zu|%d", s->kind, model,
                     (unsigned long long)s->seed, s->grid, s->size, s->half_width, s->relief, s->points,
                     s->primitives, short_tests);
    return fnv(0xCBF29CE484222325ull, text, n > 0 ? (size_t)n : 0);
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int make_points(exp_prepared *p, const asp_context *ctx, asp_error *err)
{
    if (file_exists(p->points_file) && asp_cloud_load(p->points_file, ctx, &p->cloud, NULL) == 0 &&
        p->cloud->count > 0)
        return 0;
    asp_cloud_destroy(p->cloud);
    p->cloud = NULL;
    asp_sample_desc sd = {.method = ASP_SAMPLE_AREA, .points = p->scene.points, .seed = 1};
    asp_cloud *fresh = NULL;
    int rc = asp_sample_mesh(p->mesh, &sd, ctx, &fresh, NULL, err);
    if (!rc)
        rc = asp_cloud_save(fresh, p->points_file, NULL, err);
    asp_cloud_destroy(fresh);
    /* always draw what the cache holds, so a first run and a cached run show the same points */
    if (!rc)
        rc = asp_cloud_load(p->points_file, ctx, &p->cloud, err);
    return rc;
}

static int make_primitives(exp_prepared *p, const asp_context *ctx, asp_error *err)
{
    if (file_exists(p->dps_file) && asp_dps_load(p->dps_file, ctx, &p->dps, NULL) == 0 && p->dps->level_count > 0)
        return 0;
    asp_dps_destroy(p->dps);
    p->dps = NULL;
    asp_amg *amg = NULL;
    size_t level = 0;
    int rc = asp_amg_decompose(p->cloud, NULL, ctx, &amg, err);
    if (!rc)
        rc = asp_prim_level_for_budget(amg, p->scene.primitives, &level, err);
    if (!rc)
        rc = asp_prim_build(amg, NULL, &level, 1, NULL, p->points_file, ctx, &p->dps, err);
    asp_amg_destroy(amg);
    if (!rc)
        rc = asp_dps_save(p->dps, p->dps_file, err);
    asp_dps_destroy(p->dps);
    p->dps = NULL;
    if (!rc)
        rc = asp_dps_load(p->dps_file, ctx, &p->dps, err);
    return rc;
}

static int make_renderers(exp_prepared *p, asp_gl_context *gl, const asp_experiment_desc *desc,
                          const asp_context *ctx, asp_error *err)
{
    asp_mesh_renderer_desc md = {0};
    memcpy(md.origin, p->mesh->origin, sizeof md.origin);
    int rc = asp_mesh_renderer_create(gl, &p->render_mesh, &md, &p->renderer[ASP_EXPERIMENT_POLYGONS], err);
    memcpy(p->origin[ASP_EXPERIMENT_POLYGONS], p->mesh->origin, sizeof p->origin[0]);
    /* seed 004 3.2.6: the octree cut drawn as hardware squares; tau sets how coarse the cut is (3.2.3) */
    asp_square_renderer_desc sq = {.tolerance = desc->coarse_tau > 0.0f ? desc->coarse_tau : 1.0f};
    if (!rc)
        rc = asp_square_renderer_create(gl, p->cloud, &sq, ctx, &p->renderer[ASP_EXPERIMENT_POINTS], err);
    p->tau = sq.tolerance;
    if (!rc && desc->adapt) {
        /* Fig. 3.5 with the band of an interactive rate: refine below 1/60 s, coarsen above 1/30 s */
        asp_hier_adapt_desc ad = {.f_min = 1.0 / 60.0, .f_max = 1.0 / 30.0, .mode = ASP_HIER_ADAPT_DEPTH,
                                  .depth_min = desc->depth_limit ? desc->depth_limit : 1};
        rc = asp_hier_adapt_init(&p->adapt, &ad, err);
        p->adapting = !rc;
    }
    if (!rc && desc->depth_limit)
        rc = asp_renderer_set_lod(p->renderer[ASP_EXPERIMENT_POINTS], sq.tolerance, desc->depth_limit, err);
    memcpy(p->origin[ASP_EXPERIMENT_POINTS], p->cloud->origin, sizeof p->origin[0]);
    asp_prim_renderer_desc pd = {0};
    memcpy(pd.origin, p->mesh->origin, sizeof pd.origin);
    if (!rc)
        rc = asp_prim_renderer_create(gl, &p->dps->levels[0], &pd, &p->renderer[ASP_EXPERIMENT_PRIMITIVES], err);
    memcpy(p->origin[ASP_EXPERIMENT_PRIMITIVES], p->mesh->origin, sizeof p->origin[0]);
    memcpy(p->origin[ASP_EXPERIMENT_BLANK], p->mesh->origin, sizeof p->origin[0]);
    return rc;
}

int asp__exp_prepare(const asp_experiment_scenes *scenes, asp_experiment_test test, const char *cache_dir,
                     int short_tests, asp_gl_context *gl, const asp_experiment_desc *desc, const asp_context *ctx,
                     exp_prepared *out, asp_error *err)
{
    exp_prepared p;
    memset(&p, 0, sizeof p);
    p.scene = scenes->tests[test];
    if (short_tests) {
        /* CI size: a quarter of the points and a coarser field; the scenes stay the same shape */
        p.scene.points = p.scene.points / 4 > 2000 ? p.scene.points / 4 : 2000;
        p.scene.primitives = p.scene.primitives / 4 > 50 ? p.scene.primitives / 4 : 50;
        /* but fine enough that the path is three cells across: vertex colours blend over a cell, and a
           coarser grid smears the sand of the path over its verge (issue 29) */
        uint32_t path_grid =
            p.scene.half_width > 0.0f ? (uint32_t)ceilf(p.scene.size / (0.75f * p.scene.half_width)) + 1u : 0u;
        uint32_t coarse = path_grid > 97 ? path_grid : 97;
        if (p.scene.grid > coarse)
            p.scene.grid = coarse;
    }
    const char *model = "";
    int rc = 0;
    if (p.scene.kind == 0) {
        const asp_experiment_candidate *c = NULL;
        for (size_t i = 0; i < scenes->candidate_count; i++)
            if (strcmp(scenes->candidates[i].name, p.scene.answer) == 0)
                c = &scenes->candidates[i];
        if (!c)
            return asp_error_set(err, ASP_EINVAL, "test '%s' shows '%s', which is not a candidate",
                                 asp_experiment_test_name(test), p.scene.answer);
        model = c->model;
        snprintf(p.model_name, sizeof p.model_name, "%s", c->name);
        rc = asp_mesh_load(c->model, &(asp_mesh_load_desc){.up = c->up}, ctx, &p.mesh, err);
    } else {
        rc = asp_experiment_world_generate(&p.scene, ctx, &p.world, err);
        p.mesh = p.world.mesh;
    }
    if (rc)
        return rc;
    rc = asp_scene_mesh_frame(p.mesh, &p.frame, err);
    p.materials = rc ? NULL : asp_calloc(ctx, p.mesh->material_count, sizeof *p.materials);
    if (!rc && !p.materials)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for materials");
    if (!rc)
        asp_scene_mesh_describe(p.mesh, p.materials, &p.render_mesh);
    uint64_t key = scene_key(&p.scene, model, short_tests);
    snprintf(p.points_file, sizeof p.points_file, "%s/%s-%016llx.ply", cache_dir, asp_experiment_test_name(test),
             (unsigned long long)key);
    snprintf(p.dps_file, sizeof p.dps_file, "%s/%s-%016llx.dps", cache_dir, asp_experiment_test_name(test),
             (unsigned long long)key);
    char mesh_file[2300];
    snprintf(mesh_file, sizeof mesh_file, "%s/%s-%016llx-mesh.ply", cache_dir, asp_experiment_test_name(test),
             (unsigned long long)key);
    /* the generated worlds as files too, for a look in `amgsplat view` or another program */
    if (!rc && p.scene.kind != 0 && !file_exists(mesh_file))
        rc = asp_mesh_save(p.mesh, mesh_file, NULL, err);
    if (!rc)
        rc = make_points(&p, ctx, err);
    if (!rc)
        rc = make_primitives(&p, ctx, err);
    if (!rc)
        rc = make_renderers(&p, gl, desc, ctx, err);
    if (rc) {
        asp__exp_prepared_release(&p);
        return rc;
    }
    p.triangles = p.mesh->triangle_count;
    p.points = p.cloud->count;
    p.primitives = p.dps->levels[0].prim_count;
    *out = p;
    return 0;
}

void asp__exp_prepared_release(exp_prepared *p)
{
    for (int c = 0; c < ASP_EXPERIMENT_CONDITION_COUNT; c++)
        asp_renderer_destroy(p->renderer[c]);
    asp_dps_destroy(p->dps);
    asp_cloud_destroy(p->cloud);
    asp_context ctx = p->mesh ? p->mesh->ctx : (asp_context){0};
    asp_free(&ctx, p->materials);
    if (p->world.mesh)
        asp_experiment_world_release(&p->world);
    else
        asp_mesh_destroy(p->mesh);
    memset(p, 0, sizeof *p);
}
