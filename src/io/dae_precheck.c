/*
 * Collada (.dae) pre-check (issue #31), before assimp reads the file. assimp's
 * ColladaParser trusts the counts it reads: a float_array with count="-1",
 * or one token fewer than its count, made it write past its arrays (16
 * crashes with SIGSEGV); a huge count made it reserve gigabytes. So the XML
 * is scanned here (tags, attributes and the text of the elements that matter;
 * COLLADA 1.4.1 spec chapter 5 <float_array>, <accessor>, <vertices>,
 * <triangles>, <polylist>, <polygons>, <p>, <vcount>) and:
 *  - every count, stride, offset and set attribute is a non-negative integer;
 *  - an array's count is at most its number of tokens, and its numbers parse;
 *  - an accessor's offset + stride * count fits the array it names;
 *  - a primitive's <vcount> has count entries, its <p> at least the indices
 *    its count needs, a whole number of index groups, and each index below
 *    the count of the accessor its input names.
 * What cannot be seen here is left to the reader process (child_process.h).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/mesh_precheck.h"
#include "util/banned.h"

enum { DAE_MAX_INPUTS = 32, DAE_ID = 128 };

typedef struct named {
    char id[DAE_ID];
    long long count; /* array: its count; source: its accessor's count; vertices: its POSITION source's count */
    int kind;        /* 0 array, 1 source, 2 vertices */
    char ref[DAE_ID];/* source: the array its accessor names; vertices: the source of POSITION */
} named;

typedef struct input {
    char source[DAE_ID];
    long long offset;
} input;

typedef struct dae {
    const char *b, *end, *name;
    asp_error *err;
    named *ids;
    size_t nids, cap;
    char source[DAE_ID]; /* the <source> being read */
    /* the primitive being read */
    int in_prim;
    char prim[32];
    long long prim_count, vcount_sum, vcount_n;
    input inputs[DAE_MAX_INPUTS];
    int ninputs;
    size_t line;
} dae;

static size_t line_of(const dae *d, const char *p)
{
    size_t line = 1;
    for (const char *q = d->b; q < p; q++)
        line += *q == '\n';
    return line;
}

