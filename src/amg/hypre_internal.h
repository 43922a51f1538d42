/*
 * Private to the files that call hypre (hypre_*.c, STYLE.md 6): the one
 * BoomerAMG configuration of the serial (hypre_bridge.c) and the distributed
 * (hypre_distributed.c) decomposition. Include after HYPRE.h.
 */
#ifndef ASP_AMG_HYPRE_INTERNAL_H
#define ASP_AMG_HYPRE_INTERNAL_H

#include "amgsplat/amg.h"

/*
 * A BoomerAMG solver set up to build ONE coarse level per call (journal 2.3):
 * the caller filters each coarse matrix before coarsening it again. desc has
 * its defaults resolved. Free with HYPRE_BoomerAMGDestroy.
 */
HYPRE_Solver asp__amg_hypre_create_level_solver(const asp_amg_desc *desc);

#endif
