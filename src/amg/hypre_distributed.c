/*
 * hypre on MPI ranks for the distributed decomposition (issue 19): a
 * row-distributed matrix becomes a HYPRE IJ/ParCSR matrix over
 * MPI_COMM_WORLD, BoomerAMG's setup makes one level with the serial path's
 * options (hypre_bridge.c), and P and A^1 (journal 2.3) come back as local
 * rows with global columns; the crease test's Galerkin product is hypre's
 * distributed R^T A P.
 */
#ifdef ASP_HAVE_HYPRE
#include <limits.h>
#include <stdlib.h>
#include <string.h>

int ffs(int i); /* hypre's internal header calls it without declaring it under strict C11 */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop

#include "amg/distributed.h"
#include "amg/hypre_internal.h"
#include "util/banned.h"

int asp__dist_start(asp__dist *d, asp_error *err)
{
    int rc = asp__amg_hypre_start(err); /* hypre_bridge.c: the one start of MPI and hypre */
    if (rc)
        return rc;
    d->comm = MPI_COMM_WORLD;
    MPI_Comm_rank(d->comm, &d->rank);
    MPI_Comm_size(d->comm, &d->size);
    return 0;
}

void asp_amg_distributed_shutdown(void)
{
    asp_amg_shutdown(); /* one shutdown: MPI and hypre are process-wide */
}

/* An IJ matrix of the local rows m (global columns) with rows starts[rank].. and columns cstarts[rank]... */
static int to_ij(const asp__dist *d, const asp_amg_csr *m, const size_t *starts, const size_t *cstarts,
                 HYPRE_IJMatrix *out, asp_error *err)
{
    const size_t rows = m->rows, nnz = m->row_ptr[rows];
    HYPRE_Int *ncols = asp_alloc(&d->ctx, (rows + 1) * sizeof *ncols);
    HYPRE_BigInt *rowid = asp_alloc(&d->ctx, (rows + 1) * sizeof *rowid), *cols = asp_alloc(&d->ctx, (nnz + 1) * sizeof *cols);
    if (!ncols || !rowid || !cols) {
        asp_free(&d->ctx, ncols);
        asp_free(&d->ctx, rowid);
        asp_free(&d->ctx, cols);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a hypre matrix of %zu rows", rows);
    }
    for (size_t r = 0; r < rows; r++) {
        ncols[r] = (HYPRE_Int)(m->row_ptr[r + 1] - m->row_ptr[r]);
        rowid[r] = (HYPRE_BigInt)(starts[d->rank] + r);
    }
    for (size_t k = 0; k < nnz; k++)
        cols[k] = (HYPRE_BigInt)m->col[k];
    HYPRE_IJMatrix ij;
    HYPRE_IJMatrixCreate(d->comm, (HYPRE_BigInt)starts[d->rank], (HYPRE_BigInt)starts[d->rank + 1] - 1,
                         (HYPRE_BigInt)cstarts[d->rank], (HYPRE_BigInt)cstarts[d->rank + 1] - 1, &ij);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    /*
     * NEEDSWORK: HYPRE_IJMatrixSetDiagOffdSizes would let hypre write straight into the ParCSR arrays
     * instead of an auxiliary matrix of one allocation per row (tried: 35 MB less peak and 0.6 s less
     * AMG at 1M points on one rank), but hypre then orders the entries of a row differently, RS
     * coarsening follows that order, and one rank no longer gives the serial hierarchy (whose layout,
     * hypre_bridge.c build_parcsr, is the one this path gives). Both would have to change together.
     */
    HYPRE_IJMatrixSetRowSizes(ij, ncols);
    HYPRE_IJMatrixInitialize(ij);
    if (rows)
        HYPRE_IJMatrixSetValues(ij, (HYPRE_Int)rows, ncols, rowid, cols, m->val);
    /* hypre has copied the values: our index arrays go before the assembly, its peak (issue 19) */
    asp_free(&d->ctx, ncols);
    asp_free(&d->ctx, rowid);
    asp_free(&d->ctx, cols);
    HYPRE_IJMatrixAssemble(ij);
    *out = ij;
    return 0;
}

static int cmp_entry(const void *a, const void *b)
{
    const HYPRE_BigInt x = *(const HYPRE_BigInt *)a, y = *(const HYPRE_BigInt *)b;
    return x < y ? -1 : x > y;
}

/*
 * Local rows of a ParCSR matrix as asp_amg_csr with global, increasing columns (cols: the global column
 * count); with keep, only the rows r with keep[r] (the others empty).
 */
