/*
 * Writes the .hier file of a point file, for the fuzz smoke in scripts/test.sh: no command of
 * the CLI saves a hierarchy (the viewer builds its own), and fuzz_hier needs a valid file as a
 * seed so that its mutations start past the header checks.
 *   seed_hier IN.ply OUT.hier
 */
#include <stdio.h>

#include "amgsplat/hier.h"
#include "amgsplat/io.h"

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: seed_hier IN.ply OUT.hier\n");
        return 2;
    }
    asp_error err = {0, ""};
    asp_cloud *cloud = NULL;
    asp_hier *hier = NULL;
    int rc = asp_cloud_load(argv[1], NULL, &cloud, &err);
    if (!rc)
        rc = asp_hier_build(cloud, NULL, NULL, &hier, &err);
    if (!rc)
        rc = asp_hier_save(hier, argv[2], &err);
    if (rc)
        fprintf(stderr, "seed_hier: %s\n", err.msg);
    asp_hier_destroy(hier);
    asp_cloud_destroy(cloud);
    return rc ? 1 : 0;
}
