/*
 * The scene file: which models the recognition tests show and how the
 * navigation worlds are generated (seed 004 2.2-2.3), so a lab can swap
 * models without rebuilding. JSON through cJSON; docs/cli/experiment.md.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "experiment/internal.h"
#include "util/atomic_file.h"
#include "util/json_file.h"
#include "util/regular_file.h"
#include "util/banned.h"

#define SCENES_FORMAT "amgsplat-scenes 1"
#define GLMARK "/usr/share/glmark2/models/"

static const char *const kind_names[3] = {"object", "terrain", "canyon"};

void asp_experiment_scenes_default(asp_experiment_scenes *out)
{
    memset(out, 0, sizeof *out);
    static const char *const names[3] = {"bunny", "cat", "horse"};
    static const char *const files[3] = {GLMARK "bunny.obj", GLMARK "cat.3ds", GLMARK "horse.3ds"};
    for (int i = 0; i < 3; i++) {
        snprintf(out->candidates[i].name, sizeof out->candidates[i].name, "%s", names[i]);
        snprintf(out->candidates[i].model, sizeof out->candidates[i].model, "%s", files[i]);
    }
    out->candidate_count = 3;
    /* far: the object small on screen (seed 004 2.3: polygons are not output-sensitive) */
    out->tests[ASP_EXPERIMENT_FAR] = (asp_experiment_scene){
        .kind = 0, .answer = "cat", .distance_radii = 9.0f, .time_limit = 20.0f, .points = 30000,
        .primitives = 600};
    /* near: closer than the fitted view, where points look blocky */
    out->tests[ASP_EXPERIMENT_NEAR] = (asp_experiment_scene){
        .kind = 0, .answer = "horse", .distance_radii = 2.2f, .time_limit = 20.0f, .points = 30000,
        .primitives = 600};
    out->tests[ASP_EXPERIMENT_LOWSPEED] = (asp_experiment_scene){
        .kind = 1, .seed = 4, .grid = 161, .size = 160.0f, .half_width = 1.5f, .relief = 5.0f, .speed = 3.0f,
        .eye_height = 1.7f, .time_limit = 60.0f, .points = 120000, .primitives = 3000};
    out->tests[ASP_EXPERIMENT_HIGHSPEED] = (asp_experiment_scene){
        .kind = 2, .seed = 5, .grid = 161, .size = 200.0f, .half_width = 4.0f, .relief = 14.0f, .speed = 10.0f,
        .eye_height = 2.5f, .time_limit = 20.0f, .points = 120000, .primitives = 3000};
}

static int get_number(const cJSON *o, const char *key, double lo, double hi, double *v, const char *where,
                      asp_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!it)
        return 0;
    if (!cJSON_IsNumber(it) || !(it->valuedouble >= lo && it->valuedouble <= hi))
        return asp_error_set(err, ASP_EFORMAT, "%s: '%s' must be a number in %g..%g", where, key, lo, hi);
    *v = it->valuedouble;
    return 1;
}

static int get_string(const cJSON *o, const char *key, char *dst, size_t cap, const char *where, asp_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!it)
        return 0;
    if (!cJSON_IsString(it) || strlen(it->valuestring) >= cap || !it->valuestring[0])
        return asp_error_set(err, ASP_EFORMAT, "%s: '%s' must be a non-empty string under %zu bytes", where, key,
                             cap);
    snprintf(dst, cap, "%s", it->valuestring);
    return 1;
}

