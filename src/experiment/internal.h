/*
 * Private parts of the experiment module: the seeded generator every draw of
 * the study uses (so one seed gives one study on every machine), the
 * prepared scenes and the per-frame log writer.
 */
#ifndef ASP_EXPERIMENT_INTERNAL_H
#define ASP_EXPERIMENT_INTERNAL_H

#include <stdio.h>

#include "amgsplat/amgsplat.h"
#include "amgsplat/experiment.h"

/* splitmix64 (Steele et al. 2014): 64-bit state, integer only, so draws match across compilers */
static inline uint64_t asp__exp_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* uniform in [0, n) by rejection (no modulo bias) */
static inline uint64_t asp__exp_below(uint64_t *state, uint64_t n)
{
    uint64_t limit = UINT64_MAX - UINT64_MAX % n;
    uint64_t x;
    do
        x = asp__exp_next(state);
    while (x >= limit);
    return x % n;
}

/* uniform double in [0, 1) from the top 53 bits */
static inline double asp__exp_uniform(uint64_t *state)
{
    return (double)(asp__exp_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* a stream for (seed, a, b): independent draws per subject and purpose */
static inline uint64_t asp__exp_stream(uint64_t seed, uint64_t a, uint64_t b)
{
    uint64_t s = seed ^ (a * 0xD1B54A32D192ED03ull) ^ (b * 0x8CB92BA72F3D8DD7ull);
    (void)asp__exp_next(&s);
    return s;
}

/* ---- prepared scene of one test: every condition's renderer ---- */

typedef struct exp_prepared {
    asp_experiment_scene scene;
    asp_experiment_world world;      /* navigation tests */
    asp_mesh *mesh;                  /* the polygon model (world.mesh for navigation) */
    asp_render_material *materials;
    asp_render_mesh render_mesh;
    asp_cloud *cloud;                /* sampled points */
    asp_dps *dps;                    /* domain primitives */
    size_t dps_level;
    asp_renderer *renderer[ASP_EXPERIMENT_CONDITION_COUNT]; /* blank: NULL */
    double origin[ASP_EXPERIMENT_CONDITION_COUNT][3];       /* each renderer's local frame */
    asp_frame frame;                 /* object: the mesh's framing sphere (world) */
    asp_hier_adapt adapt;            /* points with desc->adapt: the depth controller of seed 004 3.2.5 */
    int adapting;
    float tau;                       /* points: the cut's screen tolerance */
    size_t triangles, points, primitives;
    char model_name[32];
    char points_file[2200], dps_file[2200];
} exp_prepared;

int asp__exp_prepare(const asp_experiment_scenes *scenes, asp_experiment_test test, const char *cache_dir,
                     int short_tests, asp_gl_context *gl, const asp_experiment_desc *desc, const asp_context *ctx,
                     exp_prepared *out, asp_error *err);
void asp__exp_prepared_release(exp_prepared *p);

/* ---- recognition observer: reference features of the candidates ---- */

#define EXP_REF_YAWS 8
#define EXP_MASK 24
#define EXP_HIST 64

typedef struct exp_features {
    int empty;                       /* nothing but background */
    uint8_t mask[EXP_MASK * EXP_MASK];
    float hist[EXP_HIST];            /* normalised colour histogram of the foreground (4 x 4 x 4 bins) */
} exp_features;

void asp__exp_features(const asp_image *img, const uint8_t background[4], exp_features *out);
float asp__exp_feature_score(const exp_features *a, const exp_features *b);

/* ---- log writer (log.c) ---- */

typedef struct exp_log {
    FILE *fp;
    char path[4096];
} exp_log;

int asp__exp_log_open(exp_log *log, const char *path, asp_error *err);
/* writes one cJSON object as one line, flushed; takes ownership of obj */
int asp__exp_log_write(exp_log *log, void *cjson_obj, asp_error *err);
void asp__exp_log_close(exp_log *log);

/* ---- the study and one run (run.c) ---- */

#define DEG (3.14159265358979f / 180.0f)
#define FIXED_DT (1.0 / 30.0)

extern const uint8_t asp__exp_sky[4], asp__exp_backdrop[4];

typedef struct exp_refs {
    exp_features f[ASP_EXPERIMENT_MAX_CANDIDATES][EXP_REF_YAWS];
    size_t count;
} exp_refs;

typedef struct exp_source exp_source;

typedef struct exp_study {
    const asp_experiment_desc *desc;
    const asp_context *ctx;
    asp_gl_context *gl;
    asp_experiment_scenes scenes;
    exp_prepared prep[ASP_EXPERIMENT_TEST_COUNT];
    exp_refs refs;                   /* the observer's reference frames (observer_source.c) */
    uint32_t width, height;
    char cache_dir[4096];
    exp_source *source;              /* where the runs' input comes from: a person or the observer */
    int aborted;                     /* people: Esc ended the session */
} exp_study;

/* one run's running state */
typedef struct exp_run {
    exp_study *st;
    exp_prepared *p;
    asp_experiment_test test;
    asp_experiment_condition cond;
    char run;
    const char *subject;
    uint64_t rng;
    exp_log log;                     /* fp NULL: a practice run, shown and not logged */
    asp_experiment_run_result res;
    double frame_ms_sum;
    double last_t;                   /* t of the last frame logged */
} exp_run;

/* the lines of a run's log (log.c; docs/experiment-log.md) */
int asp__exp_write_header(exp_run *r, int variable, asp_error *err);
int asp__exp_write_frame(exp_run *r, size_t i, double t, double ms, const float pos[3], const float dir[3],
                         size_t drawn, const char *keys, const float *rot, asp_error *err);
int asp__exp_write_event(exp_run *r, double t, const char *what, const char *text, asp_error *err);

/* ---- views (view.c): the cameras of the tests and a condition's frame drawn offscreen ---- */

void asp__exp_first_person(asp_camera *cam, const double origin[3], const float eye[3], float yaw, float pitch,
                           float aspect, float far_plane);
void asp__exp_object_camera(asp_camera *cam, const exp_prepared *p, const double origin[3], float yaw, float pitch,
                            float distance_radii, float aspect);
int asp__exp_draw(exp_study *st, exp_prepared *p, asp_experiment_condition c, const asp_camera *cam,
                  const uint8_t bg[4], asp_image *img, double *ms, size_t *drawn, asp_error *err);

/* ---- input sources and the trial loops (trial.c) ---- */

/*
 * Where a run's input comes from (STYLE.md 9b): a person at the window
 * (window.c) or the machine observer (observer_source.c). The trial loops of
 * trial.c are the same for both: each frame they ask the source to show the
 * view, turn what it saw or what was pressed into a command, and give the
 * time step; the world (asp__exp_nav_move), the camera and the log are theirs.
 */
typedef struct exp_source_ops {
    /* before each frame; 1 = the session is to end (Esc, the window closed, the key script ran out) */
    int (*poll)(exp_source *s);
    /* width / height of the frames */
    float (*aspect)(exp_source *s);
    /* draws run r's frame from cam and shows it (window) or reads it back (observer); naming: the
       recognition's naming stage (a person sees the prompt there). *ms: the time it took; *drawn */
    int (*show)(exp_source *s, exp_run *r, const asp_camera *cam, const uint8_t bg[4], int naming, double *ms,
                size_t *drawn, asp_error *err);
    /* the simulation step after a frame that took ms milliseconds */
    double (*step)(exp_source *s, double ms);
    /* navigation: a run starts (returns the heading's offset from the path's); each frame's command */
    float (*walk_begin)(exp_source *s, exp_run *r);
    void (*walk)(exp_source *s, exp_run *r, double *turn, double *speed, char keys[8]);
    /* recognition: a run starts (the first view); the keys logged; after each frame at time t (step dt)
       look turns the view and returns 1 once recognised, name returns 1 with the answer */
    void (*look_begin)(exp_source *s, exp_run *r, float *yaw, float *pitch);
    void (*look_keys)(exp_source *s, int deciding, char keys[8]);
    int (*look)(exp_source *s, exp_run *r, double t, double dt, float *yaw, float *pitch);
    int (*name)(exp_source *s, exp_run *r, double t, double t_recognised, char answer[32]);
    /* before a test (a person's instruction screen; Esc sets st->aborted); practice: 1 before a practice
       run, 2 the "practice over" screen after the practice (test unused); NULL = none */
    int (*intro)(exp_source *s, asp_experiment_test test, int practice, asp_error *err);
    /* once the tests are prepared (the observer's reference frames); NULL = nothing */
    int (*ready)(exp_source *s, asp_error *err);
    /* frees the source (not the GL context) */
    void (*close)(exp_source *s);
} exp_source_ops;

struct exp_source {
    const exp_source_ops *ops;
    exp_study *st;
    int fixed_step; /* the observer: a fixed time step and a frame budget, so one seed gives one log */
    int warns;      /* a person: the sky turns red while off the path (the observer's frames never do) */
};

/* the sources: each creates st->gl (a window, or a headless context) and *out */
int asp__exp_person_open(exp_study *st, exp_source **out, asp_error *err);
int asp__exp_observer_open(exp_study *st, exp_source **out, asp_error *err);

/* moves the walker or ship one step and keeps it on the path (off_path / collision events) */
int asp__exp_nav_move(exp_run *r, float *x, float *z, float *yaw, double turn, double speed, double dt, double t,
                      float *along, asp_error *err);
/* one run of a test, fed by r->st->source */
int asp__exp_trial_navigation(exp_run *r, asp_error *err);
int asp__exp_trial_recognition(exp_run *r, asp_error *err);

#endif
