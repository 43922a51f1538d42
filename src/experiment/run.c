/*
 * The experiment program of seed 004 2.3: for each subject the four tests in
 * a random order, each run twice (A polygons; B polygons or the variable
 * condition), every frame logged (docs/experiment-log.md). The machine
 * observer sees only the frame read back from the framebuffer; the simulation
 * advances by a fixed time step so one seed gives one set of logs (only
 * frame_ms and the start timestamps differ between runs).
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "experiment/internal.h"
#include "util/atomic_file.h"
#include "util/json_file.h"
#include "util/banned.h"


const uint8_t asp__exp_sky[4] = {150, 190, 230, 255};      /* navigation background: bluish, never sandy */
const uint8_t asp__exp_backdrop[4] = {40, 40, 48, 255};    /* recognition background */

static void say(const exp_study *st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void say(const exp_study *st, const char *fmt, ...)
{
    if (!st->desc->log)
        return;
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    st->desc->log(st->desc->user, line);
}

/* paths under DIR: DIR is checked to be under 2048 bytes, so these never truncate */
static void pathf(char *dst, size_t cap, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void pathf(char *dst, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dst, cap, fmt, ap);
    va_end(ap);
}

static int make_dir(const char *path, asp_error *err)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST) {
        struct stat sb;
        if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
            return 0;
        return asp_error_set(err, ASP_EIO, "'%s' exists and is not a directory", path);
    }
    return asp_error_set(err, ASP_EIO, "cannot create directory '%s': %s", path, strerror(errno));
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static double gauss(uint64_t *s)
{
    /* Box-Muller from two uniforms; deterministic for a stream */
    double u = asp__exp_uniform(s), v = asp__exp_uniform(s);
    return sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * v);
}

static cJSON *vec3(const float v[3])
{
    double d[3] = {v[0], v[1], v[2]};
    return cJSON_CreateDoubleArray(d, 3);
}

/* ---------------------------------------------------------------- drawing */

/* the first-person camera: eye at eye (world), heading yaw (0 = +z), pitch (negative looks down) */
void asp__exp_first_person(asp_camera *cam, const double origin[3], const float eye[3], float yaw, float pitch,
                         float aspect, float far_plane)
{
    asp_camera_init(cam);
    float f[3] = {cosf(pitch) * sinf(yaw), sinf(pitch), cosf(pitch) * cosf(yaw)};
    for (int k = 0; k < 3; k++)
        cam->target[k] = (float)(eye[k] - origin[k]) + f[k];
    cam->distance = 1.0f;
    cam->azimuth = yaw / DEG + 180.0f;  // the eye sits at target - f
    cam->elevation = -pitch / DEG;
    cam->fov_y = 50.0f;
    cam->aspect = aspect;
    cam->z_near = 0.05f;
    cam->z_far = far_plane;
}

void asp__exp_object_camera(asp_camera *cam, const exp_prepared *p, const double origin[3], float yaw, float pitch,
                          float distance_radii, float aspect)
{
    asp_camera_init(cam);
    cam->azimuth = yaw;
    cam->elevation = pitch;
    cam->fov_y = 40.0f;
    asp_camera_frame(cam, &p->frame, origin, aspect, distance_radii);
}

/* draws one frame of condition c and reads it back (the observer's only input); blank = background only */
int asp__exp_draw(exp_study *st, exp_prepared *p, asp_experiment_condition c, const asp_camera *cam,
                const uint8_t bg[4], asp_image *img, double *ms, size_t *drawn, asp_error *err)
{
    asp_image_release(img);
    double t0 = asp_time_now();
    int rc = 0;
    if (c == ASP_EXPERIMENT_BLANK) {
        rc = asp_image_init(img, st->width, st->height, err);
        if (!rc)
            asp_image_fill(img, bg);
        *drawn = 0;
    } else {
        if (c == ASP_EXPERIMENT_POINTS && p->adapting) {
            rc = asp_renderer_set_lod(p->renderer[c], p->tau, p->adapt.depth, err);
            if (rc)
                return rc;
        }
        asp_render_desc rd = {.width = st->width, .height = st->height, .light_elevation = 45.0f};
        memcpy(rd.background, bg, 4);
        rc = asp_render_to_image(st->gl, p->renderer[c], cam, &rd, img, err);
        *drawn = rc ? 0 : asp_renderer_count(p->renderer[c]);
    }
    *ms = 1000.0 * (asp_time_now() - t0);
    if (!rc && c == ASP_EXPERIMENT_POINTS && p->adapting)
        asp_hier_adapt_update(&p->adapt, *ms / 1000.0, 1); // every frame of a run moves the view: an event
    return rc;
}

