/*
 * Shortest round-trip decimal text for floats and doubles, so ascii PLY and
 * XYZ files stay readable ("0.1", not "0.100000001") while reading them back
 * gives the same bits (the round-trip tests compare bytes).
 */
#include <stdio.h>
#include <stdlib.h>

#include "io/ply_internal.h"
#include "util/banned.h"

size_t asp__format_float(char buf[32], float v)
{
    int n = 0;
    /* 9 significant digits always round-trip a binary32; try shorter first */
    for (int digits = 6; digits <= 9; digits++) {
        n = snprintf(buf, 32, "%.*g", digits, (double)v);
        if (strtof(buf, NULL) == v || v != v)
            break;
    }
    return (size_t)n;
}

size_t asp__format_double(char buf[32], double v)
{
    int n = 0;
    for (int digits = 15; digits <= 17; digits++) {
        n = snprintf(buf, 32, "%.*g", digits, v);
        if (strtod(buf, NULL) == v || v != v)
            break;
    }
    return (size_t)n;
}

size_t asp__format_scalar(char buf[32], const void *p, asp_scalar_type t)
{
    double v = asp__scalar_load(p, t);
    if (t == ASP_SCALAR_FLOAT32)
        return asp__format_float(buf, (float)v);
    if (t == ASP_SCALAR_FLOAT64)
        return asp__format_double(buf, v);
    return (size_t)snprintf(buf, 32, "%.0f", v);
}
