/*
 * Silhouette intersection-over-union: how well two renders agree on which
 * pixels the object covers, independent of shading. Used to detect holes
 * and bloated splats (issue 6: coverage within 0.5% of the disc render).
 * Opaque images (a render on white) take their silhouette from the background
 * colour, given or detected from the corners (issue 12), not from alpha.
 */
#include <stdlib.h>
#include <string.h>

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

const char *asp_silhouette_source_name(asp_silhouette_source source)
{
    switch (source) {
    case ASP_SILHOUETTE_ALPHA:
        return "alpha";
    case ASP_SILHOUETTE_BACKGROUND:
        return "background";
    case ASP_SILHOUETTE_CORNERS:
        return "corners";
    }
    return "?";
}

enum { DEFAULT_TOLERANCE = 8 };

static int has_transparency(const asp_image *img)
{
    const size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        if (img->pixels[4 * i + 3] != 255)
            return 1;
    return 0;
}

static int near_colour(const uint8_t *p, const uint8_t bg[3], int tol)
{
    return abs((int)p[0] - bg[0]) <= tol && abs((int)p[1] - bg[1]) <= tol && abs((int)p[2] - bg[2]) <= tol;
}

/* The colour most of the four corner pixels share (within tol); ties go to the first corner in scan order. */
static int corner_background(const asp_image *img, int tol, uint8_t bg[3])
{
    const size_t w = img->width, h = img->height;
    if (w == 0 || h == 0)
        return 0;
    const size_t at[4] = {0, w - 1, (h - 1) * w, (h - 1) * w + w - 1};
    int best = 0, votes = 0;
    for (int c = 0; c < 4; c++) {
        int v = 0;
        for (int d = 0; d < 4; d++)
            v += near_colour(img->pixels + 4 * at[d], img->pixels + 4 * at[c], tol);
        if (v > votes)
            best = c, votes = v;
    }
    for (int k = 0; k < 3; k++)
        bg[k] = img->pixels[4 * at[best] + k];
    return votes;
}

/* How img's silhouette is taken (info), by the rules of asp_image_silhouettes. */
static void choose_source(const asp_image *img, const asp_silhouette_desc *desc, int tol, asp_silhouette_info *info)
{
    memset(info, 0, sizeof *info);
    if (has_transparency(img)) {
        info->source = ASP_SILHOUETTE_ALPHA;
    } else if (desc && desc->background) {
        info->source = ASP_SILHOUETTE_BACKGROUND;
        memcpy(info->background, desc->background, 3);
    } else {
        info->source = ASP_SILHOUETTE_CORNERS;
        info->corners_agreeing = corner_background(img, tol, info->background);
    }
}

static int in_silhouette(const uint8_t *p, const asp_silhouette_info *info, int tol)
{
    return info->source == ASP_SILHOUETTE_ALPHA ? p[3] != 0 : !near_colour(p, info->background, tol);
}

int asp_image_silhouettes(const asp_image *a, const asp_image *b, const asp_silhouette_desc *desc, double *iou,
                          asp_silhouette_info info[2], asp_error *err)
{
    int rc = asp__image_same_size(a, b, err);
    if (rc)
        return rc;
    const int tol = !desc || desc->tolerance == 0 ? DEFAULT_TOLERANCE : desc->tolerance < 0 ? 0 : desc->tolerance;
    asp_silhouette_info in[2];
    choose_source(a, desc, tol, &in[0]);
    choose_source(b, desc, tol, &in[1]);
    const size_t n = (size_t)a->width * a->height;
    size_t both = 0, any = 0;
    for (size_t i = 0; i < n; i++) {
        const int fa = in_silhouette(a->pixels + 4 * i, &in[0], tol), fb = in_silhouette(b->pixels + 4 * i, &in[1], tol);
        in[0].foreground += (size_t)fa;
        in[1].foreground += (size_t)fb;
        both += (size_t)(fa && fb);
        any += (size_t)(fa || fb);
    }
    *iou = any ? (double)both / (double)any : 1.0;
    if (info)
        memcpy(info, in, sizeof in);
    return 0;
}
