/* JSON reading helpers of the scene loaders (see json_read.h). */
#include "core/scene/json_read.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

/* ======================================================================
 * JSON helpers
 * ====================================================================== */

/* Appends src to the NUL-terminated dst of capacity n, truncating. */
static void str_append(char *dst, size_t n, const char *src)
{
    size_t used = strlen(dst);
    while (*src && used + 1 < n) dst[used++] = *src++;
    dst[used] = '\0';
}

void sj_path(char *dst, size_t n, const char *base, const char *key)
{
    if (n == 0) return;
    dst[0] = '\0';
    if (base) str_append(dst, n, base);
    if (key) {
        if (dst[0]) str_append(dst, n, ".");
        str_append(dst, n, key);
    }
}

void sj_path_index(char *dst, size_t n, const char *base, size_t index)
{
    char num[32];
    int k = (int)sizeof num - 1;
    num[k] = '\0';
    do {
        num[--k] = (char)('0' + index % 10);
        index /= 10;
    } while (index && k > 0);
    sj_path(dst, n, base, num + k);
}

void sj_describe(const json_t *v, char *buf, size_t n)
{
    if (n == 0) return;
    if (!v) {
        snprintf(buf, n, "nothing");
        return;
    }
    switch (json_typeof(v)) {
    case JSON_STRING: snprintf(buf, n, "\"%.60s\"", json_string_value(v)); break;
    case JSON_INTEGER: snprintf(buf, n, "%" JSON_INTEGER_FORMAT, json_integer_value(v)); break;
    case JSON_REAL: snprintf(buf, n, "%.10g", json_real_value(v)); break;
    case JSON_TRUE: snprintf(buf, n, "true"); break;
    case JSON_FALSE: snprintf(buf, n, "false"); break;
    case JSON_NULL: snprintf(buf, n, "null"); break;
    case JSON_ARRAY:
    case JSON_OBJECT: {
        char *s = json_dumps(v, JSON_COMPACT | JSON_ENCODE_ANY | JSON_REAL_PRECISION(10));
        if (s && strlen(s) <= 60)
            snprintf(buf, n, "%s", s);
        else
            snprintf(buf, n, "%s", json_is_array(v) ? "an array" : "an object");
        free(s);
        break;
    }
    default: snprintf(buf, n, "an unknown value"); break;
    }
}

int sj_bad(const char *file, const char *base, const char *key, const char *expected, const json_t *got)
{
    char path[512], what[96];
    sj_path(path, sizeof path, base, key);
    sj_describe(got, what, sizeof what);
    return mpm_error(MPM_EINPUT, "%s: %s: %s, got %s", file, path[0] ? path : "(top level)", expected,
                     what);
}

int sj_bad_number(const char *file, const char *base, const char *key, const char *expected, double got)
{
    char path[512];
    sj_path(path, sizeof path, base, key);
    return mpm_error(MPM_EINPUT, "%s: %s: %s, got %.10g", file, path[0] ? path : "(top level)", expected,
                     got);
}

int sj_missing(const char *file, const char *base, const char *key)
{
    char path[512];
    sj_path(path, sizeof path, base, key);
    return mpm_error(MPM_EINPUT, "%s: %s: missing required field", file, path);
}

int sj_check_object(json_t *obj, const char *file, const char *path, const char *const *allowed)
{
    if (!json_is_object(obj)) return sj_bad(file, path, NULL, "expected an object", obj);
    const char *key;
    json_t *val;
    json_object_foreach(obj, key, val)
    {
        int ok = 0;
        for (const char *const *a = allowed; *a; ++a)
            if (strcmp(*a, key) == 0) {
                ok = 1;
                break;
            }
        if (!ok) {
            char list[512] = "", p[512];
            size_t used = 0;
            for (const char *const *a = allowed; *a && used + 2 < sizeof list; ++a) {
                int w = snprintf(list + used, sizeof list - used, "%s%s", used ? ", " : "", *a);
                if (w < 0) break;
                used += (size_t)w;
            }
            sj_path(p, sizeof p, path, key);
            return mpm_error(MPM_EINPUT, "%s: %s: unknown key (known: %s)", file, p, list);
        }
    }
    return MPM_OK;
}

int sj_number(json_t *obj, const char *key, int required, const char *file, const char *path,
              double *out, int *present)
{
    json_t *v = json_object_get(obj, key);
    if (present) *present = v != NULL;
    if (!v) return required ? sj_missing(file, path, key) : MPM_OK;
    if (!json_is_number(v)) return sj_bad(file, path, key, "expected a number", v);
    double d = json_number_value(v);
    if (!isfinite(d)) return sj_bad(file, path, key, "expected a finite number", v);
    *out = d;
    return MPM_OK;
}

int sj_positive(json_t *obj, const char *key, int required, const char *file, const char *path,
                double *out, int *present)
{
    double d = 0.0;
    int here = 0;
    int st = sj_number(obj, key, required, file, path, &d, &here);
    if (present) *present = here;
    if (st || !here) return st;
    if (!(d > 0.0)) return sj_bad_number(file, path, key, "expected a positive number", d);
    *out = d;
    return MPM_OK;
}

int sj_value_vec3(json_t *v, const char *file, const char *path, double out[3])
{
    if (!json_is_array(v) || json_array_size(v) != 3)
        return sj_bad(file, path, NULL, "expected an array of 3 numbers", v);
    double t[3];
    for (size_t k = 0; k < 3; ++k) {
        json_t *e = json_array_get(v, k);
        char p[512];
        sj_path_index(p, sizeof p, path, k);
        if (!json_is_number(e)) return sj_bad(file, p, NULL, "expected a number", e);
        t[k] = json_number_value(e);
        if (!isfinite(t[k])) return sj_bad(file, p, NULL, "expected a finite number", e);
    }
    memcpy(out, t, sizeof t);
    return MPM_OK;
}

int sj_vec3(json_t *obj, const char *key, int required, const char *file, const char *path,
            double out[3], int *present)
{
    json_t *v = json_object_get(obj, key);
    if (present) *present = v != NULL;
    if (!v) return required ? sj_missing(file, path, key) : MPM_OK;
    char p[512];
    sj_path(p, sizeof p, path, key);
    return sj_value_vec3(v, file, p, out);
}

int sj_string(json_t *obj, const char *key, int required, const char *file, const char *path,
              const char **out, int *present)
{
    json_t *v = json_object_get(obj, key);
    if (present) *present = v != NULL;
    if (!v) return required ? sj_missing(file, path, key) : MPM_OK;
    if (!json_is_string(v)) return sj_bad(file, path, key, "expected a string", v);
    *out = json_string_value(v);
    return MPM_OK;
}

int sj_bool(json_t *obj, const char *key, int required, const char *file, const char *path, int *out,
            int *present)
{
    json_t *v = json_object_get(obj, key);
    if (present) *present = v != NULL;
    if (!v) return required ? sj_missing(file, path, key) : MPM_OK;
    if (!json_is_boolean(v)) return sj_bad(file, path, key, "expected true or false", v);
    *out = json_is_true(v);
    return MPM_OK;
}
