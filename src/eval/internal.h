/* Private helpers shared by the eval module's files. */
#ifndef ASP_EVAL_INTERNAL_H
#define ASP_EVAL_INTERNAL_H

#include "amgsplat/billboard.h"
#include "amgsplat/eval.h"

/* 0 if both images have pixels and equal size, else ASP_EINVAL naming both sizes. */
int asp__image_same_size(const asp_image *a, const asp_image *b, asp_error *err);

/*
 * A billboard cloud of mesh (else of cloud's discs) whose plane count is nearest target at about texels
 * texels (0 = the default texel), its bound searched by bisection (billboard_match.c, issue 30): *out
 * (asp_dps_destroy), its build's stats (may be NULL) and the bound chosen (*error, may be NULL).
 */
int asp__eval_billboards(const asp_mesh *mesh, const asp_cloud *cloud, size_t target, uint64_t texels,
                         const asp_context *ctx, asp_dps **out, asp_billboard_stats *stats, double *error,
                         asp_error *err);

#endif
