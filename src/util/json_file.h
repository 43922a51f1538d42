/*
 * JSON documents written to files: cJSON (the one JSON library) printed
 * indented and written through the atomic writer, so a report or scene file
 * is whole or absent. Shared by eval, stats and experiment; not public API.
 */
#ifndef ASP_UTIL_JSON_FILE_H
#define ASP_UTIL_JSON_FILE_H

#include <cjson/cJSON.h>
#include "amgsplat/core.h"

/**
 * Prints root (indented, a final newline) to path atomically and deletes
 * root (also on failure; NULL is accepted and reported as out of memory, so
 * a failed cJSON_Create* can be passed straight in). Returns 0, ASP_ENOMEM
 * or the atomic writer's errors.
 */
int asp__json_save(cJSON *root, const char *path, asp_error *err);

#endif
