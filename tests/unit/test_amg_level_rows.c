/*
 * The row kernels of a coarse level (src/amg/level_rows.c, issue 26) and the
 * one CSR entry lookup (csr.c): the serial hierarchy runs them on all rows of
 * a level with row0 = 0, each MPI rank on its own rows with row0 its first
 * global row and the columns' choices fetched into best_col. The same matrix
 * filtered whole and in two such pieces must give the same rows.
 */
#include <stdint.h>

#include "amg/internal.h"
#include "harness.h"

typedef struct entry {
    size_t row;
    asp_index col;
    double val;
} entry;

/* rows x cols from (row, col, val) in row order, columns increasing */
static asp_amg_csr *make(size_t rows, size_t cols, const entry *e, size_t n)
{
    asp_amg_csr *m = NULL;
    asp_error err = {0};
    CHECK_OK(asp_amg_csr_create(rows, cols, n, NULL, &m, &err), &err);
    if (!m)
        return NULL;
    size_t k = 0;
    m->row_ptr[0] = 0;
    for (size_t r = 0; r < rows; r++) {
        for (; k < n && e[k].row == r; k++) {
            m->col[k] = e[k].col;
            m->val[k] = e[k].val;
        }
        m->row_ptr[r + 1] = k;
    }
    return m;
}

/*
 * A coarse level of 5 unknowns: 4 rows from hypre (zero row sums, one positive
 * coupling) and unknown 4, an orphan, with no row yet.
 */
static const entry level[] = {
    {0, 0, 3.0},  {0, 1, -2.0}, {0, 2, -1.0},                  /* */
    {1, 0, -2.0}, {1, 1, 2.5},  {1, 3, -0.5},                  /* */
    {2, 0, -1.0}, {2, 2, 0.8},  {2, 3, 0.2},                   /* a positive Galerkin entry */
    {3, 1, -0.5}, {3, 2, 0.2},  {3, 3, 0.3},                   /* */
};
enum { NLEVEL = sizeof level / sizeof level[0] };

static void test_find(void)
{
    asp_amg_csr *a = make(5, 5, level, NLEVEL);
    if (!a)
        return;
    CHECK(asp__amg_csr_find(a, 0, 0) == 0);
    CHECK(asp__amg_csr_find(a, 0, 2) == 2);
    CHECK(asp__amg_csr_find(a, 3, 3) == 11);
    CHECK(asp__amg_csr_find(a, 2, 1) == SIZE_MAX); /* between two columns */
    CHECK(asp__amg_csr_find(a, 1, 4) == SIZE_MAX); /* past the last */
    CHECK(asp__amg_csr_find(a, 4, 0) == SIZE_MAX); /* an empty row */
    CHECK(asp__amg_csr_entry(a, 1, 3) == -0.5);
    CHECK(asp__amg_csr_entry(a, 3, 0) == 0.0);
    asp_amg_csr_destroy(a);
}

static void test_strongest_and_crease(void)
{
    asp_amg_csr *a = make(5, 5, level, NLEVEL);
    if (!a)
        return;
    CHECK(asp__amg_strongest(a, 0, 0) == 1);
    CHECK(asp__amg_strongest(a, 2, 0) == 0);          /* the positive entry is no coupling */
    CHECK(asp__amg_strongest(a, 4, 0) == UINT32_MAX); /* no row */
    /* local row 0 of a rank whose first row is 1: column 1 is its diagonal, so not its coupling */
    CHECK(asp__amg_strongest(a, 0, 1) == 2);
    asp_amg_csr_destroy(a);
    /* interface mean 0.1 against interiors 0.9 and 0.8 at ratio 0.5: cut; 0.5 is not below 0.4 */
    CHECK(asp__amg_crease(-0.1, -1.0, 0.5, 0.9, 0.8) == 1);
    CHECK(asp__amg_crease(-0.5, -1.0, 0.5, 0.9, 0.8) == 0);
    CHECK(asp__amg_crease(-0.1, 0.0, 0.5, 0.9, 0.8) == 0); /* nothing to compare with */
    uint64_t hist[256] = {0};
    asp_amg_csr *b = make(5, 5, level, NLEVEL);
    if (b) {
        asp__amg_coupling_hist(b, 0, hist);
        /* off-diagonal magnitudes 0.2 0.2 0.5 0.5 1 1 2 2: the 4th, 0.5, is in the bin [0.5, 1) */
        CHECK(asp__amg_hist_median(hist) == 0.75);
        asp_amg_csr_destroy(b);
    }
    uint64_t none[256] = {0};
    CHECK(asp__amg_hist_median(none) == 0);
}

/* m's rows equal the expected (row, col, val) list exactly */
static int rows_are(const asp_amg_csr *m, const entry *e, size_t n)
{
    if (m->row_ptr[m->rows] != n)
        return 0;
    for (size_t r = 0, k = 0; r < m->rows; r++)
        for (; k < m->row_ptr[r + 1]; k++)
            if (e[k].row != r || m->col[k] != e[k].col || m->val[k] != e[k].val)
                return 0;
    return 1;
}

