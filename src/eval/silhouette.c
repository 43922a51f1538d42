/*
 * Silhouette intersection-over-union: how well two renders agree on which
 * pixels the object covers, independent of shading. Used to detect holes
 * and bloated splats (issue 6: coverage within 0.5% of the disc render).
 */
#include "eval/internal.h"
#include "util/banned.h"

static int is_foreground(const uint8_t *p, const uint8_t background[3])
{
    if (!background)
        return p[3] != 0;
    return p[0] != background[0] || p[1] != background[1] || p[2] != background[2];
}

size_t asp_image_foreground_count(const asp_image *img, const uint8_t background[3])
{
    size_t n = (size_t)img->width * img->height, count = 0;
    for (size_t i = 0; i < n; i++)
        count += (size_t)is_foreground(img->pixels + 4 * i, background);
    return count;
}

int asp_image_silhouette_iou(const asp_image *a, const asp_image *b, const uint8_t background[3], double *out,
                             asp_error *err)
{
    int rc = asp__image_same_size(a, b, err);
    if (rc)
        return rc;
    size_t n = (size_t)a->width * a->height, both = 0, any = 0;
    for (size_t i = 0; i < n; i++) {
        int fa = is_foreground(a->pixels + 4 * i, background), fb = is_foreground(b->pixels + 4 * i, background);
        both += (size_t)(fa && fb);
        any += (size_t)(fa || fb);
    }
    *out = any ? (double)both / (double)any : 1.0;
    return 0;
}
