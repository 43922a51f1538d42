/*
 * Reader of the experiment logs (docs/experiment-log.md, seed 004 2.3): JSON
 * Lines, one cJSON object per line. The writer flushes every line, so a crash
 * leaves at most one line cut off mid-way; such a line (or one glued to the
 * next by a later append) is a lost frame, counted, never an error.
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>

#include "amgsplat/stats.h"
#include "util/banned.h"
#include "util/regular_file.h"

static const char log_format[] = "amgsplat-experiment-log 1";

static void copy_string(char *dst, size_t cap, const cJSON *item)
{
    if (cJSON_IsString(item) && item->valuestring)
        snprintf(dst, cap, "%s", item->valuestring);
}

static int number(const cJSON *obj, const char *key, double *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return -1;
    *out = it->valuedouble;
    return 0;
}

static int vec3(const cJSON *obj, const char *key, double out[3])
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 3)
        return -1;
    for (int k = 0; k < 3; k++) {
        const cJSON *v = cJSON_GetArrayItem(it, k);
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
            return -1;
        out[k] = v->valuedouble;
    }
    return 0;
}

static int fail_line(asp_error *err, const char *file, size_t line, const char *what)
{
    return asp_error_set(err, ASP_EFORMAT, "'%s' line %zu: %s", file, line, what);
}

static int read_header(asp_stats_log *log, const cJSON *h, asp_error *err)
{
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(h, "type");
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(h, "format");
    if (!cJSON_IsString(type) || strcmp(type->valuestring, "header") != 0)
        return fail_line(err, log->file, 1, "expected the header object {\"type\":\"header\", ...}");
    if (!cJSON_IsString(format) || strcmp(format->valuestring, log_format) != 0)
        return asp_error_set(err, ASP_EFORMAT, "'%s' line 1: expected format '%s', got '%s'", log->file, log_format,
                             cJSON_IsString(format) ? format->valuestring : "(none)");
    copy_string(log->subject, sizeof log->subject, cJSON_GetObjectItemCaseSensitive(h, "subject"));
    copy_string(log->group, sizeof log->group, cJSON_GetObjectItemCaseSensitive(h, "group"));
    copy_string(log->test, sizeof log->test, cJSON_GetObjectItemCaseSensitive(h, "test"));
    copy_string(log->run, sizeof log->run, cJSON_GetObjectItemCaseSensitive(h, "run"));
    copy_string(log->condition, sizeof log->condition, cJSON_GetObjectItemCaseSensitive(h, "condition"));
    copy_string(log->version, sizeof log->version, cJSON_GetObjectItemCaseSensitive(h, "version"));
    copy_string(log->started, sizeof log->started, cJSON_GetObjectItemCaseSensitive(h, "started"));
    copy_string(log->answer_expected, sizeof log->answer_expected,
                cJSON_GetObjectItemCaseSensitive(h, "answer_expected"));
    if (!log->subject[0] || !log->test[0] || !log->run[0] || !log->condition[0])
        return fail_line(err, log->file, 1, "header lacks one of 'subject', 'test', 'run', 'condition'");
    double v;
    if (number(h, "seed", &v) == 0 && v >= 0 && v < 18446744073709551616.0) // 2^64: the cast is defined below it
        log->seed = (uint64_t)v;
    log->observer = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(h, "observer"));
    const cJSON *screen = cJSON_GetObjectItemCaseSensitive(h, "screen");
    if (cJSON_IsArray(screen) && cJSON_GetArraySize(screen) == 2)
        for (int k = 0; k < 2; k++) {
            const cJSON *s = cJSON_GetArrayItem(screen, k);
            if (cJSON_IsNumber(s) && s->valuedouble >= 0 && s->valuedouble < 1e6)
                log->screen[k] = (unsigned)s->valuedouble;
        }
    const cJSON *drawn = cJSON_GetObjectItemCaseSensitive(h, "drawn");
    if (cJSON_IsObject(drawn)) {
        number(drawn, "triangles", &log->drawn_triangles);
        number(drawn, "points", &log->drawn_points);
        number(drawn, "primitives", &log->drawn_primitives);
    }
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(h, "path");
    if (path && !cJSON_IsNull(path)) {
        int n = cJSON_IsArray(path) ? cJSON_GetArraySize(path) : -1;
        if (n < 2)
            return fail_line(err, log->file, 1, "'path' must be an array of at least 2 [x,y,z] points");
        log->path = malloc((size_t)n * 3 * sizeof *log->path);
        if (!log->path)
            return asp_error_set(err, ASP_ENOMEM, "out of memory reading the path of '%s'", log->file);
        for (int i = 0; i < n; i++) {
            const cJSON *p = cJSON_GetArrayItem(path, i);
            double xyz[3];
            if (!cJSON_IsArray(p) || cJSON_GetArraySize(p) != 3)
                return asp_error_set(err, ASP_EFORMAT, "'%s' line 1: path point %d is not [x,y,z]", log->file, i);
            for (int k = 0; k < 3; k++) {
                const cJSON *c = cJSON_GetArrayItem(p, k);
                if (!cJSON_IsNumber(c) || !isfinite(c->valuedouble))
                    return asp_error_set(err, ASP_EFORMAT, "'%s' line 1: path point %d is not [x,y,z]", log->file, i);
                xyz[k] = c->valuedouble;
            }
            for (int k = 0; k < 3; k++)
                log->path[3 * i + k] = (float)xyz[k];
        }
        log->path_count = (size_t)n;
        if (number(h, "half_width", &log->half_width) || !(log->half_width > 0))
            return fail_line(err, log->file, 1, "a header with 'path' needs a positive 'half_width'");
    }
    return 0;
}

/* Grows *arr (elements of size) to hold one more; doubling keeps appends amortised O(1). */
static int reserve(void **arr, size_t *cap, size_t count, size_t size)
{
    if (count < *cap)
        return 0;
    size_t ncap = *cap ? *cap * 2 : 256;
    void *p = realloc(*arr, ncap * size);
    if (!p)
        return -1;
    *arr = p;
    *cap = ncap;
    return 0;
}

