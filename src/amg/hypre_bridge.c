/*
 * The only file that touches hypre and MPI: runs BoomerAMG's setup phase on
 * the stiffness matrix and copies the prolongations P^l out into our own CSR
 * matrices (journal 2.3: A^l = (P^l)^T A^(l-1) P^l). No solve is ever done.
 */
#include <errno.h>
#include <stdint.h>
#include <limits.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <mpi.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/*
 * hypre's internal header (needed for the P matrices, journal 2.3) is not
 * -Wextra clean and calls ffs() without declaring it under strict C11.
 */
int ffs(int i);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop

#include "amg/internal.h"
#include "amg/hypre_internal.h"
#include "util/banned.h"

/*
 * libsuperlu_dist, which comes with hypre, calls mallopt(M_MMAP_MAX, 0) and
 * mallopt(M_TRIM_THRESHOLD, -1) in its load-time constructor: glibc then
 * never maps a large block of its own and never gives freed memory back, so
 * every array a stage frees stays resident and the peak RSS is the heap's
 * high-water mark, fragmentation included (issue 19: 1M points, 764 MB RSS
 * where the library never held more than 778 B/point in one stage and under
 * 260 B/point between stages). This runs after the shared libraries'
 * constructors and puts glibc's defaults back before main (the dynamic mmap
 * threshold stays off: superlu's M_TRIM_THRESHOLD call disabled it, so blocks
 * from 128 KiB up are mapped and unmapped on free). Nothing here uses SuperLU.
 */
#ifdef __GLIBC__
__attribute__((constructor)) static void restore_malloc_defaults(void)
{
    mallopt(M_MMAP_MAX, 65536);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
}
#endif

/*
 * MPI is process-wide state that we cannot keep in asp_context: initialise it
 * once, lazily, and remember whether we did so that asp_amg_shutdown
 * finalises only what we started.
 */
static int mpi_started_here;
static int hypre_started;

/*
 * MPI start-up failure as one line (issue #13). Open MPI reports a failed
 * MPI_Init_thread as 25 lines on fd 2 (its own and its orted helper's) and
 * then calls _exit(1) from inside the call (ess singleton abort): no error
 * code comes back, no atexit handler runs, and MPI_ERRORS_RETURN cannot be
 * set before MPI exists. Where start-up can be made to fail (Open MPI
 * settings in the environment, OMPI_MCA_*, the case; a memory limit,
 * RLIMIT_AS or RLIMIT_DATA) the solver runs in a child process
 * (coarsen_isolated, at the end of this file) and this process turns its
 * report into one line naming the reason and the log file that keeps it.
 */
static char mpi_log[4096];
extern char **environ;

/* The reason in Open MPI's report: the missing component, else the failed call and its code, else the first line. */
static void mpi_reason(const char *log, char *out, size_t cap)
{
    char buf[16384];
    // Open MPI's helper sometimes loses part or all of the report under load (ORTE_ERROR_LOG in
    // show_help.c): then name the settings that are the likely cause
    const char *setting = NULL;
    for (char **e = environ; e && *e && !setting; e++)
        if (strncmp(*e, "OMPI_MCA_", 9) == 0)
            setting = *e;
    char limit[64] = "";
    struct rlimit as;
    if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
        snprintf(limit, sizeof limit, "; memory limit (ulimit -v) %llu MB", (unsigned long long)(as.rlim_cur >> 20));
    snprintf(out, cap, "MPI_Init_thread failed (Open MPI gave no reason%s%.80s)%s", setting ? "; set: " : "",
             setting ? setting : "", limit);
    FILE *fp = fopen(log, "r");
    if (!fp)
        return;
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = '\0';
    // first: the first paragraph of Open MPI's help text (between its dashed lines), joined into one line
    char fw[64] = "", comp[64] = "", call[128] = "", ret[128] = "", first[200] = "";
    int in_first = 0, resources = 0;
    for (char *line = buf, *next; line && *line; line = next) {
        next = strchr(line, '\n');
        if (next)
            *next++ = '\0';
        while (*line == ' ')
            line++;
        resources |= strstr(line, "OUT-OF-RESOURCE") != NULL || strstr(line, "Out of resource") != NULL;
        if (sscanf(line, "Framework: %63s", fw) == 1 || sscanf(line, "Component: %63s", comp) == 1)
            continue;
        int text = line[0] && line[0] != '-' && line[0] != '[' && line[0] != '*';
        if (in_first && text) {
            size_t used = strlen(first);
            snprintf(first + used, sizeof first - used, " %.190s", line);
            continue;
        }
        in_first = 0;
        if (strncmp(line, "--> Returned ", 13) == 0)
            snprintf(ret, sizeof ret, "%.120s", line + 13);
        else if (strstr(line, "() failed"))
            snprintf(call, sizeof call, "%.120s", line);
        else if (!first[0] && text) {
            snprintf(first, sizeof first, "%.190s", line);
            in_first = 1;
        }
    }
    char *stop = strstr(first, ". "); // its first sentence, without the full stop
    if (stop)
        *stop = '\0';
    else if (first[0] && first[strlen(first) - 1] == '.')
        first[strlen(first) - 1] = '\0';
    if (fw[0] && comp[0])
        snprintf(out, cap, "component '%s' of framework '%s' not found (an OMPI_MCA_%s setting?)", comp, fw, fw);
    else if (call[0])
        snprintf(out, cap, "%s, returned %s%s", call, ret[0] ? ret : "an error", limit);
    else if (first[0])
        snprintf(out, cap, "%s%s", first, limit);
    else if (resources)
        snprintf(out, cap, "Open MPI ran out of resources%s%.80s%s", setting ? "; set: " : "", setting ? setting : "",
                 limit);
}