static int from_parcsr_rows(const asp__dist *d, hypre_ParCSRMatrix *p, size_t cols, const uint8_t *keep,
                            asp_amg_csr **out, asp_error *err)
{
    hypre_CSRMatrix *dg = hypre_ParCSRMatrixDiag(p), *od = hypre_ParCSRMatrixOffd(p);
    const HYPRE_Int rows = hypre_CSRMatrixNumRows(dg);
    const HYPRE_BigInt first_row = hypre_ParCSRMatrixFirstRowIndex(p), first_col = hypre_ParCSRMatrixFirstColDiag(p);
    const HYPRE_Int *di = hypre_CSRMatrixI(dg), *dj = hypre_CSRMatrixJ(dg);
    const HYPRE_Int *oi = hypre_CSRMatrixI(od), *oj = hypre_CSRMatrixJ(od);
    const HYPRE_Complex *dv = hypre_CSRMatrixData(dg), *ov = hypre_CSRMatrixData(od);
    const HYPRE_BigInt *cmap = hypre_ParCSRMatrixColMapOffd(p);
    const int has_offd = oi && hypre_CSRMatrixNumCols(od) > 0;
    size_t nnz = 0;
    for (HYPRE_Int r = 0; r < rows; r++)
        if (!keep || keep[r])
            nnz += (size_t)(di[r + 1] - di[r]) + (has_offd ? (size_t)(oi[r + 1] - oi[r]) : 0);
    (void)first_row;
    asp_amg_csr *m;
    int rc = asp_amg_csr_create((size_t)rows, cols, nnz, &d->ctx, &m, err);
    if (rc)
        return rc;
    struct {
        HYPRE_BigInt c;
        double v;
    } *row = NULL;
    size_t cap = 0, w = 0;
    for (HYPRE_Int r = 0; r < rows; r++) {
        if (keep && !keep[r]) {
            m->row_ptr[r + 1] = w;
            continue;
        }
        size_t len = (size_t)(di[r + 1] - di[r]) + (has_offd ? (size_t)(oi[r + 1] - oi[r]) : 0);
        if (len > cap) {
            asp_free(&d->ctx, row);
            cap = 2 * len;
            row = asp_alloc(&d->ctx, cap * sizeof *row);
            if (!row) {
                asp_amg_csr_destroy(m);
                return asp_error_set(err, ASP_ENOMEM, "out of memory for a hypre row");
            }
        }
        size_t q = 0;
        for (HYPRE_Int k = di[r]; k < di[r + 1]; k++) {
            row[q].c = first_col + dj[k];
            row[q++].v = dv[k];
        }
        for (HYPRE_Int k = has_offd ? oi[r] : 0; has_offd && k < oi[r + 1]; k++) {
            row[q].c = cmap[oj[k]];
            row[q++].v = ov[k];
        }
        qsort(row, q, sizeof *row, cmp_entry);
        for (size_t k = 0; k < q; k++) {
            m->col[w] = (asp_index)row[k].c;
            m->val[w++] = row[k].v;
        }
        m->row_ptr[r + 1] = w;
    }
    asp_free(&d->ctx, row);
    *out = m;
    return 0;
}

static int from_parcsr(const asp__dist *d, hypre_ParCSRMatrix *p, size_t cols, asp_amg_csr **out, asp_error *err)
{
    return from_parcsr_rows(d, p, cols, NULL, out, err);
}

