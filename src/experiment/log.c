/*
 * The per-frame log of seed 004 2.3 (docs/experiment-log.md): JSON Lines
 * opened for appending and flushed after every line, so a crash or a pulled
 * plug loses at most the line being written, and nothing is ever rewritten.
 */
#include <errno.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "experiment/internal.h"
#include "util/banned.h"

int asp__exp_log_open(exp_log *log, const char *path, asp_error *err)
{
    memset(log, 0, sizeof *log);
    snprintf(log->path, sizeof log->path, "%s", path);
    log->fp = fopen(path, "a");
    if (!log->fp)
        return asp_error_set(err, ASP_EIO, "cannot open '%s' for appending: %s", path, strerror(errno));
    return 0;
}

int asp__exp_log_write(exp_log *log, void *cjson_obj, asp_error *err)
{
    cJSON *obj = cjson_obj;
    if (!log->fp) { // a practice run: shown, never logged
        cJSON_Delete(obj);
        return 0;
    }
    char *line = obj ? cJSON_PrintUnformatted(obj) : NULL;
    cJSON_Delete(obj);
    if (!line)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a line of '%s'", log->path);
    int ok = fputs(line, log->fp) >= 0 && fputc('\n', log->fp) != EOF && fflush(log->fp) == 0;
    cJSON_free(line);
    if (!ok)
        return asp_error_set(err, ASP_EIO, "cannot write '%s': %s", log->path, strerror(errno));
    return 0;
}

void asp__exp_log_close(exp_log *log)
{
    if (log->fp)
        fclose(log->fp);
    log->fp = NULL;
}
