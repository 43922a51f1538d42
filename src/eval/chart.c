/*
 * Line charts drawn on the CPU into an asp_image: the "quality against
 * primitive count" and "frame time against primitive count" figures the
 * evaluation shows (thesis Fig. 1.1 compares exactly these; journal section 5
 * Table 2). Text comes from stb_easy_font's quads, rasterised as rectangles.
 * Scatter plots with error bars and histograms draw the experiment's figures
 * (seed 004 Figs 4.1-4.5).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/eval.h"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "util/banned.h"

enum { MAX_TICKS = 32, FONT_H = 7 };

// 12 colours: an evaluation with a mesh draws up to 10 series, each needs its own
static const uint8_t palette[12][3] = {
    {31, 119, 180}, {214, 39, 40}, {44, 160, 44}, {255, 127, 14}, {148, 103, 189}, {140, 86, 75},
    {227, 119, 194}, {23, 190, 207}, {188, 189, 34}, {0, 0, 0}, {127, 127, 127}, {255, 187, 120},
};

struct canvas {
    asp_image *img;
};

static void put(const struct canvas *c, long x, long y, const uint8_t rgb[3])
{
    if (x < 0 || y < 0 || x >= (long)c->img->width || y >= (long)c->img->height)
        return;
    uint8_t *p = c->img->pixels + ((size_t)y * c->img->width + (size_t)x) * 4;
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
    p[3] = 255;
}

static void rect(const struct canvas *c, long x0, long y0, long x1, long y1, const uint8_t rgb[3])
{
    for (long y = y0; y < y1; y++)
        for (long x = x0; x < x1; x++)
            put(c, x, y, rgb);
}

/* Bresenham with a 2x2 pen so lines read at a glance on small charts. */
static void line(const struct canvas *c, long x0, long y0, long x1, long y1, int thick, const uint8_t rgb[3])
{
    long dx = labs(x1 - x0), dy = -labs(y1 - y0);
    long sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1, e = dx + dy;
    for (long guard = 0; guard < 100000; guard++) {
        if (thick)
            rect(c, x0, y0, x0 + 2, y0 + 2, rgb);
        else
            put(c, x0, y0, rgb);
        if (x0 == x1 && y0 == y1)
            break;
        long e2 = 2 * e;
        if (e2 >= dy) {
            e += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            e += dx;
            y0 += sy;
        }
    }
}

/* stb_easy_font takes a mutable string; copy the (short) label. */
static int text_width(const char *s)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    return stb_easy_font_width(buf);
}

static void text(const struct canvas *c, long x, long y, const char *s, const uint8_t rgb[3])
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    // about 270 bytes per character (stb_easy_font.h); 256 characters at most
    static const int cap = 256 * 300;
    float verts[256 * 300 / 4];
    int quads = stb_easy_font_print((float)x, (float)y, buf, NULL, verts, cap);
    for (int q = 0; q < quads; q++) {
        const float *v = verts + q * 16; // 4 vertices of 16 bytes: x y z rgba
        long qx0 = lrintf(v[0]), qy0 = lrintf(v[1]), qx1 = lrintf(v[8]), qy1 = lrintf(v[9]);
        rect(c, qx0, qy0, qx1, qy1, rgb);
    }
}

/* Vertical text: letters stacked, so the y label needs no rotation. */
static void text_vertical(const struct canvas *c, long x, long y, const char *s, const uint8_t rgb[3])
{
    for (size_t i = 0; s[i] && i < 64; i++) {
        char ch[2] = {s[i], 0};
        text(c, x, y + (long)i * (FONT_H + 2), ch, rgb);
    }
}

struct axis {
    double lo, hi;
    int log;
    int integer; /* ticks at whole numbers only */
    double ticks[MAX_TICKS];
    int nticks;
};

