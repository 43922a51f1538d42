/*
 * Option parsing shared by all subcommands: --name value, --name=value,
 * -x value, and the common options every command takes.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/cli.h"
#include "util/banned.h"

static int progress_cb(void *user, const char *stage, double fraction);

/* The library's warnings (asp_warn) as one line each, unless --quiet. */
static void warning_cb(void *user, const char *message)
{
    struct cli_env *env = user;
    if (!env->quiet)
        fprintf(stderr, "amgsplat %s: warning: %s\n", env->cmd, message);
}

static const char *type_arg(const struct cli_option *o)
{
    if (o->arg)
        return o->arg;
    switch (o->type) {
    case CLI_INT: case CLI_SIZE: return "N";
    case CLI_DOUBLE: return "X";
    case CLI_STRING: return "S";
    default: return "";
    }
}

static void print_help(const struct cli_option *opts, const char *usage)
{
    printf("%s\n", usage);
    printf("\noptions:\n");
    for (const struct cli_option *o = opts; o && o->name; o++) {
        char left[64];
        if (o->type == CLI_FLAG)
            snprintf(left, sizeof left, "%s%c%s--%s", o->short_name ? "-" : "", o->short_name ? o->short_name : ' ',
                     o->short_name ? ", " : "  ", o->name);
        else
            snprintf(left, sizeof left, "%s%c%s--%s %s", o->short_name ? "-" : "",
                     o->short_name ? o->short_name : ' ', o->short_name ? ", " : "  ", o->name, type_arg(o));
        printf("  %-26s %s\n", left + (o->short_name ? 0 : 1), o->help ? o->help : "");
    }
    printf("  %-26s %s\n", "-q, --quiet", "no progress bar or informational messages");
    printf("  %-26s %s\n", "    --json", "machine-readable output on stdout");
    printf("  %-26s %s\n", "    --threads N", "worker threads (default: all cores)");
    printf("  %-26s %s\n", "-h, --help", "show this help");
}

/*
 * Plain decimal notation: [+-]digits[.digits][e[+-]digits], then one of suffixes. strtod also
 * reads hex ("0x10" = 16), "inf", "nan" and hex floats; an option value meaning any of those is a
 * typo more often than not (issue #31), so they are refused before it.
 */
static int plain_decimal(const char *v, const char *suffixes)
{
    const char *p = v;
    if (*p == '+' || *p == '-')
        p++;
    int digits = 0;
    while (*p >= '0' && *p <= '9')
        p++, digits++;
    if (*p == '.')
        for (p++; *p >= '0' && *p <= '9'; p++)
            digits++;
    if (!digits)
        return 0;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!(*p >= '0' && *p <= '9'))
            return 0;
        while (*p >= '0' && *p <= '9')
            p++;
    }
    if (*p && strchr(suffixes, *p))
        p++;
    return *p == '\0';
}

static int set_value(struct cli_env *env, const struct cli_option *o, const char *v)
{
    char *end = NULL;
    errno = 0;
    switch (o->type) {
    case CLI_FLAG:
        *(int *)o->value = 1;
        return 0;
    case CLI_INT: {
        long x = strtol(v, &end, 10);
        if (errno || end == v || *end || x < INT_MIN || x > INT_MAX)
            return cli_usage_error(env, "--%s expects an integer, got '%s'", o->name, v);
        *(int *)o->value = (int)x;
        return 0;
    }
    case CLI_SIZE: {
        if (*v == '-' || !plain_decimal(v, "kKmM"))
            return cli_usage_error(env, "--%s expects a non-negative integer, got '%s'", o->name, v);
        /* accept 2e6 / 200k / 1M for point counts */
        double d = strtod(v, &end);
        if (end != v && (*end == 'k' || *end == 'K')) d *= 1e3, end++;
        else if (end != v && (*end == 'm' || *end == 'M')) d *= 1e6, end++;
        if (errno || end == v || *end || d < 0 || d > 1e15 || d != (double)(size_t)d)
            return cli_usage_error(env, "--%s expects a non-negative integer, got '%s'", o->name, v);
        *(size_t *)o->value = (size_t)d;
        return 0;
    }
    case CLI_DOUBLE: {
        double d = strtod(v, &end);
        if (errno || end == v || *end || !isfinite(d) || !plain_decimal(v, ""))
            return cli_usage_error(env, "--%s expects a finite number, got '%s'", o->name, v);
        *(double *)o->value = d;
        return 0;
    }
    case CLI_STRING:
        *(const char **)o->value = v;
        return 0;
    }
    return 2;
}

static void forget_preset(struct cli_env *env, const void *value)
{
    for (size_t k = 0; k < env->preset_count; k++)
        if (env->preset_values[k] == value)
            env->preset_values[k--] = env->preset_values[--env->preset_count];
}