static int read_frame(asp_stats_log *log, const cJSON *o, size_t line, asp_stats_frame *f, asp_error *err)
{
    memset(f, 0, sizeof *f);
    if (number(o, "t", &f->t))
        return fail_line(err, log->file, line, "frame lacks the number 't'");
    if (number(o, "frame_ms", &f->frame_ms))
        return fail_line(err, log->file, line, "frame lacks the number 'frame_ms'");
    if (vec3(o, "pos", f->pos))
        return fail_line(err, log->file, line, "frame lacks 'pos' [x,y,z]");
    if (vec3(o, "dir", f->dir))
        f->dir[0] = f->dir[1] = f->dir[2] = 0;
    if (number(o, "drawn", &f->drawn))
        f->drawn = NAN;
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(o, "keys");
    f->moving_keys = cJSON_IsString(keys) && keys->valuestring[0] != 0;
    return 0;
}

static int read_event(asp_stats_log *log, const cJSON *o, size_t line, asp_stats_event *e, asp_error *err)
{
    memset(e, 0, sizeof *e);
    if (number(o, "t", &e->t))
        return fail_line(err, log->file, line, "event lacks the number 't'");
    const cJSON *what = cJSON_GetObjectItemCaseSensitive(o, "what");
    if (!cJSON_IsString(what))
        return fail_line(err, log->file, line, "event lacks the string 'what'");
    copy_string(e->what, sizeof e->what, what);
    copy_string(e->text, sizeof e->text, cJSON_GetObjectItemCaseSensitive(o, "text"));
    return 0;
}

/* One body line: a frame, an event, a lost line or an ignored one. */
static int read_line(asp_stats_log *log, const char *text, size_t line, size_t caps[2], asp_error *err)
{
    cJSON *o = cJSON_Parse(text);
    if (!cJSON_IsObject(o)) {
        cJSON_Delete(o);
        o = NULL;
        if (!log->first_lost_line)
            log->first_lost_line = line;
        log->lost_frames++;
        /*
         * A run resumed after a crash appends to the cut line: the complete object glued
         * behind the cut one is recovered (the writer prints objects as {"type":...).
         */
        const char *glued = NULL;
        for (const char *q = strstr(text + 1, "{\"type\""); q; q = strstr(q + 1, "{\"type\""))
            glued = q;
        if (glued)
            o = cJSON_Parse(glued);
        if (!cJSON_IsObject(o)) {
            cJSON_Delete(o);
            return 0;
        }
    }
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(o, "type");
    int rc = 0;
    if (cJSON_IsString(type) && strcmp(type->valuestring, "frame") == 0) {
        if (reserve((void **)&log->frames, &caps[0], log->frame_count, sizeof *log->frames))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", log->file);
        else if (!(rc = read_frame(log, o, line, &log->frames[log->frame_count], err)))
            log->frame_count++;
    } else if (cJSON_IsString(type) && strcmp(type->valuestring, "event") == 0) {
        if (reserve((void **)&log->events, &caps[1], log->event_count, sizeof *log->events))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory reading '%s'", log->file);
        else if (!(rc = read_event(log, o, line, &log->events[log->event_count], err)))
            log->event_count++;
    } else if (cJSON_IsString(type) && strcmp(type->valuestring, "header") == 0) {
        rc = fail_line(err, log->file, line, "a second header (two runs appended to one log?)");
    } else {
        log->ignored_lines++;
    }
    cJSON_Delete(o);
    return rc;
}

