/* floor: app */
/* The one table of run settings (experiments/cli/run_settings.c) and the
 * one command-line parser (experiments/cli/cli.c), driven by the tables
 * themselves so that a new table line is tested without a new test:
 *  - the table is well formed: flags and keys unique, no two lines set the
 *    same RunConfig field, every matrix key has an id rule, every axis a
 *    cells.csv column, no key is also one of the matrix file's own;
 *  - `--flag value` and `--flag=value` give the same RunConfig, which differs
 *    from the default in that setting only;
 *  - run_config_argv reads back: a RunConfig with every setting away from
 *    its default, written as arguments and parsed, is the same RunConfig;
 *  - matrix keys round-trip: a matrix file giving every key in "defaults"
 *    (and, separately, per scene and as an axis) yields a cell whose
 *    RunConfig holds the value `run` would take for the flag, and whose
 *    command line, parsed by the CLI parser, is that RunConfig again;
 *  - every option of every command refuses a bad value, an unknown flag and
 *    a missing value with MPM_EINPUT and one line naming the flag;
 *  - every command's --help names every option it takes. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "experiments/commands/commands.h"
#include "experiments/cli/run_settings.h"
#include "experiments/matrix/matrix_cells.h"
#include "experiments/matrix/matrix_columns.h"
#include "experiments/matrix/matrix_keys.h"
#include "tests/common/testutil.h"

static char g_dir[256];

/* A valid value of o, away from its default, as `run` takes it (NULL for a switch). */
static const char *sample(const Option *o, char *buf, size_t n)
{
    switch (o->type) {
    case OPT_SWITCH:
        return NULL;
    case OPT_INT:
        /* ranks > 1 refuses error_ref, particles and references, which the
         * matrices here give with every other key (test_matrix_ranks.sh) */
        snprintf(buf, n, "%d", (int)o->min + (strcmp(o->flag, "--ranks") ? 1 : 0));
        return buf;
    case OPT_SIZE:
        snprintf(buf, n, "%d", (int)o->min + 999);
        return buf;
    case OPT_REAL:
        return "0.5";
    case OPT_CHOICE: {
        int k = 0;
        while (o->choices[k + 1]) ++k;
        return o->choices[k];
    }
    case OPT_TEXT:
        if (o->flags & OPT_KEY_SCENE) return "drop";
        if (!strcmp(o->flag, "--solver")) return "hot";
        if (!strcmp(o->flag, "--error-ref")) return "auto";
        if (o->flags & OPT_KEY_DIR) return "assets";
        if (!strcmp(o->flag, "--checkpoint-at") || !strcmp(o->flag, "--sample-frames")) return "3,5";
        snprintf(buf, n, "value-of%s", o->flag);
        return buf;
    case OPT_LIST:
        return o->flags & OPT_KEY_JSON ? "materials.soft.E=2e5" : "window=4";
    }
    return NULL;
}

static const Command *run_cmd(void) { return cli_command("run"); }

/* Parses the run command's arguments (after "run") into cfg. The required
 * --scene and --solver come first (a later value of a flag wins), unless
 * `bare`. */
static int parse_run_args(int bare, int argc, const char *const *argv, RunConfig *cfg)
{
    char *args[4 * RUN_SETTINGS_MAX + 8];
    int n = 0;
    args[n++] = "mpmbench";
    args[n++] = "run";
    if (!bare) {
        args[n++] = "--scene";
        args[n++] = "stretched-box";
        args[n++] = "--solver";
        args[n++] = "pn-pcg";
    }
    for (int i = 0; i < argc; ++i) args[n++] = (char *)argv[i];
    const char *operand;
    int help;
    mpm_clear_error();
    return cli_parse(run_cmd(), n, args, 2, cfg, &operand, &help);
}

static int parse_run(int argc, const char *const *argv, RunConfig *cfg) { return parse_run_args(0, argc, argv, cfg); }

