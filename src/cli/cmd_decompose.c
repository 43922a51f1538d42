/*
 * amgsplat decompose: multiscale AMG decomposition of a point set into
 * quasi-flat domains (Reniers & Telea 2006, section 2; thesis chapter 2).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat decompose IN.ply -o OUT.amg [--preset thesis|journal] [--k N] [--k-max N] [--epsilon X]\n"
    "                          [--fan-k N] [--stiffness clamped|unclamped]\n"
    "                          [--classifier variation|moment] [--alpha X] [--beta X]\n"
    "                          [--coarsen rs|falgout|cljp|pmis|hmis] [--interp classical|direct|standard|ext+i]\n"
    "                          [--strong X] [--trunc X] [--max-levels N] [--max-coarse N] [--crease-cut X]\n"
    "                          [--weak-cut X]\n"
    "                          [--drop X] [--stats] [--tau X] [--critical-k] [--json] [--distributed]\n"
    "                          [--mesh-stiffness (MESH input)]\n"
    "                          [--export-colors classifier|domains|strict --level L-3 --colors-out X.ply]\n"
    "       amgsplat decompose IN.amg --stats | --export-colors ...\n"
    "       mpirun -np P amgsplat decompose IN.ply -o OUT.amg [options] (docs/mpi.md)\n"
    "\n"
    "Classifies every point's neighbourhood (surface variation or the journal's moment\n"
    "classifier), builds a stiffness matrix on local Delaunay fans and coarsens it with\n"
    "hypre BoomerAMG into levels of basis functions (a partition of unity) whose domains\n"
    "stop at creases (a coarse coupling across a crease is cut, so flat faces never merge).\n"
    "Level names: L is the coarsest, L-5 five levels finer, or an index.\n"
    "--stats prints per level: unknowns, domains (Psi > tau), mean and max domain size,\n"
    "mean domains per point and time. An existing .amg file can be inspected or coloured.";

struct name_code {
    const char *name;
    int code;
};

static const struct name_code classifiers[] = {
    {"variation", ASP_AMG_CLASSIFIER_VARIATION}, {"moment", ASP_AMG_CLASSIFIER_MOMENT}, {0, 0}};
static const struct name_code coarsenings[] = {{"rs", ASP_AMG_COARSEN_RS},     {"falgout", ASP_AMG_COARSEN_FALGOUT},
                                               {"cljp", ASP_AMG_COARSEN_CLJP}, {"pmis", ASP_AMG_COARSEN_PMIS},
                                               {"hmis", ASP_AMG_COARSEN_HMIS}, {0, 0}};
static const struct name_code interps[] = {{"classical", ASP_AMG_INTERP_CLASSICAL},
                                           {"direct", ASP_AMG_INTERP_DIRECT},
                                           {"standard", ASP_AMG_INTERP_STANDARD},
                                           {"ext+i", ASP_AMG_INTERP_EXTENDED_I},
                                           {0, 0}};
static const struct name_code stiffness_forms[] = {
    {"clamped", ASP_AMG_STIFFNESS_CLAMPED}, {"unclamped", ASP_AMG_STIFFNESS_UNCLAMPED}, {0, 0}};
static const struct name_code color_modes[] = {
    {"classifier", ASP_AMG_COLOR_CLASSIFIER}, {"domains", ASP_AMG_COLOR_DOMAINS}, {"strict", ASP_AMG_COLOR_STRICT}, {0, 0}};

static int lookup(const struct name_code *t, const char *name, int *out)
{
    for (; t->name; t++)
        if (strcmp(t->name, name) == 0) {
            *out = t->code;
            return 0;
        }
    return -1;
}

/* The figures of asp_amg_info, as the serial and the distributed run report them alike. */
static void add_amg_info(cJSON *o, const asp_amg_info *in)
{
    cJSON_AddItemToObject(o, "epsilon", cli_json_number("%.9g", in->epsilon));
    cJSON_AddNumberToObject(o, "k_min", (double)in->k_min);
    cJSON_AddNumberToObject(o, "k_max", (double)in->k_max);
    cJSON_AddNumberToObject(o, "fan_k", (double)in->fan_k);
    cJSON_AddItemToObject(o, "mean_neighbourhood", cli_json_number("%.4g", in->mean_neighbourhood));
    cJSON_AddItemToObject(o, "mean_fan", cli_json_number("%.4g", in->mean_fan));
    cJSON_AddNumberToObject(o, "matrix_nnz", (double)in->matrix_nnz);
    cJSON_AddNumberToObject(o, "positive_offdiag_clamped", (double)in->positive_offdiag);
    cJSON_AddNumberToObject(o, "isolated_points", (double)in->isolated_points);
    cJSON_AddNumberToObject(o, "repaired_rows", (double)in->repaired_rows);
}

