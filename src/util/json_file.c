#include "util/json_file.h"

#include "util/atomic_file.h"
#include "util/banned.h"

int asp__json_save(cJSON *root, const char *path, asp_error *err)
{
    char *text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text)
        return asp_error_set(err, ASP_ENOMEM, "cannot write '%s': out of memory", path);
    asp__atomic_file f;
    int rc = asp__atomic_open(&f, path, err);
    if (rc == 0) {
        fputs(text, f.fp);
        fputc('\n', f.fp);
        rc = asp__atomic_commit(&f, err);
    }
    cJSON_free(text);
    return rc;
}