/* Whether MPI_Init_thread can plausibly fail here (see above). */
static int mpi_start_at_risk(void)
{
    for (char **e = environ; e && *e; e++)
        if (strncmp(*e, "OMPI_", 5) == 0 || strncmp(*e, "PMIX_", 5) == 0)
            return 1;
    struct rlimit as, data;
    return (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) ||
           (getrlimit(RLIMIT_DATA, &data) == 0 && data.rlim_cur != RLIM_INFINITY);
}

/*
 * MPI started early on a thread of its own (issue 19). A singleton
 * MPI_Init_thread forks Open MPI's orted helper and waits for it: 0.35-0.45 s
 * here, a tenth of a 1M-point decomposition, spent waiting. Started when the
 * decomposition begins, it overlaps the neighbour search. MPI's rules: the
 * thread that initialises MPI is its main thread and must also finalise it,
 * so this thread stays until asp_amg_shutdown; with MPI_THREAD_SERIALIZED the
 * caller's thread makes every other MPI call, never two at once. Nothing calls
 * MPI before the thread has finished starting (mpi_thread_wait).
 */
enum { MPI_THREAD_NONE, MPI_THREAD_STARTING, MPI_THREAD_UP, MPI_THREAD_FAILED };
static pthread_mutex_t mpi_thread_mutex = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t mpi_thread_cond = PTHREAD_COND_INITIALIZER;
static pthread_t mpi_thread;
static int mpi_thread_state, mpi_thread_stop;

static void *mpi_thread_main(void *arg)
{
    (void)arg;
    int provided = 0;
    int ok = MPI_Init_thread(NULL, NULL, MPI_THREAD_SERIALIZED, &provided) == MPI_SUCCESS;
    pthread_mutex_lock(&mpi_thread_mutex);
    mpi_thread_state = ok ? MPI_THREAD_UP : MPI_THREAD_FAILED;
    pthread_cond_broadcast(&mpi_thread_cond);
    while (ok && !mpi_thread_stop)
        pthread_cond_wait(&mpi_thread_cond, &mpi_thread_mutex);
    pthread_mutex_unlock(&mpi_thread_mutex);
    if (ok)
        MPI_Finalize();
    return NULL;
}

void asp__amg_hypre_prestart(void)
{
    int flag = 0;
    pthread_mutex_lock(&mpi_thread_mutex);
    int idle = mpi_thread_state == MPI_THREAD_NONE;
    pthread_mutex_unlock(&mpi_thread_mutex);
    if (!idle)
        return;
    MPI_Initialized(&flag); /* callable before MPI_Init; a launcher's or a caller's MPI needs no start */
    if (flag || mpi_start_at_risk())
        return; /* at risk: each level runs in a child process instead (coarsen_isolated) */
    pthread_mutex_lock(&mpi_thread_mutex);
    if (mpi_thread_state == MPI_THREAD_NONE && pthread_create(&mpi_thread, NULL, mpi_thread_main, NULL) == 0)
        mpi_thread_state = MPI_THREAD_STARTING;
    pthread_mutex_unlock(&mpi_thread_mutex);
}

