/*
 * LAS (ASPRS LAS 1.0-1.4) point record layouts shared by the reader and the
 * writer: which field sits at which byte of a record of each point data
 * record format 0-10 (LAS 1.4 R15, Tables 7-17), as named cloud properties.
 * Not public API.
 */
#ifndef ASP_IO_LAS_INTERNAL_H
#define ASP_IO_LAS_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "amgsplat/cloud.h"

/* Header sizes of LAS 1.0-1.2, 1.3 and 1.4 (LAS 1.4 R15 Table 3); VLR and EVLR headers (Tables 4, 6). */
enum { LAS_HEADER_12 = 227, LAS_HEADER_13 = 235, LAS_HEADER_14 = 375, LAS_VLR_HEADER = 54, LAS_EVLR_HEADER = 60 };
/* One Extra Bytes descriptor (LAS 1.4 R15 Table 24). */
enum { LAS_EXTRA_DESCRIPTOR = 192, LAS_MAX_FORMAT = 10, LAS_MAX_FIELDS = 24 };

/* Byte offsets in the public header block (LAS 1.4 R15 Table 3). */
enum {
    LASH_SOURCE_ID = 4, LASH_ENCODING = 6, LASH_GUID = 8, LASH_VERSION = 24, LASH_SYSTEM = 26, LASH_SOFTWARE = 58,
    LASH_DAY = 90, LASH_YEAR = 92, LASH_HEADER_SIZE = 94, LASH_POINT_OFFSET = 96, LASH_VLR_COUNT = 100,
    LASH_FORMAT = 104, LASH_RECORD_LENGTH = 105, LASH_LEGACY_COUNT = 107, LASH_LEGACY_BY_RETURN = 111,
    LASH_SCALE = 131, LASH_OFFSET = 155, LASH_MAX_X = 179, LASH_WAVEFORM = 227, LASH_EVLR_START = 235,
    LASH_EVLR_COUNT = 243, LASH_COUNT = 247, LASH_BY_RETURN = 255
};

/*
 * One field of a point record: the bits (shift, mask; mask 0 = the whole
 * value) of a little-endian value of type at offset. Property names are the
 * same for every format so that a conversion between formats maps fields by
 * name; the scan angle is "scan_angle_rank" (int8, degrees) in formats 0-5
 * and "scan_angle" (int16, 0.006 degree steps) in 6-10.
 */
typedef struct las_field {
    const char *name;
    asp_scalar_type type; /* the property's type */
    size_t offset;        /* in the record */
    unsigned bytes;       /* width of the stored value: 1, 2, 4 or 8 */
    char kind;            /* stored as 'u' unsigned, 's' signed integer or 'f' IEEE float */
    unsigned shift, mask;
} las_field;

/* Size of the fixed part of a record of point format fmt (0-10); 0 for an unknown format. */
size_t asp__las_format_size(unsigned fmt);

/*
 * The fields of format fmt (0-10) after X, Y, Z, in record order, into
 * out[LAS_MAX_FIELDS]; returns their count. RGB fields are "red16",
 * "green16", "blue16"; the near infrared is "nir".
 */
size_t asp__las_fields(unsigned fmt, las_field *out);

/* 1 when format fmt carries RGB. */
int asp__las_has_rgb(unsigned fmt);

/*
 * The message for a compressed (LASzip) file: "cannot read 'F': compressed
 * LAS (LASzip) needs a decompressor ...". Returns ASP_EUNSUPPORTED.
 */
int asp__las_laz_error(const char *name, asp_error *err);

/* Little-endian loads from unaligned bytes. */
static inline uint64_t las_get(const uint8_t *p, unsigned bytes)
{
    uint64_t v = 0;
    for (unsigned k = bytes; k-- > 0;)
        v = v << 8 | p[k];
    return v;
}
static inline void las_put(uint8_t *p, uint64_t v, unsigned bytes)
{
    for (unsigned k = 0; k < bytes; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

#endif
