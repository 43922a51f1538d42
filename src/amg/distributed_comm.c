/*
 * The few collective patterns of the distributed decomposition (issue 19):
 * agreeing on an error, partitions of global ids, fetching items or matrix
 * rows by global id from their owners and adding values into the owners'
 * arrays. Each is two all-to-all exchanges: requests, then answers.
 */
#ifdef ASP_HAVE_HYPRE
#include <stdlib.h>
#include <string.h>

#include "amg/distributed.h"
#include "util/banned.h"

int asp__dist_agree(const asp__dist *d, int rc, asp_error *err)
{
    int mine = rc ? d->rank : d->size, first = d->size;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, d->comm);
    if (first == d->size)
        return 0;
    struct {
        int code;
        char msg[sizeof err->msg];
    } m = {rc, ""};
    if (d->rank == first && err)
        memcpy(m.msg, err->msg, sizeof m.msg);
    MPI_Bcast(&m, (int)sizeof m, MPI_BYTE, first, d->comm);
    if (d->rank != first && err) {
        err->code = m.code;
        memcpy(err->msg, m.msg, sizeof m.msg);
    }
    return m.code;
}

int asp__dist_owner(const size_t *starts, int size, size_t g)
{
    int lo = 0, hi = size - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (starts[mid] <= g)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

unsigned long long asp__dist_sum(const asp__dist *d, unsigned long long v)
{
    unsigned long long s = 0;
    MPI_Allreduce(&v, &s, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
    return s;
}

int asp__dist_partition(const asp__dist *d, size_t local, size_t *starts)
{
    unsigned long long mine = local, *all = asp_alloc(&d->ctx, (size_t)d->size * sizeof *all);
    if (!all)
        return ASP_ENOMEM;
    MPI_Allgather(&mine, 1, MPI_UNSIGNED_LONG_LONG, all, 1, MPI_UNSIGNED_LONG_LONG, d->comm);
    starts[0] = 0;
    for (int q = 0; q < d->size; q++)
        starts[q + 1] = starts[q] + (size_t)all[q];
    asp_free(&d->ctx, all);
    return 0;
}

/* Requests grouped by owner: counts, displacements, the ids in owner order and each request's slot. */
typedef struct requests {
    int *scnt, *sdis, *rcnt, *rdis;
    size_t sent, received;
    asp_index *send, *recv; /* send: ids in owner order; recv: the ids asked of this rank */
    size_t *slot;           /* slot[i]: where request i sits in send */
} requests;

static void requests_free(const asp__dist *d, requests *r)
{
    asp_free(&d->ctx, r->scnt);
    asp_free(&d->ctx, r->send);
    asp_free(&d->ctx, r->recv);
    asp_free(&d->ctx, r->slot);
}

static int requests_make(const asp__dist *d, const size_t *starts, const asp_index *gids, size_t m, requests *r)
{
    const int P = d->size;
    memset(r, 0, sizeof *r);
    r->scnt = asp_calloc(&d->ctx, 4 * (size_t)P, sizeof *r->scnt);
    r->send = asp_alloc(&d->ctx, (m + 1) * sizeof *r->send);
    r->slot = asp_alloc(&d->ctx, (m + 1) * sizeof *r->slot);
    if (!r->scnt || !r->send || !r->slot) {
        requests_free(d, r);
        return ASP_ENOMEM;
    }
    r->sdis = r->scnt + P;
    r->rcnt = r->scnt + 2 * P;
    r->rdis = r->scnt + 3 * P;
    for (size_t i = 0; i < m; i++)
        r->scnt[asp__dist_owner(starts, P, gids[i])]++;
    for (int q = 1; q < P; q++)
        r->sdis[q] = r->sdis[q - 1] + r->scnt[q - 1];
    int *fill = asp_calloc(&d->ctx, (size_t)P, sizeof *fill);
    if (!fill) {
        requests_free(d, r);
        return ASP_ENOMEM;
    }
    for (size_t i = 0; i < m; i++) {
        int o = asp__dist_owner(starts, P, gids[i]);
        size_t s = (size_t)r->sdis[o] + (size_t)fill[o]++;
        r->send[s] = gids[i];
        r->slot[i] = s;
    }
    asp_free(&d->ctx, fill);
    r->sent = m;
    MPI_Alltoall(r->scnt, 1, MPI_INT, r->rcnt, 1, MPI_INT, d->comm);
    for (int q = 0; q < P; q++) {
        if (q)
            r->rdis[q] = r->rdis[q - 1] + r->rcnt[q - 1];
        r->received += (size_t)r->rcnt[q];
    }
    r->recv = asp_alloc(&d->ctx, (r->received + 1) * sizeof *r->recv);
    int ok = r->recv != NULL, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (!all) {
        requests_free(d, r);
        return ASP_ENOMEM;
    }
    MPI_Alltoallv(r->send, r->scnt, r->sdis, MPI_UINT32_T, r->recv, r->rcnt, r->rdis, MPI_UINT32_T, d->comm);
    return 0;
}

int asp__dist_fetch(const asp__dist *d, const size_t *starts, const void *local, size_t elem, const asp_index *gids,
                    size_t m, void *out, asp_error *err)
{
    requests r;
    if (requests_make(d, starts, gids, m, &r))
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu requests to other ranks", m);
    const size_t mine = starts[d->rank];
    char *answer = asp_alloc(&d->ctx, r.received * elem + 1), *back = asp_alloc(&d->ctx, m * elem + 1);
    int ok = answer && back, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (!all) {
        asp_free(&d->ctx, answer);
        asp_free(&d->ctx, back);
        requests_free(d, &r);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu answers to other ranks", r.received);
    }
    for (size_t i = 0; i < r.received; i++)
        memcpy(answer + i * elem, (const char *)local + (r.recv[i] - mine) * elem, elem);
    MPI_Datatype item;
    MPI_Type_contiguous((int)elem, MPI_BYTE, &item);
    MPI_Type_commit(&item);
    MPI_Alltoallv(answer, r.rcnt, r.rdis, item, back, r.scnt, r.sdis, item, d->comm);
    MPI_Type_free(&item);
    for (size_t i = 0; i < m; i++)
        memcpy((char *)out + i * elem, back + r.slot[i] * elem, elem);
    asp_free(&d->ctx, answer);
    asp_free(&d->ctx, back);
    requests_free(d, &r);
    return 0;
}

int asp__dist_scatter_add(const asp__dist *d, const size_t *starts, const asp_index *gids, const double *vals,
                          size_t m, double *local, asp_error *err)
{
    requests r;
    if (requests_make(d, starts, gids, m, &r))
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu sums on other ranks", m);
    double *sv = asp_alloc(&d->ctx, (m + 1) * sizeof *sv), *rv = asp_alloc(&d->ctx, (r.received + 1) * sizeof *rv);
    int ok = sv && rv, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (!all) {
        asp_free(&d->ctx, sv);
        asp_free(&d->ctx, rv);
        requests_free(d, &r);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu sums on other ranks", m);
    }
    for (size_t i = 0; i < m; i++)
        sv[r.slot[i]] = vals[i];
    MPI_Alltoallv(sv, r.scnt, r.sdis, MPI_DOUBLE, rv, r.rcnt, r.rdis, MPI_DOUBLE, d->comm);
    /* in rank order, then request order: the same sum for any thread count (STYLE 7) */
    const size_t mine = starts[d->rank];
    for (size_t i = 0; i < r.received; i++)
        local[r.recv[i] - mine] += rv[i];
    asp_free(&d->ctx, sv);
    asp_free(&d->ctx, rv);
    requests_free(d, &r);
    return 0;
}

int asp__dist_fetch_rows(const asp__dist *d, const size_t *starts, const asp_amg_csr *rows, const asp_index *gids,
                         size_t m, asp_amg_csr **out, asp_error *err)
{
    const int P = d->size;
    requests r;
    if (requests_make(d, starts, gids, m, &r))
        return asp_error_set(err, ASP_ENOMEM, "out of memory for %zu row requests", m);
    const size_t mine = starts[d->rank];
    uint64_t *len = asp_alloc(&d->ctx, (r.received + 1) * sizeof *len), *back = asp_alloc(&d->ctx, (m + 1) * sizeof *back);
    int *ecnt = asp_calloc(&d->ctx, 4 * (size_t)P, sizeof *ecnt);
    size_t etotal = 0;
    for (size_t i = 0; len && i < r.received; i++) {
        size_t row = r.recv[i] - mine;
        len[i] = rows->row_ptr[row + 1] - rows->row_ptr[row];
        etotal += len[i];
    }
    asp_index *ecol = asp_alloc(&d->ctx, (etotal + 1) * sizeof *ecol);
    double *evel = asp_alloc(&d->ctx, (etotal + 1) * sizeof *evel);
    int ok = len && back && ecnt && ecol && evel, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    asp_amg_csr *res = NULL;
    asp_index *rcol = NULL;
    double *rval = NULL;
    int rc = 0;
    if (!all) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu rows asked by other ranks", r.received);
        goto done;
    }
    MPI_Alltoallv(len, r.rcnt, r.rdis, MPI_UINT64_T, back, r.scnt, r.sdis, MPI_UINT64_T, d->comm);
    /* entries, grouped by the asking rank in the order asked */
    int *esd = ecnt + P, *rcv = ecnt + 2 * P, *rdv = ecnt + 3 * P;
    size_t w = 0;
    for (int q = 0; q < P; q++) {
        esd[q] = (int)w;
        for (int i = r.rdis[q]; i < r.rdis[q] + r.rcnt[q]; i++) {
            size_t row = r.recv[i] - mine;
            for (size_t k = rows->row_ptr[row]; k < rows->row_ptr[row + 1]; k++) {
                ecol[w] = rows->col[k];
                evel[w++] = rows->val[k];
            }
        }
        ecnt[q] = (int)(w - (size_t)esd[q]);
    }
    MPI_Alltoall(ecnt, 1, MPI_INT, rcv, 1, MPI_INT, d->comm);
    size_t rtotal = 0;
    for (int q = 0; q < P; q++) {
        rdv[q] = (int)rtotal;
        rtotal += (size_t)rcv[q];
    }
    rcol = asp_alloc(&d->ctx, (rtotal + 1) * sizeof *rcol);
    rval = asp_alloc(&d->ctx, (rtotal + 1) * sizeof *rval);
    size_t *at = asp_alloc(&d->ctx, (m + 1) * sizeof *at); // start of each answer (in send order) in rcol
    size_t nnz = 0;
    for (size_t i = 0; i < m; i++)
        nnz += back[i];
    ok = rcol && rval && at;
    if (ok)
        ok = asp_amg_csr_create(m, rows->cols, nnz, &d->ctx, &res, err) == 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
    if (!all) {
        asp_free(&d->ctx, at);
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for %zu fetched rows", m);
        goto done;
    }
    MPI_Alltoallv(ecol, ecnt, esd, MPI_UINT32_T, rcol, rcv, rdv, MPI_UINT32_T, d->comm);
    MPI_Alltoallv(evel, ecnt, esd, MPI_DOUBLE, rval, rcv, rdv, MPI_DOUBLE, d->comm);
    /* answers arrive per owner in send order, so their starts are a running sum in send order */
    for (size_t s = 0, acc = 0; s < m; s++) {
        at[s] = acc;
        acc += back[s];
    }
    for (size_t i = 0; i < m; i++) {
        size_t s = r.slot[i], k0 = at[s], cnt = back[s];
        res->row_ptr[i + 1] = res->row_ptr[i] + cnt;
        memcpy(res->col + res->row_ptr[i], rcol + k0, cnt * sizeof *rcol);
        memcpy(res->val + res->row_ptr[i], rval + k0, cnt * sizeof *rval);
    }
    asp_free(&d->ctx, at);
    *out = res;
    res = NULL;
done:
    asp_amg_csr_destroy(res);
    asp_free(&d->ctx, len);
    asp_free(&d->ctx, back);
    asp_free(&d->ctx, ecnt);
    asp_free(&d->ctx, ecol);
    asp_free(&d->ctx, evel);
    asp_free(&d->ctx, rcol);
    asp_free(&d->ctx, rval);
    requests_free(d, &r);
    return rc;
}
#endif
