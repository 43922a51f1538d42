/*
 * The SPZ stream of KHR_gaussian_splatting_compression_spz_2 (issue 32): Niantic's compressed
 * Gaussian splat format, version 2, the one the extension names and CesiumJS decodes (its
 * @spz-loader/core reads versions 1 to 3). Written from the format's description (nianticlabs/spz
 * README, "File Format"; the legacy gzip layout of versions 1 to 3):
 *   gzip( header, positions, alphas, colours, scales, rotations, SH )
 *   header     16 bytes little-endian: magic "NGSP" (0x5053474e), version 2, point count (u32),
 *              SH degree (u8, here 0), fractional bits (u8), flags (u8, 0), reserved (u8, 0);
 *   positions  per point x, y, z as 24-bit signed fixed point, fractional bits from the header;
 *   alphas     per point 1 byte, sigmoid(opacity logit) * 255: the opacity itself;
 *   colours    per point r, g, b bytes: SH DC * (0.15 * 255) + 127.5;
 *   scales     per point 3 bytes: (ln sigma + 10) * 16;
 *   rotations  per point x, y, z bytes of the unit quaternion with w >= 0: q * 127.5 + 127.5 (w is
 *              rebuilt as sqrt(1 - x^2 - y^2 - z^2)); version 3's smallest-three form is not written;
 *   SH         degree >= 1 coefficients (none here).
 * Each attribute is one array over all points, so gzip sees the like bytes together.
 */
#include <math.h>
#include <string.h>

#include <zlib.h>

#include "export/internal.h"
#include "util/banned.h"

static uint8_t to_u8(double x) { return (uint8_t)fmin(fmax(rint(x), 0.0), 255.0); }

int asp__spz_encode(const asp__spz_splats *s, size_t n, uint8_t **dst, size_t *dst_size, asp_error *err)
{
    ASP_ASSERT(s && dst && dst_size && s->fractional_bits >= 0 && s->fractional_bits <= 23);
    // zlib counts the input in 32 bits: 19 bytes a splat keeps a stream under 4 GiB
    if (n == 0 || n > 200000000u)
        return asp_error_set(err, ASP_EINVAL, "an SPZ stream here holds 1 to 200,000,000 splats, not %zu", n);
    size_t raw_size = 16 + n * (9 + 1 + 3 + 3 + 3);
    uint8_t *raw = asp_alloc(NULL, raw_size);
    if (!raw)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the SPZ stream of %zu splats", n);
    const uint32_t head[3] = {0x5053474eu, 2u, (uint32_t)n};
    for (int w = 0; w < 3; w++)
        for (int b = 0; b < 4; b++)
            raw[4 * w + b] = (uint8_t)(head[w] >> (8 * b));
    raw[12] = 0; // SH degree
    raw[13] = (uint8_t)s->fractional_bits;
    raw[14] = 0; // flags: not antialiased
    raw[15] = 0;
    uint8_t *pos = raw + 16, *alpha = pos + 9 * n, *color = alpha + n, *scale = color + 3 * n, *rot = scale + 3 * n;
    const double unit = ldexp(1.0, s->fractional_bits);
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            double f = rint(s->positions[3 * i + k] * unit);
            long v = (long)fmin(fmax(f, -8388608.0), 8388607.0);
            uint32_t u = (uint32_t)v; // two's complement, low 24 bits
            for (int b = 0; b < 3; b++)
                pos[9 * i + 3 * k + b] = (uint8_t)(u >> (8 * b));
            // the SH DC term: 0.15 is SPZ's colour scale, a little more than [0, 1] after 0.5 + 0.282 x
            color[3 * i + k] = to_u8(s->sh0[3 * i + k] * (0.15 * 255.0) + 127.5);
            scale[3 * i + k] = to_u8((s->log_scales[3 * i + k] + 10.0) * 16.0);
        }
        alpha[i] = to_u8(s->opacities[i] * 255.0);
        // A Gaussian is unchanged by a half turn about any of its own axes: q, q i, q j and q k
        // (x, y, z, w) = (x, y, z, w), (w, z, -y, -x), (-z, w, x, -y), (y, -x, w, -z) are one
        // splat. The one with the largest |w| keeps the rebuilt w = sqrt(1 - x^2 - y^2 - z^2) away
        // from 0, where 8-bit x, y, z tilt the splat by up to 10 degrees (3 at |w| >= 0.5).
        const float *q = s->rotations + 4 * i;
        const double c[4][4] = {{q[0], q[1], q[2], q[3]},
                                {q[3], q[2], -q[1], -q[0]},
                                {-q[2], q[3], q[0], -q[1]},
                                {q[1], -q[0], q[3], -q[2]}};
        int best = 0;
        for (int j = 1; j < 4; j++)
            if (fabs(c[j][3]) > fabs(c[best][3]))
                best = j;
        const double *b = c[best];
        double len = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
        double sign = b[3] < 0 ? -1.0 : 1.0; // q and -q are one rotation: the one with w >= 0
        for (int k = 0; k < 3; k++)
            rot[3 * i + k] = len > 0 ? to_u8(sign * b[k] / len * 127.5 + 127.5) : 128;
    }
    // gzip (RFC 1952) through zlib: window bits 15 + 16 asks deflate for the gzip wrapper. Level 9:
    // the 1M bunny 8.80 bytes a point in 6.1 s, level 6 8.89 in 3.9 s (one run, loaded machine)
    z_stream z;
    memset(&z, 0, sizeof z);
    int rc = 0;
    if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) {
        asp_free(NULL, raw);
        return asp_error_set(err, ASP_ENOMEM, "cannot start the SPZ stream's gzip (zlib %s)", zlibVersion());
    }
    size_t cap = deflateBound(&z, (uLong)raw_size) + 64;
    uint8_t *out = asp_alloc(NULL, cap);
    if (!out) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the SPZ stream of %zu splats", n);
    } else {
        z.next_in = raw;
        z.avail_in = (uInt)raw_size;
        z.next_out = out;
        z.avail_out = (uInt)cap;
        if (deflate(&z, Z_FINISH) != Z_STREAM_END) {
            asp_free(NULL, out);
            out = NULL;
            rc = asp_error_set(err, ASP_ENOMEM, "the SPZ stream of %zu splats does not fit its gzip bound", n);
        }
    }
    size_t size = z.total_out;
    deflateEnd(&z);
    asp_free(NULL, raw);
    if (rc)
        return rc;
    *dst = out;
    *dst_size = size;
    return 0;
}
