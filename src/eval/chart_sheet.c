/*
 * A contact sheet that says what it shows (issue 29): a grid of equal tiles
 * (asp_image_contact_sheet) gets a white margin on the left with each row's
 * name and one on top with each column's, drawn by PLplot like the charts
 * (src/eval/plot_canvas.c). Columns are as wide as their labels need, so small
 * tiles get white gaps between them. The tiles are copied back after drawing,
 * so their pixels, alpha included, are exactly the input's.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <plplot.h>

#include "eval/plot_canvas.h"
#include "util/banned.h"

enum { MAX_LABEL_LINES = 3 };

/* Splits text at '\n' into at most MAX_LABEL_LINES lines (copies in buf); returns the count. */
static int split_lines(const char *text, char buf[MAX_LABEL_LINES][128])
{
    int n = 0;
    const char *s = text ? text : "";
    while (n < MAX_LABEL_LINES) {
        const char *e = strchr(s, '\n');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        snprintf(buf[n++], 128, "%.*s", (int)(len < 127 ? len : 127), s);
        if (!e)
            break;
        s = e + 1;
    }
    return n;
}

/* Font size for text to fit room pixels: px, or smaller down to 7. */
static double fit_px(const char *text, double px, double room)
{
    double w = asp__plot_text_width(text, px);
    double f = w > room && w > 0 ? px * room / w : px;
    return f < 7 ? 7 : f;
}

/* Tiles of sheet (tile_w x tile_h each) into dst, column c's left edge at left + c * pitch + inset. */
static void copy_tiles(asp_image *dst, const asp_image *sheet, uint32_t tile_w, uint32_t cols, uint32_t left,
                       uint32_t top, uint32_t pitch)
{
    uint32_t inset = (pitch - tile_w) / 2;
    for (uint32_t y = 0; y < sheet->height; y++)
        for (uint32_t c = 0; c < cols; c++)
            memcpy(dst->pixels + (((size_t)(y + top) * dst->width) + left + c * pitch + inset) * 4,
                   sheet->pixels + ((size_t)y * sheet->width + (size_t)c * tile_w) * 4, (size_t)tile_w * 4);
}

int asp_chart_label_sheet(const asp_image *sheet, const asp_chart_sheet_desc *desc, asp_image *dst, asp_error *err)
{
    ASP_ASSERT(sheet && desc && dst);
    size_t rows = desc->row_count, cols = desc->col_count;
    if (!sheet->pixels || !rows || !cols || sheet->width % cols || sheet->height % rows)
        return asp_error_set(err, ASP_EINVAL, "cannot label a %ux%u sheet as %zu rows by %zu columns of equal tiles",
                             sheet->width, sheet->height, rows, cols);
    double tile_w = (double)(sheet->width / cols), tile_h = (double)(sheet->height / rows);
    double px = tile_w >= 96 ? 13 : 11, line = 1.3 * px;
    // left margin: the widest row name (at most 240 pixels; a longer one is drawn smaller)
    double left = 0;
    for (size_t r = 0; desc->row_labels && r < rows; r++) {
        double w = asp__plot_text_width(desc->row_labels[r], px);
        left = w > left ? w : left;
    }
    left = (left > 240 ? 240 : left) + 16;
    // columns as wide as their widest label line (small tiles get gaps between them), at least a tile
    int col_lines = 0;
    char lines[MAX_LABEL_LINES][128];
    double pitch = tile_w;
    for (size_t c = 0; desc->col_labels && c < cols; c++) {
        int n = split_lines(desc->col_labels[c], lines);
        col_lines = n > col_lines ? n : col_lines;
        for (int k = 0; k < n; k++) {
            double w = asp__plot_text_width(lines[k], px) + 8;
            pitch = w > pitch ? w : pitch;
        }
    }
    pitch = pitch > 4 * tile_w ? 4 * tile_w : pitch;
    double top = 8 + (desc->title ? 1.5 * (px + 2) : 0) + col_lines * line + 6;
    uint32_t l = (uint32_t)left, t = (uint32_t)top, pt = (uint32_t)ceil(pitch);
    size_t out_w = l + (size_t)pt * cols + 4, out_h = (size_t)sheet->height + t;
    if (out_w > 16384 || out_h > 16384)
        return asp_error_set(err, ASP_EINVAL, "a labelled sheet of %zux%zu is too large", out_w, out_h);
    asp_image img = {0};
    int rc = asp_image_init(&img, (uint32_t)out_w, (uint32_t)out_h, err);
    if (rc)
        return rc;
    static const uint8_t white[4] = {255, 255, 255, 255};
    asp_image_fill(&img, white);
    copy_tiles(&img, sheet, (uint32_t)tile_w, (uint32_t)cols, l, t, pt);
    struct asp__plot p;
    rc = asp__plot_begin(&p, &img, err);
    if (rc) {
        asp_image_release(&img);
        return rc;
    }
    asp__plot_page(img.width, img.height);
    plcol0(1);
    if (desc->title) {
        asp__plot_font(fit_px(desc->title, px + 2, img.width - 16));
        asp__plot_text(0.5 * img.width, 8 + 0.6 * (px + 2), 0.5, desc->title);
    }
    for (size_t r = 0; desc->row_labels && r < rows; r++) {
        const char *s = desc->row_labels[r] ? desc->row_labels[r] : "";
        asp__plot_font(fit_px(s, px, left - 16));
        asp__plot_text(left - 8, (double)t + ((double)r + 0.5) * tile_h, 1, s);
    }
    for (size_t c = 0; desc->col_labels && c < cols; c++) {
        int n = split_lines(desc->col_labels[c], lines);
        for (int k = 0; k < n; k++) {
            asp__plot_font(fit_px(lines[k], px, pitch - 6));
            // the lines end just above the tiles
            double y = (double)t - 6 - ((double)(n - k) - 0.5) * line;
            asp__plot_text((double)l + ((double)c + 0.5) * pt, y, 0.5, lines[k]);
        }
    }
    asp__plot_end(&p);
    copy_tiles(&img, sheet, (uint32_t)tile_w, (uint32_t)cols, l, t, pt); // the tiles as given, alpha included
    *dst = img;
    return 0;
}
