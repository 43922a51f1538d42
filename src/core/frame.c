/*
 * One framing for every representation of a point set: the default disc
 * radius (journal section 1: a disc is position, radius, colour and normal;
 * without a radius one is estimated from the sampling density) and the
 * bounding sphere of the drawn discs that render, view and eval fit the
 * camera to, recorded in .amg, .dps and .hier so their pictures match.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "amgsplat/cloud.h"
#include "util/banned.h"

float asp_cloud_default_radius(const asp_cloud *cloud)
{
    ASP_ASSERT(cloud);
    float lo[3], hi[3];
    if (cloud->count == 0 || asp_cloud_bounds(cloud, lo, hi, NULL) != 0)
        return 0.0f;
    // double: products of large float extents would lose digits
    double x = (double)hi[0] - lo[0], y = (double)hi[1] - lo[1], z = (double)hi[2] - lo[2];
    double n = (double)cloud->count;
    double area = x * y + y * z + z * x;
    if (area > 0 && isfinite(area))
        return (float)(2.0 * sqrt(area / (3.14159265358979323846 * n)));
    double longest = fmax(x, fmax(y, z));
    return isfinite(longest) ? (float)(longest / n) : 0.0f;
}

int asp_positions_frame(const float *positions, size_t count, const double origin[3], double radius, asp_frame *out,
                        asp_error *err)
{
    ASP_ASSERT((positions || count == 0) && origin && out);
    if (count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot frame an empty point set");
    // float bounds (as asp_cloud_bounds) and double distances: one frame whoever asks
    float lo[3], hi[3];
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = positions[k];
    for (size_t i = 0; i < count; i++)
        for (int k = 0; k < 3; k++) {
            float v = positions[3 * i + k];
            if (!isfinite(v))
                return asp_error_set(err, ASP_EFORMAT, "point %zu: coordinate %c is not finite", i, "xyz"[k]);
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = 0.5 * ((double)lo[k] + hi[k]);
    double max_d2 = 0;
    for (size_t i = 0; i < count; i++) {
        const float *p = positions + 3 * i;
        double dx = p[0] - c[0], dy = p[1] - c[1], dz = p[2] - c[2];
        double d2 = dx * dx + dy * dy + dz * dz;
        max_d2 = d2 > max_d2 ? d2 : max_d2;
    }
    double r = sqrt(max_d2) + radius;
    /*
     * Cameras are float (render/camera.c) and place the eye up to 1e6 radii away (--view DIST), with
     * a far plane beyond it: a larger sphere turns the camera into inf and NaN. An overflow is not
     * "all at the same position" (issue #13: points at +-3e38 were described so).
     */
    const double frame_max = FLT_MAX / 1e7;
    if (!(r <= frame_max))
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot frame %zu points: bounding sphere radius %.3g (extent %.3g, disc radius %.3g) is "
                             "beyond the %.3g a float camera can place; scale the points down",
                             count, r, sqrt(max_d2), radius, frame_max);
    if (!(r > 0))
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot frame %zu points: they are all at the same position and have no radius", count);
    asp_frame f;
    memset(&f, 0, sizeof f); // padding too: frames are compared bit for bit (memcmp) after a file round trip
    f.radius = r;
    for (int k = 0; k < 3; k++) {
        f.center[k] = origin[k] + c[k];
        f.half[k] = 0.5 * ((double)hi[k] - lo[k]) + radius; // the box a flat, wide set is framed by
    }
    // in the steps the files store, so a frame read back is the frame written, bit for bit
    uint16_t q[3];
    asp_frame_half_encode(&f, q);
    asp_frame_half_decode(&f, q);
    memcpy(out, &f, sizeof f);
    return 0;
}

void asp_frame_half_encode(const asp_frame *f, uint16_t q[3])
{
    for (int k = 0; k < 3; k++) {
        // a side is at most the radius (no point is farther from the centre along an axis than in all);
        // up to the next step, less a millionth of one so that a decoded side encodes to its own step
        double t = f->radius > 0 ? ceil(f->half[k] / f->radius * 65535.0 - 1e-6) : 0.0;
        q[k] = (uint16_t)(t > 0 ? (t < 65535.0 ? t : 65535.0) : 0.0); // NaN: 0, "not known"
    }
}

void asp_frame_half_decode(asp_frame *f, const uint16_t q[3])
{
    for (int k = 0; k < 3; k++)
        f->half[k] = f->radius * (double)q[k] / 65535.0;
}

int asp_cloud_frame(const asp_cloud *cloud, asp_frame *out, asp_error *err)
{
    ASP_ASSERT(cloud && out);
    if (cloud->count == 0)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot frame an empty point set");
    int rc = asp_cloud_validate(cloud, err);
    if (rc)
        return rc;
    double max_r = 0;
    if (cloud->radii) {
        for (size_t i = 0; i < cloud->count; i++)
            max_r = cloud->radii[i] > max_r ? cloud->radii[i] : max_r;
    } else {
        max_r = asp_cloud_default_radius(cloud);
    }
    rc = asp_positions_frame(cloud->positions, cloud->count, cloud->origin, max_r, out, err);
    if (!rc)
        out->up = cloud->up;
    return rc;
}