/* ---------------------------------------------------------------- logging */

static void iso_now(char *buf, size_t cap)
{
    time_t now = time(NULL);
    struct tm tmv;
    gmtime_r(&now, &tmv);
    strftime(buf, cap, "%Y-%m-%dT%H:%M:%SZ", &tmv);
}

int asp__exp_write_header(exp_run *r, int variable, asp_error *err)
{
    exp_study *st = r->st;
    exp_prepared *p = r->p;
    char started[32];
    iso_now(started, sizeof started);
    cJSON *h = cJSON_CreateObject();
    cJSON_AddStringToObject(h, "type", "header");
    cJSON_AddStringToObject(h, "format", "amgsplat-experiment-log 1");
    cJSON_AddStringToObject(h, "subject", r->subject);
    cJSON_AddStringToObject(h, "group", variable ? "variable" : "control");
    cJSON_AddStringToObject(h, "test", asp_experiment_test_name(r->test));
    cJSON_AddStringToObject(h, "run", r->run == 'A' ? "A" : "B");
    cJSON_AddStringToObject(h, "condition", asp_experiment_condition_name(r->cond));
    cJSON_AddNumberToObject(h, "seed", (double)st->desc->seed);
    cJSON_AddStringToObject(h, "version", ASP_VERSION_STRING);
    cJSON_AddBoolToObject(h, "observer", st->desc->observer != 0);
    double screen[2] = {st->width, st->height};
    cJSON_AddItemToObject(h, "screen", cJSON_CreateDoubleArray(screen, 2));
    cJSON_AddStringToObject(h, "started", started);
    if (p->scene.kind != 0) {
        cJSON *path = cJSON_AddArrayToObject(h, "path");
        for (size_t i = 0; path && i < p->world.path_count; i++)
            cJSON_AddItemToArray(path, vec3(&p->world.path[3 * i]));
        cJSON_AddNumberToObject(h, "half_width", p->world.half_width);
    } else {
        cJSON *c = cJSON_AddArrayToObject(h, "candidates");
        for (size_t i = 0; c && i < st->scenes.candidate_count; i++)
            cJSON_AddItemToArray(c, cJSON_CreateString(st->scenes.candidates[i].name));
        cJSON_AddStringToObject(h, "answer_expected", p->model_name);
    }
    cJSON *d = cJSON_AddObjectToObject(h, "drawn");
    if (d) {
        cJSON_AddNumberToObject(d, "triangles", (double)p->triangles);
        cJSON_AddNumberToObject(d, "points", (double)p->points);
        cJSON_AddNumberToObject(d, "primitives", (double)p->primitives);
    }
    return asp__exp_log_write(&r->log, h, err);
}

int asp__exp_write_frame(exp_run *r, size_t i, double t, double ms, const float pos[3], const float dir[3],
                       size_t drawn, const char *keys, const float *rot, asp_error *err)
{
    cJSON *f = cJSON_CreateObject();
    cJSON_AddStringToObject(f, "type", "frame");
    cJSON_AddNumberToObject(f, "i", (double)i);
    cJSON_AddNumberToObject(f, "t", t);
    cJSON_AddNumberToObject(f, "frame_ms", round(ms * 1000.0) / 1000.0);
    cJSON_AddItemToObject(f, "pos", vec3(pos));
    cJSON_AddItemToObject(f, "dir", vec3(dir));
    cJSON_AddNumberToObject(f, "drawn", (double)drawn);
    cJSON_AddStringToObject(f, "keys", keys);
    if (rot) {
        double d[2] = {rot[0], rot[1]};
        cJSON_AddItemToObject(f, "rot", cJSON_CreateDoubleArray(d, 2));
    }
    r->frame_ms_sum += ms;
    r->last_t = t;
    r->res.frames++;
    r->res.drawn = drawn;
    return asp__exp_log_write(&r->log, f, err);
}

int asp__exp_write_event(exp_run *r, double t, const char *what, const char *text, asp_error *err)
{
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "type", "event");
    cJSON_AddNumberToObject(e, "t", t);
    cJSON_AddStringToObject(e, "what", what);
    if (text)
        cJSON_AddStringToObject(e, "text", text);
    return asp__exp_log_write(&r->log, e, err);
}

/* ---------------------------------------------------------------- navigation */