/* The stage times of asp_amg_info into decompose --json's "seconds". */
static void add_stage_seconds(cJSON *sec, const asp_amg_info *in)
{
    cJSON_AddItemToObject(sec, "neighbours", cli_json_number("%.4f", in->t_neighbours));
    cJSON_AddItemToObject(sec, "classifier", cli_json_number("%.4f", in->t_classifier));
    cJSON_AddItemToObject(sec, "fans", cli_json_number("%.4f", in->t_fans));
    cJSON_AddItemToObject(sec, "assembly", cli_json_number("%.4f", in->t_assembly));
    cJSON_AddItemToObject(sec, "amg", cli_json_number("%.4f", in->t_amg));
}

static void add_info_json(cJSON *o, const asp_amg *amg)
{
    const asp_amg_info *in = asp_amg_get_info(amg);
    cJSON *sizes = cJSON_CreateArray(), *sec = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "points", (double)asp_amg_cloud(amg)->count);
    cJSON_AddNumberToObject(o, "levels", (double)asp_amg_level_count(amg));
    for (size_t l = 0; l < asp_amg_level_count(amg); l++)
        cJSON_AddItemToArray(sizes, cJSON_CreateNumber((double)asp_amg_level_size(amg, l)));
    cJSON_AddItemToObject(o, "level_sizes", sizes);
    add_amg_info(o, in);
    add_stage_seconds(sec, in);
    cJSON_AddItemToObject(o, "seconds", sec);
}

/* The per-level statistics: into json (tau, level_stats) when it is given, else as a table on stdout. */
static int print_stats(struct cli_env *env, const asp_amg *amg, double tau, cJSON *json, asp_error *err)
{
    size_t nl = asp_amg_level_count(amg);
    asp_amg_level_stats *st = asp_calloc(&env->ctx, nl, sizeof *st);
    if (!st)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the level statistics");
    int rc = asp_amg_level_stats_all(amg, tau, &env->ctx, st, err);
    cli_progress_end(env);
    if (!rc && json) {
        cJSON *levels = cJSON_CreateArray();
        cJSON_AddItemToObject(json, "tau", cli_json_number("%g", tau));
        for (size_t l = 0; l < nl; l++) {
            char name[32];
            snprintf(name, sizeof name, "L-%zu", nl - 1 - l);
            cJSON *j = cJSON_CreateObject();
            cJSON_AddNumberToObject(j, "level", (double)l);
            cJSON_AddStringToObject(j, "name", name);
            cJSON_AddNumberToObject(j, "unknowns", (double)st[l].unknowns);
            cJSON_AddNumberToObject(j, "domains", (double)st[l].domains);
            cJSON_AddItemToObject(j, "mean_domain_size", cli_json_number("%.6g", st[l].mean_domain_size));
            cJSON_AddNumberToObject(j, "max_domain_size", (double)st[l].max_domain_size);
            cJSON_AddItemToObject(j, "mean_domains_per_point", cli_json_number("%.6g", st[l].mean_domains_per_point));
            cJSON_AddItemToObject(j, "reduction",
                                  cli_json_number("%.4g", l ? (double)st[l - 1].unknowns / (double)st[l].unknowns : 1.0));
            cJSON_AddItemToObject(j, "max_pou_error", cli_json_number("%.3g", st[l].max_pou_error));
            cJSON_AddItemToObject(j, "seconds", cli_json_number("%.4f", st[l].seconds));
            cJSON_AddItemToArray(levels, j);
        }
        cJSON_AddItemToObject(json, "level_stats", levels);
    } else if (!rc) {
        printf("level  name   unknowns  reduction   domains  mean size   max size  domains/pt   seconds\n");
        for (size_t l = 0; l < nl; l++) {
            char name[32];
            snprintf(name, sizeof name, "L-%zu", nl - 1 - l);
            printf("%5zu  %-5s %9zu  %9.2f %9zu  %9.1f  %9zu  %10.2f  %8.3f\n", l, l == nl - 1 ? "L" : name,
                   st[l].unknowns, l ? (double)st[l - 1].unknowns / (double)st[l].unknowns : 1.0, st[l].domains,
                   st[l].mean_domain_size, st[l].max_domain_size, st[l].mean_domains_per_point, st[l].seconds);
        }
    }
    asp_free(&env->ctx, st);
    return rc;
}

