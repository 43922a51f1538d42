/* amgsplat mesh module (placeholder, being written). */
#ifndef AMGSPLAT_MESH_H
#define AMGSPLAT_MESH_H
#include "cloud.h"
#include "image.h"
#endif
