/*
 * amgsplat eval: quality against primitive count (thesis Fig. 1.1, journal
 * section 6's image difference metric): every representation rendered from
 * the same cameras as the reference, compared by PSNR, SSIM and silhouette
 * IoU, timed, and written as CSV, JSON, charts and a contact sheet.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amgsplat/instances.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat eval MODEL [-o DIR] [--views 16] [--sizes 128,256] [--max-primitives 1000]\n"
    "                     [--methods normalized,prefix,overlap,two-pass | all | none] [--frames 5]\n"
    "                     [--points N] [--texture IMG] [--elevation 20] [--crease-angle DEG|off]\n"
    "\n"
    "Renders the reference (the full point set as blended, normalised splats at tolerance 0) and,\n"
    "from the same cameras, every representation: the domain primitives of every AMG level with at\n"
    "most --max-primitives primitives, drawn with each rendering method, and the point hierarchy\n"
    "cut to the same number of splats as the level has primitives. For each: primitives, texels,\n"
    "PSNR, SSIM and silhouette IoU (mean and worst view) and the median frame time. MODEL is a\n"
    "point file (.ply .xyz .pts .txt), a synthetic shape (octahedron, cube, sphere, torus,\n"
    "checker-plane) or a mesh (sampled to --points points, default 100000).\n"
    "Given a mesh, the reference is the mesh's own render instead (the true surface), the full point set\n"
    "is measured as discs and as splats, and every level gains the mesh simplified to the level's\n"
    "primitive count in triangles (mesh-tris) and to its GPU bytes (mesh-bytes). 512 x 512 views take\n"
    "about four times as long as 256 x 256 on a CPU rasteriser: ask for them with --sizes. Writes into DIR\n"
    "(default eval-<model name>): eval.csv, eval.json, ssim-<size>.png, frametime-<size>.png and\n"
    "sheet.png (view 0: one row per representation, the reference first, then the levels).\n"
    "--methods may also name 'hybrid' and 'billboards': the latter adds per level a billboard cloud\n"
    "(simplify --billboards) of the mesh, or of the points as discs, at the level's texel count with the\n"
    "error bound whose plane count is nearest the level's primitive count.\n"
    "Sharp creases: the reference's splats and the primitives are clipped where flat parts meet at\n"
    "more than --crease-angle degrees (default 60; 'off' compares the seeds' unclipped renders).\n"
    "A scene file of instances (docs/scene-format.md) is measured as a whole from its camera: the\n"
    "reference is every point of every instance as blended splats at tolerance 0; discs, splats at\n"
    "--tolerances (default 1,2,4,8) and squares are compared with it (PSNR, SSIM, IoU, median frame\n"
    "time of --frames, default 3, at the first of --sizes, default 256) into DIR/eval.json and sheet.png.";

enum { MAX_SIZES = 8, MAX_METHODS = 16 };

/* The renderer options eval takes (renderer_options.c): the rest it sets itself, per representation. */
#define EVAL_OPTIONS (CLI_RO_CREASE | CLI_RO_TEXTURE)

static int parse_sizes(struct cli_env *env, const char *text, uint32_t *sizes, size_t *n)
{
    double v[MAX_SIZES];
    int k = cli_parse_doubles(text, v, MAX_SIZES);
    if (k < 1)
        return cli_usage_error(env, "--sizes expects up to %d comma-separated sides, e.g. 128,256, got '%s'",
                               MAX_SIZES, text);
    for (int i = 0; i < k; i++) {
        if (!(v[i] >= 16 && v[i] <= 2048) || v[i] != floor(v[i]))
            return cli_usage_error(env, "--sizes expects whole sides in 16..2048 pixels, got '%s'", text);
        sizes[i] = (uint32_t)v[i];
    }
    *n = (size_t)k;
    return 0;
}

