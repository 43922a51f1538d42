/*
 * Frame time of a polygon mesh against its points and its domain primitives
 * (issue 14 item 5). Seed 004 chapter 4 found texture-mapped polygons faster
 * than points in most of its tests; this measures where that holds on today's
 * renderers. Per model, at 128x128, 256x256 and 512x512, the median of N
 * frames of asp_render_frame with ASP_RENDER_WAIT (glFinish, no read-back; the
 * first frame of each renderer and size is not counted: shader JIT, target
 * allocation), as bench_prim_render times them, of:
 *   - the full mesh (asp_mesh_renderer_create, textures mipmapped);
 *   - the mesh simplified (asp_mesh_simplify) to 2 P triangles, the triangles
 *     of the P primitives' quads, and to P triangles (issue 14's "simplified
 *     mesh at N triangles" with N = P);
 *   - its points: area samples drawn as opaque discs and as blended splats
 *     (every point: tolerance 0; and the hierarchy's cut for tau = 4 pixels,
 *     the output-sensitive drawing of seed 004 3.2, which draws fewer splats
 *     the smaller the image: the row names the counts drawn);
 *   - the domain primitives of the AMG level nearest 400 (the same samples
 *     decomposed and built with the defaults), normalized and overlap methods.
 * Every row is seen from one camera (azimuth 30, elevation 20) fitted to the
 * mesh's frame (asp_scene_mesh_frame) with asp_camera_frame, so the pictures
 * match; the last column is the SSIM at 256x256 of that view against the full
 * mesh's render, so a fast row can be told from a wrong one. GPU bytes:
 * asp_mesh_gpu_bytes for meshes, asp_dps_level_gpu_bytes for primitives, and
 * for points 32 per point (float position, float normal, RGBA8 colour, float
 * radius) counted the same way (the splats' hierarchy nodes not included).
 * Prints markdown rows for BENCHMARKS.md; timings never fail anything.
 * usage: bench_mesh_render [--frames N] [--points N] [--images DIR] [MODEL.obj [TEXTURE.png]]
 * Without a model: the Stanford bunny (../shared/data, else glmark2's) and
 * spot with its texture (../shared/data), each skipped when missing.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/eval.h"
#include "amgsplat/geom.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "amgsplat/scene.h"
#include "bench_common.h"

enum { SIZES = 3, QSIZE = 256, MAX_FRAMES = 64 };

static const uint32_t sizes[SIZES] = {128, 256, 512};

typedef struct bench_opts {
    int frames;
    size_t points;
    const char *images; /* directory for the 256x256 PNGs, or NULL */
} bench_opts;

/* What every row is drawn with: one GL context, the mesh's frame, the reference image. */
typedef struct bench_view {
    asp_gl_context *gl;
    asp_frame frame;
    asp_image ref; /* the full mesh at QSIZE, for the SSIM column */
    const char *model;
} bench_view;

/* The view of every row: azimuth 30, elevation 20, the mesh's frame fitted in a renderer centred on origin. */
static void view_camera(asp_camera *cam, const asp_frame *frame, const double origin[3])
{
    asp_camera_init(cam);
    cam->azimuth = 30.0f;
    cam->elevation = 20.0f;
    asp_camera_frame(cam, frame, origin, 1.0f, 0.0f);
}


/* Median frame time in ms of r at size x size; NAN after printing the error. */
static double frame_ms(const bench_view *v, asp_renderer *r, const double origin[3], uint32_t size, int frames)
{
    double t[MAX_FRAMES];
    asp_camera cam;
    view_camera(&cam, &v->frame, origin);
    asp_render_desc d = {.width = size, .height = size, .background = {255, 255, 255, 255}, .flags = ASP_RENDER_WAIT};
    asp_error err;
    if (asp_render_frame(v->gl, r, &cam, &d, &err)) { // warm-up: shader JIT, target allocation
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        return NAN;
    }
    for (int f = 0; f < frames; f++) {
        double t0 = asp_time_now();
        asp_render_frame(v->gl, r, &cam, &d, &err);
        t[f] = 1e3 * (asp_time_now() - t0);
    }
    return bench_median(t, frames);
}