static void table_well_formed(void)
{
    int keyed_without_id = 0;
    for (int k = 0; k < run_settings_count; ++k) {
        const Option *o = &run_settings[k];
        CHECK(o->flag && !strncmp(o->flag, "--", 2) && o->help && o->help[0], "line %d: flag and help", k);
        char value[64];
        option_metavar(o, value, sizeof value);
        CHECK((o->type == OPT_SWITCH) == (value[0] == '\0'), "%s: a value name unless a switch", o->flag);
        CHECK(o->type != OPT_CHOICE || (o->choices && o->choices[0]), "%s: choices", o->flag);
        CHECK(o->type != OPT_LIST || o->count_offset != 0, "%s: a list needs its count", o->flag);
        for (int j = 0; j < k; ++j) {
            const Option *p = &run_settings[j];
            CHECK(strcmp(o->flag, p->flag), "%s twice", o->flag);
            CHECK(!o->key || !p->key || strcmp(o->key, p->key), "key %s twice", o->key);
            CHECK(o->offset != p->offset, "%s and %s set the same RunConfig field", o->flag, p->flag);
        }
        if (!o->key) {
            CHECK(!(o->flags & (OPT_IN_DEFAULTS | OPT_IN_SCENES | OPT_AXIS | OPT_ID_ALWAYS | OPT_ID_GIVEN)),
                  "%s: matrix flags without a key", o->flag);
            continue;
        }
        for (const char *c = o->key; *c; ++c) CHECK((*c >= 'a' && *c <= 'z') || *c == '_', "key %s", o->key);
        CHECK(o->flags & OPT_IN_DEFAULTS, "%s: a key allowed in defaults", o->key);
        CHECK(!((o->flags & OPT_ID_ALWAYS) && (o->flags & OPT_ID_GIVEN)), "%s: one id rule", o->key);
        /* the report tells cases apart by cells.csv's columns; a rule names an axis by its column */
        CHECK(!(o->flags & OPT_AXIS) || matrix_column_find(o->key) >= 0, "axis %s: a cells.csv column of that name",
              o->key);
        CHECK(!matrix_key(MATRIX_AT_SETTINGS, o->key) && (!(o->flags & OPT_AXIS) || !matrix_key(MATRIX_AT_AXES, o->key)),
              "%s: a run setting and, where it stands, a matrix file key of its own", o->key);
        if (!(o->flags & (OPT_ID_ALWAYS | OPT_ID_GIVEN))) ++keyed_without_id;
        CHECK((o->flags & (OPT_ID_ALWAYS | OPT_ID_GIVEN)) || (o->flags & OPT_KEY_DIR),
              "%s: a key outside the cell id must only locate files", o->key);
    }
    CHECK(keyed_without_id == 1, "one keyed setting outside the id (asset_dir): %d", keyed_without_id);
}

static void flag_forms(void)
{
    RunConfig def, a, b;
    CHECK(parse_run(0, NULL, &def) == MPM_OK, "--scene and --solver alone");
    for (int k = 0; k < run_settings_count; ++k) {
        const Option *o = &run_settings[k];
        char buf[64], joined[256];
        const char *v = sample(o, buf, sizeof buf);
        const char *spaced[2] = {o->flag, v};
        snprintf(joined, sizeof joined, "%s=%s", o->flag, v ? v : "1");
        const char *eq[1] = {joined};
        int sa = parse_run(v ? 2 : 1, spaced, &a);
        CHECK(sa == MPM_OK, "%s %s: %s", o->flag, v ? v : "", mpm_last_error());
        for (int j = 0; j < run_settings_count; ++j)
            CHECK((j == k) != option_equal(&run_settings[j], &a, &def), "%s %s: %s %s the default", o->flag,
                  v ? v : "", run_settings[j].flag, j == k ? "keeps" : "leaves");
        int sb = parse_run(1, eq, &b);
        if (!v) {
            CHECK(sb == MPM_EINPUT && strstr(mpm_last_error(), "takes no value"), "%s: %s", joined, mpm_last_error());
            continue;
        }
        CHECK(sb == MPM_OK, "%s: %s", joined, mpm_last_error());
        const char *diff = "";
        CHECK(run_config_equal(&a, &b, &diff), "%s: --flag value and --flag=value differ in %s", o->flag, diff);
    }
    /* the required ones */
    const char *none[1] = {"--eps"};
    CHECK(parse_run_args(1, 0, none, &a) == MPM_EINPUT && strstr(mpm_last_error(), "--scene is required"), "%s",
          mpm_last_error());
    const char *eps[2] = {"--eps=1e-3", "--scene=drop"};
    CHECK(parse_run_args(1, 2, eps, &a) == MPM_EINPUT && strstr(mpm_last_error(), "--solver is required"), "%s",
          mpm_last_error());
}

/* A RunConfig with every setting at its sample value. */
static int every_setting(RunConfig *cfg, char bufs[][64])
{
    const char *args[4 * RUN_SETTINGS_MAX] = {NULL};
    int n = 0;
    for (int k = 0; k < run_settings_count; ++k) {
        const char *v = sample(&run_settings[k], bufs[k], 64);
        args[n++] = run_settings[k].flag;
        if (v) args[n++] = v;
        if (run_settings[k].type == OPT_LIST) { /* two values, in order */
            args[n++] = run_settings[k].flag;
            args[n++] = run_settings[k].flags & OPT_KEY_JSON ? "materials.hard.E=3e5" : "levels=3";
        }
    }
    return parse_run(n, args, cfg);
}

