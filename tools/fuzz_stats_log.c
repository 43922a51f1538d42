/*
 * libFuzzer target for the experiment log reader (asp_stats_log_load, path
 * based): the bytes go to a temporary file; any bytes give a clean error that
 * names the file, or a log whose frames, events and path can be read and
 * graded (seed 004 2.4), never a crash or leak. Seeds: the logs of
 * tests/data/experiment/study:
 *   ./fuzz_stats_log -max_total_time=300 -rss_limit_mb=2048 -max_len=65536 corpus-log
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz_support.h"
#include "amgsplat/stats.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file("fuzz_stats_log", "jsonl", data, size);
    asp_stats_log log;
    asp_error err = {0};
    if (asp_stats_log_load(&log, path, &err) != 0) {
        if (log.frames || log.path || !strstr(err.msg, path))
            abort(); // zeroed on failure, and the message names the file
        return 0;
    }
    // a lost line may still give the object glued behind it: at most two per line
    if (log.frame_count + log.event_count + log.lost_frames + log.ignored_lines > 2 * log.lines)
        abort();
    double *pos = malloc((log.frame_count + 1) * 3 * sizeof *pos);
    if (!pos)
        abort();
    for (size_t i = 0; i < log.frame_count; i++)
        memcpy(pos + 3 * i, log.frames[i].pos, sizeof log.frames[i].pos);
    if (log.path) {
        asp_grade_result g;
        if (asp_stats_grade_track(log.path, log.path_count, log.half_width, pos, log.frame_count, &g, &err) == 0 &&
            !(isnan(g.grade) || (g.grade >= 0 && g.grade <= 1)))
            abort();
    }
    asp_stats_naming n;
    asp_stats_log_naming(&log, &n);
    free(pos);
    asp_stats_log_release(&log);
    return 0;
}
