/*
 * The one file recogniser (STYLE.md 9b): what a path holds, told by its first
 * bytes where the format has a magic number and by its extension
 * (case-insensitive) otherwise. Every command asks here, so "O.AMG" is an .amg
 * file for info, decompose and render alike, and a PLY with faces is a mesh.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/io.h"
#include "util/regular_file.h"
#include "util/banned.h"

enum { HEAD_BYTES = 4096 }; /* a PLY header's element lines fit in far less */

struct ext_row {
    const char *ext; /* lower case, with the dot */
    asp_file_kind kind;
    const char *format;
};

/*
 * Formats without a reliable magic (OBJ, ASCII STL, XYZ) and the fallback for
 * all others. Mesh extensions are those of assimp's importers that users meet
 * (assimp reads more; asp_mesh_load takes any it reads).
 */
static const struct ext_row ext_table[] = {
    {".ply", ASP_FILE_POINTS, "ply"},   {".xyz", ASP_FILE_POINTS, "xyz"},   {".pts", ASP_FILE_POINTS, "pts"},
    {".txt", ASP_FILE_POINTS, "txt"},   {".las", ASP_FILE_POINTS, "las"},   {".laz", ASP_FILE_POINTS, "laz"},
    {".obj", ASP_FILE_MESH, "obj"},     {".off", ASP_FILE_MESH, "off"},
    {".stl", ASP_FILE_MESH, "stl"},     {".gltf", ASP_FILE_MESH, "gltf"},   {".glb", ASP_FILE_MESH, "glb"},
    {".3ds", ASP_FILE_MESH, "3ds"},     {".fbx", ASP_FILE_MESH, "fbx"},     {".dae", ASP_FILE_MESH, "dae"},
    {".amg", ASP_FILE_AMG, "amg"},      {".dps", ASP_FILE_DPS, "dps"},      {".hier", ASP_FILE_HIER, "hier"},
    {".png", ASP_FILE_IMAGE, "png"},    {".jpg", ASP_FILE_IMAGE, "jpeg"},   {".jpeg", ASP_FILE_IMAGE, "jpeg"},
    {".bmp", ASP_FILE_IMAGE, "bmp"},    {".tga", ASP_FILE_IMAGE, "tga"},    {".gif", ASP_FILE_IMAGE, "gif"},
};
enum { N_EXT = sizeof ext_table / sizeof ext_table[0] };

static const char expected[] = ".ply, .xyz, .pts, .txt, .las, .laz, .obj, .off, .stl, .gltf, .glb, .3ds, .fbx, .dae, .amg, .dps, "
                               ".hier, .png, .jpg, .bmp, .tga, .gif";

const char *asp_file_kind_name(asp_file_kind kind)
{
    static const char *const names[] = {"unknown", "points", "mesh", "amg", "dps", "hier", "image", "scene"};
    return (unsigned)kind < sizeof names / sizeof names[0] ? names[kind] : "unknown";
}

/* The extension of the last path component, "" when none. */
static const char *extension_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    return dot ? dot : "";
}

static int same_ci(const char *a, const char *b)
{
    for (; *a && *b; a++, b++) {
        char x = (*a >= 'A' && *a <= 'Z') ? (char)(*a - 'A' + 'a') : *a;
        if (x != *b)
            return 0;
    }
    return *a == *b;
}

static const struct ext_row *by_extension(const char *path)
{
    const char *ext = extension_of(path);
    for (size_t i = 0; i < N_EXT; i++)
        if (same_ci(ext, ext_table[i].ext))
            return &ext_table[i];
    return NULL;
}

static void fill(asp_file_type *out, asp_file_kind kind, const char *format, int by_magic)
{
    out->kind = kind;
    snprintf(out->format, sizeof out->format, "%s", format);
    out->by_magic = by_magic;
}

/*
 * A PLY header (within the bytes given) declaring a face (or tristrips) element with a
 * non-zero count makes a mesh. A header longer than the bytes read is taken
 * as points: its vertex element comes first in every exporter we know.
 */
