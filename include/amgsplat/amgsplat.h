/*
 * amgsplat: point-based rendering and extreme simplification by algebraic
 * multigrid domain primitives (Reniers & Telea 2006; Pajarola et al. 2003;
 * Schwarz 2004). This header includes the whole public API: every header of
 * include/amgsplat/ (tests/unit/test_core_umbrella.c checks that none is missing).
 */
#ifndef AMGSPLAT_H
#define AMGSPLAT_H

#include "core.h"
#include "cloud.h"
#include "image.h"
#include "io.h"
#include "point_stream.h"
#include "mesh.h"
#include "geom.h"
#include "camera.h"
#include "sample.h"
#include "eval.h"
#include "hier.h"
#include "hier_ooc.h"
#include "amg.h"
#include "amg_distributed.h"
#include "prim.h"
#include "billboard.h"
#include "export.h"
#include "render.h"
#include "fit.h"
#include "scene.h"
#include "instances.h"
#include "scene_renderer.h"
#include "viewer.h"
#include "output.h"
#include "preset.h"
#include "stats.h"
#include "experiment.h"

#endif
