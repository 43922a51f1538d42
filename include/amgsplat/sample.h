/* amgsplat sample module (placeholder, being written). */
#ifndef AMGSPLAT_SAMPLE_H
#define AMGSPLAT_SAMPLE_H
#include "cloud.h"
#include "image.h"
#endif
