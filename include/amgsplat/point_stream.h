/*
 * Point files read and written in batches, for point sets larger than memory
 * (issue 28): a reader of binary PLY (little or big endian) and LAS 1.0-1.4
 * that never holds more than one batch, and a writer of binary little-endian
 * PLY (float xyz, uchar rgb) that streams to disk. Only positions and
 * colours travel; everything else in the records is skipped.
 */
#ifndef AMGSPLAT_POINT_STREAM_H
#define AMGSPLAT_POINT_STREAM_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Open point file read in batches; opaque. */
typedef struct asp_point_reader asp_point_reader;

/**
 * Opens path for batched reading: binary PLY whose first non-empty element is
 * "vertex" with scalar x, y, z (any PLY number type) and optional red, green,
 * blue (and alpha) of type uchar, or LAS 1.0-1.4 of any point format
 * (colours of formats 2, 3, 5, 7, 8 scaled from 16 to 8 bits). Returns 0;
 * ASP_EIO (cannot open); ASP_EFORMAT (malformed header, a size larger than
 * the file, naming the file); ASP_EUNSUPPORTED (ascii PLY, text formats,
 * lists in vertices: convert to binary PLY first); ASP_ENOMEM.
 * The caller frees *out with asp_point_reader_close.
 */
int asp_point_reader_open(const char *path, const asp_context *ctx, asp_point_reader **out, asp_error *err);

/** Points in the file. */
uint64_t asp_point_reader_count(const asp_point_reader *r);

/** 1 if the file has colours (PLY red/green/blue, LAS formats 2, 3, 5, 7, 8). */
int asp_point_reader_has_colors(const asp_point_reader *r);

/**
 * Reads up to cap points from the current position: world positions to xyz
 * (3 doubles each), colours to rgba (4 bytes each, white opaque without
 * colours; rgba may be NULL). *got = 0 at the end. Returns 0, ASP_EIO, or
 * ASP_EFORMAT (file shorter than its header says).
 */
int asp_point_reader_read(asp_point_reader *r, double *xyz, uint8_t *rgba, size_t cap, size_t *got,
                          asp_error *err);

/** Goes back to the first point (for another pass). Returns 0 or ASP_EIO. */
int asp_point_reader_rewind(asp_point_reader *r, asp_error *err);

/** Closes the file and frees the reader; NULL is accepted. */
void asp_point_reader_close(asp_point_reader *r);

/** PLY file written in batches; opaque. */
typedef struct asp_point_writer asp_point_writer;

/**
 * Creates path (a temporary next to it, renamed by asp_point_writer_finish)
 * as binary little-endian PLY with count vertices of float x, y, z and, with
 * colors, uchar red, green, blue. Returns 0, ASP_EIO or ASP_ENOMEM.
 */
int asp_point_writer_open(const char *path, uint64_t count, int colors, const asp_context *ctx,
                          asp_point_writer **out, asp_error *err);

/** Appends n points: xyz 3 floats each, rgb 3 bytes each (ignored without colours). Returns 0 or ASP_EIO. */
int asp_point_writer_write(asp_point_writer *w, const float *xyz, const uint8_t *rgb, size_t n, asp_error *err);

/**
 * Flushes and renames the file into place; fails with ASP_EINVAL when the
 * points written differ from the count given to open (the temporary is then
 * removed). Frees w in every case. Returns 0, ASP_EINVAL or ASP_EIO.
 */
int asp_point_writer_finish(asp_point_writer *w, asp_error *err);

/** Removes the temporary file and frees w; NULL is accepted. */
void asp_point_writer_abort(asp_point_writer *w);

#ifdef __cplusplus
}
#endif
#endif