static int parse_methods(struct cli_env *env, const char *text, asp_prim_render_method *m, size_t *n, int *hybrid,
                         int *billboards)
{
    *n = 0;
    if (strcmp(text, "none") == 0)
        return 0;
    if (strcmp(text, "all") == 0) {
        for (int i = 0; asp_prim_render_method_name((asp_prim_render_method)i) && *n < MAX_METHODS; i++)
            m[(*n)++] = (asp_prim_render_method)i;
        return 0;
    }
    char buf[512];
    if (strlen(text) >= sizeof buf)
        return cli_usage_error(env, "--methods list is too long");
    snprintf(buf, sizeof buf, "%s", text);
    for (char *item = buf; item;) {
        char *comma = strchr(item, ',');
        if (comma)
            *comma = 0;
        asp_error err = {0};
        if (strcmp(item, "hybrid") == 0) { // issue 18 item 3: not a primitive method but a row of its own
            *hybrid = 1;
            item = comma ? comma + 1 : NULL;
            continue;
        }
        if (strcmp(item, "billboards") == 0) { // issue 30: a billboard cloud matched to each level, a row of its own
            *billboards = 1;
            item = comma ? comma + 1 : NULL;
            continue;
        }
        if (*n >= MAX_METHODS || asp_prim_render_method_parse(item, &m[*n], &err))
            return cli_usage_error(env, "--methods: %s", *n >= MAX_METHODS ? "too many methods" : err.msg);
        (*n)++;
        item = comma ? comma + 1 : NULL;
    }
    return 0;
}

/* "data/bunny.obj" -> "eval-bunny" */
static void default_dir(const char *model, char *out, size_t cap)
{
    const char *base = strrchr(model, '/');
    base = base ? base + 1 : model;
    const char *dot = strrchr(base, '.');
    int len = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, cap, "eval-%.*s", len, base);
}

static void print_table(const asp_eval_result *res)
{
    printf("%-16s %-6s %5s %10s %9s %9s %8s %7s %7s %7s %7s %9s %10s\n", "representation", "level", "size",
           "primitives", "drawn", "texels", "PSNR", "SSIM", "worst", "IoU", "worst", "frame ms", "bytes");
    for (size_t i = 0; i < res->row_count; i++) {
        const asp_eval_row *r = &res->rows[i];
        if (r->note[0]) {
            printf("%-16s %-6s %5u %10zu  (%s)\n", r->representation, r->level_name, r->size, r->primitives, r->note);
            continue;
        }
        printf("%-16s %-6s %5u %10zu %9.1f %9llu %8.2f %7.4f %7.4f %7.4f %7.4f %9.3f %10llu\n", r->representation,
               r->level_name, r->size, r->primitives, r->drawn, (unsigned long long)r->texels, r->psnr_mean,
               r->ssim_mean, r->ssim_min, r->iou_mean, r->iou_min, r->frame_ms, (unsigned long long)r->bytes);
    }
}

/* The row of representation rep at the size and level of row at, or SIZE_MAX; rows without figures do not count. */
static size_t find_row(const asp_eval_result *res, const asp_eval_row *at, const char *rep)
{
    for (size_t j = 0; j < res->row_count; j++) {
        const asp_eval_row *r = &res->rows[j];
        if (r->size == at->size && r->level == at->level && strcmp(r->representation, rep) == 0 && !r->note[0])
            return j;
    }
    return SIZE_MAX;
}

/*
 * Thesis Fig. 1.1's claim per size and level: the best domain-primitive
 * method (highest mean SSIM) against the point cut to the same count, and in
 * how many views it wins; with a mesh also against the mesh simplified to the
 * same count and to the same bytes (issue 14); as text lines or JSON objects.
 */
/* 1 when rows[i] is a point cut with a domain-primitive row at its size and level: the best in *best, the mesh rows. */
static int claim_row(const asp_eval_result *res, size_t i, size_t *best, size_t *mt, size_t *mb)
{
    const asp_eval_row *pt = &res->rows[i];
    if (strcmp(pt->representation, "points") != 0)
        return 0;
    *best = SIZE_MAX;
    for (size_t j = 0; j < res->row_count; j++) {
        const asp_eval_row *r = &res->rows[j];
        if (r->size == pt->size && r->level == pt->level && strncmp(r->representation, "dp-", 3) == 0 &&
            (*best == SIZE_MAX || r->ssim_mean > res->rows[*best].ssim_mean))
            *best = j;
    }
    int mesh = res->mesh_triangles > 0;
    *mt = mesh ? find_row(res, pt, "mesh-tris") : SIZE_MAX;
    *mb = mesh ? find_row(res, pt, "mesh-bytes") : SIZE_MAX;
    return *best != SIZE_MAX;
}