static int parse_argv(const char *buf, int argc, RunConfig *cfg)
{
    const char *args[4 * RUN_SETTINGS_MAX];
    size_t off = 0;
    for (int i = 0; i < argc; ++i) {
        args[i] = buf + off;
        off += strlen(buf + off) + 1;
    }
    CHECK(argc > 0 && !strcmp(args[0], "run"), "the arguments start with run");
    return parse_run_args(1, argc - 1, args + 1, cfg);
}

static void argv_round_trip(void)
{
    static char bufs[RUN_SETTINGS_MAX][64];
    RunConfig cfg, back, def;
    run_config_default(&def);
    CHECK(every_setting(&cfg, bufs) == MPM_OK, "every setting: %s", mpm_last_error());
    for (int k = 0; k < run_settings_count; ++k)
        CHECK(!option_equal(&run_settings[k], &cfg, &def), "%s is away from its default", run_settings[k].flag);
    char buf[8192];
    int argc = 0;
    CHECK(run_config_argv(&cfg, buf, sizeof buf, &argc) == MPM_OK, "argv: %s", mpm_last_error());
    CHECK(parse_argv(buf, argc, &back) == MPM_OK, "argv parses: %s", mpm_last_error());
    const char *diff = "";
    CHECK(run_config_equal(&cfg, &back, &diff), "argv round trip differs in %s", diff);
    /* and the default RunConfig writes only what identifies a run */
    def.scene = "drop";
    def.solver = "hot";
    CHECK(run_config_argv(&def, buf, sizeof buf, &argc) == MPM_OK && parse_argv(buf, argc, &back) == MPM_OK &&
              run_config_equal(&def, &back, &diff),
          "defaults round trip: %s", diff);
    CHECK(argc == 9, "run --scene --solver --eps --scale only: %d arguments", argc);
    char small[16];
    CHECK(run_config_argv(&cfg, small, sizeof small, &argc) == MPM_EINPUT, "too long is refused");
}

/* The JSON text of o's sample value in a matrix file. */
static void sample_json(const Option *o, char *out, size_t n)
{
    char buf[64];
    const char *v = sample(o, buf, sizeof buf);
    if (o->type == OPT_SWITCH || (o->flags & OPT_KEY_SUBDIR)) snprintf(out, n, "true");
    else if (o->type == OPT_INT || o->type == OPT_REAL || o->type == OPT_SIZE) snprintf(out, n, "%s", v);
    else if (o->type == OPT_LIST) {
        const char *eq = strchr(v, '=');
        snprintf(out, n, "{\"%.*s\": \"%s\"}", (int)(eq - v), v, eq + 1);
    } else snprintf(out, n, "\"%s\"", v);
}

static int load(const char *text, Matrix *m, MatrixCells *c)
{
    static int k = 0;
    char path[320];
    snprintf(path, sizeof path, "%s/m%d.json", g_dir, k++);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    fclose(f);
    mpm_clear_error();
    int st = matrix_load(path, m);
    if (!st) st = matrix_expand(m, c);
    return st;
}

/* The cell's RunConfig has the value `run` takes for each given key, and its
 * command line parses back to that RunConfig. */
static void check_cell(const Matrix *m, const MatrixCell *cell, unsigned flag_mask, const char *what)
{
    static MatrixCellTexts texts;
    static char bufs[RUN_SETTINGS_MAX][64];
    RunConfig cfg, want, back;
    char out_dir[300];
    snprintf(out_dir, sizeof out_dir, "%s/res/cells/%s", g_dir, cell->id);
    CHECK(matrix_cell_config(m, cell, out_dir, &cfg, &texts) == MPM_OK, "%s: config", what);
    for (int k = 0; k < run_settings_count; ++k) {
        const Option *o = &run_settings[k];
        if (!o->key || !(o->flags & flag_mask)) continue;
        if (flag_mask == OPT_AXIS && !strcmp(o->key, "ranks")) continue; /* not in the axes test (below) */
        CHECK(cell->given >> k & 1, "%s: %s given", what, o->key);
        const char *v = sample(o, bufs[k], 64);
        char expect[2048];
        if (o->flags & OPT_KEY_SCENE) v = "drop"; /* a built-in name stays a name */
        if (o->flags & OPT_KEY_DIR) {
            snprintf(expect, sizeof expect, "%s/%s", g_dir, v);
            v = expect;
        }
        if (o->flags & OPT_KEY_SUBDIR) {
            snprintf(expect, sizeof expect, "%s/%s", out_dir, o->key);
            v = expect;
        }
        const char *args[2] = {o->flag, v};
        CHECK(parse_run(v ? 2 : 1, args, &want) == MPM_OK, "%s: %s", o->flag, mpm_last_error());
        CHECK(option_equal(o, &cfg, &want), "%s: key %s does not give what %s %s gives", what, o->key, o->flag,
              v ? v : "");
    }
    char buf[8192];
    int argc = 0;
    const char *diff = "";
    CHECK(matrix_cell_argv(m, cell, out_dir, buf, sizeof buf, &argc) == MPM_OK, "%s: argv %s", what, mpm_last_error());
    CHECK(parse_argv(buf, argc, &back) == MPM_OK, "%s: argv parses: %s", what, mpm_last_error());
    CHECK(run_config_equal(&cfg, &back, &diff), "%s: the cell's command line differs from its RunConfig in %s", what,
          diff);
    CHECK(back.quiet && back.out_dir && !strcmp(back.out_dir, out_dir), "%s: --quiet --out", what);
}