/* Waits for an early start to finish; the thread's state (MPI_THREAD_NONE when there was none). */
static int mpi_thread_wait(void)
{
    pthread_mutex_lock(&mpi_thread_mutex);
    while (mpi_thread_state == MPI_THREAD_STARTING)
        pthread_cond_wait(&mpi_thread_cond, &mpi_thread_mutex);
    int state = mpi_thread_state;
    pthread_mutex_unlock(&mpi_thread_mutex);
    return state;
}

/* The one start of MPI and hypre in the process, for the serial and the distributed path (hypre_distributed.c). */
int asp__amg_hypre_start(asp_error *err)
{
    int flag = 0, done = 0;
    if (mpi_thread_wait() == MPI_THREAD_FAILED)
        return asp_error_set(err, ASP_ESOLVER, "cannot start MPI for the AMG solver: MPI_Init_thread failed");
    MPI_Finalized(&done);
    if (done)
        return asp_error_set(err, ASP_ESOLVER, "cannot start hypre: MPI was already finalised");
    MPI_Initialized(&flag);
    if (!flag) {
        int provided = 0;
        /* a singleton run: no mpirun needed, no argc/argv */
        if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
            return asp_error_set(err, ASP_ESOLVER, "cannot start MPI for the AMG solver: MPI_Init_thread failed");
        mpi_started_here = 1;
    }
    if (!hypre_started) {
        HYPRE_Init();
        hypre_started = 1;
    }
    return 0;
}

void asp_amg_shutdown(void)
{
    int done = 0, state = mpi_thread_wait();
    if (state != MPI_THREAD_UP) {
        MPI_Finalized(&done);
        if (done)
            return;
    }
    if (hypre_started) {
        HYPRE_Finalize();
        hypre_started = 0;
    }
    if (state == MPI_THREAD_UP || state == MPI_THREAD_FAILED) {
        /* MPI's main thread finalises it */
        pthread_mutex_lock(&mpi_thread_mutex);
        mpi_thread_stop = 1;
        pthread_cond_broadcast(&mpi_thread_cond);
        pthread_mutex_unlock(&mpi_thread_mutex);
        pthread_join(mpi_thread, NULL);
        pthread_mutex_lock(&mpi_thread_mutex);
        mpi_thread_state = MPI_THREAD_NONE;
        mpi_thread_stop = 0;
        pthread_mutex_unlock(&mpi_thread_mutex);
    }
    if (mpi_started_here) {
        MPI_Finalize();
        mpi_started_here = 0;
    }
}

static HYPRE_Int coarsen_code(asp_amg_coarsen c)
{
    switch (c) {
    case ASP_AMG_COARSEN_FALGOUT: return 6;
    case ASP_AMG_COARSEN_CLJP: return 0;
    case ASP_AMG_COARSEN_PMIS: return 8;
    case ASP_AMG_COARSEN_HMIS: return 10;
    default: return 3; /* RS */
    }
}

static HYPRE_Int interp_code(asp_amg_interp i)
{
    switch (i) {
    case ASP_AMG_INTERP_DIRECT: return 3;
    case ASP_AMG_INTERP_STANDARD: return 8;
    case ASP_AMG_INTERP_EXTENDED_I: return 6;
    default: return 0; /* modified classical */
    }
}

HYPRE_Solver asp__amg_hypre_create_level_solver(const asp_amg_desc *desc)
{
    HYPRE_Solver amg;
    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_BoomerAMGSetCoarsenType(amg, coarsen_code(desc->coarsen));
    HYPRE_BoomerAMGSetInterpType(amg, interp_code(desc->interp));
    HYPRE_BoomerAMGSetStrongThreshold(amg, desc->strong_threshold);
    HYPRE_BoomerAMGSetTruncFactor(amg, desc->trunc_factor);
    /* one level at a time: the caller filters each coarse matrix before coarsening it again */
    HYPRE_BoomerAMGSetMaxLevels(amg, 2);
    HYPRE_BoomerAMGSetMaxCoarseSize(amg, 1);
    HYPRE_BoomerAMGSetMinCoarseSize(amg, 1);
    HYPRE_BoomerAMGSetAggNumLevels(amg, 0);
    /* our matrix is singular (zero row sums): keep Gaussian elimination off the coarsest level */
    HYPRE_BoomerAMGSetCycleRelaxType(amg, 3, 3);
    HYPRE_BoomerAMGSetMaxIter(amg, 1);
    return amg;
}

