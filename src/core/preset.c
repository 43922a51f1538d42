/*
 * The seeds' option values as presets (include/amgsplat/preset.h). Each row
 * cites the section that gives the value; docs/seeds.md explains, row by row,
 * why amgsplat's default differs and what was measured.
 */
#include <string.h>

#include "amgsplat/preset.h"
#include "util/banned.h"

#define S(cmd, opt, val, src) {cmd, opt, val, src}

/*
 * Journal 2.1-2.3 (Reniers & Telea 2006). k_min is "50..100" (2.2) and N(x) also takes every point of
 * B_epsilon(x) without a cap (2.1): k-max 1024 is the library's largest neighbourhood. The fans come from
 * that k-closest set (2.2). The journal has no crease cut, no positive-coupling clamp, tau = 0.05 (eq. 8),
 * a level around L-5 (2.3) and the overlap method of Fig. 10 without crease clipping (4).
 */
static const asp_preset_setting journal[] = {
    S("decompose", "classifier", "moment", "journal 2.1 eq. 3"),
    S("decompose", "alpha", "0.01", "journal 2.1"),
    S("decompose", "beta", "100", "journal 2.1"),
    S("decompose", "k", "50", "journal 2.2 (50..100)"),
    S("decompose", "k-max", "1024", "journal 2.1 (all of B_eps)"),
    S("decompose", "fan-k", "50", "journal 2.2"),
    S("decompose", "stiffness", "unclamped", "journal 2.2 eq. 5-7"),
    S("decompose", "crease-cut", "-1", "journal 2.3 (none)"),
    S("decompose", "tau", "0.05", "journal 2.3 eq. 8"),
    S("build", "level", "L-5", "journal 2.3"),
    S("build", "tau", "0.05", "journal 2.3 eq. 8"),
    S("build", "method", "affine", "journal 3.2"),
    S("render", "method", "overlap", "journal 4, Fig. 10"),
    S("render", "overlap-backfaces", NULL, "journal Fig. 10 (pseudocode)"),
    S("render", "crease-angle", "off", "journal 4 (none)"),
    S("view", "method", "overlap", "journal 4, Fig. 10"),
};

/*
 * Thesis (Reniers 2004): surface variation (2.3), thresholded domains with K = 0.01 (2.5), radial basis
 * functions normalised where f >= 1 (3.3.2, eq. 3.3), the overlap method (4.4.4) without crease clipping.
 */
static const asp_preset_setting thesis[] = {
    S("decompose", "classifier", "variation", "thesis 2.3 eq. 2.2"),
    S("decompose", "stiffness", "unclamped", "thesis 2.4"),
    S("decompose", "crease-cut", "-1", "thesis 2.4 (none)"),
    S("decompose", "tau", "0.01", "thesis 2.5 (K)"),
    S("build", "tau", "0.01", "thesis 2.5 (K)"),
    S("build", "method", "radial", "thesis 3.3.2"),
    S("build", "shape", "linear", "thesis 3.3.2"),
    S("build", "normalise", "ge1", "thesis 3.3.2 eq. 3.3"),
    S("build", "normalise-color", NULL, "thesis 3.3.2 eq. 3.3"),
    S("render", "method", "overlap", "thesis 4.4.4"),
    S("render", "overlap-backfaces", NULL, "thesis 4.4.4 (pseudocode)"),
    S("render", "crease-angle", "off", "thesis 4.4 (none)"),
    S("view", "method", "overlap", "thesis 4.4.4"),
};

/*
 * Pajarola, Sainz, Guidotti 2003: psi_E with a = 6, b = 1.5, n = 3 (6, Fig. 20) whose support r = b is the
 * ellipse rim (Fig. 11), tau = 0 (Table 2), one epsilon for all splats (5.3), axes a' = lambda_1, b' =
 * lambda_2 (eq. 5-6).
 */
static const asp_preset_setting pajarola[] = {
    S("render", "renderer", "splat", "seed 001 5"),
    S("render", "kernel", "6,1.5,3", "seed 001 6, Fig. 20"),
    S("render", "kernel-rim", "b", "seed 001 4.2 eq. 12, Fig. 11"),
    S("render", "epsilon-uniform", "0", "seed 001 5.3"),
    S("render", "axes", "lambda", "seed 001 3.4 eq. 5-6"),
    S("render", "tolerance", "0", "seed 001 Table 2"),
    S("render", "crease-angle", "off", "seed 001 (none)"),
    S("view", "renderer", "splat", "seed 001 5"),
};

/* Schwarz 2004: square points on the point-octree (3.2.6). */
static const asp_preset_setting schwarz[] = {
    S("render", "renderer", "square", "seed 004 3.2.6"),
    S("render", "crease-angle", "off", "seed 004 (none)"),
    S("view", "renderer", "square", "seed 004 3.2.6"),
};

static const struct {
    const char *name;
    const asp_preset_setting *settings;
    size_t count;
} presets[ASP_PRESET_COUNT] = {
    [ASP_PRESET_NONE] = {"none", NULL, 0},
    [ASP_PRESET_THESIS] = {"thesis", thesis, sizeof thesis / sizeof thesis[0]},
    [ASP_PRESET_JOURNAL] = {"journal", journal, sizeof journal / sizeof journal[0]},
    [ASP_PRESET_PAJAROLA] = {"pajarola", pajarola, sizeof pajarola / sizeof pajarola[0]},
    [ASP_PRESET_SCHWARZ] = {"schwarz", schwarz, sizeof schwarz / sizeof schwarz[0]},
};

int asp_preset_parse(const char *name, asp_preset *out, asp_error *err)
{
    ASP_ASSERT(out);
    for (int p = 0; name && p < ASP_PRESET_COUNT; p++)
        if (strcmp(presets[p].name, name) == 0) {
            *out = (asp_preset)p;
            return 0;
        }
    return asp_error_set(err, ASP_EINVAL, "unknown preset '%s': expected thesis, journal, pajarola, schwarz or none",
                         name ? name : "(null)");
}

const char *asp_preset_name(asp_preset preset)
{
    return (int)preset >= 0 && preset < ASP_PRESET_COUNT ? presets[preset].name : NULL;
}

const asp_preset_setting *asp_preset_settings(asp_preset preset, size_t *count)
{
    ASP_ASSERT(count);
    if ((int)preset < 0 || preset >= ASP_PRESET_COUNT) {
        *count = 0;
        return NULL;
    }
    *count = presets[preset].count;
    return presets[preset].settings;
}
