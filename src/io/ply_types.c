/*
 * PLY scalar types: the names and aliases of the PLY format (char/int8 ...
 * double/float64), conversion between native scalars and double, and exact
 * text parsing of one scalar for the ascii encoding and the text formats.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/ply_internal.h"
#include "util/banned.h"

asp_scalar_type asp__ply_type_from_name(const char *name, size_t len)
{
    static const struct {
        const char *name;
        asp_scalar_type type;
    } names[] = {
        {"char", ASP_SCALAR_INT8},     {"int8", ASP_SCALAR_INT8},       {"uchar", ASP_SCALAR_UINT8},
        {"uint8", ASP_SCALAR_UINT8},   {"short", ASP_SCALAR_INT16},     {"int16", ASP_SCALAR_INT16},
        {"ushort", ASP_SCALAR_UINT16}, {"uint16", ASP_SCALAR_UINT16},   {"int", ASP_SCALAR_INT32},
        {"int32", ASP_SCALAR_INT32},   {"uint", ASP_SCALAR_UINT32},     {"uint32", ASP_SCALAR_UINT32},
        {"float", ASP_SCALAR_FLOAT32}, {"float32", ASP_SCALAR_FLOAT32}, {"double", ASP_SCALAR_FLOAT64},
        {"float64", ASP_SCALAR_FLOAT64},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strlen(names[i].name) == len && memcmp(names[i].name, name, len) == 0)
            return names[i].type;
    return ASP_SCALAR_NONE;
}

double asp__scalar_load(const void *p, asp_scalar_type t)
{
    switch (t) {
    case ASP_SCALAR_INT8: { int8_t v; memcpy(&v, p, 1); return v; }
    case ASP_SCALAR_UINT8: { uint8_t v; memcpy(&v, p, 1); return v; }
    case ASP_SCALAR_INT16: { int16_t v; memcpy(&v, p, 2); return v; }
    case ASP_SCALAR_UINT16: { uint16_t v; memcpy(&v, p, 2); return v; }
    case ASP_SCALAR_INT32: { int32_t v; memcpy(&v, p, 4); return v; }
    case ASP_SCALAR_UINT32: { uint32_t v; memcpy(&v, p, 4); return v; }
    case ASP_SCALAR_FLOAT32: { float v; memcpy(&v, p, 4); return v; }
    case ASP_SCALAR_FLOAT64: { double v; memcpy(&v, p, 8); return v; }
    default: return 0.0;
    }
}

static double clamp_round(double v, double lo, double hi)
{
    if (!(v == v))
        return 0.0;
    v = floor(v + 0.5);
    return v < lo ? lo : v > hi ? hi : v;
}

void asp__scalar_store(void *p, asp_scalar_type t, double v)
{
    switch (t) {
    case ASP_SCALAR_INT8: { int8_t x = (int8_t)clamp_round(v, INT8_MIN, INT8_MAX); memcpy(p, &x, 1); break; }
    case ASP_SCALAR_UINT8: { uint8_t x = (uint8_t)clamp_round(v, 0, UINT8_MAX); memcpy(p, &x, 1); break; }
    case ASP_SCALAR_INT16: { int16_t x = (int16_t)clamp_round(v, INT16_MIN, INT16_MAX); memcpy(p, &x, 2); break; }
    case ASP_SCALAR_UINT16: { uint16_t x = (uint16_t)clamp_round(v, 0, UINT16_MAX); memcpy(p, &x, 2); break; }
    case ASP_SCALAR_INT32: { int32_t x = (int32_t)clamp_round(v, INT32_MIN, INT32_MAX); memcpy(p, &x, 4); break; }
    case ASP_SCALAR_UINT32: { uint32_t x = (uint32_t)clamp_round(v, 0, UINT32_MAX); memcpy(p, &x, 4); break; }
    case ASP_SCALAR_FLOAT32: { float x = (float)v; memcpy(p, &x, 4); break; }
    case ASP_SCALAR_FLOAT64: memcpy(p, &v, 8); break;
    default: break;
    }
}

static int is_blank(char c, const char *seps)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f' ||
           (c != '\0' && seps && strchr(seps, c));
}

/* Integer text, or an integral decimal such as "255.0" that some writers emit for integer properties. */
static int parse_integer(const char *tok, const char *end, asp_scalar_type t, double *out)
{
    char *stop;
    errno = 0;
    int is_unsigned = t == ASP_SCALAR_UINT8 || t == ASP_SCALAR_UINT16 || t == ASP_SCALAR_UINT32;
    double v;
    if (is_unsigned && *tok != '-') {
        unsigned long long u = strtoull(tok, &stop, 10);
        v = errno ? HUGE_VAL : (double)u;
    } else {
        long long x = strtoll(tok, &stop, 10);
        v = errno ? (x < 0 ? -HUGE_VAL : HUGE_VAL) : (double)x;
    }
    if (stop != end) {
        errno = 0;
        v = strtod(tok, &stop);
        if (stop != end || v != floor(v))
            return -2;
    }
    static const double lo[] = {0, INT8_MIN, 0, INT16_MIN, 0, INT32_MIN, 0};
    static const double hi[] = {0, INT8_MAX, UINT8_MAX, INT16_MAX, UINT16_MAX, INT32_MAX, UINT32_MAX};
    if (!(v >= lo[t] && v <= hi[t]))
        return -2;
    *out = v;
    return 0;
}

int asp__scalar_parse(const char **s, const char *seps, asp_scalar_type t, void *out)
{
    const char *p = *s;
    while (is_blank(*p, seps))
        p++;
    if (*p == '\0') {
        *s = p;
        return -1;
    }
    const char *end = p;
    while (*end && !is_blank(*end, seps))
        end++;
    *s = p;
    char *stop;
    if (t == ASP_SCALAR_FLOAT32) {
        float f = strtof(p, &stop);
        if (stop != end)
            return -2;
        memcpy(out, &f, 4);
    } else if (t == ASP_SCALAR_FLOAT64) {
        double d = strtod(p, &stop);
        if (stop != end)
            return -2;
        memcpy(out, &d, 8);
    } else if (asp__scalar_is_int(t)) {
        double v;
        if (parse_integer(p, end, t, &v))
            return -2;
        asp__scalar_store(out, t, v);
    } else {
        return -2;
    }
    *s = end;
    return 0;
}