int cli_given(const struct cli_env *env, const void *value)
{
    for (size_t k = 0; k < env->given_count; k++)
        if (env->given_values[k] == value)
            return 1;
    return 0;
}

int cli_from_preset(const struct cli_env *env, const void *value)
{
    for (size_t k = 0; k < env->preset_count; k++)
        if (env->preset_values[k] == value)
            return 1;
    return 0;
}

static const struct cli_option *find_long(const struct cli_option *opts, const char *name)
{
    for (const struct cli_option *p = opts; p && p->name; p++)
        if (strcmp(p->name, name) == 0)
            return p;
    return NULL;
}

/*
 * --preset NAME (issue 17): the seed's values are set before the command line is parsed, so every
 * option given explicitly wins, whatever its place. The table is the library's (asp_preset_settings);
 * only commands whose option table has "preset" take one. The applied settings go to *applied for
 * the informational line.
 */
static int apply_preset(int argc, char **argv, const struct cli_option *opts, struct cli_env *env, char *applied,
                        size_t applied_size)
{
    const char *name = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--") == 0)
            break;
        if (strcmp(argv[i], "--preset") == 0 && i + 1 < argc)
            name = argv[++i];
        else if (strncmp(argv[i], "--preset=", 9) == 0)
            name = argv[i] + 9;
    }
    if (!name || !find_long(opts, "preset"))
        return 0; /* absent, or the main loop reports the unknown option */
    asp_preset preset;
    asp_error err = {0};
    if (asp_preset_parse(name, &preset, &err))
        return cli_usage_error(env, "--preset: %s", err.msg);
    size_t count = 0;
    const asp_preset_setting *set = asp_preset_settings(preset, &count);
    int w0 = snprintf(applied, applied_size, "%s:", name);
    size_t used = w0 > 0 ? (size_t)w0 : 0;
    for (size_t k = 0; k < count; k++) {
        if (strcmp(set[k].command, env->cmd) != 0)
            continue;
        const struct cli_option *o = find_long(opts, set[k].option);
        if (!o)
            return cli_usage_error(env, "preset '%s' sets --%s, which 'amgsplat %s' lacks", name, set[k].option,
                                   env->cmd);
        if (set_value(env, o, set[k].value))
            return 2;
        if (env->preset_count < sizeof env->preset_values / sizeof env->preset_values[0])
            env->preset_values[env->preset_count++] = o->value;
        if (used < applied_size) {
            int w = snprintf(applied + used, applied_size - used, " --%s%s%s", set[k].option, set[k].value ? " " : "",
                             set[k].value ? set[k].value : "");
            used += w > 0 ? (size_t)w : 0;
        }
    }
    return 0;
}

int cli_parse(int argc, char **argv, const struct cli_option *opts, const char *usage, struct cli_env *env,
              int *npos)
{
    int n = 0;
    int only_positional = 0;
    char applied[512];
    applied[0] = '\0';
    if (apply_preset(argc, argv, opts, env, applied, sizeof applied))
        return -1;
    for (int i = 1; i < argc; i++) {
        char *a = argv[i];
        if (only_positional || a[0] != '-' || a[1] == '\0') {
            argv[n++] = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            only_positional = 1;
            continue;
        }
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            print_help(opts, usage);
            return 1;
        }
        if (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0) {
            env->quiet = 1;
            continue;
        }
        if (strcmp(a, "--json") == 0) {
            env->json = 1;
            continue;
        }
        const struct cli_option *o = NULL;
        const char *inline_value = NULL;
        char name[64];
        if (a[1] == '-') {
            const char *eq = strchr(a + 2, '=');
            size_t len = eq ? (size_t)(eq - (a + 2)) : strlen(a + 2);
            if (len >= sizeof name)
                len = sizeof name - 1;
            memcpy(name, a + 2, len);
            name[len] = '\0';
            inline_value = eq ? eq + 1 : NULL;
            if (strcmp(name, "threads") == 0) {
                const char *v = inline_value ? inline_value : (i + 1 < argc ? argv[++i] : NULL);
                char *end;
                long t = v ? strtol(v, &end, 10) : -1;
                if (!v || end == v || *end || t < 0 || t > 4096)
                    return cli_usage_error(env, "--threads expects a count from 0 (all cores) to 4096, got '%s'",
                                           v ? v : "(nothing)"),
                           -1;
                env->threads = (int)t;
                continue;
            }
            for (const struct cli_option *p = opts; p && p->name; p++)
                if (strcmp(p->name, name) == 0)
                    o = p;
        } else if (a[2] == '\0') {
            for (const struct cli_option *p = opts; p && p->name; p++)
                if (p->short_name == a[1])
                    o = p;
            snprintf(name, sizeof name, "%c", a[1]);
        } else {
            snprintf(name, sizeof name, "%s", a + 1);
        }
        if (!o) {
            cli_usage_error(env, "unknown option '%s'; see 'amgsplat %s -h'", a, env->cmd);
            return -1;
        }
        const char *v = inline_value;
        if (o->type != CLI_FLAG && !v) {
            if (i + 1 >= argc) {
                cli_usage_error(env, "option '%s' needs a value", a);
                return -1;
            }
            v = argv[++i];
        }
        if (o->type == CLI_FLAG && inline_value) {
            cli_usage_error(env, "option '--%s' takes no value", o->name);
            return -1;
        }
        if (set_value(env, o, v))
            return -1;
        forget_preset(env, o->value);
        if (!cli_given(env, o->value) && env->given_count < sizeof env->given_values / sizeof env->given_values[0])
            env->given_values[env->given_count++] = o->value;
    }
    *npos = n;
    if (applied[0])
        cli_info(env, "amgsplat %s: preset %s (options given explicitly win)", env->cmd, applied);
    env->ctx.threads = env->threads;
    env->ctx.warning = warning_cb;
    env->ctx.warning_user = env;
    if (!env->quiet && isatty(STDERR_FILENO)) {
        env->ctx.progress = progress_cb;
        env->ctx.progress_user = env;
    }
    return 0;
}

