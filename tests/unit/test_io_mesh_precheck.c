/*
 * Mesh pre-checks before assimp (issue #13): valid OFF, STL and OBJ layouts
 * pass untouched (comments, blank lines, colours, counts on the keyword
 * line, ASCII STL, an OBJ without a final newline), and every lie is refused
 * with the numbers: counts past the file size, a face index past the
 * vertices, a body cut off, a binary STL count past its size.
 */
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "io/mesh_precheck.h"

static int pre(const char *text, const char *format, asp_error *err)
{
    memset(err, 0, sizeof *err);
    return asp__mesh_precheck_memory(text, strlen(text), "m", format, err);
}

static void test_valid_layouts_pass(void)
{
    static const struct {
        const char *text, *format;
    } ok[] = {
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "off"},
        {"# made by hand\nOFF\n\n# counts\n3 1 0\n0 0 0 # a comment\n1 0 0\n\n0 1 0\n3 0 1 2 255 0 0\n", "off"},
        {"COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n", "off"},
        {"OFF 3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n", "off"},
        {"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3", "off"}, // no final newline, a quad
        {"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
         "endfacet\nendsolid t\n",
         "stl"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3", "obj"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# last line, no newline", "obj"},
        {"anything at all", "fbx"}, // formats without a pre-check pass (3DS has one since issue #31)
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        asp_error err;
        CHECK_MSG(pre(ok[i].text, ok[i].format, &err) == 0, "case %zu: %s", i, err.msg);
    }
    /* a binary STL of exactly one triangle: 84 + 50 bytes */
    unsigned char stl[134] = {0};
    stl[80] = 1;
    asp_error err = {0};
    CHECK_MSG(asp__mesh_precheck_memory(stl, sizeof stl, "b.stl", "stl", &err) == 0, "%s", err.msg);
    stl[80] = 2;
    CHECK(asp__mesh_precheck_memory(stl, sizeof stl, "b.stl", "stl", &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "cannot read 'b.stl': binary STL declares 2 triangles (100 bytes), but 50 bytes follow"),
              "%s", err.msg);
}

static void test_lies_are_refused_with_numbers(void)
{
    static const struct {
        const char *text, *format, *want;
    } bad[] = {
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n", "off", "line 6: face 0 references vertex 99 of 3 (indices 0..2)"},
        {"OFF\n200000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "off",
         "line 2 declares 200000000 vertices and 1 faces, but only 26 bytes follow"},
        {"OFF\n4 2 0\n0.000000 0.000000 0.000000\n1.000000 0.000000 0.000000\n0.000000 1.000000 0.000000\n"
         "1.000000 1.000000 0.000000\n3 0 1 2\n",
         "off", "holds 1 of the 2 faces it declares: the file is cut off"},
        {"OFF\nthree 1 0\n", "off", "line 2: expected the counts 'vertices faces edges'"},
        {"OFF\n", "off", "OFF file ends before its vertex and face counts"},
        {"OFF\n3 1 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n3 0 1\n", "off",
         "line 6: face 0: expected 3 vertex indices"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2", "obj", "line 4: the file ends inside a face line ('f 1 2'): it is cut off"},
        {"v 0 0 0\nv 1 0", "obj", "line 2: the file ends inside a vertex line ('v 1 0')"},
        {"tiny", "stl", "4 bytes, too short for binary STL (84 at least)"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        asp_error err;
        int rc = pre(bad[i].text, bad[i].format, &err);
        CHECK_MSG(rc == ASP_EFORMAT && strncmp(err.msg, "cannot read 'm': ", 17) == 0 && strstr(err.msg, bad[i].want),
                  "case %zu: rc %d '%s'", i, rc, err.msg);
    }
}

static void test_paths_that_are_not_files(void)
{
    char dir[64], fifo[80];
    snprintf(dir, sizeof dir, "/tmp/asp_precheck_%d.off", (int)getpid());
    snprintf(fifo, sizeof fifo, "/tmp/asp_precheck_%d_fifo.obj", (int)getpid());
    CHECK(mkdir(dir, 0700) == 0);
    CHECK(mkfifo(fifo, 0600) == 0);
    asp_error err = {0};
    CHECK(asp__mesh_precheck(dir, "off", NULL, &err) == ASP_EIO && strstr(err.msg, "is a directory, expected a file"));
    CHECK_MSG(asp__mesh_precheck(fifo, "obj", NULL, &err) == ASP_EIO && strstr(err.msg, "not a regular file (a FIFO)"),
              "%s", err.msg);
    rmdir(dir);
    unlink(fifo);
}

TEST_MAIN(TEST_CASE(test_valid_layouts_pass), TEST_CASE(test_lies_are_refused_with_numbers),
          TEST_CASE(test_paths_that_are_not_files))
