/*
 * amgsplat experiment: the perceptual experiment program of seed 004 chapter 2
 * (four tests, runs A and B, control and variable groups, per-frame logs) with
 * domain primitives as a third representation, and a machine observer that
 * sees only the rendered frames. An application module above render (STYLE.md
 * 9b). The log format is docs/experiment-log.md; `amgsplat experiment analyze`
 * reads it.
 */
#ifndef AMGSPLAT_EXPERIMENT_H
#define AMGSPLAT_EXPERIMENT_H

#include "mesh.h"
#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The four tests of seed 004 2.3, in the order of the log format's "tests" list. */
typedef enum asp_experiment_test {
    ASP_EXPERIMENT_FAR = 0,      /* far object recognition */
    ASP_EXPERIMENT_NEAR = 1,     /* near object recognition */
    ASP_EXPERIMENT_LOWSPEED = 2, /* walking a smooth path through rocky terrain */
    ASP_EXPERIMENT_HIGHSPEED = 3 /* flying a ship through a winding canyon */
} asp_experiment_test;
#define ASP_EXPERIMENT_TEST_COUNT 4

/** How a scene is drawn in one run. */
typedef enum asp_experiment_condition {
    ASP_EXPERIMENT_POLYGONS = 0,   /* the mesh (mesh renderer) */
    ASP_EXPERIMENT_POINTS = 1,     /* points sampled from the mesh, octree cut drawn as squares (seed 004 3.2) */
    ASP_EXPERIMENT_PRIMITIVES = 2, /* AMG domain primitives (decompose -> build -> prim renderer) */
    ASP_EXPERIMENT_BLANK = 3       /* draws nothing: the observer's sanity check */
} asp_experiment_condition;
#define ASP_EXPERIMENT_CONDITION_COUNT 4