/* The value of attribute key inside a tag [s, e), copied to out; 0 when absent. */
static int attr(const char *s, const char *e, const char *key, char *out, size_t cap)
{
    size_t kl = strlen(key);
    for (const char *p = s; p + kl + 2 <= e; p++) {
        if ((p == s || p[-1] == ' ' || p[-1] == '\t' || p[-1] == '\n' || p[-1] == '\r') && memcmp(p, key, kl) == 0) {
            const char *q = p + kl;
            while (q < e && (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r'))
                q++;
            if (q >= e || *q != '=')
                continue;
            q++;
            while (q < e && (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r'))
                q++;
            if (q >= e || (*q != '"' && *q != '\''))
                continue;
            char quote = *q++;
            const char *v = q;
            while (q < e && *q != quote)
                q++;
            size_t n = (size_t)(q - v);
            snprintf(out, cap, "%.*s", (int)(n < cap ? n : cap - 1), v);
            return 1;
        }
    }
    return 0;
}

/* A count-like attribute: absent -> def; else a non-negative integer of at most 12 digits, or -1 (refused). */
static long long int_attr(dae *d, const char *s, const char *e, const char *key, long long def, const char *tag, int *rc)
{
    char v[64];
    if (!attr(s, e, key, v, sizeof v))
        return def;
    long long x = 0;
    size_t n = strlen(v);
    int ok = n > 0 && n <= 12;
    for (size_t i = 0; ok && i < n; i++)
        ok = v[i] >= '0' && v[i] <= '9', x = 10 * x + (v[i] - '0');
    if (!ok)
        *rc = asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> %s=\"%.20s\" is not a count (a "
                            "non-negative integer)", d->name, line_of(d, s), tag, key, v);
    return ok ? x : -1;
}

static named *find(dae *d, const char *ref)
{
    if (ref[0] == '#')
        ref++;
    for (size_t i = 0; i < d->nids; i++)
        if (strcmp(d->ids[i].id, ref) == 0)
            return &d->ids[i];
    return NULL;
}

static int add(dae *d, const char *id, long long count, int kind, const char *ref)
{
    if (!id[0])
        return 0;
    if (d->nids == d->cap) {
        size_t cap = d->cap ? 2 * d->cap : 64;
        named *n = realloc(d->ids, cap * sizeof *n);
        if (!n)
            return asp_error_set(d->err, ASP_ENOMEM, "out of memory checking '%s'", d->name);
        d->ids = n, d->cap = cap;
    }
    named *n = &d->ids[d->nids++];
    snprintf(n->id, sizeof n->id, "%s", id);
    snprintf(n->ref, sizeof n->ref, "%s", ref ? (ref[0] == '#' ? ref + 1 : ref) : "");
    n->count = count, n->kind = kind;
    return 0;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* Tokens of the text [s, e) up to the next '<'; numbers: 1 when each must be a number (floats or ints). */
static long long count_tokens(dae *d, const char *s, const char *e, int numbers, int *rc, const char *tag)
{
    long long n = 0;
    const char *p = s;
    while (p < e && *p != '<') {
        while (p < e && *p != '<' && is_space(*p))
            p++;
        if (p >= e || *p == '<')
            break;
        const char *t = p;
        while (p < e && *p != '<' && !is_space(*p))
            p++;
        if (numbers) {
            char w[64];
            size_t len = (size_t)(p - t);
            snprintf(w, sizeof w, "%.*s", (int)(len < sizeof w ? len : sizeof w - 1), t);
            char *end;
            strtod(w, &end);
            if (len >= sizeof w || *end) {
                *rc = asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> holds '%.20s', not a number",
                                    d->name, line_of(d, t), tag, w);
                return -1;
            }
        }
        n++;
    }
    return n;
}

/* The indices of a <p>: a whole number of groups, each index below its input's count; the number of indices. */
static long long check_p(dae *d, const char *s, const char *e, int *rc)
{
    long long stride = 0;
    long long limit[DAE_MAX_INPUTS];
    for (int i = 0; i < d->ninputs; i++) {
        stride = d->inputs[i].offset + 1 > stride ? d->inputs[i].offset + 1 : stride;
        named *n = find(d, d->inputs[i].source);
        limit[i] = n ? n->count : -1;
    }
    if (stride == 0)
        stride = 1;
    long long k = 0;
    const char *p = s;
    while (p < e && *p != '<') {
        while (p < e && *p != '<' && is_space(*p))
            p++;
        if (p >= e || *p == '<')
            break;
        const char *t = p;
        long long v = 0;
        int digits = 0;
        while (p < e && *p >= '0' && *p <= '9' && digits < 12)
            v = 10 * v + (*p++ - '0'), digits++;
        if (!digits || (p < e && *p != '<' && !is_space(*p))) {
            // at most 12 bytes of the token, and never past the text's end (it is not NUL-terminated)
            int shown = e - t < 12 ? (int)(e - t) : 12;
            *rc = asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <p> of <%s> holds '%.*s', not an "
                                "index", d->name, line_of(d, t), d->prim, shown, t);
            return -1;
        }
        long long off = k % stride;
        for (int i = 0; i < d->ninputs; i++)
            if (d->inputs[i].offset == off && limit[i] >= 0 && v >= limit[i]) {
                *rc = asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <p> of <%s>: index %lld of input "
                                    "'%s' is past its %lld elements", d->name, line_of(d, t), d->prim, v,
                                    d->inputs[i].source, limit[i]);
                return -1;
            }
        k++;
    }
    if (k % stride) {
        *rc = asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <p> of <%s> holds %lld indices, not a "
                            "multiple of its %lld inputs", d->name, line_of(d, s), d->prim, k, stride);
        return -1;
    }
    return k / stride;
}

static int is_array(const char *tag)
{
    static const char *const arrays[] = {"float_array", "int_array", "Name_array", "IDREF_array", "bool_array",
                                         "SIDREF_array", "token_array"};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        if (strcmp(tag, arrays[i]) == 0)
            return 1;
    return 0;
}

