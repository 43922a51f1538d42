/* BC3 (DXT5) blocks of an RGBA8 image (src/prim/bc3_squish.cpp, libsquish). Not public API. */
#ifndef ASP_PRIM_BC3_H
#define ASP_PRIM_BC3_H

/* Bytes of the BC3 blocks of a width x height image: 16 per 4x4 block, partial blocks rounded up. */
#define ASP__BC3_BYTES(w, h) ((((unsigned long long)(w) + 3) / 4) * (((unsigned long long)(h) + 3) / 4) * 16)

/* Encodes width x height RGBA8 texels (rows packed) into ASP__BC3_BYTES blocks, row-major blocks. */
void asp__bc3_encode(const unsigned char *rgba, int width, int height, unsigned char *blocks);
/* Decodes ASP__BC3_BYTES blocks into width x height RGBA8 texels: what the GPU samples. */
void asp__bc3_decode(const unsigned char *blocks, int width, int height, unsigned char *rgba);

#endif
