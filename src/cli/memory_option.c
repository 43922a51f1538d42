/*
 * --memory SIZE, the working-set budget of the out-of-core commands (issue
 * 28): bytes with an optional K, M, G or T suffix (powers of 1024).
 */
#include <math.h>
#include <stdlib.h>

#include "cli/cli.h"
#include "util/banned.h"

int cli_memory_option(struct cli_env *env, const char *text, size_t *out)
{
    char *end = NULL;
    double v = strtod(text, &end);
    double unit = 1;
    if (end && *end) {
        switch (*end == 'k' ? 'K' : *end == 'm' ? 'M' : *end == 'g' ? 'G' : *end == 't' ? 'T' : *end) {
        case 'K': unit = 1024.0; break;
        case 'M': unit = 1024.0 * 1024; break;
        case 'G': unit = 1024.0 * 1024 * 1024; break;
        case 'T': unit = 1024.0 * 1024 * 1024 * 1024; break;
        default: unit = 0;
        }
        end++;
        if (*end == 'B' || *end == 'b' || (*end == 'i' && (end[1] == 'B' || end[1] == 'b')))
            end += *end == 'i' ? 2 : 1;
    }
    if (end == text || !unit || *end || !(v > 0) || !isfinite(v) || v * unit > 1e18)
        return cli_usage_error(env, "--memory expects a size such as 512M or 2G, got '%s'", text);
    *out = (size_t)(v * unit);
    return 0;
}