static int parse_scene(const cJSON *o, asp_experiment_scene *s, const char *where, asp_error *err)
{
    char kind[16] = "";
    int rc = get_string(o, "kind", kind, sizeof kind, where, err);
    if (rc < 0)
        return rc;
    if (rc) {
        int k = -1;
        for (int i = 0; i < 3; i++)
            if (strcmp(kind, kind_names[i]) == 0)
                k = i;
        if (k < 0)
            return asp_error_set(err, ASP_EFORMAT, "%s: kind '%s' (expected object, terrain, canyon)", where, kind);
        s->kind = k;
    }
    if ((rc = get_string(o, "answer", s->answer, sizeof s->answer, where, err)) < 0)
        return rc;
    double v = 0; // written by get_number when it returns 1
#define NUM(key, lo, hi, field, type)                                                                                  \
    if ((rc = get_number(o, key, lo, hi, &v, where, err)) < 0)                                                         \
        return rc;                                                                                                     \
    if (rc)                                                                                                            \
        s->field = (type)v;
    NUM("distance_radii", 0.5, 1000.0, distance_radii, float)
    NUM("seed", 0.0, 9007199254740991.0, seed, uint64_t)
    NUM("grid", 8.0, 2048.0, grid, uint32_t)
    NUM("size", 1.0, 1e5, size, float)
    NUM("half_width", 0.01, 1e4, half_width, float)
    NUM("relief", 0.0, 1e4, relief, float)
    NUM("speed", 0.01, 1e4, speed, float)
    NUM("eye_height", 0.01, 1e4, eye_height, float)
    NUM("time_limit", 0.1, 3600.0, time_limit, float)
    NUM("points", 100.0, 1e8, points, size_t)
    NUM("primitives", 1.0, 1e8, primitives, size_t)
#undef NUM
    return 0;
}

static int parse_root(const cJSON *root, const char *path, asp_experiment_scenes *sc, asp_error *err)
{
    char where[600];
    if (!cJSON_IsObject(root))
        return asp_error_set(err, ASP_EFORMAT, "'%s': expected a JSON object", path);
    const cJSON *fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
    if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, SCENES_FORMAT) != 0)
        return asp_error_set(err, ASP_EFORMAT, "'%s': \"format\" must be \"" SCENES_FORMAT "\"", path);
    const cJSON *cands = cJSON_GetObjectItemCaseSensitive(root, "candidates");
    if (cands) {
        if (!cJSON_IsObject(cands) || cJSON_GetArraySize(cands) < 1 ||
            cJSON_GetArraySize(cands) > ASP_EXPERIMENT_MAX_CANDIDATES)
            return asp_error_set(err, ASP_EFORMAT, "'%s': \"candidates\" must map 1..%d names to model files", path,
                                 ASP_EXPERIMENT_MAX_CANDIDATES);
        sc->candidate_count = 0;
        const cJSON *c;
        cJSON_ArrayForEach(c, cands)
        {
            asp_experiment_candidate *k = &sc->candidates[sc->candidate_count++];
            memset(k, 0, sizeof *k);
            if (!cJSON_IsString(c) || !c->valuestring[0] || strlen(c->valuestring) >= sizeof k->model ||
                !c->string[0] || strlen(c->string) >= sizeof k->name)
                return asp_error_set(err, ASP_EFORMAT, "'%s': candidate '%.40s' must name a model file", path,
                                     c->string ? c->string : "");
            snprintf(k->name, sizeof k->name, "%s", c->string);
            snprintf(k->model, sizeof k->model, "%s", c->valuestring);
        }
    }
    const cJSON *tests = cJSON_GetObjectItemCaseSensitive(root, "tests");
    if (tests && !cJSON_IsObject(tests))
        return asp_error_set(err, ASP_EFORMAT, "'%s': \"tests\" must be an object", path);
    for (int t = 0; tests && t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(tests, asp_experiment_test_name((asp_experiment_test)t));
        if (!o)
            continue;
        snprintf(where, sizeof where, "'%s' tests.%s", path, asp_experiment_test_name((asp_experiment_test)t));
        if (!cJSON_IsObject(o))
            return asp_error_set(err, ASP_EFORMAT, "%s must be an object", where);
        int rc = parse_scene(o, &sc->tests[t], where, err);
        if (rc)
            return rc;
    }
    for (int t = 0; t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        const asp_experiment_scene *s = &sc->tests[t];
        const char *name = asp_experiment_test_name((asp_experiment_test)t);
        if ((t <= ASP_EXPERIMENT_NEAR) != (s->kind == 0))
            return asp_error_set(err, ASP_EFORMAT, "'%s' tests.%s: kind must be %s", path, name,
                                 t <= ASP_EXPERIMENT_NEAR ? "object" : "terrain or canyon");
        if (s->kind == 0) {
            int found = 0;
            for (size_t i = 0; i < sc->candidate_count; i++)
                found |= strcmp(sc->candidates[i].name, s->answer) == 0;
            if (!found)
                return asp_error_set(err, ASP_EFORMAT, "'%s' tests.%s: answer '%s' is not a candidate", path, name,
                                     s->answer);
        }
    }
    return 0;
}

