/*
 * amgsplat bench-paper: the seeds' tables measured on this build, printed in
 * their layouts: journal Table 1 (pre-processing) and Table 2 / thesis Table
 * 5.2 (per level), thesis Table 5.3 (points against domain primitives) and
 * Table 5.4 (texture construction methods); and, with --table 6.1, thesis
 * Table 6.1 measured for real (issue 30): domain primitives against billboard
 * clouds at one texel count and the nearest plane count, against the mesh.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat bench-paper MODEL [--sizes 128,256,512] [--frames 10] [--max-primitives 2000]\n"
    "                            [--budget 500] [--no-texture-methods] [--points N] [--texture IMG]\n"
    "                            [--markdown]\n"
    "       amgsplat bench-paper MESH --table 6.1 [--budget 300] [--views 16] [--sizes 128,256] [--points N]\n"
    "\n"
    "Measures and prints, in the layouts of the seeds: journal Table 1 (points, level, polygons,\n"
    "texels, decomposition and construction time), thesis Table 5.1 (the same level with texture\n"
    "method tc, AMG and basis time cb), journal Table 2 / thesis Table 5.2 (per level:\n"
    "polygons, texels, error, normalised error, basis and construction times, frame rate at each\n"
    "screen size), thesis Table 5.3 (frame rate of the point set against domain primitives, speed-up)\n"
    "and thesis Table 5.4 (construction time per texture method at texel sizes 2, 1 and 0.5). The\n"
    "Table 1 / 5.1 / 5.3 / 5.4 level is the finest with at most --budget primitives. MODEL as for\n"
    "'amgsplat eval'. --markdown prints the tables as Markdown (docs/results.md uses it).\n"
    "\n"
    "--table 6.1 prints thesis Table 6.1 instead, measured: for every level with at most --budget\n"
    "domain primitives (of --points samples of MESH, default 50000), the level drawn normalized\n"
    "against a billboard cloud of the mesh (simplify --billboards) with the level's texel count and\n"
    "the error bound whose plane count is nearest its primitive count: count, texels, bound, build\n"
    "seconds (domain: decomposition + the level's basis and construction; billboards: plane search +\n"
    "textures), GPU bytes and SSIM, PSNR and silhouette IoU against the mesh's own render, means over\n"
    "--views views at each size; then the thesis's madcat row (59,855 triangles at a 6% bound: 171\n"
    "planes, 1,638k texels, 529 s) next to this mesh's billboard cloud at 6%.";

enum { MAX_SIZES = 8 };

static void fmt_fps(char *buf, size_t cap, double v)
{
    if (isfinite(v))
        snprintf(buf, cap, "%.0f", v);
    else
        snprintf(buf, cap, "-");
}

static void fmt_time(char *buf, size_t cap, double v)
{
    if (!isfinite(v))
        snprintf(buf, cap, "-");
    else if (v < 0.01)
        snprintf(buf, cap, "< 0.01");
    else
        snprintf(buf, cap, "%.2f", v);
}

/* One table row: cells separated by '|' in Markdown, padded columns otherwise. */
struct table {
    int md;
    int widths[16];
    int ncols;
    int header_done;
};

static void row(struct table *t, const char *const *cells)
{
    for (int i = 0; i < t->ncols; i++) {
        if (t->md)
            printf("| %s ", cells[i]);
        else
            printf(i ? "  %*s" : "%-*s", t->widths[i], cells[i]);
    }
    printf(t->md ? "|\n" : "\n");
    if (t->md && !t->header_done) {
        // the separator after the header row
        for (int i = 0; i < t->ncols; i++)
            printf("|---");
        printf("|\n");
    }
    t->header_done = 1;
}

static void title(int md, const char *text)
{
    printf(md ? "\n**%s**\n\n" : "\n%s\n", text);
}