/* Copies a hypre ParCSR matrix (single process: everything lives in the diag block) with rows sorted by column. */
static int copy_parcsr(hypre_ParCSRMatrix *p, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    hypre_CSRMatrix *d = hypre_ParCSRMatrixDiag(p);
    hypre_CSRMatrix *o = hypre_ParCSRMatrixOffd(p);
    if (o && hypre_CSRMatrixNumNonzeros(o) > 0)
        return asp_error_set(err, ASP_ESOLVER, "hypre returned an off-process block in a single-process run");
    HYPRE_Int rows = hypre_CSRMatrixNumRows(d), cols = hypre_CSRMatrixNumCols(d);
    HYPRE_Int *ia = hypre_CSRMatrixI(d), *ja = hypre_CSRMatrixJ(d);
    HYPRE_Complex *va = hypre_CSRMatrixData(d);
    size_t nnz = (size_t)ia[rows];
    asp_amg_csr *m;
    int rc = asp_amg_csr_create((size_t)rows, (size_t)cols, nnz, ctx, &m, err);
    if (rc)
        return rc;
    for (HYPRE_Int r = 0; r < rows; r++) {
        size_t b = (size_t)ia[r], e = (size_t)ia[r + 1];
        m->row_ptr[r + 1] = e;
        for (size_t k = b; k < e; k++) {
            /* insertion sort: rows hold a handful of entries; hypre puts the diagonal first */
            asp_index c = (asp_index)ja[k];
            double v = va[k];
            size_t q = k;
            while (q > b && m->col[q - 1] > c) {
                m->col[q] = m->col[q - 1];
                m->val[q] = m->val[q - 1];
                q--;
            }
            m->col[q] = c;
            m->val[q] = v;
        }
    }
    *out = m;
    return 0;
}

/*
 * a as a one-process hypre ParCSR matrix, written straight into hypre's
 * arrays (issue 19): the IJ interface kept its own row buffers beside the
 * result and cost about 240 B/point at the peak for 88 in the matrix. The
 * layout is the one IJ assembly produced: each row's diagonal first (hypre's
 * rule for the diag block), then the other columns in a's increasing order,
 * so BoomerAMG sees the same matrix and gives the same bits.
 */
static int build_parcsr(const asp_amg_csr *a, hypre_ParCSRMatrix **out, asp_error *err)
{
    const size_t n = a->rows, nnz = a->row_ptr[n];
    HYPRE_BigInt starts[2] = {0, (HYPRE_BigInt)n};
    hypre_ParCSRMatrix *m = hypre_ParCSRMatrixCreate(MPI_COMM_SELF, (HYPRE_BigInt)n, (HYPRE_BigInt)n, starts, starts, 0,
                                                     (HYPRE_Int)nnz, 0);
    if (!m || hypre_ParCSRMatrixInitialize(m) != 0 || !hypre_CSRMatrixI(hypre_ParCSRMatrixDiag(m)) ||
        (nnz && (!hypre_CSRMatrixJ(hypre_ParCSRMatrixDiag(m)) || !hypre_CSRMatrixData(hypre_ParCSRMatrixDiag(m))))) {
        if (m)
            hypre_ParCSRMatrixDestroy(m);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the hypre copy of the %zu x %zu matrix", n, n);
    }
    hypre_CSRMatrix *d = hypre_ParCSRMatrixDiag(m);
    HYPRE_Int *ia = hypre_CSRMatrixI(d), *ja = hypre_CSRMatrixJ(d);
    HYPRE_Complex *va = hypre_CSRMatrixData(d);
    ia[0] = 0;
    for (size_t r = 0; r < n; r++) {
        size_t b = a->row_ptr[r], e = a->row_ptr[r + 1], w = b;
        for (size_t k = b; k < e; k++)
            if (a->col[k] == r) {
                ja[w] = (HYPRE_Int)r;
                va[w++] = a->val[k];
            }
        for (size_t k = b; k < e; k++)
            if (a->col[k] != r) {
                ja[w] = (HYPRE_Int)a->col[k];
                va[w++] = a->val[k];
            }
        ia[r + 1] = (HYPRE_Int)e;
    }
    hypre_ParCSRMatrixSetNumNonzeros(m);
    hypre_ParCSRMatrixSetDNumNonzeros(m);
    *out = m;
    return 0;
}

