/*
 * libFuzzer target for the streamed .hier reader (asp_ooc_open, asp_ooc_select,
 * asp_ooc_load; issue 28), which takes a path: the bytes go to a temporary
 * file. Any bytes give a clean error naming the file, or an open hierarchy
 * whose node table keeps its promises (children and point ranges inside the
 * tables), whose cut for one fixed view (the render command's default camera
 * on the recorded frame, 64x64, tau 1) lists each node once with its parent
 * first, and whose loaded cloud holds exactly the cut's points with finite
 * positions and positive radii; never a crash, leak or hang. Each input is
 * also tried with its header and node-table checksums made consistent (as
 * fuzz_hier.c does): random mutations almost never keep them, and without
 * the fix none of the checks behind them is reached. Seeds: small converted
 * files (amgsplat synth terrain --points 2000; amgsplat convert X.ply X.hier):
 *   ./fuzz_ooc -max_total_time=300 -rss_limit_mb=2048 -max_len=65536 tools/corpus/fuzz_ooc
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/camera.h"
#include "amgsplat/hier_ooc.h"
#include "fuzz_support.h"
#include "util/checksum.h"

/* docs/hier.md "Streamed layout": 160-byte header, its FNV-1a 64 in the last 8 bytes; table offset and hash */
enum { HEADER = 160, TABLE_AT = 80, TABLE_HASH = 88, MAX_POINTS = 1 << 20 };

/* A broken promise: says which before aborting, so a finding reads without a debugger. */
#define EXPECT(cond)                                                                                               \
    do {                                                                                                           \
        if (!(cond)) {                                                                                             \
            fprintf(stderr, "fuzz_ooc: expected %s (line %d)\n", #cond, __LINE__);                                 \
            abort();                                                                                               \
        }                                                                                                          \
    } while (0)

static void check_cut(asp_ooc *o, const char *path)
{
    size_t nn = asp_ooc_node_count(o);
    const asp_ooc_node *nodes = asp_ooc_nodes(o);
    double origin[3];
    asp_ooc_origin(o, origin);
    asp_camera cam;
    asp_camera_init(&cam);
    cam.up = asp_ooc_frame(o)->up;
    cam.azimuth = 30;
    cam.elevation = 20;
    asp_camera_frame(&cam, asp_ooc_frame(o), origin, 1.0f, 0);
    asp_hier_view hv;
    memset(&hv, 0, sizeof hv);
    asp_camera_view_matrix(&cam, hv.view);
    asp_camera_projection_matrix(&cam, hv.proj);
    asp_camera_eye(&cam, hv.eye);
    hv.width = hv.height = 64;
    hv.tau = 1;
    uint32_t *cut = malloc(nn * sizeof *cut);
    uint8_t *seen = calloc(nn, 1);
    EXPECT(cut && seen);
    size_t n = SIZE_MAX;
    uint64_t pts = UINT64_MAX, sum = 0;
    asp_error err = {0};
    // the viewport is not empty and the heap is at most the node count: no error
    EXPECT(asp_ooc_select(o, &hv, MAX_POINTS, cut, &n, &pts, &err) == 0);
    EXPECT(n <= nn && pts <= MAX_POINTS);
    for (size_t i = 0; i < n; i++) {
        uint32_t id = cut[i];
        EXPECT(id < nn && !seen[id] && (id == 0 || seen[nodes[id].parent])); // each node once, parents first
        seen[id] = 1;
        sum += nodes[id].point_count;
    }
    EXPECT(sum == pts);
    asp_cloud *c = NULL;
    if (asp_ooc_load(o, cut, n, &c, &err) == 0) {
        EXPECT(c && c->count == pts && (!pts || (c->colors && c->radii)));
        for (size_t i = 0; i < c->count; i++) {
            for (int k = 0; k < 3; k++)
                EXPECT(isfinite(c->positions[3 * i + (size_t)k])); // the reader refuses non-finite points
            EXPECT(c->radii[i] > 0 && isfinite(c->radii[i]));
        }
        asp_cloud_destroy(c);
    } else {
        EXPECT(!c && strstr(err.msg, path));
    }
    free(cut);
    free(seen);
}

static void one(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file("fuzz_ooc", "hier", data, size);
    int probe = asp_ooc_probe(path);
    EXPECT(probe == 0 || probe == 1);
    asp_context ctx = {.threads = 1};
    asp_ooc *o = NULL;
    asp_error err = {0};
    if (asp_ooc_open(path, &ctx, &o, &err) != 0) {
        EXPECT(!o && strstr(err.msg, path)); // nothing open on failure, and the message names the file
        return;
    }
    EXPECT(o && probe == 1);
    size_t nn = asp_ooc_node_count(o);
    uint64_t np = asp_ooc_point_count(o);
    const asp_ooc_node *nodes = asp_ooc_nodes(o);
    const asp_frame *f = asp_ooc_frame(o);
    EXPECT(nn > 0 && np > 0 && isfinite(f->radius) && f->radius > 0);
    for (size_t i = 0; i < nn; i++) {
        const asp_ooc_node *a = &nodes[i];
        EXPECT(a->child_count <= 8 && (!a->child_count || (size_t)a->first_child + a->child_count <= nn));
        EXPECT(a->first_point <= np && a->point_count <= np - a->first_point);
    }
    check_cut(o, path);
    asp_ooc_close(o);
}

static uint64_t get64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--)
        v = v << 8 | p[k];
    return v;
}

static void put64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one(data, size);
    if (size < HEADER || memcmp(data, "ASPHIER", 8) != 0)
        return 0;
    uint8_t *fixed = malloc(size);
    EXPECT(fixed);
    memcpy(fixed, data, size);
    uint64_t table = get64(fixed + TABLE_AT);
    if (table >= HEADER && table <= size)
        put64(fixed + TABLE_HASH, asp__fnv1a64(ASP__FNV1A64_START, fixed + table, size - table));
    put64(fixed + HEADER - 8, asp__fnv1a64(ASP__FNV1A64_START, fixed, HEADER - 8));
    if (memcmp(fixed, data, size) != 0)
        one(fixed, size);
    free(fixed);
    return 0;
}