static int export_colors(struct cli_env *env, const asp_amg *amg, int mode, const char *level_name, const char *out,
                         asp_error *err)
{
    size_t level = 0;
    if (mode != ASP_AMG_COLOR_CLASSIFIER) {
        int rc = asp_amg_level_parse(amg, level_name, &level, err);
        if (rc)
            return rc;
    }
    asp_cloud *c = NULL;
    int rc = asp_cloud_clone(asp_amg_cloud(amg), &c, err);
    if (!rc)
        rc = asp_cloud_add_attrs(c, ASP_ATTR_COLORS, err);
    if (!rc)
        rc = asp_amg_colorize(amg, (asp_amg_color_mode)mode, level, &env->ctx, c->colors, err);
    if (!rc)
        rc = asp_cloud_save(c, out, NULL, err);
    asp_cloud_destroy(c);
    return rc;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* --critical-k: the distribution of the per-point critical size, a guide for --k (thesis 2.3) */
static int print_critical(struct cli_env *env, const asp_cloud *cloud, asp_error *err)
{
    const asp_critical_desc cd = {0};
    uint32_t *k = asp_calloc(&env->ctx, cloud->count, sizeof *k);
    if (!k)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu critical sizes", cloud->count);
    int rc = asp_critical_neighbourhood(cloud->positions, cloud->count, &cd, &env->ctx, k, err);
    cli_progress_end(env);
    if (!rc) {
        qsort(k, cloud->count, sizeof *k, cmp_u32);
        size_t n = cloud->count, jumped = 0;
        for (size_t i = 0; i < n; i++)
            jumped += k[i] < 96;
        // stderr with --json: stdout holds the one JSON document
        fprintf(env->json ? stderr : stdout,
                "critical neighbourhood size (thesis 2.3, k 8..96 step 4): 10%% %u, median %u, 90%% %u; "
                "%.1f%% of the points see a jump in the surface variation\n",
                k[n / 10], k[n / 2], k[n - 1 - n / 10], 100.0 * (double)jumped / (double)n);
    }
    asp_free(&env->ctx, k);
    return rc;
}

/* --mesh-stiffness: the mesh and its vertices as the point set, index for index (journal eq. 4) */
static int load_mesh_vertices(struct cli_env *env, const char *path, asp_mesh **mesh, asp_cloud **cloud,
                              asp_error *err)
{
    int rc = asp_mesh_load(path, NULL, &env->ctx, mesh, err);
    if (rc)
        return rc;
    const asp_mesh *m = *mesh;
    rc = asp_cloud_create(m->vertex_count, ASP_ATTR_NORMALS | (m->colors ? ASP_ATTR_COLORS : 0u), &env->ctx, cloud,
                          err);
    if (rc) {
        asp_mesh_destroy(*mesh);
        *mesh = NULL;
        return rc;
    }
    asp_cloud *c = *cloud;
    memcpy(c->origin, m->origin, sizeof c->origin);
    memcpy(c->positions, m->positions, 3 * m->vertex_count * sizeof *c->positions);
    memcpy(c->normals, m->normals, 3 * m->vertex_count * sizeof *c->normals);
    if (m->colors)
        memcpy(c->colors, m->colors, 4 * m->vertex_count * sizeof *c->colors);
    return 0;
}

#define UNSET SIZE_MAX

/* The library's ranges (src/amg/neighbourhood.c), checked here so the message names the option. */
static int check_counts(const struct cli_env *env, size_t k, size_t k_max, size_t fan_k, size_t max_levels,
                        size_t max_coarse)
{
    if (k != UNSET && (k < 3 || k > 1024))
        return cli_usage_error(env, "--k expects 3..1024, got %zu", k);
    size_t k_min = k == UNSET ? 24 : k;
    if (k_max != UNSET && (k_max < k_min || k_max > 1024))
        return cli_usage_error(env, "--k-max expects %zu (k_min)..1024, got %zu", k_min, k_max);
    if (fan_k != UNSET && (fan_k < 3 || fan_k > 1024))
        return cli_usage_error(env, "--fan-k expects 3..1024, got %zu", fan_k);
    if (max_levels != UNSET && (max_levels < 2 || max_levels > 100))
        return cli_usage_error(env, "--max-levels expects 2..100, got %zu", max_levels);
    if (max_coarse != UNSET && max_coarse < 1)
        return cli_usage_error(env, "--max-coarse expects at least 1, got %zu", max_coarse);
    return 0;
}

static int check_output_name(const struct cli_env *env, const char *input, const char *output,
                             const char *colors_out)
{
    const char *const inputs[] = {input};
    if (cli_check_output(env, output, "amg", 0, inputs, 1) ||
        cli_check_output(env, colors_out, NULL, 0, inputs, 1))
        return 2;
    const char *const out_in[] = {output};
    if (output && colors_out && cli_check_output(env, colors_out, NULL, 0, out_in, 1))
        return 2;
    if (output && colors_out && strcmp(output, colors_out) == 0)
        return cli_usage_error(env, "-o and --colors-out name the same file '%s'", output);
    return 0;
}

/* The level figures of a distributed run as decompose --stats --json writes them, plus the agreement checks. */
static void add_distributed_json(cJSON *o, const asp_amg_dist_info *in, double tau, int stats)
{
    cJSON *sizes = cJSON_CreateArray(), *sec = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "ranks", in->ranks);
    cJSON_AddNumberToObject(o, "points", (double)in->points);
    cJSON_AddNumberToObject(o, "levels", (double)in->nlevels);
    for (size_t l = 0; l < in->nlevels; l++)
        cJSON_AddItemToArray(sizes, cJSON_CreateNumber((double)in->level[l].unknowns));
    cJSON_AddItemToObject(o, "level_sizes", sizes);
    add_amg_info(o, &in->amg);
    cJSON_AddNumberToObject(o, "own_points_min", (double)in->own_points_min);
    cJSON_AddNumberToObject(o, "own_points_max", (double)in->own_points_max);
    cJSON_AddNumberToObject(o, "halo_points", (double)in->halo_points);
    cJSON_AddItemToObject(o, "peak_rss_mb_max_rank", cli_json_number("%.1f", in->peak_rss_max_mb));
    cJSON_AddItemToObject(o, "peak_rss_mb_mean_rank", cli_json_number("%.1f", in->peak_rss_mean_mb));
    cJSON_AddItemToObject(sec, "read", cli_json_number("%.4f", in->t_read));
    cJSON_AddItemToObject(sec, "halo", cli_json_number("%.4f", in->t_halo));
    add_stage_seconds(sec, &in->amg);
    cJSON_AddItemToObject(sec, "basis_stats", cli_json_number("%.4f", in->t_stats));
    cJSON_AddItemToObject(sec, "write", cli_json_number("%.4f", in->t_write));
    cJSON_AddItemToObject(o, "seconds", sec);
    if (!stats)
        return; /* the figures were not computed (ASP_AMG_DIST_NO_FIGURES), as the serial JSON has none */
    cJSON_AddItemToObject(o, "tau", cli_json_number("%g", tau));
    cJSON *levels = cJSON_CreateArray();
    for (size_t l = 0; l < in->nlevels; l++) {
        const asp_amg_dist_level *lv = &in->level[l];
        cJSON *j = cJSON_CreateObject();
        cJSON_AddNumberToObject(j, "level", (double)l);
        cJSON_AddNumberToObject(j, "unknowns", (double)lv->unknowns);
        cJSON_AddNumberToObject(j, "domains", (double)lv->domains);
        cJSON_AddNumberToObject(j, "strict_domains", (double)lv->strict_domains);
        cJSON_AddNumberToObject(j, "points_outside", (double)lv->points_outside);
        cJSON_AddItemToObject(j, "mean_domains_per_point", cli_json_number("%.6g", lv->mean_domains_per_point));
        cJSON_AddItemToObject(j, "max_pou_error", cli_json_number("%.3g", lv->max_pou_error));
        cJSON_AddItemToArray(levels, j);
    }
    cJSON_AddItemToObject(o, "level_stats", levels);
}