static void matrix_round_trip(void)
{
    char json[8192], value[256];
    /* every key in defaults */
    size_t len = (size_t)snprintf(json, sizeof json, "{\"name\": \"all\", \"defaults\": {");
    for (int k = 0, first = 1; k < run_settings_count; ++k) {
        if (!run_settings[k].key) continue;
        sample_json(&run_settings[k], value, sizeof value);
        len += (size_t)snprintf(json + len, sizeof json - len, "%s\"%s\": %s", first ? "" : ", ", run_settings[k].key,
                                value);
        first = 0;
    }
    snprintf(json + len, sizeof json - len, "}}");
    Matrix m;
    MatrixCells cells;
    int st = load(json, &m, &cells);
    CHECK(st == MPM_OK && cells.n == 1, "every key in defaults: %s\n  %s", mpm_last_error(), json);
    if (!st && cells.n == 1) check_cell(&m, &cells.cells[0], OPT_IN_DEFAULTS, "defaults");
    if (!st) matrix_cells_free(&cells);
    matrix_free(&m);

    /* every per-scene key in scenes.drop */
    len = (size_t)snprintf(json, sizeof json,
                           "{\"name\": \"scene\", \"defaults\": {\"scene\": \"drop\", \"solver\": \"hot\"}, "
                           "\"scenes\": {\"drop\": {");
    for (int k = 0, first = 1; k < run_settings_count; ++k) {
        if (!run_settings[k].key || !(run_settings[k].flags & OPT_IN_SCENES)) continue;
        sample_json(&run_settings[k], value, sizeof value);
        len += (size_t)snprintf(json + len, sizeof json - len, "%s\"%s\": %s", first ? "" : ", ", run_settings[k].key,
                                value);
        first = 0;
    }
    snprintf(json + len, sizeof json - len, "}}}");
    st = load(json, &m, &cells);
    CHECK(st == MPM_OK && cells.n == 1, "every key per scene: %s\n  %s", mpm_last_error(), json);
    if (!st && cells.n == 1) check_cell(&m, &cells.cells[0], OPT_IN_SCENES, "scenes.drop");
    if (!st) matrix_cells_free(&cells);
    matrix_free(&m);

    /* every axis: its sample value and the defaults' (or a second) value, two cells each */
    int n_axes = 0;
    len = (size_t)snprintf(json, sizeof json, "{\"name\": \"axes\", \"defaults\": {\"scene\": \"drop\", \"solver\": "
                                              "\"hot\"}, \"axes\": {");
    for (int k = 0, first = 1; k < run_settings_count; ++k) {
        const Option *o = &run_settings[k];
        /* a ranks axis has no second value that goes with every other key's */
        if (!o->key || !(o->flags & OPT_AXIS) || !strcmp(o->key, "ranks")) continue;
        sample_json(o, value, sizeof value);
        const char *other = o->flags & OPT_KEY_SCENE ? "\"stretched-box\""
                            : !strcmp(o->key, "solver") ? "\"pn-pcg\""
                            : o->type == OPT_TEXT       ? "\"pn-pcg:1e-11\""
                            : o->type == OPT_INT        ? "1"
                                                        : "0.25";
        len += (size_t)snprintf(json + len, sizeof json - len, "%s\"%s\": [%s, %s]", first ? "" : ", ", o->key, value,
                                other);
        first = 0;
        ++n_axes;
    }
    snprintf(json + len, sizeof json - len, "}}");
    st = load(json, &m, &cells);
    CHECK(st == MPM_OK && cells.n == 1 << n_axes, "%d axes of two values: %d cells: %s\n  %s", n_axes, cells.n,
          mpm_last_error(), json);
    if (!st && cells.n > 0) check_cell(&m, &cells.cells[0], OPT_AXIS, "axes (first cell)");
    for (int i = 0; !st && i < cells.n; ++i) { /* and every cell's command line reads back */
        static MatrixCellTexts texts;
        RunConfig cfg, back;
        char buf[8192];
        int argc = 0;
        const char *diff = "";
        int ok = matrix_cell_config(&m, &cells.cells[i], "out", &cfg, &texts) == MPM_OK &&
                 matrix_cell_argv(&m, &cells.cells[i], "out", buf, sizeof buf, &argc) == MPM_OK &&
                 parse_argv(buf, argc, &back) == MPM_OK && run_config_equal(&cfg, &back, &diff);
        CHECK(ok, "axes cell %d: %s %s", i, diff, mpm_last_error());
    }
    if (!st) matrix_cells_free(&cells);
    matrix_free(&m);
}

