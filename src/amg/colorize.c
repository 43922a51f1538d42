/*
 * Colours for looking at a decomposition: the classifier on a blue-to-red map
 * (journal Fig. 1b: creases blue, flat red), and the domains of a level with a
 * distinct colour per basis function mixed by Psi (journal Fig. 5c-d), or the
 * strict domains (thesis Fig. 2.7).
 */
#include <math.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

/* Blue-cyan-green-yellow-red ramp, t in [0,1]. */
static void ramp(double t, double rgb[3])
{
    static const double stops[5][3] = {{0, 0, 1}, {0, 1, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
    if (!(t > 0))
        t = 0;
    if (t > 1)
        t = 1;
    double x = t * 4;
    int i = (int)x;
    if (i > 3)
        i = 3;
    double f = x - i;
    for (int c = 0; c < 3; c++)
        rgb[c] = stops[i][c] * (1 - f) + stops[i + 1][c] * f;
}

/*
 * Colour of basis function k: hues spaced by the golden ratio so that
 * neighbouring indices (which AMG tends to place side by side) differ strongly.
 */
static void domain_colour(size_t k, double rgb[3])
{
    double h = fmod((double)k * 0.6180339887498949 + 0.1, 1.0) * 6.0;
    double s = (k / 7) % 2 ? 0.55 : 0.85, v = (k / 3) % 2 ? 0.8 : 1.0;
    int i = (int)h;
    double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double tab[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
    memcpy(rgb, tab[i % 6], sizeof tab[0]);
}

static uint8_t to_byte(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return (uint8_t)lround(x * 255.0);
}

int asp_amg_colorize(const asp_amg *amg, asp_amg_color_mode mode, size_t level, const asp_context *ctx,
                     uint8_t *rgba, asp_error *err)
{
    const size_t n = amg->cloud->count;
    if (mode == ASP_AMG_COLOR_CLASSIFIER) {
        /* log scale: the classifier spans orders of magnitude between creases and flat parts (journal 2.1) */
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < n; i++) {
            double v = log((double)amg->classifier[i]);
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
        /* the bottom of the ramp is the 2nd percentile, so a few sharp corners do not wash out the creases */
        size_t hist[1024] = {0};
        if (hi > lo) {
            for (size_t i = 0; i < n; i++) {
                size_t b = (size_t)((log((double)amg->classifier[i]) - lo) / (hi - lo) * 1023.0);
                hist[b > 1023 ? 1023 : b]++;
            }
            size_t acc = 0, b = 0;
            while (b < 1023 && (acc += hist[b]) < n / 50)
                b++;
            lo += (hi - lo) * (double)b / 1023.0;
        }
        for (size_t i = 0; i < n; i++) {
            double rgb[3];
            ramp(hi > lo ? (log((double)amg->classifier[i]) - lo) / (hi - lo) : 1.0, rgb);
            for (int c = 0; c < 3; c++)
                rgba[4 * i + c] = to_byte(rgb[c]);
            rgba[4 * i + 3] = 255;
        }
        return 0;
    }
    if (mode != ASP_AMG_COLOR_DOMAINS && mode != ASP_AMG_COLOR_STRICT)
        return asp_error_set(err, ASP_EINVAL, "invalid colour mode %d", (int)mode);
    asp_amg_csr *psi;
    int rc = asp_amg_basis(amg, level, ctx, &psi, err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++) {
        double acc[3] = {0, 0, 0}, rgb[3];
        if (mode == ASP_AMG_COLOR_STRICT) {
            asp_index label;
            asp_amg_csr row = *psi;
            row.rows = 1;
            row.row_ptr = psi->row_ptr + i;
            asp_amg_strict_domains(&row, &label);
            domain_colour(label, acc);
        } else {
            /* Psi is a partition of unity, so the mix stays a convex combination (journal Fig. 5: colours mix) */
            for (size_t k = psi->row_ptr[i]; k < psi->row_ptr[i + 1]; k++) {
                domain_colour(psi->col[k], rgb);
                for (int c = 0; c < 3; c++)
                    acc[c] += psi->val[k] * rgb[c];
            }
        }
        for (int c = 0; c < 3; c++)
            rgba[4 * i + c] = to_byte(acc[c]);
        rgba[4 * i + 3] = 255;
    }
    asp_amg_csr_destroy(psi);
    return 0;
}
