/*
 * The viewer's input kinds, one row each in a table: point files and .amg
 * decompositions, the latter coloured by the classifier (journal 2.1, Fig. 1b)
 * or by the domains of one level (journal 2.3 Fig. 5c-d; strict domains,
 * thesis 2.5), and .dps domain primitives (journal section 4), one level at a
 * time, with their source points loaded on demand.
 */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/io.h"
#include "amgsplat/prim.h"
#include "render/viewer_internal.h"
#include "util/banned.h"

static int frame_scene(asp__viewer_scene *s, const char *path, asp_error *err)
{
    asp_error inner = {0, ""};
    int rc = asp_render_bounding_sphere(s->cloud, s->center, &s->radius, &inner);
    if (rc)
        return asp_error_set(err, rc, "cannot view '%s': %s", path, inner.msg);
    return 0;
}

/* ---- point files ---- */

static int points_load(asp__viewer_scene *s, const char *path, const asp_viewer_desc *desc, asp_error *err)
{
    (void)desc;
    int rc = asp_cloud_load(path, &s->ctx, &s->cloud, err);
    if (rc)
        return rc;
    rc = frame_scene(s, path, err);
    if (rc) {
        asp_cloud_destroy(s->cloud);
        s->cloud = NULL;
    }
    return rc;
}

static void points_release(asp__viewer_scene *s)
{
    asp_cloud_destroy(s->cloud);
}

/* ---- .amg decompositions ---- */

/* Colour modes in the order the c key cycles them; INPUT only when the points had colours. */
enum { AMG_MODE_INPUT = 3, AMG_MODES = 4 };
static const char *const amg_mode_names[AMG_MODES] = {"classifier", "domains", "strict domains", "input colours"};

struct amg_state {
    asp_amg *amg;
    unsigned mode;   /* asp_amg_color_mode, or AMG_MODE_INPUT */
    size_t level;
    size_t levels;
    int has_input_colors;
};

static void amg_status(asp__viewer_scene *s)
{
    const struct amg_state *a = s->data;
    if (a->mode == ASP_AMG_COLOR_DOMAINS || a->mode == ASP_AMG_COLOR_STRICT) {
        size_t coarsest = a->levels - 1;
        snprintf(s->status, sizeof s->status, "%s, level %zu (L-%zu), %zu domains", amg_mode_names[a->mode],
                 a->level, coarsest - a->level, asp_amg_level_size(a->amg, a->level));
    } else {
        snprintf(s->status, sizeof s->status, "%s", amg_mode_names[a->mode]);
    }
}

/* Colours into a scratch buffer first so the cloud is untouched on failure. */
static int amg_recolor(asp__viewer_scene *s, unsigned mode, size_t level, asp_error *err)
{
    struct amg_state *a = s->data;
    size_t n = s->cloud->count;
    if (mode == AMG_MODE_INPUT) {
        memcpy(s->cloud->colors, asp_amg_cloud(a->amg)->colors, 4 * n);
    } else {
        uint8_t *rgba = asp_alloc(&s->ctx, 4 * n);
        if (!rgba)
            return asp_error_set(err, ASP_ENOMEM, "out of memory for the colours of %zu points", n);
        int rc = asp_amg_colorize(a->amg, (asp_amg_color_mode)mode, level, &s->ctx, rgba, err);
        if (!rc)
            memcpy(s->cloud->colors, rgba, 4 * n);
        asp_free(&s->ctx, rgba);
        if (rc)
            return rc;
    }
    a->mode = mode;
    a->level = level;
    amg_status(s);
    return 0;
}

static void amg_release(asp__viewer_scene *s)
{
    struct amg_state *a = s->data;
    if (a)
        asp_amg_destroy(a->amg);
    asp_free(&s->ctx, a);
    asp_cloud_destroy(s->cloud);
}

static int amg_load(asp__viewer_scene *s, const char *path, const asp_viewer_desc *desc, asp_error *err)
{
    struct amg_state *a = asp_calloc(&s->ctx, 1, sizeof *a);
    if (!a)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for '%s'", path);
    s->data = a;
    int rc = asp_amg_load(path, &s->ctx, &a->amg, err);
    // a private copy to colour: the decomposition's points stay as loaded
    if (!rc)
        rc = asp_cloud_clone(asp_amg_cloud(a->amg), &s->cloud, err);
    if (!rc)
        rc = asp_cloud_add_attrs(s->cloud, ASP_ATTR_COLORS, err);
    if (!rc)
        rc = frame_scene(s, path, err);
    if (!rc) {
        a->levels = asp_amg_level_count(a->amg);
        a->has_input_colors = asp_amg_cloud(a->amg)->colors != NULL;
        a->level = a->levels - 1;
        if (desc->amg_level) {
            asp_error inner = {0, ""};
            rc = asp_amg_level_parse(a->amg, desc->amg_level, &a->level, &inner);
            if (rc)
                asp_error_set(err, rc, "cannot view '%s': %s", path, inner.msg);
        }
    }
    if (!rc && desc->amg_color == AMG_MODE_INPUT && !a->has_input_colors)
        rc = asp_error_set(err, ASP_EINVAL, "cannot view '%s' in input colours: its points have no colours", path);
    if (!rc)
        rc = amg_recolor(s, desc->amg_color, a->level, err);
    if (rc) {
        amg_release(s);
        s->cloud = NULL;
        s->data = NULL;
    }
    return rc;
}

