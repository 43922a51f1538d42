/*
 * Scene files of instances (instances.h): the transforms a good file
 * describes, strict refusal of bad files (each message names the file, the
 * instance and the field), sources resolved and loaded once, the scene's
 * framing, recursion refused, save/read round trip, and `scene field`'s
 * layout: deterministic for a seed, on the ground, receding from the camera.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "amgsplat/instances.h"
#include "amgsplat/sample.h"
#include "harness.h"

static asp_error *ep(asp_error *e)
{
    return e;
}

static int parse(const char *text, asp_instance_scene *s, asp_error *err)
{
    return asp_instance_scene_parse(text, strlen(text), "/data/s.json", s, err);
}

/* Applies model m to p. */
static void apply(const double m[16], const double p[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

static void test_good_file(void)
{
    asp_instance_scene s;
    asp_error err = {0, ""};
    const char *text = "{\"version\": 1, \"instances\": ["
                       "{\"source\": \"a.ply\", \"translate\": [1, 2, 3]},"
                       "{\"source\": \"b/c.dps\", \"rotate_deg\": [0, 90, 0], \"scale\": 2},"
                       "{\"source\": \"a.ply\", \"rotate_axis_angle\": [0, 0, 5, 90], \"scale\": [1, 2, 3]},"
                       "{\"source\": \"/abs/m.obj\", \"matrix\": [2,0,0,0, 0,2,0,0, 0,0,2,0, 7,8,9,1]}],"
                       "\"camera\": {\"eye\": [0, 1, 10], \"target\": [0, 1, 0], \"fov\": 30},"
                       "\"background\": [10, 20, 30]}";
    CHECK_OK(parse(text, &s, &err), ep(&err));
    CHECK(s.instance_count == 4);
    CHECK(s.source_count == 3); // a.ply twice: one source
    CHECK(s.instances[0].source == 0 && s.instances[2].source == 0 && s.instances[1].source == 1);
    CHECK(strcmp(s.sources[0].path, "/data/a.ply") == 0);
    CHECK(strcmp(s.sources[1].path, "/data/b/c.dps") == 0);
    CHECK(strcmp(s.sources[2].path, "/abs/m.obj") == 0);
    double p[3] = {1, 0, 0}, q[3];
    apply(s.instances[0].model, p, q);
    CHECK_NEAR(q[0], 2, 1e-12);
    CHECK_NEAR(q[1], 2, 1e-12);
    CHECK_NEAR(q[2], 3, 1e-12);
    // yaw 90 about +y takes +x to -z, then scale 2
    apply(s.instances[1].model, p, q);
    CHECK_NEAR(q[0], 0, 1e-12);
    CHECK_NEAR(q[2], -2, 1e-12);
    // scale before rotation: (0, 1, 0) becomes (0, 2, 0), then +90 about +z takes it to (-2, 0, 0)
    double y[3] = {0, 1, 0};
    apply(s.instances[2].model, y, q);
    CHECK_NEAR(q[0], -2, 1e-12);
    CHECK_NEAR(q[1], 0, 1e-12);
    apply(s.instances[3].model, p, q);
    CHECK_NEAR(q[0], 9, 1e-12);
    CHECK_NEAR(q[2], 9, 1e-12);
    CHECK(s.camera.given && s.camera.fov_y == 30.0f && s.camera.eye[2] == 10);
    CHECK(s.has_background && s.background[0] == 10 && s.background[2] == 30 && s.background[3] == 255);
    asp_instance_scene_release(&s);
    CHECK(s.instances == NULL && s.instance_count == 0);
}

/* Each bad file is refused with ASP_EFORMAT and a message holding want. */
static void test_bad_files(void)
{
    static const struct {
        const char *text, *want;
    } bad[] = {
        {"[1, 2]", "expected a JSON object"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}", "not JSON near byte"},
        {"{\"version\": 2, \"instances\": [{\"source\": \"a.ply\"}]}", "'version' must be 1"},
        {"{\"version\": 1, \"instances\": []}", "'instances' must be a non-empty array"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}, {\"translate\": [0, 0, 0]}]}",
         "instance 1: missing 'source'"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"translate\": [0, 1e999, 0]}]}",
         "instance 0: 'translate' must be three finite numbers"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"translate\": [0, 0]}]}",
         "instance 0: 'translate'"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"scale\": 0}]}", "instance 0: 'scale' must be"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"scale\": -1}]}", "'scale' must be a number > 0"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"matrix\": [1,0,0,0, 0,1,0,0, 1,1,0,0, 0,0,0,1]}]}",
         "instance 0: the transform is singular"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,1, 0,0,0,1]}]}",
         "must be affine"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"matrix\": [1,0,0,0]}]}", "'matrix' must be 16"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"matrix\": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}]}",
         "instance 0: the transform mirrors"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],"
         " \"scale\": 2}]}",
         "'matrix' replaces translate"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"translation\": [1, 2, 3]}]}",
         "unknown field 'translation'"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"rotate_deg\": [0,0,0],"
         " \"rotate_axis_angle\": [0,1,0,5]}]}",
         "not both"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\", \"rotate_axis_angle\": [0,0,0,5]}]}",
         "non-zero axis"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"\"}]}", "instance 0: 'source' must be a file name"},
        {"{\"version\": 1, \"instances\": [{\"source\": 3}]}", "'source' must be a file name"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}], \"camera\": {\"eye\": [0,0,1], \"target\": "
         "[0,0,1]}}",
         "camera: 'eye' and 'target' are the same point"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}], \"camera\": {\"eye\": [0,0,1], \"target\": "
         "[0,0,0], \"fov\": 180}}",
         "'fov' must be degrees in (0, 180)"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}], \"background\": [0, 0, 256]}",
         "'background' must be"},
        {"{\"version\": 1, \"instances\": [{\"source\": \"a.ply\"}], \"extra\": 1}", "unknown field 'extra'"},
        {"{\"version\": 1, \"instances\": [7]}", "instance 0: expected an object"},
        {"", "not JSON"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        asp_instance_scene s;
        memset(&s, 0x5a, sizeof s); // unchanged on failure: the pattern stays
        asp_error err = {0, ""};
        int rc = parse(bad[i].text, &s, &err);
        CHECK_MSG(rc == ASP_EFORMAT, "bad file %zu: rc %d", i, rc);
        CHECK_MSG(strstr(err.msg, bad[i].want) != NULL, "bad file %zu: '%s' lacks '%s'", i, err.msg, bad[i].want);
        CHECK_MSG(strstr(err.msg, "/data/s.json") != NULL, "bad file %zu: '%s' does not name the file", i, err.msg);
        CHECK(s.instance_count == (size_t)0x5a5a5a5a5a5a5a5aull);
    }
}