/* mpirun -np P decompose (or --distributed): every rank runs this; rank 0 reports (docs/mpi.md). */
static int decompose_distributed(struct cli_env *env, const char *input, const char *output,
                                 const asp_amg_desc *desc, double tau, int stats)
{
    asp_error err = {0};
    asp_amg_dist_info info;
    /* the basis of every level only where --stats reports its figures */
    int rc = asp_amg_decompose_distributed(input, output, desc, stats ? tau : ASP_AMG_DIST_NO_FIGURES, &env->ctx,
                                           &info, &err);
    cli_progress_end(env);
    int status = 0;
    if (rc)
        status = info.rank == 0 ? cli_fail(env, &err) : 1; // one report, from rank 0
    else if (info.rank == 0 && env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", input);
        if (output)
            cJSON_AddStringToObject(o, "output", output);
        else
            cJSON_AddNullToObject(o, "output");
        add_distributed_json(o, &info, tau, stats);
        cJSON_AddItemToObject(o, "total_seconds", cli_json_number("%.4f", info.t_total));
        status = cli_json_print(env, o);
    } else if (info.rank == 0 && !env->quiet) {
        printf("%s: %zu points on %d ranks, %zu levels (L = %zu, coarsest %zu unknowns), epsilon %.4g, %.2f s, "
               "peak RSS %.0f MB per rank (max)\n", output ? output : input, info.points, info.ranks, info.nlevels,
               info.nlevels - 1, info.level[info.nlevels - 1].unknowns, info.amg.epsilon, info.t_total,
               info.peak_rss_max_mb);
        if (stats) {
            printf("level   unknowns   domains    strict  outside  domains/pt  max |sum Psi - 1|\n");
            for (size_t l = 0; l < info.nlevels; l++)
                printf("%5zu  %9zu %9zu %9zu %8zu  %10.2f  %.3g\n", l, info.level[l].unknowns, info.level[l].domains,
                       info.level[l].strict_domains, info.level[l].points_outside,
                       info.level[l].mean_domains_per_point, info.level[l].max_pou_error);
        }
    }
    asp_amg_distributed_shutdown();
    return status;
}