/* take (may be NULL) is a's owner: a is destroyed once hypre has its copy */
static int coarsen_here(const asp_amg_csr *a, asp_amg_csr **take, const asp_amg_desc *desc, const asp_context *ctx,
                        asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    int rc = asp__amg_hypre_start(err);
    if (rc)
        return rc;
    HYPRE_Int n = (HYPRE_Int)a->rows;
    const size_t rows = a->rows;
    HYPRE_IJVector bij = NULL, xij = NULL;
    HYPRE_Solver amg = NULL;
    hypre_ParCSRMatrix *pa = NULL;
    asp_amg_csr *p = NULL, *ac = NULL;

    HYPRE_ClearAllErrors();
    rc = build_parcsr(a, &pa, err);
    if (rc)
        goto done;
    if (take) {
        asp_amg_csr_destroy(*take);
        *take = NULL;
        a = NULL;
    }
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &bij);
    HYPRE_IJVectorSetObjectType(bij, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(bij);
    HYPRE_IJVectorAssemble(bij);
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &xij);
    HYPRE_IJVectorSetObjectType(xij, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(xij);
    HYPRE_IJVectorAssemble(xij);
    HYPRE_ParVector pb, px;
    HYPRE_IJVectorGetObject(bij, (void **)&pb);
    HYPRE_IJVectorGetObject(xij, (void **)&px);
    if (HYPRE_GetError()) {
        rc = asp_error_set(err, ASP_ESOLVER, "hypre could not build the %d x %d matrix", (int)n, (int)n);
        goto done;
    }

    amg = asp__amg_hypre_create_level_solver(desc);
    HYPRE_BoomerAMGSetup(amg, (HYPRE_ParCSRMatrix)pa, pb, px);
    /* hypre flags harmless conditions (a zero diagonal on a disconnected coarse point) as errors */
    HYPRE_ClearAllErrors();
    /* the fine matrix is ours, not the solver's (A_array[0] is only borrowed): free it before copying P and A^1 out */
    hypre_ParCSRMatrixDestroy(pa);
    pa = NULL;
    hypre_ParAMGDataAArray((hypre_ParAMGData *)amg)[0] = NULL;

    hypre_ParAMGData *data = (hypre_ParAMGData *)amg;
    if (hypre_ParAMGDataNumLevels(data) >= 2) {
        rc = copy_parcsr(hypre_ParAMGDataPArray(data)[0], ctx, &p, err);
        if (!rc)
            rc = copy_parcsr(hypre_ParAMGDataAArray(data)[1], ctx, &ac, err);
        if (!rc && (p->rows != rows || ac->rows != p->cols || ac->cols != p->cols))
            rc = asp_error_set(err, ASP_ESOLVER, "hypre returned inconsistent coarse sizes");
    }

done:
    if (amg)
        HYPRE_BoomerAMGDestroy(amg);
    if (pa)
        hypre_ParCSRMatrixDestroy(pa);
    if (bij)
        HYPRE_IJVectorDestroy(bij);
    if (xij)
        HYPRE_IJVectorDestroy(xij);
    if (rc) {
        asp_amg_csr_destroy(p);
        asp_amg_csr_destroy(ac);
        return rc;
    }
    *p_out = p;
    *ac_out = ac;
    return 0;
}

/* ---- the isolated run (issue #13: MPI under a memory limit or Open MPI settings) ---- */

/* Writes n bytes, across short writes and EINTR; 0 or -1. */
static int write_all(int fd, const void *buf, size_t n)
{
    const char *b = buf;
    while (n > 0) {
        ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;
        b += w;
        n -= (size_t)w;
    }
    return 0;
}

