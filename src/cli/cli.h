/*
 * Shared CLI plumbing: the environment every subcommand receives, the option
 * parser, error printing and the terminal progress bar. Only src/cli/ prints.
 */
#ifndef ASP_CLI_H
#define ASP_CLI_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cjson/cJSON.h>

#include "amgsplat/amgsplat.h"

struct cli_progress_state {
    double start;
    double last_draw;
    char stage[48];
    int drawn;
};

struct cli_env {
    const char *cmd;     /* subcommand name, for messages */
    asp_context ctx;     /* threads and progress set from the common options */
    int quiet;           /* --quiet: no progress, no chatter */
    int json;            /* --json: machine-readable output on stdout */
    int threads;         /* --threads N (0 = all) */
    const void *preset_values[32]; /* option values set by --preset and not given explicitly */
    size_t preset_count;
    const void *given_values[32]; /* option values given on the command line (cli_given) */
    size_t given_count;
    struct cli_progress_state progress;
};

enum cli_opt_type { CLI_FLAG, CLI_INT, CLI_SIZE, CLI_DOUBLE, CLI_STRING };

/*
 * One option. value points to: int (FLAG sets 1, INT), size_t (SIZE),
 * double (DOUBLE), const char * (STRING). Table ends with a zero entry.
 */
struct cli_option {
    const char *name;   /* long name without dashes, e.g. "points" */
    char short_name;    /* e.g. 'o', or 0 */
    enum cli_opt_type type;
    void *value;
    const char *arg;    /* argument placeholder in help, e.g. "N" */
    const char *help;
};

/*
 * Parses argv (argv[0] is the subcommand name). Every subcommand also gets
 * -h/--help, -q/--quiet, --json and --threads N. Positional arguments are
 * compacted to the front of argv; *npos receives their count.
 * Returns 0 to go on, 1 when help was printed (exit 0), -1 on a usage error
 * (already printed; exit 2).
 */
int cli_parse(int argc, char **argv, const struct cli_option *opts, const char *usage, struct cli_env *env,
              int *npos);

/*
 * 1 when the option whose value field is `value` holds a --preset value (not given on the command
 * line), so a command may drop a preset setting that does not apply to its input (a .dps method for
 * points) instead of refusing it as it refuses the same option given by hand.
 */
int cli_from_preset(const struct cli_env *env, const void *value);

/*
 * 1 when the option whose value field is `value` was given on the command line, so a command can
 * refuse a given value that its default sentinel shares (--las-scale 0, --points 0) instead of
 * falling back to the default (issue #31).
 */
int cli_given(const struct cli_env *env, const void *value);