static double nice_step(double range)
{
    double raw = range / 5, mag = pow(10, floor(log10(raw))), f = raw / mag;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

static void axis_ticks(struct axis *a)
{
    a->nticks = 0;
    if (a->log) {
        double d0 = floor(a->lo), d1 = ceil(a->hi);
        int per_decade = d1 - d0 <= 2 ? 3 : 1; // 1, 2, 5 on short log axes
        static const double steps[3] = {1, 2, 5};
        for (double d = d0; d <= d1 && a->nticks < MAX_TICKS; d++)
            for (int k = 0; k < per_decade && a->nticks < MAX_TICKS; k++) {
                double v = log10(steps[k]) + d;
                if (v >= a->lo - 1e-9 && v <= a->hi + 1e-9)
                    a->ticks[a->nticks++] = v;
            }
        return;
    }
    double step = nice_step(a->hi - a->lo);
    if (a->integer && step < 1)
        step = 1;
    for (double v = ceil(a->lo / step - 1e-9) * step; v <= a->hi + 1e-9 * step && a->nticks < MAX_TICKS; v += step)
        a->ticks[a->nticks++] = fabs(v) < 1e-12 * step ? 0 : v;
}

static int usable(double v, int log)
{
    return isfinite(v) && (!log || v > 0);
}

static void axis_range(struct axis *a, const asp_chart_series *series, size_t n, const double *const *y_err,
                       int use_x, double fixed_lo, double fixed_hi, int bars, double bar_slot)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t s = 0; s < n; s++)
        for (size_t i = 0; i < series[s].count; i++) {
            double v = use_x ? series[s].x[i] : series[s].y[i];
            double other = use_x ? series[s].y[i] : series[s].x[i];
            if (!usable(v, a->log) || !isfinite(other))
                continue;
            // error bars and bars (from 0) must fit inside the y range too
            double e = !use_x && y_err && y_err[s] && isfinite(y_err[s][i]) ? fabs(y_err[s][i]) : 0;
            double vlo = v - e, vhi = v + e;
            if (!use_x && bars)
                vlo = vlo < 0 ? vlo : 0;
            if (a->log) {
                vlo = usable(vlo, 1) ? log10(vlo) : log10(v);
                vhi = log10(vhi);
            }
            lo = vlo < lo ? vlo : lo;
            hi = vhi > hi ? vhi : hi;
        }
    if (use_x && bars && lo <= hi) {
        lo -= 0.5 * bar_slot;
        hi += 0.5 * bar_slot;
    }
    if (!use_x && fixed_lo < fixed_hi && !a->log) {
        lo = fixed_lo;
        hi = fixed_hi;
    } else if (!(lo <= hi)) {
        lo = 0;
        hi = 1;
    } else if (hi - lo < 1e-12 * (fabs(lo) + 1)) {
        lo -= a->log ? 0.5 : 0.5 * (fabs(lo) > 0 ? fabs(lo) : 1);
        hi += a->log ? 0.5 : 0.5 * (fabs(hi) > 0 ? fabs(hi) : 1);
    } else {
        double pad = 0.05 * (hi - lo);
        // a histogram's bars stand on the x axis: no padding below 0
        lo = bars && !use_x && lo == 0 ? 0 : lo - pad;
        hi += pad;
    }
    a->lo = lo;
    a->hi = hi;
    axis_ticks(a);
}

static void tick_label(char *buf, size_t cap, double v, int log)
{
    double x = log ? pow(10, v) : v;
    if (fabs(x) >= 1e5 || (fabs(x) < 1e-3 && x != 0))
        snprintf(buf, cap, "%.0e", x);
    else
        snprintf(buf, cap, "%.4g", x);
}

struct plot {
    long x0, y0, x1, y1; // plot area, pixels; y0 top
    struct axis ax, ay;
};

static long map_x(const struct plot *p, double v)
{
    return p->x0 + lrint((v - p->ax.lo) / (p->ax.hi - p->ax.lo) * (double)(p->x1 - p->x0));
}

static long map_y(const struct plot *p, double v)
{
    return p->y1 - lrint((v - p->ay.lo) / (p->ay.hi - p->ay.lo) * (double)(p->y1 - p->y0));
}