int asp_experiment_scenes_load(const char *path, asp_experiment_scenes *out, asp_error *err)
{
    char *text = NULL;
    size_t len = 0;
    int rc = asp__text_file_read(path, 64u << 20, "a scene file", &text, &len, err);
    if (rc)
        return rc;
    cJSON *root = cJSON_ParseWithLength(text, len);
    if (!root) {
        const char *at = cJSON_GetErrorPtr();
        size_t off = at && at >= text && at <= text + len ? (size_t)(at - text) : 0;
        free(text);
        return asp_error_set(err, ASP_EFORMAT, "'%s': not JSON near byte %zu", path, off);
    }
    free(text);
    asp_experiment_scenes sc;
    asp_experiment_scenes_default(&sc);
    rc = parse_root(root, path, &sc, err);
    cJSON_Delete(root);
    if (!rc)
        *out = sc;
    return rc;
}

int asp_experiment_scenes_save(const asp_experiment_scenes *sc, const char *path, asp_error *err)
{
    cJSON *root = cJSON_CreateObject(), *cands = NULL, *tests = NULL;
    int ok = root && cJSON_AddStringToObject(root, "format", SCENES_FORMAT) &&
             (cands = cJSON_AddObjectToObject(root, "candidates")) && (tests = cJSON_AddObjectToObject(root, "tests"));
    for (size_t i = 0; ok && i < sc->candidate_count; i++)
        ok = cJSON_AddStringToObject(cands, sc->candidates[i].name, sc->candidates[i].model) != NULL;
    for (int t = 0; ok && t < ASP_EXPERIMENT_TEST_COUNT; t++) {
        const asp_experiment_scene *s = &sc->tests[t];
        cJSON *o = cJSON_AddObjectToObject(tests, asp_experiment_test_name((asp_experiment_test)t));
        ok = o && cJSON_AddStringToObject(o, "kind", kind_names[s->kind]);
        if (ok && s->kind == 0)
            ok = cJSON_AddStringToObject(o, "answer", s->answer) &&
                 cJSON_AddNumberToObject(o, "distance_radii", s->distance_radii);
        if (ok && s->kind != 0)
            ok = cJSON_AddNumberToObject(o, "seed", (double)s->seed) && cJSON_AddNumberToObject(o, "grid", s->grid) &&
                 cJSON_AddNumberToObject(o, "size", s->size) &&
                 cJSON_AddNumberToObject(o, "half_width", s->half_width) &&
                 cJSON_AddNumberToObject(o, "relief", s->relief) && cJSON_AddNumberToObject(o, "speed", s->speed) &&
                 cJSON_AddNumberToObject(o, "eye_height", s->eye_height);
        ok = ok && cJSON_AddNumberToObject(o, "time_limit", s->time_limit) &&
             cJSON_AddNumberToObject(o, "points", (double)s->points) &&
             cJSON_AddNumberToObject(o, "primitives", (double)s->primitives);
    }
    if (!ok) {
        cJSON_Delete(root);
        root = NULL; // reported as out of memory
    }
    return asp__json_save(root, path, err);
}
