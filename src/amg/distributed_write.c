/*
 * The .amg file of a distributed decomposition (version 3, amg_file.c's
 * layout): rank 0 writes the header and streams every rank's part of each
 * array in rank order, in chunks of at most 4 MB, through the CRC writer
 * and the atomic temporary file. No rank holds more than its own part and
 * one chunk; the points are in the Morton order of the ranks. NEEDSWORK: at
 * 10^9 points this one writer is the longest step (BENCHMARKS.md); each rank
 * could write its part at computed offsets (MPI-IO) with CRCs combined.
 */
#ifdef ASP_HAVE_HYPRE
#include <stdint.h>
#include <string.h>

#include "amg/distributed.h"
#include "util/atomic_file.h"
#include "util/byte_io.h"
#include "util/checksum.h"
#include "util/banned.h"

enum { AMG_VERSION = 3, AMG_HEADER = 96, CHUNK = 4 << 20, TAG = 7719 };

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

static unsigned long long sum_all(const asp__dist *d, unsigned long long v)
{
    unsigned long long s = 0;
    MPI_Allreduce(&v, &s, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
    return s;
}

static void put_options(asp__crc_writer *w, const asp_amg_desc *o)
{
    asp__put_f64(w, o->epsilon);
    asp__put_u64(w, o->k_min);
    asp__put_u64(w, o->k_max);
    asp__put_u64(w, o->fan_k);
    asp__put_u32(w, (uint32_t)o->classifier);
    asp__put_u32(w, (uint32_t)o->coarsen);
    asp__put_u32(w, (uint32_t)o->interp);
    asp__put_u32(w, 0);
    asp__put_f64(w, o->alpha);
    asp__put_f64(w, o->beta);
    asp__put_f64(w, o->strong_threshold);
    asp__put_f64(w, o->trunc_factor);
    asp__put_f64(w, o->drop_tol);
    asp__put_u64(w, o->max_levels);
    asp__put_u64(w, o->max_coarse);
    asp__put_f64(w, o->weak_coupling);
    asp__put_f64(w, o->crease_cut);
    asp__put_u64(w, 0);
}

int asp__dist_write_amg(const asp__dist *d, const asp__dist_result *res, const char *path, asp_error *err)
{
    const asp__dist_points *pts = res->pts;
    const size_t n = pts->n_own;
    asp__atomic_file f;
    asp__crc_writer w = {NULL, 0, 0};
    stream s = {d, &w, NULL};
    int rc = 0;
    const uint16_t one = 1;
    if (*(const uint8_t *)&one != 1)
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
    const unsigned attrs = (pts->normals ? ASP_ATTR_NORMALS : 0u) | (pts->colors ? ASP_ATTR_COLORS : 0u) |
                           (pts->radii ? ASP_ATTR_RADII : 0u) | (pts->labels ? ASP_ATTR_LABELS : 0u);
    const uint64_t per_point = (attrs & ASP_ATTR_NORMALS ? 12u : 0u) + (attrs & ASP_ATTR_COLORS ? 4u : 0u) +
                               (attrs & ASP_ATTR_RADII ? 4u : 0u) + (attrs & ASP_ATTR_LABELS ? 4u : 0u);
    unsigned long long nnz[ASP_AMG_DIST_MAX_LEVELS] = {0}, before[ASP_AMG_DIST_MAX_LEVELS] = {0};
    const uint64_t N = pts->n_global;
    uint64_t payload = 7 * 4 * N + 8 + per_point * N + 128 + 8 * (uint64_t)res->nlevels;
    for (size_t l = 1; l < res->nlevels; l++) {
        unsigned long long mine = res->prolong[l]->row_ptr[res->prolong[l]->rows];
        nnz[l] = sum_all(d, mine);
        MPI_Exscan(&mine, &before[l], 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (d->rank == 0)
            before[l] = 0;
        payload += 8 + 8 * ((uint64_t)res->level_size[l - 1] + 1) + 12 * (uint64_t)nnz[l];
    }
    if (d->rank == 0) {
        asp__crc_put(&w, "ASPAMG\r\n", 8);
        asp__put_u32(&w, AMG_VERSION);
        asp__put_u32(&w, AMG_HEADER);
        asp__put_u64(&w, N);
        asp__put_u64(&w, res->nlevels);
        asp__put_u64(&w, payload);
        for (int a = 0; a < 3; a++)
            asp__put_f64(&w, pts->origin[a]);
        for (int a = 0; a < 3; a++)
            asp__put_f64(&w, res->frame_center[a]);
        asp__put_f64(&w, res->frame_radius);
    }
    put_all(&s, pts->pos, 3 * n * sizeof(float));
    put_all(&s, res->tangent, 3 * n * sizeof(float));
    put_all(&s, res->classifier, n * sizeof(float));
    if (d->rank == 0) {
        asp__put_u32(&w, attrs);
        asp__put_u32(&w, 0);
    }
    if (attrs & ASP_ATTR_NORMALS)
        put_all(&s, pts->normals, 3 * n * sizeof(float));
    if (attrs & ASP_ATTR_COLORS)
        put_all(&s, pts->colors, 4 * n);
    if (attrs & ASP_ATTR_RADII)
        put_all(&s, pts->radii, n * sizeof(float));
    if (attrs & ASP_ATTR_LABELS)
        put_all(&s, pts->labels, n * sizeof(uint32_t));
    if (d->rank == 0) {
        put_options(&w, res->desc);
        for (size_t l = 0; l < res->nlevels; l++)
            asp__put_u64(&w, res->level_size[l]);
    }
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
