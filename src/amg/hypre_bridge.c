/*
 * The only file that touches hypre and MPI: runs BoomerAMG's setup phase on
 * the stiffness matrix and copies the prolongations P^l out into our own CSR
 * matrices (journal 2.3: A^l = (P^l)^T A^(l-1) P^l). No solve is ever done.
 */
#include <limits.h>
#include <mpi.h>
#include <string.h>

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
#include "util/banned.h"

/*
 * MPI is process-wide state that we cannot keep in asp_context: initialise it
 * once, lazily, and remember whether we did so that asp_amg_shutdown
 * finalises only what we started.
 */
static int mpi_started_here;
static int hypre_started;

static int ensure_mpi(asp_error *err)
{
    int flag = 0, done = 0;
    MPI_Finalized(&done);
    if (done)
        return asp_error_set(err, ASP_ESOLVER, "cannot start hypre: MPI was already finalised");
    MPI_Initialized(&flag);
    if (!flag) {
        int provided = 0;
        /* a singleton run: no mpirun needed, no argc/argv */
        if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
            return asp_error_set(err, ASP_ESOLVER, "cannot initialise MPI for hypre");
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
    int done = 0;
    MPI_Finalized(&done);
    if (done)
        return;
    if (hypre_started) {
        HYPRE_Finalize();
        hypre_started = 0;
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

int asp__amg_hypre_coarsen(const asp_amg_csr *a, const asp_amg_desc *desc, const asp_context *ctx,
                           asp_amg_csr **p_out, asp_amg_csr **ac_out, asp_error *err)
{
    if (a->rows > (size_t)INT_MAX - 1 || a->row_ptr[a->rows] > (size_t)INT_MAX)
        return asp_error_set(err, ASP_EUNSUPPORTED, "matrix of %zu rows is too large for this hypre build", a->rows);
    int rc = ensure_mpi(err);
    if (rc)
        return rc;
    HYPRE_Int n = (HYPRE_Int)a->rows;
    HYPRE_IJMatrix ij = NULL;
    HYPRE_IJVector bij = NULL, xij = NULL;
    HYPRE_Solver amg = NULL;
    HYPRE_Int *ncols = NULL, *rowsv = NULL, *colsv = NULL;
    asp_amg_csr *p = NULL, *ac = NULL;

    ncols = asp_alloc(ctx, (size_t)n * sizeof *ncols);
    rowsv = asp_alloc(ctx, (size_t)n * sizeof *rowsv);
    colsv = asp_alloc(ctx, (a->row_ptr[a->rows] + 1) * sizeof *colsv);
    if (!ncols || !rowsv || !colsv) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the hypre matrix");
        goto done;
    }
    for (HYPRE_Int r = 0; r < n; r++) {
        ncols[r] = (HYPRE_Int)(a->row_ptr[r + 1] - a->row_ptr[r]);
        rowsv[r] = r;
    }
    for (size_t k = 0; k < a->row_ptr[a->rows]; k++)
        colsv[k] = (HYPRE_Int)a->col[k];

    HYPRE_ClearAllErrors();
    HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &ij);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJMatrixSetRowSizes(ij, ncols);
    HYPRE_IJMatrixInitialize(ij);
    HYPRE_IJMatrixSetValues(ij, n, ncols, rowsv, colsv, a->val);
    HYPRE_IJMatrixAssemble(ij);
    HYPRE_ParCSRMatrix pa;
    HYPRE_IJMatrixGetObject(ij, (void **)&pa);

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
    HYPRE_BoomerAMGSetup(amg, pa, pb, px);
    /* hypre flags harmless conditions (a zero diagonal on a disconnected coarse point) as errors */
    HYPRE_ClearAllErrors();

    hypre_ParAMGData *data = (hypre_ParAMGData *)amg;
    if (hypre_ParAMGDataNumLevels(data) >= 2) {
        rc = copy_parcsr(hypre_ParAMGDataPArray(data)[0], ctx, &p, err);
        if (!rc)
            rc = copy_parcsr(hypre_ParAMGDataAArray(data)[1], ctx, &ac, err);
        if (!rc && (p->rows != a->rows || ac->rows != p->cols || ac->cols != p->cols))
            rc = asp_error_set(err, ASP_ESOLVER, "hypre returned inconsistent coarse sizes");
    }

done:
    if (amg)
        HYPRE_BoomerAMGDestroy(amg);
    if (ij)
        HYPRE_IJMatrixDestroy(ij);
    if (bij)
        HYPRE_IJVectorDestroy(bij);
    if (xij)
        HYPRE_IJVectorDestroy(xij);
    asp_free(ctx, ncols);
    asp_free(ctx, rowsv);
    asp_free(ctx, colsv);
    if (rc) {
        asp_amg_csr_destroy(p);
        asp_amg_csr_destroy(ac);
        return rc;
    }
    *p_out = p;
    *ac_out = ac;
    return 0;
}
