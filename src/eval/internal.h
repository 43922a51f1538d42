/* Private helpers shared by the eval module's files. */
#ifndef ASP_EVAL_INTERNAL_H
#define ASP_EVAL_INTERNAL_H

#include "amgsplat/eval.h"

/* 0 if both images have pixels and equal size, else ASP_EINVAL naming both sizes. */
int asp__image_same_size(const asp_image *a, const asp_image *b, asp_error *err);

#endif