static void test_filter_whole(void)
{
    asp_amg_csr *a = make(4, 4, level, NLEVEL), *m = NULL;
    asp_error err = {0};
    if (!a)
        return;
    /* unknown 3 is small: it keeps its strongest coupling (to 1), in both rows, though weaker than the cut */
    const asp_index best[4] = {UINT32_MAX, UINT32_MAX, UINT32_MAX, 1};
    const asp__amg_filter keep = {.cut = 1.5, .best = best};
    CHECK(asp__amg_filter_count(a, &keep) == 4);
    CHECK_OK(asp_amg_csr_create(5, 5, asp__amg_filter_count(a, &keep) + 5, NULL, &m, &err), &err);
    if (m) {
        CHECK(asp__amg_filter_rows(a, &keep, m) == 4);
        /* (0,2) and (2,0) are weaker than the cut; the positive entries go; row 4 is the orphan's */
        static const entry want[] = {{0, 0, 2.0},  {0, 1, -2.0}, {1, 0, -2.0}, {1, 1, 2.5}, {1, 3, -0.5},
                                     {2, 2, 0.0},  {3, 1, -0.5}, {3, 3, 0.5},  {4, 4, 0.0}};
        CHECK(rows_are(m, want, sizeof want / sizeof want[0]));
    }
    asp_amg_csr_destroy(m);
    m = NULL;
    /* the crease test cut (0,1) and (1,0): row 0 keeps its diagonal alone */
    uint8_t crease[NLEVEL] = {0};
    crease[1] = crease[3] = 1;
    const asp__amg_filter cut = {.cut = 1.5, .best = best, .crease = crease};
    CHECK_OK(asp_amg_csr_create(4, 4, asp__amg_filter_count(a, &cut) + 4, NULL, &m, &err), &err);
    if (m) {
        CHECK(asp__amg_filter_rows(a, &cut, m) == 2);
        static const entry want[] = {{0, 0, 0.0},  {1, 1, 0.5}, {1, 3, -0.5},
                                     {2, 2, 0.0},  {3, 1, -0.5}, {3, 3, 0.5}};
        CHECK(rows_are(m, want, sizeof want / sizeof want[0]));
    }
    asp_amg_csr_destroy(m);
    asp_amg_csr_destroy(a);
}

/* The level in two pieces, as on 2 ranks: rows 0..1 and rows 2..4 (the orphan's empty row last). */
static void test_filter_pieces(void)
{
    const asp_index best[5] = {UINT32_MAX, UINT32_MAX, UINT32_MAX, 1, UINT32_MAX};
    asp_amg_csr *whole = make(5, 5, level, NLEVEL), *m = NULL;
    asp_error err = {0};
    if (!whole)
        return;
    const asp__amg_filter keep = {.cut = 1.5, .best = best};
    CHECK_OK(asp_amg_csr_create(5, 5, asp__amg_filter_count(whole, &keep) + 5, NULL, &m, &err), &err);
    if (!m) {
        asp_amg_csr_destroy(whole);
        return;
    }
    const size_t offdiag = asp__amg_filter_rows(whole, &keep, m);
    const size_t first[3] = {0, 2, 5};
    size_t at = 0, pieces_offdiag = 0;
    for (int q = 0; q < 2; q++) {
        const size_t r0 = first[q], rows = first[q + 1] - r0, e0 = whole->row_ptr[r0];
        entry local[NLEVEL];
        asp_index bcol[NLEVEL];
        size_t n = 0;
        for (size_t k = e0; k < whole->row_ptr[first[q + 1]]; k++, n++) {
            size_t r = 0;
            while (whole->row_ptr[r + 1] <= k)
                r++;
            local[n] = (entry){r - r0, whole->col[k], whole->val[k]};
            bcol[n] = best[whole->col[k]]; /* what asp__dist_fetch brings from the column's owner */
        }
        asp_amg_csr *a = make(rows, 5, local, n), *mq = NULL;
        if (!a)
            break;
        const asp__amg_filter kq = {.cut = 1.5, .best = best + r0, .best_col = bcol, .row0 = r0};
        CHECK_OK(asp_amg_csr_create(rows, 5, asp__amg_filter_count(a, &kq) + rows, NULL, &mq, &err), &err);
        if (mq) {
            pieces_offdiag += asp__amg_filter_rows(a, &kq, mq);
            for (size_t r = 0; r < rows; r++) {
                const size_t len = mq->row_ptr[r + 1] - mq->row_ptr[r];
                CHECK_MSG(len == m->row_ptr[r0 + r + 1] - m->row_ptr[r0 + r], "row %zu", r0 + r);
                for (size_t k = 0; k < len && at + k < m->row_ptr[5]; k++)
                    CHECK_MSG(mq->col[mq->row_ptr[r] + k] == m->col[at + k] &&
                                  mq->val[mq->row_ptr[r] + k] == m->val[at + k],
                              "row %zu entry %zu", r0 + r, k);
                at += len;
            }
        }
        asp_amg_csr_destroy(mq);
        asp_amg_csr_destroy(a);
    }
    CHECK(at == m->row_ptr[5]);
    CHECK(pieces_offdiag == offdiag);
    asp_amg_csr_destroy(m);
    asp_amg_csr_destroy(whole);
}

TEST_MAIN(TEST_CASE(test_find), TEST_CASE(test_strongest_and_crease), TEST_CASE(test_filter_whole),
          TEST_CASE(test_filter_pieces))