/*
 * Moves the walker or ship by one step and keeps it on the path: leaving it is
 * an off_path event (low speed) or a collision (high speed) and a bump back
 * inside (seed 004 2.3). The world does this, not the observer or the person.
 */
int asp__exp_nav_move(exp_run *r, float *px, float *pz, float *pyaw, double turn, double speed, double dt, double t,
                      float *along, asp_error *err)
{
    const asp_experiment_world *w = &r->p->world;
    int high = r->test == ASP_EXPERIMENT_HIGHSPEED;
    float x = *px, z = *pz, yaw = *pyaw;
    int rc = 0;
    yaw += (float)(turn * dt);
    x += (float)(speed * dt) * sinf(yaw);
    z += (float)(speed * dt) * cosf(yaw);
    float pd[2];
    float d = asp_experiment_path_nearest(w->path, w->path_count, x, z, along, pd);
    if (d > w->half_width) {
        /* bumped back inside (seed 004 2.3: off the path a warning, then back onto it) */
        float nx = w->path[0], nz = w->path[2], best = INFINITY;
        for (size_t s = 0; s < w->path_count; s++) {
            float ddx = w->path[3 * s] - x, ddz = w->path[3 * s + 2] - z, dd = ddx * ddx + ddz * ddz;
            if (dd < best) {
                best = dd;
                nx = w->path[3 * s];
                nz = w->path[3 * s + 2];
            }
        }
        x = nx + 0.6f * (x - nx) * w->half_width / d;
        z = nz + 0.6f * (z - nz) * w->half_width / d;
        /* a wall or the path's edge turns the heading halfway back along the path, as a ship slides along a wall */
        float along_yaw = atan2f(pd[0], pd[1]), diff = along_yaw - yaw;
        diff = atan2f(sinf(diff), cosf(diff));
        yaw += 0.5f * diff;
        r->res.off_path++;
        rc = asp__exp_write_event(r, t, high ? "collision" : "off_path", NULL, err);
    }
    *px = x;
    *pz = z;
    *pyaw = yaw;
    return rc;
}

/*
 * The observer walks (low speed) or flies (high speed) where it sees the
 * sandy path or canyon floor: it steers toward the look-ahead centroid of
 * those pixels, one frame late (the command from frame k acts in frame k+1),
 * and stops and turns to search when it sees none. The world, not the
 * observer, keeps it on the path: leaving it is an off_path event and a bump
 * back (seed 004 2.3), touching a canyon wall a collision.
 */
static int run_navigation(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_prepared *p = r->p;
    const asp_experiment_world *w = &p->world;
    int high = r->test == ASP_EXPERIMENT_HIGHSPEED;
    float pitch = (high ? -8.0f : -14.0f) * DEG;
    double dt = FIXED_DT;
    double limit = p->scene.time_limit * (st->desc->short_tests ? 0.1 : 1.0);
    size_t frames = (size_t)ceil(limit / dt);
    /* a subject's manner: steering gain, noise and which way it searches */
    double gain = 2.2 * (0.85 + 0.3 * asp__exp_uniform(&r->rng));
    double noise = 0.04 + 0.04 * asp__exp_uniform(&r->rng);
    double search = asp__exp_uniform(&r->rng) < 0.5 ? -1.0 : 1.0;
    float x = w->path[0], z = w->path[2];
    float yaw = atan2f(w->path[3] - w->path[0], w->path[5] - w->path[2]) + (float)(0.1 * gauss(&r->rng));
    float steer_cmd = 0.0f, frac_cmd = 0.0f; // one frame late: before the first frame it has seen nothing, so it waits
    asp_image img = {0};
    char keys[4];
    int rc = 0;
    float along = 0.0f;
    double t = 0.0;
    for (size_t i = 0; i < frames && !rc; i++) {
        float ground = asp_experiment_world_height(w, x, z);
        float eye[3] = {x, ground + p->scene.eye_height, z};
        float dir[3] = {sinf(yaw), 0.0f, cosf(yaw)};
        asp_camera cam;
        asp__exp_first_person(&cam, p->origin[r->cond], eye, yaw, pitch, (float)st->width / (float)st->height,
                     1.5f * w->size);
        double ms = 0.0;
        size_t drawn = 0;
        rc = asp__exp_draw(st, p, r->cond, &cam, asp__exp_sky, &img, &ms, &drawn, err);
        if (rc)
            break;
        float frac = 0.0f, steer = 0.0f;
        asp_experiment_see_path(&img, 0.45f, 1.0f, &frac, &steer);
        /* act on what the previous frame showed */
        int sees = frac_cmd > 0.01f;
        double turn = sees ? -gain * (steer_cmd + noise * gauss(&r->rng)) : search * 0.8;
        double max_turn = high ? 2.4 : 1.6; // radians per second: a ship turns faster than a walker
        turn = turn > max_turn ? max_turn : turn < -max_turn ? -max_turn : turn;
        double speed = sees ? p->scene.speed : 0.0;
        size_t k = 0;
        if (speed > 0.0)
            keys[k++] = 'W';
        if (turn > 0.05)
            keys[k++] = 'A';
        else if (turn < -0.05)
            keys[k++] = 'D';
        keys[k] = 0;
        float logged[3] = {eye[0], ground, eye[2]};
        rc = asp__exp_write_frame(r, i, t, ms, logged, dir, drawn, keys, NULL, err);
        steer_cmd = steer;
        frac_cmd = frac;
        if (rc)
            break;
        if (st->desc->realtime)
            dt = ms / 1000.0 < 1.0 / 240.0 ? 1.0 / 240.0 : ms / 1000.0 > 0.5 ? 0.5 : ms / 1000.0;
        t += dt;
        rc = asp__exp_nav_move(r, &x, &z, &yaw, turn, speed, dt, t, &along, err);
        if (!rc && along >= 0.995f)
            break;
    }
    asp_image_release(&img);
    r->res.progress = along;
    return rc;
}

