/*
 * The trial loops of seed 004 2.3, one per kind of test, the same for a
 * person and for the machine observer (STYLE.md 9b): the input comes from the
 * run's source (exp_source in internal.h), while the world, the cameras and
 * the per-frame log (docs/experiment-log.md) are the loop's. The person's
 * clock is the wall clock; the observer's is its frame count at a fixed step,
 * so one seed gives one set of logs.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <strings.h>

#include "experiment/internal.h"
#include "util/banned.h"

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
/* Esc: the session ends; what was recorded stays, and the run's log says where it stopped */
static int abort_run(exp_run *r, double t, asp_error *err)
{
    r->st->aborted = 1;
    return asp__exp_write_event(r, t, "abort", NULL, err);
}

/*
 * Walking (low speed) or flying (high speed) along the path to its end or
 * until the time limit: each frame is shown from the eye, the source's
 * command (keys held, or the observer's steering) is logged with it, and the
 * world moves the walker by one step. A person sees a red warning for 0.4 s
 * after leaving the path (seed 004 2.3).
 */
int asp__exp_trial_navigation(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_source *s = st->source;
    exp_prepared *p = r->p;
    const asp_experiment_world *w = &p->world;
    static const uint8_t red[4] = {230, 40, 30, 255};
    int high = r->test == ASP_EXPERIMENT_HIGHSPEED;
    float pitch = (high ? -8.0f : -14.0f) * DEG;
    // a practice run (not logged) is a quarter of the test
    double limit = p->scene.time_limit * (r->log.fp ? 1.0 : 0.25) * (st->desc->short_tests ? 0.1 : 1.0);
    size_t max_frames = s->fixed_step ? (size_t)ceil(limit / FIXED_DT) : SIZE_MAX;
    double t_limit = s->fixed_step ? INFINITY : limit;
    float x = w->path[0], z = w->path[2], along = 0.0f;
    float yaw = atan2f(w->path[3] - w->path[0], w->path[5] - w->path[2]) + s->ops->walk_begin(s, r);
    double t = 0.0, warning_until = -1.0;
    int rc = 0;
    for (size_t i = 0; !rc && i < max_frames && t < t_limit && along < 0.995f; i++) {
        if (s->ops->poll(s)) {
            rc = abort_run(r, t, err);
            break;
        }
        float ground = asp_experiment_world_height(w, x, z);
        float eye[3] = {x, ground + p->scene.eye_height, z};
        float dir[3] = {sinf(yaw), 0.0f, cosf(yaw)};
        asp_camera cam;
        asp__exp_first_person(&cam, p->origin[r->cond], eye, yaw, pitch, s->ops->aspect(s), 1.5f * w->size);
        double ms = 0.0;
        size_t drawn = 0;
        rc = s->ops->show(s, r, &cam, s->warns && t < warning_until ? red : asp__exp_sky, 0, &ms, &drawn, err);
        if (rc)
            break;
        double turn = 0.0, speed = 0.0;
        char keys[8];
        s->ops->walk(s, r, &turn, &speed, keys);
        float logged[3] = {x, ground, z};
        rc = asp__exp_write_frame(r, i, t, ms, logged, dir, drawn, keys, NULL, err);
        if (rc)
            break;
        double dt = s->ops->step(s, ms);
        size_t before = r->res.off_path;
        t += dt;
        rc = asp__exp_nav_move(r, &x, &z, &yaw, turn, speed, dt, t, &along, err);
        if (r->res.off_path != before)
            warning_until = t + 0.4;
    }
    r->res.progress = along;
    return rc;
}

/* ---------------------------------------------------------------- recognition */

/*
 * Recognising an object that may be turned but not approached (seed 004
 * 2.3): frames from the object camera until the source recognises it (Enter,
 * or the observer's confidence), then the naming stage until it names it;
 * both times are logged as events and kept in the run's result.
 */
int asp__exp_trial_recognition(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_source *s = st->source;
    exp_prepared *p = r->p;
    float yaw = 30.0f, pitch = 15.0f;
    s->ops->look_begin(s, r, &yaw, &pitch);
    double t = 0.0, t_recognised = -1.0;
    int rc = 0;
    for (size_t i = 0; !rc; i++) {
        if (s->ops->poll(s)) {
            rc = abort_run(r, t, err);
            break;
        }
        asp_camera cam;
        asp__exp_object_camera(&cam, p, p->origin[r->cond], yaw, pitch, p->scene.distance_radii, s->ops->aspect(s));
        int deciding = t_recognised < 0.0;
        double ms = 0.0;
        size_t drawn = 0;
        rc = s->ops->show(s, r, &cam, asp__exp_backdrop, !deciding, &ms, &drawn, err);
        if (rc)
            break;
        float eye[3];
        asp_camera_eye(&cam, eye);
        float dir[3] = {cam.target[0] - eye[0], cam.target[1] - eye[1], cam.target[2] - eye[2]};
        float len = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int k = 0; k < 3; k++) {
            dir[k] = len > 0.0f ? dir[k] / len : 0.0f;
            eye[k] = (float)(eye[k] + p->origin[r->cond][k]);
        }
        char keys[8];
        s->ops->look_keys(s, deciding, keys);
        float rot[2] = {yaw, pitch};
        rc = asp__exp_write_frame(r, i, t, ms, eye, dir, drawn, keys, rot, err);
        if (rc)
            break;
        double dt = s->ops->step(s, ms);
        t += dt;
        char answer[32];
        if (deciding) {
            if (s->ops->look(s, r, t, dt, &yaw, &pitch)) {
                t_recognised = t;
                rc = asp__exp_write_event(r, t, "recognised", NULL, err);
            }
        } else if (s->ops->name(s, r, t, t_recognised, answer)) {
            snprintf(r->res.answer, sizeof r->res.answer, "%s", answer);
            r->res.correct = strcasecmp(answer, p->model_name) == 0; // a person may type capitals
            r->res.recognition_s = t_recognised;
            r->res.naming_s = t - t_recognised;
            rc = asp__exp_write_event(r, t, "answer", answer, err);
            break;
        }
    }
    return rc;
}
