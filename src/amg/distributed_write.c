/*
 * The .amg file of a distributed decomposition (amg_format.h's layout and
 * header writer): rank 0 writes the header and streams every rank's part of each
 * array in rank order, in chunks of at most 4 MB, through the CRC writer
 * and the atomic temporary file. No rank holds more than its own part and
 * one chunk; the points are in the Morton order of the ranks. NEEDSWORK: at
 * 10^9 points this one writer is the longest step (BENCHMARKS.md); each rank
 * could write its part at computed offsets (MPI-IO) with CRCs combined.
 */
#ifdef ASP_HAVE_HYPRE
#include <stdint.h>
#include <string.h>

#include "amg/amg_format.h"
#include "amg/distributed.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

enum { CHUNK = 4 << 20, TAG = 7719 };

typedef struct stream {
    const asp__dist *d;
    asp__crc_writer *w; /* rank 0 */
    uint8_t *buf;       /* rank 0: CHUNK bytes */
} stream;

/* Every rank's bytes, rank 0's first: one collective step of the stream. */
static void put_all(stream *s, const void *data, size_t bytes)
{
    const asp__dist *d = s->d;
    if (d->rank == 0) {
        asp__crc_put(s->w, data, bytes);
        for (int q = 1; q < d->size; q++) {
            unsigned long long total;
            MPI_Recv(&total, 1, MPI_UNSIGNED_LONG_LONG, q, TAG, d->comm, MPI_STATUS_IGNORE);
            for (unsigned long long done = 0; done < total;) {
                int take = (int)(total - done < CHUNK ? total - done : CHUNK);
                MPI_Recv(s->buf, take, MPI_BYTE, q, TAG, d->comm, MPI_STATUS_IGNORE);
                asp__crc_put(s->w, s->buf, (size_t)take);
                done += (unsigned long long)take;
            }
        }
    } else {
        unsigned long long total = bytes;
        MPI_Send(&total, 1, MPI_UNSIGNED_LONG_LONG, 0, TAG, d->comm);
        for (size_t done = 0; done < bytes;) {
            int take = (int)(bytes - done < CHUNK ? bytes - done : CHUNK);
            MPI_Send((const uint8_t *)data + done, take, MPI_BYTE, 0, TAG, d->comm);
            done += (size_t)take;
        }
    }
}

int asp__dist_write_amg(const asp__dist *d, const asp__dist_result *res, const char *path, asp_error *err)
{
    const asp__dist_points *pts = res->pts;
    const size_t n = pts->n_own;
    asp__atomic_file f;
    asp__crc_writer w = {NULL, 0, 0};
    stream s = {d, &w, NULL};
    int rc = 0;
    if (!asp__amg_host_little_endian())
        rc = asp_error_set(err, ASP_EUNSUPPORTED, "cannot write '%s': .amg files are little-endian only", path);
    if (!rc && d->rank == 0) {
        rc = asp__atomic_open(&f, path, err);
        if (!rc) {
            w.fp = f.fp;
            s.buf = asp_alloc(&d->ctx, CHUNK);
            if (!s.buf) {
                asp__atomic_abort(&f);
                rc = asp_error_set(err, ASP_ENOMEM, "out of memory writing '%s'", path);
            }
        }
    }
    if ((rc = asp__dist_agree(d, rc, err)) != 0) {
        asp_free(&d->ctx, s.buf);
        return rc;
    }
    /* the input's attributes as amg_file.c stores them: the normals only when the input had them */
    const void *const arrays[ASP__AMG_NATTRS] = {pts->normals, pts->colors, pts->radii, pts->uvs, pts->labels};
    asp__amg_header h = {.points = pts->n_global, .nlevels = res->nlevels, .level_size = res->level_size};
    for (int i = 0; i < ASP__AMG_NATTRS; i++)
        h.attrs |= arrays[i] ? asp__amg_attr_bit[i] : 0u;
    unsigned long long nnz[ASP_AMG_DIST_MAX_LEVELS] = {0}, before[ASP_AMG_DIST_MAX_LEVELS] = {0};
    for (size_t l = 1; l < res->nlevels; l++) {
        unsigned long long mine = res->prolong[l]->row_ptr[res->prolong[l]->rows];
        MPI_Allreduce(&mine, &nnz[l], 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        MPI_Exscan(&mine, &before[l], 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (d->rank == 0)
            before[l] = 0;
        h.prolong_nnz += nnz[l];
    }
    memcpy(h.origin, pts->origin, sizeof h.origin);
    h.frame = res->frame;
    if (d->rank == 0)
        asp__amg_put_header(&w, &h);
    put_all(&s, pts->pos, 3 * n * sizeof(float));
    put_all(&s, res->tangent, 3 * n * sizeof(float));
    put_all(&s, res->classifier, n * sizeof(float));
    if (d->rank == 0)
        asp__amg_put_attr_set(&w, h.attrs, h.frame.up);
    for (int i = 0; i < ASP__AMG_NATTRS; i++)
        if (h.attrs & asp__amg_attr_bit[i])
            put_all(&s, arrays[i], asp__amg_attr_size[i] * n);
    if (d->rank == 0)
        asp__amg_put_options(&w, res->desc, res->level_size, res->nlevels);
    for (size_t l = 1; l < res->nlevels; l++) {
        const asp_amg_csr *p = res->prolong[l];
        /* the row pointers shifted by the entries of the ranks before; rank 0 adds the leading 0 */
        uint64_t *ptr = asp_alloc(&d->ctx, (p->rows + 1) * sizeof *ptr);
        int ok = ptr != NULL, all = 0;
        MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, d->comm);
        if (!all) {
            asp_free(&d->ctx, ptr);
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory writing '%s'", path);
            break;
        }
        for (size_t r = 0; r < p->rows; r++)
            ptr[r] = before[l] + p->row_ptr[r + 1];
        if (d->rank == 0) {
            asp__put_u64(&w, nnz[l]);
            asp__put_u64(&w, 0);
        }
        put_all(&s, ptr, p->rows * sizeof *ptr);
        asp_free(&d->ctx, ptr);
        put_all(&s, p->col, p->row_ptr[p->rows] * sizeof *p->col);
        put_all(&s, p->val, p->row_ptr[p->rows] * sizeof *p->val);
    }
    if (d->rank == 0) {
        if (rc)
            asp__atomic_abort(&f);
        else
            /*
             * No read-back check (amg_file.c reads the whole file back): that would put the whole
             * decomposition on rank 0; the ctest and the benchmark load the file in one process.
             */
            rc = asp__byte_commit(&w, &f, path, NULL, NULL, err);
        asp_free(&d->ctx, s.buf);
    }
    return asp__dist_agree(d, rc, err);
}
#else
typedef int asp__dist_write_unused;
#endif
