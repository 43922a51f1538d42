/*
 * The JSON object of a t test (asp_stats_ttest_json): one writer for the
 * `experiment ttest --json` output and the tests of the analysis report, so
 * both carry the same keys (they had drifted: "p_one" in one, "samples" and
 * "mu" in one, neither in the other).
 */
#include <cjson/cJSON.h>

#include "amgsplat/stats.h"
#include "util/banned.h"

static cJSON *pair(double a, double b)
{
    cJSON *ci = cJSON_CreateArray();
    if (ci && !(cJSON_AddItemToArray(ci, cJSON_CreateNumber(a)) && cJSON_AddItemToArray(ci, cJSON_CreateNumber(b)))) {
        cJSON_Delete(ci);
        ci = NULL;
    }
    return ci;
}

/* cJSON's adders return NULL (or false) on out of memory; every add is checked through ok */
static int add_number(cJSON *o, const char *key, double v)
{
    return cJSON_AddNumberToObject(o, key, v) != NULL;
}

static int add_item(cJSON *o, const char *key, cJSON *item)
{
    if (item && cJSON_AddItemToObject(o, key, item))
        return 1;
    cJSON_Delete(item);
    return 0;
}

static cJSON *samples(const asp_ttest_result *r, const asp_stats_summary *s, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int k = 0; a && k < n; k++) {
        cJSON *x = cJSON_CreateObject();
        int ok = x && add_number(x, "n", (double)s[k].n) && add_number(x, "mean", s[k].mean) &&
                 add_number(x, "sd", s[k].sd) && add_item(x, "mean_ci", pair(r->mean_lo[k], r->mean_hi[k]));
        if (!ok || !cJSON_AddItemToArray(a, x)) {
            cJSON_Delete(x);
            cJSON_Delete(a);
            a = NULL;
        }
    }
    return a;
}

int asp_stats_ttest_json(const asp_ttest_result *r, const asp_ttest_json_desc *desc, struct cJSON **out,
                         asp_error *err)
{
    ASP_ASSERT(r && out);
    static const asp_ttest_json_desc zero_desc;
    const asp_ttest_json_desc *d = desc ? desc : &zero_desc;
    const char *test = d->test ? d->test : r->welch ? "welch" : "pooled";
    cJSON *o = cJSON_CreateObject();
    int ok = o && cJSON_AddStringToObject(o, "test", test) != NULL;
    if (ok && d->one_sample)
        ok = add_number(o, "mu", d->mu);
    if (ok && d->samples)
        ok = add_item(o, "samples", samples(r, d->samples, d->one_sample ? 1 : 2));
    ok = ok && add_number(o, "diff", r->diff) && add_number(o, "se", r->se) && add_number(o, "t", r->t) &&
         add_number(o, "df", r->df) && add_number(o, "p_one", r->p_one) && add_number(o, "p_greater", r->p_greater) &&
         add_number(o, "p_less", r->p_less) && add_number(o, "p_two", r->p_two) && add_number(o, "level", r->level) &&
         add_item(o, "diff_ci", pair(r->diff_lo, r->diff_hi));
    if (!ok) {
        cJSON_Delete(o);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the JSON of a t test");
    }
    *out = o;
    return 0;
}
