/*
 * Line charts, scatter plots with error bars and histograms drawn by PLplot
 * into an asp_image (src/eval/plot_canvas.c): the "quality against primitive
 * count" and "frame time against primitive count" figures of the evaluation
 * (thesis Fig. 1.1 compares exactly these; journal section 5 Table 2) and the
 * experiment's figures (seed 004 Figs 4.1-4.5). Every chart explains itself
 * (issue 29): a title, both axis labels (the y label horizontal, above the
 * axis), at least 3 labelled ticks per axis (src/eval/chart_axis.c), a legend
 * naming each series, and colours from Okabe and Ito's palette for colour
 * blindness ("Color Universal Design", 2002), each series with its own marker
 * shape as well.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <plplot.h>

#include "eval/chart_axis.h"
#include "eval/plot_canvas.h"
#include "util/banned.h"

/*
 * Okabe-Ito without its yellow, which vanishes on white. Series 7 and on take
 * the colours again with dashed lines; the markers differ for 10 series.
 */
enum { NCOLOURS = 7, NMARKERS = 10, FIRST_SERIES_COLOUR = 4, MAX_SERIES = 64 };
static const uint8_t palette[NCOLOURS][3] = {
    {0, 114, 178}, {213, 94, 0}, {0, 158, 115}, {204, 121, 167}, {230, 159, 0}, {86, 180, 233}, {0, 0, 0},
};
static const char *const markers[NMARKERS] = {"●", "■", "▲", "◆", "▼", "◀", "▶", "★", "⬟", "✚"};

struct layout {
    double w, h;          /* image, pixels */
    double x0, y0, x1, y1; /* plot area, pixels from the top left */
    double text_px, title_px;
    double legend_x;      /* left edge of the legend; 0 = none */
};

static void page_view(const struct layout *l)
{
    asp__plot_page(l->w, l->h);
}

static void text_at(double x, double y, double just, const char *text)
{
    asp__plot_text(x, y, just, text);
}

/* Like text_at for labels this file makes (exponents as #u..#d): no escaping. */
static void raw_text_at(double x, double y, double just, const char *s)
{
    plptex(x, y, 1, 0, just, s);
}

static void set_colour(size_t s)
{
    plcol0((PLINT)(FIRST_SERIES_COLOUR + s % NCOLOURS));
    pllsty(s / NCOLOURS % 2 ? 2 : 1); // the second round of colours: dashed
}

static double tx(const struct asp__axis *a, double v)
{
    return a->log ? log10(v) : v;
}

static int usable(double v, int log)
{
    return isfinite(v) && (!log || v > 0);
}

static void draw_series(const asp_chart_series *s, size_t k, const double *y_err, const struct asp__axis *ax,
                        const struct asp__axis *ay, unsigned flags, double marker_px)
{
    set_colour(k);
    plwidth(2);
    PLFLT px[2], py[2];
    int have_prev = 0;
    for (size_t i = 0; i < s->count; i++) {
        double x = s->x[i], y = s->y[i];
        if (!usable(x, ax->log) || !usable(y, ay->log)) {
            have_prev = 0;
            continue;
        }
        px[1] = tx(ax, x);
        py[1] = tx(ay, y);
        if (have_prev && !(flags & ASP_CHART_MARKERS))
            pljoin(px[0], py[0], px[1], py[1]);
        px[0] = px[1];
        py[0] = py[1];
        have_prev = 1;
    }
    pllsty(1);
    plwidth(1.5);
    for (size_t i = 0; y_err && i < s->count; i++) {
        double x = s->x[i], y = s->y[i], e = fabs(y_err[i]);
        if (!usable(x, ax->log) || !usable(y, ay->log) || !isfinite(e) || e == 0)
            continue;
        // on a log axis the lower end may fall below 0: it runs to the bottom of the plot
        PLFLT ex = tx(ax, x), lo = ay->log ? (y - e > 0 ? log10(y - e) : ay->lo) : y - e, hi = tx(ay, y + e);
        plerry(1, &ex, &lo, &hi);
    }
    asp__plot_font(marker_px);
    for (size_t i = 0; i < s->count; i++) {
        double x = s->x[i], y = s->y[i];
        if (usable(x, ax->log) && usable(y, ay->log))
            plstring(1, &(PLFLT){tx(ax, x)}, &(PLFLT){tx(ay, y)}, markers[k % NMARKERS]);
    }
}

