/*
 * Tilesets (issue 32, asp_tiles_export_hier): a UTM-placed grid keeps its world position through
 * the root transform in 3D Tiles' z-up frame ((x, y, z) -> (x, -z, y) of the glTF content, then
 * + origin), the root box holds every point in that frame, the leaves hold every point once, and
 * bad arguments fail with their codes; the same grid's streamed hierarchy (asp_ooc_build) tiles with
 * refine ADD (asp_tiles_export_ooc), every point in one tile, the same frames.
 */
#include <errno.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "amgsplat/amgsplat.h"
#include "harness.h"

static char tmpdir[512];

static cJSON *read_json(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    size_t got = fread(s, 1, (size_t)n, f);
    fclose(f);
    s[got] = '\0';
    cJSON *j = cJSON_Parse(s);
    free(s);
    return j;
}

static double item(const cJSON *a, int i)
{
    return cJSON_GetNumberValue(cJSON_GetArrayItem(a, i));
}

/* Leaves (geometricError 0) counted and every error checked against its parent's. */
static void walk(const cJSON *tile, double parent_error, size_t *leaves, int *bad)
{
    double e = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(tile, "geometricError"));
    if (!(e >= 0 && e <= parent_error))
        (*bad)++;
    if (!cJSON_GetObjectItemCaseSensitive(tile, "boundingVolume") || !cJSON_GetObjectItemCaseSensitive(tile, "content"))
        (*bad)++;
    const cJSON *kids = cJSON_GetObjectItemCaseSensitive(tile, "children"), *k;
    if (e == 0 && kids)
        (*bad)++;
    if (e == 0)
        (*leaves)++;
    cJSON_ArrayForEach(k, kids) walk(k, e, leaves, bad);
}

/* A 60 x 60 grid on y = 0 (a floor, y up) at x = 500000, z = 5000000, 1 cm apart. */
static void test_utm_floor(void)
{
    enum { SIDE = 60, N = SIDE * SIDE };
    asp_cloud *c = NULL;
    asp_hier *h = NULL;
    asp_error err = {0};
    CHECK_OK(asp_cloud_create(N, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, &err), &err);
    if (!c)
        return;
    c->origin[0] = 500000.0;
    c->origin[1] = 250.0;
    c->origin[2] = 5000000.0;
    for (size_t i = 0; i < N; i++) {
        c->positions[3 * i] = 0.01f * (float)(i % SIDE);
        c->positions[3 * i + 1] = 0.0f;
        c->positions[3 * i + 2] = 0.01f * (float)(i / SIDE);
        c->normals[3 * i + 1] = 1.0f;
        uint8_t rgba[4] = {(uint8_t)(i % 256), 128, 255, 255};
        memcpy(c->colors + 4 * i, rgba, 4);
    }
    CHECK_OK(asp_hier_build(c, NULL, NULL, &h, &err), &err);
    asp_cloud_destroy(c);
    if (!h)
        return;
    char dir[600], path[700];
    snprintf(dir, sizeof dir, "%s/utm", tmpdir);
    asp_tiles_stats st = {0};
    const asp_tiles_desc desc = {.tile_points = 256};
    CHECK_OK(asp_tiles_export_hier(h, dir, &desc, &st, &err), &err);
    CHECK(st.points == N && st.leaf_points == N && st.tiles > 8 && st.depth >= 2 && st.root_error > 0);
    CHECK(st.origin[0] == 500000.0 && st.origin[2] == 5000000.0);
    snprintf(path, sizeof path, "%s/tileset.json", dir);
    cJSON *ts = read_json(path);
    CHECK_MSG(ts != NULL, "cannot parse '%s'", path);
    if (ts) {
        const cJSON *root = cJSON_GetObjectItemCaseSensitive(ts, "root");
        // the root transform: + origin in the z-up frame, (x, -z, y) of the y-up origin
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(root, "transform");
        CHECK(cJSON_GetArraySize(m) == 16);
        CHECK(item(m, 12) == 500000.0 && item(m, 13) == -5000000.0 && item(m, 14) == 250.0 && item(m, 15) == 1.0);
        CHECK(item(m, 0) == 1.0 && item(m, 5) == 1.0 && item(m, 10) == 1.0);
        // the floor (y = 0, z in [0, 0.59]) is the z-up box's z = 0 plane, y in [-0.59, 0]
        const cJSON *box = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "boundingVolume"), "box");
        double cx = item(box, 0), cy = item(box, 1), cz = item(box, 2);
        double hx = item(box, 3), hy = item(box, 7), hz = item(box, 11);
        CHECK(cx - hx <= 0.0 && cx + hx >= 0.59 - 1e-6);
        CHECK(cy - hy <= -0.59 + 1e-6 && cy + hy >= 0.0);
        CHECK(fabs(cz) < 0.05 && hz < 0.05); // flat: the splats' own extent only
        CHECK(strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(root, "refine")), "REPLACE") == 0);
        size_t leaves = 0;
        int bad = 0;
        walk(root, cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(ts, "geometricError")), &leaves, &bad);
        CHECK(bad == 0 && leaves > 1);
        cJSON_Delete(ts);
    }
    // bad arguments
    asp_tiles_desc levels = {.gltf = {.level_count = 1}};
    CHECK(asp_tiles_export_hier(h, dir, &levels, NULL, &err) == ASP_EINVAL);
    snprintf(path, sizeof path, "%s/afile", tmpdir);
    FILE *f = fopen(path, "w");
    if (f)
        fclose(f);
    CHECK(asp_tiles_export_hier(h, path, NULL, NULL, &err) == ASP_EIO);
    CHECK(strstr(err.msg, "cannot create directory") != NULL);
    asp_hier_destroy(h);
}

