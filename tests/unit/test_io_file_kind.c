/*
 * The one file recogniser (src/io/file_kind.c, STYLE.md 9b): every kind by
 * magic and by extension, extensions in any case, a lying extension, a PLY
 * with and without faces, and the refusals (FIFO, directory, empty file,
 * unknown extension) that must come at once and name the file.
 */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "amgsplat/io.h"
#include "harness.h"

static char dir[256];

static const char *path_in(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void write_bytes(const char *name, const void *data, size_t n)
{
    FILE *fp = fopen(path_in(name), "wb");
    CHECK(fp != NULL);
    if (fp) {
        fwrite(data, 1, n, fp);
        fclose(fp);
    }
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/asp_test_kind_XXXXXX");
    if (!mkdtemp(dir))
        snprintf(dir, sizeof dir, "/tmp");
}

static const char ply_points[] = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                 "property float z\nend_header\n0 0 0\n";
static const char ply_faces[] = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n"
                                "property float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
                                "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
static const char ply_no_faces[] = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                   "property float z\nelement face 0\nproperty list uchar int vertex_indices\n"
                                   "end_header\n0 0 0\n";
static const unsigned char png_magic[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13};
static const unsigned char jpeg_magic[] = {0xff, 0xd8, 0xff, 0xe0, 0, 16, 'J', 'F', 'I', 'F'};
static const unsigned char tds_magic[] = {0x4d, 0x4d, 0x20, 0, 0, 0, 0x02, 0x00, 0x0a, 0, 0, 0, 3, 0, 0, 0};

struct magic_case {
    const char *name; /* the extension deliberately says nothing or lies */
    const void *data;
    size_t size;
    asp_file_kind kind;
    const char *format;
};

static void test_by_magic(void)
{
    static const char hier[] = "ASPHIER\0rest";
    const struct magic_case cases[] = {
        {"a.bin", ply_points, sizeof ply_points - 1, ASP_FILE_POINTS, "ply"},
        {"b.bin", ply_faces, sizeof ply_faces - 1, ASP_FILE_MESH, "ply"},
        {"c.ply", ply_no_faces, sizeof ply_no_faces - 1, ASP_FILE_POINTS, "ply"},
        {"d.bin", "ASPAMG\r\n\1\0\0\0", 12, ASP_FILE_AMG, "amg"},
        {"e.bin", "ASPDPS\r\n\1\0\0\0", 12, ASP_FILE_DPS, "dps"},
        {"f.bin", hier, sizeof hier - 1, ASP_FILE_HIER, "hier"},
        {"x.ply", png_magic, sizeof png_magic, ASP_FILE_IMAGE, "png"}, /* a PNG named .ply */
        {"g.dat", jpeg_magic, sizeof jpeg_magic, ASP_FILE_IMAGE, "jpeg"},
        {"h.dat", "OFF\n3 1 0\n", 10, ASP_FILE_MESH, "off"},
        {"i.dat", "COFF\n3 1 0\n", 11, ASP_FILE_MESH, "off"},
        {"j.dat", "glTF\2\0\0\0", 8, ASP_FILE_MESH, "glb"},
        {"k.xyz", tds_magic, sizeof tds_magic, ASP_FILE_MESH, "3ds"}, /* a 3DS named .xyz */
        {"l.obj", "GIF89a\1\0\1\0", 10, ASP_FILE_IMAGE, "gif"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const struct magic_case *c = &cases[i];
        write_bytes(c->name, c->data, c->size);
        asp_file_type t = {0};
        asp_error e = {0};
        CHECK_OK(asp_file_recognise(path_in(c->name), &t, &e), &e);
        CHECK_MSG(t.kind == c->kind && strcmp(t.format, c->format) == 0 && t.by_magic == 1, "%s: %s %s %d", c->name,
                  asp_file_kind_name(t.kind), t.format, t.by_magic);
        /* the memory entry point agrees and touches no file */
        asp_file_type m = {0};
        CHECK_OK(asp_file_recognise_memory(c->data, c->size, c->name, &m, &e), &e);
        CHECK(m.kind == t.kind && strcmp(m.format, t.format) == 0);
        remove(path_in(c->name));
    }
}

static void test_by_extension(void)
{
    const struct {
        const char *name;
        asp_file_kind kind;
        const char *format;
    } cases[] = {
        {"bunny.xyz", ASP_FILE_POINTS, "xyz"}, {"SCAN.PTS", ASP_FILE_POINTS, "pts"}, {"p.Txt", ASP_FILE_POINTS, "txt"},
        {"m.obj", ASP_FILE_MESH, "obj"},       {"M.OBJ", ASP_FILE_MESH, "obj"},      {"part.STL", ASP_FILE_MESH, "stl"},
        {"s.gltf", ASP_FILE_MESH, "gltf"},     {"c.3DS", ASP_FILE_MESH, "3ds"},      {"d.Dae", ASP_FILE_MESH, "dae"},
        {"t.JPG", ASP_FILE_IMAGE, "jpeg"},     {"t.tga", ASP_FILE_IMAGE, "tga"},     {"t.bmp", ASP_FILE_IMAGE, "bmp"},
        {"dir.d/BUNNY.PLY", ASP_FILE_POINTS, "ply"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        /* text without a magic: only the extension can tell */
        asp_file_type t = {0};
        asp_error e = {0};
        CHECK_OK(asp_file_recognise_memory("0 0 0\n", 6, cases[i].name, &t, &e), &e);
        CHECK_MSG(t.kind == cases[i].kind && strcmp(t.format, cases[i].format) == 0 && t.by_magic == 0, "%s: %s %s",
                  cases[i].name, asp_file_kind_name(t.kind), t.format);
        asp_file_type o = {0};
        CHECK_OK(asp_file_type_of_name(cases[i].name, &o, &e), &e);
        CHECK(o.kind == cases[i].kind && strcmp(o.format, cases[i].format) == 0);
    }
    /* a text point file whose comment mentions OFF stays a point file */
    asp_file_type t = {0};
    CHECK_OK(asp_file_recognise_memory("# OFF axis\n0 0 0\n", 17, "p.xyz", &t, NULL), NULL);
    CHECK(t.kind == ASP_FILE_POINTS);
}

/* Upper-case amgsplat files: O.AMG is an .amg by its magic and by its name. */
static void test_upper_case_own_files(void)
{
    write_bytes("O.AMG", "ASPAMG\r\n\1\0\0\0", 12);
    asp_file_type t = {0};
    asp_error e = {0};
    CHECK_OK(asp_file_recognise(path_in("O.AMG"), &t, &e), &e);
    CHECK(t.kind == ASP_FILE_AMG && t.by_magic);
    CHECK_OK(asp_file_type_of_name("O.AMG", &t, &e), &e);
    CHECK(t.kind == ASP_FILE_AMG && !t.by_magic);
    CHECK_OK(asp_file_type_of_name("X.DPS", &t, &e), &e);
    CHECK(t.kind == ASP_FILE_DPS);
    remove(path_in("O.AMG"));
    /* an .amg without the magic is not one: the name alone does not make it */
    write_bytes("fake.amg", "hello world\n", 12);
    CHECK(asp_file_recognise(path_in("fake.amg"), &t, &e) == ASP_EFORMAT);
    CHECK_MSG(strstr(e.msg, "fake.amg") && strstr(e.msg, "bad magic"), "%s", e.msg);
    remove(path_in("fake.amg"));
}

static void test_refusals(void)
{
    asp_file_type t = {.kind = ASP_FILE_MESH, .format = "keep"};
    asp_error e = {0};
    /* FIFO: refused before any read, so no writer is waited for */
    CHECK(mkfifo(path_in("pipe.ply"), 0600) == 0);
    time_t t0 = time(NULL);
    CHECK(asp_file_recognise(path_in("pipe.ply"), &t, &e) == ASP_EIO);
    CHECK(time(NULL) - t0 < 5);
    CHECK_MSG(strstr(e.msg, "pipe.ply") && strstr(e.msg, "not a regular file"), "%s", e.msg);
    remove(path_in("pipe.ply"));
    /* directory */
    CHECK(mkdir(path_in("d.amg"), 0700) == 0);
    CHECK(asp_file_recognise(path_in("d.amg"), &t, &e) == ASP_EIO);
    CHECK_MSG(strstr(e.msg, "d.amg") && strstr(e.msg, "is a directory"), "%s", e.msg);
    rmdir(path_in("d.amg"));
    /* missing file */
    CHECK(asp_file_recognise(path_in("none.ply"), &t, &e) == ASP_EIO);
    CHECK_MSG(strstr(e.msg, "cannot open") && strstr(e.msg, "none.ply"), "%s", e.msg);
    /* unknown extension lists what is known */
    write_bytes("data.abc", "1 2 3\n", 6);
    CHECK(asp_file_recognise(path_in("data.abc"), &t, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "unknown file type '.abc'") && strstr(e.msg, ".ply") && strstr(e.msg, ".amg"), "%s",
              e.msg);
    remove(path_in("data.abc"));
    CHECK(asp_file_recognise_memory("1 2 3", 5, "noext", &t, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "no extension"), "%s", e.msg);
    CHECK(asp_file_type_of_name("out.abc", &t, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "cannot write 'out.abc'"), "%s", e.msg);
    /* failures leave *out as it was */
    CHECK(t.kind == ASP_FILE_MESH && strcmp(t.format, "keep") == 0);
    /* an empty file has no magic: its extension decides, and its reader reports the emptiness */
    write_bytes("empty.ply", "", 0);
    CHECK_OK(asp_file_recognise(path_in("empty.ply"), &t, &e), &e);
    CHECK(t.kind == ASP_FILE_POINTS && !t.by_magic);
    asp_cloud *c = NULL;
    CHECK(asp_cloud_load(path_in("empty.ply"), NULL, &c, &e) == ASP_EFORMAT && c == NULL);
    CHECK_MSG(strstr(e.msg, "empty"), "%s", e.msg);
    remove(path_in("empty.ply"));
    CHECK(strcmp(asp_file_kind_name((asp_file_kind)99), "unknown") == 0);
    CHECK(strcmp(asp_file_kind_name(ASP_FILE_HIER), "hier") == 0);
}

/* asp_cloud_load and asp_cloud_save go through the recogniser: upper case works, other kinds are named. */
static void test_cloud_load_uses_it(void)
{
    write_bytes("BUNNY.PLY", ply_points, sizeof ply_points - 1);
    write_bytes("P.XYZ", "1 2 3\n4 5 6\n", 12);
    asp_cloud *c = NULL;
    asp_error e = {0};
    CHECK_OK(asp_cloud_load(path_in("BUNNY.PLY"), NULL, &c, &e), &e);
    CHECK(c && c->count == 1);
    CHECK_OK(asp_cloud_save(c, path_in("OUT.PLY"), NULL, &e), &e);
    asp_cloud_destroy(c);
    c = NULL;
    CHECK_OK(asp_cloud_load(path_in("OUT.PLY"), NULL, &c, &e), &e);
    asp_cloud_destroy(c);
    c = NULL;
    CHECK_OK(asp_cloud_load(path_in("P.XYZ"), NULL, &c, &e), &e);
    CHECK(c && c->count == 2);
    CHECK_OK(asp_cloud_save(c, path_in("Q.PTS"), NULL, &e), &e);
    asp_cloud_destroy(c);
    FILE *fp = fopen(path_in("Q.PTS"), "r");
    char first[32] = "";
    CHECK(fp && fgets(first, sizeof first, fp));
    if (fp)
        fclose(fp);
    CHECK_MSG(strcmp(first, "2\n") == 0, "%s", first); /* .PTS gets its count line in any case */
    /* a PNG named x.ply is not read as PLY */
    write_bytes("x.ply", png_magic, sizeof png_magic);
    c = NULL;
    CHECK(asp_cloud_load(path_in("x.ply"), NULL, &c, &e) == ASP_EUNSUPPORTED && c == NULL);
    CHECK_MSG(strstr(e.msg, "x.ply") && strstr(e.msg, "image") && strstr(e.msg, "not a point file"), "%s", e.msg);
    /* a mesh is told to be sampled */
    write_bytes("m.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 32);
    CHECK(asp_cloud_load(path_in("m.OBJ"), NULL, &c, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "mesh") && strstr(e.msg, "amgsplat sample"), "%s", e.msg);
    /* a PLY with faces still loads its vertices as points */
    write_bytes("faces.ply", ply_faces, sizeof ply_faces - 1);
    CHECK_OK(asp_cloud_load(path_in("faces.ply"), NULL, &c, &e), &e);
    CHECK(c && c->count == 3 && c->face_count == 1);
    asp_cloud_destroy(c);
    CHECK(asp_cloud_save(NULL, path_in("y.obj"), NULL, &e) == ASP_EUNSUPPORTED);
    CHECK_MSG(strstr(e.msg, "unknown point format '.obj'"), "%s", e.msg);
    CHECK(asp_cloud_format_of("A.TXT") && strcmp(asp_cloud_format_of("A.TXT"), "xyz") == 0);
    CHECK(asp_cloud_format_of("a.obj") == NULL);
    const char *names[] = {"BUNNY.PLY", "P.XYZ", "OUT.PLY", "Q.PTS", "x.ply", "m.OBJ", "faces.ply"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        remove(path_in(names[i]));
}

/* Arbitrary and truncated heads never crash and always give a kind or an error. */
static void test_truncated_heads(void)
{
    for (size_t n = 0; n <= sizeof ply_faces - 1; n++) {
        asp_file_type t = {0};
        int rc = asp_file_recognise_memory(ply_faces, n, "h.ply", &t, NULL);
        CHECK(rc == 0 && (t.kind == ASP_FILE_POINTS || t.kind == ASP_FILE_MESH));
    }
    asp_file_type t = {0};
    CHECK(asp_file_recognise_memory(NULL, 0, "z.hier", &t, NULL) == 0 && t.kind == ASP_FILE_HIER);
}

static void teardown(void)
{
    rmdir(dir);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_by_magic), TEST_CASE(test_by_extension), TEST_CASE(test_upper_case_own_files),
          TEST_CASE(test_refusals), TEST_CASE(test_cloud_load_uses_it), TEST_CASE(test_truncated_heads),
          TEST_FIXTURE(teardown))
