/*
 * Error reporting: a code plus a fixed-size message, no allocation and no
 * global "last error" (STYLE.md section 4).
 */
#include <stdarg.h>
#include <stdio.h>

#include "amgsplat/core.h"
#include "util/banned.h"

int asp_error_set(asp_error *err, int code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        err->code = code;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return code;
}

const char *asp_error_name(int code)
{
    switch (code) {
    case ASP_OK: return "ASP_OK";
    case ASP_EINVAL: return "ASP_EINVAL";
    case ASP_ENOMEM: return "ASP_ENOMEM";
    case ASP_EIO: return "ASP_EIO";
    case ASP_EFORMAT: return "ASP_EFORMAT";
    case ASP_EUNSUPPORTED: return "ASP_EUNSUPPORTED";
    case ASP_EDEGENERATE: return "ASP_EDEGENERATE";
    case ASP_EGL: return "ASP_EGL";
    case ASP_ESOLVER: return "ASP_ESOLVER";
    case ASP_ECANCELED: return "ASP_ECANCELED";
    default: return "ASP_E?";
    }
}