static cJSON *claim_json(const asp_eval_result *res)
{
    cJSON *a = cJSON_CreateArray();
    for (size_t i = 0; i < res->row_count; i++) {
        size_t best, mt, mb;
        if (!claim_row(res, i, &best, &mt, &mb))
            continue;
        const asp_eval_row *pt = &res->rows[i], *b = &res->rows[best];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "size", pt->size);
        cJSON_AddStringToObject(o, "level_name", pt->level_name);
        cJSON_AddNumberToObject(o, "primitives", (double)pt->primitives);
        cJSON_AddStringToObject(o, "best", b->representation);
        cJSON_AddItemToObject(o, "best_ssim", cli_json_number("%.6f", b->ssim_mean));
        cJSON_AddItemToObject(o, "points_ssim", cli_json_number("%.6f", pt->ssim_mean));
        cJSON_AddNumberToObject(o, "wins", (double)asp_eval_ssim_wins(res, best, i));
        cJSON_AddNumberToObject(o, "views", (double)res->views);
        if (mt != SIZE_MAX) {
            cJSON_AddItemToObject(o, "mesh_tris_ssim", cli_json_number("%.6f", res->rows[mt].ssim_mean));
            cJSON_AddNumberToObject(o, "wins_mesh_tris", (double)asp_eval_ssim_wins(res, best, mt));
        }
        if (mb != SIZE_MAX) {
            cJSON_AddItemToObject(o, "mesh_bytes_ssim", cli_json_number("%.6f", res->rows[mb].ssim_mean));
            cJSON_AddNumberToObject(o, "wins_mesh_bytes", (double)asp_eval_ssim_wins(res, best, mb));
        }
        size_t hy = find_row(res, pt, "hybrid");
        if (hy != SIZE_MAX) { // issue 18: the hybrid against the best pure-primitive method
            cJSON_AddItemToObject(o, "hybrid_ssim", cli_json_number("%.6f", res->rows[hy].ssim_mean));
            cJSON_AddNumberToObject(o, "hybrid_wins", (double)asp_eval_ssim_wins(res, hy, best));
        }
        cJSON_AddItemToArray(a, o);
    }
    return a;
}

static void print_claim(const asp_eval_result *res, FILE *fp)
{
    int first = 1, mesh = res->mesh_triangles > 0;
    for (size_t i = 0; i < res->row_count; i++) {
        size_t best, mt, mb;
        if (!claim_row(res, i, &best, &mt, &mb))
            continue;
        const asp_eval_row *pt = &res->rows[i], *b = &res->rows[best];
        size_t wins = asp_eval_ssim_wins(res, best, i);
        if (first)
            fprintf(fp, "\nbest domain-primitive method against the point cut (thesis Fig. 1.1)%s:\n"
                        "%5s %-6s %10s %-18s %9s %9s %9s%s\n",
                    mesh ? " and the simplified mesh at equal triangles and equal bytes" : "", "size", "level",
                    "primitives", "best method", "SSIM", "points", "wins",
                    mesh ? "  mesh-tris      wins mesh-bytes      wins" : "");
        fprintf(fp, "%5u %-6s %10zu %-18s %9.4f %9.4f %5zu/%zu", pt->size, pt->level_name, pt->primitives,
                b->representation, b->ssim_mean, pt->ssim_mean, wins, res->views);
        const size_t other[2] = {mt, mb};
        for (int k = 0; k < 2 && mesh; k++) {
            if (other[k] == SIZE_MAX)
                fprintf(fp, " %10s %9s", "-", "-");
            else
                fprintf(fp, " %10.4f %5zu/%zu", res->rows[other[k]].ssim_mean,
                        asp_eval_ssim_wins(res, best, other[k]), res->views);
        }
        size_t hy = find_row(res, pt, "hybrid");
        if (hy != SIZE_MAX)
            fprintf(fp, "  hybrid %.4f wins %zu/%zu", res->rows[hy].ssim_mean, asp_eval_ssim_wins(res, hy, best),
                    res->views);
        fputc('\n', fp);
        first = 0;
    }
}