static void draw_axes(const struct canvas *c, const struct plot *p, const asp_chart_desc *d)
{
    static const uint8_t grid[3] = {225, 225, 225}, ink[3] = {40, 40, 40};
    char buf[32];
    for (int i = 0; i < p->ay.nticks; i++) {
        long y = map_y(p, p->ay.ticks[i]);
        line(c, p->x0, y, p->x1, y, 0, grid);
        tick_label(buf, sizeof buf, p->ay.ticks[i], p->ay.log);
        text(c, p->x0 - 6 - text_width(buf), y - FONT_H / 2 - 1, buf, ink);
    }
    for (int i = 0; i < p->ax.nticks; i++) {
        long x = map_x(p, p->ax.ticks[i]);
        line(c, x, p->y0, x, p->y1, 0, grid);
        tick_label(buf, sizeof buf, p->ax.ticks[i], p->ax.log);
        text(c, x - text_width(buf) / 2, p->y1 + 6, buf, ink);
    }
    line(c, p->x0, p->y1, p->x1, p->y1, 0, ink);
    line(c, p->x0, p->y0, p->x0, p->y1, 0, ink);
    if (d->title)
        text(c, (p->x0 + p->x1) / 2 - text_width(d->title) / 2, 6, d->title, ink);
    if (d->x_label)
        text(c, (p->x0 + p->x1) / 2 - text_width(d->x_label) / 2, p->y1 + 20, d->x_label, ink);
    if (d->y_label) {
        long len = (long)strlen(d->y_label);
        text_vertical(c, 4, (p->y0 + p->y1) / 2 - len * (FONT_H + 2) / 2, d->y_label, ink);
    }
}

static double clamp_y(const struct plot *p, double y)
{
    return y < p->ay.lo ? p->ay.lo : y > p->ay.hi ? p->ay.hi : y;
}

/* Vertical error bar with caps; on a log axis the lower end may fall below 0 and is clamped. */
static void draw_error_bar(const struct canvas *c, const struct plot *p, long cx, double y, double e,
                           const uint8_t rgb[3])
{
    double y0 = y - e, y1 = y + e;
    y0 = p->ay.log ? (y0 > 0 ? log10(y0) : p->ay.lo) : y0;
    y1 = p->ay.log ? log10(y1) : y1;
    long a = map_y(p, clamp_y(p, y0)), b = map_y(p, clamp_y(p, y1));
    line(c, cx, a, cx, b, 0, rgb);
    line(c, cx - 3, a, cx + 3, a, 0, rgb);
    line(c, cx - 3, b, cx + 3, b, 0, rgb);
}