int cmd_decompose(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *classifier = "variation", *coarsen = "rs", *interp = "classical";
    const char *preset = NULL, *stiffness = "clamped"; /* --preset is applied by cli_parse */
    const char *export_mode = NULL, *level_name = "L-3", *colors_out = NULL;
    /* UNSET, not 0: 0 means "default" to the library, so a given 0 would pass silently */
    size_t k = UNSET, k_max = UNSET, fan_k = UNSET, max_levels = UNSET, max_coarse = UNSET;
    double epsilon = 0, alpha = 0, beta = 0, strong = 0, trunc = 0, weak = 0, drop = 0, tau = 0.05, crease = 0;
    int stats = 0, critical = 0, mesh_stiffness = 0, distributed = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output decomposition (.amg)"},
        {"preset", 0, CLI_STRING, &preset, "SEED", "the seed's options: thesis, journal (docs/seeds.md)"},
        {"k", 'k', CLI_SIZE, &k, "N", "minimum neighbourhood size k_min (default 24)"},
        {"k-max", 0, CLI_SIZE, &k_max, "N", "cap with the epsilon-ball extension (default 2 k_min)"},
        {"epsilon", 0, CLI_DOUBLE, &epsilon, "X", "neighbourhood radius (default: median k_min-th distance)"},
        {"fan-k", 0, CLI_SIZE, &fan_k, "N", "nearest neighbours projected for the fan (default 16)"},
        {"stiffness", 0, CLI_STRING, &stiffness, "F",
         "positive off-diagonals: clamped (default, an M-matrix for AMG) or unclamped (the seeds)"},
        {"classifier", 0, CLI_STRING, &classifier, "C", "variation (default, thesis 2.3) or moment (journal eq. 3)"},
        {"alpha", 0, CLI_DOUBLE, &alpha, "X", "G(s) = 1/(alpha + beta s^2): alpha (default 0.01)"},
        {"beta", 0, CLI_DOUBLE, &beta, "X", "beta (default 100)"},
        {"coarsen", 0, CLI_STRING, &coarsen, "M", "BoomerAMG coarsening: rs (default), falgout, cljp, pmis, hmis"},
        {"interp", 0, CLI_STRING, &interp, "M", "interpolation: classical (default), direct, standard, ext+i"},
        {"strong", 0, CLI_DOUBLE, &strong, "X", "strength threshold (default 0.9)"},
        {"trunc", 0, CLI_DOUBLE, &trunc, "X", "interpolation truncation factor (default 0: none)"},
        {"max-levels", 0, CLI_SIZE, &max_levels, "N", "at most N levels (default 25)"},
        {"max-coarse", 0, CLI_SIZE, &max_coarse, "N", "stop at N unknowns (default 4)"},
        {"crease-cut", 0, CLI_DOUBLE, &crease, "X",
         "cut coarse couplings whose interface classifier is below X times the flatter side's (default 0.25, <0: off)"},
        {"weak-cut", 0, CLI_DOUBLE, &weak, "X", "cut coarse couplings below X times the median (default 0: off)"},
        {"drop", 0, CLI_DOUBLE, &drop, "X", "drop basis values below X, renormalised (default 1e-4; 0 drops nothing)"},
        {"stats", 0, CLI_FLAG, &stats, NULL, "print per-level statistics"},
        {"mesh-stiffness", 0, CLI_FLAG, &mesh_stiffness, NULL, "MESH input: the stiffness matrix on the mesh's own triangles (journal eq. 4)"},
        {"critical-k", 0, CLI_FLAG, &critical, NULL, "print the points' critical neighbourhood sizes (thesis 2.3), to choose --k"},
        {"tau", 0, CLI_DOUBLE, &tau, "X", "domain threshold for --stats (default 0.05; thesis K = 0.01)"},
        {"export-colors", 0, CLI_STRING, &export_mode, "M", "write a coloured point file: classifier, domains, strict"},
        {"level", 'l', CLI_STRING, &level_name, "L", "level for --export-colors domains|strict (default L-3)"},
        {"colors-out", 0, CLI_STRING, &colors_out, "FILE", "point file for --export-colors (.ply)"},
        {"distributed", 0, CLI_FLAG, &distributed, NULL,
         "the MPI path even on one rank (automatic under mpirun -np P > 1; docs/mpi.md)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one input file, got %d; see 'amgsplat decompose -h'", npos);
    const char *input = argv[0];
    /* the recogniser (magic, then extension in any case: O.AMG); a failure here resurfaces in the loader */
    asp_file_type type = {ASP_FILE_UNKNOWN, "", 0};
    int from_amg = asp_file_recognise(input, &type, NULL) == 0 && type.kind == ASP_FILE_AMG;
    int color_mode = 0;
    if (check_counts(env, k, k_max, fan_k, max_levels, max_coarse))
        return 2;
    if (cli_given(env, &drop) && !(drop >= 0 && drop < 1)) // issue #31: -1 was taken as "keep all"
        return cli_usage_error(env, "--drop expects a value in [0, 1) (0 drops nothing), got %g", drop);
    if (cli_given(env, &drop) && drop == 0)
        drop = -1; // the library's "keep every entry" (amg.h drop_tol), not its 0 = default
    if (check_output_name(env, input, output, colors_out))
        return 2;
    k = k == UNSET ? 0 : k, k_max = k_max == UNSET ? 0 : k_max, fan_k = fan_k == UNSET ? 0 : fan_k;
    max_levels = max_levels == UNSET ? 0 : max_levels, max_coarse = max_coarse == UNSET ? 0 : max_coarse;
    asp_amg_desc desc = {.k_min = k, .k_max = k_max, .epsilon = epsilon, .fan_k = fan_k, .alpha = alpha,
                         .beta = beta, .strong_threshold = strong, .trunc_factor = trunc, .max_levels = max_levels,
                         .max_coarse = max_coarse, .weak_coupling = weak, .drop_tol = drop,
                         .crease_cut = crease};
    int code;
    if (lookup(classifiers, classifier, &code))
        return cli_usage_error(env, "--classifier must be variation or moment, got '%s'", classifier);
    desc.classifier = (asp_amg_classifier_kind)code;
    if (lookup(coarsenings, coarsen, &code))
        return cli_usage_error(env, "--coarsen must be rs, falgout, cljp, pmis or hmis, got '%s'", coarsen);
    desc.coarsen = (asp_amg_coarsen)code;
    if (lookup(interps, interp, &code))
        return cli_usage_error(env, "--interp must be classical, direct, standard or ext+i, got '%s'", interp);
    desc.interp = (asp_amg_interp)code;
    if (lookup(stiffness_forms, stiffness, &code))
        return cli_usage_error(env, "--stiffness must be clamped or unclamped, got '%s'", stiffness);
    desc.stiffness = (asp_amg_stiffness)code;
    if (export_mode && lookup(color_modes, export_mode, &color_mode))
        return cli_usage_error(env, "--export-colors must be classifier, domains or strict, got '%s'", export_mode);
    if (export_mode && !colors_out)
        return cli_usage_error(env, "--export-colors needs --colors-out FILE.ply");
    if (!(tau >= 0 && tau < 1))
        return cli_usage_error(env, "--tau must be in [0, 1), got %g", tau);
    if (mesh_stiffness && type.kind != ASP_FILE_MESH)
        return cli_usage_error(env, "--mesh-stiffness needs a mesh input (OBJ, PLY with faces, OFF, STL, glTF, 3DS)");
    if (critical && from_amg)
        return cli_usage_error(env, "--critical-k needs a point input");
    if (!from_amg && !output && !stats && !export_mode && !critical)
        return cli_usage_error(env, "missing -o OUT.amg (or --stats / --export-colors)");
    if (from_amg && output)
        return cli_usage_error(env, "'%s' is already a decomposition; -o applies to point input", input);

    if (distributed || asp_amg_mpi_ranks() > 1) {
        if (from_amg || export_mode || critical || mesh_stiffness)
            return cli_usage_error(env, "on MPI ranks decompose takes a binary PLY point file and -o or --stats only "
                                        "(no .amg input, --export-colors, --critical-k, --mesh-stiffness)");
        return decompose_distributed(env, input, output, &desc, tau, stats);
    }

    asp_error err = {0};
    asp_amg *amg = NULL;
    double t0 = asp_time_now();
    asp_output_batch_begin(NULL); // -o and --colors-out: committed after both are written
    if (from_amg) {
        if (asp_amg_load(input, &env->ctx, &amg, &err))
            return cli_fail(env, &err);
    } else {
        asp_cloud *cloud = NULL;
        asp_mesh *mesh = NULL;
        if (mesh_stiffness ? load_mesh_vertices(env, input, &mesh, &cloud, &err)
                           : asp_cloud_load(input, &env->ctx, &cloud, &err))
            return cli_fail(env, &err);
        if (critical && print_critical(env, cloud, &err)) {
            asp_cloud_destroy(cloud);
            return cli_fail(env, &err);
        }
        if (!output && !stats && !export_mode) {
            asp_cloud_destroy(cloud);
            asp_mesh_destroy(mesh);
            return 0;
        }
        rc = mesh ? asp_amg_decompose_mesh(cloud, mesh->triangles, mesh->triangle_count, &desc, &env->ctx, &amg, &err)
                  : asp_amg_decompose_take(&cloud, &desc, &env->ctx, &amg, &err); // no copy of the points (issue 19)
        asp_cloud_destroy(cloud);
        asp_mesh_destroy(mesh);
        if (rc) {
            asp_amg_shutdown();
            return cli_fail(env, &err);
        }
        if (output && asp_amg_save(amg, output, &err)) {
            asp_output_batch_abort();
            asp_amg_destroy(amg);
            asp_amg_shutdown();
            return cli_fail(env, &err);
        }
    }
    double t_total = asp_time_now() - t0;
    rc = 0;
    if (export_mode)
        rc = export_colors(env, amg, color_mode, level_name, colors_out, &err);
    if (rc) // both appear or neither (issue #13)
        asp_output_batch_abort();
    else
        rc = asp_output_batch_commit(&err);
    cli_progress_end(env);
    int json_status = 0;
    if (!rc && env->json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", input);
        if (output)
            cJSON_AddStringToObject(o, "output", output);
        else
            cJSON_AddNullToObject(o, "output");
        add_info_json(o, amg);
        if (stats)
            rc = print_stats(env, amg, tau, o, &err);
        cJSON_AddItemToObject(o, "total_seconds", cli_json_number("%.4f", t_total));
        if (rc)
            cJSON_Delete(o);
        else
            json_status = cli_json_print(env, o);
    } else if (!rc) {
        size_t nl = asp_amg_level_count(amg);
        if (!env->quiet) {
            const asp_amg_info *in = asp_amg_get_info(amg);
            printf("%s: %zu points, %zu levels (L = %zu, coarsest %zu unknowns)", output ? output : input,
                   asp_amg_cloud(amg)->count, nl, nl - 1, asp_amg_level_size(amg, nl - 1));
            if (!from_amg)
                printf(", epsilon %.4g, %zu positive couplings %s, %.2f s", in->epsilon, in->positive_offdiag,
                       desc.stiffness == ASP_AMG_STIFFNESS_UNCLAMPED ? "kept" : "clamped", t_total);
            printf("\n");
        }
        if (stats)
            rc = print_stats(env, amg, tau, NULL, &err);
    }
    asp_amg_destroy(amg);
    asp_amg_shutdown();
    if (rc)
        return cli_fail(env, &err);
    return json_status;
}