static int blank(const char *s)
{
    for (; *s; s++)
        if (!isspace((unsigned char)*s))
            return 0;
    return 1;
}

int asp_stats_log_load(asp_stats_log *log, const char *path, asp_error *err)
{
    ASP_ASSERT(log && path);
    memset(log, 0, sizeof *log);
    snprintf(log->file, sizeof log->file, "%s", path);
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return err ? err->code : ASP_EIO;
    char *buf = NULL;
    size_t bufcap = 0, caps[2] = {0, 0}, line = 0;
    int rc = 0, have_header = 0;
    ssize_t len;
    while (rc == 0 && (len = getline(&buf, &bufcap, fp)) >= 0) {
        line++;
        if ((size_t)len != strlen(buf)) { // a NUL inside: what a torn write on some file systems leaves
            if (!have_header)
                rc = fail_line(err, path, line, "expected the header, found binary data");
            else if (!log->first_lost_line)
                log->first_lost_line = line;
            log->lost_frames += have_header;
            continue;
        }
        if (blank(buf))
            continue;
        if (!have_header) {
            cJSON *h = cJSON_Parse(buf);
            if (!cJSON_IsObject(h))
                rc = fail_line(err, path, line, "expected the header object, found text that is not JSON");
            else
                rc = read_header(log, h, err);
            cJSON_Delete(h);
            have_header = 1;
            continue;
        }
        rc = read_line(log, buf, line, caps, err);
    }
    if (rc == 0 && ferror(fp))
        rc = asp_error_set(err, ASP_EIO, "cannot read '%s'", path);
    if (rc == 0 && !have_header)
        rc = fail_line(err, path, 1, "expected the header, the log is empty");
    free(buf);
    fclose(fp);
    log->lines = line;
    if (rc) {
        asp_stats_log_release(log);
        return rc;
    }
    return 0;
}

void asp_stats_log_release(asp_stats_log *log)
{
    if (!log)
        return;
    free(log->path);
    free(log->frames);
    free(log->events);
    memset(log, 0, sizeof *log);
}

/* Compares ignoring case and surrounding blanks: "Cat " names the cat. */
static int same_name(const char *a, const char *b)
{
    while (isspace((unsigned char)*a))
        a++;
    while (isspace((unsigned char)*b))
        b++;
    size_t la = strlen(a), lb = strlen(b);
    while (la && isspace((unsigned char)a[la - 1]))
        la--;
    while (lb && isspace((unsigned char)b[lb - 1]))
        lb--;
    return la == lb && la > 0 && strncasecmp(a, b, la) == 0;
}

void asp_stats_log_naming(const asp_stats_log *log, asp_stats_naming *out)
{
    ASP_ASSERT(log && out);
    memset(out, 0, sizeof *out);
    out->recognition_s = out->naming_s = NAN;
    const asp_stats_event *rec = NULL;
    for (size_t i = 0; i < log->event_count; i++) {
        const asp_stats_event *e = &log->events[i];
        if (!rec && strcmp(e->what, "recognised") == 0)
            rec = e;
        else if (rec && strcmp(e->what, "answer") == 0) {
            out->answered = 1;
            out->recognition_s = rec->t;
            out->naming_s = e->t - rec->t; // seed 004 2.3: naming time from Enter to the typed name
            snprintf(out->answer, sizeof out->answer, "%s", e->text);
            out->correct = same_name(e->text, log->answer_expected);
            return;
        }
    }
}