static int save_outputs(const asp_eval_result *res, const char *model, const char *dir, const uint32_t *sizes,
                        size_t nsizes, asp_error *err)
{
    char path[4200]; // dir is shorter than 4000 bytes (cmd_eval)
    snprintf(path, sizeof path, "%s/eval.csv", dir);
    int rc = asp_eval_save_csv(res, path, err);
    snprintf(path, sizeof path, "%s/eval.json", dir);
    if (!rc)
        rc = asp_eval_save_json(res, model, path, err);
    for (size_t i = 0; i < nsizes && !rc; i++)
        for (int which = 0; which < 2 && !rc; which++) {
            asp_image chart = {0};
            snprintf(path, sizeof path, "%s/%s-%u.png", dir, which ? "frametime" : "ssim", sizes[i]);
            rc = asp_eval_chart(res, sizes[i], which, &chart, err);
            if (!rc)
                rc = asp_image_save_png(&chart, path, err);
            asp_image_release(&chart);
        }
    snprintf(path, sizeof path, "%s/sheet.png", dir);
    if (!rc && res->sheet.width)
        rc = asp_image_save_png(&res->sheet, path, err);
    return rc;
}

/*
 * A failed run leaves no directory it created (issue #13): everything in it
 * is this run's output, so its plain files go, then the directory.
 */
static void remove_directory(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char path[4096 + 256];
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            remove(path);
        }
        closedir(d);
    }
    rmdir(dir);
}

static int parse_tolerances(struct cli_env *env, const char *text, float *tau, size_t *n)
{
    double v[32];
    int k = cli_parse_doubles(text, v, 32);
    if (k < 1)
        return cli_usage_error(env, "--tolerances expects up to 32 comma-separated pixels, e.g. 1,2,4, got '%s'", text);
    for (int i = 0; i < k; i++) {
        if (!(v[i] >= 0 && v[i] <= 1e4))
            return cli_usage_error(env, "--tolerances expects pixels in 0..1e4, got '%s'", text);
        tau[i] = (float)v[i];
    }
    *n = (size_t)k;
    return 0;
}

static void print_scene_table(const asp_instance_eval_result *res)
{
    printf("%-9s %9s %11s %9s %8s %7s %7s %9s\n", "renderer", "tolerance", "primitives", "instances", "PSNR", "SSIM",
           "IoU", "frame ms");
    for (size_t i = 0; i < res->row_count; i++) {
        const asp_instance_eval_row *r = &res->rows[i];
        printf("%-9s %9g %11zu %9zu %8.2f %7.4f %7.4f %9.1f%s\n", r->renderer, (double)r->tolerance, r->primitives,
               r->instances_drawn, r->psnr, r->ssim, r->iou, r->frame_ms, i == 0 ? "  (reference)" : "");
    }
}

