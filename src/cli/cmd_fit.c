/*
 * amgsplat fit: the textures of a .dps level fitted to reference images of its
 * source (issue 27; asp_fit_run in fit.h): colour texels by least squares so
 * that the level, drawn by the default method, matches the source's render.
 */
static const char usage[] =
    "usage: amgsplat fit IN.dps -o OUT.dps [--reference SOURCE] [--texture IMG] [--level L]\n"
    "                    [--views V] [--holdout H] [--size PX] [--iterations N] [--seed S]\n"
    "                    [--lambda X] [--smooth X] [--texels N | --bytes B] [--alpha-rounds N]\n"
    "                    [--alpha-step X] [--uncompressed] [--json]\n"
    "\n"
    "Fits the colour texels of every level (or --level L) so that the level drawn by the\n"
    "default (normalized) method matches reference images of SOURCE from V views spread\n"
    "evenly over the sphere at PX pixels: a mesh's own render (OBJ, PLY with faces, ...),\n"
    "else a point set's blended splats (points, or the .amg's points). SOURCE defaults to\n"
    "the file the .dps was built from. H further views, not used in fitting, report the\n"
    "gain (mean squared error of linear RGB, and SSIM of the default render). Geometry and\n"
    "alpha inside the surface are not changed; alpha near the silhouette is fitted first.\n"
    "--texels/--bytes scale every texture down to a budget before fitting. The fitted atlases\n"
    "are stored as BC3 (DXT5) blocks, 1 byte a texel on the GPU, unless --uncompressed.\n"
    "Progress and the loss go to stderr.";

#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static void log_stderr(void *user, const char *line)
{
    const struct cli_env *env = user;
    if (!env->quiet)
        fprintf(stderr, "%s\n", line);
}

/* The reference: a mesh, a point file, or the points of an .amg. */
static int load_reference(struct cli_env *env, const char *path, const char *texture, asp_mesh **mesh,
                          asp_cloud **cloud, asp_amg **amg, asp_error *err)
{
    asp_file_type ft;
    int rc = asp_file_recognise(path, &ft, err);
    if (rc)
        return rc;
    if (ft.kind == ASP_FILE_MESH)
        return asp_mesh_load(path, &(asp_mesh_load_desc){.texture_override = texture}, &env->ctx, mesh, err);
    if (ft.kind == ASP_FILE_POINTS)
        return asp_cloud_load(path, &env->ctx, cloud, err);
    if (ft.kind == ASP_FILE_AMG)
        return asp_amg_load(path, &env->ctx, amg, err);
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot use '%s' as a reference: expected a mesh, points or .amg",
                         path);
}