static void table1(const asp_eval_paper *p, const char *model, int md)
{
    const asp_eval_paper_level *l = &p->levels[p->budget_level];
    title(md, "Journal Table 1: pre-processing times");
    struct table t = {.md = md, .widths = {24, 10, 9, 12, 14, 11, 12}, .ncols = 7};
    const char *head[] = {"model", "points", "AMG level", "no. of polys", "no. of texels", "sd time (s)",
                          "dpc time (s)"};
    row(&t, head);
    char pts[32], polys[32], tex[32], sd[32], dpc[32];
    snprintf(pts, sizeof pts, "%zu", p->points);
    snprintf(polys, sizeof polys, "%zu", l->primitives);
    snprintf(tex, sizeof tex, "%llu", (unsigned long long)l->texels);
    fmt_time(sd, sizeof sd, p->t_decompose);
    fmt_time(dpc, sizeof dpc, l->t_construct);
    const char *base = strrchr(model, '/');
    const char *cells[] = {base ? base + 1 : model, pts, l->name, polys, tex, sd, dpc};
    row(&t, cells);
}

/* Thesis Table 5.1: Table 1's row with the thesis's columns tc, AMG and cb (issue 17). */
static void table51(const asp_eval_paper *p, const char *model, int md)
{
    const asp_eval_paper_level *l = &p->levels[p->budget_level];
    title(md, "Thesis Table 5.1: statistics of the rendered level (times in s)");
    struct table t = {.md = md, .widths = {24, 10, 6, 7, 10, 3, 9, 9, 9}, .ncols = 9};
    const char *head[] = {"model", "#points", "level", "#poly", "# tex", "tc", "AMG", "cb", "dpc"};
    row(&t, head);
    char pts[32], polys[32], tex[32], amg[32], cb[32], dpc[32];
    snprintf(pts, sizeof pts, "%zu", p->points);
    snprintf(polys, sizeof polys, "%zu", l->primitives);
    snprintf(tex, sizeof tex, "%llu", (unsigned long long)l->texels);
    fmt_time(amg, sizeof amg, p->t_decompose); // the thesis's AMG column: matrix M^0 and the AMG run
    fmt_time(cb, sizeof cb, l->t_basis);
    fmt_time(dpc, sizeof dpc, l->t_construct);
    const char *base = strrchr(model, '/');
    // tc: the measured builds use build's defaults, linear affine textures ("la"; "r" = radial)
    const char *cells[] = {base ? base + 1 : model, pts, l->name, polys, tex, "la", amg, cb, dpc};
    row(&t, cells);
}

static void table52(const asp_eval_paper *p, int md)
{
    title(md, "Journal Table 2 / thesis Table 5.2: statistics per AMG level (fps: domain primitives)");
    struct table t = {.md = md, .widths = {5, 6, 9, 12, 10, 10, 7, 7}, .ncols = 8 + (int)p->size_count};
    char hdr[MAX_SIZES][24];
    const char *head[16] = {"level", "name", "#poly", "#tex", "error", "normalized", "cb (s)", "dpc (s)"};
    for (size_t i = 0; i < p->size_count; i++) {
        snprintf(hdr[i], sizeof hdr[i], "fps %u", p->sizes[i]);
        head[8 + i] = hdr[i];
        t.widths[8 + i] = 8;
    }
    row(&t, head);
    for (size_t l = 0; l < p->level_count; l++) {
        const asp_eval_paper_level *lv = &p->levels[l];
        char c[16][32];
        const char *cells[16];
        snprintf(c[0], 32, "%u", lv->level);
        snprintf(c[1], 32, "%s", lv->name);
        snprintf(c[2], 32, "%zu", lv->primitives);
        snprintf(c[3], 32, "%llu", (unsigned long long)lv->texels);
        snprintf(c[4], 32, "%.6f", lv->error);
        snprintf(c[5], 32, "%.3g", lv->error_norm);
        fmt_time(c[6], 32, lv->t_basis);
        fmt_time(c[7], 32, lv->t_construct);
        for (size_t i = 0; i < p->size_count; i++)
            fmt_fps(c[8 + i], 32, lv->fps[i]);
        for (int i = 0; i < t.ncols; i++)
            cells[i] = c[i];
        row(&t, cells);
    }
}