/* Smallest spacing of distinct x values within any series: the width of one histogram slot. */
static double bar_slot_width(const asp_chart_series *series, size_t n)
{
    double slot = INFINITY;
    for (size_t s = 0; s < n; s++)
        for (size_t i = 0; i + 1 < series[s].count; i++) {
            double d = fabs(series[s].x[i + 1] - series[s].x[i]);
            if (isfinite(d) && d > 0 && d < slot)
                slot = d;
        }
    return isfinite(slot) ? slot : 1;
}

/* Series k of nseries takes the k-th share of each slot, so bars of several series stand side by side. */
static void draw_bars(const asp_chart_series *s, size_t k, size_t nseries, const double *y_err, double slot)
{
    double w = 0.9 * slot / (double)nseries;
    for (size_t i = 0; i < s->count; i++) {
        double x = s->x[i], y = s->y[i];
        if (!isfinite(x) || !isfinite(y))
            continue;
        double left = x - 0.45 * slot + (double)k * w;
        PLFLT bx[4] = {left, left + w, left + w, left}, by[4] = {0, 0, y, y};
        set_colour(k);
        plfill(4, bx, by);
        if (y_err && isfinite(y_err[i]) && y_err[i] != 0) {
            plcol0(1);
            plerry(1, &(PLFLT){left + 0.5 * w}, &(PLFLT){y - fabs(y_err[i])}, &(PLFLT){y + fabs(y_err[i])});
        }
    }
}

static void layout_chart(struct layout *l, const asp_chart_desc *d, const asp_chart_series *series, size_t n,
                         const struct asp__axis *ay)
{
    l->w = d->width;
    l->h = d->height;
    l->text_px = d->width >= 400 && d->height >= 260 ? 13 : 11;
    l->title_px = l->text_px + 2;
    double line = 1.35 * l->text_px, margin = 8;
    // top: the title, then the y label above the axis; bottom: tick labels, then the x label
    l->y0 = margin + (d->title ? 1.35 * l->title_px : 0) + line + 10;
    l->y1 = l->h - margin - 2 * line - 4;
    double ylab = 0;
    char buf[64];
    for (int i = 0; i < ay->nticks; i++) {
        asp__axis_label(ay, ay->ticks[i], buf, sizeof buf);
        double tw = asp__plot_text_width(buf, l->text_px);
        ylab = tw > ylab ? tw : ylab;
    }
    l->x0 = margin + ylab + 10;
    double legend = 0;
    for (size_t s = 0; s < n; s++)
        if (series[s].name && series[s].name[0]) {
            double tw = 44 + asp__plot_text_width(series[s].name, l->text_px) + 10;
            legend = tw > legend ? tw : legend;
        }
    // the legend takes at most a third of the width, right of the plot, so it never hides data
    if (legend > l->w / 3)
        legend = l->w / 3;
    l->x1 = l->w - margin - (legend > 0 ? legend + 10 : 2.0 * l->text_px);
    l->legend_x = legend > 0 ? l->x1 + 10 : 0;
    l->x0 = round(l->x0);
    l->x1 = round(l->x1);
    l->y0 = round(l->y0);
    l->y1 = round(l->y1);
}

/*
 * The plot area, world coordinates the axes' (log10 on a log axis). Its edges lie on pixel centres
 * (+0.5), so the 1-pixel frame is one crisp row or column rather than two grey ones.
 */
static void plot_view(const struct layout *l, const struct asp__axis *ax, const struct asp__axis *ay)
{
    plvpor((l->x0 + 0.5) / l->w, (l->x1 + 0.5) / l->w, 1 - (l->y1 + 0.5) / l->h, 1 - (l->y0 + 0.5) / l->h);
    plwind(ax->lo, ax->hi, ay->lo, ay->hi);
}

