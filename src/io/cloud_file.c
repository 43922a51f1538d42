/*
 * Point files, told apart by the one recogniser (file_kind.c: magic bytes,
 * then the extension, case-insensitive): PLY through the PLY reader/writer,
 * .xyz/.pts/.txt through the text reader/writer. Loading also rejects
 * non-finite values and empty clouds, so every later stage (journal Sect. 2
 * onwards) starts from a usable point set; degenerate but valid sets (all
 * points equal) load fine.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/io.h"
#include "io/cloud_check.h"
#include "io/las_internal.h"
#include "util/banned.h"

static const char point_exts[] = ".ply, .xyz, .pts, .txt, .las";

/* "ply", "las", "laz" or "xyz" for a recognised point format, NULL otherwise. */
static const char *reader_of(const asp_file_type *t)
{
    if (strcmp(t->format, "ply") == 0)
        return "ply"; /* a PLY with faces is a mesh, but its vertices are points all the same */
    // literals, not t->format: t is the caller's local (gcc -O3 caught the dangling return)
    if (strcmp(t->format, "las") == 0)
        return "las";
    if (strcmp(t->format, "laz") == 0)
        return "laz";
    if (t->kind == ASP_FILE_POINTS)
        return "xyz";
    return NULL;
}

const char *asp_cloud_format_of(const char *path)
{
    asp_file_type t;
    if (asp_file_type_of_name(path, &t, NULL))
        return NULL;
    return reader_of(&t);
}

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    return dot ? dot : "";
}

static int unknown(const char *verb, const char *path, asp_error *err)
{
    const char *ext = extension(path);
    if (!*ext)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot %s '%s': no file extension to tell the point format (expected %s)", verb, path,
                             point_exts);
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot %s '%s': unknown point format '%.16s' (expected %s)", verb,
                         path, ext, point_exts);
}

/* What to tell a user who hands a mesh, an image or an amgsplat file to a command that wants points. */
static int not_points(const char *path, const asp_file_type *t, asp_error *err)
{
    const char *hint = t->kind == ASP_FILE_MESH  ? "; sample it to points first: amgsplat sample MESH -o OUT.ply"
                       : t->kind == ASP_FILE_AMG ? "; 'amgsplat decompose' made it from a point file"
                                                 : "";
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot read '%s': %s %s file (%s), not a point file%s", path,
                         t->kind == ASP_FILE_IMAGE ? "an" : "a", asp_file_kind_name(t->kind), t->format, hint);
}

int asp_cloud_load(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    asp_file_type t;
    asp_error e = {0};
    int rc = asp_file_recognise(path, &t, &e);
    if (rc == ASP_EUNSUPPORTED)
        return unknown("read", path, err);
    if (rc)
        return asp_error_set(err, rc, "%s", e.msg);
    const char *fmt = reader_of(&t);
    if (!fmt)
        return not_points(path, &t, err);
    asp_cloud *c = NULL;
    if (strcmp(fmt, "laz") == 0)
        return asp__las_laz_error(path, err);
    rc = strcmp(fmt, "ply") == 0   ? asp_ply_read(path, ctx, &c, err)
         : strcmp(fmt, "las") == 0 ? asp_las_read(path, ctx, &c, err)
                                   : asp_xyz_read(path, ctx, &c, err);
    if (rc)
        return rc;
    asp_error e2;
    if (c->count == 0)
        rc = asp_error_set(err, ASP_EFORMAT, "cannot read '%s': the file holds no points", path);
    else if ((rc = asp_cloud_validate(c, &e2)))
        rc = asp_error_set(err, rc, "cannot read '%s': %s", path, e2.msg);
    if (rc) {
        asp_cloud_destroy(c);
        return rc;
    }
    *out = c;
    return 0;
}

/*
 * What every point writer checks first (issue #31): the values it would
 * write are finite (asp_cloud_validate: coordinates, normals, radii, uvs,
 * and the world coordinates origin + position), so no command writes a file
 * that asp_cloud_load refuses; the message names the point, which is the
 * input's point of the same index for convert and estimate, and the sample
 * that made it for sample.
 */
int asp__cloud_output_check(const asp_cloud *c, const char *path, asp_error *err)
{
    asp_error e = {0};
    int rc = asp_cloud_validate(c, &e);
    if (rc)
        return asp_error_set(err, rc, "cannot write '%s': %s; nothing written", path, e.msg);
    for (int k = 0; k < 3; k++)
        if (!isfinite(c->origin[k]))
            return asp_error_set(err, ASP_EFORMAT, "cannot write '%s': the origin's %c is not finite; nothing written",
                                 path, "xyz"[k]);
    for (size_t i = 0; i < c->count; i++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(c->origin[k] + (double)c->positions[3 * i + k]))
                return asp_error_set(err, ASP_EFORMAT, "cannot write '%s': point %zu: world coordinate %c (origin %g "
                                     "plus %g) is not finite; nothing written", path, i, "xyz"[k], c->origin[k],
                                     (double)c->positions[3 * i + k]);
    return 0;
}

/* The read-back of every point writer (asp__atomic_check): the written file loads as asp_cloud_load loads it. */
int asp__cloud_reads_back(const char *tmp, void *user, asp_error *err)
{
    const asp__cloud_readback *rb = user;
    const asp_cloud *c = rb->cloud;
    asp_cloud *back = NULL;
    asp_error e = {0};
    int rc = strcmp(rb->format, "ply") == 0   ? asp_ply_read(tmp, &c->ctx, &back, err)
             : strcmp(rb->format, "las") == 0 ? asp_las_read(tmp, &c->ctx, &back, err)
                                              : asp_xyz_read(tmp, &c->ctx, &back, err);
    if (rc == 0 && (rc = asp_cloud_validate(back, &e)))
        asp_error_set(err, rc, "%s", e.msg);
    if (rc == 0 && back->count != c->count)
        rc = asp_error_set(err, ASP_EFORMAT, "%zu points read back of %zu written", back->count, c->count);
    asp_cloud_destroy(back);
    return rc;
}

int asp_cloud_save(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err)
{
    asp_file_type t;
    if (asp_file_type_of_name(path, &t, NULL) || t.kind != ASP_FILE_POINTS)
        return unknown("write", path, err);
    // the format writers write what they are given and their read-back names what is wrong; the
    // commands' save refuses non-finite values first, with a message that is not an internal error
    int rc = asp__cloud_output_check(cloud, path, err);
    if (rc)
        return rc;
    if (strcmp(t.format, "laz") == 0)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot write '%s': compressed LAS (LASzip) needs a compressor this build does not have; "
                             "write .las",
                             path);
    return strcmp(t.format, "ply") == 0   ? asp_ply_write(cloud, path, desc, err)
           : strcmp(t.format, "las") == 0 ? asp_las_write(cloud, path, desc, err)
                                          : asp_xyz_write(cloud, path, desc, err);
}
