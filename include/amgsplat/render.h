/* amgsplat render module (placeholder, being written). */
#ifndef AMGSPLAT_RENDER_H
#define AMGSPLAT_RENDER_H
#include "cloud.h"
#include "image.h"
#endif