static int ply_has_faces(const char *h, size_t n)
{
    size_t i = 0;
    while (i < n) {
        size_t e = i;
        while (e < n && h[e] != '\n')
            e++;
        size_t len = e - i;
        if (len >= 10 && memcmp(h + i, "end_header", 10) == 0)
            return 0;
        size_t skip = len > 13 && memcmp(h + i, "element face ", 13) == 0         ? 13
                      : len > 18 && memcmp(h + i, "element tristrips ", 18) == 0 ? 18
                                                                                  : 0;
        if (skip) {
            for (size_t k = i + skip; k < e; k++)
                if (h[k] >= '1' && h[k] <= '9')
                    return 1;
        }
        i = e + 1;
    }
    return 0;
}

/*
 * A LAS file is LASzip-compressed when bit 7 (or 6) of its point format byte
 * is set or a "laszip encoded" VLR follows the header (those within the head
 * bytes are looked at; LAS 1.4 R15 Table 3, LASzip's VLR 22204).
 */
static int las_is_compressed(const unsigned char *h, size_t n)
{
    if (n > 104 && (h[104] & 0xc0))
        return 1;
    if (n < 104)
        return 0;
    size_t at = (size_t)h[94] | (size_t)h[95] << 8;
    uint32_t nvlr = (uint32_t)h[100] | (uint32_t)h[101] << 8 | (uint32_t)h[102] << 16 | (uint32_t)h[103] << 24;
    for (uint32_t i = 0; i < nvlr && at + 54 <= n; i++) {
        if (memcmp(h + at + 2, "laszip encoded", 14) == 0)
            return 1;
        at += 54 + ((size_t)h[at + 20] | (size_t)h[at + 21] << 8);
    }
    return 0;
}

/*
 * A scene of instances (instances.h) by content: JSON text whose first
 * non-blank byte opens an object and whose head holds the key "instances"
 * (the scene writer puts it before the camera). JSON has no magic, and a
 * .json name says nothing: the experiment's scene list ("format":
 * "amgsplat-scenes 1", no "instances") stays unknown, as before.
 */
static int is_instance_scene(const unsigned char *h, size_t n)
{
    size_t i = 0;
    if (n >= 3 && h[0] == 0xef && h[1] == 0xbb && h[2] == 0xbf)
        i = 3; // a UTF-8 byte order mark
    while (i < n && (h[i] == ' ' || h[i] == '\t' || h[i] == '\n' || h[i] == '\r'))
        i++;
    if (i >= n || h[i] != '{')
        return 0;
    static const char key[] = "\"instances\"";
    for (; i + sizeof key - 1 <= n; i++)
        if (memcmp(h + i, key, sizeof key - 1) == 0)
            return 1;
    return 0;
}

