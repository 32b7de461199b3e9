/* Option tables: one line per command-line option, {flag, matrix-file key,
 * type, range or allowed values, the field it sets, help}. The same line
 * parses the flag (cli.c), checks a matrix file's value for the key
 * (experiments/matrix/matrix_file.c), writes a child process's argument
 * (run_settings.c run_config_argv) and prints the help (cli.c), so a value
 * is allowed, refused and described alike everywhere.
 *
 * A table's offsets point into one target struct (run settings: RunConfig,
 * experiments/cli/run_settings.h; a command's own options: its argument
 * struct). */
#ifndef MPM_OPTIONS_H
#define MPM_OPTIONS_H

#include <stddef.h>

#define OPT_LIST_MAX 64   /* values of a repeatable option */
#define OPT_INT_CAP 1000000000.0

/* A macro's value as it is written ("1e-7"), for a default in a help text. */
#define OPT_SPELLED(macro) OPT_SPELLED_TEXT(macro)
#define OPT_SPELLED_TEXT(text) #text

typedef enum {
    OPT_SWITCH, /* no value: the int field becomes 1 */
    OPT_INT,    /* int field: an integer in [min, max] (max 0: up to OPT_INT_CAP) */
    OPT_REAL,   /* double field: a finite number in [min, max] ((min, max] with OPT_MIN_OPEN; max 0: no bound) */
    OPT_SIZE,   /* size_t field: a whole number in [min, max], written like 1e6 or 1000000 */
    OPT_TEXT,   /* const char * field: a non-empty text (the argument itself, not a copy) */
    OPT_CHOICE, /* int field: the index of the value in choices */
    OPT_LIST    /* repeatable text: appended to a const char *[OPT_LIST_MAX] field, its count at count_offset */
} OptionType;

enum {
    OPT_MIN_OPEN = 1u << 0,    /* OPT_REAL: min itself is refused */
    OPT_ARGV_ALWAYS = 1u << 1, /* run_config_argv writes it even at its default (the cell's command reads well) */
    /* where the matrix-file key may stand (experiments/matrix/matrix_file.h) */
    OPT_IN_DEFAULTS = 1u << 4, /* "defaults" */
    OPT_IN_SCENES = 1u << 5,   /* "scenes.NAME" too */
    OPT_AXIS = 1u << 6,        /* a list of values in "axes" */
    /* what the key's value enters of a cell's id (experiments/matrix/matrix_cells.h) */
    OPT_ID_ALWAYS = 1u << 8,   /* always, given or not */
    OPT_ID_GIVEN = 1u << 9,    /* only when given (a switch: when true), so older cells keep their ids */
    /* how a matrix file's value reads */
    OPT_KEY_SCENE = 1u << 12,  /* a built-in scene name, or a scene file relative to the matrix file */
    OPT_KEY_DIR = 1u << 13,    /* a directory relative to the matrix file */
    OPT_KEY_SUBDIR = 1u << 14, /* true or false: true = the folder named by the key in the cell's folder */
    OPT_KEY_JSON = 1u << 15    /* OPT_LIST of key=value: an object {key: any JSON value} (else numbers,
                                  strings and booleans as 1/0) */
};

typedef struct Option {
    const char *flag;                 /* "--eps" */
    const char *key;                  /* matrix-file key, NULL: none */
    const char *metavar;              /* the value in the usage ("E"); NULL for a switch, and for a
                                         choice whose usage lists its choices (option_metavar) */
    OptionType type;
    double min, max;                  /* OPT_INT, OPT_REAL, OPT_SIZE */
    const char *what;                 /* the value in words ("an integer number of threads"); NULL: by type */
    const char *const *choices;       /* OPT_CHOICE: NULL-terminated */
    size_t offset;                    /* the field in the target struct */
    size_t count_offset;              /* OPT_LIST: its int count */
    int (*check)(const char *text);   /* OPT_TEXT, OPT_LIST: a further check of one value (MPM_EINPUT and
                                         a message naming the value), NULL: none */
    unsigned flags;
    const char *help;
} Option;

/* One option's value, whatever its type (matrix axes keep their values so). */
typedef union {
    int i;
    double d;
    size_t z;
    const char *s;
} OptionValue;

/* What the option accepts, in words: "an integer >= 1", "seconds in (0, 1e9]",
 * "stop or continue" (quoted: "\"stop\" or \"continue\"", for JSON files). */
void option_expect(const Option *o, int quoted, char *out, size_t n);

/* The value's name in the usage: the metavar, or a choice's values joined by
 * '|' ("stop|continue"); "" for a switch. */
void option_metavar(const Option *o, char *out, size_t n);

/* The value of text for o into *v; MPM_EINPUT with one line
 * "FLAG 'TEXT': expected WHAT" otherwise (check's own message for a text
 * it refuses). Not for OPT_SWITCH. */
int option_parse_text(const Option *o, const char *text, OptionValue *v);
/* Is the number x in o's range (OPT_INT, OPT_REAL, OPT_SIZE)? */
int option_in_range(const Option *o, double x);

/* The field of o in target: read and write (OPT_LIST: appends; MPM_EINPUT
 * past OPT_LIST_MAX values). */
void option_get(const Option *o, const void *target, OptionValue *v);
int option_set(const Option *o, void *target, const OptionValue *v);
/* Do two targets hold the same value of o (texts compared by content;
 * lists value by value)? */
int option_equal(const Option *o, const void *a, const void *b);
/* The value as an argument: shortest text reading back the same number;
 * whole seconds stay whole ("30", not "3e+01"). */
void option_format(const Option *o, const OptionValue *v, char *out, size_t n);

/* Index of flag ("--eps") or key ("eps") in table[0..n), -1 when none. */
int option_find_flag(const Option *table, int n, const char *flag);
int option_find_key(const Option *table, int n, const char *key);

#endif