/* ---------------------------------------------------------------- recognition */

/*
 * The observer turns the object while unsure (it may rotate but not
 * approach: seed 004 2.3), comparing each frame's silhouette and colours with
 * the reference frames of every candidate; it presses Enter once the best
 * candidate's mean score leads the second by its threshold, and its naming
 * time grows with how unsure it still was, so both times depend on the picture.
 */
static int run_recognition(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_prepared *p = r->p;
    size_t nc = st->scenes.candidate_count;
    double dt = FIXED_DT, t = 0.0;
    double limit = p->scene.time_limit * (st->desc->short_tests ? 0.25 : 1.0);
    double threshold = 0.10 + 0.04 * asp__exp_uniform(&r->rng);
    float yaw = (float)(360.0 * asp__exp_uniform(&r->rng)), pitch = 15.0f;
    double turn_rate = 40.0 + 20.0 * asp__exp_uniform(&r->rng); // degrees per second
    double sum[ASP_EXPERIMENT_MAX_CANDIDATES] = {0};
    size_t seen = 0, best = 0;
    double confidence = 0.0, t_recognised = -1.0, naming = 0.0;
    asp_image img = {0};
    int rc = 0;
    for (size_t i = 0; !rc; i++) {
        asp_camera cam;
        asp__exp_object_camera(&cam, p, p->origin[r->cond], yaw, pitch, p->scene.distance_radii,
                      (float)st->width / (float)st->height);
        double ms = 0.0;
        size_t drawn = 0;
        rc = asp__exp_draw(st, p, r->cond, &cam, asp__exp_backdrop, &img, &ms, &drawn, err);
        if (rc)
            break;
        int deciding = t_recognised < 0.0;
        float eye[3];
        asp_camera_eye(&cam, eye);
        float dir[3] = {cam.target[0] - eye[0], cam.target[1] - eye[1], cam.target[2] - eye[2]};
        float len = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int k = 0; k < 3; k++) {
            dir[k] = len > 0.0f ? dir[k] / len : 0.0f;
            eye[k] = (float)(eye[k] + p->origin[r->cond][k]);
        }
        float rot[2] = {yaw, pitch};
        rc = asp__exp_write_frame(r, i, t, ms, eye, dir, drawn, deciding ? "D" : "", rot, err);
        if (rc)
            break;
        if (deciding) {
            exp_features f;
            asp__exp_features(&img, asp__exp_backdrop, &f);
            if (!f.empty) {
                for (size_t c = 0; c < nc; c++) {
                    float s = 0.0f;
                    for (int y = 0; y < EXP_REF_YAWS; y++) {
                        float v = asp__exp_feature_score(&f, &st->refs.f[c][y]);
                        s = v > s ? v : s;
                    }
                    sum[c] += s;
                }
                seen++;
            }
            size_t b = 0, second = nc > 1 ? 1 : 0;
            for (size_t c = 0; c < nc; c++)
                if (sum[c] > sum[b])
                    b = c;
            for (size_t c = 0; c < nc; c++)
                if (c != b && (second == b || sum[c] > sum[second]))
                    second = c;
            best = b;
            confidence = seen && sum[b] > 0.0 ? (sum[b] - (nc > 1 ? sum[second] : 0.0)) / sum[b] : 0.0;
            /* at least a quarter second of looking; then the lead must pass the threshold */
            if ((seen >= 8 && confidence > threshold) || t + dt >= limit) {
                t_recognised = t + dt;
                naming = 0.7 + 0.08 * (double)strlen(st->scenes.candidates[b].name) +
                         1.5 * (1.0 - fmin(1.0, confidence / (2.0 * threshold))) + 0.1 * fabs(gauss(&r->rng));
                rc = asp__exp_write_event(r, t_recognised, "recognised", NULL, err);
            } else {
                yaw += (float)(turn_rate * dt);
            }
        } else if (t + dt >= t_recognised + naming) {
            const char *answer = seen ? st->scenes.candidates[best].name : "unknown";
            snprintf(r->res.answer, sizeof r->res.answer, "%s", answer);
            r->res.correct = strcmp(answer, p->model_name) == 0;
            r->res.recognition_s = t_recognised;
            r->res.naming_s = t + dt - t_recognised;
            rc = asp__exp_write_event(r, t + dt, "answer", answer, err);
            t += dt;
            break;
        }
        t += dt;
    }
    asp_image_release(&img);
    return rc;
}

