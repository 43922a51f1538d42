/*
 * LAS point data record formats 0-10 (ASPRS LAS 1.4 R15, Tables 7-17) as
 * field lists: formats 0-5 share the 20-byte legacy core (3-bit return
 * numbers, 5-bit classes), 6-10 the 30-byte core of LAS 1.4 (4-bit return
 * numbers, 8-bit classes, scanner channel, GPS time always); GPS time, RGB,
 * NIR and the wave packet follow in the order of the tables.
 */
#include <string.h>

#include "io/las_internal.h"
#include "util/banned.h"

static const size_t format_size[LAS_MAX_FORMAT + 1] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

size_t asp__las_format_size(unsigned fmt)
{
    return fmt <= LAS_MAX_FORMAT ? format_size[fmt] : 0;
}

int asp__las_has_rgb(unsigned fmt)
{
    return fmt == 2 || fmt == 3 || fmt == 5 || fmt == 7 || fmt == 8 || fmt == 10;
}

static size_t add(las_field *out, size_t n, const char *name, asp_scalar_type type, size_t offset, unsigned bytes,
                  char kind, unsigned shift, unsigned mask)
{
    out[n] = (las_field){name, type, offset, bytes, kind, shift, mask};
    return n + 1;
}

/* GPS time, RGB, NIR and wave packet from byte at on, as the format has them. */
static size_t tail_fields(unsigned fmt, las_field *out, size_t n, size_t at)
{
    int gps = fmt == 1 || fmt >= 3, nir = fmt == 8 || fmt == 10, wave = fmt == 4 || fmt == 5 || fmt >= 9;
    if (gps && fmt < 6) {
        n = add(out, n, "gps_time", ASP_SCALAR_FLOAT64, at, 8, 'f', 0, 0);
        at += 8;
    }
    if (asp__las_has_rgb(fmt)) {
        n = add(out, n, "red16", ASP_SCALAR_UINT16, at, 2, 'u', 0, 0);
        n = add(out, n, "green16", ASP_SCALAR_UINT16, at + 2, 2, 'u', 0, 0);
        n = add(out, n, "blue16", ASP_SCALAR_UINT16, at + 4, 2, 'u', 0, 0);
        at += 6;
    }
    if (nir) {
        n = add(out, n, "nir", ASP_SCALAR_UINT16, at, 2, 'u', 0, 0);
        at += 2;
    }
    if (wave) {
        /* the waveform itself is elsewhere (EVLR or .wdp file); the packet fields are kept as they are */
        n = add(out, n, "wave_packet_index", ASP_SCALAR_UINT8, at, 1, 'u', 0, 0);
        n = add(out, n, "wave_packet_offset", ASP_SCALAR_FLOAT64, at + 1, 8, 'u', 0, 0);
        n = add(out, n, "wave_packet_size", ASP_SCALAR_UINT32, at + 9, 4, 'u', 0, 0);
        n = add(out, n, "wave_return_location", ASP_SCALAR_FLOAT32, at + 13, 4, 'f', 0, 0);
        n = add(out, n, "wave_dx", ASP_SCALAR_FLOAT32, at + 17, 4, 'f', 0, 0);
        n = add(out, n, "wave_dy", ASP_SCALAR_FLOAT32, at + 21, 4, 'f', 0, 0);
        n = add(out, n, "wave_dz", ASP_SCALAR_FLOAT32, at + 25, 4, 'f', 0, 0);
    }
    return n;
}

size_t asp__las_fields(unsigned fmt, las_field *out)
{
    size_t n = 0;
    n = add(out, n, "intensity", ASP_SCALAR_UINT16, 12, 2, 'u', 0, 0);
    if (fmt < 6) {
        n = add(out, n, "return_number", ASP_SCALAR_UINT8, 14, 1, 'u', 0, 7);
        n = add(out, n, "number_of_returns", ASP_SCALAR_UINT8, 14, 1, 'u', 3, 7);
        n = add(out, n, "scan_direction_flag", ASP_SCALAR_UINT8, 14, 1, 'u', 6, 1);
        n = add(out, n, "edge_of_flight_line", ASP_SCALAR_UINT8, 14, 1, 'u', 7, 1);
        n = add(out, n, "classification", ASP_SCALAR_UINT8, 15, 1, 'u', 0, 31);
        /* synthetic, key-point, withheld: bits 0-2 as in the 4-bit flags of formats 6-10 */
        n = add(out, n, "classification_flags", ASP_SCALAR_UINT8, 15, 1, 'u', 5, 7);
        n = add(out, n, "scan_angle_rank", ASP_SCALAR_INT8, 16, 1, 's', 0, 0);
        n = add(out, n, "user_data", ASP_SCALAR_UINT8, 17, 1, 'u', 0, 0);
        n = add(out, n, "point_source_id", ASP_SCALAR_UINT16, 18, 2, 'u', 0, 0);
        return tail_fields(fmt, out, n, 20);
    }
    n = add(out, n, "return_number", ASP_SCALAR_UINT8, 14, 1, 'u', 0, 15);
    n = add(out, n, "number_of_returns", ASP_SCALAR_UINT8, 14, 1, 'u', 4, 15);
    n = add(out, n, "classification_flags", ASP_SCALAR_UINT8, 15, 1, 'u', 0, 15);
    n = add(out, n, "scanner_channel", ASP_SCALAR_UINT8, 15, 1, 'u', 4, 3);
    n = add(out, n, "scan_direction_flag", ASP_SCALAR_UINT8, 15, 1, 'u', 6, 1);
    n = add(out, n, "edge_of_flight_line", ASP_SCALAR_UINT8, 15, 1, 'u', 7, 1);
    n = add(out, n, "classification", ASP_SCALAR_UINT8, 16, 1, 'u', 0, 0);
    n = add(out, n, "user_data", ASP_SCALAR_UINT8, 17, 1, 'u', 0, 0);
    n = add(out, n, "scan_angle", ASP_SCALAR_INT16, 18, 2, 's', 0, 0);
    n = add(out, n, "point_source_id", ASP_SCALAR_UINT16, 20, 2, 'u', 0, 0);
    n = add(out, n, "gps_time", ASP_SCALAR_FLOAT64, 22, 8, 'f', 0, 0);
    return tail_fields(fmt, out, n, 30);
}

int asp__las_laz_error(const char *name, asp_error *err)
{
    // the example names the file without its folder: the whole path twice overran the message (256 bytes)
    const char *slash = strrchr(name, '/'), *base = slash ? slash + 1 : name, *dot = strrchr(base, '.');
    int stem = (int)(dot ? (size_t)(dot - base) : strlen(base));
    return asp_error_set(err, ASP_EUNSUPPORTED,
                         "cannot read '%s': compressed LAS (LASzip) needs a decompressor this build does not have; "
                         "decompress it first (e.g. `laszip -i %s -o %.*s.las`)",
                         name, base, stem, base);
}