static int amg_action(asp__viewer_scene *s, enum asp__viewer_action act, char *note, size_t cap, asp_error *err)
{
    struct amg_state *a = s->data;
    unsigned mode = a->mode;
    size_t level = a->level;
    switch (act) {
    case ASP__VIEWER_COLOR_MODE:
        mode = (mode + 1) % (a->has_input_colors ? AMG_MODES : AMG_MODE_INPUT);
        break;
    case ASP__VIEWER_LEVEL_FINER:
    case ASP__VIEWER_LEVEL_COARSER:
        // a level means nothing to the classifier colours: stepping it shows domains
        if (mode != ASP_AMG_COLOR_DOMAINS && mode != ASP_AMG_COLOR_STRICT) {
            mode = ASP_AMG_COLOR_DOMAINS;
        } else if (act == ASP__VIEWER_LEVEL_FINER) {
            if (level == 0) {
                snprintf(note, cap, "already at the finest level (0, the points)");
                return 0;
            }
            level--;
        } else {
            if (level + 1 >= a->levels) {
                snprintf(note, cap, "already at the coarsest level (%zu, L)", level);
                return 0;
            }
            level++;
        }
        break;
    default:
        return 0;
    }
    int rc = amg_recolor(s, mode, level, err);
    return rc ? rc : 1;
}


/* ---- .dps domain primitives ---- */

struct dps_state {
    asp_dps *dps;
    size_t level;     /* index into dps->levels (finest first) */
    int source_tried; /* p already tried to load the source and failed: say so again without retrying */
};

static void dps_status(asp__viewer_scene *s)
{
    const struct dps_state *d = s->data;
    char name[16];
    asp_dps_level_name(d->dps, d->level, name);
    snprintf(s->status, sizeof s->status, "level %u (%s)", d->dps->levels[d->level].level, name);
}

static void dps_release(asp__viewer_scene *s)
{
    struct dps_state *d = s->data;
    if (d)
        asp_dps_destroy(d->dps);
    asp_free(&s->ctx, d);
    asp_cloud_destroy(s->cloud);
}

/* --level: "L", "L-2" (names of asp_dps_summarize) or an AMG level index, as amgsplat render takes it. */
static int dps_pick_level(const asp_dps *dps, const char *path, const char *want, size_t *out, asp_error *err)
{
    if (!asp_dps_level_parse(dps, want, out, err))
        return 0;
    char msg[sizeof err->msg];
    snprintf(msg, sizeof msg, "%s", err->msg);
    return asp_error_set(err, ASP_EINVAL, "cannot view '%s': it has %s", path, msg);
}

static int dps_load(asp__viewer_scene *s, const char *path, const asp_viewer_desc *desc, asp_error *err)
{
    struct dps_state *d = asp_calloc(&s->ctx, 1, sizeof *d);
    if (!d)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for '%s'", path);
    s->data = d;
    int rc = asp_dps_load(path, &s->ctx, &d->dps, err);
    if (!rc && d->dps->level_count == 0)
        rc = asp_error_set(err, ASP_EDEGENERATE, "cannot view '%s': it holds no level", path);
    if (!rc && desc->amg_level)
        rc = dps_pick_level(d->dps, path, desc->amg_level, &d->level, err);
    if (!rc) {
        // the world frame (origin 0), as amgsplat render frames a .dps
        asp_error inner = {0, ""};
        rc = asp_prim_level_bounding_sphere(&d->dps->levels[d->level], NULL, s->center, &s->radius, &inner);
        if (rc)
            asp_error_set(err, rc, "cannot view '%s': %s", path, inner.msg);
    }
    if (rc) {
        dps_release(s);
        s->data = NULL;
        return rc;
    }
    dps_status(s);
    return 0;
}

static int has_extension(const char *path, const char *ext);

/*
 * The source points of the .dps, into the primitives' frame (origin 0) so the
 * camera is shared. The name is tried as stored, then next to the .dps file.
 */