static int is_prim(const char *tag)
{
    static const char *const prims[] = {"triangles", "polylist", "polygons", "lines", "linestrips", "trifans",
                                        "tristrips"};
    for (size_t i = 0; i < sizeof prims / sizeof prims[0]; i++)
        if (strcmp(tag, prims[i]) == 0)
            return 1;
    return 0;
}

/* At the end of a primitive: <vcount> against count, the indices of <p> against what count needs. */
static int end_prim(dae *d, long long groups, const char *at)
{
    long long need = -1;
    if (strcmp(d->prim, "triangles") == 0)
        need = 3 * d->prim_count;
    else if (strcmp(d->prim, "lines") == 0)
        need = 2 * d->prim_count;
    else if (strcmp(d->prim, "polylist") == 0) {
        if (d->vcount_n != d->prim_count)
            return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <polylist> count=\"%lld\" but its "
                                 "<vcount> has %lld entries", d->name, line_of(d, at), d->prim_count, d->vcount_n);
        need = d->vcount_sum;
    }
    if (need >= 0 && groups < need)
        return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> count=\"%lld\" needs %lld vertices "
                             "in <p>, which holds %lld", d->name, line_of(d, at), d->prim, d->prim_count, need, groups);
    return 0;
}

static int scan(dae *d)
{
    const char *p = d->b, *e = d->end;
    long long groups = 0;
    int rc = 0;
    while (p < e) {
        const char *lt = memchr(p, '<', (size_t)(e - p));
        if (!lt)
            break;
        if (e - lt >= 4 && memcmp(lt, "<!--", 4) == 0) {
            const char *c = lt + 4;
            while (c + 3 <= e && memcmp(c, "-->", 3) != 0)
                c++;
            p = c + 3 <= e ? c + 3 : e;
            continue;
        }
        if (e - lt >= 9 && memcmp(lt, "<![CDATA[", 9) == 0) {
            const char *c = lt + 9;
            while (c + 3 <= e && memcmp(c, "]]>", 3) != 0)
                c++;
            p = c + 3 <= e ? c + 3 : e;
            continue;
        }
        const char *gt = memchr(lt, '>', (size_t)(e - lt));
        if (!gt)
            return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: a tag is not closed: the file is cut "
                                 "off", d->name, line_of(d, lt));
        const char *ts = lt + 1;
        int closing = *ts == '/';
        if (closing)
            ts++;
        char tag[32];
        const char *te = ts;
        while (te < gt && !is_space(*te) && *te != '/' && *te != '>')
            te++;
        size_t tl = (size_t)(te - ts);
        snprintf(tag, sizeof tag, "%.*s", (int)(tl < sizeof tag ? tl : sizeof tag - 1), ts);
        const char *text = gt + 1;
        p = text;
        if (closing) {
            if (d->in_prim && strcmp(tag, d->prim) == 0) {
                if ((rc = end_prim(d, groups, lt)))
                    return rc;
                d->in_prim = 0;
            }
            if (strcmp(tag, "source") == 0)
                d->source[0] = '\0';
            continue;
        }
        if (tag[0] == '?' || tag[0] == '!')
            continue;
        // every count-like attribute is a non-negative integer (count="-1" crashed assimp)
        static const char *const counts[] = {"count", "stride", "offset", "set"};
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
            int_attr(d, lt, gt, counts[i], 0, tag, &rc);
            if (rc)
                return rc;
        }
        char id[DAE_ID] = "", src[DAE_ID] = "";
        if (is_array(tag)) {
            long long count = int_attr(d, lt, gt, "count", -1, tag, &rc);
            if (count < 0)
                return rc ? rc : asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> has no count",
                                               d->name, line_of(d, lt), tag);
            long long tokens = count_tokens(d, text, e, strcmp(tag, "float_array") == 0 || strcmp(tag, "int_array") == 0,
                                            &rc, tag);
            if (rc)
                return rc;
            if (tokens < count)
                return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> count=\"%lld\" but it holds "
                                     "%lld values", d->name, line_of(d, lt), tag, count, tokens);
            attr(lt, gt, "id", id, sizeof id);
            if ((rc = add(d, id, count, 0, NULL)))
                return rc;
        } else if (strcmp(tag, "source") == 0) {
            attr(lt, gt, "id", d->source, sizeof d->source);
        } else if (strcmp(tag, "accessor") == 0) {
            long long count = int_attr(d, lt, gt, "count", -1, tag, &rc);
            long long stride = int_attr(d, lt, gt, "stride", 1, tag, &rc);
            long long offset = int_attr(d, lt, gt, "offset", 0, tag, &rc);
            if (rc)
                return rc;
            if (count < 0)
                return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <accessor> has no count", d->name,
                                     line_of(d, lt));
            attr(lt, gt, "source", src, sizeof src);
            named *a = src[0] ? find(d, src) : NULL;
            if (a && a->kind == 0 && count > 0 && offset + stride * (count - 1) + 1 > a->count)
                return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <accessor> of %lld elements "
                                     "(stride %lld, offset %lld) reads past the %lld values of '%s'", d->name,
                                     line_of(d, lt), count, stride, offset, a->count, src);
            if ((rc = add(d, d->source, count, 1, src)))
                return rc;
        } else if (strcmp(tag, "vertices") == 0) {
            attr(lt, gt, "id", id, sizeof id);
            if ((rc = add(d, id, -1, 2, NULL)))
                return rc;
        } else if (strcmp(tag, "input") == 0) {
            char sem[32] = "";
            attr(lt, gt, "semantic", sem, sizeof sem);
            attr(lt, gt, "source", src, sizeof src);
            if (!d->in_prim && d->nids && d->ids[d->nids - 1].kind == 2 && strcmp(sem, "POSITION") == 0) {
                named *v = &d->ids[d->nids - 1], *s = find(d, src);
                v->count = s ? s->count : -1;
            } else if (d->in_prim && d->ninputs < DAE_MAX_INPUTS) {
                input *in = &d->inputs[d->ninputs++];
                snprintf(in->source, sizeof in->source, "%s", src[0] == '#' ? src + 1 : src);
                in->offset = int_attr(d, lt, gt, "offset", 0, tag, &rc);
                if (rc)
                    return rc;
            } else if (d->in_prim) {
                return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <%s> with more than %d inputs",
                                     d->name, line_of(d, lt), d->prim, DAE_MAX_INPUTS);
            }
        } else if (is_prim(tag)) {
            d->in_prim = gt[-1] != '/';
            snprintf(d->prim, sizeof d->prim, "%s", tag);
            d->prim_count = int_attr(d, lt, gt, "count", 0, tag, &rc);
            d->vcount_sum = d->vcount_n = 0;
            d->ninputs = 0;
            groups = 0;
        } else if (d->in_prim && strcmp(tag, "vcount") == 0) {
            const char *q = text;
            while (q < e && *q != '<') {
                while (q < e && *q != '<' && is_space(*q))
                    q++;
                if (q >= e || *q == '<')
                    break;
                long long v = 0;
                int digits = 0;
                while (q < e && *q >= '0' && *q <= '9' && digits < 9)
                    v = 10 * v + (*q++ - '0'), digits++;
                if (!digits || (q < e && *q != '<' && !is_space(*q)))
                    return asp_error_set(d->err, ASP_EFORMAT, "cannot read '%s': line %zu: <vcount> holds something "
                                         "that is not a vertex count", d->name, line_of(d, q));
                d->vcount_sum += v;
                d->vcount_n++;
            }
        } else if (d->in_prim && strcmp(tag, "p") == 0 && gt[-1] != '/') {
            long long g = check_p(d, text, e, &rc);
            if (rc)
                return rc;
            groups += g;
        }
    }
    return 0;
}

int asp__dae_precheck_memory(const void *data, size_t size, const char *name, asp_error *err)
{
    dae d = {.b = data, .end = (const char *)data + size, .name = name, .err = err};
    int rc = scan(&d);
    free(d.ids);
    return rc;
}