int asp__exp_append_answer(exp_run *r, const char *subject_dir, asp_error *err)
{
    char path[4200];
    pathf(path, sizeof path, "%s/answers.jsonl", subject_dir);
    exp_log a;
    int rc = asp__exp_log_open(&a, path, err);
    if (rc)
        return rc;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "subject", r->subject);
    cJSON_AddStringToObject(o, "test", asp_experiment_test_name(r->test));
    cJSON_AddStringToObject(o, "run", r->run == 'A' ? "A" : "B");
    cJSON_AddStringToObject(o, "condition", asp_experiment_condition_name(r->cond));
    cJSON_AddNumberToObject(o, "recognition_s", round(r->res.recognition_s * 1e6) / 1e6);
    cJSON_AddNumberToObject(o, "naming_s", round(r->res.naming_s * 1e6) / 1e6);
    cJSON_AddStringToObject(o, "answer", r->res.answer);
    cJSON_AddBoolToObject(o, "correct", r->res.correct);
    rc = asp__exp_log_write(&a, o, err);
    asp__exp_log_close(&a);
    return rc;
}

static int run_one(exp_study *st, const char *subject, size_t subject_index, const char *subject_dir,
                   asp_experiment_test test, char run, asp_experiment_condition cond, int variable,
                   asp_error *err)
{
    char path[4200];
    pathf(path, sizeof path, "%s/%s-%c.jsonl", subject_dir, asp_experiment_test_name(test), run);
    if (exists(path)) {
        /* only reachable with resume: a log is never rewritten or appended to twice */
        say(st, "%s %s-%c: log exists, kept", subject, asp_experiment_test_name(test), run);
        return 0;
    }
    exp_run r;
    memset(&r, 0, sizeof r);
    r.st = st;
    r.p = &st->prep[test];
    r.test = test;
    r.cond = cond;
    r.run = run;
    r.subject = subject;
    r.rng = asp__exp_stream(st->desc->seed, (uint64_t)subject_index + 1, 0x100u + 2u * (unsigned)test + (run == 'B'));
    snprintf(r.res.subject, sizeof r.res.subject, "%s", subject);
    r.res.test = test;
    r.res.run = run;
    r.res.condition = cond;
    r.res.variable = variable;
    int rc = asp__exp_log_open(&r.log, path, err);
    if (rc)
        return rc;
    rc = asp__exp_write_header(&r, variable, err);
    double t_end = 0.0;
    if (!rc && !st->desc->observer)
        rc = asp__exp_window_instructions(st, test, 0, err);
    if (!rc && !st->aborted) {
        if (st->desc->observer)
            rc = test <= ASP_EXPERIMENT_NEAR ? run_recognition(&r, err) : run_navigation(&r, err);
        else
            rc = test <= ASP_EXPERIMENT_NEAR ? asp__exp_window_recognition(&r, err)
                                             : asp__exp_window_navigation(&r, err);
    } else if (!rc) {
        rc = asp__exp_write_event(&r, 0.0, "abort", NULL, err);
    }
    if (!rc) {
        t_end = st->desc->observer ? (double)r.res.frames * FIXED_DT : r.last_t;
        rc = asp__exp_write_event(&r, t_end, "end", NULL, err);
    }
    asp__exp_log_close(&r.log);
    if (!rc && test <= ASP_EXPERIMENT_NEAR && r.res.answer[0])
        rc = asp__exp_append_answer(&r, subject_dir, err);
    if (rc)
        return rc;
    r.res.mean_frame_ms = r.res.frames ? r.frame_ms_sum / (double)r.res.frames : 0.0;
    if (st->desc->on_run)
        st->desc->on_run(st->desc->user, &r.res);
    return 0;
}