/* Too many instances: refused before any allocation of that size. */
static void test_huge_count(void)
{
    size_t n = ASP_INSTANCE_SCENE_MAX_INSTANCES + 1;
    size_t cap = 64 + n * 4;
    char *text = malloc(cap);
    CHECK(text != NULL);
    if (!text)
        return;
    size_t len = (size_t)snprintf(text, cap, "{\"version\": 1, \"instances\": [");
    for (size_t i = 0; i < n; i++)
        len += (size_t)snprintf(text + len, cap - len, "%s{}", i ? "," : "");
    len += (size_t)snprintf(text + len, cap - len, "]}");
    asp_instance_scene s;
    asp_error err = {0, ""};
    CHECK(asp_instance_scene_parse(text, len, "big.json", &s, &err) == ASP_EFORMAT);
    CHECK(strstr(err.msg, "more than 1000000") != NULL);
    free(text);
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

/* Sources load once, relative to the scene file; the frame holds every moved, scaled instance. */
static void test_load_and_frame(void)
{
    char dir[] = "/tmp/asp_test_instances_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char ply[600], scene[600], nested[600], missing[600];
    snprintf(ply, sizeof ply, "%s/sphere.ply", dir);
    snprintf(scene, sizeof scene, "%s/s.json", dir);
    snprintf(nested, sizeof nested, "%s/nested.json", dir);
    snprintf(missing, sizeof missing, "%s/missing.json", dir);
    asp_cloud *c = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 2000}, NULL, &c, &err), ep(&err));
    CHECK_OK(asp_cloud_save(c, ply, NULL, &err), ep(&err));
    asp_cloud_destroy(c);
    write_text(scene, "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\", \"translate\": [-10, 0, 0]},"
                      "{\"source\": \"sphere.ply\", \"translate\": [10, 0, 0], \"scale\": 3}]}");
    asp_instance_scene s;
    CHECK_OK(asp_instance_scene_load(scene, NULL, NULL, &s, &err), ep(&err));
    if (s.instance_count == 2) {
        CHECK(s.source_count == 1 && s.sources[0].scene.cloud && s.sources[0].scene.cloud->count == 2000);
        double r = s.sources[0].scene.frame.radius; // about 1 plus the disc radius
        CHECK(r > 1.0 && r < 1.2);
        // the box of the spheres runs from -10 - r to 10 + 3 r: centre and radius follow
        CHECK_NEAR(s.frame.center[0], r, 1e-3);
        CHECK_NEAR(s.frame.radius, 10 + 2 * r, 1e-3);
        CHECK(asp_instance_scene_count(&s, 0) == 2);
        float m[32];
        CHECK(asp_instance_scene_models(&s, 0, m) == 2);
        // local (0,0,0) is the cloud's origin; in the scene centred on the frame it lies at 10 - centre
        CHECK_NEAR(m[16 + 12], 10 - s.frame.center[0] + 3 * s.sources[0].scene.origin[0], 1e-4);
        CHECK_NEAR(m[16 + 0], 3.0, 1e-6);
        // the scene camera is GL-free (camera.h): every build checks it
        asp_camera cam;
        asp_instance_scene_camera(&s, 0, 1.0f, 40.0f, 0.0f, 0.0f, 0.0f, &cam);
        CHECK(cam.distance > s.frame.radius && cam.z_far > cam.distance);
    }
    asp_instance_scene_release(&s);

    // a scene inside a scene is refused, naming the instance and source
    write_text(nested, "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\"}, {\"source\": \"s.json\"}]}");
    CHECK(asp_instance_scene_load(nested, NULL, NULL, &s, &err) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(err.msg, "instance 1 source 's.json'") && strstr(err.msg, "scene inside a scene"), "%s",
              err.msg);
    // a missing source names the scene file, the instance and the source
    write_text(missing, "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\"}, {\"source\": \"no.ply\"}]}");
    CHECK(asp_instance_scene_load(missing, NULL, NULL, &s, &err) == ASP_EIO);
    CHECK_MSG(strstr(err.msg, "missing.json' instance 1 source 'no.ply'"), "%s", err.msg);
    // the recogniser tells a scene by its content, whatever its name
    asp_file_type t;
    CHECK_OK(asp_file_recognise(scene, &t, &err), ep(&err));
    CHECK(t.kind == ASP_FILE_SCENE && strcmp(t.format, "json") == 0 && t.by_magic);
    const char *exp = "{\"format\": \"amgsplat-scenes 1\", \"tests\": {}}";
    CHECK(asp_file_recognise_memory(exp, strlen(exp), "scenes.json", &t, &err) == ASP_EUNSUPPORTED);
    unlink(ply);
    unlink(scene);
    unlink(nested);
    unlink(missing);
    rmdir(dir);
}

