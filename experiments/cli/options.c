/* Option values: parsing, range checks, words, formatting (options.h). */
#include "experiments/cli/options.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* A range bound as one writes it: 1024, 1e9, 1e12, 0.5. */
static void bound_text(double v, char *out, size_t n)
{
    double e = v > 0 ? log10(v) : 0.0;
    if (v >= 1e6 && e == floor(e)) snprintf(out, n, "1e%.0f", e);
    else snprintf(out, n, "%.15g", v);
}

static double int_max(const Option *o) { return o->max > 0 ? o->max : OPT_INT_CAP; }

void option_expect(const Option *o, int quoted, char *out, size_t n)
{
    char lo[32], hi[32];
    bound_text(o->min, lo, sizeof lo);
    bound_text(o->max, hi, sizeof hi);
    switch (o->type) {
    case OPT_INT:
    case OPT_SIZE: {
        const char *what = o->what ? o->what : "an integer";
        if (o->max > 0) snprintf(out, n, "%s in [%s, %s]", what, lo, hi);
        else snprintf(out, n, "%s >= %s", what, lo);
        break;
    }
    case OPT_REAL:
        if (o->max > 0)
            snprintf(out, n, "%s in %c%s, %s]", o->what ? o->what : "a number", o->flags & OPT_MIN_OPEN ? '(' : '[', lo,
                     hi);
        else if (o->min == 0 && (o->flags & OPT_MIN_OPEN))
            snprintf(out, n, "%s", o->what ? o->what : "a positive number");
        else
            snprintf(out, n, "%s %s %s", o->what ? o->what : "a number", o->flags & OPT_MIN_OPEN ? ">" : ">=", lo);
        break;
    case OPT_CHOICE: {
        size_t len = 0, k = 0;
        out[0] = '\0';
        while (o->choices[k]) ++k;
        for (size_t i = 0; i < k && len < n; ++i) {
            const char *sep = i == 0 ? "" : i + 1 == k ? " or " : ", ";
            len += (size_t)snprintf(out + len, n - len, quoted ? "%s\"%s\"" : "%s%s", sep, o->choices[i]);
        }
        break;
    }
    case OPT_SWITCH:
        snprintf(out, n, "%s", quoted ? "true or false" : "no value");
        break;
    case OPT_TEXT:
    case OPT_LIST:
        snprintf(out, n, "%s", o->what ? o->what : "a non-empty string");
        break;
    }
}

void option_metavar(const Option *o, char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "%s", o->metavar ? o->metavar : "");
    if (o->metavar || o->type != OPT_CHOICE) return;
    for (int k = 0; o->choices[k] && len < n; ++k)
        len += (size_t)snprintf(out + len, n - len, "%s%s", k ? "|" : "", o->choices[k]);
}

int option_in_range(const Option *o, double x)
{
    if (!isfinite(x)) return 0;
    switch (o->type) {
    case OPT_INT:
    case OPT_SIZE:
        return x == floor(x) && x >= o->min && x <= int_max(o);
    case OPT_REAL:
        if (o->flags & OPT_MIN_OPEN ? !(x > o->min) : !(x >= o->min)) return 0;
        return o->max > 0 ? x <= o->max : 1;
    default:
        return 0;
    }
}

static int refuse(const Option *o, const char *text)
{
    char want[256];
    option_expect(o, 0, want, sizeof want);
    return mpm_error(MPM_EINPUT, "%s '%s': expected %s", o->flag, text, want);
}

int option_parse_text(const Option *o, const char *text, OptionValue *v)
{
    char *end = NULL;
    memset(v, 0, sizeof *v);
    switch (o->type) {
    case OPT_INT: {
        /* digits only (no blanks, no 0x, no exponent): what a person means by an integer */
        const char *p = text[0] == '-' || text[0] == '+' ? text + 1 : text;
        size_t digits = strspn(p, "0123456789");
        if (!digits || p[digits] || digits > 12) return refuse(o, text);
        double x = strtod(text, &end);
        if (!option_in_range(o, x)) return refuse(o, text);
        v->i = (int)x;
        return MPM_OK;
    }
    case OPT_SIZE: {
        double x = text[0] && !isspace((unsigned char)text[0]) ? strtod(text, &end) : NAN;
        if (!end || *end || !option_in_range(o, x)) return refuse(o, text);
        v->z = (size_t)x;
        return MPM_OK;
    }
    case OPT_REAL: {
        double x = text[0] && !isspace((unsigned char)text[0]) ? strtod(text, &end) : NAN;
        if (!end || *end || !option_in_range(o, x)) return refuse(o, text);
        v->d = x;
        return MPM_OK;
    }
    case OPT_CHOICE:
        for (int k = 0; o->choices[k]; ++k)
            if (!strcmp(text, o->choices[k])) {
                v->i = k;
                return MPM_OK;
            }
        return refuse(o, text);
    case OPT_TEXT:
    case OPT_LIST:
        if (!text[0]) return refuse(o, text);
        if (o->check) {
            int st = o->check(text);
            if (st) return st;
        }
        v->s = text;
        return MPM_OK;
    case OPT_SWITCH:
        break;
    }
    return mpm_error(MPM_EINPUT, "%s takes no value (got '%s')", o->flag, text);
}