/* A scene of instances (instances.h): the whole scene at full detail against coarser cuts and renderers. */
static int eval_instance_scene(const char *path, const char *dir, uint32_t size, size_t frames,
                               const char *tolerances, struct cli_env *env)
{
    float tau[32];
    size_t ntau = 0;
    if (tolerances && parse_tolerances(env, tolerances, tau, &ntau))
        return 2;
    asp_error err = {0};
    asp_instance_scene s;
    int rc = asp_instance_scene_load(path, NULL, &env->ctx, &s, &err);
    if (rc)
        return cli_fail(env, &err);
    int created = mkdir(dir, 0777) == 0;
    if (!created && errno != EEXIST) {
        asp_instance_scene_release(&s);
        asp_error_set(&err, ASP_EIO, "cannot create directory '%s': %s", dir, strerror(errno));
        return cli_fail(env, &err);
    }
    double t0 = asp_time_now();
    asp_instance_eval_result *res = NULL;
    asp_instance_eval_desc d = {.width = size, .height = size, .frames = frames,
                                .tolerances = tolerances ? tau : NULL, .tolerance_count = ntau};
    rc = asp_instance_scene_eval(&s, &d, &env->ctx, &res, &err);
    asp_image sheet = {0, 0, NULL};
    asp_image *tiles = NULL;
    if (!rc) {
        tiles = calloc(res->row_count, sizeof *tiles);
        if (!tiles)
            rc = asp_error_set(&err, ASP_ENOMEM, "out of memory");
        for (size_t i = 0; tiles && i < res->row_count; i++)
            tiles[i] = res->rows[i].image; // borrowed for the sheet
    }
    char json_path[4200], sheet_path[4200];
    snprintf(json_path, sizeof json_path, "%s/eval.json", dir);
    snprintf(sheet_path, sizeof sheet_path, "%s/sheet.png", dir);
    // one row of tiles, each headed by what it is and how it measured (issue 29: a sheet says what it shows)
    asp_image grid = {0, 0, NULL};
    char(*text)[128] = !rc ? calloc(res->row_count, sizeof *text) : NULL;
    const char **labels = !rc ? calloc(res->row_count, sizeof *labels) : NULL;
    if (!rc && (!text || !labels))
        rc = asp_error_set(&err, ASP_ENOMEM, "out of memory");
    for (size_t i = 0; !rc && i < res->row_count; i++) {
        const asp_instance_eval_row *r = &res->rows[i];
        if (i == 0)
            snprintf(text[i], sizeof text[i], "reference\nsplat, tau 0\n%zu splats", r->primitives);
        else if (strcmp(r->renderer, "disc") == 0)
            snprintf(text[i], sizeof text[i], "disc, every point\nSSIM %.3f\n%zu discs", r->ssim, r->primitives);
        else
            snprintf(text[i], sizeof text[i], "%s, tau %g px\nSSIM %.3f\n%zu %ss", r->renderer, (double)r->tolerance,
                     r->ssim, r->primitives, r->renderer);
        labels[i] = text[i];
    }
    if (!rc)
        rc = asp_image_contact_sheet(tiles, res->row_count, (uint32_t)res->row_count, &grid, &err);
    char title[160];
    snprintf(title, sizeof title, "%zu instances from the scene's camera at %ux%u", s.instance_count, size, size);
    if (!rc)
        rc = asp_chart_label_sheet(&grid,
                                   &(asp_chart_sheet_desc){.title = title, .row_count = 1,
                                                           .col_count = res->row_count, .col_labels = labels},
                                   &sheet, &err);
    asp_image_release(&grid);
    free(text);
    free(labels);
    if (!rc) { // the report's files appear all or none (issue #13)
        asp_output_batch_begin(NULL);
        rc = asp_instance_eval_save_json(res, path, json_path, &err);
        if (!rc)
            rc = asp_image_save_png(&sheet, sheet_path, &err);
        if (rc)
            asp_output_batch_abort();
        else
            rc = asp_output_batch_commit(&err);
    }
    int status = 0;
    if (rc) {
        if (created)
            remove_directory(dir);
        status = cli_fail(env, &err);
    } else {
        cli_progress_end(env);
        if (env->json) {
            cJSON *o = cJSON_CreateObject(), *rows = cJSON_CreateArray();
            cJSON_AddStringToObject(o, "scene", path);
            cJSON_AddStringToObject(o, "output", dir);
            cJSON_AddNumberToObject(o, "instances", (double)s.instance_count);
            for (size_t i = 0; i < res->row_count; i++) {
                const asp_instance_eval_row *r = &res->rows[i];
                cJSON *row = cJSON_CreateObject();
                cJSON_AddStringToObject(row, "renderer", r->renderer);
                cJSON_AddNumberToObject(row, "tolerance", r->tolerance);
                cJSON_AddNumberToObject(row, "primitives", (double)r->primitives);
                cJSON_AddNumberToObject(row, "instances_drawn", (double)r->instances_drawn);
                cJSON_AddItemToObject(row, "psnr", isfinite(r->psnr) ? cJSON_CreateNumber(r->psnr) : cJSON_CreateNull());
                cJSON_AddItemToObject(row, "ssim", cli_json_number("%.6f", r->ssim));
                cJSON_AddItemToObject(row, "iou", cli_json_number("%.6f", r->iou));
                cJSON_AddItemToObject(row, "frame_ms", cli_json_number("%.3f", r->frame_ms));
                cJSON_AddItemToArray(rows, row);
            }
            cJSON_AddItemToObject(o, "rows", rows);
            cJSON_AddItemToObject(o, "seconds", cli_json_number("%.3f", asp_time_now() - t0));
            status = cli_json_print(env, o);
        } else if (!env->quiet) {
            printf("scene '%s': %zu instances of %zu sources, %ux%u, %s\n", path, s.instance_count, s.source_count,
                   size, size, res->gl_renderer);
            print_scene_table(res);
            printf("wrote %s and %s\n", json_path, sheet_path);
        }
    }
    free(tiles);
    asp_image_release(&sheet);
    asp_instance_eval_result_destroy(res);
    asp_instance_scene_release(&s);
    return status;
}

