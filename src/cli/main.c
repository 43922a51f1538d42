/*
 * amgsplat: git-style dispatcher. The table below is the only list of
 * subcommands; each lives in src/cli/cmd_<name>.c.
 */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

struct cli_command {
    const char *name;
    int (*fn)(int argc, char **argv, struct cli_env *env);
    const char *summary;
    const char *reads; /* what its input may be, listed by the overview (issue 29) */
};

static const struct cli_command commands[] = {
    {"info", cmd_info, "print counts, attributes, bounds and radii of a point or primitive file",
     "points (PLY, LAS, XYZ/PTS/TXT), meshes, .amg, .dps, .hier, images (PNG), scenes (.json), glTF exports"},
    {"convert", cmd_convert, "convert between point formats (PLY ascii/binary, LAS, XYZ/PTS/TXT)",
     "points: PLY, LAS, XYZ/PTS/TXT (writes the same)"},
    {"sample", cmd_sample, "sample a mesh (OBJ, PLY, OFF, STL, glTF, 3DS) to points",
     "meshes: OBJ+MTL, PLY with faces, OFF, STL, glTF/GLB, 3DS (assimp)"},
    {"synth", cmd_synth, "make a synthetic test model (octahedron, cube, sphere, torus, checker-plane)",
     "nothing (a shape name)"},
    {"estimate", cmd_estimate, "estimate normals and radii of a raw scan",
     "points: PLY, LAS, XYZ/PTS/TXT"},
    {"render", cmd_render, "render points, .amg, .dps, meshes or scenes to PNG headlessly (EGL)",
     "points (PLY, LAS, XYZ/PTS/TXT), .amg, .dps, .hier, meshes, scenes (.json)"},
    {"imgdiff", cmd_imgdiff, "compare two images: PSNR, SSIM, silhouette IoU",
     "two images (PNG)"},
    {"decompose", cmd_decompose, "multiscale AMG decomposition of a point set into domains",
     "points (PLY, LAS, XYZ/PTS/TXT), meshes (--mesh-stiffness), .amg (--stats)"},
    {"simplify", cmd_simplify, "simplify a mesh to N triangles (meshoptimizer), keeping UVs and textures",
     "meshes: OBJ+MTL, PLY with faces, OFF, STL, glTF/GLB, 3DS"},
    {"build", cmd_build, "domain primitives (textured polygons) of AMG levels into a .dps file",
     "points (PLY, LAS, XYZ/PTS/TXT) or .amg"},
    {"fit", cmd_fit, "fit the textures of .dps levels to images of their source (mesh or points)",
     ".dps, with a mesh, points or images as the reference"},
    {"export", cmd_export, "glTF 2.0 (.glb/.gltf) of domain primitives, point sets and hierarchies",
     ".dps, points (PLY, LAS, XYZ/PTS/TXT), .hier"},
    {"view", cmd_view, "open a window on points, .amg, .dps, meshes or scenes (interactive viewer)",
     "points (PLY, LAS, XYZ/PTS/TXT), .amg, .dps, .hier, meshes, scenes (.json)"},
    {"eval", cmd_eval, "measure every representation against the reference: PSNR, SSIM, IoU, frame time",
     "points (PLY, LAS, XYZ/PTS/TXT), meshes, synthetic shape names"},
    {"bench-paper", cmd_bench_paper, "print the seeds' tables (journal Tables 1-2, thesis Tables 5.1-5.4)",
     "points, meshes or synthetic shape names, as eval"},
    {"scene", cmd_scene, "scene files of instances: 'scene field' writes N models receding to the horizon",
     "points, .amg, .hier, .dps and meshes as instances (writes SCENE.json)"},
    {"experiment", cmd_experiment, "the perceptual experiment of seed 004: run (people or observer), analyze, ttest",
     "run: scenes it makes itself; analyze: its logs; ttest: summary figures"},
};
enum { N_COMMANDS = sizeof commands / sizeof commands[0] };

static void print_overview(FILE *fp)
{
    fprintf(fp, "usage: amgsplat <command> [options] [args]\n"
                "       amgsplat help <command>\n\n"
                "Point-based rendering and AMG domain-primitive simplification (amgsplat %s).\n\n"
                "commands:\n",
            ASP_VERSION_STRING);
    for (size_t i = 0; i < N_COMMANDS; i++)
        fprintf(fp, "  %-10s %s\n", commands[i].name, commands[i].summary);
    // a section of its own: tests/cli/help.sh reads command names from the lines under "commands:"
    fprintf(fp, "\nwhat each command reads:\n");
    for (size_t i = 0; i < N_COMMANDS; i++)
        fprintf(fp, "  %-10s %s\n", commands[i].name, commands[i].reads);
    fprintf(fp, "\nEvery command takes -h, --quiet, --json and --threads N.\n");
}

static const struct cli_command *find_command(const char *name)
{
    for (size_t i = 0; i < N_COMMANDS; i++)
        if (strcmp(commands[i].name, name) == 0)
            return &commands[i];
    return NULL;
}

static int run(const struct cli_command *c, int argc, char **argv)
{
    struct cli_env env;
    memset(&env, 0, sizeof env);
    env.cmd = c->name;
    int status = c->fn(argc, argv, &env);
    cli_progress_end(&env);
    return status;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        print_overview(stderr);
        return 2;
    }
    const char *name = argv[1];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
        print_overview(stdout);
        return 0;
    }
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("amgsplat %s\n", ASP_VERSION_STRING);
        return 0;
    }
    if (strcmp(name, "help") == 0) {
        if (argc < 3) {
            print_overview(stdout);
            return 0;
        }
        const struct cli_command *c = find_command(argv[2]);
        if (!c) {
            fprintf(stderr, "amgsplat: '%s' is not a command; see 'amgsplat help'\n", argv[2]);
            return 2;
        }
        char *help_argv[] = {argv[2], "--help", NULL};
        return run(c, 2, help_argv);
    }
    const struct cli_command *c = find_command(name);
    if (c && (strcmp(name, "decompose") == 0 || strcmp(name, "build") == 0))
        cli_huge_pages_restart(argv);
    if (!c) {
        fprintf(stderr, "amgsplat: '%s' is not a command; see 'amgsplat help'\n", name);
        return 2;
    }
    return run(c, argc - 1, argv + 1);
}
