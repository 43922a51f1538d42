/*
 * The viewer's keys on what it shows, over the one scene loader (scene.h):
 * .amg points coloured by the classifier (journal 2.1, Fig. 1b) or by the
 * domains of one level (journal 2.3 Fig. 5c-d; strict domains, thesis 2.5),
 * .dps domain primitives (journal section 4) one level at a time, with their
 * source points loaded on demand.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/geom.h"
#include "viewer/internal.h"
#include "util/banned.h"

/* The viewer's colour modes in the order the c key cycles them (asp_viewer_desc.amg_color). */
enum { MODE_CLASSIFIER = 0, MODE_DOMAINS = 1, MODE_STRICT = 2, MODE_INPUT = 3, MODES = 4 };
static const char *const mode_names[MODES] = {"classifier", "domains", "strict domains", "input colours"};

/* viewer mode -> scene colour: the scene counts the points' own colours first */
static asp_scene_amg_color scene_color(unsigned mode)
{
    return mode == MODE_INPUT ? ASP_SCENE_AMG_INPUT : (asp_scene_amg_color)(mode + 1);
}

static unsigned viewer_mode(asp_scene_amg_color c)
{
    return c == ASP_SCENE_AMG_INPUT ? MODE_INPUT : (unsigned)c - 1;
}

void asp__viewer_scene_status(const asp_scene *s, char *status, size_t cap)
{
    status[0] = '\0';
    if (s->amg) {
        unsigned mode = viewer_mode(s->amg_color);
        size_t coarsest = asp_amg_level_count(s->amg) - 1;
        if (mode == MODE_DOMAINS || mode == MODE_STRICT)
            snprintf(status, cap, "%s, level %zu (L-%zu), %zu domains", mode_names[mode], s->amg_level,
                     coarsest - s->amg_level, asp_amg_level_size(s->amg, s->amg_level));
        else
            snprintf(status, cap, "%s", mode_names[mode]);
    } else if (s->dps) {
        char name[16];
        asp_dps_level_name(s->dps, s->dps_level, name);
        const asp_dps_level *lv = &s->dps->levels[s->dps_level];
        snprintf(status, cap, "level %u (%s)%s", lv->level, name, lv->strict ? ", strict domains" : "");
    }
}

int asp__viewer_scene_check_desc(const asp_viewer_desc *desc, asp_error *err)
{
    if (desc->amg_color >= MODES)
        return asp_error_set(err, ASP_EINVAL, "unknown .amg colour mode %u (expected 0..%d)", desc->amg_color,
                             MODES - 1);
    return 0;
}

int asp__viewer_scene_load(asp_scene *s, const char *path, const asp_viewer_desc *desc, const asp_context *ctx,
                           asp_error *err)
{
    // points cut at creases as `render` and the primitives do (one picture per --view, issue 12)
    asp_scene_desc d = {.amg_color = scene_color(desc->amg_color), .level = desc->amg_level,
                        .crease_angle = ASP_PRIM_CREASE_ANGLE_DEFAULT, .crease_if_normals = 1,
                        .texture = desc->texture};
    asp_scene t;
    memset(&t, 0, sizeof t);
    int rc = asp_scene_load(path, &d, ctx, &t, err);
    if (rc)
        return rc;
    // the hybrid renderer draws the source points beside the primitives (docs/hybrid.md)
    if (t.dps && desc->renderer && strcmp(desc->renderer, "hybrid") == 0 && (rc = asp_scene_load_source(&t, err))) {
        asp_scene_release(&t);
        return rc;
    }
    if (t.amg && desc->amg_color == MODE_INPUT && !asp_amg_cloud(t.amg)->colors) {
        asp_scene_release(&t);
        return asp_error_set(err, ASP_EINVAL, "cannot view '%s' in input colours: its points have no colours", path);
    }
    // a scan's own fields (issue 29): the same colouring as amgsplat render --color-by, along the shown up axis
    if (desc->color_field) {
        asp_error e = {0, ""};
        if (!t.cloud || t.amg || t.dps || t.mesh || t.hier)
            rc = asp_error_set(&e, ASP_EINVAL, "a point file's points (PLY, XYZ, LAS), not %s input",
                               asp_file_kind_name(t.type.kind));
        else
            rc = asp_cloud_color_by(t.cloud, desc->color_field, desc->up, &e);
        if (rc) {
            asp_scene_release(&t);
            return asp_error_set(err, rc, "cannot colour '%s' by '%s': %s", path, desc->color_field, e.msg);
        }
    }
    *s = t;
    return 0;
}

