/*
 * The machine observer as an input source of the trial loops (trial.c): it
 * is given only the frame read back from the offscreen framebuffer (what it
 * sees is observer.c's), acts one frame late as a person would, and draws its
 * manner (gain, noise, thresholds) from the run's seeded stream, so one seed
 * gives one set of logs (only frame_ms and the start timestamps differ).
 */
#include <math.h>
#include <string.h>

#include "experiment/internal.h"
#include "util/banned.h"

typedef struct observer {
    exp_source base;
    asp_image img;              /* the frame last shown, read back */
    /* navigation: a subject's manner and the command of the frame before */
    double gain, noise, search;
    float steer_cmd, frac_cmd;
    /* recognition: the manner, the candidates' summed scores and the naming time */
    double limit, threshold, turn_rate, confidence, naming;
    double sum[ASP_EXPERIMENT_MAX_CANDIDATES];
    size_t seen, best;
} observer;

static double gauss(uint64_t *s)
{
    /* Box-Muller from two uniforms; deterministic for a stream */
    double u = asp__exp_uniform(s), v = asp__exp_uniform(s);
    return sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * v);
}

static int poll(exp_source *s)
{
    (void)s;
    return 0; // the observer never stops a session
}

static float aspect(exp_source *s)
{
    return (float)s->st->width / (float)s->st->height;
}

/* the observer sees the object while it names it too */
static int show(exp_source *s, exp_run *r, const asp_camera *cam, const uint8_t bg[4], int naming, double *ms,
                size_t *drawn, asp_error *err)
{
    (void)naming;
    observer *o = (observer *)s;
    return asp__exp_draw(s->st, r->p, r->cond, cam, bg, &o->img, ms, drawn, err);
}

/* a fixed step; with desc->realtime the frame's own time, bounded */
static double step(exp_source *s, double ms)
{
    if (!s->st->desc->realtime)
        return FIXED_DT;
    return ms / 1000.0 < 1.0 / 240.0 ? 1.0 / 240.0 : ms / 1000.0 > 0.5 ? 0.5 : ms / 1000.0;
}

/* ---------------------------------------------------------------- navigation */

static float walk_begin(exp_source *s, exp_run *r)
{
    observer *o = (observer *)s;
    /* a subject's manner: steering gain, noise and which way it searches */
    o->gain = 2.2 * (0.85 + 0.3 * asp__exp_uniform(&r->rng));
    o->noise = 0.04 + 0.04 * asp__exp_uniform(&r->rng);
    o->search = asp__exp_uniform(&r->rng) < 0.5 ? -1.0 : 1.0;
    o->steer_cmd = o->frac_cmd = 0.0f; // one frame late: before the first frame it has seen nothing, so it waits
    return (float)(0.1 * gauss(&r->rng));
}

/*
 * The observer walks (low speed) or flies (high speed) where it sees the
 * sandy path or canyon floor: it steers toward the look-ahead centroid of
 * those pixels, one frame late (the command from frame k acts in frame k+1),
 * and stops and turns to search when it sees none. The world, not the
 * observer, keeps it on the path.
 */
static void walk(exp_source *s, exp_run *r, double *pturn, double *pspeed, char keys[8])
{
    observer *o = (observer *)s;
    float frac = 0.0f, steer = 0.0f;
    asp_experiment_see_path(&o->img, 0.45f, 1.0f, &frac, &steer);
    /* act on what the previous frame showed */
    int sees = o->frac_cmd > 0.01f;
    double turn = sees ? -o->gain * (o->steer_cmd + o->noise * gauss(&r->rng)) : o->search * 0.8;
    double max_turn = r->test == ASP_EXPERIMENT_HIGHSPEED ? 2.4 : 1.6; // radians per second: a ship turns faster
    turn = turn > max_turn ? max_turn : turn < -max_turn ? -max_turn : turn;
    double speed = sees ? r->p->scene.speed : 0.0;
    size_t k = 0;
    if (speed > 0.0)
        keys[k++] = 'W';
    if (turn > 0.05)
        keys[k++] = 'A';
    else if (turn < -0.05)
        keys[k++] = 'D';
    keys[k] = 0;
    o->steer_cmd = steer;
    o->frac_cmd = frac;
    *pturn = turn;
    *pspeed = speed;
}

/* ---------------------------------------------------------------- recognition */

static void look_begin(exp_source *s, exp_run *r, float *yaw, float *pitch)
{
    observer *o = (observer *)s;
    o->limit = r->p->scene.time_limit * (s->st->desc->short_tests ? 0.25 : 1.0);
    o->threshold = 0.10 + 0.04 * asp__exp_uniform(&r->rng);
    *yaw = (float)(360.0 * asp__exp_uniform(&r->rng));
    *pitch = 15.0f;
    o->turn_rate = 40.0 + 20.0 * asp__exp_uniform(&r->rng); // degrees per second
    memset(o->sum, 0, sizeof o->sum);
    o->seen = o->best = 0;
    o->confidence = o->naming = 0.0;
}

/* "D": deciding (the key a person holds to turn the object, as the log's keys) */
static void look_keys(exp_source *s, int deciding, char keys[8])
{
    (void)s;
    snprintf(keys, 8, "%s", deciding ? "D" : "");
}

/*
 * The observer turns the object while unsure (it may rotate but not
 * approach: seed 004 2.3), comparing each frame's silhouette and colours with
 * the reference frames of every candidate; it presses Enter once the best
 * candidate's mean score leads the second by its threshold, and its naming
 * time grows with how unsure it still was, so both times depend on the picture.
 */
