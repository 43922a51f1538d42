/*
 * Checks of mesh files before assimp reads them (issue #13): declared counts
 * against the file size, face indices against the vertex count and bodies cut
 * off, so a lying header fails at once with a message naming the file instead
 * of assimp allocating until the process dies. Not public API.
 */
#ifndef ASP_IO_MESH_PRECHECK_H
#define ASP_IO_MESH_PRECHECK_H

#include "amgsplat/core.h"

/*
 * Checks path as format ("off", "stl", "obj", "gltf", "glb", "dae", "3ds"; any other format passes).
 * 0 when nothing is wrong; ASP_EFORMAT with "cannot read '<path>': ..." when
 * the file contradicts itself; ASP_EIO or ASP_ENOMEM when it cannot be read.
 */
int asp__mesh_precheck(const char *path, const char *format, const asp_context *ctx, asp_error *err);

/*
 * The same over bytes in memory (the fuzz targets' entry); name is used in messages and, for glTF,
 * to find the files its buffers name beside it.
 */
int asp__mesh_precheck_memory(const void *data, size_t size, const char *name, const char *format, asp_error *err);

/* glTF 2.0 JSON or GLB (gltf_precheck.c): header, chunk, buffer, bufferView, accessor and node ranges. */
int asp__gltf_precheck_memory(const void *data, size_t size, const char *name, asp_error *err);

/* Collada (dae_precheck.c): array counts against their text, accessors and primitive indices in range. */
int asp__dae_precheck_memory(const void *data, size_t size, const char *name, asp_error *err);

/* 3DS (mesh_precheck.c): chunk lengths nested inside their parents, vertex and face lists inside their chunks. */
int asp__3ds_precheck_memory(const void *data, size_t size, const char *name, asp_error *err);

#endif
