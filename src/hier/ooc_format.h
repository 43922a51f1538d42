/*
 * The streamed .hier layout shared by its writer (ooc_build.c) and reader
 * (ooc_file.c); docs/hier.md "Streamed layout". Not public API.
 */
#ifndef ASP_HIER_OOC_FORMAT_H
#define ASP_HIER_OOC_FORMAT_H

#include "amgsplat/hier_ooc.h"

_Static_assert(sizeof(asp_ooc_node) == 56, "asp_ooc_node is a 56-byte file record");
_Static_assert(sizeof(asp_ooc_point) == 16, "asp_ooc_point is a 16-byte file record");

enum {
    ASP__OOC_VERSION = 2,      /* the in-memory layout's version: the STREAMED flag tells them apart */
    ASP__OOC_HEADER = 160,
    ASP__OOC_NODE_REC = 56,
    ASP__OOC_POINT_REC = 16,
    ASP__OOC_FRAME_AT = 96,    /* frame centre (3 doubles) and radius, as the in-memory layout */
    ASP__OOC_TABLE_AT = 80,    /* byte offset of the node table (uint64) */
    ASP__OOC_TABLE_HASH = 88,  /* FNV-1a 64 of the node table */
    ASP__OOC_UP_AT = 128,      /* uint32: the source's up axis + 1 (0: not recorded, y), as the in-memory layout */
    ASP__OOC_HALF_AT = 132,    /* 3 x uint16 (asp_frame_half_encode): the frame's box; 0 0 0 in files before it */
    ASP__OOC_RADIUS_AT = 144,  /* double: the disc radius of the whole set at full density (asp_cloud_default_radius) */
    ASP__OOC_SAMPLE_GRID = 128 /* an inner node keeps one point per cell of this grid over its cube */
};

#endif
