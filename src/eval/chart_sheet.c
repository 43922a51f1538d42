/*
 * A contact sheet that says what it shows (issue 29): a grid of equal tiles
 * (asp_image_contact_sheet) gets a white margin on the left with each row's
 * name and one on top with each column's, drawn by PLplot like the charts
 * (src/eval/plot_canvas.c). The tiles are copied back after drawing, so their
 * pixels, alpha included, are exactly the input's.
 */
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

static void copy_sheet(asp_image *dst, const asp_image *sheet, uint32_t left, uint32_t top)
{
    for (uint32_t y = 0; y < sheet->height; y++)
        memcpy(dst->pixels + (((size_t)(y + top) * dst->width) + left) * 4,
               sheet->pixels + (size_t)y * sheet->width * 4, (size_t)sheet->width * 4);
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
    // left margin: the widest row name (at most two tiles wide); top: the title and the most column lines
    double left = 0;
    for (size_t r = 0; desc->row_labels && r < rows; r++) {
        double w = asp__plot_text_width(desc->row_labels[r], px);
        left = w > left ? w : left;
    }
    left = left > 2 * tile_w ? 2 * tile_w : left;
    left += 16;
    int col_lines = 0;
    char lines[MAX_LABEL_LINES][128];
    for (size_t c = 0; desc->col_labels && c < cols; c++) {
        int n = split_lines(desc->col_labels[c], lines);
        col_lines = n > col_lines ? n : col_lines;
    }
    double top = 8 + (desc->title ? 1.5 * (px + 2) : 0) + col_lines * line + 6;
    uint32_t l = (uint32_t)left, t = (uint32_t)top;
    if ((size_t)sheet->width + l > 16384 || (size_t)sheet->height + t > 16384)
        return asp_error_set(err, ASP_EINVAL, "a labelled sheet of %ux%u is too large", sheet->width + l,
                             sheet->height + t);
    asp_image img = {0};
    int rc = asp_image_init(&img, sheet->width + l, sheet->height + t, err);
    if (rc)
        return rc;
    static const uint8_t white[4] = {255, 255, 255, 255};
    asp_image_fill(&img, white);
    copy_sheet(&img, sheet, l, t);
    struct asp__plot p;
    rc = asp__plot_begin(&p, &img, err);
    if (rc) {
        asp_image_release(&img);
        return rc;
    }
    asp__plot_page(img.width, img.height);
    plcol0(1);
    if (desc->title) {
        asp__plot_font(px + 2);
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
            asp__plot_font(fit_px(lines[k], px, tile_w - 6));
            // the lines end just above the tiles
            double y = (double)t - 6 - ((double)(n - k) - 0.5) * line;
            asp__plot_text((double)l + ((double)c + 0.5) * tile_w, y, 0.5, lines[k]);
        }
    }
    asp__plot_end(&p);
    copy_sheet(&img, sheet, l, t); // the tiles exactly as given, alpha included
    *dst = img;
    return 0;
}