/* A bad text for o: one its type refuses. */
static const char *bad_value(const Option *o)
{
    switch (o->type) {
    case OPT_INT:
    case OPT_REAL:
    case OPT_SIZE:
        return "x";
    case OPT_CHOICE:
        return "no-such-choice";
    case OPT_LIST:
        return o->check ? "no-equals-sign" : "";
    default:
        return "";
    }
}

static int one_line(const char *s) { return s[0] && !strchr(s, '\n'); }

/* cli_parse of cmd with its operand (if it takes one) and then args. */
static int parse_cmd(const Command *cmd, int argc, const char *const *args, void *target)
{
    char *all[8];
    int n = 0;
    if (cli_takes_operand(cmd)) all[n++] = (char *)(cmd->operand_choices ? cmd->operand_choices[0] : "operand");
    for (int i = 0; i < argc; ++i) all[n++] = (char *)args[i];
    const char *got;
    int help;
    mpm_clear_error();
    return cli_parse(cmd, n, all, 0, target, &got, &help);
}

static void bad_input(void)
{
    for (int c = 0; cli_commands[c]; ++c) {
        const Command *cmd = cli_commands[c];
        void *a = calloc(1, cmd->args_size + 1);
        const char *unknown[1] = {"--no-such-flag"};
        int st = parse_cmd(cmd, 1, unknown, a);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "--no-such-flag") && one_line(mpm_last_error()),
              "%s: an unknown flag: %s", cmd->name, mpm_last_error());
        for (int g = 0; g < cmd->n_groups; ++g) {
            const OptionGroup *grp = &cmd->groups[g];
            for (int k = 0; grp->table[k].flag && (grp->n == 0 || k < grp->n); ++k) {
                const Option *o = &grp->table[k];
                if (!cli_find(cmd, o->flag, NULL) || o->type == OPT_SWITCH) continue;
                const char *args[2] = {o->flag, bad_value(o)};
                st = parse_cmd(cmd, 2, args, a);
                CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), o->flag) && one_line(mpm_last_error()),
                      "%s %s '%s': %s", cmd->name, o->flag, args[1], mpm_last_error());
                st = parse_cmd(cmd, 1, args, a);
                CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "missing value"), "%s %s without a value: %s",
                      cmd->name, o->flag, mpm_last_error());
            }
        }
        free(a);
    }
}

static void help_names_every_option(void)
{
    for (int c = 0; cli_commands[c]; ++c) {
        const Command *cmd = cli_commands[c];
        char *text = NULL;
        size_t size = 0;
        FILE *f = open_memstream(&text, &size);
        if (!f) continue;
        cli_usage(cmd, f);
        fclose(f);
        for (int g = 0; g < cmd->n_groups; ++g)
            for (int k = 0; cmd->groups[g].table[k].flag && (cmd->groups[g].n == 0 || k < cmd->groups[g].n); ++k) {
                const Option *o = &cmd->groups[g].table[k];
                if (!cli_find(cmd, o->flag, NULL)) continue;
                char line[128];
                snprintf(line, sizeof line, "  %s", o->flag);
                CHECK(strstr(text, line), "%s --help names %s", cmd->name, o->flag);
            }
        CHECK(strstr(text, "usage: mpmbench ") && strstr(text, cmd->name), "%s --help: usage line", cmd->name);
        free(text);
    }
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/test_run_settings.XXXXXX");
    if (!mkdtemp(g_dir)) return 1;
    table_well_formed();
    flag_forms();
    argv_round_trip();
    matrix_round_trip();
    bad_input();
    help_names_every_option();
    char cmd[320];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", g_dir);
    return test_summary("test_run_settings");
}