/* Grid, frame, ticks and their labels; the axis labels and the title. */
static void draw_axes(const struct layout *l, const struct asp__axis *ax, const struct asp__axis *ay,
                      const asp_chart_desc *d, const char *const *categories, size_t ncat)
{
    // the plot area: world coordinates are the axes' (log10 on a log axis)
    plot_view(l, ax, ay);
    plwidth(1);
    // grid lines and tick marks on pixel centres: crisp 1-pixel lines
    double gx[ASP__AXIS_MAX_TICKS], gy[ASP__AXIS_MAX_TICKS];
    for (int i = 0; i < ax->nticks; i++) {
        double px = round(l->x0 + (ax->ticks[i] - ax->lo) / (ax->hi - ax->lo) * (l->x1 - l->x0));
        gx[i] = ax->lo + (px - l->x0) / (l->x1 - l->x0) * (ax->hi - ax->lo);
    }
    for (int i = 0; i < ay->nticks; i++) {
        double py = round(l->y1 - (ay->ticks[i] - ay->lo) / (ay->hi - ay->lo) * (l->y1 - l->y0));
        gy[i] = ay->lo + (l->y1 - py) / (l->y1 - l->y0) * (ay->hi - ay->lo);
    }
    plcol0(2);
    for (int i = 0; i < ax->nticks; i++)
        pljoin(gx[i], ay->lo, gx[i], ay->hi);
    for (int i = 0; i < ay->nticks; i++)
        pljoin(ax->lo, gy[i], ax->hi, gy[i]);
    plcol0(1);
    plbox("bc", 0, 0, "bc", 0, 0);
    double tick_x = 5 * (ax->hi - ax->lo) / (l->x1 - l->x0), tick_y = 5 * (ay->hi - ay->lo) / (l->y1 - l->y0);
    for (int i = 0; i < ax->nticks; i++)
        pljoin(gx[i], ay->lo, gx[i], ay->lo + tick_y);
    for (int i = 0; i < ay->nticks; i++)
        pljoin(ax->lo, gy[i], ax->lo + tick_x, gy[i]);
    page_view(l);
    asp__plot_font(l->text_px);
    char buf[64];
    double tick_row = l->y1 + 0.75 * l->text_px + 4;
    for (int i = 0; i < ax->nticks; i++) {
        double px = l->x0 + (ax->ticks[i] - ax->lo) / (ax->hi - ax->lo) * (l->x1 - l->x0);
        double v = ax->ticks[i];
        size_t c = (size_t)llround(v);
        if (categories && fabs(v - (double)c) < 1e-9 && c >= 1 && c <= ncat) {
            text_at(px, tick_row, 0.5, categories[c - 1]);
            continue;
        }
        asp__axis_label(ax, ax->ticks[i], buf, sizeof buf);
        raw_text_at(px, tick_row, 0.5, categories ? "" : buf);
    }
    for (int i = 0; i < ay->nticks; i++) {
        double py = l->y1 - (ay->ticks[i] - ay->lo) / (ay->hi - ay->lo) * (l->y1 - l->y0);
        asp__axis_label(ay, ay->ticks[i], buf, sizeof buf);
        raw_text_at(l->x0 - 6, py, 1, buf);
    }
    double line = 1.35 * l->text_px;
    if (d->x_label)
        text_at(0.5 * (l->x0 + l->x1), tick_row + line, 0.5, d->x_label);
    if (d->y_label)
        text_at(8, l->y0 - 0.5 * line - 8, 0, d->y_label); // horizontal, above the y axis and its top label
    if (d->title) {
        asp__plot_font(l->title_px);
        text_at(0.5 * l->w, 8 + 0.6 * l->title_px, 0.5, d->title);
    }
}

static void draw_legend(const struct layout *l, const asp_chart_series *series, size_t n, unsigned flags)
{
    if (!l->legend_x)
        return;
    double line = 1.5 * l->text_px, x = l->legend_x, y = l->y0 + 2;
    size_t rows = 0;
    for (size_t s = 0; s < n; s++)
        rows += series[s].name && series[s].name[0];
    // a white box with a grey rim
    PLFLT bx[4] = {x, l->w - 8, l->w - 8, x}, by[4] = {y, y, y + (double)rows * line + 8, y + (double)rows * line + 8};
    plcol0(3);
    plfill(4, bx, by);
    plcol0(2);
    plwidth(1);
    plline(4, bx, by);
    pljoin(bx[3], by[3], bx[0], by[0]);
    y += 4 + 0.5 * line;
    for (size_t s = 0; s < n; s++) {
        if (!(series[s].name && series[s].name[0]))
            continue;
        if (flags & ASP_CHART_BARS) {
            PLFLT sx[4] = {x + 8, x + 34, x + 34, x + 8}, sy[4] = {y - 5, y - 5, y + 5, y + 5};
            set_colour(s);
            plfill(4, sx, sy);
        } else {
            set_colour(s);
            plwidth(2);
            if (!(flags & ASP_CHART_MARKERS)) // a scatter plot's series have no lines
                pljoin(x + 6, y, x + 36, y);
            asp__plot_font(0.9 * l->text_px);
            plstring(1, &(PLFLT){x + 21}, &(PLFLT){y}, markers[s % NMARKERS]);
        }
        pllsty(1);
        plcol0(1);
        asp__plot_font(l->text_px);
        char name[128];
        // a name wider than the legend's third of the chart is cut, with an ellipsis
        double room = l->w - 12 - (x + 44);
        snprintf(name, sizeof name, "%s", series[s].name);
        for (size_t len = strlen(name); len > 4 && asp__plot_text_width(name, l->text_px) > room; len--) {
            while (len > 1 && ((unsigned char)name[len - 1] & 0xC0) == 0x80)
                len--; // never split a UTF-8 character
            snprintf(name + len - 1, sizeof name - (len - 1), "…");
        }
        text_at(x + 44, y, 0, name);
        y += line;
    }
}