/* Renders r at QSIZE into *img (zeroed before); saves it as DIR/<model>_<tag>.png when asked. */
static int still(const bench_view *v, asp_renderer *r, const double origin[3], const bench_opts *o, const char *tag,
                 asp_image *img)
{
    asp_camera cam;
    view_camera(&cam, &v->frame, origin);
    asp_render_desc d = {.width = QSIZE, .height = QSIZE, .background = {255, 255, 255, 255}};
    asp_error err;
    if (asp_render_to_image(v->gl, r, &cam, &d, img, &err)) {
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        return -1;
    }
    if (o->images) {
        const char *base = strrchr(v->model, '/');
        char path[1024], stem[128];
        snprintf(stem, sizeof stem, "%s", base ? base + 1 : v->model);
        char *dot = strrchr(stem, '.');
        if (dot)
            *dot = '\0';
        snprintf(path, sizeof path, "%s/%s_%s.png", o->images, stem, tag);
        if (asp_image_save_png(img, path, &err))
            fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
    }
    return 0;
}

/*
 * Times r at every size and prints one markdown row: what, count, triangles,
 * GPU bytes, ms per size, SSIM against the full mesh. With is_ref the 256
 * render becomes v->ref. Destroys r.
 */
static void row(bench_view *v, asp_renderer *r, const double origin[3], const bench_opts *o, const char *what,
                const char *tag, size_t count, size_t triangles, size_t bytes, int is_ref)
{
    double ms[SIZES];
    size_t drawn[SIZES];
    for (int s = 0; s < SIZES; s++) {
        ms[s] = frame_ms(v, r, origin, sizes[s], o->frames);
        drawn[s] = asp_renderer_count(r); // what the last frame drew: a level-of-detail cut draws fewer
    }
    asp_image img = {0, 0, NULL};
    double ssim = NAN;
    asp_error err;
    if (!still(v, r, origin, o, tag, &img)) {
        if (is_ref) {
            v->ref = img;
            img = (asp_image){0, 0, NULL};
            ssim = 1.0;
        } else if (v->ref.pixels && asp_image_ssim(&v->ref, &img, &ssim, &err)) {
            fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        }
    }
    asp_image_release(&img);
    asp_renderer_destroy(r);
    char tri[32] = "-", cut[96] = "";
    if (triangles)
        snprintf(tri, sizeof tri, "%zu", triangles);
    if (drawn[0] != count || drawn[2] != count)
        snprintf(cut, sizeof cut, " (drawn at 128/256/512: %zu/%zu/%zu)", drawn[0], drawn[1], drawn[2]);
    printf("| %s%s | %zu | %s | %zu | %.2f | %.2f | %.2f | %.3f |\n", what, cut, count, tri, bytes, ms[0], ms[1], ms[2],
           ssim);
    fflush(stdout);
}

/* Simplifies mesh to target triangles and prints its row. */
static void simplified_row(bench_view *v, const asp_mesh *mesh, size_t target, const bench_opts *o, const char *label)
{
    asp_mesh *s = NULL;
    asp_mesh_simplify_stats st = {0};
    asp_error err;
    asp_renderer *r = NULL;
    asp_render_material *mats = NULL;
    if (asp_mesh_simplify(mesh, &(asp_mesh_simplify_desc){.target_triangles = target}, NULL, &s, &st, &err)) {
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        return;
    }
    mats = calloc(s->material_count, sizeof *mats);
    if (!mats) {
        fprintf(stderr, "bench_mesh_render: out of memory\n");
        asp_mesh_destroy(s);
        return;
    }
    asp_render_mesh rm;
    asp_scene_mesh_describe(s, mats, &rm);
    asp_mesh_renderer_desc md = {.origin = {s->origin[0], s->origin[1], s->origin[2]}};
    if (asp_mesh_renderer_create(v->gl, &rm, &md, &r, &err)) {
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
    } else {
        char what[96], tag[32];
        snprintf(what, sizeof what, "mesh simplified to %s (%zu asked%s)", label, target,
                 st.short_of_target ? ", stopped short" : "");
        snprintf(tag, sizeof tag, "mesh%zu", target);
        row(v, r, md.origin, o, what, tag, s->triangle_count, s->triangle_count, asp_mesh_gpu_bytes(s, NULL), 0);
    }
    free(mats);
    asp_mesh_destroy(s);
}