static int amg_action(asp_scene *s, enum asp__viewer_action act, char *note, size_t cap, asp_error *err)
{
    unsigned mode = viewer_mode(s->amg_color);
    size_t level = s->amg_level, levels = asp_amg_level_count(s->amg);
    int has_input = asp_amg_cloud(s->amg)->colors != NULL;
    switch (act) {
    case ASP__VIEWER_COLOR_MODE:
        mode = (mode + 1) % (has_input ? MODES : MODE_INPUT);
        break;
    case ASP__VIEWER_LEVEL_FINER:
    case ASP__VIEWER_LEVEL_COARSER:
        // a level means nothing to the classifier colours: stepping it shows domains
        if (mode != MODE_DOMAINS && mode != MODE_STRICT) {
            mode = MODE_DOMAINS;
        } else if (act == ASP__VIEWER_LEVEL_FINER) {
            if (level == 0) {
                snprintf(note, cap, "already at the finest level (0, the points)");
                return 0;
            }
            level--;
        } else {
            if (level + 1 >= levels) {
                snprintf(note, cap, "already at the coarsest level (%zu, L)", level);
                return 0;
            }
            level++;
        }
        break;
    default:
        return 0;
    }
    int rc = asp_scene_recolor(s, scene_color(mode), level, err);
    return rc ? rc : 1;
}

/* The next level of the same domain set (thesis appendix C "Domain Set") towards dir; SIZE_MAX if none. */
static size_t step_in_set(const asp_dps *dps, size_t from, int dir)
{
    for (size_t i = from; dir < 0 ? i-- > 0 : ++i < dps->level_count;)
        if ((dps->levels[i].strict != 0) == (dps->levels[from].strict != 0))
            return i;
    return SIZE_MAX;
}

int asp__viewer_scene_domain_set(asp_scene *s, char *note, size_t cap)
{
    if (!s->dps) {
        snprintf(note, cap, "the domain set applies to .dps input only");
        return 0;
    }
    asp_error e = {0, ""};
    int strict = !s->dps->levels[s->dps_level].strict;
    if (asp_dps_domain_set_pick(s->dps, s->dps_level, strict, &s->dps_level, &e)) {
        snprintf(note, cap, "%s", e.msg);
        return 0;
    }
    return 1;
}

static int dps_action(asp_scene *s, enum asp__viewer_action act, char *note, size_t cap, asp_error *err)
{
    size_t next;
    switch (act) {
    case ASP__VIEWER_LEVEL_FINER:
        if ((next = step_in_set(s->dps, s->dps_level, -1)) == SIZE_MAX) {
            snprintf(note, cap, "already at the finest level in the file (%u)", s->dps->levels[s->dps_level].level);
            return 0;
        }
        s->dps_level = next;
        return 1;
    case ASP__VIEWER_LEVEL_COARSER:
        if ((next = step_in_set(s->dps, s->dps_level, +1)) == SIZE_MAX) {
            snprintf(note, cap, "already at the coarsest level in the file (%u)", s->dps->levels[s->dps_level].level);
            return 0;
        }
        s->dps_level = next;
        return 1;
    case ASP__VIEWER_POINTS: {
        if (s->cloud)
            return 1;
        asp_error e = {0, ""};
        if (asp_scene_load_source(s, &e)) {
            snprintf(note, cap, "cannot show the source points: %s", e.msg);
            return 0;
        }
        return 1;
    }
    default:
        (void)err;
        return 0;
    }
}

int asp__viewer_scene_action(asp_scene *s, enum asp__viewer_action act, char *note, size_t cap, asp_error *err)
{
    if (s->amg)
        return amg_action(s, act, note, cap, err);
    if (s->dps)
        return dps_action(s, act, note, cap, err);
    if (s->mesh && act == ASP__VIEWER_POINTS) {
        // points sampled from the mesh (or a PLY's own vertices), drawn in the mesh's frame
        asp_error e = {0, ""};
        if (asp_scene_load_source(s, &e)) {
            snprintf(note, cap, "cannot sample points from the mesh: %s", e.msg);
            return 0;
        }
        return 1;
    }
    return 0;
}
