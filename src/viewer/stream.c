/*
 * The viewer on a streamed .hier (issue 28's out-of-core layout; docs/cli/view.md "Streamed
 * hierarchies"): the points of the first view's cut are loaded before the window opens, as
 * `amgsplat render` loads them (asp_ooc_select under the --memory budget, then asp_ooc_load), and
 * whenever the camera has rested for a moment the cut of the new view is selected again and, if it
 * names other nodes, loaded by a second thread while the old points are still drawn, then swapped
 * in. Coarse-first selection by projected point spacing is seed 004 section 3.2's traversal, and
 * refining only once the camera stops is what Potree and CloudCompare's LOD mode do: moving views
 * keep their frame rate, a still view converges to the budget's detail.
 *
 * Scripted runs (--frames) must give the same picture every run, so there the load happens in the
 * frame after the camera stops, and the frame waits for it, instead of going by the clock.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "viewer/internal.h"
#include "util/banned.h"

/* How long the camera must rest before the cut is chosen again: shorter re-reads mid-gesture. */
#define REST_SECONDS 0.25

struct asp__viewer_stream {
    asp_ooc *ooc;
    uint64_t budget;         /* points of one view's cut */
    float tau;               /* pixels of projected spacing the cut refines to (0 = 1) */
    int scripted;
    uint32_t *loaded;        /* sorted node ids of the points now shown */
    size_t loaded_n;
    uint32_t *scratch;       /* a selection, node_count long */
    float last_view[16];     /* the camera of the last frame, to see it rest */
    double rest_since;
    int checked;             /* the resting camera's cut was already compared */
    /* the loader thread */
    pthread_t thread;
    int running;
    atomic_int done;
    uint32_t *job;
    size_t job_n;
    asp_cloud *result;
    int job_rc;
    asp_error job_err;
    size_t loads;
};

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The cut of cam into s->scratch, sorted; its node count into *n. */
static int select_cut(asp__viewer_stream *s, const asp_camera *cam, uint32_t w, uint32_t h, size_t *n,
                      asp_error *err)
{
    asp_hier_view hv;
    asp_hier_view_of_camera(cam, w ? w : 1, h ? h : 1, s->tau, &hv);
    uint64_t points = 0;
    int rc = asp_ooc_select(s->ooc, &hv, s->budget, s->scratch, n, &points, err);
    if (!rc)
        qsort(s->scratch, *n, sizeof *s->scratch, cmp_u32);
    return rc;
}

int asp__viewer_stream_open(const char *path, size_t memory, float tau, int scripted, const asp_context *ctx,
                            asp__viewer_stream **out, asp_error *err)
{
    asp__viewer_stream *s = calloc(1, sizeof *s);
    if (!s)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the stream of '%s'", path);
    int rc = asp_ooc_open(path, ctx, &s->ooc, err);
    if (!rc) {
        size_t nn = asp_ooc_node_count(s->ooc);
        s->loaded = malloc(nn * sizeof *s->loaded);
        s->scratch = malloc(nn * sizeof *s->scratch);
        s->job = malloc(nn * sizeof *s->job);
        if (!s->loaded || !s->scratch || !s->job)
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the cuts of '%s' (%zu nodes)", path, nn);
    }
    if (rc) {
        asp__viewer_stream_close(s);
        return rc;
    }
    s->budget = asp_ooc_budget_points(memory);
    s->tau = tau;
    s->scripted = scripted;
    atomic_init(&s->done, 0);
    *out = s;
    return 0;
}

int asp__viewer_stream_first(asp__viewer_stream *s, const asp_camera *cam, uint32_t w, uint32_t h, asp_scene *scene,
                             asp_error *err)
{
    size_t n = 0;
    int rc = select_cut(s, cam, w, h, &n, err);
    asp_cloud *cloud = NULL;
    if (!rc)
        rc = asp_ooc_load(s->ooc, s->scratch, n, &cloud, err);
    if (rc)
        return rc;
    memcpy(s->loaded, s->scratch, n * sizeof *s->loaded);
    s->loaded_n = n;
    s->loads = 1;
    scene->cloud = cloud;
    return 0;
}

