/*
 * amgsplat output batches: the files one command writes appear all or none
 * (issue #13). Every file the library writes goes to "<path>.tmp.<pid>"
 * first and is renamed into place when complete; a batch defers those
 * renames until the caller has written everything.
 */
#ifndef AMGSPLAT_OUTPUT_H
#define AMGSPLAT_OUTPUT_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Opens an output batch on the calling thread. Until asp_output_batch_commit
 * or asp_output_batch_abort, every file the library writes from this thread
 * (asp_cloud_save, asp_amg_save, asp_dps_save, asp_image_save_png, ...) is
 * written, validated and left under its temporary name; the targets are not
 * touched. A signal (SIGINT, SIGTERM, SIGHUP) removes the temporaries. At
 * most 128 files can be pending at once, in all threads together.
 * Batches nest: a batch begun inside another joins it, and only the
 * outermost commit renames (asp_mesh_save's OBJ+MTL+PNG inside a command's
 * batch). Every begin is matched by one commit or one abort. Returns 0.
 */
int asp_output_batch_begin(asp_error *err);

/**
 * Closes the innermost batch; the outermost commit renames every file of the
 * thread's batch into place. Returns 0, ASP_EINVAL (no batch open),
 * ASP_ECANCELED (an inner batch was aborted: nothing is renamed) or ASP_EIO:
 * a rename failed, the remaining temporaries are removed, and the message
 * says how many outputs had already appeared (renames cannot be undone).
 */
int asp_output_batch_commit(asp_error *err);

/**
 * Removes every file of the thread's batch (the outer batches' too) and
 * closes the innermost one; the targets stay as they were, and the outer
 * commits return ASP_ECANCELED. No-op without a batch.
 */
void asp_output_batch_abort(void);

#ifdef __cplusplus
}
#endif

#endif
