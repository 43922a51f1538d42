/*
 * The one door to PLplot (Debian libplplot, the plotting library the charts
 * and the labelled contact sheet draw with; issue 29): its "memcairo" driver
 * (Debian plplot-driver-cairo) draws with cairo, anti-aliased and with real
 * fonts, straight into an asp_image's RGBA pixels, in this process. PLplot
 * never touches a file here: the caller saves the image with
 * asp_image_save_png, the project's atomic write (temporary file, read back,
 * rename), where the pngcairo driver would write the PNG in place with
 * cairo_surface_write_to_png.
 *
 * PLplot keeps its streams in process-wide state (the current stream plsc), so
 * one mutex serialises every drawing: that is what keeps asp_chart_draw thread
 * safe. plinit() calls plexit(), which exits the process, when the driver is
 * missing; the driver list is checked first so the library returns an error
 * instead.
 */
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include <plplot.h>

#include "eval/plot_canvas.h"
#include "util/banned.h"

static pthread_mutex_t plot_mutex = PTHREAD_MUTEX_INITIALIZER;

enum { MAX_DEVICES = 64 };

/* 1 if PLplot lists the memcairo driver (plplot-driver-cairo is installed). */
static int have_memcairo(void)
{
    const char *menu[MAX_DEVICES], *names[MAX_DEVICES];
    const char **pm = menu, **pn = names;
    int n = MAX_DEVICES;
    plgDevs(&pm, &pn, &n);
    for (int i = 0; i < n && i < MAX_DEVICES; i++)
        if (pn[i] && strcmp(pn[i], "memcairo") == 0)
            return 1;
    return 0;
}

int asp__plot_begin(struct asp__plot *p, asp_image *img, asp_error *err)
{
    ASP_ASSERT(p && img && img->pixels);
    pthread_mutex_lock(&plot_mutex);
    if (!have_memcairo()) {
        pthread_mutex_unlock(&plot_mutex);
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "PLplot has no 'memcairo' driver: install plplot-driver-cairo (scripts/bootstrap.sh)");
    }
    p->img = img;
    PLINT old = 0, strm = 0;
    plgstrm(&old);
    p->old_stream = old;
    plmkstrm(&strm); // a stream of our own: a host program's PLplot stream stays as it was
    plsdev("memcairo");
    plsmema((PLINT)img->width, (PLINT)img->height, img->pixels); // drawn over what the pixels hold
    // colour map 0: 0 background, 1 ink, 2 grid, 3 legend box; the caller sets the series colours from 4 on
    plscol0(0, 255, 255, 255);
    plinit();
    plscol0(1, 40, 40, 40);
    plscol0(2, 222, 222, 222);
    plscol0(3, 255, 255, 255);
    pladv(0);
    return 0;
}

void asp__plot_font(double px)
{
    // plschr takes the character height in mm, and the cairo drivers run at 72 dpi (1 mm = 72 / 25.4
    // pixels); a line of DejaVu Sans comes out about 1.4 times that height, measured
    plschr((PLFLT)(px / 1.4 * 25.4 / 72.0), 1.0);
}

void asp__plot_end(struct asp__plot *p)
{
    plend1();
    plsstrm((PLINT)p->old_stream);
    // memcairo draws on cairo's RGB24 surface, whose fourth byte is undefined: the image is opaque
    size_t n = (size_t)p->img->width * p->img->height;
    for (size_t i = 0; i < n; i++)
        p->img->pixels[4 * i + 3] = 255;
    pthread_mutex_unlock(&plot_mutex);
}

char *asp__plot_escape(char *dst, size_t cap, const char *text)
{
    // '#' starts PLplot's escape sequences (#u superscript, ...); "##" is a literal '#'
    size_t k = 0;
    for (const char *s = text ? text : ""; *s && k + 2 < cap; s++) {
        if (*s == '#')
            dst[k++] = '#';
        dst[k++] = *s;
    }
    dst[k < cap ? k : cap - 1] = 0;
    return dst;
}

double asp__plot_text_width(const char *text, double px)
{
    // DejaVu Sans averages about 0.6 em a character; the escapes #u and #d take no room
    double n = 0;
    for (const unsigned char *c = (const unsigned char *)(text ? text : ""); *c; c++) {
        if (c[0] == '#' && (c[1] == 'u' || c[1] == 'd')) {
            c++;
            continue;
        }
        n += (*c & 0xC0) != 0x80; // one per UTF-8 character
    }
    return n * 0.6 * px;
}

void asp__plot_page(double width, double height)
{
    plvpor(0, 1, 0, 1);
    plwind(0, width, height, 0); // y down, as in the image
}

void asp__plot_text(double x, double y, double just, const char *text)
{
    char buf[512];
    plptex(x, y, 1, 0, just, asp__plot_escape(buf, sizeof buf, text)); // (x, y): the text's vertical middle
}
