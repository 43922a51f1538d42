/* PLplot drawing into an asp_image (src/eval/plot_canvas.c); private to the eval module. */
#ifndef ASP_EVAL_PLOT_CANVAS_H
#define ASP_EVAL_PLOT_CANVAS_H

#include <stddef.h>

#include "amgsplat/eval.h"

struct asp__plot {
    asp_image *img;
    int old_stream;
};

/*
 * Opens a PLplot stream drawing over img's pixels (kept: PLplot draws on top)
 * and holds the PLplot lock until asp__plot_end. Colour map 0: 0 white,
 * 1 ink, 2 grid grey, 3 white (legend box). Returns 0 or ASP_EUNSUPPORTED
 * (the memcairo driver is missing; then nothing is held).
 */
int asp__plot_begin(struct asp__plot *p, asp_image *img, asp_error *err);
/* Sets the text size so that a line of text is about px pixels tall. */
void asp__plot_font(double px);
/* Ends the stream (the pixels now hold the drawing, alpha 255) and releases the lock. */
void asp__plot_end(struct asp__plot *p);
/* text with PLplot's escape character '#' doubled, into dst (cap bytes); returns dst. */
char *asp__plot_escape(char *dst, size_t cap, const char *text);
/* Estimated width in pixels of text drawn at px (a little generous, so that layouts leave room). */
double asp__plot_text_width(const char *text, double px);
/* World coordinates = the image's pixels, origin at the top left, over the whole image. */
void asp__plot_page(double width, double height);
/* Draws text (escaped) horizontally, its vertical middle at y; just 0 left, 0.5 centre, 1 right of x. */
void asp__plot_text(double x, double y, double just, const char *text);

#endif
