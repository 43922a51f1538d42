/*
 * Benchmark of the AMG decomposition (journal 2, Table 1 "sd time"): samples
 * the bunny with N points (area method), or reads a point file, and prints the
 * median time of each stage (neighbours, classifier, fans, assembly, AMG,
 * basis of all levels) and the peak memory. Usage: bench_decompose [N=1000000]
 * [RUNS=3] [THREADS=0] [STRONG=0 (default 0.9)] [CREASE_CUT=0 (default 0.25, -1 off)]
 * [--in FILE.ply] [--mem] [--save OUT.amg]. --mem also prints where the bytes go
 * (issue 19): per stage, the library's live and peak allocation (a counting
 * allocator in the context) and the process's peak RSS within the stage
 * (VmHWM, reset at each stage through /proc/self/clear_refs), which also sees
 * hypre's own allocations. --save adds writing the .amg (with its read-back).
 */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "amgsplat/amg.h"
#include "amgsplat/io.h"
#include "amgsplat/mesh.h"
#include "amgsplat/sample.h"
#include "bench_common.h"

/* ---- the counting allocator and the per-stage records of --mem ---- */

enum { HDR = 64, MAX_STAGES = 16 };

typedef struct mem_stage {
    char name[16];
    size_t live_start, live_peak; /* library bytes at the stage's start, the most within it */
    long rss_start_kb, hwm_kb;    /* process RSS at the start, its peak within the stage */
} mem_stage;

typedef struct mem_track {
    atomic_size_t live, peak;
    mem_stage st[MAX_STAGES];
    int nst;
} mem_track;

static void *track_alloc(void *user, size_t size, size_t alignment)
{
    mem_track *t = user;
    (void)alignment; /* the library asks for 64 (ASP_ALIGNMENT); the header keeps it */
    size_t rounded = (size + HDR + HDR - 1) / HDR * HDR;
    char *b = aligned_alloc(HDR, rounded);
    if (!b)
        return NULL;
    memcpy(b, &size, sizeof size);
    size_t now = atomic_fetch_add(&t->live, size) + size, old = atomic_load(&t->peak);
    while (now > old && !atomic_compare_exchange_weak(&t->peak, &old, now))
        ;
    return b + HDR;
}

static void track_free(void *user, void *ptr)
{
    mem_track *t = user;
    char *b = (char *)ptr - HDR;
    size_t size;
    memcpy(&size, b, sizeof size);
    atomic_fetch_sub(&t->live, size);
    free(b);
}

/* VmRSS and VmHWM of this process in kB. */
static void read_rss(long *rss, long *hwm)
{
    char line[256];
    *rss = *hwm = 0;
    FILE *fp = fopen("/proc/self/status", "r");
    if (!fp)
        return;
    while (fgets(line, sizeof line, fp)) {
        if (strncmp(line, "VmRSS:", 6) == 0)
            *rss = atol(line + 6);
        else if (strncmp(line, "VmHWM:", 6) == 0)
            *hwm = atol(line + 6);
    }
    fclose(fp);
}

/* Closes the current stage (its peaks) and opens `name` (NULL: none), resetting both peaks. */
static void mem_mark(mem_track *t, const char *name)
{
    long rss, hwm;
    read_rss(&rss, &hwm);
    if (t->nst > 0) {
        mem_stage *s = &t->st[t->nst - 1];
        s->live_peak = atomic_load(&t->peak);
        s->hwm_kb = hwm;
    }
    if (!name || t->nst == MAX_STAGES)
        return;
    /* "5" resets the peak RSS to the current RSS (Linux 4.0, proc(5)) */
    FILE *fp = fopen("/proc/self/clear_refs", "w");
    if (fp) {
        fputs("5", fp);
        fclose(fp);
    }
    read_rss(&rss, &hwm);
    mem_stage *s = &t->st[t->nst++];
    snprintf(s->name, sizeof s->name, "%s", name);
    s->live_start = atomic_load(&t->live);
    atomic_store(&t->peak, s->live_start);
    s->rss_start_kb = rss;
}

/* The pipeline's stage names (decompose.c); "knn" and repeated "amg" calls stay in the open stage. */
static int track_progress(void *user, const char *stage, double fraction)
{
    mem_track *t = user;
    (void)fraction;
    static const char *stages[] = {"neighbours", "classifier", "fans", "assembly", "amg"};
    for (size_t i = 0; i < sizeof stages / sizeof *stages; i++)
        if (strcmp(stage, stages[i]) == 0 && (t->nst == 0 || strcmp(t->st[t->nst - 1].name, stage) != 0))
            mem_mark(t, stage);
    return 0;
}

static void mem_print(const mem_track *t, size_t n)
{
    printf("  memory by stage (B/point; library: counting allocator; RSS: process, incl. hypre and the input):\n");
    printf("  %-11s %10s %10s %10s %10s\n", "stage", "lib start", "lib peak", "RSS start", "RSS peak");
    for (int i = 0; i < t->nst; i++) {
        const mem_stage *s = &t->st[i];
        printf("  %-11s %10.1f %10.1f %10.1f %10.1f\n", s->name, (double)s->live_start / (double)n,
               (double)s->live_peak / (double)n, 1024.0 * (double)s->rss_start_kb / (double)n,
               1024.0 * (double)s->hwm_kb / (double)n);
    }
}

