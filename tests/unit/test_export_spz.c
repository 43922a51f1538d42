/*
 * SPZ splats (issue 32, export --splat-codec spz): the GLB's SPZ stream, gunzipped with zlib and read
 * as the format describes it (nianticlabs/spz README: 16-byte header, then positions, alphas,
 * colours, scales, rotations), gives back the plain export's Gaussians through the node's matrix,
 * within SPZ's 8-bit steps; the flag's conflicts are refused.
 */
#include <errno.h>
#include <sys/stat.h>
#include <zlib.h>

#include <cjson/cJSON.h>

#include "amgsplat/amgsplat.h"
#include "harness.h"

enum { N = 400 };
static char tmpdir[512];

static uint32_t u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The GLB at path: its bytes (free) with *json parsed and *bin the binary chunk; NULL on a bad file. */
static uint8_t *glb_read(const char *path, cJSON **json, const uint8_t **bin)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    size_t size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc(size);
    size_t got = b ? fread(b, 1, size, f) : 0;
    fclose(f);
    if (got != size || size < 28 || memcmp(b, "glTF", 4) != 0 || 20 + u32(b + 12) + 8 > size) {
        free(b);
        return NULL;
    }
    *json = cJSON_ParseWithLength((const char *)b + 20, u32(b + 12));
    *bin = b + 28 + u32(b + 12);
    return b;
}

static double num(const cJSON *o, const char *key) { return cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(o, key)); }

static const cJSON *item(const cJSON *root, const char *array, int index)
{
    return cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, array), index);
}

static const float *floats(const cJSON *json, const uint8_t *bin, const cJSON *attrs, const char *name)
{
    const cJSON *acc = item(json, "accessors", (int)num(attrs, name));
    const cJSON *view = item(json, "bufferViews", (int)num(acc, "bufferView"));
    return (const float *)(bin + (size_t)num(view, "byteOffset"));
}

static asp_cloud *grid_cloud(void)
{
    asp_cloud *c = NULL;
    asp_error err = {0};
    CHECK_OK(asp_cloud_create(N, ASP_ATTR_NORMALS | ASP_ATTR_COLORS, NULL, &c, &err), &err);
    if (!c)
        return NULL;
    for (size_t i = 0; i < N; i++) {
        // a wavy 20 x 20 grid: normals, colours and splat shapes all vary
        double x = 0.01 * (double)(i % 20), y = 0.01 * (double)(i / 20), z = 0.004 * sin(40 * x) * cos(30 * y);
        c->positions[3 * i] = (float)x;
        c->positions[3 * i + 1] = (float)y;
        c->positions[3 * i + 2] = (float)z;
        double nx = -0.16 * cos(40 * x) * cos(30 * y), ny = 0.12 * sin(40 * x) * sin(30 * y);
        double nl = sqrt(nx * nx + ny * ny + 1);
        c->normals[3 * i] = (float)(nx / nl);
        c->normals[3 * i + 1] = (float)(ny / nl);
        c->normals[3 * i + 2] = (float)(1 / nl);
        uint8_t rgba[4] = {(uint8_t)(i % 256), (uint8_t)(7 * i % 256), 200, 255};
        memcpy(c->colors + 4 * i, rgba, 4);
    }
    return c;
}

