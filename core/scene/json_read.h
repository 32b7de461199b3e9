/* JSON reading helpers shared by the shape, collider, source and scene
 * parsers. They all report MPM_EINPUT through mpm_error with a message
 * "<file>: <path>: <what was expected>, got <value>" where <path> is the
 * dot path of the field (objects by key, arrays by index). */
#ifndef MPM_JSON_READ_H
#define MPM_JSON_READ_H

#include <jansson.h>
#include <stddef.h>

/* dst = base.key (or key when base is empty). */
void sj_path(char *dst, size_t n, const char *base, const char *key);
/* dst = base.index */
void sj_path_index(char *dst, size_t n, const char *base, size_t index);
/* Short human description of a JSON value: `-1`, `"abc"`, `true`, `null`,
 * `an array`, `an object` (truncated to fit). */
void sj_describe(const json_t *v, char *buf, size_t n);

/* Reports "<file>: <base>.<key>: <expected>, got <value>" (key nullable:
 * then the path is <base>). Return MPM_EINPUT. */
int sj_bad(const char *file, const char *base, const char *key, const char *expected, const json_t *got);
int sj_bad_number(const char *file, const char *base, const char *key, const char *expected, double got);
/* Reports "<file>: <base>.<key>: missing required field"; MPM_EINPUT. */
int sj_missing(const char *file, const char *base, const char *key);

/* Checks that `obj` is a JSON object whose keys are all in the
 * NULL-terminated list `allowed`; an unknown key is an error naming it and
 * listing the allowed ones. */
int sj_check_object(json_t *obj, const char *file, const char *path, const char *const *allowed);

/* Field readers. When the field is missing: required -> error "missing
 * required field"; optional -> return MPM_OK and leave *out unchanged.
 * *present (nullable) tells whether the field was there. Numbers accept JSON
 * integers and reals and must be finite. */
int sj_number(json_t *obj, const char *key, int required, const char *file, const char *path,
              double *out, int *present);
/* A number that must be > 0 ("expected a positive number"). */
int sj_positive(json_t *obj, const char *key, int required, const char *file, const char *path,
                double *out, int *present);
int sj_vec3(json_t *obj, const char *key, int required, const char *file, const char *path,
            double out[3], int *present);
int sj_string(json_t *obj, const char *key, int required, const char *file, const char *path,
              const char **out, int *present);
int sj_bool(json_t *obj, const char *key, int required, const char *file, const char *path,
            int *out, int *present);
/* Reads a 3-vector from a JSON value itself (not a field). */
int sj_value_vec3(json_t *v, const char *file, const char *path, double out[3]);

#endif
