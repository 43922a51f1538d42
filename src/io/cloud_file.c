/*
 * Point files by extension: .ply through the PLY reader/writer, .xyz/.pts/
 * .txt through the text reader/writer. Loading also rejects non-finite values
 * and empty clouds, so every later stage (journal Sect. 2 onwards) starts from a
 * usable point set; degenerate but valid sets (all points equal) load fine.
 */
#include <ctype.h>
#include <string.h>

#include "amgsplat/io.h"
#include "util/banned.h"

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    return dot ? dot : "";
}

static int ext_is(const char *ext, const char *lit)
{
    size_t n = strlen(lit);
    if (strlen(ext) != n)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (tolower((unsigned char)ext[i]) != lit[i])
            return 0;
    return 1;
}

const char *asp_cloud_format_of(const char *path)
{
    const char *ext = extension(path);
    if (ext_is(ext, ".ply"))
        return "ply";
    if (ext_is(ext, ".xyz") || ext_is(ext, ".pts") || ext_is(ext, ".txt"))
        return "xyz";
    return NULL;
}

static int unknown(const char *verb, const char *path, asp_error *err)
{
    const char *ext = extension(path);
    if (!*ext)
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot %s '%s': no file extension to tell the point format (expected .ply, .xyz, "
                             ".pts, .txt)",
                             verb, path);
    return asp_error_set(err, ASP_EUNSUPPORTED,
                         "cannot %s '%s': unknown point format '%.16s' (expected .ply, .xyz, .pts, .txt)", verb, path,
                         ext);
}

int asp_cloud_load(const char *path, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    const char *fmt = asp_cloud_format_of(path);
    if (!fmt)
        return unknown("read", path, err);
    asp_cloud *c = NULL;
    int rc = fmt[0] == 'p' ? asp_ply_read(path, ctx, &c, err) : asp_xyz_read(path, ctx, &c, err);
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

int asp_cloud_save(const asp_cloud *cloud, const char *path, const asp_save_desc *desc, asp_error *err)
{
    const char *fmt = asp_cloud_format_of(path);
    if (!fmt)
        return unknown("write", path, err);
    return fmt[0] == 'p' ? asp_ply_write(cloud, path, desc, err) : asp_xyz_write(cloud, path, desc, err);
}
