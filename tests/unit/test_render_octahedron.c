/*
 * Domain-primitive rendering on a real decomposition (issue 5 "done when";
 * journal section 4, thesis chapter 4): the octahedron decomposed in-process
 * (amg.h), its 8-domain level built (prim.h) and drawn with every method from
 * 16 views at 256x256, compared by SSIM with the opaque-disc render of its
 * 16,000 points. Set ASP_TEST_PRIM_OUT=<dir> to keep the contact sheets.
 * The pixel-exact checks on hand-made levels are in test_render_dps.c.
 *
 * The decomposition runs in a child process that saves the .dps and leaves
 * with _exit: hypre starts OpenMPI, whose by-design leaks LeakSanitizer can
 * only suppress with full stack unwinding on every malloc, and that slows
 * llvmpipe about 100-fold (CMakeLists.txt). So this process never starts MPI.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "amgsplat/amg.h"
#include "amgsplat/eval.h"
#include "amgsplat/geom.h"
#include "amgsplat/prim.h"
#include "amgsplat/render.h"
#include "amgsplat/sample.h"
#include "gl_harness.h"
#include "harness.h"


static asp_error *ep(asp_error *e)
{
    return e;
}

/* ---- the octahedron acceptance (issue 5 "done when") ---- */

enum { VIEWS = 16, SIZE = 256 };

static void view_camera(asp_camera *cam, size_t i, const float center[3], float radius)
{
    test_view_camera(cam, i, VIEWS, center, radius);
}

static void save_sheet(const asp_image *tiles, const char *name)
{
    test_save_sheet(tiles, VIEWS, "ASP_TEST_PRIM_OUT", name);
}

/* Mean SSIM of r against ref over the 16 views; fills img (released by the caller). */
static double views_ssim(asp_renderer *r, const asp_image *ref, asp_image *img, const float center[3], float radius,
                         const asp_render_desc *rd, double *worst)
{
    asp_error err = {0, ""};
    double mean = 0;
    *worst = 1;
    for (size_t v = 0; v < VIEWS; v++) {
        asp_camera cam;
        view_camera(&cam, v, center, radius);
        double s = 0;
        CHECK_OK(asp_render_to_image(gl, r, &cam, rd, &img[v], &err), ep(&err));
        CHECK_OK(asp_image_ssim(&ref[v], &img[v], &s, &err), ep(&err));
        *worst = fmin(*worst, s);
        mean += s / VIEWS;
    }
    return mean;
}

static void release_views(asp_image *img)
{
    for (size_t v = 0; v < VIEWS; v++)
        asp_image_release(&img[v]);
}

static char dps_path[] = "/tmp/asp_octahedron_XXXXXX";
static int dps_built;

/*
 * Synthesises the octahedron, decomposes it (amg.h), builds its 8-domain
 * level (prim.h) and saves it to dps_path, in a child process forked before
 * this process starts any thread (GL, OpenMP; see the top of the file).
 */
static void build_primitives(void)
{
    int fd = mkstemp(dps_path);
    CHECK(fd >= 0);
    if (fd < 0)
        return;
    close(fd);
    fflush(stderr);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        asp_error err = {0, ""};
        asp_cloud *oct = NULL;
        asp_amg *amg = NULL;
        asp_dps *dps = NULL;
        int rc = asp_synth(ASP_SYNTH_OCTAHEDRON, NULL, NULL, &oct, &err);
        if (!rc)
            rc = asp_amg_decompose(oct, NULL, NULL, &amg, &err);
        size_t level8 = SIZE_MAX;
        for (size_t l = 0; !rc && l < asp_amg_level_count(amg); l++)
            if (asp_amg_level_size(amg, l) == 8)
                level8 = l;
        if (!rc && level8 == SIZE_MAX)
            rc = asp_error_set(&err, ASP_EINVAL, "no level with 8 domains");
        if (!rc)
            rc = asp_prim_build(amg, NULL, &level8, 1, NULL, "octahedron", NULL, &dps, &err);
        if (!rc)
            rc = asp_dps_save(dps, dps_path, &err);
        if (rc)
            fprintf(stderr, "octahedron primitives: %s\n", err.msg);
        asp_dps_destroy(dps);
        asp_amg_destroy(amg);
        asp_cloud_destroy(oct);
        asp_amg_shutdown();
        _exit(rc ? 1 : 0); // no atexit handlers: LeakSanitizer does not look at MPI's allocations
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
    dps_built = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    CHECK_MSG(dps_built, "building the octahedron's primitives failed (status %d)", status);
}

/* Opaque discs of cloud, clipped at its creases (asp_crease_clip_planes, 60 degrees) when clip. */
static asp_renderer *disc_renderer(const asp_cloud *cloud, int clip)
{
    asp_error err = {0, ""};
    float *planes = NULL;
    if (clip) {
        planes = malloc(8 * cloud->count * sizeof *planes);
        CHECK(planes != NULL);
        if (!planes)
            return NULL;
        size_t clipped = 0;
        CHECK_OK(asp_crease_clip_planes(cloud, NULL, NULL, planes, &clipped, &err), ep(&err));
        CHECK(clipped > cloud->count / 10); // the points within a disc radius of an edge (about 18%)
    }
    asp_renderer *disc = NULL;
    CHECK_OK(asp_disc_renderer_create(gl, cloud, &(asp_disc_renderer_desc){.clip_planes = planes}, &disc, &err),
             ep(&err));
    free(planes);
    return disc;
}

