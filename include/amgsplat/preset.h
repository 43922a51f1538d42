/*
 * Seed presets: for each seed (thesis, journal, Pajarola et al., Schwarz) the
 * option values its text gives, so a user can reproduce a paper's method with
 * one switch (--preset NAME) and compare it with amgsplat's measured defaults.
 * The values, their sources and why the defaults differ are in docs/seeds.md.
 */
#ifndef AMGSPLAT_PRESET_H
#define AMGSPLAT_PRESET_H

#include <stddef.h>

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One preset per seed; NONE means amgsplat's own defaults. */
typedef enum asp_preset {
    ASP_PRESET_NONE = 0,
    ASP_PRESET_THESIS,   /* Reniers 2004, master's thesis */
    ASP_PRESET_JOURNAL,  /* Reniers & Telea 2006, The Visual Computer */
    ASP_PRESET_PAJAROLA, /* Pajarola, Sainz, Guidotti 2003 (seed 001) */
    ASP_PRESET_SCHWARZ,  /* Schwarz 2004 (seed 004) */
    ASP_PRESET_COUNT
} asp_preset;

/**
 * One setting of a preset. The options are named by the long names of the
 * amgsplat commands' options, the vocabulary docs/seeds.md and the command
 * pages share; a consumer of the library maps them onto its own descs.
 */
typedef struct asp_preset_setting {
    const char *command; /* "decompose", "build", "render" or "view" */
    const char *option;  /* long option name without dashes, e.g. "classifier" */
    const char *value;   /* the seed's value as the option's text; NULL for a flag */
    const char *source;  /* where the seed says so, e.g. "journal 2.1" */
} asp_preset_setting;

/**
 * Parses a preset name ("thesis", "journal", "pajarola", "schwarz"; "none"
 * gives ASP_PRESET_NONE). Returns 0, or ASP_EINVAL naming the text and the
 * valid names (*out unchanged). Thread-safe.
 */
int asp_preset_parse(const char *name, asp_preset *out, asp_error *err);

/** The name of a preset ("none" for ASP_PRESET_NONE, NULL out of range). */
const char *asp_preset_name(asp_preset preset);

/**
 * The settings of preset for every command, in the order they apply; *count
 * receives their number (0 for ASP_PRESET_NONE or out of range, then NULL is
 * returned). The array is static: valid for the life of the process.
 */
const asp_preset_setting *asp_preset_settings(asp_preset preset, size_t *count);

#ifdef __cplusplus
}
#endif
#endif
