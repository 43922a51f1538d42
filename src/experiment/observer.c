/*
 * What the machine observer sees: it is given only the frame read back from
 * the framebuffer. Navigation finds the sandy path (or canyon floor) by
 * colour; recognition reduces the frame to a silhouette and a colour
 * histogram and compares them with reference frames of each candidate.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "experiment/internal.h"
#include "util/banned.h"

/* sandy = the path and floor colour of world.c: red well above blue; a ratio, so shading does not change it */
static int sandy(const uint8_t *p)
{
    return p[0] > 60 && (float)(p[0] - p[2]) > 0.22f * (float)p[0];
}

void asp_experiment_see_path(const asp_image *frame, float band_top, float band_bottom, float *fraction,
                             float *steer)
{
    uint32_t w = frame->width, h = frame->height;
    uint32_t r0 = (uint32_t)(band_top * (float)h), r1 = (uint32_t)(band_bottom * (float)h);
    if (r1 > h)
        r1 = h;
    double sum = 0.0, weight = 0.0;
    size_t total = 0;
    for (uint32_t y = r0; y < r1; y++) {
        /* rows nearer the horizon look further ahead: weight them more so the observer anticipates bends */
        double rw = 1.0 + 2.0 * (double)(r1 - y) / (double)(r1 - r0 + 1);
        for (uint32_t x = 0; x < w; x++) {
            total++;
            if (sandy(&frame->pixels[4 * ((size_t)y * w + x)])) {
                sum += rw * ((2.0 * x + 1.0) / w - 1.0);
                weight += rw;
            }
        }
    }
    size_t hits = 0;
    for (uint32_t y = r0; y < r1; y++)
        for (uint32_t x = 0; x < w; x++)
            hits += (size_t)sandy(&frame->pixels[4 * ((size_t)y * w + x)]);
    *fraction = total ? (float)hits / (float)total : 0.0f;
    *steer = weight > 0.0 ? (float)(sum / weight) : 0.0f;
}

static int is_background(const uint8_t *p, const uint8_t bg[4])
{
    return abs(p[0] - bg[0]) + abs(p[1] - bg[1]) + abs(p[2] - bg[2]) < 24;
}

void asp__exp_features(const asp_image *img, const uint8_t bg[4], exp_features *out)
{
    memset(out, 0, sizeof *out);
    uint32_t w = img->width, h = img->height, x0 = w, y0 = h, x1 = 0, y1 = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            if (!is_background(&img->pixels[4 * ((size_t)y * w + x)], bg)) {
                x0 = x < x0 ? x : x0;
                x1 = x > x1 ? x : x1;
                y0 = y < y0 ? y : y0;
                y1 = y > y1 ? y : y1;
            }
    if (x1 < x0 || (x1 - x0 + 1) * (y1 - y0 + 1) < 4) {
        out->empty = 1;
        return;
    }
    /* the silhouette in its square bounding box (aspect kept), so the size on screen does not matter */
    uint32_t side = (x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0) + 1;
    float cx = 0.5f * (float)(x0 + x1 + 1), cy = 0.5f * (float)(y0 + y1 + 1);
    double count = 0.0;
    for (int j = 0; j < EXP_MASK; j++)
        for (int i = 0; i < EXP_MASK; i++) {
            float fx = cx + ((float)i + 0.5f - 0.5f * EXP_MASK) * (float)side / EXP_MASK;
            float fy = cy + ((float)j + 0.5f - 0.5f * EXP_MASK) * (float)side / EXP_MASK;
            if (fx < 0.0f || fy < 0.0f || fx >= (float)w || fy >= (float)h)
                continue;
            const uint8_t *p = &img->pixels[4 * ((size_t)fy * w + (size_t)fx)];
            out->mask[j * EXP_MASK + i] = (uint8_t)!is_background(p, bg);
        }
    for (uint32_t y = y0; y <= y1; y++)
        for (uint32_t x = x0; x <= x1; x++) {
            const uint8_t *p = &img->pixels[4 * ((size_t)y * w + x)];
            if (is_background(p, bg))
                continue;
            out->hist[(p[0] >> 6) * 16 + (p[1] >> 6) * 4 + (p[2] >> 6)] += 1.0f;
            count += 1.0;
        }
    for (int b = 0; b < EXP_HIST; b++)
        out->hist[b] = count > 0.0 ? (float)(out->hist[b] / count) : 0.0f;
}

float asp__exp_feature_score(const exp_features *a, const exp_features *b)
{
    if (a->empty || b->empty)
        return 0.0f;
    int inter = 0, uni = 0;
    for (int i = 0; i < EXP_MASK * EXP_MASK; i++) {
        inter += a->mask[i] & b->mask[i];
        uni += a->mask[i] | b->mask[i];
    }
    float iou = uni ? (float)inter / (float)uni : 0.0f;
    float hi = 0.0f;
    for (int i = 0; i < EXP_HIST; i++)
        hi += a->hist[i] < b->hist[i] ? a->hist[i] : b->hist[i];
    /* shape decides most: the candidates are animals of similar colours */
    return 0.7f * iou + 0.3f * hi;
}