/*
 * Issue 5: every method but blend-all renders the octahedron with SSIM >= 0.95
 * against the opaque-disc render of its 16,000 points. The discs are clipped
 * at the creases (docs/render-methods.md "Crease clipping"): plain discs
 * overhang every crease and silhouette edge in jagged scallops, so a second
 * sampling of the same octahedron drawn the same way scored only 0.920 mean
 * (0.903 worst view) against them, and no representation could reach 0.95.
 * Clipped, the second sampling scores 0.99: the reference now shows the
 * surface, not the sampling. The primitives are clipped likewise (the
 * renderer's default); with clipping off (the seeds exactly) they are
 * reported too, and must stay above 0.80.
 */
static void test_octahedron_methods(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_cloud *oct = NULL, *other = NULL;
    asp_dps *dps = NULL;
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, NULL, NULL, &oct, &err), ep(&err));
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.seed = 7}, NULL, &other, &err), ep(&err));
    if (dps_built)
        CHECK_OK(asp_dps_load(dps_path, NULL, &dps, &err), ep(&err));
    if (!dps || !other) {
        asp_cloud_destroy(oct);
        asp_cloud_destroy(other);
        return;
    }
    CHECK(dps->levels[0].prim_count == 8);

    float center[3], radius;
    CHECK_OK(asp_render_bounding_sphere(oct, center, &radius, &err), ep(&err));
    static asp_image ref[VIEWS], img[VIEWS];
    asp_render_desc rd = {.width = SIZE, .height = SIZE, .background = {255, 255, 255, 255}};
    asp_renderer *disc = disc_renderer(oct, 1);
    for (size_t v = 0; disc && v < VIEWS; v++) {
        asp_camera cam;
        view_camera(&cam, v, center, radius);
        CHECK_OK(asp_render_to_image(gl, disc, &cam, &rd, &ref[v], &err), ep(&err));
    }
    asp_renderer_destroy(disc);
    save_sheet(ref, "octahedron-discs");
    // the floor: the same surface sampled with another seed, clipped and plain
    double floor_mean[2] = {0}, floor_worst[2] = {0};
    for (int clip = 1; clip >= 0; clip--) {
        disc = disc_renderer(other, clip);
        if (disc)
            floor_mean[clip] = views_ssim(disc, ref, img, center, radius, &rd, &floor_worst[clip]);
        asp_renderer_destroy(disc);
        if (!clip)
            save_sheet(img, "octahedron-discs-unclipped");
        release_views(img);
        fprintf(stderr, "octahedron %-26s SSIM mean %.4f, worst view %.4f\n",
                clip ? "discs, another seed" : "discs unclipped, another", floor_mean[clip], floor_worst[clip]);
    }
    CHECK_MSG(floor_mean[1] > 0.98, "another sampling of the octahedron scores %.4f", floor_mean[1]);
    CHECK(floor_mean[0] < floor_mean[1]);

    asp_renderer *r = NULL;
    asp_prim_renderer_desc pd = {.origin = {oct->origin[0], oct->origin[1], oct->origin[2]}};
    CHECK_OK(asp_prim_renderer_create(gl, &dps->levels[0], &pd, &r, &err), ep(&err));
    CHECK(r && asp_renderer_count(r) == 8 && strcmp(asp_renderer_name(r), "prim") == 0);
    double means[16] = {0};
    for (unsigned m = 0; r && asp_prim_render_method_name(m); m++) {
        const char *name = asp_prim_render_method_name(m);
        for (int clip = 1; clip >= 0; clip--) {
            asp_prim_render_options o = {.method = (asp_prim_render_method)m, .crease_angle = clip ? 0.0f : -1.0f};
            CHECK_OK(asp_prim_renderer_set_options(r, &o, &err), ep(&err));
            double worst = 0, mean = views_ssim(r, ref, img, center, radius, &rd, &worst);
            char label[64], sheet[64];
            snprintf(label, sizeof label, "%s%s", name, clip ? "" : ", creases off");
            fprintf(stderr, "octahedron %-26s SSIM mean %.4f, worst view %.4f\n", label, mean, worst);
            snprintf(sheet, sizeof sheet, "octahedron-%s%s", name, clip ? "" : "-unclipped");
            save_sheet(img, sheet);
            release_views(img);
            if (!clip) {
                if (m != ASP_PRIM_RENDER_BLEND_ALL && m != ASP_PRIM_RENDER_POLYGONS)
                    CHECK_MSG(mean >= 0.80, "%s: SSIM mean %.4f", label, mean);
                continue;
            }
            means[m] = mean;
            if (m != ASP_PRIM_RENDER_BLEND_ALL)
                CHECK_MSG(mean >= 0.95, "%s: SSIM mean %.4f (worst view %.4f), expected >= 0.95", label, mean, worst);
        }
    }
    // the per-pixel division removes the seeds' light seams (journal Fig. 11, thesis 5.3.1)
    CHECK(means[ASP_PRIM_RENDER_NORMALIZED] > means[ASP_PRIM_RENDER_OVERLAP]);
    CHECK(means[ASP_PRIM_RENDER_PREFIX] > means[ASP_PRIM_RENDER_OVERLAP]);
    // nothing limits visibility in blend-all: the far faces show through (thesis Fig. 4.3)
    CHECK(means[ASP_PRIM_RENDER_BLEND_ALL] < means[ASP_PRIM_RENDER_PREFIX]);
    asp_renderer_destroy(r);
    release_views(ref);
    asp_dps_destroy(dps);
    asp_cloud_destroy(oct);
    asp_cloud_destroy(other);
}

static void cleanup(void)
{
    if (dps_path[sizeof dps_path - 2] != 'X')
        unlink(dps_path);
}

TEST_MAIN(TEST_CASE(build_primitives), TEST_FIXTURE(setup), TEST_CASE(test_octahedron_methods), TEST_FIXTURE(teardown),
          TEST_FIXTURE(cleanup))
