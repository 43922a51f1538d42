/*
 * Shared internals of the PLY reader and writer: scalar type names and
 * aliases, byte order, value conversion, shortest round-trip number text.
 * Private to src/io; not public API.
 */
#ifndef ASP_IO_PLY_INTERNAL_H
#define ASP_IO_PLY_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "amgsplat/cloud.h"

/* PLY type name or alias ("uchar", "uint8", "float32" ...) of len bytes; NONE when unknown. */
asp_scalar_type asp__ply_type_from_name(const char *name, size_t len);

/* 1 on a big-endian host. */
static inline int asp__host_big_endian(void)
{
    const uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 0;
}

/* Reverses n (1, 2, 4 or 8) bytes in place. */
static inline void asp__swap_bytes(void *p, size_t n)
{
    uint8_t *b = p;
    for (size_t i = 0; i < n / 2; i++) {
        uint8_t t = b[i];
        b[i] = b[n - 1 - i];
        b[n - 1 - i] = t;
    }
}

/* Value of one native-order scalar of type t at p (unaligned allowed). */
double asp__scalar_load(const void *p, asp_scalar_type t);
/* Stores v into one native-order scalar of type t at p, rounding and clamping integer types. */
void asp__scalar_store(void *p, asp_scalar_type t, double v);
/* 1 when t is one of the integer types. */
static inline int asp__scalar_is_int(asp_scalar_type t)
{
    return t >= ASP_SCALAR_INT8 && t <= ASP_SCALAR_UINT32;
}

/*
 * Parses one value of type t from the NUL-terminated text at *s (leading
 * blanks and the separators in seps skipped) into a native scalar at out.
 * Integers must be integral and in range; float32 uses strtof so a float
 * written by asp__format_float reads back to the same bits. Advances *s.
 * Returns 0, -1 when no token is left, -2 when the token is not a number of
 * that type (then *s points at the token).
 */
int asp__scalar_parse(const char **s, const char *seps, asp_scalar_type t, void *out);

/*
 * Writes the shortest decimal text (at most 31 bytes + NUL into buf[32])
 * that reads back to exactly the same float/double. Returns the length.
 */
size_t asp__format_float(char buf[32], float v);
size_t asp__format_double(char buf[32], double v);
/* Text of one native scalar of type t (integers exact, floats shortest). */
size_t asp__format_scalar(char buf[32], const void *p, asp_scalar_type t);

/*
 * As asp_ply_read, and counts the face lists of fewer than 3 indices (no
 * surface; left out of the triangles): the mesh path rewrites such files for
 * assimp, whose triangulation aborts on an empty face (fuzz_mesh, issue #13).
 */
int asp__ply_read_counting(const char *path, const asp_context *ctx, asp_cloud **out, size_t *short_faces,
                           asp_error *err);

#endif
