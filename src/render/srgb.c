/*
 * sRGB transfer functions (IEC 61966-2-1). Point colours are 8-bit sRGB
 * (cloud.h); shading and multisample averaging are meant for linear light, so
 * CPU-side colour maths (clear colours, un-premultiplying) converts first.
 */
#include <math.h>

#include "render/internal.h"
#include "util/banned.h"

float asp__srgb_to_linear(uint8_t v)
{
    double c = v / 255.0;
    return (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
}

uint8_t asp__linear_to_srgb(float v)
{
    double c = v <= 0 ? 0 : v >= 1 ? 1 : v;
    double s = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
    return (uint8_t)lround(s * 255.0);
}
