/*
 * Private to src/amg: the .amg layout (docs/cli/decompose.md) and the one
 * writer of its header, attribute set and options block, shared by
 * asp_amg_save (amg_file.c) and the distributed writer (distributed_write.c),
 * which streams the per-point arrays and rows of every rank between them.
 */
#ifndef ASP_AMG_FORMAT_H
#define ASP_AMG_FORMAT_H

#include <stdint.h>

#include "amgsplat/amg.h"
#include "util/checksum.h"

#define ASP__AMG_MAGIC "ASPAMG\r\n"
/*
 * Version 3 appends the source point set's frame (asp_frame, 32 bytes) to the
 * header, so every representation of a model is framed by one sphere (issue
 * 12); version 2 files still load, their frame computed from the points.
 */
enum { ASP__AMG_VERSION = 3, ASP__AMG_HEADER = 96, ASP__AMG_HEADER_V2 = 64, ASP__AMG_OPTIONS = 128 };

/* The optional point arrays a file may carry after the classifier, in file order, and their bytes per point. */
enum { ASP__AMG_NATTRS = 5 };
extern const unsigned asp__amg_attr_bit[ASP__AMG_NATTRS];
extern const unsigned asp__amg_attr_size[ASP__AMG_NATTRS];
/* Every bit of asp__amg_attr_bit. */
#define ASP__AMG_ATTRS (ASP_ATTR_NORMALS | ASP_ATTR_COLORS | ASP_ATTR_RADII | ASP_ATTR_UVS | ASP_ATTR_LABELS)

/* Bytes per point of the optional arrays in attrs. */
uint64_t asp__amg_attr_bytes(unsigned attrs);

static inline int asp__amg_host_little_endian(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}

/* What the header records, and what the payload size follows from. */
typedef struct asp__amg_header {
    uint64_t points, nlevels;
    const size_t *level_size; /* nlevels: sizes of the levels, [0] = points */
    uint64_t prolong_nnz;     /* the entries of every P^l, l >= 1, together */
    unsigned attrs;           /* the optional point arrays stored (asp__amg_attr_bit) */
    double origin[3];
    asp_frame frame;
} asp__amg_header;

/* The header (ASP__AMG_HEADER bytes), its payload size computed from h. */
void asp__amg_put_header(asp__crc_writer *w, const asp__amg_header *h);
/*
 * The attribute set between the classifier and the optional arrays: the bits, then the source's
 * up axis plus 1 (issue 29; the word was reserved, 0 in older files: not recorded, taken as y).
 */
void asp__amg_put_attr_set(asp__crc_writer *w, unsigned attrs, asp_up_axis up);
/* The options block (ASP__AMG_OPTIONS bytes: what produced the hierarchy), then the nlevels level sizes. */
void asp__amg_put_options(asp__crc_writer *w, const asp_amg_desc *d, const size_t *level_size, size_t nlevels);

#endif