/* Reads exactly n bytes; 0, or -1 at an early end (the child died) or an error. */
static int read_all(int fd, void *buf, size_t n)
{
    char *b = buf;
    while (n > 0) {
        ssize_t r = read(fd, b, n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            return -1;
        b += r;
        n -= (size_t)r;
    }
    return 0;
}

static int write_csr(int fd, const asp_amg_csr *m)
{
    uint64_t dims[3] = {m->rows, m->cols, m->row_ptr[m->rows]};
    return write_all(fd, dims, sizeof dims) || write_all(fd, m->row_ptr, (m->rows + 1) * sizeof *m->row_ptr) ||
                   write_all(fd, m->col, dims[2] * sizeof *m->col) || write_all(fd, m->val, dims[2] * sizeof *m->val)
               ? -1
               : 0;
}

/* 1 when read, 0 at an early end of the pipe (the child died), <0 an error code set in err. */
static int read_csr(int fd, const asp_context *ctx, asp_amg_csr **out, asp_error *err)
{
    uint64_t dims[3];
    if (read_all(fd, dims, sizeof dims))
        return 0;
    asp_amg_csr *m;
    int rc = asp_amg_csr_create((size_t)dims[0], (size_t)dims[1], (size_t)dims[2], ctx, &m, err);
    if (rc)
        return -rc;
    if (read_all(fd, m->row_ptr, (m->rows + 1) * sizeof *m->row_ptr) || read_all(fd, m->col, dims[2] * sizeof *m->col) ||
        read_all(fd, m->val, dims[2] * sizeof *m->val)) {
        asp_amg_csr_destroy(m);
        return 0;
    }
    *out = m;
    return 1;
}

/*
 * The coarsening in a forked child, this process never starting MPI. Open MPI
 * cannot be made to fail politely: a failed MPI_Init_thread exits the
 * process from inside the call with a 25-line report (no error code, no
 * atexit handler), and under an address-space limit it may instead crash
 * later in its own progress thread (measured: bunny 100k points, ulimit -v
 * 200000: SIGSEGV in orte_util_print_jobids, a snprintf into a NULL buffer
 * after a failed allocation; at 180000 and 220000 the run works). So where
 * start-up can fail (Open MPI settings in the environment, a memory limit:
 * mpi_start_at_risk) each coarsening runs in a child that inherits the matrix
 * (fork), sends P and A^c back through a pipe, and has its fds 1 and 2 in a
 * log file; whatever Open MPI does to the child, this process reports one
 * line. Cost: MPI's start-up (0.4-0.5 s) per level, only in such runs; the
 * child runs hypre on one thread (libgomp's pool is not safe across fork).
 */
static int coarsen_isolated(const asp_amg_csr *a, asp_amg_csr **take, const asp_amg_desc *desc,
                            const asp_context *ctx, asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    const size_t rows = a->rows;
    const char *dir = getenv("TMPDIR");
    snprintf(mpi_log, sizeof mpi_log, "%s/amgsplat-mpi-XXXXXX", dir && *dir ? dir : "/tmp");
    int logfd = mkstemp(mpi_log);
    if (logfd < 0)
        return asp_error_set(err, ASP_EIO, "cannot create the log file '%s' of the AMG solver: %s", mpi_log,
                             strerror(errno));
    int fds[2];
    if (pipe(fds) != 0) {
        int e = errno;
        close(logfd);
        unlink(mpi_log);
        return asp_error_set(err, ASP_ESOLVER, "cannot start the AMG solver's process: pipe: %s", strerror(e));
    }
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(logfd);
        close(fds[0]);
        close(fds[1]);
        unlink(mpi_log);
        return asp_error_set(err, ASP_ESOLVER, "cannot start the AMG solver's process: fork: %s", strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        dup2(logfd, 1);
        dup2(logfd, 2);
        close(logfd);
#ifdef _OPENMP
        omp_set_num_threads(1);
#endif
        asp_error cerr = {0, ""};
        int32_t rc = asp__amg_hypre_start(&cerr);
        char started = 'M'; // MPI is up: a failure from here on is the solver's, not start-up's
        if (!rc && write_all(fds[1], &started, 1))
            _exit(3);
        asp_amg_csr *p = NULL, *ac = NULL;
        if (!rc)
            rc = coarsen_here(a, take, desc, ctx, &p, &ac, &cerr); // frees the child's view of *take too
        int32_t has = p != NULL;
        if (rc) {
            uint32_t len = (uint32_t)strlen(cerr.msg);
            if (write_all(fds[1], &rc, sizeof rc) || write_all(fds[1], &len, sizeof len) ||
                write_all(fds[1], cerr.msg, len))
                _exit(3);
        } else if (write_all(fds[1], &rc, sizeof rc) || write_all(fds[1], &has, sizeof has) ||
                   (has && (write_csr(fds[1], p) || write_csr(fds[1], ac)))) {
            _exit(3);
        }
        _exit(0); // no MPI_Finalize: the helper it waits for costs more than the run itself
    }
    close(logfd);
    close(fds[1]);
    if (take) { // the child has its own copy of the pages now
        asp_amg_csr_destroy(*take);
        *take = NULL;
        a = NULL;
    }
    char started = 0;
    int32_t crc = 0, has = 0;
    asp_amg_csr *p = NULL, *ac = NULL;
    int got = 0, rc = 0; // got: the child's whole answer arrived
    if (read_all(fds[0], &started, 1) == 0 && read_all(fds[0], &crc, sizeof crc) == 0) {
        if (crc) {
            uint32_t len = 0;
            char msg[sizeof err->msg] = "";
            if (read_all(fds[0], &len, sizeof len) == 0 && len < sizeof msg && read_all(fds[0], msg, len) == 0) {
                msg[len] = '\0';
                rc = asp_error_set(err, crc, "%s", msg);
                got = 1;
            }
        } else if (read_all(fds[0], &has, sizeof has) == 0) {
            if (!has) {
                got = 1;
            } else {
                int r = read_csr(fds[0], ctx, &p, err);
                if (r == 1)
                    r = read_csr(fds[0], ctx, &ac, err);
                if (r < 0)
                    rc = -r;
                got = r == 1;
            }
        }
    }
    close(fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (got && !rc && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        unlink(mpi_log);
        *p_out = p;
        *ac_out = ac;
        return 0;
    }
    asp_amg_csr_destroy(p);
    asp_amg_csr_destroy(ac);
    if (got || rc) { // the solver's own error, already in err
        unlink(mpi_log);
        return rc ? rc : asp_error_set(err, ASP_ESOLVER, "the AMG solver's process exited with status %d",
                                       WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    }
    // Open MPI's helper (orted) prints part of the report after the child has gone: wait until the
    // log has not grown for 0.3 s, at most 3 s
    off_t last = -1;
    for (int i = 0, still = 0; i < 60 && still < 6; i++) {
        struct stat st;
        off_t now = stat(mpi_log, &st) == 0 ? st.st_size : -1;
        still = now > 0 && now == last ? still + 1 : 0;
        last = now;
        nanosleep(&(struct timespec){0, 50 * 1000 * 1000}, NULL);
    }
    char reason[512];
    mpi_reason(mpi_log, reason, sizeof reason);
    if (WIFSIGNALED(status))
        snprintf(reason + strlen(reason), sizeof reason - strlen(reason), " (killed by signal %d)", WTERMSIG(status));
    if (started != 'M')
        return asp_error_set(err, ASP_ESOLVER, "cannot start MPI for the AMG solver: %s; Open MPI's report is in '%s'",
                             reason, mpi_log);
    return asp_error_set(err, ASP_ESOLVER,
                         "the AMG solver (hypre on Open MPI) failed in its process on a %zu x %zu matrix: %s; "
                         "Open MPI's report is in '%s'",
                         rows, rows, reason, mpi_log);
}

static int coarsen(const asp_amg_csr *a, asp_amg_csr **take, const asp_amg_desc *desc, const asp_context *ctx,
                   asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    if (a->rows > (size_t)INT_MAX - 1 || a->row_ptr[a->rows] > (size_t)INT_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "matrix of %zu rows is too large for this hypre build", a->rows);
    int started = 0;
    mpi_thread_wait();
    MPI_Initialized(&started);
    if (!started && mpi_start_at_risk())
        return coarsen_isolated(a, take, desc, ctx, p_out, ac_out, err);
    return coarsen_here(a, take, desc, ctx, p_out, ac_out, err);
}

int asp__amg_hypre_coarsen(const asp_amg_csr *a, const asp_amg_desc *desc, const asp_context *ctx,
                           asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    return coarsen(a, NULL, desc, ctx, p_out, ac_out, err);
}

int asp__amg_hypre_coarsen_take(asp_amg_csr **a, const asp_amg_desc *desc, const asp_context *ctx,
                                asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    return coarsen(*a, a, desc, ctx, p_out, ac_out, err);
}