void asp__viewer_stream_frame(const asp__viewer_stream *s, asp_scene *scene)
{
    scene->frame = *asp_ooc_frame(s->ooc);
    asp_ooc_origin(s->ooc, scene->origin);
}

static void *load_main(void *arg)
{
    asp__viewer_stream *s = arg;
    s->job_rc = asp_ooc_load(s->ooc, s->job, s->job_n, &s->result, &s->job_err);
    atomic_store(&s->done, 1);
    return NULL;
}

/* The finished job's cloud into *fresh (the points now shown), or its error. */
static int take(asp__viewer_stream *s, asp_cloud **fresh, asp_error *err)
{
    atomic_store(&s->done, 0);
    if (s->job_rc) {
        if (err)
            *err = s->job_err;
        return s->job_rc;
    }
    memcpy(s->loaded, s->job, s->job_n * sizeof *s->loaded);
    s->loaded_n = s->job_n;
    s->loads++;
    *fresh = s->result;
    s->result = NULL;
    return 0;
}

/* Joins the loader thread once it is done; its cloud into *fresh or its error. */
static int join(asp__viewer_stream *s, asp_cloud **fresh, asp_error *err)
{
    if (!s->running || !atomic_load(&s->done))
        return 0;
    pthread_join(s->thread, NULL);
    s->running = 0;
    return take(s, fresh, err);
}

int asp__viewer_stream_update(asp__viewer_stream *s, const asp_camera *cam, uint32_t w, uint32_t h, double now,
                              asp_cloud **fresh, asp_error *err)
{
    *fresh = NULL;
    int rc = join(s, fresh, err);
    if (rc || *fresh)
        return rc;
    float view[16];
    asp_camera_view_matrix(cam, view);
    if (memcmp(view, s->last_view, sizeof view) != 0) { // moving: wait until it rests
        memcpy(s->last_view, view, sizeof view);
        s->rest_since = now;
        s->checked = 0;
        return 0;
    }
    if (s->checked || s->running || (!s->scripted && now - s->rest_since < REST_SECONDS))
        return 0;
    s->checked = 1;
    size_t n = 0;
    if ((rc = select_cut(s, cam, w, h, &n, err)) != 0)
        return rc;
    if (n == s->loaded_n && memcmp(s->scratch, s->loaded, n * sizeof *s->loaded) == 0)
        return 0; // the points shown are this view's
    memcpy(s->job, s->scratch, n * sizeof *s->job);
    s->job_n = n;
    if (pthread_create(&s->thread, NULL, load_main, s) != 0) { // no thread to be had: load in this one
        load_main(s);
        return take(s, fresh, err);
    }
    s->running = 1;
    if (s->scripted) { // the same loader, waited for, so a scripted run shows the same frames every time
        pthread_join(s->thread, NULL);
        s->running = 0;
        return take(s, fresh, err);
    }
    return 0;
}

void asp__viewer_stream_set_tolerance(asp__viewer_stream *s, float tau)
{
    s->tau = tau;
    s->checked = 0; // the resting camera's cut is chosen again
}

int asp__viewer_stream_busy(const asp__viewer_stream *s)
{
    return s->running || (!s->checked && !s->scripted);
}

void asp__viewer_stream_counts(const asp__viewer_stream *s, size_t *loads, size_t *nodes, size_t *node_count,
                               uint64_t *point_count)
{
    *loads = s->loads;
    *nodes = s->loaded_n;
    *node_count = asp_ooc_node_count(s->ooc);
    *point_count = asp_ooc_point_count(s->ooc);
}

void asp__viewer_stream_close(asp__viewer_stream *s)
{
    if (!s)
        return;
    if (s->running)
        pthread_join(s->thread, NULL);
    asp_cloud_destroy(s->result);
    asp_ooc_close(s->ooc);
    free(s->loaded);
    free(s->scratch);
    free(s->job);
    free(s);
}