/* ---------------------------------------------------------------- study setup */

static int make_references(exp_study *st, asp_error *err)
{
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

static int write_study(exp_study *st, char subjects[][32], size_t nsubjects, const char *path, asp_error *err)
{
    const asp_experiment_desc *d = st->desc;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "format", "amgsplat-study 1");
    cJSON_AddNumberToObject(root, "seed", (double)d->seed);
    cJSON_AddStringToObject(root, "version", ASP_VERSION_STRING);
    cJSON *subj = cJSON_AddArrayToObject(root, "subjects");
    for (size_t i = 0; i < nsubjects; i++)
        cJSON_AddItemToArray(subj, cJSON_CreateString(subjects[i]));
    cJSON *tests = cJSON_AddArrayToObject(root, "tests"), *conds = cJSON_AddArrayToObject(root, "conditions");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        cJSON_AddItemToArray(tests, cJSON_CreateString(asp_experiment_test_name((asp_experiment_test)t)));
    for (int c = 0; c < 3; c++)
        cJSON_AddItemToArray(conds, cJSON_CreateString(asp_experiment_condition_name((asp_experiment_condition)c)));
    cJSON_AddBoolToObject(root, "observer", d->observer != 0);
    cJSON *scenes = cJSON_AddObjectToObject(root, "scenes");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        const exp_prepared *p = &st->prep[t];
        cJSON *o = cJSON_AddObjectToObject(scenes, asp_experiment_test_name((asp_experiment_test)t));
        if (p->scene.kind == 0) {
            cJSON_AddStringToObject(o, "kind", "object");
            cJSON_AddStringToObject(o, "model", p->model_name);
            for (size_t c = 0; c < st->scenes.candidate_count; c++)
                if (strcmp(st->scenes.candidates[c].name, p->model_name) == 0)
                    cJSON_AddStringToObject(o, "file", st->scenes.candidates[c].model);
            cJSON_AddNumberToObject(o, "distance_radii", p->scene.distance_radii);
        } else {
            cJSON_AddStringToObject(o, "kind", p->scene.kind == 1 ? "terrain" : "canyon");
            cJSON_AddNumberToObject(o, "generator_seed", (double)p->scene.seed);
            cJSON_AddNumberToObject(o, "grid", p->scene.grid);
            cJSON_AddNumberToObject(o, "size", p->scene.size);
            cJSON_AddNumberToObject(o, "half_width", p->scene.half_width);
            cJSON_AddNumberToObject(o, "speed", p->scene.speed);
        }
        cJSON_AddNumberToObject(o, "triangles", (double)p->triangles);
        cJSON_AddNumberToObject(o, "points", (double)p->points);
        cJSON_AddNumberToObject(o, "primitives", (double)p->primitives);
        cJSON_AddNumberToObject(o, "points_tolerance_px", d->coarse_tau > 0.0f ? d->coarse_tau : 1.0);
        cJSON_AddNumberToObject(o, "points_depth_limit", d->depth_limit);
        cJSON_AddStringToObject(o, "points_file", p->points_file);
        cJSON_AddStringToObject(o, "primitives_file", p->dps_file);
    }
    return asp__json_save(root, path, err);
}

