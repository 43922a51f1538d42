/*
 * The umbrella header (STYLE.md 1: amgsplat.h = all): this file includes no library header but
 * amgsplat.h, so it compiles only while amgsplat.h declares what it uses (stats.h, experiment.h
 * were missing, issue 26); and every header of include/amgsplat/ is one amgsplat.h includes.
 */
#include "amgsplat/amgsplat.h"

#include <dirent.h>

#include "harness.h"

/* Headers of include/amgsplat/ that amgsplat.h does not name in an #include line. */
static void test_includes_every_header(void)
{
    char dir[1024], path[1100];
    snprintf(dir, sizeof dir, "%s/../include/amgsplat", ASP_TEST_SRC);
    snprintf(path, sizeof path, "%s/amgsplat.h", dir);
    FILE *fp = fopen(path, "r");
    CHECK_MSG(fp != NULL, "cannot open '%s'", path);
    if (!fp)
        return;
    static char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    text[n] = '\0';
    fclose(fp);
    DIR *d = opendir(dir);
    CHECK_MSG(d != NULL, "cannot list '%s'", dir);
    if (!d)
        return;
    size_t headers = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        size_t len = strlen(e->d_name);
        if (len < 3 || strcmp(e->d_name + len - 2, ".h") != 0 || strcmp(e->d_name, "amgsplat.h") == 0)
            continue;
        char line[300];
        snprintf(line, sizeof line, "#include \"%s\"", e->d_name);
        CHECK_MSG(strstr(text, line) != NULL, "amgsplat.h does not include '%s'", e->d_name);
        headers++;
    }
    closedir(d);
    CHECK_MSG(headers >= 20, "only %zu headers beside amgsplat.h in '%s'", headers, dir);
}

/* A call into stats.h (built in every configuration) and, with GL, into experiment.h. */
static void test_stats_and_experiment_declared(void)
{
    const double x[3] = {1, 2, 6};
    asp_stats_summary s;
    asp_error err = {0, ""};
    CHECK_OK(asp_stats_summarize(x, 3, &s, &err), &err);
    CHECK_NEAR(s.mean, 3.0, 1e-12);
    CHECK_NEAR(s.median, 2.0, 1e-12);
#ifdef ASP_HAVE_GL
    asp_experiment_condition c = ASP_EXPERIMENT_BLANK;
    CHECK_OK(asp_experiment_condition_parse("points", &c, &err), &err);
    CHECK(c == ASP_EXPERIMENT_POINTS);
    CHECK(strcmp(asp_experiment_condition_name(ASP_EXPERIMENT_PRIMITIVES), "primitives") == 0);
#endif
}

TEST_MAIN(TEST_CASE(test_includes_every_header), TEST_CASE(test_stats_and_experiment_declared))