void option_get(const Option *o, const void *target, OptionValue *v)
{
    const char *f = (const char *)target + o->offset;
    memset(v, 0, sizeof *v);
    switch (o->type) {
    case OPT_SWITCH:
    case OPT_INT:
    case OPT_CHOICE:
        memcpy(&v->i, f, sizeof v->i);
        break;
    case OPT_REAL:
        memcpy(&v->d, f, sizeof v->d);
        break;
    case OPT_SIZE:
        memcpy(&v->z, f, sizeof v->z);
        break;
    case OPT_TEXT:
        memcpy(&v->s, f, sizeof v->s);
        break;
    case OPT_LIST:
        break; /* a list is read value by value (the field is an array) */
    }
}

int option_set(const Option *o, void *target, const OptionValue *v)
{
    char *f = (char *)target + o->offset;
    switch (o->type) {
    case OPT_SWITCH:
    case OPT_INT:
    case OPT_CHOICE:
        memcpy(f, &v->i, sizeof v->i);
        break;
    case OPT_REAL:
        memcpy(f, &v->d, sizeof v->d);
        break;
    case OPT_SIZE:
        memcpy(f, &v->z, sizeof v->z);
        break;
    case OPT_TEXT:
        memcpy(f, &v->s, sizeof v->s);
        break;
    case OPT_LIST: {
        int *count = (int *)((char *)target + o->count_offset);
        if (*count >= OPT_LIST_MAX) return mpm_error(MPM_EINPUT, "%s: more than %d values", o->flag, OPT_LIST_MAX);
        ((const char **)(void *)f)[(*count)++] = v->s;
        break;
    }
    }
    return MPM_OK;
}

static int text_equal(const char *a, const char *b) { return a == b || (a && b && !strcmp(a, b)); }

int option_equal(const Option *o, const void *a, const void *b)
{
    if (o->type == OPT_LIST) {
        int na = *(const int *)(const void *)((const char *)a + o->count_offset);
        int nb = *(const int *)(const void *)((const char *)b + o->count_offset);
        const char *const *la = (const char *const *)(const void *)((const char *)a + o->offset);
        const char *const *lb = (const char *const *)(const void *)((const char *)b + o->offset);
        if (na != nb) return 0;
        for (int i = 0; i < na; ++i)
            if (!text_equal(la[i], lb[i])) return 0;
        return 1;
    }
    OptionValue x, y;
    option_get(o, a, &x);
    option_get(o, b, &y);
    switch (o->type) {
    case OPT_REAL:
        return x.d == y.d || (isnan(x.d) && isnan(y.d));
    case OPT_SIZE:
        return x.z == y.z;
    case OPT_TEXT:
        return text_equal(x.s, y.s);
    default:
        return x.i == y.i;
    }
}

void option_format(const Option *o, const OptionValue *v, char *out, size_t n)
{
    switch (o->type) {
    case OPT_SWITCH:
    case OPT_INT:
        snprintf(out, n, "%d", v->i);
        break;
    case OPT_SIZE:
        snprintf(out, n, "%zu", v->z);
        break;
    case OPT_REAL:
        if (v->d == floor(v->d) && fabs(v->d) < 1e15) {
            snprintf(out, n, "%.0f", v->d);
            break;
        }
        for (int p = 1; p <= 17; ++p) { /* the shortest text that reads back as the same double */
            snprintf(out, n, "%.*g", p, v->d);
            if (strtod(out, NULL) == v->d) break;
        }
        break;
    case OPT_CHOICE:
        snprintf(out, n, "%s", o->choices[v->i]);
        break;
    case OPT_TEXT:
    case OPT_LIST:
        snprintf(out, n, "%s", v->s ? v->s : "");
        break;
    }
}

int option_find_flag(const Option *table, int n, const char *flag)
{
    for (int i = 0; i < n; ++i)
        if (table[i].flag && !strcmp(table[i].flag, flag)) return i;
    return -1;
}

int option_find_key(const Option *table, int n, const char *key)
{
    for (int i = 0; i < n; ++i)
        if (table[i].key && !strcmp(table[i].key, key)) return i;
    return -1;
}