int main(int argc, char **argv)
{
    const char *in = NULL, *save = NULL;
    int mem = 0, npos = 0;
    char *pos[8] = {0};
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--mem") == 0)
            mem = 1;
        else if (strcmp(argv[i], "--in") == 0 && i + 1 < argc)
            in = argv[++i];
        else if (strcmp(argv[i], "--save") == 0 && i + 1 < argc)
            save = argv[++i];
        else if (npos < 8)
            pos[npos++] = argv[i];
    }
    size_t n = npos > 0 ? (size_t)atof(pos[0]) : 1000000;
    int runs = npos > 1 ? atoi(pos[1]) : 3;
    static mem_track track;
    asp_context ctx = {.threads = npos > 2 ? atoi(pos[2]) : 0};
    asp_amg_desc desc = {.strong_threshold = npos > 3 ? atof(pos[3]) : 0, .crease_cut = npos > 4 ? atof(pos[4]) : 0};
    if (runs < 1 || runs > 50)
        runs = 3;
    if (mem) {
        runs = 1; /* one run: the stage records are per run */
        ctx.allocator = (asp_allocator){track_alloc, track_free, &track};
        ctx.progress = track_progress;
        ctx.progress_user = &track;
        mem_mark(&track, "input");
    }
    asp_error err;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    if (in) {
        if (asp_cloud_load(in, &ctx, &cloud, &err)) {
            fprintf(stderr, "bench_decompose: %s\n", err.msg);
            return 1;
        }
    } else if (asp_mesh_load(ASP_TEST_DATA "/stanford-bunny.obj", NULL, &ctx, &mesh, &err) ||
               asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_AREA, .points = n}, &ctx, &cloud, NULL,
                               &err)) {
        fprintf(stderr, "bench_decompose: %s\n", err.msg);
        return 1;
    }
    asp_mesh_destroy(mesh);
    enum { STAGES = 7 };
    static const char *names[STAGES] = {"neighbours", "classifier", "fans", "assembly", "amg", "basis", "total"};
    double t[STAGES][50];
    size_t levels = 0, coarsest = 0;
    for (int r = 0; r < runs; r++) {
        asp_amg *amg = NULL;
        double t0 = asp_time_now();
        if (asp_amg_decompose(cloud, &desc, &ctx, &amg, &err)) {
            fprintf(stderr, "bench_decompose: %s\n", err.msg);
            return 1;
        }
        double t1 = asp_time_now();
        if (mem)
            mem_mark(&track, "save");
        if (save && asp_amg_save(amg, save, &err)) {
            fprintf(stderr, "bench_decompose: %s\n", err.msg);
            return 1;
        }
        if (mem)
            mem_mark(&track, "basis");
        levels = asp_amg_level_count(amg);
        coarsest = asp_amg_level_size(amg, levels - 1);
        asp_amg_level_stats *st = calloc(levels, sizeof *st);
        if (!st || asp_amg_level_stats_all(amg, 0.05, &ctx, st, &err)) {
            fprintf(stderr, "bench_decompose: level statistics failed\n");
            return 1;
        }
        double t2 = asp_time_now();
        if (mem)
            mem_mark(&track, NULL);
        const asp_amg_info *info = asp_amg_get_info(amg);
        t[0][r] = info->t_neighbours;
        t[1][r] = info->t_classifier;
        t[2][r] = info->t_fans;
        t[3][r] = info->t_assembly;
        t[4][r] = info->t_amg;
        t[5][r] = t2 - t1;
        t[6][r] = t1 - t0;
        free(st);
        asp_amg_destroy(amg);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double load[3] = {0, 0, 0};
    FILE *fp = fopen("/proc/loadavg", "r");
    if (fp) {
        if (fscanf(fp, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3)
            load[0] = 0;
        fclose(fp);
    }
    printf("bench_decompose: %s, %zu points, %d runs, %d threads, strength %g, crease cut %g, %zu levels (coarsest "
           "%zu unknowns), load average %.2f\n",
           in ? in : "bunny", cloud->count, runs, asp_context_threads(&ctx),
           desc.strong_threshold ? desc.strong_threshold : 0.9, desc.crease_cut ? desc.crease_cut : 0.25, levels,
           coarsest, load[0]);
    for (int s = 0; s < STAGES; s++)
        printf("  %-11s %8.3f s (median)%s\n", names[s], bench_median_upper(t[s], runs),
               s == 5 && save ? " (includes writing the .amg)" : "");
    /* --mem resets the peak at each stage (clear_refs), so getrusage's maximum is the last stage's */
    double peak_kb = (double)ru.ru_maxrss;
    for (int i = 0; mem && i < track.nst; i++)
        peak_kb = i == 0 || (double)track.st[i].hwm_kb > peak_kb ? (double)track.st[i].hwm_kb : peak_kb;
    printf("  peak memory %.0f MB (max RSS, includes %s)\n", peak_kb / 1024.0, in ? "the input" : "sampling");
    if (mem)
        mem_print(&track, cloud->count);
    asp_cloud_destroy(cloud);
    asp_amg_shutdown();
    return 0;
}
