/*
 * ASP_ASSERT's failure path (STYLE.md section 4: programmer errors abort at the entry that
 * detects them, like git's BUG()). The only place the library writes to stderr: a broken
 * contract has no caller left to hand an asp_error to.
 */
#include <stdio.h>
#include <stdlib.h>

#include "amgsplat/core.h"

void asp__assert_fail(const char *file, int line, const char *cond)
{
    fprintf(stderr, "%s:%d: assertion failed: %s\n", file, line, cond);
    fflush(stderr);
    abort();
}
