/*
 * libFuzzer target for the file recogniser (asp_file_recognise_memory): any
 * head of any length, under names with every extension it knows in both
 * cases, must give a known kind with a NUL-terminated lower-case format, or a
 * clean error naming the file; never a crash or a read past the head.
 * Build with -DASP_FUZZ=ON, then: ./fuzz_file_kind -max_total_time=60 -max_len=4096
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/io.h"

static const char *const names[] = {"f.ply", "F.PLY", "f.xyz", "f.pts", "f.obj", "F.OBJ", "f.amg", "O.AMG",
                                    "f.dps", "f.hier", "f.png", "f.3ds", "f.abc", "noext", "dir.x/f"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* a copy of exactly size bytes, so ASan catches any read past the head */
    uint8_t *head = malloc(size ? size : 1);
    if (!head)
        return 0;
    if (size)
        memcpy(head, data, size);
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        asp_file_type t = {.kind = (asp_file_kind)77};
        asp_error err = {0};
        int rc = asp_file_recognise_memory(head, size, names[i], &t, &err);
        if (rc == 0) {
            if (t.kind < ASP_FILE_POINTS || t.kind > ASP_FILE_SCENE || !memchr(t.format, '\0', sizeof t.format) ||
                !t.format[0])
                abort();
            for (const char *c = t.format; *c; c++)
                if (*c >= 'A' && *c <= 'Z')
                    abort();
        } else if (t.kind != (asp_file_kind)77 || strncmp(err.msg, "cannot read '", 13) != 0) {
            abort(); /* failures leave the output alone and explain themselves */
        }
    }
    free(head);
    return 0;
}