static void draw_series(const struct canvas *c, const struct plot *p, const asp_chart_series *s, const double *y_err,
                        const uint8_t rgb[3], unsigned flags)
{
    int have_prev = 0;
    long px = 0, py = 0;
    for (size_t i = 0; i < s->count; i++) {
        double x = s->x[i], y = s->y[i];
        if (!usable(x, p->ax.log) || !usable(y, p->ay.log)) {
            have_prev = 0;
            continue;
        }
        x = p->ax.log ? log10(x) : x;
        double yv = y;
        y = p->ay.log ? log10(y) : y;
        // clamp to the plot so a fixed y range never draws outside it
        y = clamp_y(p, y);
        long cx = map_x(p, x), cy = map_y(p, y);
        if (have_prev && !(flags & ASP_CHART_MARKERS))
            line(c, px, py, cx, cy, 1, rgb);
        rect(c, cx - 2, cy - 2, cx + 4, cy + 4, rgb);
        if (y_err && isfinite(y_err[i]) && y_err[i] != 0)
            draw_error_bar(c, p, cx + 1, yv, fabs(y_err[i]), rgb);
        px = cx;
        py = cy;
        have_prev = 1;
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
static void draw_bars(const struct canvas *c, const struct plot *p, const asp_chart_series *s, const double *y_err,
                      size_t k, size_t nseries, double slot, const uint8_t rgb[3])
{
    double w = 0.9 * slot / (double)nseries;
    for (size_t i = 0; i < s->count; i++) {
        double x = s->x[i], y = s->y[i];
        if (!isfinite(x) || !isfinite(y))
            continue;
        double left = x - 0.45 * slot + (double)k * w;
        long x0 = map_x(p, left), x1 = map_x(p, left + w);
        long y0 = map_y(p, clamp_y(p, 0)), y1 = map_y(p, clamp_y(p, y));
        if (x1 <= x0)
            x1 = x0 + 1;
        rect(c, x0, y1 < y0 ? y1 : y0, x1, (y1 < y0 ? y0 : y1) + 1, rgb);
        if (y_err && isfinite(y_err[i]) && y_err[i] != 0)
            draw_error_bar(c, p, (x0 + x1) / 2, y, fabs(y_err[i]), (const uint8_t[3]){40, 40, 40});
    }
}

static void draw_legend(const struct canvas *c, const struct plot *p, const asp_chart_series *series, size_t n)
{
    static const uint8_t ink[3] = {40, 40, 40}, box[3] = {250, 250, 250};
    int w = 0, rows = 0;
    for (size_t s = 0; s < n; s++)
        if (series[s].name && series[s].name[0]) {
            int tw = text_width(series[s].name);
            w = tw > w ? tw : w;
            rows++;
        }
    if (!rows)
        return;
    // right of the plot area (asp_chart_draw leaves the room), so it never hides data
    long x = p->x1 + 10, y = p->y0 + 4;
    rect(c, x - 4, y - 3, x + w + 22, y + rows * 12 + 1, box);
    for (size_t s = 0; s < n; s++) {
        if (!(series[s].name && series[s].name[0]))
            continue;
        rect(c, x, y + 2, x + 14, y + 5, palette[s % 12]);
        text(c, x + 18, y, series[s].name, ink);
        y += 12;
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
    for (size_t s = 0; s < nseries; s++)
        if (series[s].count && (!series[s].x || !series[s].y))
            return asp_error_set(err, ASP_EINVAL, "chart series %zu ('%s') has %zu points but no x or y array", s,
                                 series[s].name ? series[s].name : "", series[s].count);
    asp_image img = {0};
    int rc = asp_image_init(&img, d.width, d.height, err);
    if (rc)
        return rc;
    static const uint8_t white[4] = {255, 255, 255, 255};
    asp_image_fill(&img, white);
    struct canvas c = {&img};
    int legend = 0;
    for (size_t s = 0; s < nseries; s++)
        if (series[s].name && series[s].name[0]) {
            int tw = text_width(series[s].name) + 36;
            legend = tw > legend ? tw : legend;
        }
    // the legend takes at most a third of the width
    if (legend > (int)d.width / 3)
        legend = (int)d.width / 3;
    struct plot p = {.x0 = 58, .y0 = 22, .x1 = (long)d.width - 14 - legend, .y1 = (long)d.height - 34};
    int bars = (d.flags & ASP_CHART_BARS) != 0;
    p.ax.log = (d.flags & ASP_CHART_LOG_X) != 0 && !bars;
    p.ay.log = (d.flags & ASP_CHART_LOG_Y) != 0 && !bars;
    p.ax.integer = (d.flags & ASP_CHART_X_INTEGER) != 0 && !p.ax.log;
    double slot = bars ? bar_slot_width(series, nseries) : 0;
    axis_range(&p.ax, series, nseries, NULL, 1, 0, 0, bars, slot);
    axis_range(&p.ay, series, nseries, d.y_err, 0, d.y_min, d.y_max, bars, slot);
    draw_axes(&c, &p, &d);
    for (size_t s = 0; s < nseries; s++) {
        const double *e = d.y_err ? d.y_err[s] : NULL;
        if (bars)
            draw_bars(&c, &p, &series[s], e, s, nseries, slot, palette[s % 12]);
        else
            draw_series(&c, &p, &series[s], e, palette[s % 12], d.flags);
    }
    draw_legend(&c, &p, series, nseries);
    *dst = img;
    return 0;
}