static int dps_load_source(asp__viewer_scene *s, const char *dps_path, char *note, size_t cap)
{
    struct dps_state *d = s->data;
    const char *src = d->dps->source;
    if (!src[0] || !(has_extension(src, ".amg") || has_extension(src, ".ply"))) {
        snprintf(note, cap, "no source points to show: the .dps names %s%s%s (p needs an .amg or .ply)",
                 src[0] ? "'" : "no source file", src, src[0] ? "'" : "");
        return 0;
    }
    char alt[512] = "";
    const char *slash = strrchr(dps_path, '/');
    if (src[0] != '/' && slash)
        snprintf(alt, sizeof alt, "%.*s/%s", (int)(slash - dps_path), dps_path, src);
    const char *tries[2] = {src, alt};
    asp_error e = {0, ""};
    asp_cloud *cloud = NULL;
    for (int t = 0; t < 2 && !cloud; t++) {
        const char *name = tries[t];
        if (!name[0])
            continue;
        asp_error inner = {0, ""};
        int rc;
        if (has_extension(name, ".amg")) {
            asp_amg *amg = NULL;
            rc = asp_amg_load(name, &s->ctx, &amg, &inner);
            if (!rc)
                rc = asp_cloud_clone(asp_amg_cloud(amg), &cloud, &inner);
            asp_amg_destroy(amg);
        } else {
            rc = asp_cloud_load(name, &s->ctx, &cloud, &inner);
        }
        if (rc && (t == 0 || !e.code))
            e = inner;
    }
    if (!cloud) {
        snprintf(note, cap, "cannot show the source points: %s", e.msg);
        return 0;
    }
    for (size_t i = 0; i < cloud->count; i++)
        for (int k = 0; k < 3; k++)
            cloud->positions[3 * i + k] = (float)(cloud->positions[3 * i + k] + cloud->origin[k]);
    memset(cloud->origin, 0, sizeof cloud->origin);
    s->cloud = cloud;
    return 1;
}

static int dps_action(asp__viewer_scene *s, enum asp__viewer_action act, char *note, size_t cap, asp_error *err)
{
    (void)err;
    struct dps_state *d = s->data;
    switch (act) {
    case ASP__VIEWER_LEVEL_FINER:
        if (d->level == 0) {
            snprintf(note, cap, "already at the finest level in the file (%u)", d->dps->levels[0].level);
            return 0;
        }
        d->level--;
        dps_status(s);
        return 1;
    case ASP__VIEWER_LEVEL_COARSER:
        if (d->level + 1 >= d->dps->level_count) {
            snprintf(note, cap, "already at the coarsest level in the file (%u)", d->dps->levels[d->level].level);
            return 0;
        }
        d->level++;
        dps_status(s);
        return 1;
    case ASP__VIEWER_POINTS:
        if (s->cloud)
            return 1;
        if (d->source_tried) {
            snprintf(note, cap, "no source points to show (see above)");
            return 0;
        }
        {
            int got = dps_load_source(s, s->path, note, cap);
            d->source_tried = !got;
            return got;
        }
    default:
        return 0;
    }
}

const asp_dps_level *asp__viewer_scene_dps_level(const asp__viewer_scene *s)
{
    if (!s->kind || s->kind->bit != ASP__VIEWER_INPUT_DPS)
        return NULL;
    const struct dps_state *d = s->data;
    return &d->dps->levels[d->level];
}

/* ---- the table ---- */

static const char *const amg_extensions[] = {".amg", NULL};
static const char *const dps_extensions[] = {".dps", NULL};

static const asp__viewer_input_kind input_kinds[] = {
    {"amg", ASP__VIEWER_INPUT_AMG, amg_extensions, amg_load, amg_action, amg_release},
    {"dps", ASP__VIEWER_INPUT_DPS, dps_extensions, dps_load, dps_action, dps_release},
    // last: asp_cloud_load knows the point formats and names the expected ones for anything else
    {"points", ASP__VIEWER_INPUT_POINTS, NULL, points_load, NULL, points_release},
};
enum { N_INPUT_KINDS = sizeof input_kinds / sizeof input_kinds[0] };

static int has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; i++)
        if (tolower((unsigned char)path[n - m + i]) != ext[i])
            return 0;
    return 1;
}

const asp__viewer_input_kind *asp__viewer_input_for(const char *path)
{
    for (size_t i = 0; i < N_INPUT_KINDS; i++) {
        if (!input_kinds[i].extensions)
            return &input_kinds[i];
        for (const char *const *e = input_kinds[i].extensions; *e; e++)
            if (has_extension(path, *e))
                return &input_kinds[i];
    }
    return &input_kinds[N_INPUT_KINDS - 1];
}

int asp__viewer_scene_check_desc(const asp_viewer_desc *desc, asp_error *err)
{
    if (desc->amg_color >= AMG_MODES)
        return asp_error_set(err, ASP_EINVAL, "unknown .amg colour mode %u (expected 0..%d)", desc->amg_color,
                             AMG_MODES - 1);
    return 0;
}

int asp__viewer_scene_load(asp__viewer_scene *s, const char *path, const asp_viewer_desc *desc, asp_error *err)
{
    asp__viewer_scene t;
    memset(&t, 0, sizeof t);
    if (desc->ctx)
        t.ctx = *desc->ctx;
    t.kind = asp__viewer_input_for(path);
    t.path = path;
    int rc = t.kind->load(&t, path, desc, err);
    if (rc)
        return rc;
    *s = t;
    return 0;
}

void asp__viewer_scene_release(asp__viewer_scene *s)
{
    if (s->kind)
        s->kind->release(s);
    memset(s, 0, sizeof *s);
}