/* PNGs of every test in every condition from its start view, for the docs and for checking a lab's scenes */
static int write_screenshots(exp_study *st, asp_error *err)
{
    int rc = make_dir(st->desc->screenshots_dir, err);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT && !rc; t++) {
        exp_prepared *p = &st->prep[t];
        for (int c = 0; c < ASP_EXPERIMENT_CONDITION_COUNT && !rc; c++) {
            asp_camera cam;
            const uint8_t *bg = p->scene.kind ? asp__exp_sky : asp__exp_backdrop;
            if (p->scene.kind) {
                const asp_experiment_world *w = &p->world;
                float yaw = atan2f(w->path[3 * 6] - w->path[0], w->path[3 * 6 + 2] - w->path[2]);
                float eye[3] = {w->path[0], w->path[1] + p->scene.eye_height, w->path[2]};
                asp__exp_first_person(&cam, p->origin[c], eye, yaw, (t == ASP_EXPERIMENT_HIGHSPEED ? -8.0f : -14.0f) * DEG,
                             (float)st->width / (float)st->height, 1.5f * w->size);
            } else {
                asp__exp_object_camera(&cam, p, p->origin[c], 30.0f, 15.0f, p->scene.distance_radii,
                              (float)st->width / (float)st->height);
            }
            asp_image img = {0};
            double ms;
            size_t drawn;
            rc = asp__exp_draw(st, p, (asp_experiment_condition)c, &cam, bg, &img, &ms, &drawn, err);
            char path[4300];
            pathf(path, sizeof path, "%s/%s-%s.png", st->desc->screenshots_dir,
                     asp_experiment_test_name((asp_experiment_test)t),
                     asp_experiment_condition_name((asp_experiment_condition)c));
            if (!rc)
                rc = asp_image_save_png(&img, path, err);
            asp_image_release(&img);
        }
    }
    return rc;
}

static int subject_id_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= 32)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_'))
            return 0;
    }
    return 1;
}

static int has_logs(const char *dir)
{
    char path[4200];
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        for (int r = 0; r < 2; r++) {
            pathf(path, sizeof path, "%s/%s-%c.jsonl", dir, asp_experiment_test_name((asp_experiment_test)t),
                     r ? 'B' : 'A');
            if (exists(path))
                return 1;
        }
    pathf(path, sizeof path, "%s/answers.jsonl", dir);
    return exists(path);
}

/* a person's practice: a quarter of the walking test in polygons, shown but not logged */
static int practice(exp_study *st, asp_error *err)
{
    exp_run r;
    memset(&r, 0, sizeof r);
    r.st = st;
    r.p = &st->prep[ASP_EXPERIMENT_LOWSPEED];
    r.test = ASP_EXPERIMENT_LOWSPEED;
    r.cond = ASP_EXPERIMENT_POLYGONS;
    r.run = 'A';
    r.subject = "practice";
    int rc = asp__exp_window_instructions(st, ASP_EXPERIMENT_LOWSPEED, 1, err);
    if (!rc && !st->aborted)
        rc = asp__exp_window_navigation(&r, err); // r.log.fp NULL: nothing is written
    return rc;
}

