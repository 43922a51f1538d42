/*
 * Shared CLI plumbing: the environment every subcommand receives, the option
 * parser, error printing and the terminal progress bar. Only src/cli/ prints.
 */
#ifndef ASP_CLI_H
#define ASP_CLI_H

#include <stddef.h>
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

/* Parses "a,b[,c]" doubles into out (up to max); returns how many, -1 on junk. */
int cli_parse_doubles(const char *s, double *out, int max);
/* Parses --up: "y", "z", "x", "-y", "-z" or "-x" ("+y" = "y"); returns 0 or -1. */
int cli_parse_up(const char *s, asp_up_axis *out);

/*
 * --view AZ,EL[,DIST] of render and view: AZ in -36000..36000 degrees, EL in -90..90, DIST in
 * (0, 1e6] bounding-sphere radii (0 when not given: fit). Prints the usage error and returns 2.
 */
int cli_parse_view(struct cli_env *env, const char *s, double *az, double *el, double *dist);
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
