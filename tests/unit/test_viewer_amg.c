/*
 * The viewer's .amg input kind without a window (src/viewer/scene_actions.c): the
 * points coloured by classifier, domains, strict domains or their own colours,
 * the [ and ] keys stepping levels and stopping at both ends, and errors for a
 * level out of range or input colours that are not there. Starts MPI (hypre).
 */
#include <string.h>
#include <unistd.h>

#include "amgsplat/amg.h"
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
static size_t distinct_colours(const asp_cloud *c)
{
    size_t n = 0;
    for (size_t i = 0; i < c->count; i++) {
        size_t j = 0;
        while (j < i && memcmp(c->colors + 4 * j, c->colors + 4 * i, 3) != 0)
            j++;
        n += j == i;
    }
    return n;
}

/* Writes the decomposition of cloud c to path; returns its level count (0 on failure). */
static size_t write_amg(const asp_cloud *c, const char *path)
{
    asp_error err = {0, ""};
    asp_amg *amg = NULL;
    CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, &err), &err);
    if (amg)
        CHECK_OK(asp_amg_save(amg, path, &err), &err);
    size_t levels = amg ? asp_amg_level_count(amg) : 0;
    asp_amg_destroy(amg);
    return levels;
}

/* The .amg kind: colours by classifier, then domains; [ and ] step levels and stop at the ends. */
static void test_amg_scene_actions(void)
{
    asp_error err = {0, ""};
    asp_cloud *c = NULL, *bare = NULL;
    char path[128], bare_path[128];
    snprintf(path, sizeof path, "/tmp/asp_test_viewer_%ld.amg", (long)getpid());
    snprintf(bare_path, sizeof bare_path, "/tmp/asp_test_viewer_bare_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 1500}, NULL, &c, &err), &err);
    if (!c)
        return;
    CHECK(c->colors != NULL); // the synthetic octahedron is coloured by face
    // the same points without colours
    CHECK_OK(asp_cloud_create(c->count, ASP_ATTR_NORMALS, NULL, &bare, &err), &err);
    if (bare) {
        memcpy(bare->positions, c->positions, 12 * c->count);
        memcpy(bare->normals, c->normals, 12 * c->count);
    }
    size_t levels = write_amg(c, path), bare_levels = bare ? write_amg(bare, bare_path) : 0;
    if (levels < 3 || bare_levels < 1) {
        CHECK_MSG(0, "decompositions have %zu and %zu levels", levels, bare_levels);
        asp_cloud_destroy(c);
        asp_cloud_destroy(bare);
        return;
    }
    asp_file_type ft;
    CHECK(asp_file_recognise(path, &ft, &err) == 0 && ft.kind == ASP_FILE_AMG);
    CHECK(asp_file_type_of_name("x.PLY", &ft, &err) == 0 && ft.kind == ASP_FILE_POINTS);

    asp_scene s;
    memset(&s, 0, sizeof s);
    asp_error bad = {0, ""};
    CHECK(asp__viewer_scene_load(&s, path, &(asp_viewer_desc){.amg_level = "L-99"}, NULL, &bad) == ASP_EINVAL);
    CHECK_MSG(strstr(bad.msg, path) && strstr(bad.msg, "L-99"), "%s", bad.msg);
    CHECK(s.cloud == NULL && s.type.kind == ASP_FILE_UNKNOWN);

    CHECK_OK(asp__viewer_scene_load(&s, path, &(asp_viewer_desc){0}, NULL, &err), &err);
    if (!s.cloud) {
        asp_cloud_destroy(c);
        asp_cloud_destroy(bare);
        return;
    }
    CHECK(s.frame.radius > 1.0 && s.frame.radius < 1.2); // the octahedron |x|+|y|+|z| = 1 plus disc radii
    CHECK(strcmp(status_of(&s), "classifier") == 0);
    CHECK(s.cloud->colors != NULL && memcmp(s.cloud->colors, c->colors, 4 * c->count) != 0);
    char note[160] = "";
    // ] from classifier colours shows the domains of the first level (L, the coarsest)
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_COARSER, note, sizeof note, &err) == 1);
    char want[64];
    snprintf(want, sizeof want, "domains, level %zu (L-0)", levels - 1);
    CHECK_MSG(strncmp(status_of(&s), want, strlen(want)) == 0, "%s", status_of(&s));
    size_t coarse_colours = distinct_colours(s.cloud);
    // already coarsest: nothing changes and the note says why
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_COARSER, note, sizeof note, &err) == 0);
    CHECK(strstr(note, "coarsest") != NULL);
    for (size_t l = levels - 1; l > 0; l--)
        CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_FINER, note, sizeof note, &err) == 1);
    CHECK(strncmp(status_of(&s), "domains, level 0 (L-", 20) == 0);
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_LEVEL_FINER, note, sizeof note, &err) == 0);
    CHECK(strstr(note, "finest") != NULL);
    // finer levels have more domains, so more distinct mixed colours
    CHECK_MSG(distinct_colours(s.cloud) > coarse_colours, "%zu vs %zu", distinct_colours(s.cloud), coarse_colours);
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_COLOR_MODE, note, sizeof note, &err) == 1);
    CHECK(strncmp(status_of(&s), "strict domains", 14) == 0);
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_COLOR_MODE, note, sizeof note, &err) == 1);
    CHECK(strcmp(status_of(&s), "input colours") == 0);
    CHECK(memcmp(s.cloud->colors, c->colors, 4 * c->count) == 0);
    CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_COLOR_MODE, note, sizeof note, &err) == 1);
    CHECK(strcmp(status_of(&s), "classifier") == 0);
    asp_scene_release(&s);

    // without colours the cycle skips "input colours", and asking for them is an error
    CHECK_OK(asp__viewer_scene_load(&s, bare_path, &(asp_viewer_desc){.amg_color = 2}, NULL, &err), &err);
    if (s.cloud) {
        CHECK(strncmp(status_of(&s), "strict domains", 14) == 0);
        CHECK(asp__viewer_scene_action(&s, ASP__VIEWER_COLOR_MODE, note, sizeof note, &err) == 1);
        CHECK(strcmp(status_of(&s), "classifier") == 0);
    }
    asp_scene_release(&s);
    CHECK(asp__viewer_scene_load(&s, bare_path, &(asp_viewer_desc){.amg_color = 3}, NULL, &bad) == ASP_EINVAL);
    CHECK_MSG(strstr(bad.msg, "no colours") != NULL, "%s", bad.msg);
    unlink(path);
    unlink(bare_path);
    asp_cloud_destroy(c);
    asp_cloud_destroy(bare);
    asp_amg_shutdown();
}

TEST_MAIN(TEST_CASE(test_amg_scene_actions))
