/*
 * amgsplat scene: scene files of instances (instances.h, docs/scene-format.md).
 * `scene field MODEL --instances N -o scene.json` writes a test scene of N
 * instances on a ground grid receding to the horizon (issue 18 item 4); the
 * layout is the library's (asp_instance_field). Glue only; docs/cli/scene.md.
 */
#if !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* realpath (POSIX XSI) */
#endif
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/instances.h"
#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat scene field MODEL --instances N -o SCENE.json [--seed S] [--spacing D] [--jitter J]\n"
    "\n"
    "Scene files place instances of point sets, .amg, .hier, .dps files and meshes with\n"
    "transforms (docs/scene-format.md); render, view, eval and info accept them.\n"
    "field: N instances of MODEL on the ground plane y = 0, on a grid D model diameters apart\n"
    "(default 1.5), twice as deep as wide, each turned by a random yaw and moved by up to J/2\n"
    "grid steps (default 0.3), seeded by S (default 1: one seed, one file), with a default\n"
    "camera at the near edge, half a model high, looking along the field, so near instances\n"
    "show large and far ones tiny. MODEL is written relative to the scene file's folder.";

/* MODEL as the scene file at output names it: relative to the output's folder when inside it, else absolute. */
static int source_name(const char *model, const char *output, char *dst, size_t cap)
{
    char real_model[PATH_MAX], dir[PATH_MAX], real_dir[PATH_MAX];
    if (!realpath(model, real_model))
        return -1;
    const char *slash = strrchr(output, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - output + (slash == output)) : 1, slash ? output : ".");
    size_t n = 0;
    if (realpath(dir, real_dir)) {
        n = strlen(real_dir);
        if (!(strncmp(real_model, real_dir, n) == 0 && real_model[n] == '/'))
            n = 0;
        else
            n++;
    }
    int w = snprintf(dst, cap, "%s", real_model + n);
    return w < 0 || (size_t)w >= cap ? -1 : 0;
}

static int print_json(const struct cli_env *env, const char *output, const asp_instance_scene *s, uint64_t seed,
                      double seconds)
{
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "output", output);
    cJSON_AddStringToObject(j, "source", s->sources[0].name);
    cJSON_AddNumberToObject(j, "instances", (double)s->instance_count);
    cJSON_AddNumberToObject(j, "seed", (double)seed);
    cJSON_AddItemToObject(j, "eye", cJSON_CreateDoubleArray(s->camera.eye, 3));
    cJSON_AddItemToObject(j, "target", cJSON_CreateDoubleArray(s->camera.target, 3));
    cJSON_AddItemToObject(j, "seconds", cli_json_number("%.3f", seconds));
    return cli_json_print(env, j);
}

static int scene_field(int argc, char **argv, struct cli_env *env)
{
    const char *output = NULL;
    size_t instances = 0, seed = 1;
    double spacing = 1.5, jitter = 0.3;
    const struct cli_option opts[] = {
        {"instances", 'n', CLI_SIZE, &instances, "N", "instances of MODEL (required, 1..1000000)"},
        {"output", 'o', CLI_STRING, &output, "SCENE.json", "scene file to write (required)"},
        {"seed", 0, CLI_SIZE, &seed, "S", "seed of the yaws and jitter (default 1)"},
        {"spacing", 0, CLI_DOUBLE, &spacing, "D", "grid step in model diameters (default 1.5)"},
        {"jitter", 0, CLI_DOUBLE, &jitter, "J", "random offset in grid steps, 0..1 (default 0.3)"},
        {0},
    };
    int npos = 0, prc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (prc)
        return prc > 0 ? 0 : 2;
    if (npos != 1)
        return cli_usage_error(env, "expected one MODEL file, got %d; see 'amgsplat scene field -h'", npos);
    if (!output)
        return cli_usage_error(env, "missing -o SCENE.json");
    const char *dot = strrchr(output, '.');
    if (!dot || strcmp(dot, ".json") != 0)
        return cli_usage_error(env, "output '%s': this command writes .json", output);
    if (cli_check_output(env, output, NULL, 0, (const char *const[]){argv[0]}, 1))
        return 2;
    if (instances < 1 || instances > ASP_INSTANCE_SCENE_MAX_INSTANCES)
        return cli_usage_error(env, "--instances expects 1..%d, got %zu", ASP_INSTANCE_SCENE_MAX_INSTANCES,
                               instances);
    if (!(spacing > 0 && spacing <= 1000))
        return cli_usage_error(env, "--spacing expects model diameters in (0, 1000], got %g", spacing);
    if (!(jitter >= 0 && jitter <= 1))
        return cli_usage_error(env, "--jitter expects grid steps in 0..1, got %g", jitter);
    char name[512];
    if (source_name(argv[0], output, name, sizeof name) != 0) {
        asp_error e;
        asp_error_set(&e, ASP_EIO, "cannot open '%s': no such file, or its path is over %zu bytes", argv[0],
                      sizeof name - 1);
        return cli_fail(env, &e);
    }
    double t0 = asp_time_now();
    asp_error err = {0, ""};
    asp_scene model;
    memset(&model, 0, sizeof model);
    asp_instance_scene s;
    memset(&s, 0, sizeof s);
    // the model's frame and lowest point size and place the field; its own file's type decides how
    int rc = asp_scene_load(argv[0], NULL, &env->ctx, &model, &err);
    if (!rc)
        rc = asp_instance_field(&model, name,
                                &(asp_instance_field_desc){.instances = instances, .seed = seed, .spacing = spacing,
                                                           .jitter = jitter > 0 ? jitter : -1.0},
                                &s, &err);
    if (!rc)
        rc = asp_instance_scene_save(&s, output, &err);
    int status = 0;
    if (rc) {
        status = cli_fail(env, &err);
    } else if (env->json) {
        status = print_json(env, output, &s, seed, asp_time_now() - t0);
    } else {
        cli_info(env, "wrote '%s': %zu instances of '%s' (seed %zu), camera at %.3g,%.3g,%.3g\n", output,
                 s.instance_count, name, seed, s.camera.eye[0], s.camera.eye[1], s.camera.eye[2]);
    }
    asp_instance_scene_release(&s);
    asp_scene_release(&model);
    return status;
}

int cmd_scene(int argc, char **argv, struct cli_env *env)
{
    if (argc < 2 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        FILE *fp = argc < 2 ? stderr : stdout;
        fprintf(fp, "%s\n", usage);
        return argc < 2 ? 2 : 0;
    }
    if (strcmp(argv[1], "field") == 0) {
        env->cmd = "scene field";
        return scene_field(argc - 1, argv + 1, env);
    }
    return cli_usage_error(env, "unknown subcommand '%s' (expected field)", argv[1]);
}
