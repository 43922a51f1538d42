/*
 * The viewer's .dps input kind without a window (src/viewer/scene_actions.c): the
 * level picked by --level and stepped by [ and ] (stopping at both ends), and
 * p loading the source points the file names (an .amg), moved into the
 * primitives' frame, or explaining why it cannot. Starts MPI (hypre).
 */
#include <math.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/prim.h"
#include "amgsplat/sample.h"
#include "harness.h"
#include "viewer/internal.h"


/* The viewer's title text for s (asp__viewer_scene_status). */
static const char *status_of(const asp_scene *s)
{
    static char buf[96];
    asp__viewer_scene_status(s, buf, sizeof buf);
    return buf;
}
/* Saves the octahedron's decomposition to amg_path (unless NULL) and levels L-1, L to dps_path naming source. */
static int write_files(const char *amg_path, const char *dps_path, const char *source, size_t *points)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL;
    asp_amg *amg = NULL;
    asp_dps *dps = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 1500}, NULL, &c, &err), &err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, &err), &err);
    size_t n = amg ? asp_amg_level_count(amg) : 0;
    if (n >= 2) {
        size_t levels[2] = {n - 2, n - 1};
        if (amg_path)
            CHECK_OK(asp_amg_save(amg, amg_path, &err), &err);
        CHECK_OK(asp_prim_build(amg, NULL, levels, 2, NULL, source, NULL, &dps, &err), &err);
        if (dps)
            CHECK_OK(asp_dps_save(dps, dps_path, &err), &err);
    }
    *points = c ? c->count : 0;
    int ok = dps != NULL && dps->level_count == 2;
    asp_dps_destroy(dps);
    asp_amg_destroy(amg);
    asp_cloud_destroy(c);
    return ok;
}

static void test_dps_scene_actions(void)
{
    asp_error err = {0, ""};
    char amg_path[128], dps_path[128], lone_path[128];
    long pid = (long)getpid();
    snprintf(amg_path, sizeof amg_path, "/tmp/asp_test_viewer_dps_%ld.amg", pid);
    snprintf(dps_path, sizeof dps_path, "/tmp/asp_test_viewer_dps_%ld.dps", pid);
    snprintf(lone_path, sizeof lone_path, "/tmp/asp_test_viewer_dps_lone_%ld.dps", pid);
    size_t points = 0;
    int ok = write_files(amg_path, dps_path, amg_path, &points);
    size_t lone_points = 0;
    ok = ok && write_files(NULL, lone_path, "/nonexistent/dir/o.amg", &lone_points);
    CHECK(ok);
    if (!ok)
        goto done;
    asp_file_type ft;
    CHECK(asp_file_recognise(dps_path, &ft, &err) == 0 && ft.kind == ASP_FILE_DPS);
    CHECK(asp_file_type_of_name("X.DPS", &ft, &err) == 0 && ft.kind == ASP_FILE_DPS);

    asp_scene s;
    memset(&s, 0, sizeof s);
    asp_error bad = {0, ""};
    CHECK(asp__viewer_scene_load(&s, dps_path, &(asp_viewer_desc){.amg_level = "L-5"}, NULL, &bad) == ASP_EINVAL);
    CHECK_MSG(strstr(bad.msg, dps_path) && strstr(bad.msg, "no level 'L-5'") && strstr(bad.msg, "L-1, L"), "%s",
              bad.msg);
    CHECK(s.type.kind == ASP_FILE_UNKNOWN && s.dps == NULL);

    // the default is the finest level in the file; no points until p
    CHECK_OK(asp__viewer_scene_load(&s, dps_path, &(asp_viewer_desc){0}, NULL, &err), &err);
    if (!s.dps)
        goto done;
    CHECK(s.cloud == NULL && s.frame.radius > 0);
    const asp_dps_level *fine = asp_scene_dps_level(&s);
    CHECK(fine != NULL && fine->prim_count > 0);
    CHECK_MSG(strstr(status_of(&s), "(L-1)") != NULL, "%s", status_of(&s));
    char note[256] = "";
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_FINER, note, sizeof note, &err) == 0);
    CHECK_MSG(strstr(note, "already at the finest level") != NULL, "%s", note);
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_COARSER, note, sizeof note, &err) == 1);
    const asp_dps_level *coarse = asp_scene_dps_level(&s);
    CHECK(coarse != fine && coarse->level == fine->level + 1);
    CHECK_MSG(strstr(status_of(&s), "(L)") != NULL, "%s", status_of(&s));
    note[0] = 0;
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_COARSER, note, sizeof note, &err) == 0);
    CHECK_MSG(strstr(note, "already at the coarsest level") != NULL, "%s", note);
    CHECK(asp_scene_dps_level(&s) == coarse);

    // p: the source .amg's points, in the world frame of the primitives, loaded once
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_POINTS, note, sizeof note, &err) == 1);
    CHECK(s.cloud != NULL && s.cloud->count == points);
    if (s.cloud) {
        // moved into the primitives' frame, so one camera shows both
        CHECK(memcmp(s.cloud->origin, s.origin, sizeof s.origin) == 0);
        // every point lies within the primitives' bounding sphere (plus a point radius of slack)
        float worst = 0;
        for (size_t i = 0; i < s.cloud->count; i++) {
            float d2 = 0;
            for (int k = 0; k < 3; k++) {
                float e = (float)(s.cloud->positions[3 * i + k] - (s.frame.center[k] - s.origin[k]));
                d2 += e * e;
            }
            worst = d2 > worst ? d2 : worst;
        }
        CHECK_MSG(worst <= 1.1 * 1.1 * s.frame.radius * s.frame.radius, "a point at %g from the centre, radius %g",
                  (double)sqrtf(worst), s.frame.radius);
    }
    const asp_cloud *first = s.cloud;
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_POINTS, note, sizeof note, &err) == 1 && s.cloud == first);
    asp_scene_release(&s);
    CHECK(s.type.kind == ASP_FILE_UNKNOWN && s.cloud == NULL);

    // a source that is not there: p explains with the loader's message, every time
    CHECK_OK(asp__viewer_scene_load(&s, lone_path, &(asp_viewer_desc){.amg_level = "L"}, NULL, &err), &err);
    if (s.dps) {
        CHECK_MSG(strstr(status_of(&s), "(L)") != NULL, "%s", status_of(&s));
        note[0] = 0;
        CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_POINTS, note, sizeof note, &err) == 0 && s.cloud == NULL);
        CHECK_MSG(strstr(note, "cannot show the source points") && strstr(note, "/nonexistent/dir/o.amg"), "%s",
                  note);
        note[0] = 0;
        CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_POINTS, note, sizeof note, &err) == 0 && s.cloud == NULL);
        CHECK_MSG(strstr(note, "cannot show the source points") != NULL, "%s", note);
        asp_scene_release(&s);
    }
done:
    unlink(amg_path);
    unlink(dps_path);
    unlink(lone_path);
}

TEST_MAIN(TEST_CASE(test_dps_scene_actions))