int asp_chart_draw(const asp_chart_series *series, size_t nseries, const asp_chart_desc *desc, asp_image *dst,
                   asp_error *err)
{
    asp_chart_desc d = desc ? *desc : (asp_chart_desc){0};
    if (!d.width)
        d.width = 560;
    if (!d.height)
        d.height = 340;
    if (d.width < 160 || d.height < 160 || d.width > 4096 || d.height > 4096)
        return asp_error_set(err, ASP_EINVAL, "chart size %ux%u is outside 160..4096", d.width, d.height);
    if (nseries > MAX_SERIES)
        return asp_error_set(err, ASP_EINVAL, "chart of %zu series (at most %d)", nseries, MAX_SERIES);
    for (size_t s = 0; s < nseries; s++)
        if (series[s].count && (!series[s].x || !series[s].y))
            return asp_error_set(err, ASP_EINVAL, "chart series %zu ('%s') has %zu points but no x or y array", s,
                                 series[s].name ? series[s].name : "", series[s].count);
    if (d.x_categories && d.x_category_count == 0)
        return asp_error_set(err, ASP_EINVAL, "chart x categories given but their count is 0");
    int bars = (d.flags & ASP_CHART_BARS) != 0;
    struct asp__axis ax = {.log = (d.flags & ASP_CHART_LOG_X) != 0 && !bars},
                     ay = {.log = (d.flags & ASP_CHART_LOG_Y) != 0 && !bars};
    ax.integer = ((d.flags & ASP_CHART_X_INTEGER) != 0 || d.x_categories) && !ax.log;
    double slot = bars ? bar_slot_width(series, nseries) : 0;
    asp__axis_fit(&ax, series, nseries, NULL, 1, 0, 0, bars, slot);
    asp__axis_fit(&ay, series, nseries, d.y_err, 0, d.y_min, d.y_max, bars, slot);
    if (d.x_categories) {
        // one tick per category, named, over the categories' range whatever the data
        ax.lo = 0.5;
        ax.hi = (double)d.x_category_count + 0.5;
        ax.nticks = 0;
        for (size_t c = 1; c <= d.x_category_count && ax.nticks < ASP__AXIS_MAX_TICKS; c++)
            ax.ticks[ax.nticks++] = (double)c;
    }
    asp_image img = {0};
    int rc = asp_image_init(&img, d.width, d.height, err);
    if (rc)
        return rc;
    static const uint8_t white[4] = {255, 255, 255, 255};
    asp_image_fill(&img, white);
    struct asp__plot p;
    rc = asp__plot_begin(&p, &img, err);
    if (rc) {
        asp_image_release(&img);
        return rc;
    }
    for (int c = 0; c < NCOLOURS; c++)
        plscol0(FIRST_SERIES_COLOUR + c, palette[c][0], palette[c][1], palette[c][2]);
    struct layout l;
    layout_chart(&l, &d, series, nseries, &ay);
    draw_axes(&l, &ax, &ay, &d, d.x_categories, d.x_category_count);
    // the data, clipped to the plot area
    plot_view(&l, &ax, &ay);
    for (size_t s = 0; s < nseries; s++) {
        const double *e = d.y_err ? d.y_err[s] : NULL;
        if (bars)
            draw_bars(&series[s], s, nseries, e, slot);
        else
            draw_series(&series[s], s, e, &ax, &ay, d.flags, 0.8 * l.text_px);
    }
    plcol0(1);
    pllsty(1);
    plwidth(1);
    plbox("bc", 0, 0, "bc", 0, 0); // the frame again, over bars that stand on it
    page_view(&l);
    if (ax.empty || ay.empty) {
        // nothing to draw: say so, rather than leave an empty frame to puzzle over
        plcol0(1);
        asp__plot_font(l.text_px);
        text_at(0.5 * (l.x0 + l.x1), 0.5 * (l.y0 + l.y1), 0.5, nseries ? "no finite data" : "no data");
    }
    draw_legend(&l, series, nseries, d.flags);
    asp__plot_end(&p);
    *dst = img;
    return 0;
}
