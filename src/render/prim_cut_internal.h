/*
 * Private to the cut renderer (prim_cut_renderer.c, prim_cut_shaders.c; issue
 * 18): its shader sources. The primitive records are the prim renderer's
 * asp__prim_gpu (prim_internal.h).
 */
#ifndef ASP_RENDER_PRIM_CUT_INTERNAL_H
#define ASP_RENDER_PRIM_CUT_INTERNAL_H

#include "render/prim_internal.h"

/* Storage-buffer binding of the instances' model matrices (after the prim renderer's 0..2). */
enum { ASP__CUT_BIND_MODELS = 3 };

extern const char *const asp__cut_vertex_src;
extern const char *const asp__cut_fragment_src;

#endif