int cmd_fit(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL, *reference = NULL, *texture = NULL, *level_name = NULL;
    size_t views = 64, holdout = 16, iterations = 60, size = 128, seed = 1;
    double lambda = 0.0, smooth = 0.0, alpha_step = 0.0;
    int alpha_rounds = 8;
    size_t texels = 0, bytes = 0;
    int uncompressed = 0;
    const struct cli_option opts[] = {
        {"output", 'o', CLI_STRING, &output, "FILE", "output .dps"},
        {"reference", 'r', CLI_STRING, &reference, "SOURCE", "mesh or point set to match (default: the source)"},
        {"texture", 't', CLI_STRING, &texture, "IMG", "texture for a mesh whose material names none"},
        {"level", 'l', CLI_STRING, &level_name, "L", "fit only this level (name 'L-3' or AMG index)"},
        {"views", 0, CLI_SIZE, &views, "V", "training views over the sphere (1-256, default 64)"},
        {"holdout", 0, CLI_SIZE, &holdout, "H", "held-out views for the report (1-256, default 16)"},
        {"size", 's', CLI_SIZE, &size, "PX", "image side in pixels (default 128)"},
        {"iterations", 'n', CLI_SIZE, &iterations, "N", "conjugate-gradient iterations (default 60)"},
        {"seed", 0, CLI_SIZE, &seed, "S", "rotates the view lattices (default 1)"},
        {"lambda", 0, CLI_DOUBLE, &lambda, "X", "pull towards the unfitted texels (default 0.1)"},
        {"smooth", 0, CLI_DOUBLE, &smooth, "X", "smoothness of the correction (default 4; negative: none)"},
        {"texels", 0, CLI_SIZE, &texels, "N", "texel budget per level: textures scaled down to fit, then fitted"},
        {"bytes", 0, CLI_SIZE, &bytes, "B", "GPU-byte budget per level (as info and eval count them)"},
        {"alpha-rounds", 0, CLI_INT, &alpha_rounds, "N", "silhouette rounds on alpha (default 8; 0: colour only)"},
        {"alpha-step", 0, CLI_DOUBLE, &alpha_step, "X", "largest alpha change per round (default 0.08)"},
        {"uncompressed", 0, CLI_FLAG, &uncompressed, NULL, "keep RGBA8 atlases (default: BC3 blocks)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one .dps file, got %d; see 'amgsplat fit -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o OUT.dps");
    if (views < 1 || views > 256 || holdout < 1 || holdout > 256)
        return cli_usage_error(env, "--views and --holdout must be 1 to 256, got %zu and %zu", views, holdout);
    if (size < 8 || size > 4096)
        return cli_usage_error(env, "--size must be 8 to 4096 pixels, got %zu", size);
    if (iterations < 1 || iterations > 10000)
        return cli_usage_error(env, "--iterations must be 1 to 10000, got %zu", iterations);
    if (alpha_rounds < 0 || alpha_rounds > 100)
        return cli_usage_error(env, "--alpha-rounds must be 0 to 100, got %d", alpha_rounds);
    if (alpha_step < 0 || alpha_step > 1)
        return cli_usage_error(env, "--alpha-step must be in 0..1, got %g", alpha_step);
    if (lambda < 0)
        return cli_usage_error(env, "--lambda must be >= 0, got %g", lambda);
    const char *inputs[] = {argv[0]};
    if (cli_check_output(env, output, "dps", 0, inputs, 1))
        return 2;

    asp_error err = {0};
    asp_dps *dps = NULL;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    asp_amg *amg = NULL;
    asp_gl_context *gl = NULL;
    if (asp_dps_load(argv[0], &env->ctx, &dps, &err))
        return cli_fail(env, &err);
    size_t first = 0, last = dps->level_count;
    if (level_name) {
        if (asp_dps_level_parse(dps, level_name, &first, &err)) {
            asp_dps_destroy(dps);
            return cli_usage_error(env, "'%s': %s", argv[0], err.msg);
        }
        last = first + 1;
    }
    const char *ref_path = reference ? reference : dps->source;
    if (!ref_path[0]) {
        asp_dps_destroy(dps);
        return cli_usage_error(env, "'%s' names no source: give --reference SOURCE", argv[0]);
    }
    cJSON *levels = env->json ? cJSON_CreateArray() : NULL;
    rc = load_reference(env, ref_path, texture, &mesh, &cloud, &amg, &err);
    if (!rc)
        rc = asp_gl_context_create_headless(NULL, &env->ctx, &gl, &err);
    asp_fit_reference ref = {.mesh = mesh, .cloud = amg ? asp_amg_cloud(amg) : cloud};
    asp_fit_desc desc = {.views = views, .holdout = holdout, .size = (uint32_t)size,
                         .iterations = (uint32_t)iterations, .seed = seed, .lambda = lambda, .smooth = smooth,
                         .texels = texels, .bytes = bytes, .uncompressed = uncompressed,
                         .alpha_rounds = alpha_rounds ? alpha_rounds : -1, .alpha_step = alpha_step,
                         .log = log_stderr, .log_user = env};
    for (size_t l = first; l < last && !rc; l++) {
        char name[16];
        asp_dps_level_name(dps, l, name);
        cli_info(env, "amgsplat fit: level %s, %zu primitives, %zu + %zu views at %zu px, reference '%s'", name,
                 dps->levels[l].prim_count, views, holdout, size, ref_path);
        asp_fit_stats st = {0};
        rc = asp_fit_run(gl, dps, l, &ref, &desc, &env->ctx, &st, &err);
        if (rc)
            break;
        cli_progress_end(env);
        if (levels) {
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "level", name);
            cJSON_AddNumberToObject(o, "primitives", (double)dps->levels[l].prim_count);
            cJSON_AddItemToObject(o, "train_before", cli_json_number("%.9g", st.train_before));
            cJSON_AddItemToObject(o, "train_after", cli_json_number("%.9g", st.train_after));
            cJSON_AddItemToObject(o, "holdout_before", cli_json_number("%.9g", st.holdout_before));
            cJSON_AddItemToObject(o, "holdout_after", cli_json_number("%.9g", st.holdout_after));
            cJSON_AddItemToObject(o, "ssim_before", cli_json_number("%.6f", st.ssim_before));
            cJSON_AddItemToObject(o, "ssim_after", cli_json_number("%.6f", st.ssim_after));
            cJSON_AddNumberToObject(o, "texels", (double)dps->levels[l].texels);
            cJSON_AddNumberToObject(o, "bytes", (double)asp_dps_level_gpu_bytes(&dps->levels[l], NULL));
            cJSON_AddNumberToObject(o, "silhouette_before", (double)st.silhouette_before);
            cJSON_AddNumberToObject(o, "silhouette_after", (double)st.silhouette_after);
            cJSON_AddNumberToObject(o, "texels_seen", (double)st.texels_seen);
            cJSON_AddNumberToObject(o, "pixels", (double)st.pixels);
            cJSON_AddNumberToObject(o, "iterations", st.iterations);
            cJSON_AddItemToObject(o, "seconds", cli_json_number("%.3f", st.seconds));
            cJSON_AddItemToArray(levels, o);
        } else if (!env->quiet) {
            printf("level %s: %zu primitives: held-out SSIM %.4f -> %.4f, held-out MSE %.3g -> %.3g, training "
                   "MSE %.3g -> %.3g (%u iterations, %.1f s)\n",
                   name, dps->levels[l].prim_count, st.ssim_before, st.ssim_after, st.holdout_before,
                   st.holdout_after, st.train_before, st.train_after, st.iterations, st.seconds);
        }
    }
    if (!rc)
        rc = asp_dps_save(dps, output, &err);
    int status = 0;
    if (rc) {
        cJSON_Delete(levels);
        status = cli_fail(env, &err);
    } else if (levels) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "input", argv[0]);
        cJSON_AddStringToObject(o, "output", output);
        cJSON_AddStringToObject(o, "reference", ref_path);
        cJSON_AddItemToObject(o, "levels", levels);
        status = cli_json_print(env, o);
    }
    asp_gl_context_destroy(gl);
    asp_amg_destroy(amg);
    asp_cloud_destroy(cloud);
    asp_mesh_destroy(mesh);
    asp_dps_destroy(dps);
    return status;
}