int cmd_eval(int argc, char **argv, struct cli_env *env)
{
    const char *out_dir = NULL, *sizes_text = NULL, *methods_text = NULL, *tolerances = NULL;
    struct cli_renderer_opts r; // --crease-angle, --texture: shared with render and view (renderer_options.c)
    cli_renderer_opts_init(&r);
    size_t views = 16, max_prims = 1000, frames = 5, points = 0;
    double elevation = 20;
    struct cli_option opts[24] = {
        {"output", 'o', CLI_STRING, &out_dir, "DIR", "output directory (default eval-<model name>)"},
        {"views", 0, CLI_SIZE, &views, "N", "cameras around the model (default 16)"},
        {"sizes", 's', CLI_STRING, &sizes_text, "LIST", "square image sides, e.g. 128,256,512 (default 128,256)"},
        {"max-primitives", 'p', CLI_SIZE, &max_prims, "N", "evaluate levels with at most N primitives (1000)"},
        {"methods", 'm', CLI_STRING, &methods_text, "LIST",
         "domain-primitive methods, 'all' or 'none' (default normalized,prefix,overlap,two-pass)"},
        {"frames", 0, CLI_SIZE, &frames, "N", "timed frames per figure, median (default 5)"},
        {"points", 'n', CLI_SIZE, &points, "N", "samples of a mesh or synthetic MODEL"},
        {"elevation", 0, CLI_DOUBLE, &elevation, "DEG", "views alternate +DEG and -DEG (default 20)"},
        {"tolerances", 0, CLI_STRING, &tolerances, "LIST", "scene files: splat tolerances in pixels (default 1,2,4,8)"},
        {0},
    };
    cli_renderer_rows(&r, EVAL_OPTIONS, opts, sizeof opts / sizeof opts[0]);
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one MODEL, got %d; see 'amgsplat eval -h'", npos);
    if (cli_renderer_check(env, &r, EVAL_OPTIONS))
        return 2;
    if (views < 1 || views > 256)
        return cli_usage_error(env, "--views expects 1..256, got %zu", views);
    if (frames < 1 || frames > 1000)
        return cli_usage_error(env, "--frames expects 1..1000, got %zu", frames);
    if (max_prims < 1)
        return cli_usage_error(env, "--max-primitives expects at least 1");
    if (!(elevation >= -90 && elevation <= 90) || elevation == 0)
        return cli_usage_error(env, "--elevation expects degrees in -90..90, not 0, got %g", elevation);
    // the reference's splats clip too, and a point clip plane needs an angle below 90 degrees
    double crease = r.crease;
    if (!(crease < 90))
        return cli_usage_error(env, "--crease-angle expects degrees in (0, 90) or 'off', got '%s'", r.crease_angle);
    uint32_t sizes[MAX_SIZES] = {128, 256};
    size_t nsizes = 2;
    if (sizes_text && parse_sizes(env, sizes_text, sizes, &nsizes))
        return 2;
    asp_prim_render_method methods[MAX_METHODS];
    size_t nmethods = 0;
    int hybrid = 0, billboards = 0;
    if (methods_text && parse_methods(env, methods_text, methods, &nmethods, &hybrid, &billboards))
        return 2;
    char dir[4000];
    if (out_dir && strlen(out_dir) >= sizeof dir)
        return cli_usage_error(env, "-o: directory name is too long");
    if (out_dir)
        snprintf(dir, sizeof dir, "%s", out_dir);
    else
        default_dir(argv[0], dir, sizeof dir);
    asp_file_type type = {ASP_FILE_UNKNOWN, "", 0};
    if (asp_file_recognise(argv[0], &type, NULL) == 0 && type.kind == ASP_FILE_SCENE)
        return eval_instance_scene(argv[0], dir, sizes_text ? sizes[0] : 256, frames == 5 ? 3 : frames, tolerances,
                                   env);
    if (tolerances)
        return cli_usage_error(env, "--tolerances is for scene files (amgsplat scene field makes one)");

    asp_error err = {0};
    asp_cloud *cloud = NULL;
    asp_mesh *mesh = NULL;
    rc = asp_eval_load_model_mesh(argv[0], points, r.texture, &env->ctx, &cloud, &mesh, &err);
    if (rc)
        return cli_fail(env, &err);
    int created = mkdir(dir, 0777) == 0;
    if (!created && errno != EEXIST) {
        asp_cloud_destroy(cloud);
        asp_mesh_destroy(mesh);
        asp_error_set(&err, ASP_EIO, "cannot create directory '%s': %s", dir, strerror(errno));
        return cli_fail(env, &err);
    }
    asp_eval_desc desc = {.views = views, .sizes = sizes, .size_count = nsizes, .max_primitives = max_prims,
                          .frames = frames, .elevation = (float)elevation, .crease_angle = (float)crease,
                          .methods = methods_text ? methods : NULL, .method_count = nmethods, .mesh = mesh,
                          .hybrid = hybrid, .billboards = billboards};
    double t0 = asp_time_now();
    asp_eval_result *res = NULL;
    rc = asp_eval_run(cloud, &desc, &env->ctx, &res, &err);
    if (!rc) { // the report's files appear all or none (issue #13): a failed chart keeps the old report whole
        asp_output_batch_begin(NULL);
        rc = save_outputs(res, argv[0], dir, sizes, nsizes, &err);
        if (rc)
            asp_output_batch_abort();
        else
            rc = asp_output_batch_commit(&err);
    }
    double seconds = asp_time_now() - t0;
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    asp_amg_shutdown();
    cli_progress_end(env);
    if (rc) {
        asp_eval_result_destroy(res);
        if (created)
            remove_directory(dir);
        return cli_fail(env, &err);
    }
    int status = 0;
    if (env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "model", argv[0]);
        cJSON_AddStringToObject(o, "output", dir);
        cJSON_AddNumberToObject(o, "points", (double)res->points);
        cJSON_AddNumberToObject(o, "mesh_triangles", (double)res->mesh_triangles);
        cJSON_AddNumberToObject(o, "views", (double)res->views);
        cJSON_AddNumberToObject(o, "rows", (double)res->row_count);
        cJSON_AddItemToObject(o, "seconds", cli_json_number("%.2f", seconds));
        cJSON_AddStringToObject(o, "gl_renderer", res->gl_renderer);
        cJSON_AddItemToObject(o, "claim", claim_json(res));
        status = cli_json_print(env, o);
    } else {
        if (!env->quiet)
            printf("%s: %zu points%s, %zu levels, %zu views, %s; decomposition %.2f s, primitives %.2f s, "
                   "simplification %.2f s, rendering %.2f s; written to %s/\n",
                   argv[0], res->points, res->mesh_triangles ? " sampled from the mesh (the reference)" : "",
                   res->level_count, res->views, res->gl_renderer, res->t_decompose, res->t_build, res->t_simplify,
                   res->t_render, dir);
        print_table(res);
        print_claim(res, stdout);
    }
    asp_eval_result_destroy(res);
    return status;
}