/* The level of amg nearest 400 primitives (issue 5), on a log scale as bench_prim_render picks it. */
static size_t level_near_400(const asp_amg *amg)
{
    size_t q = 0;
    for (size_t l = 0; l < asp_amg_level_count(amg); l++)
        if (fabs(log((double)asp_amg_level_size(amg, l) / 400.0)) <
            fabs(log((double)asp_amg_level_size(amg, q) / 400.0)))
            q = l;
    return q;
}

static int bench_model(asp_gl_context *gl, const char *path, const char *texture, const bench_opts *o)
{
    asp_error err = {0, ""};
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    asp_dps *dps = NULL;
    asp_render_material *mats = NULL;
    asp_renderer *r = NULL;
    bench_view v = {.gl = gl, .model = path};
    double t0 = asp_time_now();
    int rc = asp_mesh_load(path, &(asp_mesh_load_desc){.texture_override = texture}, NULL, &mesh, &err);
    if (!rc)
        rc = asp_scene_mesh_frame(mesh, &v.frame, &err);
    if (!rc)
        rc = asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = o->points}, NULL, &cloud,
                             NULL, &err);
    if (!rc)
        rc = asp_amg_decompose(cloud, NULL, NULL, &amg, &err);
    size_t level = amg ? level_near_400(amg) : 0;
    if (!rc)
        rc = asp_prim_build(amg, NULL, &level, 1, NULL, path, NULL, &dps, &err);
    if (!rc && !(mats = calloc(mesh->material_count, sizeof *mats)))
        rc = asp_error_set(&err, ASP_ENOMEM, "out of memory for %zu materials", mesh->material_count);
    if (rc) {
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        goto done;
    }
    const asp_dps_level *lv = &dps->levels[0];
    char lname[16];
    asp_dps_level_name(dps, 0, lname);
    printf("\n%s%s%s: %zu triangles, %zu vertices; %zu area samples decomposed into %zu levels, level %s "
           "(%zu primitives) built; set-up %.1f s\n\n",
           path, texture ? " with " : "", texture ? texture : "", mesh->triangle_count, mesh->vertex_count,
           cloud->count, asp_amg_level_count(amg), lname, lv->prim_count, asp_time_now() - t0);
    printf("| what | count | triangles | GPU bytes | 128 ms | 256 ms | 512 ms | SSIM vs mesh |\n");
    printf("|---|---|---|---|---|---|---|---|\n");

    asp_render_mesh rm;
    asp_scene_mesh_describe(mesh, mats, &rm);
    asp_mesh_renderer_desc md = {.origin = {mesh->origin[0], mesh->origin[1], mesh->origin[2]}};
    if (asp_mesh_renderer_create(gl, &rm, &md, &r, &err)) {
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
        rc = 1;
        goto done;
    }
    row(&v, r, md.origin, o, "full mesh", "mesh", mesh->triangle_count, mesh->triangle_count,
        asp_mesh_gpu_bytes(mesh, NULL), 1);

    simplified_row(&v, mesh, 2 * lv->prim_count, o, "2 P");
    simplified_row(&v, mesh, lv->prim_count, o, "P");

    // points: 12 position + 12 normal + 4 RGBA8 + 4 radius bytes each, as asp_mesh_gpu_bytes counts vertices
    size_t point_bytes = 32 * cloud->count;
    if (!asp_disc_renderer_create(gl, cloud, NULL, &r, &err))
        row(&v, r, cloud->origin, o, "area samples as discs", "discs", cloud->count, 0, point_bytes, 0);
    else
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
    if (!asp_splat_renderer_create(gl, cloud, NULL, NULL, &r, &err))
        row(&v, r, cloud->origin, o, "area samples as splats", "splats", cloud->count, 0, point_bytes, 0);
    else
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
    // the output-sensitive case of seed 004 chapter 4 (its far-object test): the hierarchy cut for 4 pixels
    if (!asp_splat_renderer_create(gl, cloud, &(asp_splat_renderer_desc){.tolerance = 4.0f}, NULL, &r, &err))
        row(&v, r, cloud->origin, o, "splats, cut at tau = 4 px", "splats_tau4", cloud->count, 0, point_bytes, 0);
    else
        fprintf(stderr, "bench_mesh_render: %s\n", err.msg);

    const asp_cloud *ac = asp_amg_cloud(amg);
    for (int m = 0; m < 2; m++) {
        asp_prim_renderer_desc pd = {.options = {.method = m ? ASP_PRIM_RENDER_OVERLAP : ASP_PRIM_RENDER_NORMALIZED},
                                     .origin = {ac->origin[0], ac->origin[1], ac->origin[2]}};
        if (asp_prim_renderer_create(gl, lv, &pd, &r, &err)) {
            fprintf(stderr, "bench_mesh_render: %s\n", err.msg);
            continue;
        }
        char what[96];
        snprintf(what, sizeof what, "primitives %s, %s", lname, asp_prim_render_method_name(pd.options.method));
        row(&v, r, pd.origin, o, what, asp_prim_render_method_name(pd.options.method), lv->prim_count,
            2 * lv->prim_count, asp_dps_level_gpu_bytes(lv, NULL), 0);
    }