/* A finer floor (300 x 300, 2 mm) through a streamed hierarchy: ADD tiles, one a node, every point once. */
static void test_utm_floor_streamed(void)
{
    // finer than the inner nodes' 128^3 grid, so the root keeps a subsample and children the rest
    enum { SIDE = 300, N = SIDE * SIDE };
    asp_cloud *c = NULL;
    asp_error err = {0};
    CHECK_OK(asp_cloud_create(N, ASP_ATTR_COLORS, NULL, &c, &err), &err);
    if (!c)
        return;
    c->origin[0] = 500000.0;
    c->origin[1] = 250.0;
    c->origin[2] = 5000000.0;
    for (size_t i = 0; i < N; i++) {
        c->positions[3 * i] = 0.002f * (float)(i % SIDE);
        c->positions[3 * i + 1] = 0.0f;
        c->positions[3 * i + 2] = 0.002f * (float)(i / SIDE);
        uint8_t rgba[4] = {(uint8_t)(i % 256), 128, 255, 255};
        memcpy(c->colors + 4 * i, rgba, 4);
    }
    char ply[600], hier[600], dir[600], path[700];
    snprintf(ply, sizeof ply, "%s/floor.ply", tmpdir);
    snprintf(hier, sizeof hier, "%s/floor.hier", tmpdir);
    snprintf(dir, sizeof dir, "%s/floor_tiles", tmpdir);
    CHECK_OK(asp_cloud_save(c, ply, NULL, &err), &err);
    asp_cloud_destroy(c);
    CHECK_OK(asp_ooc_build(ply, hier, &(asp_ooc_build_desc){.node_points = 256}, NULL, NULL, &err), &err);
    asp_ooc *ooc = NULL;
    CHECK_OK(asp_ooc_open(hier, NULL, &ooc, &err), &err);
    if (!ooc)
        return;
    asp_tiles_stats st = {0};
    CHECK_OK(asp_tiles_export_ooc(ooc, dir, NULL, &st, &err), &err);
    // every point stored once: the tiles' points are the set
    CHECK(st.points == N && st.splats == N && st.tiles >= 2 && st.leaf_points > 0 && st.leaf_points < N);
    double o[3];
    asp_ooc_origin(ooc, o);
    CHECK(st.origin[0] == o[0] && st.origin[1] == o[1] && st.origin[2] == o[2]); // y up already
    snprintf(path, sizeof path, "%s/tileset.json", dir);
    cJSON *ts = read_json(path);
    CHECK_MSG(ts != NULL, "cannot parse '%s'", path);
    if (ts) {
        const cJSON *root = cJSON_GetObjectItemCaseSensitive(ts, "root");
        CHECK(strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(root, "refine")), "ADD") == 0);
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(root, "transform");
        CHECK(cJSON_GetArraySize(m) == 16);
        CHECK(fabs(item(m, 12) - 500000.0) < 1 && fabs(item(m, 13) + 5000000.0) < 1 && fabs(item(m, 14) - 250.0) < 1);
        CHECK(item(m, 12) == o[0] && item(m, 13) == -o[2] && item(m, 14) == o[1]);
        // the floor, world y = 250, is the z-up box's plane z = 250 - origin y; flat, and the whole 0.598 wide
        const cJSON *box = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "boundingVolume"), "box");
        double cx = item(box, 0), cy = item(box, 1), cz = item(box, 2);
        double hx = item(box, 3), hy = item(box, 7), hz = item(box, 11);
        double wx0 = 500000.0 - o[0], wz0 = 5000000.0 - o[2], y = 250.0 - o[1];
        CHECK(cx - hx <= wx0 + 1e-3 && cx + hx >= wx0 + 0.598 - 1e-3);
        CHECK(cy - hy <= -(wz0 + 0.598) + 1e-3 && cy + hy >= -wz0 - 1e-3);
        CHECK(fabs(cz - y) < 1e-3 && hz < 1e-3);
        size_t leaves = 0;
        int bad = 0;
        walk(root, cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(ts, "geometricError")), &leaves, &bad);
        CHECK(bad == 0 && leaves > 1);
        CHECK(cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(root, "geometricError")) ==
              (double)asp_ooc_nodes(ooc)[0].spacing);
        cJSON_Delete(ts);
    }
    // the nodes are the tiles: no tile budget; no levels
    CHECK(asp_tiles_export_ooc(ooc, dir, &(asp_tiles_desc){.tile_points = 100}, NULL, &err) == ASP_EINVAL);
    CHECK(asp_tiles_export_ooc(ooc, dir, &(asp_tiles_desc){.gltf = {.level_count = 1}}, NULL, &err) == ASP_EINVAL);
    // a node number past the table
    asp_ooc_point p;
    CHECK(asp_ooc_read_points(ooc, (uint32_t)asp_ooc_node_count(ooc), &p, &err) == ASP_EINVAL);
    asp_ooc_close(ooc);
}

static void setup(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/asp_export_tiles_%ld", base ? base : "/tmp", (long)getpid());
    CHECK_MSG(mkdir(tmpdir, 0700) == 0 || errno == EEXIST, "cannot create '%s': %s", tmpdir, strerror(errno));
}

static void cleanup(void)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_utm_floor), TEST_CASE(test_utm_floor_streamed),
          TEST_FIXTURE(cleanup))