static void table53(const asp_eval_paper *p, const char *model, int md)
{
    const asp_eval_paper_level *l = &p->levels[p->budget_level];
    char text[160];
    snprintf(text, sizeof text, "Thesis Table 5.3: frame rate of points against domain primitives (%s, level %s)",
             p->fps_method[0] ? p->fps_method : "no renderer", l->name);
    title(md, text);
    struct table t = {.md = md, .widths = {24, 6, 11, 8, 8}, .ncols = 5};
    const char *head[] = {"model", "size", "fps points", "fps dp", "speedup"};
    row(&t, head);
    const char *base = strrchr(model, '/');
    for (size_t i = 0; i < p->size_count; i++) {
        char sz[16], a[32], b[32], s[32];
        snprintf(sz, sizeof sz, "%u", p->sizes[i]);
        fmt_fps(a, sizeof a, p->fps_points[i]);
        fmt_fps(b, sizeof b, l->fps[i]);
        double up = l->fps[i] / p->fps_points[i];
        if (isfinite(up))
            snprintf(s, sizeof s, "%.1f", up);
        else
            snprintf(s, sizeof s, "-");
        const char *cells[] = {base ? base + 1 : model, sz, a, b, s};
        row(&t, cells);
    }
}

static void table54(const asp_eval_paper *p, int md)
{
    char text[160];
    snprintf(text, sizeof text, "Thesis Table 5.4: construction time (s) per texture method, level %s",
             p->levels[p->budget_level].name);
    title(md, text);
    struct table t = {.md = md, .widths = {10, 9, 9, 9, 9, 13}, .ncols = 6};
    const char *head[] = {"texel size", "#texels", "constant", "linear", "Gaussian", "linear affine"};
    row(&t, head);
    for (int k = 0; k < 3; k++) {
        char c[6][32];
        snprintf(c[0], 32, "%g", p->t54_texel_size[k]);
        snprintf(c[1], 32, "%.0f k", (double)p->t54_texels[k] / 1000.0);
        for (int m = 0; m < 4; m++)
            fmt_time(c[2 + m], 32, p->t54_seconds[k][m]);
        const char *cells[] = {c[0], c[1], c[2], c[3], c[4], c[5]};
        row(&t, cells);
    }
}

static int print_json(const struct cli_env *env, const asp_eval_paper *p, const char *model, int texture_methods)
{
    cJSON *o = cJSON_CreateObject(), *sizes = cJSON_CreateArray(), *fps = cJSON_CreateArray(),
          *levels = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "model", model);
    cJSON_AddNumberToObject(o, "points", (double)p->points);
    cJSON_AddItemToObject(o, "decompose_seconds", cli_json_number("%.4f", p->t_decompose));
    cJSON_AddStringToObject(o, "gl_renderer", p->gl_renderer);
    cJSON_AddStringToObject(o, "fps_method", p->fps_method);
    for (size_t i = 0; i < p->size_count; i++) {
        cJSON_AddItemToArray(sizes, cJSON_CreateNumber(p->sizes[i]));
        cJSON_AddItemToArray(fps, cli_json_number("%.2f", p->fps_points[i]));
    }
    cJSON_AddItemToObject(o, "sizes", sizes);
    cJSON_AddItemToObject(o, "fps_points", fps);
    cJSON_AddStringToObject(o, "budget_level", p->levels[p->budget_level].name);
    for (size_t l = 0; l < p->level_count; l++) {
        const asp_eval_paper_level *lv = &p->levels[l];
        cJSON *j = cJSON_CreateObject(), *lfps = cJSON_CreateArray();
        cJSON_AddNumberToObject(j, "level", lv->level);
        cJSON_AddStringToObject(j, "name", lv->name);
        cJSON_AddNumberToObject(j, "primitives", (double)lv->primitives);
        cJSON_AddNumberToObject(j, "texels", (double)lv->texels);
        cJSON_AddItemToObject(j, "error", cli_json_number("%.9g", lv->error));
        cJSON_AddItemToObject(j, "normalised_error", cli_json_number("%.6g", lv->error_norm));
        cJSON_AddItemToObject(j, "cb_seconds", cli_json_number("%.4f", lv->t_basis));
        cJSON_AddItemToObject(j, "dpc_seconds", cli_json_number("%.4f", lv->t_construct));
        for (size_t i = 0; i < p->size_count; i++)
            cJSON_AddItemToArray(lfps, cli_json_number("%.2f", lv->fps[i]));
        cJSON_AddItemToObject(j, "fps", lfps);
        cJSON_AddItemToArray(levels, j);
    }
    cJSON_AddItemToObject(o, "levels", levels);
    if (!texture_methods) {
        cJSON_AddNullToObject(o, "texture_methods");
        return cli_json_print(env, o);
    }
    cJSON *tm = cJSON_CreateArray();
    static const char *names[4] = {"constant", "linear", "gaussian", "linear_affine"};
    for (int k = 0; k < 3; k++) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddItemToObject(j, "texel_size", cli_json_number("%g", p->t54_texel_size[k]));
        cJSON_AddNumberToObject(j, "texels", (double)p->t54_texels[k]);
        for (int m = 0; m < 4; m++)
            cJSON_AddItemToObject(j, names[m], cli_json_number("%.4f", p->t54_seconds[k][m]));
        cJSON_AddItemToArray(tm, j);
    }
    cJSON_AddItemToObject(o, "texture_methods", tm);
    return cli_json_print(env, o);
}

