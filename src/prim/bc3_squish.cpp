/*
 * BC3 (DXT5, GL_EXT_texture_compression_s3tc) blocks through Debian's libsquish
 * (issue 27: the atlas stored and uploaded in a compressed GPU format). libsquish
 * is C++ only; this file is the one C++ translation unit of the library and
 * exposes two C functions (declared in prim/internal.h). BC3 over BC1: BC1 has
 * 1-bit alpha, and the alpha channel is the basis function (thesis 3.3), which
 * the normalised blend divides by, so it needs BC3's 8-level interpolated alpha.
 */
#include <squish.h>

extern "C" {
#include "prim/bc3.h"
}

extern "C" void asp__bc3_encode(const unsigned char *rgba, int width, int height, unsigned char *blocks)
{
    /* cluster fit (squish's best colour fit) with perceptual colour weights: the atlas colours are sRGB */
    squish::CompressImage(rgba, width, height, blocks, squish::kDxt5 | squish::kColourClusterFit);
}

extern "C" void asp__bc3_decode(const unsigned char *blocks, int width, int height, unsigned char *rgba)
{
    squish::DecompressImage(rgba, width, height, blocks, squish::kDxt5);
}
