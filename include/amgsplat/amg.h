/* amgsplat amg module (placeholder, being written). */
#ifndef AMGSPLAT_AMG_H
#define AMGSPLAT_AMG_H
#include "cloud.h"
#include "image.h"
#endif