done:
    asp_image_release(&v.ref);
    free(mats);
    asp_dps_destroy(dps);
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    return rc ? 1 : 0;
}

int main(int argc, char **argv)
{
    bench_opts o = {.frames = 7, .points = 200000, .images = NULL};
    const char *model = NULL, *texture = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc)
            o.frames = atoi(argv[++i]);
        else if (strcmp(argv[i], "--points") == 0 && i + 1 < argc)
            o.points = (size_t)strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--images") == 0 && i + 1 < argc)
            o.images = argv[++i];
        else if (!model)
            model = argv[i];
        else
            texture = argv[i];
    }
    if (o.frames < 1 || o.frames > MAX_FRAMES)
        o.frames = 7;
    if (o.points < 1000)
        o.points = 200000;
    asp_gl_context *gl = bench_gl_headless("bench_mesh_render");
    if (!gl)
        return 1;
    printf("GL: %s; median of %d frames, %ux%u / %ux%u / %ux%u, view 30,20 fitted to the mesh\n",
           asp_gl_context_renderer(gl), o.frames, sizes[0], sizes[0], sizes[1], sizes[1], sizes[2], sizes[2]);
    int rc = 0;
    if (model) {
        rc = bench_model(gl, model, texture, &o);
    } else {
        const char *bunny = ASP_TEST_DATA "/stanford-bunny.obj";
        if (access(bunny, R_OK) != 0)
            bunny = "/usr/share/glmark2/models/bunny.obj";
        if (access(bunny, R_OK) == 0)
            rc |= bench_model(gl, bunny, NULL, &o);
        else
            printf("bunny: %s not found, skipped\n", bunny);
        const char *spot = ASP_TEST_DATA "/spot_triangulated.obj", *spot_tex = ASP_TEST_DATA "/spot_texture.png";
        if (access(spot, R_OK) == 0 && access(spot_tex, R_OK) == 0)
            rc |= bench_model(gl, spot, spot_tex, &o);
        else
            printf("spot: %s not found, skipped\n", spot);
    }
    asp_gl_context_destroy(gl);
    asp_amg_shutdown();
    return rc;
}