int cli_fail(const struct cli_env *env, const asp_error *err)
{
    fprintf(stderr, "amgsplat %s: error: %s\n", env->cmd, err && err->msg[0] ? err->msg : "failed");
    return 1;
}

int cli_usage_error(const struct cli_env *env, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "amgsplat %s: ", env->cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return 2;
}

void cli_info(const struct cli_env *env, const char *fmt, ...)
{
    if (env->quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* Progress bar with ETA, redrawn at most 10 times a second, only on a terminal. */
static int progress_cb(void *user, const char *stage, double fraction)
{
    struct cli_env *env = user;
    struct cli_progress_state *p = &env->progress;
    double now = asp_time_now();
    if (strncmp(p->stage, stage, sizeof p->stage - 1) != 0) {
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->start = now;
        p->last_draw = 0;
    }
    if (fraction < 1.0 && now - p->last_draw < 0.1)
        return 0;
    p->last_draw = now;
    if (fraction < 0) fraction = 0;
    if (fraction > 1) fraction = 1;
    int width = 30, fill = (int)(fraction * width + 0.5);
    char bar[32];
    for (int i = 0; i < width; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    double elapsed = now - p->start;
    char eta[32] = "";
    if (fraction > 0.02 && fraction < 1.0)
        snprintf(eta, sizeof eta, " ETA %.0fs", elapsed * (1.0 - fraction) / fraction);
    fprintf(stderr, "\r%-12s [%s] %3.0f%%%-12s", p->stage, bar, 100.0 * fraction, eta);
    p->drawn = 1;
    return 0;
}

void cli_progress_end(struct cli_env *env)
{
    if (env->progress.drawn) {
        fputs("\r\033[K", stderr);
        env->progress.drawn = 0;
    }
}

int cli_parse_up(const char *s, asp_up_axis *out)
{
    int neg = s[0] == '-';
    if (s[0] == '+' || s[0] == '-')
        s++;
    asp_up_axis a;
    if (strcmp(s, "y") == 0 || strcmp(s, "Y") == 0)
        a = ASP_UP_Y;
    else if (strcmp(s, "z") == 0 || strcmp(s, "Z") == 0)
        a = ASP_UP_Z;
    else if (strcmp(s, "x") == 0 || strcmp(s, "X") == 0)
        a = ASP_UP_X;
    else
        return -1;
    *out = neg ? (asp_up_axis)(a + ASP_UP_NEG_Y) : a;
    return 0;
}

int cli_parse_doubles(const char *s, double *out, int max)
{
    int n = 0;
    const char *p = s;
    while (*p) {
        char *end;
        errno = 0;
        double d = strtod(p, &end);
        if (end == p || errno || d != d || n >= max)
            return -1;
        out[n++] = d;
        p = end;
        if (*p == ',')
            p++;
        else if (*p)
            return -1;
    }
    return n;
}

static int hex_digit(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

int cli_parse_colour(const struct cli_env *env, const char *option, const char *s, int allow_alpha, uint8_t out[4])
{
    double v[4] = {0, 0, 0, 255};
    int n = -1;
    if (s[0] == '#') {
        size_t len = strlen(s + 1);
        if (len == 6 || len == 8) {
            n = (int)len / 2;
            for (int i = 0; i < n && n > 0; i++) {
                int hi = hex_digit(s[1 + 2 * i]), lo = hex_digit(s[2 + 2 * i]);
                if (hi < 0 || lo < 0)
                    n = -1;
                else
                    v[i] = hi * 16 + lo;
            }
        }
    } else {
        n = cli_parse_doubles(s, v, 4);
        for (int i = 0; i < n; i++)
            if (!(v[i] >= 0 && v[i] <= 255))
                n = -1;
    }
    if (n < 3 || (n == 4 && !allow_alpha))
        return cli_usage_error(env, "%s expects R,G,B%s with channels in 0..255, or #RRGGBB%s, got '%s'", option,
                               allow_alpha ? "[,A]" : "", allow_alpha ? "[AA]" : "", s);
    for (int i = 0; i < 4; i++)
        out[i] = (uint8_t)floor(v[i] + 0.5);
    return 0;
}

int cli_parse_size2(const char *s, unsigned *w, unsigned *h)
{
    char *end;
    unsigned long a = strtoul(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X'))
        return -1;
    const char *q = end + 1;
    unsigned long b = strtoul(q, &end, 10);
    if (end == q || *end || a == 0 || b == 0 || a > 16384 || b > 16384)
        return -1;
    *w = (unsigned)a;
    *h = (unsigned)b;
    return 0;
}

cJSON *cli_json_number(const char *fmt, double v)
{
    char text[64];
    if (!isfinite(v))
        return cJSON_CreateNull(); // JSON has no NaN or infinity; the old writers printed invalid JSON there
    snprintf(text, sizeof text, fmt, v);
    return cJSON_CreateNumber(strtod(text, NULL));
}

cJSON *cli_json_doubles(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++)
        cJSON_AddItemToArray(a, cli_json_number("%.17g", v[i]));
    return a;
}

int cli_json_print(const struct cli_env *env, cJSON *root)
{
    char *text = root ? cJSON_PrintUnformatted(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        fprintf(stderr, "amgsplat %s: error: out of memory for the JSON output\n", env->cmd);
        return 1;
    }
    /*
     * cJSON's compact text with a space after each ':' and ',' outside strings: the one-line
     * layout amgsplat has always printed ({"points": 4, "attributes": ["normals", "colors"]}),
     * easy to read and to grep, and the same tokens
     */
    int in_string = 0, escaped = 0;
    for (const char *c = text; *c; c++) {
        putchar(*c);
        if (in_string) {
            if (escaped)
                escaped = 0;
            else if (*c == '\\')
                escaped = 1;
            else if (*c == '"')
                in_string = 0;
        } else if (*c == '"') {
            in_string = 1;
        } else if (*c == ':' || *c == ',') {
            putchar(' ');
        }
    }
    putchar('\n');
    cJSON_free(text);
    return 0;
}

int cli_check_output(const struct cli_env *env, const char *output, const char *format, int allow_bare,
                     const char *const *inputs, size_t ninputs)
{
    struct stat so;
    if (output && stat(output, &so) == 0)
        for (size_t i = 0; i < ninputs; i++) {
            struct stat si;
            if (inputs[i] && stat(inputs[i], &si) == 0 && si.st_dev == so.st_dev && si.st_ino == so.st_ino)
                return cli_usage_error(env, "output '%s' is the input '%s'; write to another file", output,
                                       inputs[i]);
        }
    if (!output || !format)
        return 0;
    const char *slash = strrchr(output, '/'), *dot = strrchr(output, '.');
    int bare = !dot || (slash && dot < slash) || dot == (slash ? slash + 1 : output);
    if (bare && allow_bare)
        return 0;
    if (!asp_file_name_is(output, format))
        return cli_usage_error(env, "output '%s': this command writes .%s, not %s%s%s", output, format,
                               bare ? "a name without extension" : "'", bare ? "" : dot, bare ? "" : "'");
    return 0;
}

int cli_parse_view(struct cli_env *env, const char *s, double *az, double *el, double *dist)
{
    double v[3] = {0, 0, 0};
    int n = cli_parse_doubles(s, v, 3);
    // bounded so that a float camera stays finite: 1e300 degrees or radii would turn into inf and NaN
    if (n < 2 || !(fabs(v[0]) <= 36000) || !(v[1] >= -90 && v[1] <= 90) || (n == 3 && !(v[2] > 0 && v[2] <= 1e6)))
        return cli_usage_error(env,
                               "--view expects AZ,EL[,DIST] with AZ in -36000..36000, EL in -90..90 and DIST in "
                               "(0, 1e6] radii, got '%s'",
                               s);
    *az = v[0];
    *el = v[1];
    *dist = n == 3 ? v[2] : 0;
    return 0;
}