/* `scene field`: seeded, so equal seeds give equal files; on the ground; the camera looks along it. */
static void test_field(void)
{
    asp_cloud *c = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_synth(ASP_SYNTH_SPHERE, &(asp_synth_desc){.points = 1000}, NULL, &c, &err), ep(&err));
    if (!c)
        return;
    for (size_t i = 0; i < c->count; i++)
        c->positions[3 * i + 1] += 5.0f; // a model standing above its own origin
    asp_scene model;
    memset(&model, 0, sizeof model);
    model.cloud = c;
    CHECK_OK(asp_cloud_frame(c, &model.frame, &err), ep(&err));
    asp_instance_scene a, b, d;
    asp_instance_field_desc desc = {.instances = 300, .seed = 7};
    CHECK_OK(asp_instance_field(&model, "m.ply", &desc, &a, &err), ep(&err));
    CHECK_OK(asp_instance_field(&model, "m.ply", &desc, &b, &err), ep(&err));
    desc.seed = 8;
    CHECK_OK(asp_instance_field(&model, "m.ply", &desc, &d, &err), ep(&err));
    CHECK(a.instance_count == 300 && a.source_count == 1 && a.camera.given);
    CHECK(memcmp(a.instances, b.instances, 300 * sizeof *a.instances) == 0);
    CHECK(memcmp(a.instances, d.instances, 300 * sizeof *a.instances) != 0);
    double lowest = INFINITY, zmin = INFINITY, zmax = -INFINITY;
    for (size_t k = 0; k < a.instance_count; k++) {
        for (size_t i = 0; i < c->count; i++) {
            double p[3] = {c->positions[3 * i], c->positions[3 * i + 1], c->positions[3 * i + 2]}, q[3];
            apply(a.instances[k].model, p, q);
            lowest = fmin(lowest, q[1]);
        }
        zmin = fmin(zmin, a.instances[k].model[14]);
        zmax = fmax(zmax, a.instances[k].model[14]);
        // yaw only: y stays up
        CHECK_NEAR(a.instances[k].model[5], 1.0, 1e-12);
    }
    CHECK_NEAR(lowest, 0.0, 1e-6); // standing on y = 0
    // twice as deep as wide (13 x 24 grid steps) and receding from the camera along -z
    double step = 1.5 * 2 * model.frame.radius;
    CHECK(zmax - zmin > 20 * step);
    CHECK(a.camera.eye[2] > zmax && a.camera.target[2] < zmin + 2 * step && a.camera.eye[1] > 0);
    CHECK(asp_instance_field(&model, "m.ply", &(asp_instance_field_desc){.instances = 2000000}, &d, &err) ==
          ASP_EINVAL);
    // save and read back: the same instances to the last bit
    char dir[] = "/tmp/asp_test_field_XXXXXX", path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/field.json", dir);
    CHECK_OK(asp_instance_scene_save(&a, path, &err), ep(&err));
    asp_instance_scene r;
    CHECK_OK(asp_instance_scene_read(path, &r, &err), ep(&err));
    CHECK(r.instance_count == 300 && r.camera.given && strcmp(r.sources[0].name, "m.ply") == 0);
    if (r.instance_count == 300)
        CHECK(memcmp(a.instances, r.instances, 300 * sizeof *a.instances) == 0);
    unlink(path);
    rmdir(dir);
    asp_instance_scene_release(&r);
    asp_instance_scene_release(&a);
    asp_instance_scene_release(&b);
    asp_instance_scene_release(&d);
    asp_cloud_destroy(c);
}

TEST_MAIN(TEST_CASE(test_good_file), TEST_CASE(test_bad_files), TEST_CASE(test_huge_count),
          TEST_CASE(test_load_and_frame), TEST_CASE(test_field))