/* take (may be NULL) owns a: destroyed once hypre has its copy; a_rows (with take) as asp__dist_coarsen_take */
static int coarsen(const asp__dist *d, const asp_amg_csr *a, asp_amg_csr **take, const size_t *starts,
                   const asp_amg_desc *desc, asp_amg_csr **p_out, asp_amg_csr **ac_out, size_t *cstarts,
                   asp_amg_csr **a_rows, asp_error *err)
{
    if (starts[d->size] > (size_t)INT_MAX - 1)
        return asp_error_set(err, ASP_EUNSUPPORTED, "matrix of %zu rows is too large for this hypre build",
                             starts[d->size]);
    HYPRE_IJMatrix ij = NULL;
    HYPRE_IJVector bij = NULL, xij = NULL;
    HYPRE_Solver amg = NULL;
    asp_amg_csr *p = NULL, *ac = NULL;
    int rc = to_ij(d, a, starts, starts, &ij, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    HYPRE_ParCSRMatrix pa;
    HYPRE_IJMatrixGetObject(ij, (void **)&pa);
    const size_t nrows = a->rows;
    if (take) {
        asp_amg_csr_destroy(*take);
        *take = NULL;
        a = NULL;
    }
    const HYPRE_BigInt lo = (HYPRE_BigInt)starts[d->rank], hi = (HYPRE_BigInt)starts[d->rank + 1] - 1;
    HYPRE_IJVectorCreate(d->comm, lo, hi, &bij);
    HYPRE_IJVectorSetObjectType(bij, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(bij);
    HYPRE_IJVectorAssemble(bij);
    HYPRE_IJVectorCreate(d->comm, lo, hi, &xij);
    HYPRE_IJVectorSetObjectType(xij, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(xij);
    HYPRE_IJVectorAssemble(xij);
    HYPRE_ParVector pb, px;
    HYPRE_IJVectorGetObject(bij, (void **)&pb);
    HYPRE_IJVectorGetObject(xij, (void **)&px);

    /* the serial path's options (hypre_bridge.c): one level per call, the caller filters between levels */
    amg = asp__amg_hypre_create_level_solver(desc);
    HYPRE_BoomerAMGSetup(amg, pa, pb, px);
    HYPRE_ClearAllErrors();

    hypre_ParAMGData *data = (hypre_ParAMGData *)amg;
    int coarsened = hypre_ParAMGDataNumLevels(data) >= 2;
    if (coarsened) {
        hypre_ParCSRMatrix *hp = hypre_ParAMGDataPArray(data)[0], *hac = hypre_ParAMGDataAArray(data)[1];
        size_t nc_local = (size_t)hypre_CSRMatrixNumCols(hypre_ParCSRMatrixDiag(hp));
        if (asp__dist_partition(d, nc_local, cstarts))
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the coarse partition");
        if (!rc)
            rc = from_parcsr(d, hp, cstarts[d->size], &p, err);
        if (!rc)
            rc = from_parcsr(d, hac, cstarts[d->size], &ac, err);
        if (!rc && (p->rows != nrows || ac->rows != nc_local ||
                    (size_t)hypre_ParCSRMatrixFirstColDiag(hp) != cstarts[d->rank]))
            rc = asp_error_set(err, ASP_ESOLVER, "hypre returned inconsistent coarse sizes on rank %d", d->rank);
        if (!rc && a_rows) {
            /* the rows of A where P is empty, from hypre's copy of A (ours is gone) */
            uint8_t *keep = asp_alloc(&d->ctx, nrows + 1);
            if (!keep)
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the AMG hierarchy");
            for (size_t r = 0; keep && r < nrows; r++)
                keep[r] = p->row_ptr[r + 1] == p->row_ptr[r];
            if (!rc)
                rc = from_parcsr_rows(d, (hypre_ParCSRMatrix *)pa, starts[d->size], keep, a_rows, err);
            asp_free(&d->ctx, keep);
        }
    }
    HYPRE_BoomerAMGDestroy(amg);
    HYPRE_IJMatrixDestroy(ij);
    HYPRE_IJVectorDestroy(bij);
    HYPRE_IJVectorDestroy(xij);
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_amg_csr_destroy(p);
        asp_amg_csr_destroy(ac);
        if (a_rows) {
            asp_amg_csr_destroy(*a_rows);
            *a_rows = NULL;
        }
        return rc;
    }
    *p_out = p;
    *ac_out = ac;
    return 0;
}

int asp__dist_coarsen(const asp__dist *d, const asp_amg_csr *a, const size_t *starts, const asp_amg_desc *desc,
                      asp_amg_csr **p_out, asp_amg_csr **ac_out, size_t *cstarts, asp_error *err)
{
    return coarsen(d, a, NULL, starts, desc, p_out, ac_out, cstarts, NULL, err);
}

int asp__dist_coarsen_take(const asp__dist *d, asp_amg_csr **a, const size_t *starts, const asp_amg_desc *desc,
                           asp_amg_csr **p_out, asp_amg_csr **ac_out, size_t *cstarts, asp_amg_csr **a_rows,
                           asp_error *err)
{
    *a_rows = NULL;
    return coarsen(d, *a, a, starts, desc, p_out, ac_out, cstarts, a_rows, err);
}

int asp__dist_galerkin(const asp__dist *d, const asp_amg_csr *p, const size_t *starts, const size_t *cstarts,
                       const asp_amg_csr *f, asp_amg_csr **out, asp_error *err)
{
    HYPRE_IJMatrix pij = NULL, fij = NULL;
    int rc = to_ij(d, p, starts, cstarts, &pij, err);
    if (!rc)
        rc = to_ij(d, f, starts, starts, &fij, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        if (pij)
            HYPRE_IJMatrixDestroy(pij);
        if (fij)
            HYPRE_IJMatrixDestroy(fij);
        return rc;
    }
    HYPRE_ParCSRMatrix hp, hf;
    HYPRE_IJMatrixGetObject(pij, (void **)&hp);
    HYPRE_IJMatrixGetObject(fij, (void **)&hf);
    /* RAP exchanges rows through the matrices' communication packages, which IJ assembly does not make */
    if (!hypre_ParCSRMatrixCommPkg((hypre_ParCSRMatrix *)hp))
        hypre_MatvecCommPkgCreate((hypre_ParCSRMatrix *)hp);
    if (!hypre_ParCSRMatrixCommPkg((hypre_ParCSRMatrix *)hf))
        hypre_MatvecCommPkgCreate((hypre_ParCSRMatrix *)hf);
    /* hypre's R^T A P with R = P: the coarse matrix of the same fans with C = 1 (hierarchy.c's crease test) */
    hypre_ParCSRMatrix *fc = hypre_ParCSRMatrixRAP((hypre_ParCSRMatrix *)hp, (hypre_ParCSRMatrix *)hf,
                                                   (hypre_ParCSRMatrix *)hp);
    rc = fc ? from_parcsr(d, fc, cstarts[d->size], out, err)
            : asp_error_set(err, ASP_ESOLVER, "hypre could not form the coarse crease-test matrix");
    if (fc)
        hypre_ParCSRMatrixDestroy(fc);
    HYPRE_IJMatrixDestroy(pij);
    HYPRE_IJMatrixDestroy(fij);
    return asp__dist_agree(d, rc, err);
}
#else
typedef int asp__dist_hypre_unused;
#endif