/* 0 and *out filled when the first bytes name the format; 1 when they do not. */
static int by_magic(const unsigned char *h, size_t n, asp_file_type *out)
{
    if (n >= 4 && memcmp(h, "LASF", 4) == 0) {
        fill(out, ASP_FILE_POINTS, las_is_compressed(h, n) ? "laz" : "las", 1);
        return 0;
    }
    if (n >= 4 && memcmp(h, "ply", 3) == 0 && (h[3] == '\n' || h[3] == '\r')) {
        fill(out, ply_has_faces((const char *)h, n) ? ASP_FILE_MESH : ASP_FILE_POINTS, "ply", 1);
        return 0;
    }
    static const struct {
        const char *magic;
        size_t len;
        asp_file_kind kind;
        const char *format;
    } magics[] = {
        {"ASPAMG\r\n", 8, ASP_FILE_AMG, "amg"},
        {"ASPDPS\r\n", 8, ASP_FILE_DPS, "dps"},
        {"ASPHIER", 8, ASP_FILE_HIER, "hier"}, /* with its NUL */
        {"\x89PNG\r\n\x1a\n", 8, ASP_FILE_IMAGE, "png"},
        {"\xff\xd8\xff", 3, ASP_FILE_IMAGE, "jpeg"},
        {"GIF87a", 6, ASP_FILE_IMAGE, "gif"},
        {"GIF89a", 6, ASP_FILE_IMAGE, "gif"},
        {"glTF", 4, ASP_FILE_MESH, "glb"},
        {"Kaydara FBX Binary", 18, ASP_FILE_MESH, "fbx"},
    };
    for (size_t i = 0; i < sizeof magics / sizeof magics[0]; i++)
        if (n >= magics[i].len && memcmp(h, magics[i].magic, magics[i].len) == 0) {
            fill(out, magics[i].kind, magics[i].format, 1);
            return 0;
        }
    /*
     * OFF and its variants ([ST][C][N][4][n]OFF: STOFF, COFF, NOFF, 4OFF ...):
     * the keyword opens the file and ends at a blank or line end, so a text
     * point file whose comment mentions "OFF" is not taken for a mesh.
     */
    size_t k = 0;
    while (k < n && k < 6 && h[k] && strchr("STCN4n", h[k]))
        k++;
    if (k + 3 <= n && memcmp(h + k, "OFF", 3) == 0 &&
        (k + 3 == n || h[k + 3] == '\n' || h[k + 3] == '\r' || h[k + 3] == ' ' || h[k + 3] == '\t')) {
        fill(out, ASP_FILE_MESH, "off", 1);
        return 0;
    }
    if (is_instance_scene(h, n)) {
        fill(out, ASP_FILE_SCENE, "json", 1);
        return 0;
    }
    // 3DS: the main chunk 0x4D4D, then its length (little endian), then the version chunk 0x0002
    if (n >= 8 && h[0] == 0x4d && h[1] == 0x4d && h[6] == 0x02 && h[7] == 0x00) {
        fill(out, ASP_FILE_MESH, "3ds", 1);
        return 0;
    }
    return 1;
}

int asp_file_recognise_memory(const void *head, size_t size, const char *name, asp_file_type *out, asp_error *err)
{
    const char *nm = name ? name : "<memory>";
    if (head && !by_magic(head, size, out))
        return 0;
    const struct ext_row *row = by_extension(nm);
    if (!row || row->kind == ASP_FILE_AMG || row->kind == ASP_FILE_DPS || row->kind == ASP_FILE_HIER) {
        // amgsplat's own files always carry their magic: a name alone does not make one
        if (row && size > 0)
            return asp_error_set(err, ASP_EFORMAT, "cannot read '%s': not %s file (bad magic)", nm,
                                 row->kind == ASP_FILE_AMG ? "an .amg" : row->kind == ASP_FILE_DPS ? "a .dps" : "a .hier");
        if (!row && !*extension_of(nm))
            return asp_error_set(err, ASP_EUNSUPPORTED,
                                 "cannot read '%s': unknown file type (no known magic bytes and no extension; "
                                 "expected %s)",
                                 nm, expected);
        if (!row)
            return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': unknown file type '%.16s' (expected %s)", nm,
                                 extension_of(nm), expected);
    }
    fill(out, row->kind, row->format, 0);
    return 0;
}

int asp_file_recognise(const char *path, asp_file_type *out, asp_error *err)
{
    FILE *fp = asp__regular_file_open(path, err);
    if (!fp)
        return ASP_EIO;
    unsigned char head[HEAD_BYTES];
    size_t n = fread(head, 1, sizeof head, fp);
    int failed = ferror(fp);
    int e = errno;
    fclose(fp);
    if (failed)
        return asp_error_set(err, ASP_EIO, "cannot read '%s': %s", path, strerror(e));
    return asp_file_recognise_memory(head, n, path, out, err);
}

int asp_file_type_of_name(const char *path, asp_file_type *out, asp_error *err)
{
    const struct ext_row *row = by_extension(path);
    if (!row)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': unknown file type '%.16s' (expected %s)", path,
                             *extension_of(path) ? extension_of(path) : "(none)", expected);
    fill(out, row->kind, row->format, 0);
    return 0;
}

int asp_file_name_is(const char *path, const char *format)
{
    asp_file_type t;
    return asp_file_type_of_name(path, &t, NULL) == 0 && strcmp(t.format, format) == 0;
}