/** "far", "near", "lowspeed", "highspeed"; NULL past the end. */
const char *asp_experiment_test_name(asp_experiment_test t);
/** "polygons", "points", "primitives", "blank"; NULL past the end. */
const char *asp_experiment_condition_name(asp_experiment_condition c);
/** Parses a condition name; returns 0 or ASP_EINVAL naming the choices. */
int asp_experiment_condition_parse(const char *name, asp_experiment_condition *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Design (seed 004 2.3)                                                    */
/* ------------------------------------------------------------------------ */

/** Group assignment for asp_experiment_plan_draw. */
enum asp_experiment_group_rule {
    ASP_EXPERIMENT_GROUP_BALANCED = 0, /* permuted blocks over control + each variable condition (default) */
    ASP_EXPERIMENT_GROUP_CONTROL = 1,  /* every run B is polygons */
    ASP_EXPERIMENT_GROUP_VARIABLE = 2, /* every run B a variable condition, subjects in blocks over them */
    ASP_EXPERIMENT_GROUP_RANDOM = 3    /* a seeded coin per test, as seed 004 2.3 words it (unbalanced) */
};

/** One subject's plan: the test order and, per test, what run B shows. */
typedef struct asp_experiment_plan {
    asp_experiment_test order[ASP_EXPERIMENT_TEST_COUNT];        /* a seeded permutation */
    int variable[ASP_EXPERIMENT_TEST_COUNT];                     /* by test: 1 = variable group, 0 = control */
    asp_experiment_condition run_b[ASP_EXPERIMENT_TEST_COUNT];   /* by test: condition of run B */
} asp_experiment_plan;

/**
 * Draws subject number subject's plan (0-based) from seed: the tests in a
 * random order (seed 004 2.3's counterbalancing), and what run B shows.
 * BALANCED: the groups are control (run B polygons again) and one per
 * variable[i]; subjects 0..G-1 form the first block, G..2G-1 the next, each
 * block a seeded permutation of the G groups, and a subject keeps its group
 * in every test; so every complete block covers every group once. VARIABLE:
 * the same over the variable conditions only; CONTROL: always polygons;
 * RANDOM: a fair coin per test and a uniform variable[i]. Run A is always
 * polygons. The same (seed, subject, variable, rule) give the same plan on
 * every machine (a 64-bit generator, no floating point in the draws); adding
 * subjects never changes the earlier ones' plans. Returns 0 or ASP_EINVAL
 * (nvariable == 0 for a rule that needs one, polygons or a repeat in
 * variable). Pure, thread safe.
 */
int asp_experiment_plan_draw(uint64_t seed, size_t subject, const asp_experiment_condition *variable,
                             size_t nvariable, int rule, asp_experiment_plan *out, asp_error *err);

/** How a design spreads subjects 0..n-1 over its groups (asp_experiment_design_check). */
typedef struct asp_experiment_design {
    asp_experiment_condition groups[ASP_EXPERIMENT_CONDITION_COUNT]; /* run B's condition; polygons = control */
    size_t group_count;
    size_t runs_b[ASP_EXPERIMENT_CONDITION_COUNT]; /* by condition: runs B over all subjects and tests */
    int balanced;                                  /* every group got as many runs B */
    char warning[320];                             /* why not, naming the counts; "" when balanced */
} asp_experiment_design;

/**
 * Checks the design of nsubjects subjects (asp_experiment_plan_draw for each):
 * balanced when every group gets as many runs B, which for the block rules
 * means a multiple of the group count. Returns 0 (out filled, out->warning
 * set when unbalanced) or asp_experiment_plan_draw's errors.
 */
int asp_experiment_design_check(uint64_t seed, size_t nsubjects, const asp_experiment_condition *variable,
                                size_t nvariable, int rule, asp_experiment_design *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Scenes (seed 004 2.1-2.2)                                                */
/* ------------------------------------------------------------------------ */

#define ASP_EXPERIMENT_MAX_CANDIDATES 8

/** A recognition candidate: a name the subject may answer and its model file. */
typedef struct asp_experiment_candidate {
    char name[32];
    char model[512];
    asp_up_axis up;
} asp_experiment_candidate;

/** What a test shows; filled from the scene file (asp_experiment_scenes_load) or the defaults. */
typedef struct asp_experiment_scene {
    int kind;              /* 0 = object, 1 = terrain, 2 = canyon */
    char answer[32];       /* object: the candidate shown */
    float distance_radii;  /* object: eye distance in bounding-sphere radii */
    uint64_t seed;         /* terrain/canyon: generator seed */
    uint32_t grid;         /* terrain/canyon: height-field vertices per side */
    float size;            /* terrain/canyon: side of the square, world units */
    float half_width;      /* terrain/canyon: half width of the path or channel */
    float relief;          /* terrain: rock height; canyon: wall height */
    float speed;           /* navigation: forward speed, world units per second */
    float eye_height;      /* navigation: eye above the ground */
    float time_limit;      /* seconds of simulated time per run */
    size_t points;         /* points sampled from the mesh */
    size_t primitives;     /* primitive budget: the finest AMG level with at most this many */
} asp_experiment_scene;

/** The scene file: candidates and one scene per test. */
typedef struct asp_experiment_scenes {
    asp_experiment_candidate candidates[ASP_EXPERIMENT_MAX_CANDIDATES];
    size_t candidate_count;
    asp_experiment_scene tests[ASP_EXPERIMENT_TEST_COUNT];
} asp_experiment_scenes;

/**
 * The default scenes: candidates bunny, cat, horse from Debian's glmark2-data
 * (/usr/share/glmark2/models), far = cat, near = horse; a 160-unit rocky
 * terrain with a sandy path; a 200-unit canyon. Pure.
 */
void asp_experiment_scenes_default(asp_experiment_scenes *out);

/**
 * Reads a scene file (JSON, "format": "amgsplat-scenes 1", docs/cli/experiment.md)
 * over the defaults: fields left out keep their default. Returns 0, ASP_EIO,
 * ASP_EFORMAT (names the field and what was expected) or ASP_ENOMEM; *out is
 * unchanged on failure.
 */
int asp_experiment_scenes_load(const char *path, asp_experiment_scenes *out, asp_error *err);

/** Writes scenes as a scene file (atomic). Returns 0, ASP_EIO or ASP_ENOMEM. */
int asp_experiment_scenes_save(const asp_experiment_scenes *scenes, const char *path, asp_error *err);

/**
 * A generated navigation world: the mesh (vertex colours: sandy path or
 * floor, grey rock or walls), its height field and the path's centre
 * polyline. Free with asp_experiment_world_release.
 */
typedef struct asp_experiment_world {
    asp_mesh *mesh;
    float *heights;        /* grid * grid ground heights, row z, column x */
    uint32_t grid;
    float size;            /* the field covers [-size/2, size/2]^2 in x and z */
    float *path;           /* 3 * path_count: the centre polyline, start to goal, on the ground */
    size_t path_count;
    float half_width;
} asp_experiment_world;

/**
 * Generates the terrain (kind 1: a fractal height field of value noise with a
 * smooth path carved along a seeded winding curve) or the canyon (kind 2: a
 * flat floor between steep rough walls along such a curve). Deterministic
 * for a scene. Returns 0, ASP_EINVAL (grid < 8 or > 2048, size or half_width
 * not positive) or ASP_ENOMEM; *out is zeroed on failure.
 */
int asp_experiment_world_generate(const asp_experiment_scene *scene, const asp_context *ctx,
                                  asp_experiment_world *out, asp_error *err);

/** Ground height at (x, z), bilinear in the height field (clamped at the edges). */
float asp_experiment_world_height(const asp_experiment_world *w, float x, float z);

/**
 * Nearest point of the path to (x, z) in the ground plane: returns the
 * distance, and in *along the arc length fraction 0..1 of that point and in
 * dir (may be NULL) the unit direction of its segment. Pure.
 */
float asp_experiment_path_nearest(const float *path, size_t count, float x, float z, float *along, float dir[2]);

void asp_experiment_world_release(asp_experiment_world *w);

/* ------------------------------------------------------------------------ */
/* The machine observer (sees only the frame read back)                    */
/* ------------------------------------------------------------------------ */

/**
 * What the observer sees of a path in one frame: the frame's pixels whose
 * colour is "sandy" ((r - b) / r > 0.22 and r > 60: the path and canyon floor
 * colour, which shading scales but does not turn), counted in the band of
 * rows [band_top, band_bottom) of the image height (fractions). fraction =
 * sandy share of the band; steer = their mean column mapped to -1 (left edge)
 * .. 1 (right edge), 0 when none. Pure.
 */
void asp_experiment_see_path(const asp_image *frame, float band_top, float band_bottom, float *fraction,
                             float *steer);

/* ------------------------------------------------------------------------ */
/* Running the experiment                                                   */
/* ------------------------------------------------------------------------ */

/** The result of one run, reported through asp_experiment_desc.on_run. */
typedef struct asp_experiment_run_result {
    char subject[32];
    asp_experiment_test test;
    char run;                        /* 'A' or 'B' */
    asp_experiment_condition condition;
    int variable;                    /* group of this test */
    size_t frames;
    double mean_frame_ms;            /* measured drawing + read back time */
    size_t drawn;                    /* primitives drawn in the last frame */
    double progress;                 /* navigation: arc length fraction reached, 0..1 */
    size_t off_path;                 /* navigation: off_path / collision events */
    char answer[32];                 /* recognition */
    int correct;
    double recognition_s, naming_s;
} asp_experiment_run_result;

typedef void (*asp_experiment_run_fn)(void *user, const asp_experiment_run_result *r);
/** Receives a progress line (no newline); only the CLI prints it. */
typedef void (*asp_experiment_log_fn)(void *user, const char *line);

/** Options of asp_experiment_run; the zero value means defaults where noted. */
typedef struct asp_experiment_desc {
    const char *output_dir;        /* DIR (required): study.json, DIR/<subject>/<test>-<run>.jsonl */
    const char *scenes_path;       /* scene file; NULL = defaults (written to DIR/scenes.json) */
    const char *cache_dir;         /* derived points and .dps; NULL = DIR/scenes */
    uint64_t seed;
    int observer;                  /* 1: machine observer, headless; 0: a person at a window */
    size_t subjects;               /* observer: simulated subjects S01..; 0 = 1 */
    const char *subject;           /* person: the subject id (letters, digits, '-', '_') */
    int short_tests;               /* short runs (CI): a fifth of each time limit, smaller meshes */
    int resume;                    /* add missing runs to existing subject directories */
    int practice;                  /* person: a short walk and flight before the tests, not logged, then a
                                      "practice over" screen */
    size_t subject_number;         /* person: the subject's 1-based place in the design (its block and
                                      group); 0 = 1. The observer numbers S01.. itself */
    uint32_t width, height;        /* frame size; 0 = 160 x 120 (observer), 1024 x 640 (window) */
    const asp_experiment_condition *variable; /* conditions of the variable group; NULL = points, primitives */
    size_t variable_count;
    int group_rule;                /* asp_experiment_group_rule */
    float coarse_tau;              /* points: screen tolerance of the octree cut in pixels; 0 = 1 */
    uint32_t depth_limit;          /* points: deepest octree level drawn (seed 004 3.2.5 k_0, Fig. 3.4); 0 = none */
    int adapt;                     /* points: seed 004 3.2.5 depth control from the measured frame time
                                      (not reproducible) */
    int realtime;                  /* observer: simulated time step = measured frame time (not reproducible);
                                      default a fixed 1/30 s */
    const char *keys;              /* person: scripted keys for tests, one per frame ("W", "A", "S", "D" held,
                                      '>' Enter, '<' Backspace, '!' Esc, lowercase letters typed, '.' none);
                                      when they run out, Esc; NULL = the keyboard */
    const char *screenshots_dir;   /* write PNGs of the first frame of each test and condition; NULL = none */
    asp_experiment_run_fn on_run;
    asp_experiment_log_fn log;
    /* an unbalanced design (asp_experiment_design_check), shown whatever the verbosity; NULL = log */
    asp_experiment_log_fn warn;
    void *user;
} asp_experiment_desc;

/**
 * Runs the study: prepares the scenes (generated meshes, sampled points,
 * decomposition and primitives, cached in desc->cache_dir), writes
 * DIR/study.json, then for each subject its plan (asp_experiment_plan_draw
 * with the subject's index) test by test, run A and run B, logging every
 * frame as docs/experiment-log.md says. The observer runs on a headless
 * context (EGL), the person in a GLFW window. A subject directory that
 * already holds logs is refused unless desc->resume, which runs only the
 * missing logs (answers.jsonl is only ever appended to). A person's session
 * runs in a GLFW window on the main thread; Esc ends it early, which is not
 * an error (the runs logged so far stay). The decomposition may start MPI:
 * call asp_amg_shutdown once at exit, as after asp_amg_decompose.
 * Returns 0; ASP_EINVAL (bad desc, or a subject directory that holds logs,
 * naming it); ASP_EIO; ASP_EFORMAT (the scene file); the loaders' and
 * renderers' errors; ASP_EGL (no context or window); ASP_ENOMEM.
 */
int asp_experiment_run(const asp_experiment_desc *desc, const asp_context *ctx, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