static void test_spz_stream(void)
{
    asp_cloud *c = grid_cloud();
    if (!c)
        return;
    asp_error err = {0};
    char pp[600], sp[600];
    snprintf(pp, sizeof pp, "%s/plain.glb", tmpdir);
    snprintf(sp, sizeof sp, "%s/spz.glb", tmpdir);
    CHECK_OK(asp_gltf_export_cloud(c, pp, &(asp_gltf_desc){.flags = ASP_GLTF_PLAIN}, NULL, NULL, &err), &err);
    CHECK_OK(asp_gltf_export_cloud(c, sp, &(asp_gltf_desc){.flags = ASP_GLTF_SPZ}, NULL, NULL, &err), &err);
    cJSON *jp = NULL, *js = NULL;
    const uint8_t *bp = NULL, *bs = NULL;
    uint8_t *fp = glb_read(pp, &jp, &bp), *fs = glb_read(sp, &js, &bs);
    CHECK(fp && fs && jp && js);
    if (!fp || !fs || !jp || !js)
        goto done;
    const cJSON *pr = item(item(js, "meshes", 0), "primitives", 0);
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(pr, "extensions"),
                                                                          "KHR_gaussian_splatting"),
                                         "extensions"),
        "KHR_gaussian_splatting_compression_spz_2");
    CHECK(ext != NULL);
    if (!ext)
        goto done;
    const cJSON *view = item(js, "bufferViews", (int)num(ext, "bufferView"));
    // gunzip (zlib's window bits 15 + 16: gzip only)
    size_t raw_size = 16 + (size_t)N * 19;
    uint8_t *raw = malloc(raw_size + 1);
    z_stream z;
    memset(&z, 0, sizeof z);
    CHECK(inflateInit2(&z, 15 + 16) == Z_OK);
    z.next_in = (Bytef *)(bs + (size_t)num(view, "byteOffset"));
    z.avail_in = (uInt)num(view, "byteLength");
    z.next_out = raw;
    z.avail_out = (uInt)raw_size + 1;
    int zr = inflate(&z, Z_FINISH);
    CHECK_MSG(zr == Z_STREAM_END && z.total_out == raw_size, "gunzip: %d, %lu bytes of %zu", zr, z.total_out, raw_size);
    inflateEnd(&z);
    CHECK(u32(raw) == 0x5053474eu && u32(raw + 4) == 2 && u32(raw + 8) == N);
    CHECK_MSG(raw[12] == 0 && raw[13] == 8 && raw[14] == 0, "SH degree %d, fractional bits %d, flags %d", raw[12],
              raw[13], raw[14]);
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(item(js, "nodes", 0), "matrix");
    double s = cJSON_GetArrayItem(m, 0)->valuedouble, t[3];
    for (int k = 0; k < 3; k++)
        t[k] = cJSON_GetArrayItem(m, 12 + k)->valuedouble;
    CHECK(fabs(s - 0.19 / 256) < 1e-6 && cJSON_GetArrayItem(m, 5)->valuedouble == s);
    const cJSON *ap = cJSON_GetObjectItemCaseSensitive(item(item(jp, "meshes", 0), "primitives", 0), "attributes");
    const float *ppos = floats(jp, bp, ap, "POSITION"), *prot = floats(jp, bp, ap, "KHR_gaussian_splatting:ROTATION");
    const float *pscale = floats(jp, bp, ap, "KHR_gaussian_splatting:SCALE");
    const float *psh = floats(jp, bp, ap, "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0");
    const uint8_t *pos = raw + 16, *alpha = pos + 9 * N, *col = alpha + N, *scl = col + 3 * N, *rot = scl + 3 * N;
    int seen[N] = {0}, matched = 0;
    double worst_pos = 0, worst_scale = 0, worst_tilt = 0, worst_sh = 0;
    for (size_t j = 0; j < N; j++) {
        double w[3];
        for (int k = 0; k < 3; k++) {
            int32_t v = pos[9 * j + 3 * k] | pos[9 * j + 3 * k + 1] << 8 | pos[9 * j + 3 * k + 2] << 16;
            if (v & 0x800000)
                v -= 0x1000000;
            w[k] = t[k] + s * (v / 256.0);
        }
        long ix = lround(w[0] / 0.01), iy = lround(w[1] / 0.01);
        if (ix < 0 || ix >= 20 || iy < 0 || iy >= 20 || seen[iy * 20 + ix]++)
            continue;
        size_t i = (size_t)(iy * 20 + ix);
        matched++;
        for (int k = 0; k < 3; k++) {
            worst_pos = fmax(worst_pos, fabs(w[k] - ppos[3 * i + k]));
            // SCALE in the node's units: ln sigma - ln s
            worst_scale = fmax(worst_scale, fabs(scl[3 * j + k] / 16.0 - 10.0 + log(s) - pscale[3 * i + k]));
            worst_sh = fmax(worst_sh, fabs((col[3 * j + k] / 255.0 - 0.5) / 0.15 - psh[3 * i + k]));
        }
        CHECK(alpha[j] == 255);
        // the splat's normal (third axis) from the rebuilt quaternion against the plain one's
        double x = rot[3 * j] / 127.5 - 1, y = rot[3 * j + 1] / 127.5 - 1, zq = rot[3 * j + 2] / 127.5 - 1;
        double wq = sqrt(fmax(0.0, 1 - x * x - y * y - zq * zq));
        double n1[3] = {2 * (x * zq + wq * y), 2 * (y * zq - wq * x), 1 - 2 * (x * x + y * y)};
        const float *q = prot + 4 * i;
        double n0[3] = {2 * (q[0] * q[2] + q[3] * q[1]), 2 * (q[1] * q[2] - q[3] * q[0]),
                        1 - 2 * (q[0] * q[0] + q[1] * q[1])};
        double dot = fabs(n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2]); // a half turn may flip it
        worst_tilt = fmax(worst_tilt, acos(fmin(dot, 1.0)) * 57.29577951308232);
    }
    CHECK_MSG(matched == N, "%d of %d SPZ splats matched a grid point", matched, N);
    CHECK_MSG(worst_pos <= 0.51 * s / 256 + 1e-7, "position error %g (step %g)", worst_pos, s / 256);
    CHECK_MSG(worst_scale <= 1.0 / 32 + 1e-6, "ln sigma error %g (SPZ step 1/16)", worst_scale);
    CHECK_MSG(worst_sh <= 0.5 / (0.15 * 255) + 1e-6, "SH DC error %g (SPZ step %g)", worst_sh, 1 / (0.15 * 255));
    CHECK_MSG(worst_tilt < 2, "normal tilted by %g degrees (8-bit quaternion)", worst_tilt);
    free(raw);
done:
    cJSON_Delete(jp);
    cJSON_Delete(js);
    free(fp);
    free(fs);
    asp_cloud_destroy(c);
}

static void test_spz_conflicts(void)
{
    asp_cloud *c = grid_cloud();
    if (!c)
        return;
    char path[600];
    snprintf(path, sizeof path, "%s/bad.glb", tmpdir);
    asp_error err = {0};
    CHECK(asp_gltf_export_cloud(c, path, &(asp_gltf_desc){.flags = ASP_GLTF_SPZ | ASP_GLTF_PLAIN}, NULL, NULL, &err) ==
          ASP_EINVAL);
    CHECK(strstr(err.msg, "plain") != NULL);
    CHECK(asp_gltf_export_cloud(c, path, &(asp_gltf_desc){.flags = ASP_GLTF_SPZ | ASP_GLTF_NO_SPLATS}, NULL, NULL,
                                &err) == ASP_EINVAL);
    struct stat st;
    CHECK(stat(path, &st) != 0); // nothing written
    asp_cloud_destroy(c);
}

static void setup(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/asp_export_spz_%ld", base ? base : "/tmp", (long)getpid());
    CHECK_MSG(mkdir(tmpdir, 0700) == 0 || errno == EEXIST, "cannot create '%s': %s", tmpdir, strerror(errno));
}

static void cleanup(void)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_spz_stream), TEST_CASE(test_spz_conflicts), TEST_FIXTURE(cleanup))
