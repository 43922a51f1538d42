/*
 * libFuzzer target for scene files of instances (asp_instance_scene_parse,
 * instances.h; docs/scene-format.md): any bytes give a clean error naming the
 * file with the output untouched, or a scene whose every instance names a
 * source in range with a finite, invertible affine model, never a crash or
 * leak. Parsing loads no source, so no file is touched. Seeds: tools/corpus/fuzz_scene_file:
 *   ./fuzz_scene_file -max_total_time=300 -rss_limit_mb=2048 -max_len=65536 corpus-scene
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/instances.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char path[] = "fuzz/scene.json";
    asp_instance_scene s;
    memset(&s, 0x6b, sizeof s);
    asp_error err = {0};
    if (asp_instance_scene_parse((const char *)data, size, path, &s, &err) != 0) {
        if (s.instance_count != (size_t)0x6b6b6b6b6b6b6b6bull || !strstr(err.msg, path))
            abort(); // unchanged on failure, and the message names the file
        return 0;
    }
    if (s.instance_count < 1 || s.instance_count > ASP_INSTANCE_SCENE_MAX_INSTANCES || s.source_count < 1 ||
        s.source_count > ASP_INSTANCE_SCENE_MAX_SOURCES || s.source_count > s.instance_count)
        abort();
    for (size_t i = 0; i < s.instance_count; i++) {
        const double *m = s.instances[i].model;
        if (s.instances[i].source >= s.source_count || m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1)
            abort();
        for (int k = 0; k < 16; k++)
            if (!isfinite(m[k]))
                abort();
        double det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
                     m[8] * (m[1] * m[6] - m[5] * m[2]);
        if (!(det > 0)) // singular and mirroring transforms are refused
            abort();
    }
    size_t total = 0;
    float *models = malloc(16 * s.instance_count * sizeof *models);
    if (!models)
        abort();
    for (size_t k = 0; k < s.source_count; k++) {
        if (!s.sources[k].name[0] || !memchr(s.sources[k].path, '\0', sizeof s.sources[k].path))
            abort();
        total += asp_instance_scene_models(&s, k, models);
    }
    free(models);
    if (total != s.instance_count)
        abort();
    if (s.camera.given && !(s.camera.fov_y == 0 || (s.camera.fov_y > 0 && s.camera.fov_y < 180)))
        abort();
    asp_instance_scene_release(&s);
    return 0;
}