int asp_experiment_run(const asp_experiment_desc *desc, const asp_context *ctx, asp_error *err)
{
    ASP_ASSERT(desc);
    if (!desc->output_dir || !desc->output_dir[0] || strlen(desc->output_dir) >= 2048)
        return asp_error_set(err, ASP_EINVAL, "no output directory, or one over 2047 bytes");
    if ((desc->cache_dir && strlen(desc->cache_dir) >= 2048) ||
        (desc->screenshots_dir && strlen(desc->screenshots_dir) >= 2048))
        return asp_error_set(err, ASP_EINVAL, "cache or screenshot directory over 2047 bytes");
    if (!desc->observer && !desc->subject)
        return asp_error_set(err, ASP_EINVAL, "a person's session needs a subject id");
    size_t nsubjects = desc->subjects ? desc->subjects : 1;
    if (nsubjects > 999)
        return asp_error_set(err, ASP_EINVAL, "at most 999 subjects, got %zu", nsubjects);
    if (desc->subject && !subject_id_ok(desc->subject))
        return asp_error_set(err, ASP_EINVAL, "subject id '%s' must be 1..31 letters, digits, '-' or '_'",
                             desc->subject);
    if (desc->width > 4096 || desc->height > 4096 || (desc->width && desc->width < 32) ||
        (desc->height && desc->height < 32))
        return asp_error_set(err, ASP_EINVAL, "frame size must be 32..4096 pixels a side");
    static const asp_experiment_condition default_variable[2] = {ASP_EXPERIMENT_POINTS, ASP_EXPERIMENT_PRIMITIVES};
    const asp_experiment_condition *variable = desc->variable ? desc->variable : default_variable;
    size_t nvariable = desc->variable ? desc->variable_count : 2;
    asp_experiment_plan probe;
    int rc = asp_experiment_plan_draw(desc->seed, 0, variable, nvariable, desc->group_rule, &probe, err);
    if (rc)
        return rc;

    char (*subjects)[32] = asp_calloc(ctx, nsubjects, 32);
    exp_study *st = asp_calloc(ctx, 1, sizeof *st);
    if (!subjects || !st) {
        asp_free(ctx, subjects);
        asp_free(ctx, st);
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    }
    if (desc->subject && nsubjects == 1)
        snprintf(subjects[0], 32, "%s", desc->subject);
    else
        for (size_t i = 0; i < nsubjects; i++)
            snprintf(subjects[i], 32, "S%02zu", i + 1);
    st->desc = desc;
    st->ctx = ctx;
    st->width = desc->width ? desc->width : desc->observer ? 160 : 1024;
    st->height = desc->height ? desc->height : desc->observer ? 120 : 640;

    char path[4200];
    rc = make_dir(desc->output_dir, err);
    pathf(path, sizeof path, "%s/study.json", desc->output_dir);
    int study_exists = exists(path);
    for (size_t i = 0; i < nsubjects && !rc && !desc->resume; i++) {
        char dir[4200];
        pathf(dir, sizeof dir, "%s/%s", desc->output_dir, subjects[i]);
        if (has_logs(dir))
            rc = asp_error_set(err, ASP_EINVAL,
                               "subject '%s' already has logs in '%s': a subject's answers are never overwritten "
                               "(--resume adds the missing runs)",
                               subjects[i], dir);
    }
    if (!rc) {
        if (desc->scenes_path)
            rc = asp_experiment_scenes_load(desc->scenes_path, &st->scenes, err);
        else
            asp_experiment_scenes_default(&st->scenes);
    }
    pathf(path, sizeof path, "%s/scenes.json", desc->output_dir);
    if (!rc && !exists(path))
        rc = asp_experiment_scenes_save(&st->scenes, path, err);
    if (desc->cache_dir)
        snprintf(st->cache_dir, sizeof st->cache_dir, "%s", desc->cache_dir);
    else
        snprintf(st->cache_dir, sizeof st->cache_dir, "%s/scenes", desc->output_dir);
    if (!rc)
        rc = make_dir(st->cache_dir, err);
    if (!rc)
        rc = desc->observer ? asp_gl_context_create_headless(NULL, ctx, &st->gl, err)
                            : asp__exp_window_open(st, err);
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT && !rc; t++) {
        say(st, "preparing %s", asp_experiment_test_name((asp_experiment_test)t));
        rc = asp__exp_prepare(&st->scenes, (asp_experiment_test)t, st->cache_dir, desc->short_tests, st->gl, desc,
                              ctx, &st->prep[t], err);
    }
    if (!rc && desc->observer)
        rc = make_references(st, err);
    pathf(path, sizeof path, "%s/study.json", desc->output_dir);
    if (!rc && !study_exists)
        rc = write_study(st, subjects, nsubjects, path, err);
    if (!rc && desc->screenshots_dir)
        rc = write_screenshots(st, err);
    if (!rc && !desc->observer && desc->practice)
        rc = practice(st, err);
    for (size_t s = 0; s < nsubjects && !rc && !st->aborted; s++) {
        asp_experiment_plan plan;
        char dir[4200];
        pathf(dir, sizeof dir, "%s/%s", desc->output_dir, subjects[s]);
        rc = make_dir(dir, err);
        if (!rc)
            rc = asp_experiment_plan_draw(desc->seed, s, variable, nvariable, desc->group_rule, &plan, err);
        for (int k = 0; k < ASP_EXPERIMENT_TEST_COUNT && !rc && !st->aborted; k++) {
            asp_experiment_test t = plan.order[k];
            say(st, "%s %s: A polygons, B %s", subjects[s], asp_experiment_test_name(t),
                asp_experiment_condition_name(plan.run_b[t]));
            rc = run_one(st, subjects[s], s, dir, t, 'A', ASP_EXPERIMENT_POLYGONS, plan.variable[t], err);
            if (!rc && !st->aborted)
                rc = run_one(st, subjects[s], s, dir, t, 'B', plan.run_b[t], plan.variable[t], err);
        }
    }
    if (!rc && st->aborted)
        say(st, "session stopped by Esc; what was recorded stays");
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++)
        asp__exp_prepared_release(&st->prep[t]);
    asp__exp_window_close(st);
    asp_gl_context_destroy(st->gl);
    asp_free(ctx, st);
    asp_free(ctx, subjects);
    return rc;
}
