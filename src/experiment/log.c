/*
 * The per-frame log of seed 004 2.3 (docs/experiment-log.md): JSON Lines
 * opened for appending and flushed after every line, so a crash or a pulled
 * plug loses at most the line being written, and nothing is ever rewritten;
 * and the header, frame and event lines of a run.
 */
#include <errno.h>
#include <math.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "experiment/internal.h"
#include "util/banned.h"

int asp__exp_log_open(exp_log *log, const char *path, asp_error *err)
{
    memset(log, 0, sizeof *log);
    snprintf(log->path, sizeof log->path, "%s", path);
    log->fp = fopen(path, "a");
    if (!log->fp)
        return asp_error_set(err, ASP_EIO, "cannot open '%s' for appending: %s", path, strerror(errno));
    return 0;
}

int asp__exp_log_write(exp_log *log, void *cjson_obj, asp_error *err)
{
    cJSON *obj = cjson_obj;
    if (!log->fp) { // a practice run: shown, never logged
        cJSON_Delete(obj);
        return 0;
    }
    char *line = obj ? cJSON_PrintUnformatted(obj) : NULL;
    cJSON_Delete(obj);
    if (!line)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a line of '%s'", log->path);
    int ok = fputs(line, log->fp) >= 0 && fputc('\n', log->fp) != EOF && fflush(log->fp) == 0;
    cJSON_free(line);
    if (!ok)
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", log->path, strerror(errno));
    return 0;
}

void asp__exp_log_close(exp_log *log)
{
    if (log->fp)
        fclose(log->fp);
    log->fp = NULL;
}

/* ---------------------------------------------------------------- a run's lines */

static cJSON *vec3(const float v[3])
{
    double d[3] = {v[0], v[1], v[2]};
    return cJSON_CreateDoubleArray(d, 3);
}

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
