/* amgsplat io module (placeholder, being written). */
#ifndef AMGSPLAT_IO_H
#define AMGSPLAT_IO_H
#include "cloud.h"
#include "image.h"
#endif