/* The rows of representation name at the level named level_name and image size size (SIZE_MAX: none). */
static size_t find_row61(const asp_eval_result *res, const char *name, const char *level_name, uint32_t size)
{
    for (size_t i = 0; i < res->row_count; i++)
        if (strcmp(res->rows[i].representation, name) == 0 && strcmp(res->rows[i].level_name, level_name) == 0 &&
            res->rows[i].size == size)
            return i;
    return SIZE_MAX;
}

/*
 * Thesis Table 6.1 for real (issue 30): the thesis took billboard clouds' figures from Decoret et al.
 * 2003 (madcat) against its own dinosaur; here both methods run on one mesh, at one texel count and
 * the nearest plane count, against the mesh's render (asp_eval_run with the billboards row).
 */
static int table61(struct cli_env *env, const char *model, const char *texture, size_t points, size_t budget,
                   size_t views, const uint32_t *sizes, size_t nsizes, int md)
{
    asp_error err = {0};
    asp_cloud *cloud = NULL;
    asp_mesh *mesh = NULL;
    int rc = asp_eval_load_model_mesh(model, points ? points : 50000, texture, &env->ctx, &cloud, &mesh, &err);
    if (!rc && !mesh) {
        asp_cloud_destroy(cloud);
        return cli_usage_error(env, "--table 6.1 compares against a mesh's render: '%s' is not a mesh", model);
    }
    static const asp_prim_render_method normalized = ASP_PRIM_RENDER_NORMALIZED;
    asp_eval_result *res = NULL;
    if (!rc) {
        asp_eval_desc d = {.views = views, .sizes = sizes, .size_count = nsizes, .max_primitives = budget,
                           .frames = 1, .methods = &normalized, .method_count = 1, .mesh = mesh, .billboards = 1};
        rc = asp_eval_run(cloud, &d, &env->ctx, &res, &err);
    }
    /* the madcat row: this mesh at the 6% bound Decoret et al. quote, default texel */
    asp_dps *bb6 = NULL;
    asp_billboard_stats st6 = {0};
    if (!rc)
        rc = asp_billboard_mesh(mesh, &(asp_billboard_desc){.error = 0.06}, model, &env->ctx, &bb6, &st6, &err);
    asp_amg_shutdown();
    cli_progress_end(env);
    if (rc) {
        asp_eval_result_destroy(res);
        asp_cloud_destroy(cloud);
        asp_mesh_destroy(mesh);
        return cli_fail(env, &err);
    }
    if (env->json) {
        cJSON *o = cJSON_CreateObject(), *rows = cJSON_CreateArray();
        cJSON_AddStringToObject(o, "model", model);
        cJSON_AddNumberToObject(o, "triangles", (double)mesh->triangle_count);
        cJSON_AddNumberToObject(o, "points", (double)cloud->count);
        cJSON_AddNumberToObject(o, "views", (double)res->views);
        cJSON_AddItemToObject(o, "t_decompose", cli_json_number("%.4f", res->t_decompose));
        for (size_t i = 0; i < res->row_count; i++) {
            const asp_eval_row *a = &res->rows[i];
            int bb = strcmp(a->representation, "billboards") == 0;
            if (!bb && strcmp(a->representation, "dp-normalized") != 0)
                continue;
            cJSON *j = cJSON_CreateObject();
            cJSON_AddStringToObject(j, "level", a->level_name);
            cJSON_AddStringToObject(j, "method", bb ? "billboards" : "domain");
            cJSON_AddNumberToObject(j, "size", a->size);
            cJSON_AddNumberToObject(j, "count", (double)a->primitives);
            cJSON_AddNumberToObject(j, "texels", (double)a->texels);
            cJSON_AddItemToObject(j, "error_bound", cli_json_number("%.6g", a->error_bound));
            cJSON_AddItemToObject(j, "build_seconds", cli_json_number("%.4f", a->build_seconds));
            cJSON_AddNumberToObject(j, "bytes", (double)a->bytes);
            cJSON_AddItemToObject(j, "ssim", cli_json_number("%.6f", a->ssim_mean));
            cJSON_AddItemToObject(j, "psnr", cli_json_number("%.4f", a->psnr_mean));
            cJSON_AddItemToObject(j, "iou", cli_json_number("%.6f", a->iou_mean));
            cJSON_AddItemToArray(rows, j);
        }
        cJSON_AddItemToObject(o, "rows", rows);
        cJSON *m6 = cJSON_CreateObject();
        cJSON_AddNumberToObject(m6, "planes", (double)st6.planes);
        cJSON_AddNumberToObject(m6, "texels", (double)st6.texels);
        cJSON_AddItemToObject(m6, "seconds", cli_json_number("%.4f", st6.t_search + st6.t_texture));
        cJSON_AddItemToObject(o, "bound_6_percent", m6);
        rc = cli_json_print(env, o);
        asp_dps_destroy(bb6);
        asp_eval_result_destroy(res);
        asp_cloud_destroy(cloud);
        asp_mesh_destroy(mesh);
        return rc;
    }
    char text[256];
    snprintf(text, sizeof text, "Thesis Table 6.1 measured: domain primitives (%zu samples) against billboard clouds of "
             "'%s' (%zu triangles), %zu views, against the mesh's render", cloud->count, model, mesh->triangle_count,
             res->views);
    title(md, text);
    struct table t = {.md = md, .widths = {6, 11, 6, 9, 6, 8, 9}, .ncols = 7 + 3 * (int)nsizes};
    const char *head[7 + 3 * MAX_SIZES] = {"level", "method", "count", "texels", "bound", "build s", "bytes"};
    char hb[3 * MAX_SIZES][24];
    for (size_t k = 0; k < nsizes; k++) {
        snprintf(hb[3 * k], sizeof hb[0], "SSIM %u", sizes[k]);
        snprintf(hb[3 * k + 1], sizeof hb[0], "PSNR %u", sizes[k]);
        snprintf(hb[3 * k + 2], sizeof hb[0], "IoU %u", sizes[k]);
        for (int j = 0; j < 3; j++)
            head[7 + 3 * k + (size_t)j] = hb[3 * k + (size_t)j], t.widths[7 + 3 * k + (size_t)j] = 8;
    }
    row(&t, head);
    static const char *const reps[2] = {"dp-normalized", "billboards"};
    for (size_t l = 0; l < res->level_count; l++)
        for (int m = 0; m < 2; m++) {
            /* the level names in the order the rows hold them */
            size_t first = SIZE_MAX;
            for (size_t i = 0, seen = 0; i < res->row_count && first == SIZE_MAX; i++)
                if (strcmp(res->rows[i].representation, "dp-normalized") == 0 && res->rows[i].size == sizes[0] &&
                    seen++ == l)
                    first = i;
            if (first == SIZE_MAX)
                continue;
            const char *lname = res->rows[first].level_name;
            size_t r0 = find_row61(res, reps[m], lname, sizes[0]);
            if (r0 == SIZE_MAX)
                continue;
            const asp_eval_row *a = &res->rows[r0];
            char c[7 + 3 * MAX_SIZES][24];
            const char *cells[7 + 3 * MAX_SIZES];
            snprintf(c[0], sizeof c[0], "%s", lname);
            snprintf(c[1], sizeof c[1], "%s", m ? "billboards" : "domain");
            snprintf(c[2], sizeof c[2], "%zu", a->primitives);
            snprintf(c[3], sizeof c[3], "%lluk", (unsigned long long)((a->texels + 500) / 1000));
            if (m)
                snprintf(c[4], sizeof c[4], "%.1f%%", 100 * a->error_bound);
            else
                snprintf(c[4], sizeof c[4], "-");
            fmt_time(c[5], sizeof c[5], m ? a->build_seconds : res->t_decompose + a->build_seconds);
            snprintf(c[6], sizeof c[6], "%.2fM", (double)a->bytes / 1e6);
            for (size_t k = 0; k < nsizes; k++) {
                size_t r = find_row61(res, reps[m], lname, sizes[k]);
                const asp_eval_row *b = r == SIZE_MAX ? NULL : &res->rows[r];
                snprintf(c[7 + 3 * k], sizeof c[0], b ? "%.3f" : "-", b ? b->ssim_mean : 0.0);
                snprintf(c[8 + 3 * k], sizeof c[0], b ? "%.1f" : "-", b ? b->psnr_mean : 0.0);
                snprintf(c[9 + 3 * k], sizeof c[0], b ? "%.3f" : "-", b ? b->iou_mean : 0.0);
            }
            for (int i = 0; i < t.ncols; i++)
                cells[i] = c[i];
            row(&t, cells);
        }
    title(md, "The madcat row of thesis Table 6.1 (Decoret et al. 2003) next to this mesh at a 6% bound");
    struct table u = {.md = md, .widths = {34, 10, 7, 8, 10}, .ncols = 5};
    row(&u, (const char *const[]){"model", "triangles", "planes", "texels", "seconds"});
    row(&u, (const char *const[]){"madcat (thesis, 2003 hardware)", "59,855", "171", "1,638k", "529"});
    char c6[5][64];
    snprintf(c6[0], sizeof c6[0], "%s (this machine)", strrchr(model, '/') ? strrchr(model, '/') + 1 : model);
    snprintf(c6[1], sizeof c6[1], "%zu", mesh->triangle_count);
    snprintf(c6[2], sizeof c6[2], "%zu", st6.planes);
    snprintf(c6[3], sizeof c6[3], "%lluk", (unsigned long long)((st6.texels + 500) / 1000));
    snprintf(c6[4], sizeof c6[4], "%.2f", st6.t_search + st6.t_texture);
    row(&u, (const char *const[]){c6[0], c6[1], c6[2], c6[3], c6[4]});
    if (!env->quiet)
        printf("%stexel of the 6%% cloud: 1/512 of the diagonal; images on %s\n", md ? "\n" : "",
               res->gl_renderer);
    asp_dps_destroy(bb6);
    asp_eval_result_destroy(res);
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    return 0;
}

