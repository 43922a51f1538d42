/*
 * The Domain Set switch of the thesis's viewer (appendix C): a .dps built
 * with both domain sets holds each AMG level twice, thresholded (Psi > tau,
 * journal eq. 8) and strict (thesis eq. 2.5); this picks the counterpart of a
 * level in the other set.
 */
#include "amgsplat/prim.h"
#include "util/banned.h"

int asp_dps_domain_set_pick(const asp_dps *dps, size_t from, int strict, size_t *index, asp_error *err)
{
    ASP_ASSERT(dps && index);
    if (from >= dps->level_count)
        return asp_error_set(err, ASP_EINVAL, "level index %zu out of range: the file holds %zu levels", from,
                             dps->level_count);
    strict = strict != 0;
    size_t first = SIZE_MAX;
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        if ((lv->strict != 0) != strict)
            continue;
        if (lv->level == dps->levels[from].level) {
            *index = i;
            return 0;
        }
        if (first == SIZE_MAX)
            first = i; // levels are stored finest first
    }
    if (first == SIZE_MAX)
        return asp_error_set(err, ASP_EINVAL, "no %s levels in the file; build with --domains %s or both",
                             strict ? "strict" : "thresholded", strict ? "strict" : "thresholded");
    *index = first;
    return 0;
}
