/*
 * libFuzzer target for image input (asp_image_load and asp_image_probe, both
 * path-based, through stb_image): the bytes go to a temporary file, and any
 * bytes give a clean error or an image whose every pixel can be read. Seeds:
 * any small PNG/JPEG/BMP/TGA/GIF, e.g. /usr/share/glmark2/textures/ *.png cut
 * below 64 KB:
 *   ./fuzz_image -max_total_time=600 -rss_limit_mb=2048 -max_len=65536 corpus-image
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz_support.h"
#include "amgsplat/image.h"
#include "amgsplat/io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file("fuzz_image", "png", data, size);
    asp_image img = {0};
    asp_error err = {0};
    if (asp_image_load(&img, path, &err) == 0) {
        if (img.width == 0 || img.height == 0 || !img.pixels)
            abort();
        volatile uint8_t sink = 0;
        for (size_t i = 0; i < (size_t)img.width * img.height * 4; i++)
            sink ^= img.pixels[i];
        (void)sink;
        asp_image_release(&img);
    } else if (img.pixels || !strstr(err.msg, path)) {
        abort(); // outputs unchanged on failure, and the message names the file
    }
    asp_image_header h;
    memset(&err, 0, sizeof err);
    if (asp_image_probe(path, &h, &err) == 0) {
        if (h.width == 0 || h.height == 0 || h.channels < 1 || h.channels > 4)
            abort();
    } else if (!strstr(err.msg, path)) {
        abort();
    }
    return 0;
}