static int look(exp_source *s, exp_run *r, double t, double dt, float *yaw, float *pitch)
{
    (void)pitch;
    observer *o = (observer *)s;
    const exp_study *st = s->st;
    size_t nc = st->scenes.candidate_count;
    exp_features f;
    asp__exp_features(&o->img, asp__exp_backdrop, &f);
    if (!f.empty) {
        for (size_t c = 0; c < nc; c++) {
            float sc = 0.0f;
            for (int y = 0; y < EXP_REF_YAWS; y++) {
                float v = asp__exp_feature_score(&f, &st->refs.f[c][y]);
                sc = v > sc ? v : sc;
            }
            o->sum[c] += sc;
        }
        o->seen++;
    }
    size_t b = 0, second = nc > 1 ? 1 : 0;
    for (size_t c = 0; c < nc; c++)
        if (o->sum[c] > o->sum[b])
            b = c;
    for (size_t c = 0; c < nc; c++)
        if (c != b && (second == b || o->sum[c] > o->sum[second]))
            second = c;
    o->best = b;
    o->confidence = o->seen && o->sum[b] > 0.0 ? (o->sum[b] - (nc > 1 ? o->sum[second] : 0.0)) / o->sum[b] : 0.0;
    /* at least a quarter second of looking; then the lead must pass the threshold */
    if ((o->seen >= 8 && o->confidence > o->threshold) || t >= o->limit) {
        o->naming = 0.7 + 0.08 * (double)strlen(st->scenes.candidates[b].name) +
                    1.5 * (1.0 - fmin(1.0, o->confidence / (2.0 * o->threshold))) + 0.1 * fabs(gauss(&r->rng));
        return 1;
    }
    *yaw += (float)(o->turn_rate * dt);
    return 0;
}

static int name(exp_source *s, exp_run *r, double t, double t_recognised, char answer[32])
{
    (void)r;
    observer *o = (observer *)s;
    if (t < t_recognised + o->naming)
        return 0;
    snprintf(answer, 32, "%s", o->seen ? s->st->scenes.candidates[o->best].name : "unknown");
    return 1;
}

/* ---------------------------------------------------------------- setup */

/* the reference frames of every candidate: polygons, EXP_REF_YAWS yaws around it, from the default distance */
static int ready(exp_source *s, asp_error *err)
{
    exp_study *st = s->st;
    st->refs.count = st->scenes.candidate_count;
    int rc = 0;
    for (size_t c = 0; c < st->scenes.candidate_count && !rc; c++) {
        const asp_experiment_candidate *k = &st->scenes.candidates[c];
        asp_mesh *mesh = NULL;
        asp_render_material *mats = NULL;
        asp_renderer *rend = NULL;
        exp_prepared tmp;
        memset(&tmp, 0, sizeof tmp);
        rc = asp_mesh_load(k->model, &(asp_mesh_load_desc){.up = k->up}, st->ctx, &mesh, err);
        if (!rc)
            rc = asp_scene_mesh_frame(mesh, &tmp.frame, err);
        if (!rc && !(mats = asp_calloc(st->ctx, mesh->material_count, sizeof *mats)))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for materials");
        asp_render_mesh rm;
        if (!rc) {
            asp_scene_mesh_describe(mesh, mats, &rm);
            asp_mesh_renderer_desc md = {0};
            memcpy(md.origin, mesh->origin, sizeof md.origin);
            rc = asp_mesh_renderer_create(st->gl, &rm, &md, &rend, err);
        }
        for (int y = 0; y < EXP_REF_YAWS && !rc; y++) {
            tmp.renderer[0] = rend;
            asp_camera cam;
            asp__exp_object_camera(&cam, &tmp, mesh->origin, 360.0f * (float)y / EXP_REF_YAWS, 15.0f, 0.0f,
                                   (float)st->width / (float)st->height);
            asp_image img = {0};
            double ms;
            size_t drawn;
            rc = asp__exp_draw(st, &tmp, ASP_EXPERIMENT_POLYGONS, &cam, asp__exp_backdrop, &img, &ms, &drawn, err);
            if (!rc)
                asp__exp_features(&img, asp__exp_backdrop, &st->refs.f[c][y]);
            asp_image_release(&img);
        }
        asp_renderer_destroy(rend);
        asp_free(st->ctx, mats);
        asp_mesh_destroy(mesh);
    }
    return rc;
}

static void close_observer(exp_source *s)
{
    observer *o = (observer *)s;
    asp_image_release(&o->img);
    asp_free(s->st->ctx, o);
}

static const exp_source_ops observer_ops = {
    .poll = poll,
    .aspect = aspect,
    .show = show,
    .step = step,
    .walk_begin = walk_begin,
    .walk = walk,
    .look_begin = look_begin,
    .look_keys = look_keys,
    .look = look,
    .name = name,
    .ready = ready,
    .close = close_observer,
};

int asp__exp_observer_open(exp_study *st, exp_source **out, asp_error *err)
{
    observer *o = asp_calloc(st->ctx, 1, sizeof *o);
    if (!o)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    int rc = asp_gl_context_create_headless(NULL, st->ctx, &st->gl, err);
    if (rc) {
        asp_free(st->ctx, o);
        return rc;
    }
    o->base = (exp_source){.ops = &observer_ops, .st = st, .fixed_step = 1};
    *out = &o->base;
    return 0;
}
