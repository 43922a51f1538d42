/*
 * libFuzzer target for the .amg reader (asp_amg_load_memory): arbitrary bytes
 * must give a clean error or a decomposition whose invariants hold (journal
 * 2.3: decreasing level sizes, prolongations that are partitions of unity),
 * never a crash, leak or huge allocation (STYLE.md section 11).
 *   ./fuzz_amg -max_total_time=300 -rss_limit_mb=2048 corpus
 * Seed the corpus with small saved files (amgsplat decompose). Each input is
 * also tried with its payload size and CRC-32 trailer patched, so mutations
 * reach the parser behind the checksum.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "fuzz_support.h"

enum { PAYLOAD_AT = 32 }; /* header byte of the payload size */

static void check_csr(const asp_amg_csr *p, size_t rows, size_t cols, int partition)
{
    if (!p || p->rows != rows || p->cols != cols || p->row_ptr[0] != 0)
        abort();
    for (size_t q = 0; q < rows; q++) {
        if (p->row_ptr[q + 1] < p->row_ptr[q] + (partition ? 1 : 0))
            abort();
        double sum = 0;
        for (size_t k = p->row_ptr[q]; k < p->row_ptr[q + 1]; k++) {
            if (p->col[k] >= cols)
                abort();
            if (partition && ((k > p->row_ptr[q] && p->col[k] <= p->col[k - 1]) || !(p->val[k] >= 0 && p->val[k] <= 1)))
                abort();
            sum += p->val[k];
        }
        if (partition && fabs(sum - 1) > 1e-6)
            abort();
    }
}

static void check(const asp_amg *a)
{
    const asp_cloud *c = asp_amg_cloud(a);
    const size_t n = c->count, levels = asp_amg_level_count(a);
    if (n < 1 || levels < 1 || levels > 100 || asp_amg_level_size(a, 0) != n || !c->positions || !c->normals ||
        asp_amg_prolongation(a, 0) != NULL || asp_amg_matrix(a) != NULL)
        abort();
    const float *t = asp_amg_tangent_normals(a), *cls = asp_amg_classifier(a);
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++)
            if (!isfinite(c->positions[3 * i + k]) || !isfinite(t[3 * i + k]))
                abort();
        if (!isfinite(cls[i]))
            abort();
    }
    for (size_t l = 1; l < levels; l++) {
        size_t rows = asp_amg_level_size(a, l - 1), cols = asp_amg_level_size(a, l);
        if (cols < 1 || cols >= rows)
            abort();
        check_csr(asp_amg_prolongation(a, l), rows, cols, 1);
    }
    /* the loaded hierarchy must be usable: the coarsest basis is a chain of products over every P */
    if (n <= 2048) {
        asp_amg_csr *psi = NULL;
        asp_error err = {0};
        if (asp_amg_basis(a, levels - 1, NULL, &psi, &err) == 0) {
            check_csr(psi, n, asp_amg_level_size(a, levels - 1), 0);
            asp_amg_csr_destroy(psi);
        } else if (err.msg[0] == '\0') {
            abort();
        }
    }
}

static void one(const uint8_t *data, size_t size)
{
    fuzz_budget b;
    asp_context ctx = fuzz_budget_context(&b, size, "fuzz_amg");
    asp_amg *a = NULL;
    asp_error err = {0};
    int rc = asp_amg_load_memory(data, size, "fuzz.amg", &ctx, &a, &err);
    if (rc == 0) {
        if (!a)
            abort();
        /* the recorded (or, version 2, computed) frame is finite with radius >= 0 */
        const asp_frame *f = asp_amg_frame(a);
        if (!(isfinite(f->center[0]) && isfinite(f->center[1]) && isfinite(f->center[2]) && isfinite(f->radius) &&
              f->radius >= 0))
            abort();
        check(a);
        asp_amg_destroy(a);
        return;
    }
    /* a failure leaves the output alone and explains itself, naming the file */
    if (a || err.msg[0] == '\0' || !strstr(err.msg, "fuzz.amg") || rc != err.code)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_with_fixed_trailer(data, size, PAYLOAD_AT, one);
    return 0;
}
