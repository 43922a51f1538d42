/*
 * No command writes what its own reader refuses (issue #13): asp_amg_save and
 * asp_ply_write read the written file back before it replaces the target.
 * A decomposition damaged in memory (a weight above 1 in P, an epsilon of inf
 * as decompose once wrote for points at +-3e38) and a cloud with a NaN
 * coordinate are refused with "internal error: ... does not read back", the
 * target keeps its old bytes, and no temporary is left.
 */
#include <math.h>
#include <unistd.h>

#include "amg/internal.h"
#include "amgsplat/amg.h"
#include "amgsplat/io.h"
#include "amgsplat/sample.h"
#include "harness.h"

static char path[256];

static int old_bytes_kept(const char *p)
{
    char line[32] = "";
    FILE *fp = fopen(p, "r");
    if (!fp)
        return 0;
    if (!fgets(line, sizeof line, fp))
        line[0] = '\0';
    fclose(fp);
    char tmp[300];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", p, (long)getpid());
    return strcmp(line, "old\n") == 0 && access(tmp, F_OK) != 0;
}

static void put_old(const char *p)
{
    FILE *fp = fopen(p, "w");
    if (fp) {
        fputs("old\n", fp);
        fclose(fp);
    }
}

static void test_amg(void)
{
    asp_error err = {0};
    asp_cloud *c = NULL;
    asp_amg *amg = NULL;
    snprintf(path, sizeof path, "/tmp/asp_test_readback_%ld.amg", (long)getpid());
    CHECK_OK(asp_synth(ASP_SYNTH_OCTAHEDRON, &(asp_synth_desc){.points = 1500}, NULL, &c, &err), &err);
    if (c)
        CHECK_OK(asp_amg_decompose(c, NULL, NULL, &amg, &err), &err);
    asp_cloud_destroy(c);
    if (!amg)
        return;
    CHECK_OK(asp_amg_save(amg, path, &err), &err); // the undamaged one reads back
    CHECK(amg->nlevels >= 2);
    double *w = &amg->prolong[1]->val[0], keep = *w;
    *w = 1.0000000000000566;
    put_old(path);
    CHECK(asp_amg_save(amg, path, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "internal error: the written '") && strstr(err.msg, "' does not read back: ") &&
                  strstr(err.msg, "has weight 1.0000000000000566, above 1"),
              "%s", err.msg);
    CHECK(old_bytes_kept(path));
    *w = keep;
    amg->desc.epsilon = INFINITY;
    CHECK(asp_amg_save(amg, path, &err) == ASP_EFORMAT);
    CHECK_MSG(strstr(err.msg, "does not read back: ") && strstr(err.msg, "epsilon inf"), "%s", err.msg);
    CHECK(old_bytes_kept(path));
    asp_amg_destroy(amg);
    unlink(path);
}

static void test_ply(void)
{
    asp_error err = {0};
    asp_cloud *c = NULL;
    snprintf(path, sizeof path, "/tmp/asp_test_readback_%ld.ply", (long)getpid());
    CHECK_OK(asp_cloud_create(4, 0, NULL, &c, &err), &err);
    if (!c)
        return;
    for (size_t i = 0; i < 12; i++)
        c->positions[i] = (float)i;
    CHECK_OK(asp_ply_write(c, path, NULL, &err), &err);
    c->positions[4] = NAN;
    put_old(path);
    int rc = asp_ply_write(c, path, NULL, &err);
    CHECK(rc == ASP_EFORMAT);
    // the writer writes what it is given; the read-back names the element and the value
    CHECK_MSG(strstr(err.msg, "does not read back: ") && strstr(err.msg, "element 'vertex' 2 of 4") &&
                  strstr(err.msg, "coordinate y is NaN"),
              "%s", err.msg);
    CHECK(old_bytes_kept(path));
    asp_cloud_destroy(c);
    unlink(path);
}

TEST_MAIN(TEST_CASE(test_amg), TEST_CASE(test_ply))