/* Prints "amgsplat CMD: error: MSG" and returns exit status 1. */
int cli_fail(const struct cli_env *env, const asp_error *err);
/* Prints a formatted usage error and returns exit status 2. */
int cli_usage_error(const struct cli_env *env, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Informational line on stderr unless --quiet. */
void cli_info(const struct cli_env *env, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* The views render draws of a streamed .hier (render_streamed.c), as render_views makes its cameras. */
struct cli_streamed_view {
    size_t views;
    double az, el, dist, fov, tau; /* tau <= 0: 1 pixel */
    asp_up_axis up;
    int up_given; /* else the file's own up axis (z for a LAS source) */
    uint32_t width, height;
    size_t memory; /* bytes; 0 = 2 GiB */
};
struct cli_streamed_stats {
    size_t nodes, node_count;
    uint64_t points, point_count, budget;
    double load_seconds;
};
/*
 * Opens the streamed hierarchy at path, selects each view's cut and loads their union into s (a
 * point scene framed by the file's frame; release with asp_scene_release). Returns the library's errors.
 */
int cli_render_streamed(const char *path, const struct cli_streamed_view *v, const asp_context *ctx, asp_scene *s,
                        struct cli_streamed_stats *st, asp_error *err);

/* --memory SIZE (bytes, K/M/G/T suffixes of 1024) into *out; a usage error (returns 2) when malformed. */
int cli_memory_option(struct cli_env *env, const char *text, size_t *out);

/* Ends a progress bar line if one is drawn (call before printing results). */
void cli_progress_end(struct cli_env *env);

/*
 * Output checks shared by the commands that write files (issue #13): refuses
 * (usage error, 2) an output that is the same file as an input (same device
 * and inode, so "./in.ply" and links are caught) and an output whose
 * extension names another format than `format` (a recogniser format name:
 * "amg", "dps", "png"). A name without extension is accepted when
 * allow_bare is set. Returns 0 when the output is fine.
 */
int cli_check_output(const struct cli_env *env, const char *output, const char *format, int allow_bare,
                     const char *const *inputs, size_t ninputs);

/*
 * The options that pick and steer a renderer, declared once for render, view and eval (issue 26):
 * renderer_options.c holds their names, placeholders, help and checks. A command takes the ones its
 * mask names: cli_renderer_opts_init, cli_renderer_rows into its option table, cli_parse, then
 * cli_renderer_check; what depends on the input (which renderer, which level) stays the command's.
 * Each old spelling is accepted by every command that takes the option: --tau = --tolerance (view's
 * name), --color = --color-by (view's name); giving both spellings is a usage error.
 */
enum cli_renderer_option {
    CLI_RO_RENDERER = 1u << 0,    /* --renderer NAME */
    CLI_RO_TOLERANCE = 1u << 1,   /* --tolerance PX, --tau PX */
    CLI_RO_BUDGET = 1u << 2,      /* --budget N */
    CLI_RO_LEVEL = 1u << 3,       /* --level L */
    CLI_RO_COLOR_BY = 1u << 4,    /* --color-by MODE, --color MODE */
    CLI_RO_METHOD = 1u << 5,      /* --method NAME (.dps blending) */
    CLI_RO_ALPHA_REF = 1u << 6,   /* --alpha-ref X */
    CLI_RO_CREASE = 1u << 7,      /* --crease-angle DEG|off */
    CLI_RO_HYBRID = 1u << 8,      /* --hybrid */
    CLI_RO_CULL = 1u << 9,        /* --cull-backfaces */
    CLI_RO_DEPTH_LIMIT = 1u << 10, /* --depth-limit N */
    CLI_RO_FRAME_MS = 1u << 11,   /* --frame-ms T */
    CLI_RO_UNLIT = 1u << 12,      /* --unlit */
    CLI_RO_TEXTURE = 1u << 13,    /* --texture IMG */
    CLI_RO_EDL = 1u << 14         /* --edl, --no-edl, --edl-strength S */
};

struct cli_renderer_opts {
    /* as given; NULL, NaN (the parser refuses non-finite numbers) or 0 when not */
    const char *renderer, *level, *color_by, *color, *method, *crease_angle, *texture;
    double tolerance, tau, alpha_ref, frame_ms;
    size_t budget, depth_limit;
    int hybrid, cull_backfaces, unlit;
    int edl, no_edl;                 /* eye-dome lighting forced on or off; default: on for points without normals */
    double edl_strength;             /* NaN: not given (1); implies edl */
    /* set by cli_renderer_check */
    const char *tolerance_name;      /* "--tolerance" or "--tau", as given, for the command's messages */
    const char *color_by_name;       /* "--color-by" or "--color" */
    int has_color;                   /* a colour mode was given: color_mode holds it */
    asp_scene_amg_color color_mode;  /* classifier, domains (or "domain"), strict, input */
    const char *color_field;         /* a point file's scalar: elevation, classification, prop:NAME (asp_cloud_color_by) */
    asp_prim_render_method method_kind; /* when method */
    float alpha_ref_lib;             /* asp_prim_render_options.alpha_ref (-1: exactly 0) when alpha_ref */
    double crease;                   /* degrees in (0, 180); -1 = off; 0 = not given */
};

/* The "not given" state of every field. */
void cli_renderer_opts_init(struct cli_renderer_opts *o);
/*
 * Appends the rows of the options in `which` (CLI_RO_* bits), aliases included, to the option table
 * rows (capacity cap entries, zero-terminated; stays so). The table then points into o.
 */
void cli_renderer_rows(struct cli_renderer_opts *o, unsigned which, struct cli_option *rows, size_t cap);
/*
 * Checks what was given of the options in `which` and sets the fields below the line; tolerance
 * takes tau when that spelling was given. Returns 0, or 2 after printing the usage error.
 */
int cli_renderer_check(const struct cli_env *env, struct cli_renderer_opts *o, unsigned which);

/* Parses "a,b[,c]" doubles into out (up to max); returns how many, -1 on junk. */
int cli_parse_doubles(const char *s, double *out, int max);
/* Parses --up: "y", "z", "x", "-y", "-z" or "-x" ("+y" = "y"); returns 0 or -1. */
int cli_parse_up(const char *s, asp_up_axis *out);

/*
 * --view AZ,EL[,DIST] of render and view: AZ in -36000..36000 degrees, EL in -90..90, DIST in
 * (0, 1e6] bounding-sphere radii (0 when not given: fit). Prints the usage error and returns 2.
 */
int cli_parse_view(struct cli_env *env, const char *s, double *az, double *el, double *dist);
/*
 * The one colour grammar (--background of render, view and imgdiff; issue 26), the union of what each
 * accepted before: "R,G,B" or "R,G,B,A", each channel a number in 0..255 as every list option reads it
 * (cli_parse_doubles: 255, 255.0, 2.55e2; a fraction is rounded to the nearest level), or "#RRGGBB" /
 * "#RRGGBBAA", exactly 6 or 8 hex digits of either case. Alpha defaults to 255; where allow_alpha is
 * 0 (a window, imgdiff's opaque images) a fourth channel is refused. Writes out[4] and returns 0, or
 * prints the usage error naming `option` and returns 2 (out unchanged).
 */
int cli_parse_colour(const struct cli_env *env, const char *option, const char *s, int allow_alpha, uint8_t out[4]);
/* Parses "WxH"; returns 0 or -1. */
int cli_parse_size2(const char *s, unsigned *w, unsigned *h);
/*
 * --json output: prints root (built with cJSON, the one JSON library) as one
 * line on stdout, a space after each ':' and ',', and frees it. Returns 0, or 1 (the exit status) after
 * printing an error when root is NULL or printing ran out of memory, so a
 * failed cJSON_Create* anywhere in the tree surfaces here.
 */
int cli_json_print(const struct cli_env *env, cJSON *root);
/*
 * A JSON number holding v as printf(fmt, v) writes it (fmt such as "%.9g",
 * "%.4f"), so --json keeps the digits the text output shows; null for NaN
 * and infinities, which JSON cannot hold. NULL when out of memory.
 */
cJSON *cli_json_number(const char *fmt, double v);
/* A JSON array of n doubles, each to 17 significant digits (round trip exact). */
cJSON *cli_json_doubles(const double *v, int n);

/*
 * For the commands that allocate most (decompose, build): starts the process again with glibc's
 * transparent-huge-page tunable where the kernel's THP mode is "madvise" (huge_pages.c). Returns
 * when nothing was done or the start failed.
 */
void cli_huge_pages_restart(char **argv);

#endif
