/*
 * Names of the texture-construction options (thesis 3.3.2-3.3.3) for the
 * command line and the file summary.
 */
#include <string.h>

#include "amgsplat/prim.h"
#include "util/banned.h"

static const char *const methods[] = {"affine", "radial"};
static const char *const shapes[] = {"linear", "constant", "gaussian"};
static const char *const norms[] = {"positive", "ge1"};

static int lookup(const char *const *names, int n, const char *name, const char *what, const char *choices, int *out,
                  asp_error *err)
{
    for (int i = 0; name && i < n; i++)
        if (strcmp(names[i], name) == 0) {
            *out = i;
            return 0;
        }
    return asp_error_set(err, ASP_EINVAL, "unknown %s '%s' (expected %s)", what, name ? name : "", choices);
}

int asp_prim_method_parse(const char *name, asp_prim_method *out, asp_error *err)
{
    int v = 0, rc = lookup(methods, 2, name, "texture method", "affine or radial", &v, err);
    if (!rc)
        *out = (asp_prim_method)v;
    return rc;
}

int asp_prim_shape_parse(const char *name, asp_prim_shape *out, asp_error *err)
{
    int v = 0, rc = lookup(shapes, 3, name, "radial shape", "linear, constant or gaussian", &v, err);
    if (!rc)
        *out = (asp_prim_shape)v;
    return rc;
}

int asp_prim_normalise_parse(const char *name, asp_prim_normalise *out, asp_error *err)
{
    int v = 0, rc = lookup(norms, 2, name, "normalisation", "positive (f > 0) or ge1 (f >= 1)", &v, err);
    if (!rc)
        *out = (asp_prim_normalise)v;
    return rc;
}

const char *asp_prim_method_name(asp_prim_method m)
{
    return (unsigned)m < 2 ? methods[m] : "?";
}

const char *asp_prim_shape_name(asp_prim_shape s)
{
    return (unsigned)s < 3 ? shapes[s] : "?";
}

const char *asp_prim_normalise_name(asp_prim_normalise n)
{
    return (unsigned)n < 2 ? norms[n] : "?";
}