int cmd_bench_paper(int argc, char **argv, struct cli_env *env)
{
    const char *sizes_text = NULL, *texture = NULL;
    const char *table_name = NULL;
    size_t frames = 10, max_prims = 2000, budget = SIZE_MAX, points = 0, views = 0; // SIZE_MAX: not given
    int no_t54 = 0, markdown = 0;
    const struct cli_option opts[] = {
        {"sizes", 's', CLI_STRING, &sizes_text, "LIST", "screen sizes of the frame rates (default 128,256,512)"},
        {"frames", 0, CLI_SIZE, &frames, "N", "timed frames per figure, median (default 10)"},
        {"max-primitives", 'p', CLI_SIZE, &max_prims, "N", "Table 5.2 levels with at most N primitives (2000)"},
        {"budget", 'b', CLI_SIZE, &budget, "N", "Table 1/5.3/5.4 level: the finest with at most N (500); 6.1: levels (300)"},
        {"table", 0, CLI_STRING, &table_name, "T", "6.1: thesis Table 6.1, domain primitives against billboard clouds"},
        {"views", 0, CLI_SIZE, &views, "N", "Table 6.1: cameras around the model (default 16)"},
        {"no-texture-methods", 0, CLI_FLAG, &no_t54, NULL, "leave out Table 5.4 (12 extra builds)"},
        {"points", 'n', CLI_SIZE, &points, "N", "samples of a mesh or synthetic MODEL"},
        {"texture", 0, CLI_STRING, &texture, "IMG", "texture of a mesh MODEL without material textures"},
        {"markdown", 0, CLI_FLAG, &markdown, NULL, "print Markdown tables"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one MODEL, got %d; see 'amgsplat bench-paper -h'", npos);
    if (frames < 1 || frames > 1000)
        return cli_usage_error(env, "--frames expects 1..1000, got %zu", frames);
    if (max_prims < 1 || budget < 1)
        return cli_usage_error(env, "--max-primitives and --budget expect at least 1");
    if (table_name && strcmp(table_name, "6.1") != 0)
        return cli_usage_error(env, "--table expects 6.1 (the other tables are printed without it), got '%s'",
                               table_name);
    if (views > 256)
        return cli_usage_error(env, "--views expects 1..256, got %zu", views);
    uint32_t sizes[MAX_SIZES] = {128, 256, 512};
    size_t nsizes = table_name ? 2 : 3;
    if (sizes_text) {
        double v[MAX_SIZES];
        int k = cli_parse_doubles(sizes_text, v, MAX_SIZES);
        if (k < 1)
            return cli_usage_error(env, "--sizes expects up to %d comma-separated sides, got '%s'", MAX_SIZES,
                                   sizes_text);
        for (int i = 0; i < k; i++) {
            if (!(v[i] >= 16 && v[i] <= 4096) || v[i] != floor(v[i]))
                return cli_usage_error(env, "--sizes expects whole sides in 16..4096 pixels, got '%s'", sizes_text);
            sizes[i] = (uint32_t)v[i];
        }
        nsizes = (size_t)k;
    }
    if (table_name)
        return table61(env, argv[0], texture, points, budget == SIZE_MAX ? 300 : budget, views, sizes, nsizes,
                       markdown);
    if (budget == SIZE_MAX)
        budget = 500;
    asp_error err = {0};
    asp_cloud *cloud = NULL;
    rc = asp_eval_load_model(argv[0], points, texture, &env->ctx, &cloud, &err);
    asp_eval_paper *p = NULL;
    if (!rc) {
        asp_eval_paper_desc desc = {.sizes = sizes, .size_count = nsizes, .frames = frames,
                                    .max_primitives = max_prims, .budget = budget, .skip_texture_methods = no_t54};
        rc = asp_eval_paper_run(cloud, &desc, &env->ctx, &p, &err);
    }
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
    cli_progress_end(env);
    if (rc)
        return cli_fail(env, &err);
    int status = 0;
    if (env->json) {
        status = print_json(env, p, argv[0], !no_t54);
    } else {
        if (!env->quiet)
            printf("%s: %zu points; frame rates on %s\n", argv[0], p->points, p->gl_renderer);
        table1(p, argv[0], markdown);
        table51(p, argv[0], markdown);
        table52(p, markdown);
        table53(p, argv[0], markdown);
        if (!no_t54)
            table54(p, markdown);
    }
    asp_eval_paper_destroy(p);
    return status;
}
